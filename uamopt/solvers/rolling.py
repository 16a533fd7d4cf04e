"""Solver ``rolling``: rolling-horizon decomposition of the scheduling model for large instances.

Method
------
Flights are sorted by planned departure and the day is cut into windows of ``window_s`` seconds
(by planned departure; empty windows are skipped). Window by window, the window's flights (the
*free* flights) are solved exactly by the inner solver (``inner`` = ``"cpsat"`` or ``"highs"``)
on a **sub-problem** in which the flights of earlier windows are *fixed* at their decisions:

- every earlier **operated** flight that matters to a free flight — it conflicts with one (a pair
  of ``problem.pairs``, or a pad hold that can meet one of the free flight's, family ``pads``),
  or it is the last operated earlier flight of a free flight's aircraft
  (the turnaround rule of the model is implied by the last operated one) — enters the sub-problem
  as a *fixed* flight: planned departure = its decided departure, delay bound 0 (``max_delay_s
  = 0``), and it **must operate** (``must_operate`` of the sub-problem, uamopt.schedule.core,
  which every inner solver reads; with delay bound 0 only, the solver could buy free flights by
  cancelling a fixed one). Conflict
  intervals are on actual departures, so they carry over unchanged; fixed–fixed pairs are
  dropped (already satisfied);
- a free return whose outbound was cancelled in an earlier window is cancelled (precedence);
- the sub-problem keeps the global G, so its weighted objective is the global one restricted to
  the window plus a constant.

Per aircraft the decided flights are always a prefix of its chain (windows follow planned
departure), so every constraint between a free flight and a decided one is in the sub-problem;
hence a window decision that passes ``violations(sub, ...)`` with every fixed flight operated
keeps the union feasible. A window whose inner solve fails (no incumbent, infeasible from
rounding, a violation, a fixed flight cancelled) falls back to the greedy preliminary strategy on
the sub-problem with the fixed flights placed first (they are mutually consistent, so they keep
delay 0), and if even that cancels a fixed flight, to cancelling the window's free flights.
The end result is asserted with ``violations(problem, ...) == []`` (else: the whole-problem greedy
schedule, ``extras["fallback"]``).

Lower bound (cheap, valid)
--------------------------
Drop all constraints except, for a set M of *disjoint* conflicting pairs, each pair's own
conflict. The objective is separable per flight with c d ≥ 0, so a flight outside M contributes
≥ −ω7 (operated on time), and a pair (p, q) ∈ M contributes ≥ min(−ω7, −2ω7 + ω6/G · dist),
where dist is the least total delay d_p + d_q that moves δ = dep_q − dep_p from its planned value
out of every forbidden interval within reach (∞ if no admissible δ: at most one operates), since
|Δδ| ≤ d_p + d_q. Dropping constraints only lowers the minimum, so the sum is ≤ the optimum.
M is a greedy maximum-improvement matching; dist is reduced by 2·TIME_TOL_S to stay valid under
the feasibility tolerance. Lexicographic: the same with −1 per flight and dist/(ΣU + 1).
(The sum of the windows' own bounds is *not* a bound of the whole problem.)

Time: ``time_limit_s`` bounds the whole solve; each window's inner solve gets at most what is left
of it, and the windows reached after it are placed together by the greedy strategy, earlier
decisions fixed (``extras["windows_past_limit"]``).

Options (``[options]`` of a profile): ``window_s`` (900), ``inner`` ("cpsat"), ``window_time_limit_s``
(default ``time_limit_s`` / number of non-empty windows), ``time_unit_s`` (CP-SAT, 0.01),
``step_s`` (greedy fallback ΔT_a; default the problem's ``schedule.time_step_s``). Termination: ``time_limit`` when the
limit came before the last window, else ``stopped`` (status ``feasible``; windows whose inner solve
stopped unproved are counted in ``extras["unproved"]``); ``no_solution`` when a must-operate flight
found no place (a heuristic: no proof). Registered as
``"rolling"`` (profile ``solvers/rolling.toml``): ``solve(problem, "rolling")``, or
``solve(problem, SolverProfile("rolling", time_limit_s=60, options={"window_s": 600.0}))``.
"""

from __future__ import annotations

import dataclasses
import time
from typing import TYPE_CHECKING

import numpy as np

from uamopt.errors import UamoptError
from uamopt.interrupts import stopping
from uamopt.schedule.flights import TIME_TOL_S
from uamopt.schedule.model import Schedule, SchedulingProblem, Termination, make_schedule, violations
from uamopt.schedule.occupancy import ConflictTable
from uamopt.solvers.greedy import greedy_decisions

if TYPE_CHECKING:
    from uamopt.solvers import SolverProfile

SHAPES = frozenset({"bounds", "must_operate", "precedence", "turnaround", "pairs", "cumulative"})
#: its sub-problems rebuild the paper's five families from a sub flight set, and carry ``pads``
#: (families/pads.py, restricted to the window's flights): no other family survives
FAMILIES = frozenset({"delay_bounds", "must_operate", "precedence", "turnaround", "conflicts", "pads"})
OBJECTIVES = frozenset({"weighted", "lexicographic"})  # its lower bound needs Σ d (pair_matching_bound)


# --- the cheap lower bound ---------------------------------------------------------------------
def pair_matching_bound(problem: SchedulingProblem) -> float:
    """A valid lower bound of the optimum (module docstring): disjoint conflicting pairs, each alone."""
    n = problem.n_flights
    view = problem.pairs
    per_flight, per_delay = problem.objective.per_flight, problem.objective.per_delay
    if len(view) == 0:
        return -per_flight * n
    upper = problem.delay_upper_s
    p, q = view.p, view.q
    row_pair = view.row_pair
    lo, hi = view.lo, view.hi
    d0 = view.shift[row_pair]
    inside = (lo < d0) & (d0 < hi)
    down = np.where(lo >= d0 - upper[p[row_pair]], d0 - lo, np.inf)  # p delayed / q earlier: δ down to lo
    up = np.where(hi <= d0 + upper[q[row_pair]], hi - d0, np.inf)  # q delayed: δ up to hi
    dist = np.zeros(len(view))
    rows = np.flatnonzero(inside)
    dist[row_pair[rows]] = np.minimum(down[rows], up[rows])
    dist = np.maximum(0.0, dist - 2 * TIME_TOL_S)
    gain = np.minimum(per_flight, per_delay * dist)  # above the −2·per_flight of two free flights
    used = np.zeros(n, dtype=bool)
    total = 0.0
    for k in np.argsort(-gain, kind="stable"):
        if gain[k] <= 0:
            break
        a, b = int(p[k]), int(q[k])
        if not (used[a] or used[b]):
            used[a] = used[b] = True
            total += float(gain[k])
    return -per_flight * n + total


# --- sub-problems -------------------------------------------------------------------------------
def subproblem(problem: SchedulingProblem, free: np.ndarray, fixed: np.ndarray, departure: np.ndarray
               ) -> tuple[SchedulingProblem, np.ndarray, np.ndarray]:
    """The window's model: ``free`` flights as they are, ``fixed`` flights at ``departure`` with delay
    bound 0 (to be forced operated by the caller). Returns (sub-problem, global index of each sub
    flight, fixed mask over sub flights)."""
    fs = problem.flights
    n = problem.n_flights
    index = np.union1d(free, fixed)
    pos = np.full(n, -1, dtype=np.int64)
    pos[index] = np.arange(len(index))
    is_fixed = np.zeros(n, dtype=bool)
    is_fixed[fixed] = True
    flights = tuple(dataclasses.replace(fs.flights[i], planned_departure_s=float(departure[i]), max_delay_s=0.0)
                    if is_fixed[i] else fs.flights[i] for i in index.tolist())
    # the chains in the original order (a fixed flight's new departure could reorder a re-sort), and
    # the original precedence (a sub-chain may start with a return): given to the FlightSet
    chains = []
    for chain in fs.chains:
        members = pos[chain]
        members = members[members >= 0]
        if len(members):
            chains.append(members)
    req = problem.requires[index]
    sub_req = np.where(req >= 0, pos[np.maximum(req, 0)], -1)
    free_mask = ~is_fixed[index]
    if np.any(free_mask & (req >= 0) & (sub_req < 0)):
        raise UamoptError("a free return's outbound is missing from its window's sub-problem", "solver rolling",
                          "report this as a bug")
    sub_fs = dataclasses.replace(fs, flights=flights, chain_order=tuple(chains), outbound_of=sub_req)
    # conflicts with at least one free flight, re-indexed (pos is increasing, so p < q and the order hold)
    c = problem.conflicts
    keep = (pos[c.p] >= 0) & (pos[c.q] >= 0) & ~(is_fixed[c.p] & is_fixed[c.q])
    counts = np.diff(c.ptr)
    row_keep = np.repeat(keep, counts)
    table = ConflictTable(p=pos[c.p[keep]], q=pos[c.q[keep]],
                          ptr=np.concatenate([[0], np.cumsum(counts[keep])]).astype(np.int64),
                          intervals=c.intervals[row_keep])
    pads = tuple(f.restricted(pos) for f in problem.extra_families if f.name == "pads")
    sub = SchedulingProblem(flights=sub_fs, conflicts=table, weights=problem.weights,
                            aircraft_count=problem.aircraft_count, objective_kind=problem.objective_kind,
                            time_step_s=problem.time_step_s, must_operate=is_fixed[index] | problem.must_operate[index],
                            extra_families=pads)
    return sub, index, is_fixed[index]


def _inner_cpsat(sub: SchedulingProblem, hint: tuple[np.ndarray, np.ndarray], limit_s: float,
                 threads: int, seed: int, unit_s: float) -> tuple[np.ndarray, np.ndarray, bool] | None:
    from ortools.sat.python import cp_model

    from uamopt.solvers.cpsat import build_cpsat, cp_solver

    built = build_cpsat(sub, unit_s)  # the fixed flights must operate (sub.must_operate)
    model, operate, delay = built.model, built.operate, built.delay
    h_op, h_d = hint
    for i in range(sub.n_flights):
        model.add_hint(operate[i], bool(h_op[i]))
        model.add_hint(delay[i], int(np.rint(h_d[i] / unit_s)) if h_op[i] else 0)
    solver = cp_solver(limit_s, threads, seed, where="profile rolling")  # CP-SAT's settings, one copy
    with stopping(solver.stop_search):
        code = solver.solve(model)
    if code not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        return None
    operated = np.array([solver.boolean_value(v) for v in operate])
    delay_s = np.array([solver.value(v) for v in delay], dtype=float) * unit_s
    return operated, delay_s, code == cp_model.OPTIMAL


def _inner_highs(sub: SchedulingProblem, limit_s: float, threads: int, seed: int
                 ) -> tuple[np.ndarray, np.ndarray, bool] | None:
    import pyomo.environ as pyo
    from pyomo.contrib.solver.common.factory import SolverFactory
    from pyomo.contrib.solver.common.results import SolutionStatus, TerminationCondition

    from uamopt.solvers import milp

    m = milp.build_model(sub)  # the fixed flights must operate (sub.must_operate)
    solver = SolverFactory(milp.SOLVER_NAME)
    with stopping(milp.cancel(solver)):
        result = solver.solve(m, time_limit=float(limit_s), threads=int(threads),
                              solver_options={"mip_rel_gap": 0.0, "random_seed": int(seed)}, load_solutions=False,
                              raise_exception_on_nonoptimal_result=False)
    if result.solution_status not in (SolutionStatus.optimal, SolutionStatus.feasible):
        return None
    result.solution_loader.load_vars()
    operated = np.array([pyo.value(m.operate[f]) > 0.5 for f in range(sub.n_flights)])
    delay = milp.least_delays(sub, operated, milp.chosen_gaps(m, operated))
    if delay is None:
        delay = np.where(operated, np.clip([pyo.value(m.delay[f]) for f in range(sub.n_flights)], 0.0, sub.delay_upper_s), 0.0)
    proved = result.termination_condition == TerminationCondition.convergenceCriteriaSatisfied
    return operated, delay, proved


# --- the solver -----------------------------------------------------------------------------------
def _options(profile) -> dict:
    """The profile's options (typed and checked by the profile, uamopt.solvers.options), defaults filled."""
    return {key: profile.option(key) for key in ("inner", "window_s", "window_time_limit_s", "time_unit_s", "step_s")}


def solve(problem: SchedulingProblem, profile: SolverProfile) -> Schedule:
    """Rolling horizon (module docstring); never worse than the whole-problem warm start
    (:mod:`~uamopt.solvers.warmstart`: greedy, greedy with exact gaps), which it returns instead
    when the windows end worse (``extras["incumbent"]``)."""
    from uamopt.solvers.warmstart import no_worse, warm_start

    o = _options(profile)
    start = time.perf_counter()
    deadline = start + profile.time_limit_s
    first = warm_start(problem, o["step_s"], seed=profile.seed)
    n = problem.n_flights
    dep0 = problem.planned_departure_s
    order = np.lexsort((np.arange(n), dep0))
    t0 = float(dep0[order[0]]) if n else 0.0
    window_of = np.floor((dep0 - t0) / o["window_s"]).astype(np.int64)
    windows = [order[window_of[order] == w] for w in np.unique(window_of)]
    limit = (float(o["window_time_limit_s"]) if o["window_time_limit_s"] is not None
             else profile.time_limit_s / max(len(windows), 1))
    aircraft = problem.flights.aircraft_index
    pairs = np.stack([problem.pairs.p, problem.pairs.q], axis=1)  # one-pad holds included (problem.pairs)
    for family in problem.of_shape("cumulative"):  # flights whose holds can meet at a resource of more pads
        rest = family.residual()
        a, b = rest.meetings(np.arange(len(rest.flight)), dep0, problem.delay_upper_s)
        pairs = np.concatenate([pairs, np.stack([rest.flight[a], rest.flight[b]], axis=1)])
    decided = np.zeros(n, dtype=bool)
    operated = np.zeros(n, dtype=bool)
    delay = np.zeros(n)
    last_operated = np.full(problem.flights.n_aircraft, -1, dtype=np.int64)
    stats = {"windows": len(windows), "window_time_limit_s": limit, "inner": o["inner"], "proved": 0,
             "unproved": 0, "greedy_windows": 0, "cancelled_windows": 0, "max_subproblem": 0}
    w = 0
    while w < len(windows):
        free, w = windows[w], w + 1
        if deadline - time.perf_counter() < 0.05 and w < len(windows):  # past the limit: the rest in one greedy pass
            stats["windows_past_limit"] = 1 + len(windows) - w
            free, w = np.concatenate([free, *windows[w:]]), len(windows)
        free = np.sort(free)
        # a return whose outbound was cancelled earlier cannot fly
        req = problem.requires[free]
        dead = (req >= 0) & decided[np.maximum(req, 0)] & ~operated[np.maximum(req, 0)]
        decided[free[dead]] = True
        free = free[~dead]
        if len(free) == 0:
            continue
        is_free = np.zeros(n, dtype=bool)
        is_free[free] = True
        on = operated & decided
        touch = (is_free[pairs[:, 0]] & on[pairs[:, 1]]) | (is_free[pairs[:, 1]] & on[pairs[:, 0]])
        fixed = np.union1d(np.where(is_free[pairs[touch, 0]], pairs[touch, 1], pairs[touch, 0]),
                           last_operated[np.unique(aircraft[free])])
        fixed = fixed[fixed >= 0].astype(np.int64)
        sub, index, fixed_mask = subproblem(problem, free, fixed, dep0 + delay)
        stats["max_subproblem"] = max(stats["max_subproblem"], sub.n_flights)
        hint = greedy_decisions(sub, float(o["step_s"] or problem.time_step_s))  # must-operate flights placed first
        answer = None
        left = deadline - time.perf_counter()
        try:
            if left < 0.05:  # the whole-solve limit is spent: the greedy hint
                pass
            elif o["inner"] == "cpsat":
                answer = _inner_cpsat(sub, hint, min(limit, left), profile.threads, profile.seed, o["time_unit_s"])
            else:
                answer = _inner_highs(sub, min(limit, left), profile.threads, profile.seed)
        except UamoptError:
            answer = None
        if answer is not None and not violations(sub, answer[0], answer[1]):  # violations checks must-operate
            stats["proved" if answer[2] else "unproved"] += 1
            sub_op, sub_d = answer[0], answer[1]
        else:
            stats["greedy_windows"] += 1
            sub_op, sub_d = hint
            if violations(sub, sub_op, sub_d):
                stats["cancelled_windows"] += 1
                sub_op, sub_d = fixed_mask.copy(), np.zeros(sub.n_flights)
        free_rows = ~fixed_mask
        g = index[free_rows]
        operated[g] = sub_op[free_rows]
        delay[g] = np.where(sub_op[free_rows], sub_d[free_rows], 0.0)
        decided[g] = True
        for f in free.tolist():  # free is in index order; chains are by departure: take the latest operated
            if operated[f]:
                a = aircraft[f]
                last = last_operated[a]
                if last < 0 or dep0[f] > dep0[last] or (dep0[f] == dep0[last] and f > last):
                    last_operated[a] = f
    bad = violations(problem, operated, delay)
    if bad:  # cannot happen by construction; never return an infeasible schedule
        stats["fallback"] = f"whole-problem greedy ({len(bad)} violations, first: {bad[0]})"
        operated, delay = greedy_decisions(problem, o["step_s"] and float(o["step_s"]))
    bound: float | None = pair_matching_bound(problem)
    # the limit reached before the last window: time_limit; else the run ended by its own rule (every window
    # solved once; an inner window unproved at its share of the limit is counted in extras["unproved"])
    termination: Termination = "time_limit" if stats.get("windows_past_limit") else "stopped"
    if not first.found and violations(problem, operated, delay):  # as greedy: a must-operate flight not placed
        termination, bound = "no_solution", None
    stats["bound_of"] = "pair-matching relaxation (rolling.py docstring)"
    return no_worse(problem, make_schedule(problem, "rolling", termination, operated, delay, bound=bound,
                                           solve_seconds=time.perf_counter() - start, seed=profile.seed, extras=stats), first)
