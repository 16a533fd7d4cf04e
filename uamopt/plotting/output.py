"""Output: where a figure leaves the library.

:func:`save` is the one place a figure becomes a file; :func:`png_bytes` renders it to PNG bytes
and :func:`show_figures_in` lets Jupyter/IPython display a returned Figure with them.
"""

from __future__ import annotations

import io
from pathlib import Path

from matplotlib.figure import Figure

from uamopt.plotting.layout import root_figure
from uamopt.plotting.style import DPI


def save(fig, path: str | Path, *, dpi: float = DPI) -> Path:
    """Write ``fig`` (a Figure, or the Figure of a SubFigure or Axes) to ``path`` and return it.

    The format follows the suffix (``.png``, ``.pdf``, ``.svg``); a PNG is written at ``dpi``.
    The folder must exist. The figure is left as it is, so it can be
    shown or saved again.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> fig = Figure(figsize=(2, 1))
    >>> _ = fig.add_subplot().plot([0, 1], [1, 0])
    >>> import tempfile, pathlib
    >>> png = save(fig, pathlib.Path(tempfile.mkdtemp()) / "line.png")
    >>> png.read_bytes()[:8] == b"\\x89PNG\\r\\n\\x1a\\n"
    True
    """
    path = Path(path)
    root_figure(fig).savefig(path, dpi=dpi)
    return path


def png_bytes(fig, dpi: float = DPI) -> bytes:
    """The figure as PNG bytes (what Jupyter displays)."""
    buffer = io.BytesIO()
    root_figure(fig).savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


def show_figures_in(shell) -> bool:
    """Let Jupyter/IPython ``shell`` display a returned Figure as a PNG, as ``%matplotlib inline``
    does, without importing pyplot. Leaves an existing Figure printer alone; returns True when
    this one was registered. Called with the running shell when :mod:`uamopt.plotting` is
    imported."""
    if shell is None:
        return False
    formatter = shell.display_formatter.formatters["image/png"]
    try:
        formatter.lookup_by_type(Figure)
        return False
    except KeyError:
        formatter.for_type(Figure, png_bytes)
        return True
