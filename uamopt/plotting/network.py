"""Figure of the route network (Sec. 4.1.2): every route and direction over the cruise layer,
and their altitude profiles.

One colour per route, arrow heads for the direction of flight, the two directions of a route
told apart by line style; the layering of Sec. 4.1.2 puts them on different cruise layers.
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

from uamopt.plotting.geometry import (
    along_track_m,
    cruise_altitude_m,
    pair_directions,
    point_at,
    route_waypoints,
)
from uamopt.plotting.style import (
    BAND_GREEN,
    BAND_TEXT,
    HALO,
    LEGEND_BELOW,
    NO_FLY,
    cell_image,
    draw_vertiports,
    finish,
    inch_grid,
    is_tall,
    layer_of,
    map_axes,
    no_fly_hatching,
    panel_title,
    panels,
    vertiport_points,
)

SAFE_PALE = "#f7f7f5"  # free cells with R ≤ R_0
UNSAFE_PALE = "#e3d3c3"  # free cells with R > R_0


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


def network(model, routes, ax=None, *, vertiports: Iterable = (), title: str = "") -> Figure:
    """Draw a route network; return the Figure.

    (a) map over the cruise layer (pale: safe, tan: unsafe (Eq. 9), grey: buildings, red
    hatching: no-fly), one colour per route, arrow heads for the direction of flight, the two
    directions of a route solid and dashed; (b) altitude against horizontal distance flown for
    every track: the layering of Sec. 4.1.2 shows as two cruise levels per route.

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
        Axes: the map (a) only; two Axes: (a) and (b).
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
    palette = matplotlib.colormaps["tab10" if len(pairs) <= 10 else "tab20"].colors
    fig, axes, page = panels(ax, 2, _network_layout(field))
    ax_map, ax_prof = axes[0], (axes[1] if len(axes) > 1 else None)
    _muted_layer(ax_map, field, k)
    map_axes(ax_map, field)
    handles = []
    for n, (forward, reverse) in enumerate(pairs):
        colour = palette[n % len(palette)]
        # the way back: a darker dashed line over the way out, so both show where they overlap
        dark = tuple(0.6 * np.asarray(colors.to_rgb(colour)))
        for name, style, c, lw in ((forward, "-", colour, 2.6), (reverse, (0, (3, 1.8)), dark, 1.3)):
            if name is None:
                continue
            wp = tracks_m[name]
            halo = [patheffects.withStroke(linewidth=lw + 1.8, foreground="white")] if style == "-" else []
            ax_map.plot(wp[:, 0], wp[:, 1], color=c, lw=lw, ls=style, zorder=6 if style == "-" else 7,
                        solid_capstyle="round", path_effects=halo)
            _draw_direction_arrows(ax_map, wp, c)
            if ax_prof is not None:
                ax_prof.plot(along_track_m(wp), wp[:, 2], color=c, lw=1.6 if style == "-" else 1.3, ls=style)
        text = f"{forward} ({cruise_altitude_m(tracks_m[forward]):.0f} m)"
        if reverse is not None:
            text += f" / {reverse} ({cruise_altitude_m(tracks_m[reverse]):.0f} m, dashed)"
        handles.append(Line2D([], [], color=colour, lw=2.4, label=text))
    draw_vertiports(ax_map, vertiport_points(vertiports))
    z0, z1 = k * g.cell[2], (k + 1) * g.cell[2]
    panel_title(ax_map, f"(a) routes over layer k={k}: z = {z0:g}–{z1:g} m")
    ax_map.legend(handles=[Patch(facecolor=SAFE_PALE, edgecolor="0.6", label="R ≤ R₀"),
                           Patch(facecolor=UNSAFE_PALE, label="R > R₀ (Eq. 9)"),
                           Patch(facecolor="#9a9a9a", label="building"),
                           Patch(facecolor="none", edgecolor=NO_FLY, hatch="////", label="no-fly")],
                  **{**LEGEND_BELOW, "ncol": 4})
    if ax_prof is not None:
        _network_profiles(ax_prof, field, handles)
    finish(page, axes, field, f"{title + ' — ' if title else ''}route network: {len(tracks_m)} tracks on "
                              f"{len(pairs)} routes; cells {g.cell[0]:g} × {g.cell[1]:g} × {g.cell[2]:g} m")
    return fig


def _network_profiles(ax, field, handles) -> None:
    g = field.grid
    low, high = field.band
    for level in (low, high):
        ax.axhline(level, color=BAND_GREEN, lw=1.2, ls="--")
    ax.annotate(f"band {low:g}–{high:g} m (Eq. 14)", (1.0, high), xycoords=("axes fraction", "data"),
                xytext=(-3, -2), textcoords="offset points", ha="right", va="top", fontsize=7, color=BAND_TEXT,
                path_effects=HALO)
    ax.set_ylim(0.0, min(high + 2 * g.cell[2], g.extent[2]))
    ax.set_xlim(0.0, None)
    ax.set_xlabel("horizontal distance flown (m)", fontsize=8)
    ax.set_ylabel("altitude z (m)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.legend(handles=handles, fontsize=7, loc="lower center", ncol=2, framealpha=0.9,
              title="route: direction (cruise altitude)", title_fontsize=7)
    panel_title(ax, "(b) vertical profiles: solid and dashed are the two directions of a route")
