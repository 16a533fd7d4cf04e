"""Figures and axes: the page a plot function draws on, laid out in inches.

:func:`panels` and :func:`single_axes` turn the ``ax=`` argument of a plot function into its
figure and axes; :func:`inch_grid` places the panels of a page with margins and gaps in inches;
:func:`colorbar_axes` glues a colour bar to a panel; :func:`is_tall` picks the arrangement of a
page's maps; :func:`finish` writes the page's title and the data credit (:func:`attribution`,
:func:`credit`).

Figures are :class:`matplotlib.figure.Figure` objects built directly (no pyplot state, no GUI
backend), so they work headless and display in Jupyter. Pages use a fixed layout in inches
rather than matplotlib's constrained layout: the layout engine measures every tick label
twice before the figure is drawn and cost about half of the time of a save (see
``tests/benchmarks/bench_figures.py``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure, FigureBase

from uamopt.plotting.style import DPI, FIGSIZE_IN, HALO, OSM_CREDIT


def root_figure(target) -> Figure:
    """The top-level :class:`Figure` of an Axes, a SubFigure or a Figure."""
    fig = target if isinstance(target, FigureBase) else target.figure
    while not isinstance(fig, Figure):
        fig = fig.figure
    return fig


def panels(ax, count: int, layout: Callable[[FigureBase], list], figsize=FIGSIZE_IN, *, single: bool = True):
    """Resolve the ``ax`` argument of a plot function into (figure, axes, page).

    ``ax`` may be None (a new page of ``figsize`` inches), a Figure or SubFigure (the page is
    laid out in it), one Axes (the caller then draws its first panel only; refused when
    ``single`` is False) or a sequence of ``count`` Axes (one per panel). ``layout(page)``
    creates the page's axes. ``page`` is the Figure or SubFigure the function owns (for its
    title and footer), None when the caller passed axes.

    Raises
    ------
    TypeError
        ``ax`` is none of these (or one Axes where ``single`` is False).
    ValueError
        ``ax`` is a sequence of the wrong length.
    """
    if ax is None:
        page = Figure(figsize=figsize, dpi=DPI)
        return page, layout(page), page
    if isinstance(ax, FigureBase):
        return root_figure(ax), layout(ax), ax
    if isinstance(ax, Axes) and single:
        return root_figure(ax), [ax], None
    axes = list(np.ravel(ax)) if isinstance(ax, (Iterable, np.ndarray)) else [ax]  # e.g. fig.subplots(2, 2)
    if not all(isinstance(a, Axes) for a in axes):
        raise TypeError(f"ax must be None, a Figure, {'one Axes, ' if single else ''}or a sequence of {count} Axes, "
                        f"got {ax!r}")
    if len(axes) != count:
        raise ValueError(f"ax must hold one Axes per panel: {count} Axes, got {len(axes)}")
    return root_figure(axes[0]), axes, None


def single_axes(ax, figsize) -> tuple[Figure, Axes, bool]:
    """(figure, axes, new) for a one-panel plot: ``ax`` itself, a new Axes filling a given Figure,
    or a new constrained-layout Figure of ``figsize`` inches when ``ax`` is None."""
    if ax is None:
        fig = Figure(figsize=figsize, dpi=DPI, layout="constrained")
        return fig, fig.add_subplot(), True
    if isinstance(ax, FigureBase):
        return root_figure(ax), ax.add_subplot(), True
    if not isinstance(ax, Axes):
        raise TypeError(f"ax must be None, a Figure or one Axes, got {ax!r}")
    return root_figure(ax), ax, False


def size_in(target: FigureBase) -> tuple[float, float]:
    """Width and height (in) of a Figure or SubFigure."""
    if isinstance(target, Figure):
        w, h = target.get_size_inches()
        return float(w), float(h)
    dpi = root_figure(target).dpi
    return target.bbox.width / dpi, target.bbox.height / dpi


def inch_grid(target: FigureBase, nrows: int, ncols: int, *, left: float, right: float, bottom: float,
              top: float, wgap: float = 0.0, hgap: float = 0.0, width_ratios=None, height_ratios=None):
    """A GridSpec on ``target`` with margins (``left``, ``right``, ``bottom``, ``top``: distance
    from each edge) and gaps between cells given in inches, so that the fonts (in points) fit
    whatever the page size and resolution."""
    w, h = size_in(target)
    x0, x1, y0, y1 = left / w, 1.0 - right / w, bottom / h, 1.0 - top / h

    def relative(gap_in: float, span: float, n: int, size: float) -> float:
        gap = gap_in / size  # matplotlib: separation = wspace × mean cell size
        return gap * n / max(span - gap * (n - 1), 1e-6) if n > 1 else 0.0

    return target.add_gridspec(nrows, ncols, left=x0, right=x1, bottom=y0, top=y1,
                               wspace=relative(wgap, x1 - x0, ncols, w), hspace=relative(hgap, y1 - y0, nrows, h),
                               width_ratios=width_ratios, height_ratios=height_ratios)


def attribution(field) -> str:
    """The city's attribution; OpenStreetMap data is always credited (ODbL)."""
    text = field.city.attribution or ""
    if field.city.source == "osm" and "OpenStreetMap" not in text:
        text = f"{OSM_CREDIT}. {text}".strip(". ")
    return text


def credit(target, text: str) -> None:
    """Print the data credit in the bottom-right corner of a page, or inside an Axes' corner
    when the caller owns the page."""
    if not text:
        return
    if isinstance(target, FigureBase):
        target.text(0.995, 0.002, text, ha="right", va="bottom", fontsize=7, color="0.25")
    else:
        target.text(0.995, 0.005, text, transform=target.transAxes, ha="right", va="bottom", fontsize=6,
                    color="0.25", path_effects=HALO, zorder=12)


def finish(page, axes: Sequence[Axes], field, title: str) -> None:
    """A page gets the suptitle and the footer; axes the caller owns get the credit in the first."""
    if page is not None:
        if title:
            page.suptitle(title, fontsize=10.5, y=1.0 - 0.08 / size_in(page)[1], va="top")
        credit(page, attribution(field))
    else:
        credit(axes[0], attribution(field))


def colorbar_axes(ax: Axes, width: float = 0.045, pad: float = 0.03) -> Axes:
    """A colour-bar axes glued to the right of ``ax``'s drawn box (follows an equal aspect)."""
    return ax.inset_axes([1.0 + pad, 0.0, width, 1.0])


def is_tall(field) -> bool:
    """True when the grid is at least 0.8 times as high (north) as wide (east): the pages then
    put maps side by side, else above the other panels."""
    return field.grid.extent[1] >= 0.8 * field.grid.extent[0]
