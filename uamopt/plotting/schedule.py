"""Figures of the scheduling stage (Sec. 4.3): a Gantt chart of one schedule and the delay per
flight of several solvers side by side (the analogue of Fig. 19).

Each figure draws its bars with one call per kind (operated, cancelled), not one per flight.
"""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from uamopt.plotting.layout import single_axes

DELAY_RED = "crimson"


def _route_key(route: str) -> str:
    """A route and its way back share a colour: the sorted end points of ``"A-B"``."""
    return "-".join(sorted(route.split("-")))


def objective_text(problem) -> str:
    """The objective a schedule was optimised for, as the scheduling figures' titles name it
    (``problem.objective_kind``)."""
    if problem.objective_kind == "lexicographic":
        return "objective lexicographic: most flights, then least delay"
    if problem.objective_kind == "weighted":
        return "objective Eq. 20 weighted"
    return f"objective {problem.objective_kind}"


def gantt(problem, schedule, ax=None, *, title: str = "") -> Figure:
    """One row per aircraft: each operated flight from departure to arrival (colour: route), its
    delay d_f as a red line from the planned departure D_f, cancelled flights as hatched outlines
    at their planned slot (Eqs. 24–26: dep_f = D_f + d_f).

    Parameters
    ----------
    problem : SchedulingProblem
    schedule : Schedule
        A schedule of ``problem`` (any solver's).
    ax : None, Figure or Axes
        None: a new figure 14 in wide, 0.32 in per aircraft; a Figure: one Axes filling it.
    title : str
        Replaces the leading part of the title (solver, operated, cancelled, total delay); the
        objective (:func:`objective_text`) always follows it.

    Returns
    -------
    matplotlib.figure.Figure
        Operated flights are the patches of ``ax.containers[0]``, cancelled ones of
        ``ax.containers[1]``.
    """
    flights = problem.flights.flights
    aircraft = sorted({f.aircraft for f in flights}, key=lambda a: (len(a), a))
    row = {a: i for i, a in enumerate(aircraft)}
    keys = [_route_key(f.route) for f in flights]
    base = sorted(set(keys))
    cmap = matplotlib.colormaps["tab10"]
    colour = {r: cmap(i % 10) for i, r in enumerate(base)}
    planned = np.asarray(problem.planned_departure_s, dtype=float)
    duration = np.asarray(problem.flight_time_s, dtype=float)
    delay = np.asarray(schedule.delay_s, dtype=float)
    on = np.asarray(schedule.operated, dtype=bool)
    y = np.array([row[f.aircraft] for f in flights], dtype=float)
    default = (f"{schedule.solver}: {schedule.operated_count} operated, {schedule.cancelled_count} cancelled, "
               f"total delay {schedule.total_delay_s:.0f} s")
    fig, ax, _ = single_axes(ax, (14.0, max(4.0, 0.32 * len(aircraft) + 1.5)))
    ax.barh(y[on], duration[on], left=(planned + delay)[on], height=0.6,
            color=[colour[k] for k, o in zip(keys, on, strict=True) if o], edgecolor="black", linewidth=0.3)
    ax.barh(y[~on], duration[~on], left=planned[~on], height=0.6, fill=False, hatch="///", edgecolor="grey",
            linewidth=0.6)
    late = on & (delay > 0)
    ax.add_collection(LineCollection(np.stack([np.column_stack([planned[late], y[late]]),
                                               np.column_stack([planned[late] + delay[late], y[late]])], axis=1),
                                     colors=DELAY_RED, linewidths=1.4))
    ax.set_yticks(range(len(aircraft)), aircraft)
    ax.invert_yaxis()
    ax.set_xlabel("time (s)")
    ax.set_ylabel("aircraft")
    handles = [Patch(color=colour[r], label=r) for r in base]
    handles += [Patch(fill=False, hatch="///", edgecolor="grey", label="cancelled (planned slot)"),
                Patch(color=DELAY_RED, label="delay")]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
    ax.set_title(f"{title or default} — {objective_text(problem)}", y=1.0)
    return fig


def delays(problem, schedules: Mapping, ax=None, *, title: str = "") -> Figure:
    """Fig. 19 analogue: the delay d_f of every flight delayed or cancelled by any solver, side by
    side, one colour per solver; a cancelled flight is a hollow bar at its delay bound Δd.

    Parameters
    ----------
    problem : SchedulingProblem
    schedules : mapping of str to Schedule
        Solver name to its schedule of ``problem``, in legend order.
    ax : None, Figure or Axes
        None: a new 14 × 5.5 in figure; a Figure: one Axes filling it.
    title : str
        Replaces the leading part of the title ("delay per flight, by solver"); the objective
        (:func:`objective_text`: "Eq. 20 weighted" or "lexicographic: most flights, then least
        delay") always follows it, so that the figures of the two objectives are told apart.

    Returns
    -------
    matplotlib.figure.Figure
        ``ax.containers`` holds two bar containers per solver (operated, cancelled).
    """
    ids = [f.id for f in problem.flights.flights]
    touched = np.zeros(problem.n_flights, dtype=bool)
    for s in schedules.values():
        touched |= (s.delay_s > 0) | ~s.operated
    idx = np.flatnonzero(touched)
    fig, ax, _ = single_axes(ax, (14.0, 5.5))
    width = 0.8 / max(len(schedules), 1)
    cmap = matplotlib.colormaps["tab10"]
    for n, (name, s) in enumerate(schedules.items()):
        x = np.arange(len(idx)) + (n - (len(schedules) - 1) / 2) * width
        on = s.operated[idx]
        ax.bar(x[on], s.delay_s[idx][on], width=width, color=cmap(n),
               label=f"{name}: total {s.total_delay_s:.0f} s, {s.cancelled_count} cancelled")
        ax.bar(x[~on], problem.delay_upper_s[idx][~on], width=width, fill=False, edgecolor=cmap(n), hatch="..")
    ax.set_xticks(np.arange(len(idx)), [ids[i] for i in idx], rotation=90, fontsize=6)
    ax.set_ylabel("delay d (s); hollow: cancelled (drawn at Δd)")
    ax.set_title(f"{title or 'delay per flight, by solver (Fig. 19 analogue)'} — {objective_text(problem)}", y=1.0)
    ax.legend(fontsize=8)
    return fig
