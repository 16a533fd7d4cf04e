"""Figure of the route network (Sec. 4.1.2): every route and direction over the cruise layer,
and their altitude profiles.

One colour per route, named on the map beside the track; arrow heads for the direction of
flight, the two directions of a route told apart by line style (the first listed solid, the way
back dashed); the layering of Sec. 4.1.2 puts them on different cruise layers. The profiles are
small multiples, one row per route, so that tracks flying the same layer do not hide each other.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import matplotlib
import numpy as np
from matplotlib import colors, patheffects
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator

from uamopt.plotting.draw import (
    cell_image,
    draw_vertiports,
    map_axes,
    no_fly_hatching,
    panel_letter,
    panel_title,
    vertiport_points,
)
from uamopt.plotting.geometry import along_track_m, cruise_altitude_m, layer_of, pair_directions, point_at, route_waypoints
from uamopt.plotting.layout import finish, inch_grid, is_tall, panels, root_figure
from uamopt.plotting.style import BAND_GREEN, LEGEND_BELOW, NO_FLY

SAFE_PALE = "#f7f7f5"  # free cells with R ≤ R_0
UNSAFE_PALE = "#e3d3c3"  # free cells with R > R_0
WAY_BACK = (0, (3.2, 1.6))  # the dash pattern of a route's second direction
LABEL_MAX_CHARS = 9  # longer route names are numbered on the map, the key in (b)
PROFILE_ROW_IN = 0.55  # least height of one route's profile row (in), gap included


def _draw_direction_arrows(ax, waypoints: np.ndarray, colour, fractions=(0.3, 0.62)) -> None:
    """Arrow heads along a track at the given fractions of its horizontal length."""
    d = along_track_m(waypoints)
    if d[-1] <= 0:
        return
    for f in fractions:
        a, b = point_at(waypoints, np.array([f * d[-1], min(f * d[-1] + 0.02 * d[-1], d[-1])]))
        ax.annotate("", xy=b, xytext=a, zorder=8,
                    arrowprops={"arrowstyle": "-|>,head_length=0.7,head_width=0.35", "color": colour, "lw": 1.2,
                                "shrinkA": 0, "shrinkB": 0,
                                "path_effects": [patheffects.withStroke(linewidth=2.6, foreground="white")]})


def _muted_layer(ax, field, k: int) -> None:
    """Layer k in three pale tones (safe, unsafe, building) so that route colours stand out."""
    g = field.grid
    kind = np.where(field.obstacle[:, :, k], 2, np.where(field.unsafe[:, :, k], 1, 0))
    cell_image(ax, kind, g.edges(0), g.edges(1), cmap=colors.ListedColormap([SAFE_PALE, UNSAFE_PALE, "#9a9a9a"]),
               norm=colors.BoundaryNorm([-0.5, 0.5, 1.5, 2.5], 3))
    no_fly_hatching(ax, field.city.no_fly, g.edges(0), g.edges(1), linewidth=1.0, zorder=3)


def _network_layout(field):
    def tall(page):
        grid = inch_grid(page, 1, 2, left=0.75, right=0.25, top=0.65, bottom=0.85, wgap=0.9, width_ratios=[1.0, 1.5])
        return [page.add_subplot(grid[0]), page.add_subplot(grid[1])]

    def wide(page):
        grid = inch_grid(page, 2, 1, left=0.75, right=0.25, top=0.65, bottom=0.5, hgap=1.05, height_ratios=[1.6, 1.0])
        return [page.add_subplot(grid[0]), page.add_subplot(grid[1])]

    return tall if is_tall(field) else wide


def route_colours(n: int) -> list:
    """One distinct colour per route: tab10 up to ten routes, else tab20's dark tones before its
    light ones (so that neighbours in the list differ most)."""
    if n <= 10:
        return list(matplotlib.colormaps["tab10"].colors[:n])
    tab20 = matplotlib.colormaps["tab20"].colors
    order = list(tab20[0::2]) + list(tab20[1::2])
    return [order[i % len(order)] for i in range(n)]


def route_label(forward: str) -> str:
    """"V1–V4" for the route "V1-V4" (an en dash between two end points), else the name."""
    parts = forward.split("-")
    return "–".join(parts) if len(parts) == 2 else forward


def _label_positions(tracks: list[np.ndarray], avoid: list[tuple[float, float]], spacing: float) -> list[np.ndarray]:
    """One label anchor per track: the point along it (from its middle outwards) farthest from
    the labels already placed and from the ``avoid`` points, at least ``spacing`` m from them
    when such a point exists."""
    placed = [np.asarray(p, dtype=float) for p in avoid]
    anchors = []
    fractions = np.array([0.5, 0.42, 0.58, 0.34, 0.66, 0.26, 0.74, 0.18, 0.82])
    for wp in tracks:
        d = along_track_m(wp)
        candidates = point_at(wp, fractions * d[-1]) if d[-1] > 0 else wp[:1, :2]
        if placed:
            gaps = np.min(np.linalg.norm(candidates[:, None, :] - np.asarray(placed)[None, :, :], axis=2), axis=1)
            good = np.flatnonzero(gaps >= spacing)
            choice = candidates[good[0]] if good.size else candidates[int(np.argmax(gaps))]
        else:
            choice = candidates[0]
        placed.append(choice)
        anchors.append(choice)
    return anchors


def network(model, routes, ax=None, *, vertiports: Iterable = (), title: str = "") -> Figure:
    """Draw a route network; return the Figure.

    (a) map over the cruise layer (pale: safe, tan: unsafe (Eq. 9), grey: buildings, red
    hatching: no-fly), one colour per route, named ("V1–V4") beside its track, arrow heads for
    the direction of flight, the route's first direction solid and its way back dashed in the
    same colour; (b) the altitude profiles, one row per route (both directions: altitude
    against horizontal distance flown), on shared axes: the layering of Sec. 4.1.2 shows as
    the two cruise levels of each route. Every legend lies inside the page.

    Parameters
    ----------
    model : PlanningModel
        The model the tracks were planned on.
    routes : mapping
        Route name (e.g. ``"V1-V2"``) to waypoints (n, 3) in metres, to a TrackPlan (its
        optimal stage), to a ``network.json`` route entry, or the result of
        :func:`uamopt.planning.network.plan_network`; a whole ``network.json`` document also
        works. A track and the one flying back between the same end points (within two cells)
        are drawn as one route.
    ax : None, Figure, Axes or sequence of 2 Axes
        None: a new 14 × 8 in page with (a) and (b); a Figure or SubFigure: that page in it; one
        Axes: the map (a) only; two Axes: (a) and (b) (the rows of (b) are inset axes of the
        second, its ``child_axes``, one per route in the order of the map's legend).
    vertiports : iterable
        As for :func:`uamopt.plotting.risk`: objects with ``name``, ``x``, ``y`` or tuples.
    title : str
        Leading text of the page title.

    Raises
    ------
    ValueError
        ``routes`` is empty.
    """
    tracks_m = route_waypoints(routes)
    if not tracks_m:
        raise ValueError("routes must name at least one route")
    field = model.field
    g = field.grid
    k = layer_of(field, model.scenario.network.cruise_altitude_m)
    pairs = pair_directions(tracks_m, 2.0 * math.hypot(*g.cell[:2]))
    palette = route_colours(len(pairs))
    fig, axes, page = panels(ax, 2, _network_layout(field))
    ax_map, ax_prof = axes[0], (axes[1] if len(axes) > 1 else None)
    _muted_layer(ax_map, field, k)
    map_axes(ax_map, field)
    for (forward, reverse), colour in zip(pairs, palette, strict=True):
        for name, style, lw in ((forward, "-", 2.6), (reverse, WAY_BACK, 1.5)):
            if name is None:
                continue
            wp = tracks_m[name]
            # a white edge: the dashed way back reads over the solid way out where they overlap
            halo = [patheffects.withStroke(linewidth=lw + (1.8 if style == "-" else 1.4), foreground="white")]
            ax_map.plot(wp[:, 0], wp[:, 1], color=colour, lw=lw, ls=style, zorder=6 if style == "-" else 7,
                        solid_capstyle="round", path_effects=halo, label=name)
            _draw_direction_arrows(ax_map, wp, colour)
    ports = vertiport_points(vertiports)
    draw_vertiports(ax_map, ports)
    # beside each route its name, or its number in (b) when names are long (real vertiport names)
    names = [route_label(f) for f, _ in pairs]
    keyed = ax_prof is not None and max(len(t) for t in names) > LABEL_MAX_CHARS
    span = max(g.extent[:2])
    avoid = [(x, y) for _, x, y in ports] + [(x + 0.06 * span, y + 0.02 * span) for _, x, y in ports]
    anchors = _label_positions([tracks_m[f] for f, _ in pairs], avoid, 0.09 * span)
    for n, (text, colour, (x, y)) in enumerate(zip(names, palette, anchors, strict=True)):
        ax_map.annotate(str(n + 1) if keyed else text, (x, y), ha="center", va="center", fontsize=6.5, fontweight="bold",
                        color=tuple(0.75 * np.asarray(colors.to_rgb(colour))), zorder=9,
                        bbox={"boxstyle": "round,pad=0.18", "fc": "white", "ec": colour, "lw": 0.8, "alpha": 0.9})
    z0, z1 = k * g.cell[2], (k + 1) * g.cell[2]
    letter = "(a)" if ax_prof is not None or page is not None else panel_letter(ax_map)
    panel_title(ax_map, f"{letter} routes over layer k={k}: z = {z0:g}–{z1:g} m")
    ax_map.legend(handles=[Patch(facecolor=SAFE_PALE, edgecolor="0.6", label="R ≤ R₀"),
                           Patch(facecolor=UNSAFE_PALE, label="R > R₀ (Eq. 9)"),
                           Patch(facecolor="#9a9a9a", label="building"),
                           Patch(facecolor="none", edgecolor=NO_FLY, hatch="////", label="no-fly"),
                           Line2D([], [], color="0.2", lw=2.2, label="a route's first direction"),
                           Line2D([], [], color="0.2", lw=1.4, ls=WAY_BACK, label="its way back")],
                  **{**LEGEND_BELOW, "ncol": 3})
    if ax_prof is not None:
        _network_profiles(ax_prof, field, pairs, tracks_m, palette, keyed)
    finish(page, axes, field, f"{title + ' — ' if title else ''}route network: {len(tracks_m)} tracks on "
                              f"{len(pairs)} routes; cells {g.cell[0]:g} × {g.cell[1]:g} × {g.cell[2]:g} m")
    return fig


def _network_profiles(ax, field, pairs, tracks_m, palette, keyed: bool = False) -> None:
    """Panel (b): ``ax`` becomes a frame holding one inset row per route (its ``child_axes``),
    all on the same distance and altitude scales; ``keyed``: each row's title starts with the
    number that names the route on the map."""
    g = field.grid
    low, high = field.band
    n = len(pairs)
    dpi = root_figure(ax).dpi
    height_in = max(ax.bbox.height / dpi, 1e-3)
    ncols = int(min(max(math.ceil(n * PROFILE_ROW_IN / height_in), 1), 4, n))
    nrows = math.ceil(n / ncols)
    every = np.concatenate([w[:, 2] for w in tracks_m.values()])
    z_lo, z_hi = float(every.min()) - g.cell[2], float(every.max()) + g.cell[2]
    d_max = max(float(along_track_m(w)[-1]) for w in tracks_m.values()) or 1.0
    levels = sorted({round(cruise_altitude_m(w)) for w in tracks_m.values()})
    ticks = levels if len(levels) <= 4 else MaxNLocator(4).tick_values(z_lo, z_hi)
    ax.set_axis_off()
    wgap, hgap = 0.04 if ncols > 1 else 0.0, 0.16 / height_in  # axes fractions: room for each row's name
    width, height = (1.0 - wgap * (ncols - 1)) / ncols, (1.0 - hgap * nrows) / nrows
    for i, ((forward, reverse), colour) in enumerate(zip(pairs, palette, strict=True)):
        r, c = i % nrows, i // nrows  # down the first column, then the next
        row = ax.inset_axes([c * (width + wgap), 1.0 - (r + 1) * (height + hgap), width, height])
        for name, style in ((forward, "-"), (reverse, WAY_BACK)):
            if name is not None:
                wp = tracks_m[name]
                row.plot(along_track_m(wp), wp[:, 2], color=colour, lw=1.6 if style == "-" else 1.3, ls=style,
                         label=name)
        for level in (low, high):
            if z_lo < level < z_hi:
                row.axhline(level, color=BAND_GREEN, lw=0.9, ls="--")
        row.set_xlim(0.0, d_max)
        row.set_ylim(z_lo, z_hi)
        row.set_yticks(ticks)
        row.grid(axis="y", color="0.88", lw=0.6)
        row.tick_params(labelsize=6, length=2, pad=1, labelbottom=r == nrows - 1 or i == n - 1)
        text = (f"{i + 1}: " if keyed else "") + f"{forward} (solid)" + (f", {reverse} (dashed)" if reverse else "")
        row.set_title(text, fontsize=6.5, loc="left", y=1.0, pad=1.5, color=tuple(0.75 * np.asarray(colors.to_rgb(colour))),
                      fontweight="bold")
        if r == nrows - 1 or i == n - 1:
            row.set_xlabel("horizontal distance flown (m)", fontsize=7, labelpad=1)
    ax.text(-0.055 if ncols == 1 else -0.07, 0.5, "altitude z (m)", transform=ax.transAxes, rotation=90,
            ha="center", va="center", fontsize=8)
    shown = z_lo < low < z_hi or z_lo < high < z_hi
    panel_title(ax, f"(b) altitude profile of every track, one row per route; band {low:g}–{high:g} m (Eq. 14)"
                    + (" dashed green" if shown else ""))
