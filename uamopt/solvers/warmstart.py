"""Incumbents for the exact solvers: the best heuristic schedule that is cheap to get.

Every exact solver (``highs``, ``cpsat``, ``rolling``, ``timeindexed``) starts from
:func:`warm_start` — HiGHS through its MIP start (``Highs.setSolution``), CP-SAT through hints —
and :func:`no_worse` makes sure the schedule it returns is never worse than that start, whatever
the time limit: when the solver's own incumbent is worse (or missing), the start is returned with
the solver's bound and status ``time_limit`` (``extras["incumbent"]`` says so).

Candidates, best objective (Eq. 20 or the lexicographic scalar) wins, ties to the first:

1. the preliminary strategy (Sec. 5.2.1) on the ΔT_a grid (``greedy`` with ``step_s``): its delays
   are multiples of ΔT_a, so it is also a point of the time-indexed grid model;
2. the preliminary strategy with exact gaps (a flight pushed exactly to the end of a forbidden
   gap): often better for the continuous model, never on a grid;
3. when ``soa_s`` > 0, a short SOA run (Table 1; ``soa_s`` seconds, same seed): its delays are on
   the ΔT_a grid too.

``on_grid=True`` keeps only grid candidates (1 and 3), for a model whose delays are k·ΔT_a.
Each greedy candidate is also run on :func:`reduced` (delays capped where cancelling is better).

Dominance (weighted objective, Eq. 20): cancelling an operated flight f together with every flight
that (transitively) requires it keeps a schedule feasible — conflicts and turnarounds only bind
operated flights, and the turnaround rows are all-pairs (model.py) — and changes W by
Σ_{g ∈ S} (ω7 − ω6 d_g / G) ≤ |S| ω7 − ω6 d_f / G. So every optimal schedule has
d_f ≤ (1 + dependants_f) · ω7 G / ω6, and capping Δd_f there (:func:`reduced`) changes no optimum,
continuous or on a grid. (No such cap for the lexicographic objective, where flights come first,
nor for a flight that must operate or that a must-operate flight requires: it cannot be cancelled.)
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from uamopt.errors import UamoptError
from uamopt.schedule.model import (
    Schedule,
    SchedulingProblem,
    Termination,
    evaluate,
    make_schedule,
    violations,
)
from uamopt.solvers.greedy import DEFAULT_STEP_S, greedy_decisions
from uamopt.solvers.watchdog import report_incumbent


@dataclass(frozen=True)
class Start:
    """A feasible schedule to start from: decisions, objective and where it came from. ``operated``
    is None (objective inf) when no cheap schedule satisfies the must-operate flights: the exact
    model then decides whether any schedule does (``found`` is False)."""

    operated: np.ndarray | None
    delay_s: np.ndarray | None
    objective: float
    source: str
    seconds: float

    @property
    def found(self) -> bool:
        return self.operated is not None

    @property
    def decisions(self) -> tuple[np.ndarray, np.ndarray]:
        """(operated, delay_s) of a start that was ``found``."""
        assert self.operated is not None and self.delay_s is not None, "no start was found"
        return self.operated, self.delay_s


def _pinned(problem: SchedulingProblem, shown: int = 8) -> str:
    """The must-operate flights' ids, the first ``shown`` of them."""
    ids = [problem.flights.flights[f].id for f in np.flatnonzero(problem.must_operate)]
    return ", ".join(ids[:shown]) + (", …" if len(ids) > shown else "")


def infeasible_reason(problem: SchedulingProblem) -> str:
    """Why a proved-infeasible problem is infeasible, in words (the must-operate flights pinned)."""
    if not problem.must_operate.any():
        return "the model has no feasible point"
    return (f"no schedule operates every must-operate flight ({_pinned(problem)}) within the pair conflicts, "
            "turnarounds, delay bounds and service window")


def no_schedule(problem: SchedulingProblem, solver: str, why: str) -> UamoptError:
    """The error for a solver that stopped with no schedule satisfying the must-operate flights
    and without proving that none exists (a limit hit before either)."""
    return UamoptError(f"no schedule that operates every must-operate flight ({_pinned(problem, 5)}) was found: {why}",
                       f"solver {solver}", "raise the time limit, or pin fewer flights")


def reduced(problem: SchedulingProblem) -> SchedulingProblem:
    """The problem with each delay bound capped by dominance (module docstring); the same optima.

    Evaluate schedules with the original problem (the lexicographic scalar uses Σ U; it is returned
    unchanged)."""
    if problem.objective_kind != "weighted" or problem.objective.per_delay <= 0 \
            or problem.core_families is not None:  # its dependants are the paper's precedence (speed copies: groups)
        return problem
    req = problem.requires
    dependants = np.zeros(problem.n_flights, dtype=np.int64)
    pinned = problem.must_operate.copy()  # cannot be cancelled: itself or a dependant must operate
    for f in np.flatnonzero(req >= 0):  # walk up each chain of requirements
        r = int(req[f])
        while r >= 0:
            dependants[r] += 1
            pinned[r] |= problem.must_operate[f]
            r = int(req[r])
    cap = np.where(pinned, np.inf, (1 + dependants) * problem.objective.per_flight / problem.objective.per_delay)
    fs = problem.flights
    if np.all(cap >= fs.delay_upper_s):
        return problem
    flights = tuple(dataclasses.replace(f, max_delay_s=float(min(f.max_delay_s, c)))
                    for f, c in zip(fs.flights, cap, strict=True))
    return dataclasses.replace(problem, flights=dataclasses.replace(fs, flights=flights))


#: schedules handed to the next warm_start of a problem (uamopt.solvers.solve: speed options start
#: from the cruise-speed model's schedule); keyed by id(problem), consumed by warm_start
SEEDS: dict[int, list] = {}


def warm_start(problem: SchedulingProblem, step_s: float = DEFAULT_STEP_S, *, soa_s: float = 0.0, seed: int = 0,
               on_grid: bool = False) -> Start:
    """The best of the cheap heuristic schedules (module docstring), and of any schedule seeded for
    this problem (:data:`SEEDS`); always feasible."""
    t0 = time.perf_counter()
    small = reduced(problem)
    candidates = [("greedy", *greedy_decisions(problem, step_s))]
    report_incumbent(problem, candidates[0][1], candidates[0][2], "warm start (greedy)")  # a watched child's first answer
    candidates += [(name, op, d) for name, op, d in SEEDS.get(id(problem), ())
                   if not on_grid or np.allclose(np.where(op, d, 0.0) / step_s, np.rint(np.where(op, d, 0.0) / step_s))]
    if small is not problem:
        candidates.append(("greedy-capped", *greedy_decisions(small, step_s)))
    if not on_grid:
        candidates.append(("greedy-exact-gaps", *greedy_decisions(problem, step_s, exact_gaps=True)))
        if small is not problem:
            candidates.append(("greedy-capped-exact-gaps", *greedy_decisions(small, step_s, exact_gaps=True)))
    if soa_s > 0:
        from uamopt.solvers import SolverProfile
        from uamopt.solvers.genetic import solve as genetic_solve

        soa = genetic_solve(problem, SolverProfile("soa", time_limit_s=soa_s, seed=seed, options={"step_s": step_s}))
        candidates.append(("soa", soa.operated, soa.delay_s))
    best = None
    for source, operated, delay in candidates:
        if violations(problem, operated, delay):  # cannot happen (the decoder is feasible by construction)
            continue
        value = evaluate(problem, operated, delay)
        if best is None or value < best[0] - 1e-12:
            best = (value, source, operated, delay)
    if best is None:  # only with must-operate flights: no cheap schedule places them all
        return Start(operated=None, delay_s=None, objective=math.inf,
                     source="none (no cheap schedule operates every must-operate flight)",
                     seconds=time.perf_counter() - t0)
    report_incumbent(problem, best[2], best[3], f"warm start ({best[1]})")
    return Start(operated=best[2].copy(), delay_s=np.where(best[2], best[3], 0.0), objective=best[0], source=best[1],
                 seconds=time.perf_counter() - t0)


def no_start(why: str = "none (an extra= callback: a heuristic schedule need not meet its rows)") -> Start:
    """The empty start: the solver runs cold and :func:`no_worse` has nothing to fall back on."""
    return Start(operated=None, delay_s=None, objective=math.inf, source=why, seconds=0.0)


def no_worse(problem: SchedulingProblem, schedule: Schedule, start: Start) -> Schedule:
    """``schedule``, or ``start`` when the solver's incumbent is worse (keeping the solver's bound).

    A solver that proved optimality cannot be worse than a feasible start (up to its tolerances), so
    the swap only happens under a limit; the status becomes ``time_limit``.
    """
    if not start.found:  # nothing to fall back on: the solver's own answer (callers refuse a non-schedule)
        return schedule
    if schedule.objective is not None and schedule.objective <= start.objective + 1e-9 * (1.0 + abs(start.objective)):
        return schedule
    extras = dict(schedule.extras, incumbent=f"warm start ({start.source}): the solver's own was "
                  f"{'none' if schedule.objective is None else f'{schedule.objective:.6f}'}")
    termination: Termination
    bound, termination = schedule.bound, "time_limit"
    if schedule.termination in ("optimal", "stopped"):  # ended by a proof on a restricted model or a gap rule
        termination = "stopped"
        if schedule.bound is not None and schedule.bound > start.objective + 1e-9 * (1.0 + abs(start.objective)):
            bound = None  # not a bound of the problem the start solves
            extras["bound_dropped"] = f"{schedule.bound!r}: the optimum of {schedule.extras.get('model', 'its model')}"
    return make_schedule(problem, schedule.solver, termination, *start.decisions, bound=bound,
                         solve_seconds=schedule.solve_seconds, seed=schedule.seed, extras=extras)
