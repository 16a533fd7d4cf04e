"""Figures of the risk field (Sec. 4.1.1, Eqs. 8–9) over the city it was computed on.

:func:`risk` draws the page ``uamopt risk`` saves as ``risk.png``:

(a) map of log10 R (Eq. 8) on the layer holding the cruise altitude, x east, y north, metres;
    obstacle cells dark grey, no-fly columns hatched red, roads outlined, vertiports labelled;
    the colour map jumps from blue to yellow at R_0 (Eq. 9), so safe and unsafe read at a glance;
(b) the city: building heights over ground, roads and open space (parks, water);
(c) a vertical x–z section along one row: log10 R, the surface profile, the altitude band of
    Eq. 14 and the outline of the unsafe free cells;
(d) the mean of each risk term over the free cells of every layer, and (e) the share of unsafe
    cells per layer.

:func:`risk_components` draws (d) larger, one panel per term of Eq. 8.

Every array is drawn whole: no Python loop over cells.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable

import matplotlib
import numpy as np
from matplotlib import colors, patheffects
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from uamopt.plotting.draw import (
    cell_image,
    draw_risk_layer,
    draw_vertiports,
    log10,
    log_axis,
    map_axes,
    mark_threshold,
    outline,
    panel_letter,
    panel_title,
    risk_cmap,
    risk_norm,
    vertiport_points,
)
from uamopt.plotting.geometry import layer_of
from uamopt.plotting.layout import colorbar_axes, finish, inch_grid, is_tall, panels
from uamopt.plotting.style import (
    BAND_GREEN,
    BAND_TEXT,
    BUILDING_GREY,
    GROUND,
    HALO,
    LEGEND_BELOW,
    NO_FLY,
    OBSTACLE_GREY,
    OPEN_SPACE,
    ROAD,
    ROAD_OUTLINE_MAX_COLUMNS,
)

PROFILE_STYLE = {  # risk term: (label, colour)
    "risk": ("R (Eq. 8)", "black"),
    "risk_P": ("R^P people", "#1f77b4"),
    "risk_V": ("R^V vehicles", "#ff7f0e"),
    "risk_U": ("R^U UAVs", "#9467bd"),
}


def _positive(values: np.ndarray) -> np.ndarray:
    """NaN where not > 0, so a log axis leaves a gap instead of warning."""
    return np.where(values > 0, values, np.nan)


def _height_cmap() -> colors.ListedColormap:
    """Orange (low-rise) to black (towers): distinct from the cream ground and grey roads."""
    return colors.ListedColormap(matplotlib.colormaps["magma_r"](np.linspace(0.22, 1.0, 256)), name="heights")


def _default_section_y(field, ports: list[tuple[str, float, float]]) -> float:
    """Midpoint of the first pair of vertiports inside the grid, the only one, or the grid's middle."""
    ex, ey = field.grid.extent[:2]
    ports = [p for p in ports if 0.0 <= p[1] <= ex and 0.0 <= p[2] <= ey]
    if len(ports) >= 2:
        return 0.5 * (ports[0][2] + ports[1][2])
    if len(ports) == 1:
        return ports[0][2]
    return 0.5 * field.grid.extent[1]


def _layer_profiles(field) -> dict[str, np.ndarray]:
    """Mean over the free cells of each layer of every risk term (NaN where a layer has none)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN layers give NaN, as wanted
        return {name: np.nanmean(getattr(field, name), axis=(0, 1)) for name in PROFILE_STYLE}


# --- panels ------------------------------------------------------------------------------------


def _draw_section_line(ax, y: float, xmax: float) -> None:
    ax.plot([0.0, xmax], [y, y], color="black", lw=0.9, ls=(0, (6, 3)), zorder=5)
    ax.annotate("section (c)", (0.0, y), xytext=(3, 3), textcoords="offset points", fontsize=7,
                path_effects=HALO, zorder=7)


def _panel_risk_map(ax, field, k, norm, cmap, ports, section_y, letter="(a)"):
    g = field.grid
    image = draw_risk_layer(ax, field, k, norm, cmap)
    map_axes(ax, field)
    if section_y is not None:
        _draw_section_line(ax, section_y, g.extent[0])
    draw_vertiports(ax, ports)
    z0, z1 = k * g.cell[2], (k + 1) * g.cell[2]
    panel_title(ax, f"{letter} risk R (Eq. 8) on layer k={k}, z = {z0:g}–{z1:g} m")
    cbar = ax.figure.colorbar(image, cax=colorbar_axes(ax))
    mark_threshold(cbar, field)
    handles = [Patch(facecolor=OBSTACLE_GREY, label="building (obstacle)"),
               Patch(facecolor="none", edgecolor=NO_FLY, hatch="////", label="no-fly")]
    if g.shape[0] <= ROAD_OUTLINE_MAX_COLUMNS:
        handles.append(Line2D([], [], color="white", lw=1.0, label="road columns",
                              path_effects=[patheffects.withStroke(linewidth=2.2, foreground="0.4")]))
    ax.legend(handles=handles, **LEGEND_BELOW)


def _panel_city_map(ax, field, ports, section_y):
    g, city = field.grid, field.city
    xe, ye = g.edges(0), g.edges(1)
    ground = np.zeros(city.building_height.shape, dtype=int)
    ground[city.road_length > 0] = 1
    ground[city.open_space] = 2
    cell_image(ax, ground, xe, ye, cmap=colors.ListedColormap([GROUND, ROAD, OPEN_SPACE]),
               norm=colors.BoundaryNorm([-0.5, 0.5, 1.5, 2.5], 3))
    heights = np.ma.masked_less_equal(city.building_height, 0.0)
    top = max(float(city.building_height.max()), 1.0)
    image = cell_image(ax, heights, xe, ye, cmap=_height_cmap(), norm=colors.Normalize(0.0, top))
    if city.no_fly.any():
        ax.add_collection(LineCollection(outline(city.no_fly, xe, ye), colors=NO_FLY, linewidths=1.2, zorder=4),
                          autolim=False)
    map_axes(ax, field)
    _draw_section_line(ax, section_y, g.extent[0])
    draw_vertiports(ax, ports)
    panel_title(ax, f"(b) city ({city.source}): buildings, roads, open space")
    cbar = ax.figure.colorbar(image, cax=colorbar_axes(ax))
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


def _panel_section(ax, field, j, norm, cmap, cruise_altitude_m):
    g, city = field.grid, field.city
    xe, ze = g.edges(0), g.edges(2)
    zmax = g.extent[2]
    image = cell_image(ax, log10(field.risk[:, j, :]), xe, ze, cmap=cmap, norm=norm)
    # the true surface profile (stepped per column) over the obstacle cells it rounds up to
    surface = city.surface_height[:, j]
    ax.fill_between(np.repeat(xe, 2)[1:-1], 0.0, np.repeat(surface, 2), color=BUILDING_GREY, lw=0, zorder=3)
    free_unsafe = field.unsafe[:, j, :] & ~field.obstacle[:, j, :]
    # thinner outlines on finer grids, so a one-cell column keeps its colour
    width = float(np.clip(60.0 / g.shape[0], 0.2, 0.8))
    ax.add_collection(LineCollection(outline(free_unsafe, xe, ze), colors="black", linewidths=width, zorder=4),
                      autolim=False)
    # roads and no-fly columns on a strip below the ground line
    strip = -0.05 * zmax
    for mask, colour in ((city.road_length[:, j] > 0, ROAD), (city.no_fly[:, j], NO_FLY)):
        i = np.flatnonzero(mask)
        ax.hlines(np.full(i.size, 0.5 * strip), xe[i], xe[i + 1], colors=colour, lw=4, zorder=3)
    low, high = field.band
    for level, label, dy, va in ((low, "band low", 2, "bottom"), (high, "band high", -2, "top")):
        ax.axhline(level, color=BAND_GREEN, lw=1.2, ls="--", zorder=5)
        ax.annotate(f"{label} {level:g} m", (g.extent[0], level), xytext=(-3, dy), textcoords="offset points",
                    ha="right", va=va, fontsize=6.5, color=BAND_TEXT, path_effects=HALO, zorder=6)
    ax.axhline(cruise_altitude_m, color="black", lw=0.8, ls=":", zorder=5)
    ax.annotate(f"cruise {cruise_altitude_m:g} m", (0.0, cruise_altitude_m), xytext=(3, 2),
                textcoords="offset points", fontsize=6.5, path_effects=HALO, zorder=6)
    ax.set_xlim(0.0, g.extent[0])
    ax.set_ylim(strip, zmax)
    ax.set_xlabel("x east (m)", fontsize=8)
    ax.set_ylabel("altitude z (m)", fontsize=8)
    ax.tick_params(labelsize=7)
    y0, y1 = j * g.cell[1], (j + 1) * g.cell[1]
    panel_title(ax, f"(c) section at y = {y0:g}–{y1:g} m (row j={j}); outlined: unsafe free cells")
    mark_threshold(ax.figure.colorbar(image, cax=colorbar_axes(ax, width=0.018, pad=0.012)), field)


def _panel_profiles(ax, field) -> None:
    z = field.grid.z
    for name, values in _layer_profiles(field).items():
        label, colour = PROFILE_STYLE[name]
        ax.plot(_positive(values), z, color=colour, lw=1.6 if name == "risk" else 1.1,
                label=label, marker=".", ms=3)
    log_axis(ax)
    ax.axvline(field.threshold, color="0.45", lw=1.0, ls="--", label="R₀")
    ax.axhspan(*field.band, color=BAND_GREEN, alpha=0.08, lw=0, label="altitude band")
    ax.set_ylim(0.0, field.grid.extent[2])
    ax.set_xlabel("mean over free cells (per flight hour)", fontsize=8)
    ax.set_ylabel("altitude z (m)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=6.5, loc="best", framealpha=0.85)
    panel_title(ax, "(d) risk terms (unweighted)")


def _panel_unsafe_share(ax, field) -> None:
    z, dz = field.grid.z, field.grid.cell[2]
    n = field.grid.shape[0] * field.grid.shape[1]
    parts = {
        "building": field.obstacle.sum(axis=(0, 1)) / n,
        "no-fly": (field.no_fly & ~field.obstacle).sum(axis=(0, 1)) / n,
        "R > R₀": (field.unsafe & ~field.obstacle & ~field.no_fly).sum(axis=(0, 1)) / n,
    }
    left = np.zeros_like(z)
    for (label, share), colour in zip(parts.items(), (OBSTACLE_GREY, NO_FLY, "#fd8d3c"), strict=True):
        ax.barh(z, share, height=0.9 * dz, left=left, color=colour, label=label)
        left = left + share
    ax.axhspan(*field.band, color=BAND_GREEN, alpha=0.08, lw=0)
    ax.set_xlim(0.0, 1.0)
    ax.set_ylim(0.0, field.grid.extent[2])
    ax.set_xlabel("share of the layer's cells", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=6.5, loc="upper right", framealpha=0.85)
    panel_title(ax, "(e) unsafe share per layer")


# --- the page ----------------------------------------------------------------------------------


def _layout(field):
    """The page's five axes: maps side by side on the left and the section over the profiles on
    the right for a tall city; maps on top and section and profiles below for a wide one."""
    def tall(page):
        maps = inch_grid(page, 1, 2, left=0.6, right=6.0, top=0.65, bottom=1.0, wgap=1.4)
        right = inch_grid(page, 2, 2, left=9.45, right=0.85, top=0.55, bottom=0.62, hgap=0.75, wgap=0.12,
                          height_ratios=[1.0, 1.25])
        ax_d = page.add_subplot(right[1, 0])
        return [page.add_subplot(maps[0]), page.add_subplot(maps[1]), page.add_subplot(right[0, :]), ax_d,
                page.add_subplot(right[1, 1], sharey=ax_d)]

    def wide(page):
        maps = inch_grid(page, 1, 2, left=0.6, right=0.9, top=0.65, bottom=4.15, wgap=1.5)
        section = inch_grid(page, 1, 1, left=0.6, right=7.0, top=5.1, bottom=0.45)
        right = inch_grid(page, 1, 2, left=8.75, right=0.2, top=5.1, bottom=0.62, wgap=0.12)
        ax_d = page.add_subplot(right[0])
        return [page.add_subplot(maps[0]), page.add_subplot(maps[1]), page.add_subplot(section[0]), ax_d,
                page.add_subplot(right[1], sharey=ax_d)]

    return tall if is_tall(field) else wide


def risk(field, ax=None, *, vertiports: Iterable = (), cruise_altitude_m: float = 120.0,
         section_y_m: float | None = None, title: str = "") -> Figure:
    """Draw the risk field (Eqs. 8–9) and its city; return the Figure (nothing is written).

    Parameters
    ----------
    field : RiskField
        The field to draw with its grid and city layers.
    ax : None, Figure, Axes or sequence of 5 Axes
        None: a new 14 × 8 in page with panels (a)–(e) (module docstring), a title and the data
        credit. A Figure or SubFigure: that page laid out in it. One Axes: map (a) only, with
        its colour bar and legend, the credit in its corner, lettered by its place among the
        figure's panels (three maps in ``fig.subplots(1, 3)`` are (a), (b), (c)). Five Axes:
        panels (a)–(e) in them.
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
        Leading text of the page title (e.g. the scenario name).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn into; save it with :func:`uamopt.plotting.save`.

    Examples
    --------
    >>> fig = risk(field, vertiports=scenario.network.vertiports, title=scenario.name)  # doctest: +SKIP
    >>> save(fig, "risk.png")  # doctest: +SKIP
    """
    g = field.grid
    nx, ny, nz = g.shape
    ports = vertiport_points(vertiports)
    k = layer_of(field, cruise_altitude_m)
    section_y = float(np.clip(_default_section_y(field, ports) if section_y_m is None else section_y_m,
                              0.0, g.extent[1]))
    j = int(np.clip(math.floor(section_y / g.cell[1]), 0, ny - 1))
    section_y = (j + 0.5) * g.cell[1]
    norm, cmap = risk_norm(field), risk_cmap()
    fig, axes, page = panels(ax, 5, _layout(field))
    if len(axes) == 1:
        _panel_risk_map(axes[0], field, k, norm, cmap, ports, None, panel_letter(axes[0]))
        finish(None, axes, field, "")
        return fig
    ax_a, ax_b, ax_c, ax_d, ax_e = axes
    _panel_risk_map(ax_a, field, k, norm, cmap, ports, section_y)
    _panel_city_map(ax_b, field, ports, section_y)
    _panel_section(ax_c, field, j, norm, cmap, cruise_altitude_m)
    _panel_profiles(ax_d, field)
    _panel_unsafe_share(ax_e, field)
    if ax_e.get_shared_y_axes().joined(ax_d, ax_e):
        ax_e.tick_params(labelleft=False)
    head = f"{title} — " if title else ""
    # the report's figure (summary()["band_unsafe_share"]): obstacle cells are in neither count
    band_text = (f", {field.unsafe_share():.1%} of the band's free cells ({field.band[0]:g}–{field.band[1]:g} m)"
                 if field.band_layers().size else "")
    finish(page, axes, field,
           f"{head}city: {field.city.source}; cells {g.cell[0]:g} × {g.cell[1]:g} × {g.cell[2]:g} m "
           f"({nx} × {ny} × {nz}); unsafe (Eq. 9: R > R₀ = {field.threshold:.0e}/h, buildings, no-fly): "
           f"{field.unsafe.mean():.1%} of all cells{band_text}")
    return fig


def risk_components(field, ax=None, *, title: str = "") -> Figure:
    """Vertical profiles of each term of Eq. 8 (R^P, R^V, R^U and R), one panel each.

    Each panel shows, per layer, the mean over the free cells (line) and the 10–90 % range of
    the free cells where the term is positive (band; R^V is zero off the roads, and the title
    gives the share of free cells over a road), on a log axis with R_0 dashed and the altitude
    band of Eq. 14 shaded. ``ax``: None (a new 12 × 4 in page), a Figure or SubFigure, or a
    sequence of 4 Axes. Returns the Figure.
    """
    z = field.grid.z
    means = _layer_profiles(field)

    def layout(page):
        grid = inch_grid(page, 1, 4, left=0.6, right=0.15, top=0.6, bottom=0.55, wgap=0.15)
        first = page.add_subplot(grid[0])
        return [first] + [page.add_subplot(grid[i], sharey=first) for i in (1, 2, 3)]

    fig, axes, page = panels(ax, 4, layout, figsize=(12.0, 4.0), single=False)
    free = ~field.obstacle
    for i, (axis, name) in enumerate(zip(axes, ("risk_P", "risk_V", "risk_U", "risk"), strict=False)):
        label, colour = PROFILE_STYLE[name]
        values = getattr(field, name)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            lo, hi = np.nanpercentile(_positive(values), [10, 90], axis=(0, 1))
        axis.fill_betweenx(z, _positive(lo), _positive(hi), color=colour, alpha=0.2, lw=0,
                           label="10–90 % (term > 0)")
        axis.plot(_positive(means[name]), z, color=colour, lw=1.5, marker=".", label="mean")
        log_axis(axis)
        axis.axvline(field.threshold, color=NO_FLY, lw=1.0, ls="--", label="R₀")
        axis.axhspan(*field.band, color=BAND_GREEN, alpha=0.08, lw=0)
        share = (values > 0).sum() / max(int(free.sum()), 1)
        axis.set_title(label if share > 0.999 else f"{label} (> 0 in {share:.0%} of free cells)", fontsize=9, y=1.0)
        axis.set_xlabel("per flight hour", fontsize=8)
        axis.tick_params(labelsize=7, which="both", labelleft=i == 0 or page is None)
    axes[0].set_ylabel("altitude z (m)", fontsize=8)
    axes[0].set_ylim(0.0, field.grid.extent[2])
    axes[0].legend(fontsize=7)
    g = field.grid
    finish(page, axes, field, f"{title + ' — ' if title else ''}risk terms over the free cells of each layer "
                              f"(cells {g.cell[0]:g} × {g.cell[1]:g} × {g.cell[2]:g} m)")
    return fig
