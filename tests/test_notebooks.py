"""Every notebook in notebooks/ runs top to bottom without an error (its asserts are checks),
at the small sizes its first cell picks when ``UAMOPT_NOTEBOOK_SMALL=1``, and (slow) at full size.

The kernel is this interpreter (``sys.executable``, i.e. the project's venv): the kernel spec
comes from the ipykernel installed here, never from a ``python3`` kernel spec in the user's
home or elsewhere on the Jupyter path, and nothing is installed or written outside a temporary
folder. The notebooks are independent, so two kernels run at once (one per core).
"""

from __future__ import annotations

import asyncio
import os
import time
from pathlib import Path

import nbformat
import pytest
from jupyter_client.kernelspec import KernelSpecManager
from jupyter_client.manager import AsyncKernelManager
from nbclient import NotebookClient
from traitlets import default

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
TIMEOUT_S = 120  # per cell, small run
FULL_TIMEOUT_S = 3600  # per cell, full size (slow: `make test-all`, CI's second step)


class ThisPythonKernelManager(AsyncKernelManager):
    """Starts ``python3`` as ipykernel's native spec: [sys.executable, -m, ipykernel_launcher, ...]."""

    @default("kernel_spec_manager")
    def _only_the_native_kernel(self) -> KernelSpecManager:
        return KernelSpecManager(kernel_dirs=[], ensure_native_kernel=True)


def test_there_are_notebooks():
    assert NOTEBOOKS, "notebooks/*.ipynb is empty"


def test_kernel_is_this_interpreter():
    import sys

    spec = ThisPythonKernelManager(kernel_name="python3").kernel_spec
    assert spec.argv[0] == sys.executable


#: kernels at once: the notebooks are independent, and each kernel is one busy core
PARALLEL = max(1, min(2, os.cpu_count() or 1))


async def _execute(path: Path, scratch: Path, slots: asyncio.Semaphore, small: bool = True):
    """Run one notebook in its own kernel; returns (executed notebook, seconds, error or None)."""
    async with slots:
        env = os.environ | {
            # the kernel's runtime files (connection file, IPython profile) stay out of the home folder
            "JUPYTER_RUNTIME_DIR": str(scratch / "runtime"),
            "IPYTHONDIR": str(scratch / "ipython"),
            "MPLBACKEND": "Agg",
            "UAMOPT_NOTEBOOK_SMALL": "1" if small else "0",  # each notebook's first cell picks its sizes
        }
        nb = nbformat.read(path, as_version=4)
        client = NotebookClient(
            nb,
            timeout=TIMEOUT_S if small else FULL_TIMEOUT_S,
            kernel_name="python3",
            kernel_manager_class=ThisPythonKernelManager,
            resources={"metadata": {"path": str(ROOT)}},  # cwd = repository root
        )
        started = time.perf_counter()
        try:
            await client.async_execute(env=env)  # raises CellExecutionError on the first failing cell
        except Exception as error:  # noqa: BLE001 - reported by the notebook's own test below
            return nb, time.perf_counter() - started, error
        return nb, time.perf_counter() - started, None


def _execute_all(scratch: Path, small: bool, parallel: int) -> dict:
    async def run_all():
        slots = asyncio.Semaphore(parallel)
        jobs = [_execute(path, scratch / path.stem, slots, small) for path in NOTEBOOKS]
        return dict(zip((p.name for p in NOTEBOOKS), await asyncio.gather(*jobs), strict=True))

    return asyncio.run(run_all())


@pytest.fixture(scope="module")
def executed(tmp_path_factory) -> dict:
    """Every notebook executed once, ``PARALLEL`` kernels at a time: name -> (notebook, seconds, error)."""
    return _execute_all(tmp_path_factory.mktemp("kernels"), True, PARALLEL)


@pytest.fixture(scope="module")
def executed_full(tmp_path_factory) -> dict:
    """Every notebook at full size, one kernel at a time (notebook 03 runs its own 2-worker Dask cluster)."""
    return _execute_all(tmp_path_factory.mktemp("kernels_full"), False, 1)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_notebook_runs(path: Path, executed):
    check_executed(path, *executed[path.name])  # a timing is printed, not asserted (nbclient times out a hung cell)


def check_executed(path: Path, nb, seconds: float, error) -> None:
    if error is not None:
        raise error
    errors = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.get("outputs", [])
              if o.get("output_type") == "error"]
    assert not errors
    assert all(cell.get("execution_count") for cell in nb.cells if cell.cell_type == "code")
    print(f"{path.name}: {seconds:.1f} s")


@pytest.mark.slow(reason="every notebook at full size, as a user runs it: about 10-20 minutes on 2 cores")
@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_notebook_runs_at_full_size(path: Path, executed_full):
    check_executed(path, *executed_full[path.name])
