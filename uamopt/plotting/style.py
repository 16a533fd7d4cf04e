"""The shared look of uamopt's figures, and the helpers every plotting module uses.

Colours, resolution and the attribution footer; the risk colour map whose jump marks R_0
(Eq. 9); cell outlines and runs drawn as one collection each; the page layout in inches; and
:func:`save`, the one place a figure becomes a file.

Figures are :class:`matplotlib.figure.Figure` objects built directly (no pyplot state, no GUI
backend), so they work headless and display in Jupyter. Pages use a fixed layout in inches
rather than matplotlib's constrained layout: the layout engine measures every tick label
twice before the figure is drawn and cost about half of the time of a save (see
``tests/benchmarks/bench_figures.py``).
"""

from __future__ import annotations

import io
import math
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib import colors, patheffects, ticker
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure, FigureBase

DPI = 110  # dots per inch of a saved PNG (a 14 × 8 in page is 1540 × 880 pixels)
FIGSIZE_IN = (14.0, 8.0)  # the page of the risk, tracks and network figures
OSM_CREDIT = "© OpenStreetMap contributors (ODbL)"

OBSTACLE_GREY = "#3d3d3d"  # cells inside or below a building (NaN risk)
BUILDING_GREY = "#1f1f1f"  # the true surface profile in a section
GROUND = "#efebe4"
OPEN_SPACE = "#b9dba0"  # parks and water
ROAD = "#8c8c8c"
NO_FLY = "#d62728"
BAND_GREEN = "#2ca02c"  # the altitude band of Eq. 14
BAND_TEXT = "#1a6e1a"
HALO = [patheffects.withStroke(linewidth=2.5, foreground="white")]
ROAD_OUTLINE_MAX_COLUMNS = 120  # columns across a map up to which road columns are outlined
# legends below a map, clear of its tick labels and x label (borderaxespad is in font sizes)
LEGEND_BELOW = {"loc": "upper center", "bbox_to_anchor": (0.5, 0.0), "borderaxespad": 3.4, "ncol": 2,
                "fontsize": 7, "frameon": False}


# --- figures, axes and files -----------------------------------------------------------------


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


# --- risk colours ----------------------------------------------------------------------------


def risk_cmap() -> colors.ListedColormap:
    """Blues below R_0, yellow-to-red above: the Eq. 9 threshold is the colour jump."""
    safe = matplotlib.colormaps["Blues_r"](np.linspace(0.05, 0.75, 128))
    unsafe = matplotlib.colormaps["YlOrRd"](np.linspace(0.15, 1.0, 128))
    return colors.ListedColormap(np.vstack([safe, unsafe]), name="risk_r0").with_extremes(bad=OBSTACLE_GREY)


def risk_norm(field) -> colors.TwoSlopeNorm:
    """log10 R scale shared by maps and sections, centred (colour jump) on log10 R_0."""
    centre = math.log10(field.threshold)
    finite = field.risk[np.isfinite(field.risk) & (field.risk > 0)]
    lo = float(np.log10(finite.min())) if finite.size else centre - 1.0
    hi = float(np.log10(finite.max())) if finite.size else centre + 1.0
    return colors.TwoSlopeNorm(vcenter=centre, vmin=min(lo, centre - 0.25), vmax=max(hi, centre + 0.25))


def log10(values: np.ndarray) -> np.ndarray:
    """log10 of the values, NaN where not finite or not positive (obstacles, zero risk)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.log10(values)
    return np.where(np.isfinite(out), out, np.nan)


def mark_threshold(cbar, field) -> None:
    """Label a log10 R colour bar and draw R_0 across it."""
    level = math.log10(field.threshold)
    cbar.set_label("log10 R per flight hour", fontsize=8)
    cbar.ax.axhline(level, color="black", lw=1.5)
    cbar.ax.tick_params(labelsize=7)
    cbar.ax.annotate("R₀", (0.5, level), xycoords=("axes fraction", "data"), xytext=(0, 2),
                     textcoords="offset points", ha="center", va="bottom", fontsize=6.5, path_effects=HALO)


_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


class PowerOfTenFormatter(ticker.LogFormatter):
    """Log-axis labels 10⁻⁷ and 3×10⁻⁸ in plain text: what matplotlib's default writes with
    mathtext, whose parser costs about a quarter of a second per process."""

    def _num_to_string(self, x, vmin, vmax):
        exponent = math.floor(math.log10(x) + 1e-9)
        coefficient = round(x / 10.0 ** exponent, 6)
        power = f"10{str(exponent).translate(_SUPERSCRIPT)}"
        return power if coefficient == 1 else f"{coefficient:g}×{power}"


def log_axis(ax: Axes, which: str = "x") -> None:
    """Log scale on the ``which`` axis, labelled by :class:`PowerOfTenFormatter`."""
    axis = ax.xaxis if which == "x" else ax.yaxis
    (ax.set_xscale if which == "x" else ax.set_yscale)("log")
    axis.set_major_formatter(PowerOfTenFormatter())  # the choice of labels of matplotlib's default
    axis.set_minor_formatter(PowerOfTenFormatter())


def colorbar_axes(ax: Axes, width: float = 0.045, pad: float = 0.03) -> Axes:
    """A colour-bar axes glued to the right of ``ax``'s drawn box (follows an equal aspect)."""
    return ax.inset_axes([1.0 + pad, 0.0, width, 1.0])


# --- cells as collections --------------------------------------------------------------------


def outline(mask: np.ndarray, xe: np.ndarray, ye: np.ndarray) -> np.ndarray:
    """Cell faces separating ``mask`` (shape (n, m), axis 0 along ``xe``) from the rest.

    Returns segments (K, 2, 2) ready for a LineCollection; faces on the domain border count.
    """
    m = np.pad(np.asarray(mask, dtype=bool), 1)
    i, j = np.nonzero(m[1:, 1:-1] != m[:-1, 1:-1])  # faces x = xe[i], from ye[j] to ye[j+1]
    vertical = np.stack([np.column_stack([xe[i], ye[j]]), np.column_stack([xe[i], ye[j + 1]])], axis=1)
    i, j = np.nonzero(m[1:-1, 1:] != m[1:-1, :-1])  # faces y = ye[j], from xe[i] to xe[i+1]
    horizontal = np.stack([np.column_stack([xe[i], ye[j]]), np.column_stack([xe[i + 1], ye[j]])], axis=1)
    return np.concatenate([vertical, horizontal]).reshape(-1, 2, 2)


def runs(mask: np.ndarray, xe: np.ndarray, ye: np.ndarray) -> np.ndarray:
    """Rectangles (K, 4, 2) covering ``mask``, one per run of consecutive cells along axis 0.

    Used for hatching: one polygon per run instead of one per cell.
    """
    m = np.pad(np.asarray(mask, dtype=bool), ((1, 1), (0, 0)))
    starts_i, starts_j = np.nonzero(m[1:-1] & ~m[:-2])
    ends_i, ends_j = np.nonzero(m[1:-1] & ~m[2:])
    # nonzero walks axis 0 first; sort both by (j, i) so the k-th start pairs with the k-th end
    s = np.lexsort((starts_i, starts_j))
    e = np.lexsort((ends_i, ends_j))
    i0, i1, j = starts_i[s], ends_i[e] + 1, starts_j[s]
    x0, x1, y0, y1 = xe[i0], xe[i1], ye[j], ye[j + 1]
    return np.stack([np.column_stack(p) for p in ((x0, y0), (x1, y0), (x1, y1), (x0, y1))], axis=1)


def cell_image(ax: Axes, values: np.ndarray, xe: np.ndarray, ye: np.ndarray, **kwargs):
    """Draw a (n, m) array of cells (axis 0 along ``xe``) as one image over its cell edges.

    The cells of a grid are uniform, so an image shows what a mesh (one polygon per cell)
    shows, and saving costs less: on the paper case about 10 % of the risk page's save time and
    30 % of the track page's against ``pcolormesh`` (the network page: no difference), at 50 m
    and at 10 m cells (``tests/benchmarks/bench_figures.py --cells pcolormesh``). ``get_array()`` of the result is
    ``values.T`` (rows along ``ye``).
    """
    # smaller than a pixel, cells are averaged in colour (not in value, which would blend across R_0)
    return ax.imshow(values.T, origin="lower", extent=(xe[0], xe[-1], ye[0], ye[-1]), aspect="auto",
                     interpolation="antialiased", interpolation_stage="rgba", **kwargs)


def no_fly_hatching(ax: Axes, no_fly: np.ndarray, xe: np.ndarray, ye: np.ndarray, *, linewidth: float = 1.2,
                    zorder: float = 4) -> None:
    """No-fly columns: red hatching (zero edge width hides the run borders) and a red outline."""
    if not no_fly.any():
        return
    ax.add_collection(PolyCollection(runs(no_fly, xe, ye), facecolors="none", edgecolors=NO_FLY, linewidths=0.0,
                                     hatch="////", zorder=zorder), autolim=False)
    ax.add_collection(LineCollection(outline(no_fly, xe, ye), colors=NO_FLY, linewidths=linewidth, zorder=zorder),
                      autolim=False)


def is_tall(field) -> bool:
    """True when the grid is at least 0.8 times as high (north) as wide (east): the pages then
    put maps side by side, else above the other panels."""
    return field.grid.extent[1] >= 0.8 * field.grid.extent[0]


def layer_of(field, altitude_m: float) -> int:
    """Layer index holding ``altitude_m`` (a face goes to the upper layer), clipped to the grid."""
    g = field.grid
    return int(np.clip(math.floor(altitude_m / g.cell[2] + 1e-9), 0, g.shape[2] - 1))


def window_slices(field, window=None) -> tuple[slice, slice]:
    """Column slices of the grid covering ``window`` (x0, x1, y0, y1) m with one cell to spare."""
    g = field.grid
    if window is None:
        return slice(0, g.shape[0]), slice(0, g.shape[1])
    x0, x1, y0, y1 = window[:4]
    i0, i1 = int(max(math.floor(x0 / g.cell[0]) - 1, 0)), int(min(math.ceil(x1 / g.cell[0]) + 1, g.shape[0]))
    j0, j1 = int(max(math.floor(y0 / g.cell[1]) - 1, 0)), int(min(math.ceil(y1 / g.cell[1]) + 1, g.shape[1]))
    return slice(i0, i1), slice(j0, j1)


def draw_risk_layer(ax: Axes, field, k: int, norm, cmap, window=None):
    """log10 R (Eq. 8) on layer k, buildings dark grey, no-fly hatched, road columns outlined in
    white where cells are large enough on the page; restricted to ``window`` (x0, x1, y0, y1)
    when given. Returns the image (its array is log10 R of the layer, transposed)."""
    g, city = field.grid, field.city
    si, sj = window_slices(field, window)
    xe, ye = g.edges(0)[si.start:si.stop + 1], g.edges(1)[sj.start:sj.stop + 1]
    image = cell_image(ax, log10(field.risk[si, sj, k]), xe, ye, cmap=cmap, norm=norm)
    # on finer grids the outline would paint over the cells (roads are then the unsafe lines)
    if len(xe) - 1 <= ROAD_OUTLINE_MAX_COLUMNS:
        ax.add_collection(LineCollection(outline(city.road_length[si, sj] > 0, xe, ye), colors="white",
                                         linewidths=0.35, alpha=0.7), autolim=False)
    no_fly_hatching(ax, city.no_fly[si, sj], xe, ye)
    return image


# --- maps ------------------------------------------------------------------------------------


def map_axes(ax: Axes, field) -> None:
    """x east, y north in metres over the whole grid, equal scales."""
    ex, ey = field.grid.extent[:2]
    ax.set_xlim(0.0, ex)
    ax.set_ylim(0.0, ey)
    ax.set_aspect("equal")
    ax.set_xlabel("x east (m)", fontsize=8)
    ax.set_ylabel("y north (m)", fontsize=8)
    ax.tick_params(labelsize=7)


def vertiport_points(vertiports: Iterable) -> list[tuple[str, float, float]]:
    """(name, x, y) from Vertiport objects, mappings or (name, x, y) tuples."""
    points = []
    for v in vertiports:
        if hasattr(v, "x"):
            points.append((str(getattr(v, "name", "")), float(v.x), float(v.y)))
        elif isinstance(v, dict):
            points.append((str(v.get("name", "")), float(v["x"]), float(v["y"])))
        else:
            name, x, y = v
            points.append((str(name), float(x), float(y)))
    return points


def draw_vertiports(ax: Axes, ports: list[tuple[str, float, float]]) -> None:
    """Labelled white triangles; labels kept inside the map near its edges."""
    if not ports:
        return
    ax.scatter([p[1] for p in ports], [p[2] for p in ports], marker="^", s=60, c="white", edgecolors="black",
               linewidths=1.2, zorder=6)
    ex, ey = ax.get_xlim()[1], ax.get_ylim()[1]
    for name, x, y in ports:  # a handful of labels, not cells
        east, north = x > 0.7 * ex, y > 0.95 * ey
        ax.annotate(name, (x, y), xytext=(-5 if east else 5, -5 if north else 5), textcoords="offset points",
                    ha="right" if east else "left", va="top" if north else "bottom", fontsize=8,
                    fontweight="bold", zorder=7, path_effects=HALO)


def panel_letter(ax: Axes) -> str:
    """The letter of a map drawn alone into an Axes the caller passed: its place among the
    panels of its figure, "(a)", "(b)", "(c)" for ``fig.subplots(1, 3)`` (the order they were
    created in; colour bars are not panels), so that maps drawn side by side are told apart.
    A page a plot function lays out itself letters its panels in its own order instead."""
    siblings = [a for a in ax.figure.axes if a.get_label() != "<colorbar>"]
    n = next((i for i, a in enumerate(siblings) if a is ax), 0)
    return f"({chr(ord('a') + n)})" if n < 26 else f"({n + 1})"


def panel_title(ax: Axes, text: str, fontsize: float = 9) -> None:
    """A left-aligned panel title at a fixed height (y = 1 skips matplotlib's search for tick
    labels above the axes, which is costly and finds none here)."""
    ax.set_title(text, fontsize=fontsize, loc="left", y=1.0)
