"""Every notebook in notebooks/ runs top to bottom without an error (its asserts are checks),
at the small sizes its first cell picks when ``UAMOPT_NOTEBOOK_SMALL=1`` (full sizes otherwise).

The kernel is this interpreter (``sys.executable``, i.e. the project's venv): the kernel spec
comes from the ipykernel installed here, never from a ``python3`` kernel spec in the user's
home or elsewhere on the Jupyter path, and nothing is installed or written outside a temporary
folder.
"""

from __future__ import annotations

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


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_notebook_runs(path: Path, tmp_path: Path, monkeypatch):
    # keep the kernel's runtime files (connection file, IPython profile) out of the home folder
    monkeypatch.setenv("JUPYTER_RUNTIME_DIR", str(tmp_path / "runtime"))
    monkeypatch.setenv("IPYTHONDIR", str(tmp_path / "ipython"))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.setenv("UAMOPT_NOTEBOOK_SMALL", "1")  # each notebook's first cell picks its small sizes
    nb = nbformat.read(path, as_version=4)
    client = NotebookClient(
        nb,
        timeout=TIMEOUT_S,
        kernel_name="python3",
        kernel_manager_class=ThisPythonKernelManager,
        resources={"metadata": {"path": str(ROOT)}},  # cwd = repository root
    )
    started = time.perf_counter()
    client.execute()  # raises CellExecutionError on the first failing cell
    errors = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.get("outputs", [])
              if o.get("output_type") == "error"]
    assert not errors
    assert all(cell.get("execution_count") for cell in nb.cells if cell.cell_type == "code")
    assert time.perf_counter() - started < TIMEOUT_S
