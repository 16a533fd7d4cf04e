"""Figures of one planned track (Sec. 6.2, Fig. 18) and of the risk–transport trade-off of its
origin–destination pair (Sec. 6.3.2, Fig. 21).

:func:`tracks` draws the page ``uamopt plan`` saves as ``tracks.png``:

(a) map of log10 R (Eq. 8) on the cruise layer (blue below R_0, yellow-red above, buildings dark
    grey, no-fly hatched red) with the four stages of Table 2 in the paper's colours: shortest
    red, initial orange, equivalent gold, optimal green;
(b) a zoom on the largest detour of the initial track from the shortest one, over the layer the
    initial track flies there, with the footprint of the initial track's cells (the corridor of
    the equivalent track) and the clearance margin of Eq. 15 dotted;
(c) the vertical profile: altitude against horizontal distance flown, with the band of Eq. 14
    and the cell layers.

:func:`pareto` draws Fig. 21: the Pareto front of weighted initial tracks.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib import patheffects
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle
from matplotlib.ticker import MaxNLocator

from uamopt.plotting.draw import (
    draw_risk_layer,
    map_axes,
    mark_threshold,
    outline,
    panel_letter,
    panel_title,
    risk_cmap,
    risk_norm,
    runs,
)
from uamopt.plotting.geometry import (
    along_track_m,
    corridor_columns,
    detour_window,
    layer_of,
    point_at,
    unsafe_spans,
    window_slices,
)
from uamopt.plotting.layout import colorbar_axes, finish, inch_grid, is_tall, panels, single_axes
from uamopt.plotting.style import BAND_GREEN, BAND_TEXT, HALO, LEGEND_BELOW, NO_FLY, OBSTACLE_GREY

DARK_EDGE = [patheffects.withStroke(linewidth=3.4, foreground="#5c4400")]
WHITE_EDGE = [patheffects.withStroke(linewidth=3.3, foreground="white")]
# stage: (label, colour, line width, z-order, extra line keywords); the paper's Fig. 18 colours
STAGE_STYLE = {
    "shortest": ("shortest (A*, Eq. 12)", "#d62728", 1.5, 8, {"path_effects": WHITE_EDGE}),
    "initial": ("initial (A*, Eq. 10 + buffer)", "#ff7f0e", 5.0, 5, {"solid_capstyle": "round"}),
    "equivalent": ("equivalent (corridor)", "#f2c200", 2.0, 6, {"path_effects": DARK_EDGE}),
    "optimal": ("optimal (smoothed)", "#138a2e", 1.1, 7, {}),
}
STAGES = tuple(STAGE_STYLE)  # Table 2 order, as uamopt.planning.tracks.STAGES (not imported: it loads cvxpy)


def _draw_stage(ax, name: str, xy: np.ndarray, label: str | None = None, lw: float | None = None) -> None:
    _, colour, width, z, extra = STAGE_STYLE[name]
    ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=lw or width, zorder=z, label=label, **extra)


def _draw_endpoints(ax, origin, destination) -> None:
    ax.scatter([origin[0]], [origin[1]], marker="o", s=55, c="white", edgecolors="black", linewidths=1.4, zorder=10)
    ax.scatter([destination[0]], [destination[1]], marker="*", s=150, c="white", edgecolors="black",
               linewidths=1.1, zorder=10)


def _stage_label(plan, name: str) -> str:
    st = plan.stages[name]
    return (f"{STAGE_STYLE[name][0]}: C_T ¥{st.transport_cost:.2f}, C_R {st.risk_cost:.4g}, "
            f"{st.n_waypoints} wp, {st.length_m / 1000:.2f} km")


def _draw_margin(ax, model, k: int, window) -> None:
    """Free cells of layer k closer than s_min to a building (Eq. 15): dotted, not flyable."""
    field = model.field
    si, sj = window_slices(field, window)
    g = field.grid
    margin = ~model.admissible[si, sj, k] & ~field.obstacle[si, sj, k] & ~field.city.no_fly[si, sj]
    if not margin.any():
        return
    xe, ye = g.edges(0)[si.start:si.stop + 1], g.edges(1)[sj.start:sj.stop + 1]
    ax.add_collection(PolyCollection(runs(margin, xe, ye), facecolors="none", edgecolors="0.15",
                                     linewidths=0.0, hatch="....", zorder=3), autolim=False)


# --- the tracks page --------------------------------------------------------------------------


def _panel_map(ax, model, plan, norm, cmap, window, letter="(a)"):
    field = model.field
    k = layer_of(field, plan.origin[2])
    image = draw_risk_layer(ax, field, k, norm, cmap)
    for name in STAGES:
        _draw_stage(ax, name, plan.stages[name].waypoints, _stage_label(plan, name))
    _draw_endpoints(ax, plan.origin, plan.destination)
    map_axes(ax, field)
    if window is not None:
        x0, x1, y0, y1 = window[:4]
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ec="black", lw=1.2, ls="--", zorder=9))
        ax.annotate("(b)", (x0, y1), xytext=(2, 2), textcoords="offset points", fontsize=8, fontweight="bold",
                    path_effects=HALO, zorder=9)
    z0, z1 = k * field.grid.cell[2], (k + 1) * field.grid.cell[2]
    panel_title(ax, f"{letter} tracks over R (Eq. 8), layer k={k}: z = {z0:g}–{z1:g} m")
    mark_threshold(ax.figure.colorbar(image, cax=colorbar_axes(ax)), field)


def _panel_zoom(ax, model, plan, norm, cmap, window):
    field = model.field
    x0, x1, y0, y1, k = window
    draw_risk_layer(ax, field, k, norm, cmap, window)
    _draw_margin(ax, model, k, window)
    si, sj = window_slices(field, window)
    corridor = corridor_columns(field, plan.stages["initial"].waypoints)[si, sj]
    g = field.grid
    xe, ye = g.edges(0)[si.start:si.stop + 1], g.edges(1)[sj.start:sj.stop + 1]
    ax.add_collection(PolyCollection(runs(corridor, xe, ye), facecolors=STAGE_STYLE["initial"][1], alpha=0.45,
                                     edgecolors="none", zorder=4), autolim=False)
    ax.add_collection(LineCollection(outline(corridor, xe, ye), colors="#8a4a00", linewidths=0.8, zorder=4),
                      autolim=False)
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
    panel_title(ax, f"(b) where the largest detour starts, layer k={k}: z = {z0:g}–{z1:g} m\n"
                    "orange: the initial track's columns; gold dots: equivalent waypoints", fontsize=8.5)


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
    idx = np.clip(np.floor(point_at(opt, s) / np.asarray(g.cell[:2])).astype(int), 0, np.asarray(g.shape[:2]) - 1)
    ax.fill_between(s, 0.0, field.city.surface_height[idx[:, 0], idx[:, 1]], color="0.55", lw=0, zorder=1,
                    label="surface under the optimal track")
    for name in STAGES:
        wp = plan.stages[name].waypoints
        _, colour, lw, z, extra = STAGE_STYLE[name]
        ax.plot(along_track_m(wp), wp[:, 2], color=colour, lw=lw, zorder=z, **extra)
    for level, text, va, dy in ((low, "band low", "bottom", 2), (high, "band high", "top", -2)):
        ax.axhline(level, color=BAND_GREEN, lw=1.2, ls="--", zorder=2)
        ax.annotate(f"{text} {level:g} m (Eq. 14)", (1.0, level), xycoords=("axes fraction", "data"),
                    xytext=(-3, dy), textcoords="offset points", ha="right", va=va, fontsize=7, color=BAND_TEXT,
                    path_effects=HALO)
    top = min(max(max(float(plan.stages[n].waypoints[:, 2].max()) for n in STAGES), high) + 2 * g.cell[2],
              g.extent[2])
    # a strip below the ground: one row per stage, filled where it flies through unsafe cells
    row = 0.045 * top
    for r, name in enumerate(STAGES):
        spans = unsafe_spans(model, plan.stages[name].waypoints)
        ax.hlines(np.full(len(spans), -(r + 1.0) * row), spans[:, 0], spans[:, 1], colors=STAGE_STYLE[name][1],
                  lw=3.2, zorder=3)
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
    panel_title(ax, f"(c) vertical profile; grey lines: cell layers ({g.cell[2]:g} m); strips below 0: "
                    "where each stage flies through unsafe cells (Eq. 9)")


def _tracks_layout(field):
    def tall(page):  # map on the left, zoom and profile on the right
        left = inch_grid(page, 1, 1, left=0.75, right=10.25, top=0.65, bottom=2.35)
        right = inch_grid(page, 2, 1, left=5.0, right=0.25, top=0.8, bottom=0.5, hgap=0.75, height_ratios=[1.2, 1.0])
        return [page.add_subplot(left[0]), page.add_subplot(right[0]), page.add_subplot(right[1])]

    def wide(page):  # map and zoom on top, profile below
        top = inch_grid(page, 1, 2, left=0.75, right=0.3, top=0.8, bottom=4.25, wgap=1.6)
        bottom = inch_grid(page, 1, 1, left=0.75, right=0.3, top=5.4, bottom=0.5)
        return [page.add_subplot(top[0]), page.add_subplot(top[1]), page.add_subplot(bottom[0])]

    return tall if is_tall(field) else wide


def tracks(plan, model, ax=None, *, title: str = "") -> Figure:
    """Draw the four stages of a track plan (Fig. 18, Table 2); return the Figure.

    Parameters
    ----------
    plan : TrackPlan
        From :func:`uamopt.planning.plan_track`; all four stages are drawn.
    model : PlanningModel
        The model the plan was made on (its risk field, admissible cells and band).
    ax : None, Figure, Axes or sequence of 3 Axes
        None: a new 14 × 8 in page with panels (a)–(c) (module docstring). A Figure or
        SubFigure: that page laid out in it. One Axes: map (a) only. Three Axes: (a)–(c).
    title : str
        Leading text of the page title (e.g. the scenario name).

    Examples
    --------
    >>> plan = plan_track(model, (300, 300, 120), (2220, 4220, 120))  # doctest: +SKIP
    >>> save(tracks(plan, model, title="paper_case"), "tracks.png")  # doctest: +SKIP
    """
    field = model.field
    g = field.grid
    norm, cmap = risk_norm(field), risk_cmap()
    fig, axes, page = panels(ax, 3, _tracks_layout(field))
    tall = is_tall(field)
    window = None if len(axes) == 1 else detour_window(plan, field, aspect=2.4 if tall else max(g.extent[0] / g.extent[1], 1.0))
    _panel_map(axes[0], model, plan, norm, cmap, window, "(a)" if window is not None else panel_letter(axes[0]))
    if window is not None:
        _panel_zoom(axes[1], model, plan, norm, cmap, window)
        _panel_profile(axes[2], model, plan)
    handles, _ = axes[0].get_legend_handles_labels()
    handles += [Line2D([], [], ls="", marker="o", mfc="white", mec="black", label="origin"),
                Line2D([], [], ls="", marker="*", ms=10, mfc="white", mec="black", label="destination"),
                Patch(facecolor=OBSTACLE_GREY, label="building (obstacle)"),
                Patch(facecolor="none", edgecolor=NO_FLY, hatch="////", label="no-fly")]
    if window is not None:
        handles.append(Patch(facecolor="none", edgecolor="0.15", hatch="....", lw=0,
                             label="clearance margin (Eq. 15), in (b)"))
    axes[0].legend(handles=handles, **{**LEGEND_BELOW, "ncol": 1 if tall else 2, "fontsize": 7.5})
    o, dst = plan.origin, plan.destination
    w4, w5 = model.scenario.tracks.weights
    finish(page, axes, field,
           f"{title + ' — ' if title else ''}tracks from ({o[0]:g}, {o[1]:g}, {o[2]:g}) to "
           f"({dst[0]:g}, {dst[1]:g}, {dst[2]:g}) m; cells {g.cell[0]:g} × {g.cell[1]:g} × {g.cell[2]:g} m; "
           f"ω4 = {w4:g}, ω5 = {w5:g}, μ = {model.scenario.tracks.buffer_penalty:g}, "
           f"s_min = {model.scenario.tracks.clearance_m:g} m")
    return fig


# --- the Pareto front -------------------------------------------------------------------------

SERIES_STYLE = (("#1f4e9c", "o"), ("#7b3294", "s"), ("#1b7837", "^"), ("#8c510a", "D"))  # colour, marker
FOCUS_SHARE = 0.2  # a group of points narrower than this share of the axis range gets the axis to itself
TINY_WEIGHT = 1e-6  # weights below this are the sweep's tie-break ε, not a weighting


def focus_range(values) -> tuple[float, float] | None:
    """(lo, hi) of the main group of ``values`` when the rest lie so far off that the group
    would fill less than a fifth of an axis spanning them all (Fig. 21's ω4 = 1 track at ¥124
    against eight tracks at ¥29–31); None when one axis shows them all well. The main group is
    the larger side of the widest gap between sorted values (the lower side on a tie).

    >>> focus_range([29.3, 29.4, 30.2, 30.9, 123.6])
    (29.3, 30.9)
    >>> focus_range([1.0, 2.0, 3.0]) is None
    True
    """
    v = np.sort(np.asarray([x for x in values if np.isfinite(x)], dtype=float))
    if v.size < 2 or v[-1] == v[0]:
        return None
    i = int(np.argmax(np.diff(v)))
    low, high = v[:i + 1], v[i + 1:]
    main = low if low.size >= high.size else high
    if main[-1] - main[0] >= FOCUS_SHARE * (v[-1] - v[0]):
        return None
    return float(main[0]), float(main[-1])


def _weights_text(p) -> str:
    """The point's risk weight ω4 / (ω4 + ω5) (a weighted sum is unchanged by scaling both);
    ε when it is the sweep's tie-break (below 10⁻⁶)."""
    w = p.w4 / (p.w4 + p.w5)
    return "ω4 = ε" if w < TINY_WEIGHT else f"ω4 = {w:.2g}"


BREAK_AT = 0.83  # axes fraction where the main part of a broken x axis ends
OUTLIERS_FROM = 0.86  # and where the part beyond the break starts


def _break_marks(ax) -> None:
    """Short diagonal strokes on the top and bottom edges at both sides of the cut."""
    for x in (BREAK_AT, OUTLIERS_FROM):
        for y in (0.0, 1.0):
            ax.plot([x - 0.006, x + 0.006], [y - 0.015, y + 0.015], transform=ax.transAxes, color="black", lw=1.0,
                    clip_on=False, zorder=11)


def pareto(points, ax=None, *, plan=None, title: str = "") -> Figure:
    """Draw the trade-off of Fig. 21 (8 × 5.5 in when ``ax`` is None); return the Figure.

    ``points`` (ParetoPoint) may hold a whole :func:`uamopt.planning.pareto.weight_sweep`: the
    non-dominated ones form the front (line and markers, each labelled with its risk weight
    ω4 / (ω4 + ω5), ε for the sweep's tie-break), the others are greyed. A mapping of series
    name to such points draws several sweeps, one colour and marker each, with a legend, e.g.
    the two that the report tables::

        pareto({"Eq. 10 (μ = 0)": weight_sweep(model, a, b, buffer=False),
                "Eq. 10 + μ·R(t)": weight_sweep(model, a, b)})

    When a few points lie so far off that the others would crowd into less than a fifth of the
    transport-cost axis (the ω4 = 1 track at ¥124 against eight at ¥29–31, see
    :func:`focus_range`), the axis is broken: the Axes shows the main group, and a narrow
    panel at its right (an inset, ``ax.child_axes[0]``, sharing the risk axis) the points
    beyond the cut on their own scale, with break marks between. With ``plan``, its four stages
    (Table 2) are marked in the colours of Fig. 18 for comparison. ``ax``: None, a Figure or
    one Axes.

    Raises
    ------
    ValueError
        ``points`` is empty (or a series of the mapping is).
    """
    from uamopt.planning.pareto import (
        non_dominated,  # the planning stage, loaded when a front is drawn
    )

    series = dict(points) if isinstance(points, Mapping) else {"": list(points)}
    if not series or any(not list(v) for v in series.values()):
        raise ValueError("points must hold at least one ParetoPoint (in every series)")
    several = len(series) > 1
    fig, ax, _ = single_axes(ax, (8.0, 5.5))
    stages = [(name, marker, plan.stages[name]) for name, marker in zip(STAGES, "sDPo", strict=True)] if plan is not None else []
    every = [p for pts in series.values() for p in pts]
    costs = [p.transport_cost for p in every] + [st.transport_cost for _, _, st in stages]
    focus = focus_range(costs)
    fronts = {name: non_dominated(list(pts)) for name, pts in series.items()}

    def draw(target, lo: float, hi: float, above: bool) -> None:
        """Every series and stage into ``target``; weight labels for the points in [lo, hi],
        beside them or (``above``, in the narrow panel beyond a cut) above them."""
        middle = 0.5 * (lo + hi)
        labelled: dict = {}  # (C_T, C_R) → labels already there: the same track of another series
        for n, (name, pts) in enumerate(series.items()):
            colour, marker = SERIES_STYLE[n % len(SERIES_STYLE)]
            front = fronts[name]
            on_front = {id(p) for p in front}
            rest = [p for p in pts if id(p) not in on_front]
            if rest:
                target.scatter([p.transport_cost for p in rest], [p.risk_cost for p in rest], s=28, marker=marker,
                               c="0.75" if not several else "none", edgecolors="0.45" if not several else colour,
                               linewidths=0.6, zorder=3, label=f"dominated ({name})" if several else "dominated")
            target.plot([p.transport_cost for p in front], [p.risk_cost for p in front], color=colour, lw=1.4,
                        marker=marker, ms=6, mfc="white", mew=1.4, zorder=4,
                        label=f"{name + ': ' if several else ''}Pareto front ({len(front)} "
                              f"track{'s' if len(front) > 1 else ''})")
            for p in front:  # labels point inwards, away from the axes' edges
                if not lo <= p.transport_cost <= hi:
                    continue
                left = p.transport_cost > middle
                key = (round(p.transport_cost, 6), round(p.risk_cost, 6))
                shift = 7.5 * labelled.get(key, 0)  # a second series' label beside the first, not on it
                labelled[key] = labelled.get(key, 0) + 1
                place = ({"xytext": (shift, 7), "ha": "center", "va": "bottom", "rotation": 90} if above else
                         {"xytext": (-8 if left else 8, -shift), "ha": "right" if left else "left", "va": "center"})
                target.annotate(_weights_text(p), (p.transport_cost, p.risk_cost), textcoords="offset points",
                                fontsize=6.5, color=colour, zorder=6, **place)
        for name, marker, st in stages:
            target.scatter([st.transport_cost], [st.risk_cost], marker=marker, s=55, c=STAGE_STYLE[name][1],
                           edgecolors="black", linewidths=0.7, zorder=5, label=f"{name} track (Table 2)")

    lo, hi = focus if focus is not None else (min(costs), max(costs))
    pad = 0.08 * (hi - lo) if hi > lo else max(0.02 * abs(hi), 1e-9)
    draw(ax, lo, hi, False)
    ax.margins(y=0.08)
    ax.autoscale_view()
    if focus is None:
        ax.set_xlim(lo - pad, hi + pad)
        legend_anchor = {}
    else:
        # the main group on the left BREAK_AT of the axes; beyond the cut, an inset on its own scale
        x0, x1 = lo - pad, hi + pad
        ax.set_xlim(x0, x0 + (x1 - x0) / BREAK_AT)
        ax.set_xticks([t for t in MaxNLocator(6).tick_values(x0, x1) if x0 <= t <= x1])
        for side in ("top", "bottom"):
            ax.spines[side].set_bounds(x0, x1)
        ax.spines["right"].set_visible(False)
        far = [c for c in costs if c > x1 or c < x0]
        f0, f1 = min(far), max(far)
        fpad = 0.15 * (f1 - f0) if f1 > f0 else max(0.03 * abs(f1), 1e-9)
        beyond = ax.inset_axes([OUTLIERS_FROM, 0.0, 1.0 - OUTLIERS_FROM, 1.0], sharey=ax, zorder=9)
        draw(beyond, f0 - fpad, f1 + fpad, True)
        beyond.set_xlim(f0 - fpad, f1 + fpad)
        beyond.xaxis.set_major_locator(MaxNLocator(2))
        beyond.spines["left"].set_visible(False)
        beyond.tick_params(labelsize=8, left=False, labelleft=False)
        beyond.grid(color="0.9", lw=0.6)
        _break_marks(ax)
        legend_anchor = {"bbox_to_anchor": (BREAK_AT - 0.01, 1.0)}
    ax.set_xlabel("transport cost C_T (¥, Eq. 12)" + ("; the axis is cut (//)" if focus is not None else ""),
                  fontsize=9)
    ax.set_ylabel("operational risk cost C_R (Eq. 11)", fontsize=9)
    ax.tick_params(labelsize=8)
    ax.grid(color="0.9", lw=0.6)
    ax.legend(fontsize=7.5, loc="upper right", framealpha=0.9, **legend_anchor).set_zorder(12)
    ax.set_title(f"{title + ' — ' if title else ''}operational risk against transport cost (Fig. 21)",
                 fontsize=10, y=1.0)
    return fig
