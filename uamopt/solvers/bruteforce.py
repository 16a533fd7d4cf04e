"""An exact reference for *tiny* instances (≤ ``MAX_FLIGHTS`` flights): a test oracle, not a solver.

It shares nothing with ``milp.py`` or ``cpsat.py`` beyond the model data of
:class:`SchedulingProblem` (Sec. 4.3) and its core (``problem.objective``, the admissible gaps of
``problem.pairs``, ``problem.must_operate``; uamopt.schedule.core, tested on its own against
hand-made pairs) and enumerates instead of modelling:

1. every operate/cancel vector c ∈ {0, 1}ⁿ that keeps the precedence (a return needs its
   outbound) and operates every must-operate flight, most operated flights first;
2. for a fixed c the objective (Eqs. 20-22) only needs the least total delay Σ d_f. Each pair
   of operated flights with forbidden open intervals of δ = dep_q − dep_p must put δ in one of
   the closed gaps between them (within δ's reachable range); for a fixed choice of gaps every
   constraint — the gap, the turnaround of Eqs. 27-28 between every two operated flights of an
   aircraft, 0 ≤ d_f ≤ U_f (Eqs. 26, 29) — is linear, so the least Σ d is an LP, solved by
   ``scipy.optimize.linprog`` (HiGHS). The gap choices are enumerated depth first; a partial
   choice is an LP relaxation of its completions, so a branch is cut when its LP is infeasible
   or already no better than the best completion found (exact pruning).
   A ``cumulative`` family (vertiport pads with n > 1) branches the same way: for every n + 1
   operated holds of one resource, one of them ends before another starts.
3. c vectors are abandoned once −ω7·S (the objective with zero delay) cannot beat the best.

Register nothing: call ``solve(problem, profile)`` (same signature as the solvers) from tests.
"""

from __future__ import annotations

import itertools
import time
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import linprog

from uamopt.errors import UamoptError
from uamopt.schedule.model import Schedule, SchedulingProblem, make_schedule

if TYPE_CHECKING:
    from uamopt.solvers import SolverProfile

SHAPES = frozenset({"bounds", "must_operate", "precedence", "turnaround", "pairs", "cumulative"})  # every shape
OBJECTIVES = frozenset({"weighted", "lexicographic", "earliness_tardiness"})
MAX_FLIGHTS = 10  # 2¹⁰ operate vectors; beyond that use ``highs``
LP_TOL = 1e-7  # the LP's own accuracy on Σ d, s


def _lp(problem: SchedulingProblem, flown: list[int], rows: list[tuple[int, int, float]]):
    """min Σ d (the linear kinds) or Σ e_f E_f + l_f L_f (earliness/tardiness, with E_f ≥ a_f − d_f,
    L_f ≥ d_f − a_f, both ≥ 0) over the operated flights s.t. d_i − d_j ≤ b for (i, j, b) in rows,
    0 ≤ d ≤ U. Returns (the delay part of the objective, d) or None if infeasible."""
    o = problem.objective
    m = len(flown)
    extra = 2 * m if o.per_flight_terms else 0
    col = {f: k for k, f in enumerate(flown)}
    a_ub = np.zeros((len(rows) + extra, m + extra))
    b_ub = np.zeros(len(rows) + extra)
    for r, (i, j, b) in enumerate(rows):
        a_ub[r, col[i]] += 1.0
        a_ub[r, col[j]] -= 1.0
        b_ub[r] = b
    bounds: list[tuple[float, float | None]] = [(0.0, float(problem.delay_upper_s[f])) for f in flown]
    if o.per_flight_terms:
        target, early, late = o.terms
        cost = np.concatenate([np.zeros(m), early[flown], late[flown]])
        for k, f in enumerate(flown):
            r = len(rows) + 2 * k
            a_ub[r, k], a_ub[r, m + k], b_ub[r] = -1.0, -1.0, -float(target[f])  # a − d ≤ E
            a_ub[r + 1, k], a_ub[r + 1, 2 * m + k], b_ub[r + 1] = 1.0, -1.0, float(target[f])  # d − a ≤ L
        bounds += [(0.0, None)] * extra
    else:
        cost = np.ones(m)
    res = linprog(cost, A_ub=a_ub if len(b_ub) else None, b_ub=b_ub if len(b_ub) else None, bounds=bounds, method="highs")
    if res.status == 2:
        return None
    if res.status != 0:
        raise UamoptError(f"linprog failed: {res.message}", "bruteforce", "this is a test oracle; report it")
    d = res.x[:m]
    return (float(res.fun) if o.per_flight_terms else float(res.fun) * o.per_delay), d


def _cumulative_choices(res, operated: np.ndarray, dep: np.ndarray) -> list:
    """Capacity n at a resource ⇔ no n + 1 operated holds pairwise overlap (intervals: Helly), so for
    every n + 1 of them one pair is disjoint, one before the other: a choice of linear rows
    (a before b: dep_a + d_a + o_a + l_a ≤ dep_b + d_b + o_b)."""
    out = []
    for r in np.unique(res.resource).tolist():
        ev = [k for k in np.flatnonzero(res.resource == r).tolist() if operated[res.flight[k]]]
        for subset in itertools.combinations(ev, int(res.capacity[r]) + 1):
            choice = []
            for a, b in itertools.permutations(subset, 2):
                fa, fb = int(res.flight[a]), int(res.flight[b])
                bound = dep[fb] + res.offset_s[b] - dep[fa] - res.offset_s[a] - res.duration_s[a]
                choice.append([(fa, fb, float(bound))])
            out.append(choice)
    return out


def least_delay(problem: SchedulingProblem, operated: np.ndarray) -> tuple[float, np.ndarray] | None:
    """The least delay cost (per_delay · Σ d, or the earliness/tardiness sum) and its delays for the
    operate vector ``operated``, or None if none is feasible."""
    dep = problem.planned_departure_s
    flown = [int(f) for f in np.flatnonzero(operated)]
    if not flown:
        return 0.0, np.zeros(problem.n_flights)
    t = problem.turnaround  # d_f − d_e ≥ need  ⇔  d_e − d_f ≤ −need (families/turnaround.py)
    both = operated[t.e] & operated[t.f]
    fixed = list(zip(t.e[both].tolist(), t.f[both].tolist(), (-t.need_s[both]).tolist(), strict=True))
    branching = []
    view = problem.pairs  # the admissible-gap view (uamopt.schedule.core)
    for k, (p, q) in enumerate(zip(view.p.tolist(), view.q.tolist(), strict=True)):
        gaps = view.gaps_of(k)
        if not (operated[p] and operated[q]):
            continue
        if not gaps:
            return None
        # δ ∈ [a, b]  ⇔  d_p − d_q ≤ ΔD − a  and  d_q − d_p ≤ b − ΔD
        shift = dep[q] - dep[p]
        branching.append([[(p, q, shift - a), (q, p, b - shift)] for a, b in gaps])
    for family in problem.of_shape("cumulative"):
        branching += _cumulative_choices(family.residual(), operated, dep)
    branching.sort(key=len)
    best: list = [np.inf, None]
    tol = LP_TOL * max(problem.objective.per_delay, 1e-300) if not problem.objective.per_flight_terms else LP_TOL

    def dfs(depth: int, rows: list) -> None:
        found = _lp(problem, flown, rows)
        if found is None or found[0] >= best[0] - tol:
            return
        if depth == len(branching):
            best[:] = list(found)
            return
        for choice in branching[depth]:
            dfs(depth + 1, rows + choice)

    dfs(0, fixed)
    if best[1] is None:
        return None
    delay = np.zeros(problem.n_flights)
    delay[flown] = np.clip(best[1], 0.0, problem.delay_upper_s[flown])
    o = problem.objective
    fixed_cost = 0.0 if o.operate_cost_s is None else o.per_delay * float(np.sum(o.operate_cost_s[flown]))
    if not o.per_flight_terms:  # the clipped delays' own Σ d
        return o.per_delay * float(delay.sum()) + fixed_cost, delay
    return float(problem.objective.delay_cost(delay[flown], np.asarray(flown)).sum()), delay


def solve(problem: SchedulingProblem, profile: SolverProfile | None = None) -> Schedule:
    """The exact optimum by enumeration (see the module docstring); ``profile`` is ignored.

    Raises
    ------
    UamoptError
        More than ``MAX_FLIGHTS`` flights.
    """
    n = problem.n_flights
    if n > MAX_FLIGHTS:
        raise UamoptError(f"{n} flights is too many for the brute force", "bruteforce",
                          f"use at most {MAX_FLIGHTS} or the highs solver")
    start = time.perf_counter()
    must, objective = problem.must_operate, problem.objective
    groups = [g for family in problem.of_shape("precedence") for g in family.groups()]
    vectors = [np.array(c, dtype=bool) for c in itertools.product((True, False), repeat=n)]
    vectors = [c for c in vectors if all(not c[f] or c[group].any() for f, group in groups) and c[must].all()]
    vectors.sort(key=lambda c: -int(c.sum()))  # stable: ties keep the product order
    best_value, best = np.inf, None
    for c in vectors:
        if -objective.per_flight * int(c.sum()) >= best_value - 1e-12:
            break  # every later vector operates no more flights, and a delay costs ≥ 0
        found = least_delay(problem, c)
        if found is not None and found[0] - objective.per_flight * int(c.sum()) < best_value:
            best_value, best = found[0] - objective.per_flight * int(c.sum()), (c, found[1])
    if best is None:  # only with must-operate flights: cancelling every other flight is always feasible
        return make_schedule(problem, "bruteforce", "infeasible", np.zeros(n, bool), np.zeros(n), proved_for="continuous",
                             solve_seconds=time.perf_counter() - start, extras={"vectors": len(vectors)})
    return make_schedule(problem, "bruteforce", "optimal", best[0], best[1], proved_for="continuous", bound=best_value,
                         solve_seconds=time.perf_counter() - start, extras={"vectors": len(vectors)})
