"""Solver ``windows``: a day cut into windows of flights solved on a Dask cluster, with a valid global bound.

Method
------
Flights are sorted by planned departure and cut into windows of ``window_flights`` consecutive
flights. Each window's **relaxed sub-problem** keeps its own flights and only the rows among them:
the conflicts, turnarounds and precedence rows that link it to another window are dropped (a
return whose outbound lies in another window is free to operate). Each is solved by discovery.py
(its rounds' bounds are valid for continuous delays) as one Dask task: on a loopback
``LocalCluster`` of ``workers`` processes by default, or on the running cluster at ``scheduler``
(``tcp://host:8786``: ``dask scheduler`` and ``dask worker`` processes with uamopt installed).

Global bound. The weighted objective (Eq. 20 with Eq. 21: W = ω6/G · Σ c d − ω7 · Σ c) is a sum over flights, and every
row kept lies inside one window, so the problem with the cross-window rows dropped separates into
the windows' relaxed sub-problems: its optimum is the *sum of their optima*, and it is a
relaxation of the whole problem (fewer rows), so Σ_w bound_w ≤ Σ_w OPT_w ≤ OPT. The bound reported
is that sum of the windows' discovery bounds. (Windows that fix their neighbours' decisions, as
``rolling`` does, give no such bound: their sum is not a relaxation.)

Schedule. The windows' schedules are joined; the rows across windows they break are mended
(polish.py: the later flight of each broken row taken out and put back where it fits; a return
whose outbound was cancelled is cancelled), then left shifts and insertions, then neighbourhood
search (lns.py) in the time left, and the result is never worse than the warm start.

Same answer, any number of workers: each window's task is the same computation wherever it runs
(one thread, the profile's seed, at most ``rounds`` discovery rounds, its own time limit
``window_time_limit_s``); it is reproducible when no window stops at that limit
(``extras["windows_at_limit"]`` is 0). Only the weighted objective (the lexicographic weights
depend on the whole day's delay bounds) and the shapes of discovery.py.
"""

from __future__ import annotations

import dataclasses
import time
from typing import TYPE_CHECKING

import numpy as np

from uamopt.optional import require
from uamopt.schedule.model import Schedule, SchedulingProblem, evaluate, make_schedule, violations
from uamopt.schedule.occupancy import ConflictTable

if TYPE_CHECKING:
    from uamopt.solvers import SolverProfile

SHAPES = frozenset({"bounds", "must_operate", "precedence", "turnaround", "pairs"})
OBJECTIVES = frozenset({"weighted"})
WINDOWS_SHARE = 0.75  # of the time limit, for the windows (the rest: joining, mending, search)
#: the windows' results are waited for until this share of the time limit: a window whose engine
#: overran its own limit (HiGHS's presolve does not listen), or whose worker or scheduler died, is
#: replaced by the warm start on its flights (:func:`stand_in`), so that the solve keeps its limit
GATHER_SHARE = 0.85


def collect(client, futures: list, deadline: float) -> tuple[list, dict[int, str]]:
    """The windows' results in order, waited for until ``deadline`` (a ``time.perf_counter`` time),
    and the windows lost: {index: why} (not done by then, failed, or the cluster gone)."""
    from distributed import wait

    results: list = [None] * len(futures)
    lost: dict[int, str] = {}
    try:
        wait(futures, timeout=max(0.1, deadline - time.perf_counter()))
    except Exception:  # noqa: BLE001 - TimeoutError: some not done; OSError & co: the cluster is gone
        pass
    for k, future in enumerate(futures):
        try:
            if future.status == "finished":
                results[k] = future.result(timeout=5)
                continue
            lost[k] = "not done by the deadline" if future.status == "pending" else f"its task {future.status}"
        except Exception as exc:  # noqa: BLE001 - a worker killed too often, the scheduler gone
            lost[k] = f"{type(exc).__name__}: {exc}"[:200]
        try:
            future.cancel()
        except Exception:  # noqa: BLE001 - the client is gone already
            pass
    return results, lost


def stand_in(sub: SchedulingProblem, start, index: np.ndarray, why: str) -> dict:
    """A lost window's result: the warm start restricted to its flights (the join mends it with the
    rest), and the separable bound of its relaxed sub-problem (valid: the sum stays a bound)."""
    from uamopt.solvers.watchdog import separable_bound

    operated = start.operated[index] if start.found else None
    delay = np.where(operated, start.delay_s[index], 0.0) if operated is not None else None
    return {"bound": separable_bound(sub), "clique_rows": 0, "operated": operated, "delay_s": delay,
            "objective": None, "rounds": 0, "seconds": 0.0, "proved": False, "at_limit": True, "lost": why}


def window_problem(problem: SchedulingProblem, index: np.ndarray) -> SchedulingProblem:
    """The relaxed sub-problem of the flights ``index`` (sorted): their own rows only (module docstring)."""
    fs = problem.flights
    n = problem.n_flights
    pos = np.full(n, -1, dtype=np.int64)
    pos[index] = np.arange(len(index))
    chains = [pos[c][pos[c] >= 0] for c in fs.chains]
    req = problem.requires[index]
    sub_req = np.where(req >= 0, pos[np.maximum(req, 0)], -1)  # an outbound outside: no precedence
    sub_fs = dataclasses.replace(fs, flights=tuple(fs.flights[i] for i in index.tolist()),
                                 chain_order=tuple(c for c in chains if len(c)), outbound_of=sub_req)
    c = problem.conflicts
    keep = (pos[c.p] >= 0) & (pos[c.q] >= 0)
    counts = np.diff(c.ptr)
    # the restriction of a table computed from the tracks to some of its flights (departures unchanged)
    # is that flight set's own table: clique rows may still be derived
    table = ConflictTable(p=pos[c.p[keep]], q=pos[c.q[keep]],
                          ptr=np.concatenate([[0], np.cumsum(counts[keep])]).astype(np.int64),
                          intervals=c.intervals[np.repeat(keep, counts)],
                          from_tracks=bool(getattr(c, "from_tracks", False)))
    return SchedulingProblem(flights=sub_fs, conflicts=table, weights=problem.weights,
                             aircraft_count=problem.aircraft_count, objective_kind=problem.objective_kind,
                             time_step_s=problem.time_step_s, must_operate=problem.must_operate[index])


def solve_window(sub: SchedulingProblem, limit_s: float, seed: int, options: dict) -> dict:
    """One window's task (runs on a Dask worker): discovery on its relaxed sub-problem, one thread."""
    from uamopt.solvers.discovery import discover
    from uamopt.solvers.warmstart import reduced, warm_start

    t = time.perf_counter()
    start = warm_start(sub, options["step_s"])
    state: dict = {}
    found = discover(sub, reduced(sub), t + limit_s, 1, seed, step_s=options["step_s"],
                     start=start.decisions if start.found else None, gap=options["mip_rel_gap"],
                     cliques=options["cliques"], max_rounds=options["rounds"], round_s=options["round_s"], state=state)
    return {"bound": found.bound, "clique_rows": state.get("clique_rows", 0), "operated": found.operated,
            "delay_s": found.delay_s, "objective": found.objective,
            "rounds": len(found.rounds), "seconds": time.perf_counter() - t, "proved": found.proved,
            # stopped by a clock (the window's limit, or a round's): then not reproducible on other machines
            "at_limit": any("time" in r.termination.lower() for r in found.rounds)
            or (time.perf_counter() - t >= limit_s - 1.0 and not found.proved and len(found.rounds) < options["rounds"])}


def split(problem: SchedulingProblem, size: int) -> list[np.ndarray]:
    """Windows of ``size`` consecutive flights by planned departure (each sorted by flight index)."""
    order = np.argsort(problem.planned_departure_s, kind="stable")
    return [np.sort(order[i:i + size]) for i in range(0, len(order), size)]


def join(problem: SchedulingProblem, parts: list[tuple[np.ndarray, dict]]) -> tuple[np.ndarray, np.ndarray]:
    """The windows' schedules as one feasible schedule (module docstring, *Schedule*)."""
    from uamopt.solvers.polish import Neighbours, mend, polish

    n = problem.n_flights
    operated, delay = np.zeros(n, dtype=bool), np.zeros(n)
    for index, result in parts:
        if result["operated"] is not None:
            operated[index] = result["operated"]
            delay[index] = np.where(result["operated"], result["delay_s"], 0.0)
    nb = Neighbours(problem)
    for f in np.flatnonzero(operated).tolist():  # a return whose outbound (another window's) was cancelled
        if operated[f] and not nb.allowed(f, operated):
            nb.drop(f, operated, delay)
    return polish(problem, nb, *mend(problem, nb, operated, delay))


def solve(problem: SchedulingProblem, profile: SolverProfile) -> Schedule:
    """Windows on Dask, the sum of their bounds, the joined schedule (module docstring)."""
    from uamopt.cluster import connect
    from uamopt.solvers import lns
    from uamopt.solvers.warmstart import no_worse, reduced, warm_start
    from uamopt.solvers.watchdog import warm_workers

    require("distributed", extra="sweep", what="the windows solver (Dask)")
    o = profile.option
    t0 = time.perf_counter()
    options = {"step_s": o("step_s"), "mip_rel_gap": o("mip_rel_gap"), "cliques": o("cliques"), "rounds": o("rounds"),
               "round_s": o("round_time_limit_s")}
    start = warm_start(problem, o("step_s"))
    windows = split(problem, o("window_flights"))
    workers = o("workers")
    per_window = o("window_time_limit_s") or max(
        1.0, WINDOWS_SHARE * profile.time_limit_s * min(workers, len(windows)) / len(windows))
    subs = [window_problem(problem, index) for index in windows]
    client, cluster = connect(o("scheduler") or None, workers, len(windows))
    warm_workers(client)
    try:
        # the sub-problems go to the workers as data, not inside the task graph (13 MB at 10,000 flights:
        # Dask warned of a large graph)
        futures = client.map(solve_window, client.scatter(subs), [per_window] * len(subs),
                             [profile.seed] * len(subs), [options] * len(subs), pure=False)
        results, lost = collect(client, futures, t0 + GATHER_SHARE * profile.time_limit_s)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    for k, why in lost.items():  # the warm start on that window, and any valid bound of its relaxed sub-problem
        results[k] = stand_in(subs[k], start, windows[k], why)
    bounds = [r["bound"] for r in results]
    bound = float(sum(bounds)) if all(b is not None for b in bounds) else None
    operated, delay = join(problem, list(zip(windows, results, strict=True)))
    small = reduced(problem)
    passes = improved = 0
    while time.perf_counter() - t0 < profile.time_limit_s - 2.0:
        operated, delay, better = lns.improve(problem, small, operated, delay, t0 + profile.time_limit_s,
                                              profile.threads, profile.seed, size=o("lns_window"),
                                              window_s=o("lns_window_time_limit_s"), pass_index=passes)
        passes += 1
        improved += better
        if not better:
            break
    broken = violations(problem, operated, delay)
    if broken:  # not expected (join mends every cross-window row): the warm start, and say so
        if not start.found:
            from uamopt.solvers.warmstart import no_schedule

            raise no_schedule(problem, profile.name or "windows", f"the joined windows break a row ({broken[0]})")
        operated, delay = start.decisions
    value = evaluate(problem, operated, delay)
    proved = bound is not None and value - bound <= 1e-9 * (1.0 + abs(value))
    extras = {"model": "continuous (bound: the sum of the windows' discovery bounds, cross-window rows dropped)",
              "model_kind": "continuous", "windows": len(windows), "window_flights": o("window_flights"),
              "window_time_limit_s": per_window, "workers": workers, "scheduler": o("scheduler") or "LocalCluster",
              "window_bounds": bounds, "window_rounds": [r["rounds"] for r in results],
              "clique_rows": int(sum(r["clique_rows"] for r in results)),
              "windows_at_limit": int(sum(bool(r["at_limit"]) for r in results)),
              "windows_proved": int(sum(bool(r["proved"]) for r in results)),
              "window_seconds": [round(r["seconds"], 1) for r in results], "lns_passes": passes,
              "windows_lost": {int(k): why for k, why in lost.items()},
              "joined_schedule": f"broke a row ({broken[0]}): the warm start kept" if broken else "feasible",
              "lns_windows_improved": improved,
              "warm_start": f"{start.source} {start.objective:.6f}", "continuous_bound": bound,
              "continuous_bound_model": "sum over windows of discovery relaxations (cross-window rows dropped)"}
    schedule = make_schedule(problem, "windows", "optimal" if proved else "time_limit", operated, delay,
                             proved_for="continuous" if proved else "none", bound=bound,
                             solve_seconds=time.perf_counter() - t0, seed=profile.seed, extras=extras)
    return no_worse(problem, schedule, start)
