"""Large-neighbourhood search on continuous delays: free a window of flights, fix the rest, solve it exactly.

Neighbourhoods are windows of ``size`` consecutive flights by planned departure, advanced by half a
window. A window's flights are *free*; every operated flight outside it that can bind one of them
(a conflict partner, any flight of one of their aircraft, the outbound a free return requires)
is *fixed* at its decided departure and must operate (rolling.py's :func:`subproblem`, whose
sub-problem's objective is the whole problem's restricted to the window plus a constant). A free
return whose outbound is cancelled outside the window stays cancelled. The sub-problem is solved
by discovery.py (exact for continuous delays when it proves its point), started from the current
decisions, and its schedule replaces the window's decisions when the whole schedule still passes
:func:`~uamopt.schedule.model.violations` and its objective falls. So a pass never makes the
schedule worse, and each window's result is optimal for that window given the rest when proved.
"""

from __future__ import annotations

import time

import numpy as np

from uamopt.schedule.model import SchedulingProblem, evaluate, violations

WINDOW = 80  # flights per neighbourhood
WINDOW_S = 3.0  # at most this many seconds per window's solve


def _neighbourhood(problem: SchedulingProblem, free: np.ndarray, operated: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(free, fixed): the window's flights (less returns whose outbound is cancelled outside it) and the
    operated flights outside it that can bind them."""
    n = problem.n_flights
    is_free = np.zeros(n, dtype=bool)
    is_free[free] = True
    req = problem.requires
    orphan = is_free & (req >= 0) & ~is_free[np.maximum(req, 0)] & ~operated[np.maximum(req, 0)]
    is_free &= ~orphan
    view = problem.pairs
    touch = np.zeros(n, dtype=bool)
    touch[view.p[is_free[view.q]]] = True
    touch[view.q[is_free[view.p]]] = True
    aircraft = problem.flights.aircraft_index
    touch |= np.isin(aircraft, np.unique(aircraft[is_free]))
    touch[req[is_free & (req >= 0)]] = True
    fixed = touch & ~is_free & operated
    return np.flatnonzero(is_free), np.flatnonzero(fixed)


def improve(problem: SchedulingProblem, small: SchedulingProblem, operated: np.ndarray, delay_s: np.ndarray,
            deadline: float, threads: int, seed: int, size: int = WINDOW, log=None) -> tuple[np.ndarray, np.ndarray, int]:
    """One pass of windows over the day (module docstring) until ``deadline``; returns the decisions and
    how many windows improved them."""
    from uamopt.solvers.discovery import discover
    from uamopt.solvers.rolling import subproblem
    from uamopt.solvers.warmstart import reduced

    operated, delay = operated.copy(), np.where(operated, delay_s, 0.0)
    value = evaluate(problem, operated, delay)
    order = np.argsort(small.planned_departure_s, kind="stable")
    better = 0
    for lo in range(0, max(1, len(order) - size // 2), max(1, size // 2)):
        if time.perf_counter() > deadline - 0.5:
            break
        free, fixed = _neighbourhood(small, order[lo:lo + size], operated)
        if not len(free):
            continue
        sub, index, is_fixed = subproblem(small, free, fixed, small.planned_departure_s + delay)
        start = (operated[index].copy(), np.where(is_fixed, 0.0, delay[index]))
        found = discover(sub, reduced(sub), min(deadline, time.perf_counter() + WINDOW_S), threads, seed,
                         start=start, cliques=False)
        if found.operated is None or found.delay_s is None or not np.all(found.operated[is_fixed]):
            continue
        new_op, new_d = operated.copy(), delay.copy()
        new_op[index[~is_fixed]] = found.operated[~is_fixed]
        new_d[index[~is_fixed]] = np.where(found.operated[~is_fixed], found.delay_s[~is_fixed], 0.0)
        new_value = evaluate(problem, new_op, new_d)
        if new_value < value - 1e-9 and not violations(problem, new_op, new_d):
            operated, delay, value = new_op, new_d, new_value
            better += 1
        if log is not None:
            log(lo, len(free), len(fixed), found.proved, value)
    return operated, delay, better
