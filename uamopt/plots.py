"""Figures of the risk field (Sec. 4.1.1, Eqs. 8–9) over the city it was computed on.

:func:`plot_risk` draws the page ``uamopt risk`` writes as ``risk.png``:

(a) map of log10 R (Eq. 8) on the layer holding the cruise altitude, x east, y north, metres;
    obstacle cells dark grey, no-fly columns hatched red, roads outlined, vertiports labelled;
    the colour map jumps from blue to yellow at R_0 (Eq. 9), so safe and unsafe read at a glance;
(b) the city: building heights over ground, roads and open space (parks, water);
(c) a vertical x–z section along one row: log10 R, the surface profile, the altitude band of
    Eq. 14 and the outline of the unsafe free cells;
(d) the mean of each risk term over the free cells of every layer, and (e) the share of unsafe
    cells per layer.

:func:`plot_risk_components` draws (d) larger, one panel per term of Eq. 8.

Figures are built on :class:`matplotlib.figure.Figure` directly (no pyplot state, no GUI
backend), rendered by Agg and released when the function returns. Every array is drawn whole:
no Python loop over cells, so a 250 × 450 × 36 grid plots in about a second.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib import colors, patheffects
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from uamopt.risk import RiskField

FIGSIZE_IN = (14.0, 8.0)
DPI = 130
OSM_CREDIT = "© OpenStreetMap contributors (ODbL)"

OBSTACLE_GREY = "#3d3d3d"  # cells inside or below a building (NaN risk)
BUILDING_GREY = "#1f1f1f"  # the true surface profile in the section
GROUND = "#efebe4"
OPEN_SPACE = "#b9dba0"  # parks and water
ROAD = "#8c8c8c"
NO_FLY = "#d62728"
HALO = [patheffects.withStroke(linewidth=2.5, foreground="white")]
ROAD_OUTLINE_MAX_COLUMNS = 120  # columns across map (a) up to which road columns are outlined
# legends below the map, clear of its tick labels and x label (borderaxespad is in font sizes)
LEGEND_BELOW = {"loc": "upper center", "bbox_to_anchor": (0.5, 0.0), "borderaxespad": 3.4, "ncol": 2,
                "fontsize": 7, "frameon": False}
PROFILE_STYLE = {  # risk term: (label, colour)
    "risk": ("R (Eq. 8)", "black"),
    "risk_P": ("R^P people", "#1f77b4"),
    "risk_V": ("R^V vehicles", "#ff7f0e"),
    "risk_U": ("R^U UAVs", "#9467bd"),
}


# --- small vectorised helpers ----------------------------------------------------------------


def _risk_cmap() -> colors.ListedColormap:
    """Blues below R_0, yellow-to-red above: the Eq. 9 threshold is the colour jump."""
    safe = matplotlib.colormaps["Blues_r"](np.linspace(0.05, 0.75, 128))
    unsafe = matplotlib.colormaps["YlOrRd"](np.linspace(0.15, 1.0, 128))
    return colors.ListedColormap(np.vstack([safe, unsafe]), name="risk_r0").with_extremes(bad=OBSTACLE_GREY)


def _risk_norm(field: RiskField) -> colors.TwoSlopeNorm:
    """log10 R scale shared by map and section, centred (colour jump) on log10 R_0."""
    centre = math.log10(field.threshold)
    finite = field.risk[np.isfinite(field.risk) & (field.risk > 0)]
    lo = float(np.log10(finite.min())) if finite.size else centre - 1.0
    hi = float(np.log10(finite.max())) if finite.size else centre + 1.0
    return colors.TwoSlopeNorm(vcenter=centre, vmin=min(lo, centre - 0.25), vmax=max(hi, centre + 0.25))


def _log10(values: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.log10(values)
    return np.where(np.isfinite(out), out, np.nan)


def _positive(values: np.ndarray) -> np.ndarray:
    """NaN where not > 0, so a log axis leaves a gap instead of warning."""
    return np.where(values > 0, values, np.nan)


def _outline(mask: np.ndarray, xe: np.ndarray, ye: np.ndarray) -> np.ndarray:
    """Cell faces separating ``mask`` (shape (n, m), axis 0 along ``xe``) from the rest.

    Returns segments (K, 2, 2) ready for a LineCollection; faces on the domain border count.
    """
    m = np.pad(np.asarray(mask, dtype=bool), 1)
    i, j = np.nonzero(m[1:, 1:-1] != m[:-1, 1:-1])  # faces x = xe[i], from ye[j] to ye[j+1]
    vertical = np.stack([np.column_stack([xe[i], ye[j]]), np.column_stack([xe[i], ye[j + 1]])], axis=1)
    i, j = np.nonzero(m[1:-1, 1:] != m[1:-1, :-1])  # faces y = ye[j], from xe[i] to xe[i+1]
    horizontal = np.stack([np.column_stack([xe[i], ye[j]]), np.column_stack([xe[i + 1], ye[j]])], axis=1)
    return np.concatenate([vertical, horizontal]).reshape(-1, 2, 2)


def _runs(mask: np.ndarray, xe: np.ndarray, ye: np.ndarray) -> np.ndarray:
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


def _colorbar_axes(ax, width: float = 0.045, pad: float = 0.03):
    """A colour-bar axes glued to the right of ``ax``'s drawn box (follows an equal aspect)."""
    return ax.inset_axes([1.0 + pad, 0.0, width, 1.0])


def _height_cmap() -> colors.ListedColormap:
    """Orange (low-rise) to black (towers): distinct from the cream ground and grey roads."""
    return colors.ListedColormap(matplotlib.colormaps["magma_r"](np.linspace(0.22, 1.0, 256)), name="heights")



def _vertiport_points(vertiports: Iterable) -> list[tuple[str, float, float]]:
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


def _default_section_y(field: RiskField, ports: list[tuple[str, float, float]]) -> float:
    """Midpoint of the first pair of vertiports inside the grid, the only one, or the grid's middle."""
    ex, ey = field.grid.extent[:2]
    ports = [p for p in ports if 0.0 <= p[1] <= ex and 0.0 <= p[2] <= ey]
    if len(ports) >= 2:
        return 0.5 * (ports[0][2] + ports[1][2])
    if len(ports) == 1:
        return ports[0][2]
    return 0.5 * field.grid.extent[1]


def _attribution(field: RiskField) -> str:
    """The city's attribution; OpenStreetMap data is always credited (ODbL)."""
    text = field.city.attribution or ""
    if field.city.source == "osm" and "OpenStreetMap" not in text:
        text = f"{OSM_CREDIT}. {text}".strip(". ")
    return text


def _finish(fig: Figure, field: RiskField, path: Path) -> Path:
    """Credit the data in the bottom-right corner, write the PNG, free the figure."""
    credit = _attribution(field)
    if credit:
        fig.text(0.995, 0.002, credit, ha="right", va="bottom", fontsize=7, color="0.25")
    fig.savefig(path, dpi=DPI)
    fig.clear()
    return path


# --- panels ------------------------------------------------------------------------------------


def _draw_vertiports(ax, ports: list[tuple[str, float, float]]) -> None:
    if not ports:
        return
    xs = [p[1] for p in ports]
    ys = [p[2] for p in ports]
    ax.scatter(xs, ys, marker="^", s=60, c="white", edgecolors="black", linewidths=1.2, zorder=6)
    ex, ey = ax.get_xlim()[1], ax.get_ylim()[1]
    for name, x, y in ports:  # a handful of labels, not cells; kept inside the map near its edges
        east, north = x > 0.7 * ex, y > 0.95 * ey
        ax.annotate(name, (x, y), xytext=(-5 if east else 5, -5 if north else 5), textcoords="offset points",
                    ha="right" if east else "left", va="top" if north else "bottom", fontsize=8,
                    fontweight="bold", zorder=7, path_effects=HALO)


def _draw_section_line(ax, y: float, xmax: float) -> None:
    ax.plot([0.0, xmax], [y, y], color="black", lw=0.9, ls=(0, (6, 3)), zorder=5)
    ax.annotate("section (c)", (0.0, y), xytext=(3, 3), textcoords="offset points", fontsize=7,
                path_effects=HALO, zorder=7)


def _map_axes(ax, field: RiskField) -> None:
    ex, ey = field.grid.extent[:2]
    ax.set_xlim(0.0, ex)
    ax.set_ylim(0.0, ey)
    ax.set_aspect("equal")
    ax.set_xlabel("x east (m)", fontsize=8)
    ax.set_ylabel("y north (m)", fontsize=8)
    ax.tick_params(labelsize=7)


def _panel_risk_map(fig, ax, field, k, norm, cmap, ports, section_y):
    g, city = field.grid, field.city
    xe, ye = g.edges(0), g.edges(1)
    z0, z1 = k * g.cell[2], (k + 1) * g.cell[2]
    mesh = ax.pcolormesh(xe, ye, _log10(field.risk[:, :, k]).T, cmap=cmap, norm=norm, shading="flat")
    # Road columns outlined in white where a cell is wide enough on the page to show a line
    # inside it; on finer grids the outline would paint over the cells (roads are then the
    # unsafe lines themselves, and map (b) shows them).
    outline_roads = g.shape[0] <= ROAD_OUTLINE_MAX_COLUMNS
    if outline_roads:
        ax.add_collection(LineCollection(_outline(city.road_length > 0, xe, ye), colors="white",
                                         linewidths=0.35, alpha=0.7))
    if city.no_fly.any():
        # the hatch takes the edge colour; zero width keeps the run borders invisible
        ax.add_collection(PolyCollection(_runs(city.no_fly, xe, ye), facecolors="none", edgecolors=NO_FLY,
                                         linewidths=0.0, hatch="////", zorder=4))
        ax.add_collection(LineCollection(_outline(city.no_fly, xe, ye), colors=NO_FLY, linewidths=1.2, zorder=4))
    _map_axes(ax, field)
    _draw_section_line(ax, section_y, g.extent[0])
    _draw_vertiports(ax, ports)
    ax.set_title(f"(a) risk R (Eq. 8) on layer k={k}, z = {z0:g}–{z1:g} m", fontsize=9, loc="left")
    cbar = fig.colorbar(mesh, cax=_colorbar_axes(ax))
    _mark_threshold(cbar, field)
    handles = [Patch(facecolor=OBSTACLE_GREY, label="building (obstacle)"),
               Patch(facecolor="none", edgecolor=NO_FLY, hatch="////", label="no-fly")]
    if outline_roads:
        handles.append(Line2D([], [], color="white", lw=1.0, label="road columns",
                              path_effects=[patheffects.withStroke(linewidth=2.2, foreground="0.4")]))
    ax.legend(handles=handles, **LEGEND_BELOW)


def _mark_threshold(cbar, field: RiskField) -> None:
    level = math.log10(field.threshold)
    cbar.set_label("log10 R per flight hour", fontsize=8)
    cbar.ax.axhline(level, color="black", lw=1.5)
    cbar.ax.tick_params(labelsize=7)
    cbar.ax.annotate("R₀", (0.5, level), xycoords=("axes fraction", "data"), xytext=(0, 2),
                     textcoords="offset points", ha="center", va="bottom", fontsize=6.5, path_effects=HALO)


def _panel_city_map(fig, ax, field, ports, section_y):
    g, city = field.grid, field.city
    xe, ye = g.edges(0), g.edges(1)
    ground = np.zeros(city.building_height.shape, dtype=int)
    ground[city.road_length > 0] = 1
    ground[city.open_space] = 2
    ax.pcolormesh(xe, ye, ground.T, cmap=colors.ListedColormap([GROUND, ROAD, OPEN_SPACE]),
                  norm=colors.BoundaryNorm([-0.5, 0.5, 1.5, 2.5], 3), shading="flat")
    heights = np.ma.masked_less_equal(city.building_height, 0.0)
    top = max(float(city.building_height.max()), 1.0)
    mesh = ax.pcolormesh(xe, ye, heights.T, cmap=_height_cmap(), norm=colors.Normalize(0.0, top), shading="flat")
    if city.no_fly.any():
        ax.add_collection(LineCollection(_outline(city.no_fly, xe, ye), colors=NO_FLY, linewidths=1.2, zorder=4))
    _map_axes(ax, field)
    _draw_section_line(ax, section_y, g.extent[0])
    _draw_vertiports(ax, ports)
    ax.set_title(f"(b) city ({city.source}): buildings, roads, open space", fontsize=9, loc="left")
    cbar = fig.colorbar(mesh, cax=_colorbar_axes(ax))
    cbar.set_label("building height (m)", fontsize=8)
    cbar.ax.tick_params(labelsize=7)
    low = field.band[0]
    if low < top:
        cbar.ax.axhline(low, color="black", lw=1.2)
        cbar.ax.annotate("h_min", (0.5, low), xycoords=("axes fraction", "data"), xytext=(0, 3),
                         textcoords="offset points", ha="center", va="bottom", fontsize=6.5, rotation=90,
                         path_effects=HALO)
    ax.legend(handles=[Patch(facecolor=ROAD, label="road"), Patch(facecolor=OPEN_SPACE, label="park / water"),
                       Patch(facecolor=GROUND, edgecolor="0.6", label="open ground"),
                       Patch(facecolor="none", edgecolor=NO_FLY, lw=1.2, label="no-fly")],
              **LEGEND_BELOW)


def _panel_section(fig, ax, field, j, norm, cmap, cruise_altitude_m):
    g, city = field.grid, field.city
    xe, ze = g.edges(0), g.edges(2)
    zmax = g.extent[2]
    mesh = ax.pcolormesh(xe, ze, _log10(field.risk[:, j, :]).T, cmap=cmap, norm=norm, shading="flat")
    # the true surface profile (stepped per column) over the obstacle cells it rounds up to
    surface = city.surface_height[:, j]
    ax.fill_between(np.repeat(xe, 2)[1:-1], 0.0, np.repeat(surface, 2), color=BUILDING_GREY, lw=0, zorder=3)
    free_unsafe = field.unsafe[:, j, :] & ~field.obstacle[:, j, :]
    # thinner outlines on finer grids, so a one-cell column keeps its colour
    width = float(np.clip(60.0 / g.shape[0], 0.2, 0.8))
    ax.add_collection(LineCollection(_outline(free_unsafe, xe, ze), colors="black", linewidths=width, zorder=4))
    # roads and no-fly columns on a strip below the ground line
    strip = -0.05 * zmax
    for mask, colour in ((city.road_length[:, j] > 0, ROAD), (city.no_fly[:, j], NO_FLY)):
        i = np.flatnonzero(mask)
        ax.hlines(np.full(i.size, 0.5 * strip), xe[i], xe[i + 1], colors=colour, lw=4, zorder=3)
    low, high = field.band
    for level, label, dy, va in ((low, "band low", 2, "bottom"), (high, "band high", -2, "top")):
        ax.axhline(level, color="#2ca02c", lw=1.2, ls="--", zorder=5)
        ax.annotate(f"{label} {level:g} m", (g.extent[0], level), xytext=(-3, dy), textcoords="offset points",
                    ha="right", va=va, fontsize=6.5, color="#1a6e1a", path_effects=HALO, zorder=6)
    ax.axhline(cruise_altitude_m, color="black", lw=0.8, ls=":", zorder=5)
    ax.annotate(f"cruise {cruise_altitude_m:g} m", (0.0, cruise_altitude_m), xytext=(3, 2),
                textcoords="offset points", fontsize=6.5, path_effects=HALO, zorder=6)
    ax.set_xlim(0.0, g.extent[0])
    ax.set_ylim(strip, zmax)
    ax.set_xlabel("x east (m)", fontsize=8)
    ax.set_ylabel("altitude z (m)", fontsize=8)
    ax.tick_params(labelsize=7)
    y0, y1 = j * g.cell[1], (j + 1) * g.cell[1]
    ax.set_title(f"(c) section at y = {y0:g}–{y1:g} m (row j={j}); outlined: unsafe free cells", fontsize=9,
                 loc="left")
    cbar = fig.colorbar(mesh, cax=_colorbar_axes(ax, width=0.018, pad=0.012))
    _mark_threshold(cbar, field)


def _layer_profiles(field: RiskField) -> dict[str, np.ndarray]:
    """Mean over the free cells of each layer of every risk term (NaN where a layer has none)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN layers give NaN, as wanted
        return {name: np.nanmean(getattr(field, name), axis=(0, 1))
                for name in ("risk", "risk_P", "risk_V", "risk_U")}



def _panel_profiles(ax, field: RiskField) -> None:
    z = field.grid.z
    for name, values in _layer_profiles(field).items():
        label, colour = PROFILE_STYLE[name]
        ax.plot(_positive(values), z, color=colour, lw=1.6 if name == "risk" else 1.1,
                label=label, marker=".", ms=3)
    ax.set_xscale("log")
    ax.axvline(field.threshold, color="0.45", lw=1.0, ls="--", label="R₀")
    ax.axhspan(*field.band, color="#2ca02c", alpha=0.08, lw=0, label="altitude band")
    ax.set_ylim(0.0, field.grid.extent[2])
    ax.set_xlabel("mean over free cells (per flight hour)", fontsize=8)
    ax.set_ylabel("altitude z (m)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=6.5, loc="best", framealpha=0.85)
    ax.set_title("(d) risk terms (unweighted)", fontsize=9, loc="left")


def _panel_unsafe_share(ax, field: RiskField) -> None:
    z, dz = field.grid.z, field.grid.cell[2]
    n = field.grid.shape[0] * field.grid.shape[1]
    parts = {
        "building": field.obstacle.sum(axis=(0, 1)) / n,
        "no-fly": (field.no_fly & ~field.obstacle).sum(axis=(0, 1)) / n,
        "R > R₀": (field.unsafe & ~field.obstacle & ~field.no_fly).sum(axis=(0, 1)) / n,
    }
    left = np.zeros_like(z)
    for (label, share), colour in zip(parts.items(), (OBSTACLE_GREY, NO_FLY, "#fd8d3c")):
        ax.barh(z, share, height=0.9 * dz, left=left, color=colour, label=label)
        left = left + share
    ax.axhspan(*field.band, color="#2ca02c", alpha=0.08, lw=0)
    ax.set_xlim(0.0, 1.0)
    ax.set_ylim(0.0, field.grid.extent[2])
    ax.set_xlabel("share of the layer's cells", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=6.5, loc="upper right", framealpha=0.85)
    ax.set_title("(e) unsafe share per layer", fontsize=9, loc="left")


# --- public --------------------------------------------------------------------------------


def plot_risk(
    field: RiskField,
    path: str | Path,
    *,
    vertiports: Iterable = (),
    cruise_altitude_m: float = 120.0,
    section_y_m: float | None = None,
    title: str = "",
) -> Path:
    """Draw the risk field and its city on one page and write it as a PNG (14 × 8 in, 130 dpi).

    Parameters
    ----------
    field : RiskField
        The field to draw (Eqs. 8–9) with its grid and city layers.
    path : str or Path
        PNG to write; its folder must exist.
    vertiports : iterable
        Objects with ``name``, ``x``, ``y`` (m), e.g. ``scenario.network.vertiports``, or
        ``(name, x, y)`` tuples; drawn as labelled markers.
    cruise_altitude_m : float
        Altitude (m) whose layer the map (a) shows; a value on a cell face takes the upper layer,
        as :meth:`AirspaceGrid.index_of` does. Clipped to the grid.
    section_y_m : float, optional
        y (m) of the x–z section (c); default: midpoint of the first two vertiports, else the
        middle of the grid. Clipped to the grid.
    title : str
        Leading text of the figure title (e.g. the scenario name).

    Returns
    -------
    Path
        ``path``.

    Notes
    -----
    Used as ``plot_risk(field, out / "risk.png", vertiports=scenario.network.vertiports,
    cruise_altitude_m=scenario.network.cruise_altitude_m, title=scenario.name)``; see
    ``notebooks/01_risk_field.ipynb`` and ``tests/test_plots.py``.
    """
    path = Path(path)
    g = field.grid
    nx, ny, nz = g.shape
    ports = _vertiport_points(vertiports)
    k = int(np.clip(math.floor(cruise_altitude_m / g.cell[2] + 1e-9), 0, nz - 1))
    section_y = float(np.clip(_default_section_y(field, ports) if section_y_m is None else section_y_m,
                              0.0, g.extent[1]))
    j = int(np.clip(math.floor(section_y / g.cell[1]), 0, ny - 1))
    section_y = (j + 0.5) * g.cell[1]
    norm, cmap = _risk_norm(field), _risk_cmap()

    fig = Figure(figsize=FIGSIZE_IN, dpi=DPI, layout="constrained")
    fig.get_layout_engine().set(w_pad=0.04, h_pad=0.04, wspace=0.02, hspace=0.03, rect=(0.0, 0.015, 1.0, 0.985))
    tall = g.extent[1] >= 0.8 * g.extent[0]
    if tall:  # maps side by side on the left, section and profiles on the right
        gs = fig.add_gridspec(2, 4, width_ratios=[1.0, 1.0, 0.62, 0.62], height_ratios=[1.0, 1.25])
        ax_a, ax_b, ax_c = fig.add_subplot(gs[:, 0]), fig.add_subplot(gs[:, 1]), fig.add_subplot(gs[0, 2:])
        ax_d, ax_e = fig.add_subplot(gs[1, 2]), fig.add_subplot(gs[1, 3])
    else:  # wide city: maps on top, section and profiles below
        gs = fig.add_gridspec(2, 4, height_ratios=[1.4, 1.0])
        ax_a, ax_b, ax_c = fig.add_subplot(gs[0, :2]), fig.add_subplot(gs[0, 2:]), fig.add_subplot(gs[1, :2])
        ax_d, ax_e = fig.add_subplot(gs[1, 2]), fig.add_subplot(gs[1, 3])
    ax_e.sharey(ax_d)

    _panel_risk_map(fig, ax_a, field, k, norm, cmap, ports, section_y)
    _panel_city_map(fig, ax_b, field, ports, section_y)
    _panel_section(fig, ax_c, field, j, norm, cmap, cruise_altitude_m)
    _panel_profiles(ax_d, field)
    _panel_unsafe_share(ax_e, field)
    ax_e.tick_params(labelleft=False)

    in_band = field.unsafe[:, :, field.band_layers()]
    head = f"{title} — " if title else ""
    band_text = f", {in_band.mean():.1%} in the band {field.band[0]:g}–{field.band[1]:g} m" if in_band.size else ""
    fig.suptitle(
        f"{head}city: {field.city.source}; cells {g.cell[0]:g} × {g.cell[1]:g} × {g.cell[2]:g} m "
        f"({nx} × {ny} × {nz}); unsafe (Eq. 9, R > R₀ = {field.threshold:.0e} per flight hour, "
        f"buildings, no-fly): {field.unsafe.mean():.1%} of cells{band_text}",
        fontsize=10.5,
    )
    return _finish(fig, field, path)


def plot_risk_components(field: RiskField, path: str | Path, *, title: str = "") -> Path:
    """Vertical profiles of each term of Eq. 8 (R^P, R^V, R^U and R), one panel each.

    Each panel shows, per layer, the mean over the free cells (line) and the 10–90 % range of
    the free cells where the term is positive (band; R^V is zero off the roads, and the title
    gives the share of free cells over a road), on a log axis with R_0 dashed and the altitude
    band of Eq. 14 shaded.
    Writes a 12 × 4 in PNG at 130 dpi and returns ``path``.
    """
    path = Path(path)
    z = field.grid.z
    means = _layer_profiles(field)
    fig = Figure(figsize=(12.0, 4.0), dpi=DPI, layout="constrained")
    fig.get_layout_engine().set(rect=(0.0, 0.03, 1.0, 0.97))
    axes = fig.subplots(1, 4, sharey=True)
    free = ~field.obstacle
    for ax, name in zip(axes, ("risk_P", "risk_V", "risk_U", "risk")):
        label, colour = PROFILE_STYLE[name]
        values = getattr(field, name)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            lo, hi = np.nanpercentile(_positive(values), [10, 90], axis=(0, 1))
        ax.fill_betweenx(z, _positive(lo), _positive(hi), color=colour, alpha=0.2, lw=0,
                         label="10–90 % (term > 0)")
        ax.plot(_positive(means[name]), z, color=colour, lw=1.5, marker=".", label="mean")
        ax.set_xscale("log")
        ax.axvline(field.threshold, color=NO_FLY, lw=1.0, ls="--", label="R₀")
        ax.axhspan(*field.band, color="#2ca02c", alpha=0.08, lw=0)
        share = (values > 0).sum() / max(int(free.sum()), 1)
        ax.set_title(label if share > 0.999 else f"{label} (> 0 in {share:.0%} of free cells)", fontsize=9)
        ax.set_xlabel("per flight hour", fontsize=8)
        ax.tick_params(labelsize=7, which="both")
    axes[0].set_ylabel("altitude z (m)", fontsize=8)
    axes[0].set_ylim(0.0, field.grid.extent[2])
    axes[0].legend(fontsize=7)
    g = field.grid
    fig.suptitle(f"{title + ' — ' if title else ''}risk terms over the free cells of each layer "
                 f"(cells {g.cell[0]:g} × {g.cell[1]:g} × {g.cell[2]:g} m)", fontsize=10)
    return _finish(fig, field, path)
