"""Shared drawing on an Axes, used by every map and section of the figures.

The risk colour map whose jump marks R_0 (Eq. 9), its norm and colour-bar label; log axes
labelled in plain text; cells drawn as one image, and cell outlines and runs as one collection
each (no-fly hatching, road outlines); a risk layer of the field; map axes and vertiports; panel
letters and titles. The figures and their axes come from :mod:`uamopt.plotting.layout`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import matplotlib
import numpy as np
from matplotlib import colors, ticker
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection, PolyCollection

from uamopt.plotting.geometry import window_slices
from uamopt.plotting.style import HALO, NO_FLY, OBSTACLE_GREY, ROAD_OUTLINE_MAX_COLUMNS

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
