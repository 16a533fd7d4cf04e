"""Figures of the scheduling stage: a Gantt chart of a schedule and the delay comparison of Fig. 19."""

from __future__ import annotations

from pathlib import Path
from typing import Mapping

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from uamopt.schedule import Schedule, SchedulingProblem


def plot_gantt(problem: SchedulingProblem, schedule: Schedule, path: str | Path, *, title: str = "") -> Path:
    """One row per aircraft: each operated flight from departure to arrival (colour: route), its
    delay as a thin line from the planned departure, cancelled flights as hatched outlines."""
    fs = problem.flights
    aircraft = sorted({f.aircraft for f in fs.flights}, key=lambda a: (len(a), a))
    row = {a: i for i, a in enumerate(aircraft)}
    routes = sorted({f.route.split("-")[0] + "-" + f.route.split("-")[-1] if "-" in f.route else f.route
                     for f in fs.flights})
    base = sorted({"-".join(sorted(r.split("-"))) for r in routes})
    cmap = __import__("matplotlib").colormaps["tab10"]
    colour = {r: cmap(i % 10) for i, r in enumerate(base)}
    planned = problem.planned_departure_s
    dep = planned + schedule.delay_s
    fig = Figure(figsize=(14, max(4.0, 0.32 * len(aircraft) + 1.5)), dpi=130)
    ax = fig.add_subplot(1, 1, 1)
    for i, f in enumerate(fs.flights):
        y = row[f.aircraft]
        key = "-".join(sorted(f.route.split("-")))
        if schedule.operated[i]:
            ax.barh(y, problem.flight_time_s[i], left=dep[i], height=0.6, color=colour.get(key, "grey"),
                    edgecolor="black", linewidth=0.3)
            if schedule.delay_s[i] > 0:
                ax.plot([planned[i], dep[i]], [y, y], color="crimson", linewidth=1.4)
        else:
            ax.barh(y, problem.flight_time_s[i], left=planned[i], height=0.6, fill=False, hatch="///",
                    edgecolor="grey", linewidth=0.6)
    ax.set_yticks(range(len(aircraft)), aircraft)
    ax.invert_yaxis()
    ax.set_xlabel("time (s)")
    ax.set_ylabel("aircraft")
    handles = [Patch(color=colour[r], label=r) for r in base]
    handles += [Patch(fill=False, hatch="///", edgecolor="grey", label="cancelled (planned slot)"),
                Patch(color="crimson", label="delay")]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
    ax.set_title(title or f"{schedule.solver}: {schedule.operated_count} operated, {schedule.cancelled} cancelled, "
                 f"total delay {schedule.total_delay_s:.0f} s")
    fig.tight_layout()
    fig.savefig(path)
    return Path(path)


def plot_delay_comparison(problem: SchedulingProblem, schedules: Mapping[str, Schedule], path: str | Path,
                          *, title: str = "") -> Path:
    """Fig. 19 analogue: the delay of every flight delayed or cancelled by any solver, side by side;
    a cancelled flight is drawn as a hollow bar at its delay threshold."""
    ids = [f.id for f in problem.flights.flights]
    touched = np.zeros(problem.n_flights, dtype=bool)
    for s in schedules.values():
        touched |= (s.delay_s > 0) | ~s.operated
    idx = np.flatnonzero(touched)
    fig = Figure(figsize=(14, 5.5), dpi=130)
    ax = fig.add_subplot(1, 1, 1)
    width = 0.8 / max(len(schedules), 1)
    cmap = __import__("matplotlib").colormaps["tab10"]
    for n, (name, s) in enumerate(schedules.items()):
        x = np.arange(len(idx)) + (n - (len(schedules) - 1) / 2) * width
        on = s.operated[idx]
        ax.bar(x[on], s.delay_s[idx][on], width=width, color=cmap(n),
               label=f"{name}: total {s.total_delay_s:.0f} s, {s.cancelled} cancelled")
        ax.bar(x[~on], problem.delay_upper_s[idx][~on], width=width, fill=False, edgecolor=cmap(n), hatch="..")
    ax.set_xticks(np.arange(len(idx)), [ids[i] for i in idx], rotation=90, fontsize=6)
    ax.set_ylabel("delay d (s); hollow: cancelled (drawn at Δd)")
    ax.set_title(title or "delay per flight, by solver (Fig. 19 analogue)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    return Path(path)
