"""Figures of planned tracks (Sec. 6.2, Fig. 18) and of the route network over the risk field.

:func:`plot_tracks` draws the page ``uamopt tracks`` writes as ``tracks.png``:

(a) map of log10 R (Eq. 8) on the cruise layer (colours of :mod:`uamopt.plots`: blue below R_0,
    yellow-red above, buildings dark grey, no-fly hatched red) with the four stages of Table 2 in
    the paper's colours: shortest red, initial orange, equivalent gold, optimal green;
(b) a zoom on the largest detour of the initial track from the shortest one, over the layer the
    initial track flies there, with the footprint of the initial track's cells (the corridor of
    the equivalent track) and the clearance margin of Eq. 15 dotted;
(c) the vertical profile: altitude against horizontal distance flown, with the band of Eq. 14
    and the cell layers.

:func:`plot_network` draws the route network: one colour per route, arrows for the direction of
flight, the two directions told apart by line style, and their altitude profiles (the layering
of Sec. 4.1.2 puts them on different cruise layers).

Like :mod:`uamopt.plots`, figures are :class:`matplotlib.figure.Figure` objects rendered by Agg
(no pyplot state); arrays are drawn whole, no Python loop over cells.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib import colors, patheffects
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle
from matplotlib.ticker import MaxNLocator

from uamopt.geometry import polyline_pieces
from uamopt.planning.problem import PlanningModel
from uamopt.planning.tracks import STAGES, TrackPlan
from uamopt.plots import (
    DPI,
    FIGSIZE_IN,
    HALO,
    LEGEND_BELOW,
    NO_FLY,
    OBSTACLE_GREY,
    ROAD_OUTLINE_MAX_COLUMNS,
    _colorbar_axes,
    _draw_vertiports,
    _finish,
    _log10,
    _map_axes,
    _mark_threshold,
    _outline,
    _risk_cmap,
    _risk_norm,
    _runs,
    _vertiport_points,
)
from uamopt.risk import RiskField

BAND_GREEN = "#2ca02c"
DARK_EDGE = [patheffects.withStroke(linewidth=3.4, foreground="#5c4400")]
WHITE_EDGE = [patheffects.withStroke(linewidth=3.3, foreground="white")]
# stage: (label, colour, line width, z-order, extra line keywords); the paper's Fig. 18 colours
STAGE_STYLE = {
    "shortest": ("shortest (A*, Eq. 12)", "#d62728", 1.5, 8, {"path_effects": WHITE_EDGE}),
    "initial": ("initial (A*, Eq. 10 + buffer)", "#ff7f0e", 5.0, 5, {"solid_capstyle": "round"}),
    "equivalent": ("equivalent (corridor)", "#f2c200", 2.0, 6, {"path_effects": DARK_EDGE}),
    "optimal": ("optimal (smoothed)", "#138a2e", 1.1, 7, {}),
}
SAFE_PALE = "#f7f7f5"  # network map: free cells with R ≤ R_0
UNSAFE_PALE = "#e3d3c3"  # network map: free cells with R > R_0


# --- geometry helpers -----------------------------------------------------------------------


def along_track_m(waypoints: np.ndarray) -> np.ndarray:
    """Horizontal distance flown to each waypoint (n,), m: the profile's abscissa."""
    step = np.diff(np.asarray(waypoints, dtype=float)[:, :2], axis=0)
    return np.concatenate([[0.0], np.cumsum(np.hypot(step[:, 0], step[:, 1]))])


def _point_at(waypoints: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points (m, 2) at horizontal distances ``s`` along a track."""
    d = along_track_m(waypoints)
    return np.column_stack([np.interp(s, d, waypoints[:, 0]), np.interp(s, d, waypoints[:, 1])])


def _distance_to_polyline(points: np.ndarray, line: np.ndarray) -> np.ndarray:
    """Horizontal distance (m,) from each point (m, 2) to a polyline (n, 2); (m × n) at once."""
    a, b = line[:-1, None, :2], line[1:, None, :2]
    ab = b - a
    t = np.clip(np.einsum("sij,sij->si", points[None, :, :2] - a, ab)
                / np.maximum(np.einsum("sij,sij->si", ab, ab), 1e-12), 0.0, 1.0)
    foot = a + t[..., None] * ab
    return np.linalg.norm(points[None, :, :2] - foot, axis=2).min(axis=0)


def layer_of(field: RiskField, altitude_m: float) -> int:
    """Layer index holding ``altitude_m`` (a face goes to the upper layer), clipped to the grid."""
    g = field.grid
    return int(np.clip(math.floor(altitude_m / g.cell[2] + 1e-9), 0, g.shape[2] - 1))


def detour_window(plan: TrackPlan, field: RiskField, aspect: float = 1.0) -> tuple[float, float, float, float, int]:
    """(x0, x1, y0, y1, k): a window of width/height ``aspect``, 16–30 cells high, on the fork
    where the initial track leaves the shortest one for its largest detour, and the layer the
    initial track flies at the fork.

    The window is shifted towards the detour so that both the fork and the first part of the
    detour are in view; without a detour (tracks within two cells) it shows the largest gap.
    """
    g = field.grid
    initial, shortest = plan.stages["initial"].waypoints, plan.stages["shortest"].waypoints
    # sample the initial track every half cell so long straight segments are seen too
    d = along_track_m(initial)
    s = np.linspace(0.0, d[-1], max(int(d[-1] / (0.5 * min(g.cell[:2]))), 2))
    pts = _point_at(initial, s)
    gap = _distance_to_polyline(pts, shortest)
    at = int(np.argmax(gap))
    near = gap <= 2.0 * max(g.cell[:2])
    fork = at - int(np.argmax(near[at::-1])) if near[:at + 1].any() else at
    side = float(np.clip(2.0 * gap[at] + 8 * g.cell[1], 16 * g.cell[1], 30 * g.cell[1]))
    ex, ey = g.extent[:2]
    w, h = min(aspect * side, ex), min(side, ey)
    toward = pts[at] - pts[fork]
    reach = float(np.hypot(*toward))
    cx, cy = pts[fork] + (toward * min(1.0, 0.35 * min(w, h) / reach) if reach > 0 else 0.0)
    x0, y0 = np.clip(cx - w / 2, 0.0, ex - w), np.clip(cy - h / 2, 0.0, ey - h)
    k = layer_of(field, float(np.interp(s[fork], d, initial[:, 2])))
    return float(x0), float(x0 + w), float(y0), float(y0 + h), k


# --- drawing helpers ------------------------------------------------------------------------


def _window_slices(field: RiskField, window) -> tuple[slice, slice]:
    g = field.grid
    if window is None:
        return slice(0, g.shape[0]), slice(0, g.shape[1])
    x0, x1, y0, y1 = window[:4]
    i0, i1 = int(max(math.floor(x0 / g.cell[0]) - 1, 0)), int(min(math.ceil(x1 / g.cell[0]) + 1, g.shape[0]))
    j0, j1 = int(max(math.floor(y0 / g.cell[1]) - 1, 0)), int(min(math.ceil(y1 / g.cell[1]) + 1, g.shape[1]))
    return slice(i0, i1), slice(j0, j1)


def _draw_risk_layer(ax, field: RiskField, k: int, norm, cmap, window=None):
    """log10 R on layer k with no-fly hatching (and road outlines when cells are large on the
    page), restricted to ``window`` (x0, x1, y0, y1) when given. Returns the mesh."""
    g, city = field.grid, field.city
    si, sj = _window_slices(field, window)
    xe, ye = g.edges(0)[si.start:si.stop + 1], g.edges(1)[sj.start:sj.stop + 1]
    mesh = ax.pcolormesh(xe, ye, _log10(field.risk[si, sj, k]).T, cmap=cmap, norm=norm, shading="flat",
                         rasterized=True)
    if len(xe) - 1 <= ROAD_OUTLINE_MAX_COLUMNS:
        ax.add_collection(LineCollection(_outline(city.road_length[si, sj] > 0, xe, ye), colors="white",
                                         linewidths=0.35, alpha=0.6))
    no_fly = city.no_fly[si, sj]
    if no_fly.any():
        ax.add_collection(PolyCollection(_runs(no_fly, xe, ye), facecolors="none", edgecolors=NO_FLY,
                                         linewidths=0.0, hatch="////", zorder=3))
        ax.add_collection(LineCollection(_outline(no_fly, xe, ye), colors=NO_FLY, linewidths=1.2, zorder=3))
    return mesh


def _draw_margin(ax, model: PlanningModel, k: int, window) -> None:
    """Free cells of layer k closer than s_min to a building (Eq. 15): dotted, not flyable."""
    field = model.field
    si, sj = _window_slices(field, window)
    g = field.grid
    margin = ~model.admissible[si, sj, k] & ~field.obstacle[si, sj, k] & ~field.city.no_fly[si, sj]
    if not margin.any():
        return
    xe, ye = g.edges(0)[si.start:si.stop + 1], g.edges(1)[sj.start:sj.stop + 1]
    ax.add_collection(PolyCollection(_runs(margin, xe, ye), facecolors="none", edgecolors="0.15",
                                     linewidths=0.0, hatch="....", zorder=3))


def _draw_stage(ax, name: str, xy: np.ndarray, label: str | None = None, lw: float | None = None) -> None:
    _, colour, width, z, extra = STAGE_STYLE[name]
    ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=lw or width, zorder=z, label=label, **extra)


def _draw_endpoints(ax, origin, destination) -> None:
    ax.scatter([origin[0]], [origin[1]], marker="o", s=55, c="white", edgecolors="black", linewidths=1.4, zorder=10)
    ax.scatter([destination[0]], [destination[1]], marker="*", s=150, c="white", edgecolors="black",
               linewidths=1.1, zorder=10)


def _stage_label(plan: TrackPlan, name: str) -> str:
    st = plan.stages[name]
    return (f"{STAGE_STYLE[name][0]}: C_T ¥{st.transport_cost:.2f}, C_R {st.risk_cost:.4g}, "
            f"{st.n_waypoints} wp, {st.length_m / 1000:.2f} km")


def unsafe_spans(model: PlanningModel, waypoints: np.ndarray) -> np.ndarray:
    """(K, 2) horizontal-distance intervals (m) in which a track flies through unsafe cells
    (Eq. 9: R > R_0) — the pieces that the binary risk cost of Eq. 11 counts."""
    pts = np.asarray(waypoints, dtype=float)
    cells, s0, s1 = polyline_pieces(pts, model.field.grid.cell)
    cells = np.clip(cells, 0, np.asarray(model.field.grid.shape) - 1)
    unsafe = model.field.unsafe[tuple(cells.T)]
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    ground = along_track_m(pts)
    return np.column_stack([np.interp(s0[unsafe], arc, ground), np.interp(s1[unsafe], arc, ground)])


def _corridor_columns(field: RiskField, waypoints: np.ndarray) -> np.ndarray:
    """(nx, ny) bool: columns holding a cell of a cell-centre path."""
    g = field.grid
    idx = np.clip(np.floor(waypoints[:, :2] / np.asarray(g.cell[:2])).astype(int), 0, np.asarray(g.shape[:2]) - 1)
    mask = np.zeros(g.shape[:2], dtype=bool)
    mask[idx[:, 0], idx[:, 1]] = True
    return mask


# --- panels ---------------------------------------------------------------------------------


def _panel_map(fig, ax, model, plan, k, norm, cmap, window):
    field = model.field
    mesh = _draw_risk_layer(ax, field, k, norm, cmap)
    for name in STAGES:
        _draw_stage(ax, name, plan.stages[name].waypoints, _stage_label(plan, name))
    _draw_endpoints(ax, plan.origin, plan.destination)
    _map_axes(ax, field)
    x0, x1, y0, y1 = window[:4]
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ec="black", lw=1.2, ls="--", zorder=9))
    ax.annotate("(b)", (x0, y1), xytext=(2, 2), textcoords="offset points", fontsize=8, fontweight="bold",
                path_effects=HALO, zorder=9)
    z0, z1 = k * field.grid.cell[2], (k + 1) * field.grid.cell[2]
    ax.set_title(f"(a) tracks over R (Eq. 8), layer k={k}: z = {z0:g}–{z1:g} m", fontsize=9, loc="left")
    cbar = fig.colorbar(mesh, cax=_colorbar_axes(ax))
    _mark_threshold(cbar, field)
    return mesh


def _panel_zoom(ax, model, plan, norm, cmap, window):
    field = model.field
    x0, x1, y0, y1, k = window
    _draw_risk_layer(ax, field, k, norm, cmap, window)
    _draw_margin(ax, model, k, window)
    si, sj = _window_slices(field, window)
    corridor = _corridor_columns(field, plan.stages["initial"].waypoints)[si, sj]
    g = field.grid
    xe, ye = g.edges(0)[si.start:si.stop + 1], g.edges(1)[sj.start:sj.stop + 1]
    ax.add_collection(PolyCollection(_runs(corridor, xe, ye), facecolors=STAGE_STYLE["initial"][1], alpha=0.45,
                                     edgecolors="none", zorder=4))
    ax.add_collection(LineCollection(_outline(corridor, xe, ye), colors="#8a4a00", linewidths=0.8, zorder=4))
    for name in STAGES:
        _draw_stage(ax, name, plan.stages[name].waypoints, lw=1.6 if name == "initial" else None)
    eq = plan.stages["equivalent"].waypoints
    ax.scatter(eq[:, 0], eq[:, 1], s=14, c=STAGE_STYLE["equivalent"][1], edgecolors="#5c4400", linewidths=0.8,
               zorder=7)
    _draw_endpoints(ax, plan.origin, plan.destination)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.tick_params(labelsize=7)
    z0, z1 = k * g.cell[2], (k + 1) * g.cell[2]
    ax.set_title(f"(b) where the largest detour starts, layer k={k}: z = {z0:g}–{z1:g} m\n"
                 "orange: the initial track's columns; gold dots: equivalent waypoints",
                 fontsize=8.5, loc="left")


def _panel_profile(ax, model, plan):
    field = model.field
    g = field.grid
    low, high = field.band
    band = field.band_layers()
    edges = g.edges(2)
    shown = edges[(edges >= edges[band[0]] - 1e-9) & (edges <= edges[band[-1] + 1] + 1e-9)] if band.size else edges
    ax.hlines(shown, 0.0, 1.0, transform=ax.get_yaxis_transform(), colors="0.85", lw=0.6, zorder=0)
    # ground under the optimal track: its sampled surface height (why it climbs)
    opt = plan.stages["optimal"].waypoints
    d = along_track_m(opt)
    s = np.linspace(0.0, d[-1], max(int(d[-1] / (0.5 * g.cell[0])), 2))
    xy = _point_at(opt, s)
    idx = np.clip(np.floor(xy / np.asarray(g.cell[:2])).astype(int), 0, np.asarray(g.shape[:2]) - 1)
    ax.fill_between(s, 0.0, field.city.surface_height[idx[:, 0], idx[:, 1]], color="0.55", lw=0, zorder=1,
                    label="surface under the optimal track")
    for name in STAGES:
        wp = plan.stages[name].waypoints
        _, colour, lw, z, extra = STAGE_STYLE[name]
        ax.plot(along_track_m(wp), wp[:, 2], color=colour, lw=lw, zorder=z, **extra)
    for level, text, va, dy in ((low, "band low", "bottom", 2), (high, "band high", "top", -2)):
        ax.axhline(level, color=BAND_GREEN, lw=1.2, ls="--", zorder=2)
        ax.annotate(f"{text} {level:g} m (Eq. 14)", (1.0, level), xycoords=("axes fraction", "data"),
                    xytext=(-3, dy), textcoords="offset points", ha="right", va=va, fontsize=7, color="#1a6e1a",
                    path_effects=HALO)
    top = min(max(max(float(plan.stages[n].waypoints[:, 2].max()) for n in STAGES), high) + 2 * g.cell[2],
              g.extent[2])
    # a strip below the ground: one row per stage, filled where it flies through unsafe cells
    row = 0.045 * top
    for r, name in enumerate(STAGES):
        spans = unsafe_spans(model, plan.stages[name].waypoints)
        y = -(r + 1.0) * row
        ax.hlines(np.full(len(spans), y), spans[:, 0], spans[:, 1], colors=STAGE_STYLE[name][1], lw=3.2,
                  zorder=3)
    ax.axhline(0.0, color="0.3", lw=0.6)
    ticks = [t for t in MaxNLocator(7).tick_values(0.0, top) if 0.0 <= t <= top]
    ax.set_yticks(ticks + [-(r + 1.0) * row for r in range(len(STAGES))],
                  [f"{t:g}" for t in ticks] + list(STAGES))
    ax.set_ylim(-(len(STAGES) + 0.6) * row, top)
    ax.set_xlim(0.0, max(along_track_m(plan.stages[n].waypoints)[-1] for n in STAGES))
    ax.set_xlabel("horizontal distance flown (m)", fontsize=8)
    ax.set_ylabel("altitude z (m)", fontsize=8)
    ax.tick_params(labelsize=7)
    for label in ax.get_yticklabels()[-len(STAGES):]:
        label.set_fontsize(6)
    ax.legend(fontsize=7, loc="upper left", framealpha=0.85)
    ax.set_title(f"(c) vertical profile; grey lines: cell layers ({g.cell[2]:g} m); strips below 0: "
                 "where each stage flies through unsafe cells (Eq. 9)", fontsize=9, loc="left")


# --- public ---------------------------------------------------------------------------------


def plot_tracks(model: PlanningModel, plan: TrackPlan, path: str | Path, *, title: str = "") -> Path:
    """Draw the four stages of a track plan (Fig. 18, Table 2) and write a 14 × 8 in PNG at 130 dpi.

    Parameters
    ----------
    model : PlanningModel
        The model the plan was made on (its risk field, admissible cells and band).
    plan : TrackPlan
        From :func:`uamopt.planning.plan_track`; all four stages are drawn.
    path : str or Path
        PNG to write; its folder must exist.
    title : str
        Leading text of the figure title (e.g. the scenario name).

    Returns
    -------
    Path
        ``path``.

    Examples
    --------
    >>> import tempfile
    >>> from uamopt.planning import plan_track, planning_model
    >>> from uamopt.scenario import Scenario
    >>> from uamopt.stages import compute_risk
    >>> scenario = Scenario().with_overrides(["grid.cell=[100,100,60]"])
    >>> model = planning_model(scenario, compute_risk(scenario).field)
    >>> plan = plan_track(model, (300, 300, 120), (2220, 4220, 120))
    >>> png = plot_tracks(model, plan, Path(tempfile.mkdtemp()) / "tracks.png", title="Table B.3")
    >>> png.name, png.stat().st_size > 50_000
    ('tracks.png', True)
    """
    path = Path(path)
    field = model.field
    g = field.grid
    k = layer_of(field, plan.origin[2])
    norm, cmap = _risk_norm(field), _risk_cmap()
    fig = Figure(figsize=FIGSIZE_IN, dpi=DPI, layout="constrained")
    fig.get_layout_engine().set(w_pad=0.04, h_pad=0.04, wspace=0.02, hspace=0.03, rect=(0.0, 0.015, 1.0, 0.985))
    tall = g.extent[1] >= 0.8 * g.extent[0]
    if tall:  # map on the left, zoom and profile on the right
        gs = fig.add_gridspec(2, 2, width_ratios=[1.0, 1.5], height_ratios=[1.2, 1.0])
        ax_a, ax_b, ax_c = fig.add_subplot(gs[:, 0]), fig.add_subplot(gs[0, 1]), fig.add_subplot(gs[1, 1])
    else:  # wide city: map and zoom on top, profile below
        gs = fig.add_gridspec(2, 2, height_ratios=[1.5, 1.0])
        ax_a, ax_b, ax_c = fig.add_subplot(gs[0, 0]), fig.add_subplot(gs[0, 1]), fig.add_subplot(gs[1, :])
    window = detour_window(plan, field, aspect=2.4 if tall else max(g.extent[0] / g.extent[1], 1.0))
    _panel_map(fig, ax_a, model, plan, k, norm, cmap, window)
    _panel_zoom(ax_b, model, plan, norm, cmap, window)
    _panel_profile(ax_c, model, plan)
    handles, _ = ax_a.get_legend_handles_labels()
    handles += [Line2D([], [], ls="", marker="o", mfc="white", mec="black", label="origin"),
                Line2D([], [], ls="", marker="*", ms=10, mfc="white", mec="black", label="destination"),
                Patch(facecolor=OBSTACLE_GREY, label="building (obstacle)"),
                Patch(facecolor="none", edgecolor=NO_FLY, hatch="////", label="no-fly"),
                Patch(facecolor="none", edgecolor="0.15", hatch="....", lw=0,
                      label="clearance margin (Eq. 15), in (b)")]
    ax_a.legend(handles=handles, **{**LEGEND_BELOW, "ncol": 1 if tall else 2, "fontsize": 7.5})
    head = f"{title} — " if title else ""
    o, dst = plan.origin, plan.destination
    w4, w5 = model.scenario.tracks.weights
    fig.suptitle(f"{head}tracks from ({o[0]:g}, {o[1]:g}, {o[2]:g}) to ({dst[0]:g}, {dst[1]:g}, {dst[2]:g}) m; "
                 f"cells {g.cell[0]:g} × {g.cell[1]:g} × {g.cell[2]:g} m; ω4 = {w4:g}, ω5 = {w5:g}, "
                 f"μ = {model.scenario.tracks.buffer_penalty:g}, s_min = {model.scenario.tracks.clearance_m:g} m",
                 fontsize=10.5)
    return _finish(fig, field, path)


# --- the route network ----------------------------------------------------------------------


def pair_directions(tracks: Mapping[str, np.ndarray], tolerance_m: float) -> list[tuple[str, str | None]]:
    """Group tracks into routes: (forward, reverse) where one track's origin is the other's
    destination (within ``tolerance_m`` horizontally), else (track, None); in the given order."""
    ends = {n: (np.asarray(w, dtype=float)[0, :2], np.asarray(w, dtype=float)[-1, :2]) for n, w in tracks.items()}

    def close(p: np.ndarray, q: np.ndarray) -> bool:
        return float(np.hypot(*(p - q))) <= tolerance_m
    pairs, used = [], set()
    for a in tracks:
        if a in used:
            continue
        used.add(a)
        partner = next((b for b in tracks if b not in used and close(ends[b][0], ends[a][1])
                        and close(ends[b][1], ends[a][0])), None)
        if partner is not None:
            used.add(partner)
        pairs.append((a, partner))
    return pairs


def cruise_altitude_m(waypoints: np.ndarray) -> float:
    """Median altitude over the horizontal distance flown, m (the layer a track cruises on)."""
    wp = np.asarray(waypoints, dtype=float)
    d = along_track_m(wp)
    if d[-1] <= 0:
        return float(np.median(wp[:, 2]))
    return float(np.median(np.interp(np.linspace(0.0, d[-1], 512), d, wp[:, 2])))


def _draw_direction_arrows(ax, waypoints: np.ndarray, colour, fractions=(0.3, 0.62)) -> None:
    """Arrow heads along a track at the given fractions of its horizontal length."""
    d = along_track_m(waypoints)
    if d[-1] <= 0:
        return
    for f in fractions:
        a, b = _point_at(waypoints, np.array([f * d[-1], min(f * d[-1] + 0.02 * d[-1], d[-1])]))
        ax.annotate("", xy=b, xytext=a, zorder=8,
                    arrowprops={"arrowstyle": "-|>,head_length=0.7,head_width=0.35", "color": colour, "lw": 1.2,
                                "shrinkA": 0, "shrinkB": 0,
                                "path_effects": [patheffects.withStroke(linewidth=2.6, foreground="white")]})


def _muted_layer(ax, field: RiskField, k: int) -> None:
    """Layer k in three pale tones (safe, unsafe, building) so that route colours stand out."""
    g = field.grid
    kind = np.where(field.obstacle[:, :, k], 2, np.where(field.unsafe[:, :, k], 1, 0))
    ax.pcolormesh(g.edges(0), g.edges(1), kind.T, cmap=colors.ListedColormap([SAFE_PALE, UNSAFE_PALE, "#9a9a9a"]),
                  norm=colors.BoundaryNorm([-0.5, 0.5, 1.5, 2.5], 3), shading="flat", rasterized=True)
    if field.city.no_fly.any():
        xe, ye = g.edges(0), g.edges(1)
        ax.add_collection(PolyCollection(_runs(field.city.no_fly, xe, ye), facecolors="none", edgecolors=NO_FLY,
                                         linewidths=0.0, hatch="////", zorder=3))
        ax.add_collection(LineCollection(_outline(field.city.no_fly, xe, ye), colors=NO_FLY, linewidths=1.0,
                                         zorder=3))


def plot_network(model: PlanningModel, tracks: Mapping[str, np.ndarray], path: str | Path, *,
                 vertiports: Iterable = (), title: str = "") -> Path:
    """Draw a route network on one page and write it as a 14 × 8 in PNG at 130 dpi.

    (a) map over the cruise layer (pale: safe, tan: unsafe (Eq. 9), grey: buildings, red
    hatching: no-fly), one colour per route, arrow heads for the direction of flight, the two
    directions of a route solid and dashed; (b) altitude against horizontal distance flown for
    every track: the layering of Sec. 4.1.2 shows as two cruise levels per route.

    Parameters
    ----------
    model : PlanningModel
        The model the tracks were planned on.
    tracks : mapping of str to array (n, 3)
        Route name (e.g. ``"V1-V2"``) to waypoints in metres. A track and the one flying back
        between the same end points (within two cells) are drawn as one route.
    path : str or Path
        PNG to write; its folder must exist.
    vertiports : iterable
        As for :func:`uamopt.plots.plot_risk`: objects with ``name``, ``x``, ``y`` or tuples.
    title : str
        Leading text of the figure title.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    if not tracks:
        raise ValueError("tracks must name at least one route")
    field = model.field
    g = field.grid
    tracks = {name: np.asarray(w, dtype=float) for name, w in tracks.items()}
    k = layer_of(field, model.scenario.network.cruise_altitude_m)
    pairs = pair_directions(tracks, 2.0 * math.hypot(*g.cell[:2]))
    palette = matplotlib.colormaps["tab10" if len(pairs) <= 10 else "tab20"].colors
    fig = Figure(figsize=FIGSIZE_IN, dpi=DPI, layout="constrained")
    fig.get_layout_engine().set(w_pad=0.04, h_pad=0.04, wspace=0.03, rect=(0.0, 0.015, 1.0, 0.985))
    tall = g.extent[1] >= 0.8 * g.extent[0]
    gs = fig.add_gridspec(1, 2, width_ratios=[1.0, 1.5]) if tall else fig.add_gridspec(2, 1, height_ratios=[1.6, 1])
    ax_map, ax_prof = fig.add_subplot(gs[0]), fig.add_subplot(gs[1])
    _muted_layer(ax_map, field, k)
    _map_axes(ax_map, field)
    handles = []
    for n, (forward, reverse) in enumerate(pairs):
        colour = palette[n % len(palette)]
        # the way back: a darker dashed line over the way out, so both show where they overlap
        dark = tuple(0.6 * np.asarray(colors.to_rgb(colour)))
        for name, style, c, lw in ((forward, "-", colour, 2.6), (reverse, (0, (3, 1.8)), dark, 1.3)):
            if name is None:
                continue
            wp = tracks[name]
            halo = [patheffects.withStroke(linewidth=lw + 1.8, foreground="white")] if style == "-" else []
            ax_map.plot(wp[:, 0], wp[:, 1], color=c, lw=lw, ls=style, zorder=6 if style == "-" else 7,
                        solid_capstyle="round", path_effects=halo)
            _draw_direction_arrows(ax_map, wp, c)
            ax_prof.plot(along_track_m(wp), wp[:, 2], color=c, lw=1.6 if style == "-" else 1.3, ls=style)
        text = f"{forward} ({cruise_altitude_m(tracks[forward]):.0f} m)"
        if reverse is not None:
            text += f" / {reverse} ({cruise_altitude_m(tracks[reverse]):.0f} m, dashed)"
        handles.append(Line2D([], [], color=colour, lw=2.4, label=text))
    _draw_vertiports(ax_map, _vertiport_points(vertiports))
    z0, z1 = k * g.cell[2], (k + 1) * g.cell[2]
    ax_map.set_title(f"(a) routes over layer k={k}: z = {z0:g}–{z1:g} m", fontsize=9, loc="left")
    ax_map.legend(handles=[Patch(facecolor=SAFE_PALE, edgecolor="0.6", label="R ≤ R₀"),
                           Patch(facecolor=UNSAFE_PALE, label="R > R₀ (Eq. 9)"),
                           Patch(facecolor="#9a9a9a", label="building"),
                           Patch(facecolor="none", edgecolor=NO_FLY, hatch="////", label="no-fly")],
                  **{**LEGEND_BELOW, "ncol": 4})
    low, high = field.band
    for level in (low, high):
        ax_prof.axhline(level, color=BAND_GREEN, lw=1.2, ls="--")
    ax_prof.annotate(f"band {low:g}–{high:g} m (Eq. 14)", (1.0, high), xycoords=("axes fraction", "data"),
                     xytext=(-3, -2), textcoords="offset points", ha="right", va="top", fontsize=7, color="#1a6e1a",
                     path_effects=HALO)
    ax_prof.set_ylim(0.0, min(high + 2 * g.cell[2], g.extent[2]))
    ax_prof.set_xlim(0.0, None)
    ax_prof.set_xlabel("horizontal distance flown (m)", fontsize=8)
    ax_prof.set_ylabel("altitude z (m)", fontsize=8)
    ax_prof.tick_params(labelsize=7)
    ax_prof.legend(handles=handles, fontsize=7, loc="lower center", ncol=2, framealpha=0.9,
                   title="route: direction (cruise altitude)", title_fontsize=7)
    ax_prof.set_title("(b) vertical profiles: solid and dashed are the two directions of a route", fontsize=9,
                      loc="left")
    head = f"{title} — " if title else ""
    fig.suptitle(f"{head}route network: {len(tracks)} tracks on {len(pairs)} routes; cells "
                 f"{g.cell[0]:g} × {g.cell[1]:g} × {g.cell[2]:g} m", fontsize=10.5)
    return _finish(fig, field, path)
