"""Shared by the make_NN.py generators: write a notebook of cells (no outputs) beside them.

Each generator is run as ``python notebooks/make_NN.py`` from anywhere; the notebook it writes is
committed without outputs, and ``tests/test_notebooks.py`` executes it.
"""
from pathlib import Path

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

md, code = new_markdown_cell, new_code_cell


def write_notebook(cells: list, name: str) -> Path:
    """Validate ``cells`` as a Python 3 notebook and write it to notebooks/``name``; cell ids are
    numbered (not random), so regenerating an unchanged notebook changes nothing."""
    for i, cell in enumerate(cells):
        cell["id"] = f"{name[:2]}-{i:02d}"
    nb = new_notebook(cells=cells, metadata={
        "kernelspec": {"display_name": "Python 3 (ipykernel)", "language": "python", "name": "python3"},
        "language_info": {"name": "python"},
    })
    nbformat.validate(nb)
    target = Path(__file__).resolve().parent / name
    nbformat.write(nb, target)
    print("wrote", target)
    return target
