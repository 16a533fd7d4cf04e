"""Large-neighbourhood search on continuous delays: free a window of flights, fix the rest, solve it exactly.

Neighbourhoods are of two kinds, taken in turn in each pass:

- *time windows*: ``size`` consecutive flights by planned departure, advanced by half a window
  (every other pass shifted by a quarter window, so the windows' edges move);
- *aircraft groups*: the whole days of about ``size`` / (flights per aircraft) aircraft, drawn at
  random (seeded by the pass): a delay that runs down an aircraft's turnaround chain crosses every
  time window's edge, and only a neighbourhood along the chain can move it. On plan seed 2 of
  ``benchmark_1000``, a schedule no time window of 250 flights could improve fell by 2.81 in one
  pass of aircraft groups (12 s), against 0.39 for windows shifted by a quarter.

A neighbourhood's flights are *free*; every operated flight outside it that can bind one of them
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

WINDOW = 250  # flights per neighbourhood
WINDOW_S = 20.0  # at most this many seconds per window's solve


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


def _solve_free(problem: SchedulingProblem, small: SchedulingProblem, operated: np.ndarray, delay: np.ndarray,
                free: np.ndarray, deadline: float, threads: int, seed: int):
    """The window ``free`` solved exactly with the operated flights around it fixed (module docstring):
    (global indices of the free flights, their operated flags, delays, proved) or None."""
    from uamopt.solvers.discovery import discover
    from uamopt.solvers.rolling import subproblem
    from uamopt.solvers.warmstart import reduced

    free, fixed = _neighbourhood(small, free, operated)
    if not len(free):
        return None
    sub, index, is_fixed = subproblem(small, free, fixed, small.planned_departure_s + delay)
    start = (operated[index].copy(), np.where(is_fixed, 0.0, delay[index]))
    found = discover(sub, reduced(sub), deadline, threads, seed, start=start, cliques=False, exact_repair=False)
    if found.operated is None or found.delay_s is None or not np.all(found.operated[is_fixed]):
        return None
    keep = ~is_fixed
    return index[keep], found.operated[keep], np.where(found.operated[keep], found.delay_s[keep], 0.0), found.proved


def repair(problem: SchedulingProblem, small: SchedulingProblem, operated: np.ndarray, delay_s: np.ndarray,
           flights: np.ndarray, deadline: float, threads: int, seed: int) -> tuple[np.ndarray, np.ndarray] | None:
    """A schedule from a point whose only broken rows are among ``flights``: those flights are freed,
    every other operated flight is fixed where the point put it, and each group of freed flights that
    share a row (a pair, a turnaround, an aircraft) is solved exactly on its own. None when a group
    finds no schedule in time or the result breaks a row."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    operated, delay = operated.copy(), np.where(operated, delay_s, 0.0)
    n = problem.n_flights
    freed = np.zeros(n, dtype=bool)
    freed[flights] = True
    view = problem.pairs
    aircraft = problem.flights.aircraft_index
    t = problem.turnaround
    a = np.concatenate([view.p, t.e])
    b = np.concatenate([view.q, t.f])
    link = freed[a] & freed[b]
    graph = coo_matrix((np.ones(int(link.sum())), (a[link], b[link])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    label = np.where(freed, label, -1)
    same: dict[int, list[int]] = {}  # flights of one aircraft in one group: their chain rows bind them together
    for f in np.flatnonzero(freed).tolist():
        same.setdefault(int(aircraft[f]), []).append(f)
    for chain in same.values():
        label[chain] = label[chain[0]]
    operated[freed], delay[freed] = False, 0.0  # the groups' solves decide them
    for group in np.unique(label[label >= 0]).tolist():
        if time.perf_counter() > deadline:
            return None
        solved = _solve_free(problem, small, operated, delay, np.flatnonzero(label == group), deadline, threads, seed)
        if solved is None:
            return None
        index, op, d, _ = solved
        operated[index], delay[index] = op, d
    if violations(problem, operated, delay):
        return None
    return operated, delay


def neighbourhoods(problem: SchedulingProblem, size: int, seed: int, pass_index: int) -> list[tuple[int, np.ndarray]]:
    """The neighbourhoods of one pass (module docstring), each as (a label: the window's first rank, or
    −1 − the group's number, sorted flight indices)."""
    n = problem.n_flights
    order = np.argsort(problem.planned_departure_s, kind="stable")
    step = max(1, size // 2)
    shift = (size // 4) if pass_index % 2 else 0
    out = [(lo, np.sort(order[lo:lo + size])) for lo in range(shift, max(shift + 1, n - step), step)]
    if shift:  # the flights before the shifted first window
        out.insert(0, (0, np.sort(order[:shift])))
    aircraft = problem.flights.aircraft_index
    names = np.unique(aircraft)
    if len(names) > 1:
        per = max(1, round(size * len(names) / max(1, n)))
        if per < len(names):  # more than one group: otherwise the one group is the whole problem
            drawn = np.random.default_rng([seed, pass_index]).permutation(names)
            for g, i in enumerate(range(0, len(drawn), per)):
                out.append((-1 - g, np.flatnonzero(np.isin(aircraft, drawn[i:i + per]))))
    return out


def improve(problem: SchedulingProblem, small: SchedulingProblem, operated: np.ndarray, delay_s: np.ndarray,
            deadline: float, threads: int, seed: int, size: int = WINDOW, window_s: float = WINDOW_S,
            log=None, pass_index: int = 0) -> tuple[np.ndarray, np.ndarray, int]:
    """One pass of neighbourhoods (module docstring; ``pass_index`` chooses the windows' shift and the
    aircraft groups' draw) until ``deadline``; returns the decisions and how many neighbourhoods
    improved them."""
    operated, delay = operated.copy(), np.where(operated, delay_s, 0.0)
    value = evaluate(problem, operated, delay)
    better = 0
    for lo, free in neighbourhoods(small, size, seed, pass_index):
        if time.perf_counter() > deadline - 0.5:
            break
        solved = _solve_free(problem, small, operated, delay, free,
                             min(deadline, time.perf_counter() + window_s), threads, seed)
        if solved is None:
            continue
        index, op, d, proved = solved
        new_op, new_d = operated.copy(), delay.copy()
        new_op[index], new_d[index] = op, d
        new_value = evaluate(problem, new_op, new_d)
        if new_value < value - 1e-9 and not violations(problem, new_op, new_d):
            operated, delay, value = new_op, new_d, new_value
            better += 1
        if log is not None:
            log(lo, len(index), proved, value)
    return operated, delay, better
