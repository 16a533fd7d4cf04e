"""Every notebook in notebooks/ runs top to bottom without an error (its asserts are checks),
at the small sizes its first cell picks when ``UAMOPT_NOTEBOOK_SMALL=1`` (full sizes otherwise).

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
TIMEOUT_S = 120


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


async def _execute(path: Path, scratch: Path, slots: asyncio.Semaphore):
    """Run one notebook in its own kernel; returns (executed notebook, seconds, error or None)."""
    async with slots:
        env = os.environ | {
            # the kernel's runtime files (connection file, IPython profile) stay out of the home folder
            "JUPYTER_RUNTIME_DIR": str(scratch / "runtime"),
            "IPYTHONDIR": str(scratch / "ipython"),
            "MPLBACKEND": "Agg",
            "UAMOPT_NOTEBOOK_SMALL": "1",  # each notebook's first cell picks its small sizes
        }
        nb = nbformat.read(path, as_version=4)
        client = NotebookClient(
            nb,
            timeout=TIMEOUT_S,
            kernel_name="python3",
            kernel_manager_class=ThisPythonKernelManager,
            resources={"metadata": {"path": str(ROOT)}},  # cwd = repository root
        )
        started = time.perf_counter()
        try:
            await client.async_execute(env=env)  # raises CellExecutionError on the first failing cell
        except Exception as error:  # reported by the notebook's own test below
            return nb, time.perf_counter() - started, error
        return nb, time.perf_counter() - started, None


@pytest.fixture(scope="module")
def executed(tmp_path_factory) -> dict:
    """Every notebook executed once, ``PARALLEL`` kernels at a time: name -> (notebook, seconds, error)."""
    scratch = tmp_path_factory.mktemp("kernels")

    async def run_all():
        slots = asyncio.Semaphore(PARALLEL)
        jobs = [_execute(path, scratch / path.stem, slots) for path in NOTEBOOKS]
        return dict(zip((p.name for p in NOTEBOOKS), await asyncio.gather(*jobs)))

    return asyncio.run(run_all())


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_notebook_runs(path: Path, executed):
    nb, seconds, error = executed[path.name]
    if error is not None:
        raise error
    errors = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.get("outputs", [])
              if o.get("output_type") == "error"]
    assert not errors
    assert all(cell.get("execution_count") for cell in nb.cells if cell.cell_type == "code")
    print(f"{path.name}: {seconds:.1f} s")  # a timing, reported (nbclient's own timeout stops a hung cell)
