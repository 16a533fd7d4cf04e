"""Local search on continuous delays: mend a nearly feasible point, shift flights left, insert cancelled ones.

Each move takes one flight out and puts it back at the *earliest* delay that every operated
partner allows (the gap ends of its forbidden intervals, its aircraft's turnarounds before and
after it, its delay bound), or leaves it cancelled when no delay does:

- :func:`mend`: a point that breaks some pair intervals or turnarounds (a relaxation's point,
  discovery.py) loses the later-departing flight of each broken row (and the flights that require
  it), which is then put back, earliest departure first;
- :func:`polish`: passes over the operated flights, each moved to its earliest admissible delay
  (never later than it was), and over the cancelled ones, each inserted where it fits, while the
  objective improves.

Every result passes :func:`uamopt.schedule.model.violations` (the caller checks). Applies where
discovery.py does (pairs, turnarounds, precedence, delay bounds; no ``cumulative`` shape), for an
objective that falls when a flight is added or a delay shrinks (``weighted``, ``lexicographic``).
"""

from __future__ import annotations

import numpy as np

from uamopt.schedule.model import SchedulingProblem, evaluate

PASSES = 3  # polish: at most this many passes over the flights


class Neighbours:
    """Per flight, the rows that bind it: pair intervals as windows of its own delay given a partner's,
    and turnarounds as bounds."""

    def __init__(self, problem: SchedulingProblem) -> None:
        from uamopt.solvers.discovery import Constraints

        c = Constraints.of(problem)
        n = problem.n_flights
        # z = d_q − d_p ∉ (lo, hi): d_q ∉ (d_p + lo, d_p + hi); d_p ∉ (d_q − hi, d_q − lo)
        who = np.concatenate([c.q, c.p])
        other = np.concatenate([c.p, c.q])
        lo = np.concatenate([c.lo, -c.hi])
        hi = np.concatenate([c.hi, -c.lo])
        order = np.argsort(who, kind="stable")
        self.w_ptr = np.searchsorted(who[order], np.arange(n + 1))
        self.w_other, self.w_lo, self.w_hi = other[order], lo[order], hi[order]
        # turnaround d_f − d_e ≥ need: f ≥ d_e + need (after), e ≤ d_f − need (before)
        order = np.argsort(c.tf, kind="stable")
        self.a_ptr = np.searchsorted(c.tf[order], np.arange(n + 1))
        self.a_other, self.a_need = c.te[order], c.need[order]
        order = np.argsort(c.te, kind="stable")
        self.b_ptr = np.searchsorted(c.te[order], np.arange(n + 1))
        self.b_other, self.b_need = c.tf[order], c.need[order]
        self.upper = np.asarray(problem.delay_upper_s, dtype=float)
        self.needs: dict[int, list[np.ndarray]] = {}  # precedence: f operates only with one of each group
        self.dependants: dict[int, list[int]] = {}
        for family in problem.of_shape("precedence"):
            for f, group in family.groups():
                self.needs.setdefault(f, []).append(group)
                for r in group.tolist():
                    self.dependants.setdefault(r, []).append(f)
        self.must = np.asarray(problem.must_operate, dtype=bool)
        self.objective = problem.objective

    def earliest(self, f: int, operated: np.ndarray, delay: np.ndarray, at_least: float = 0.0,
                 jumps: list | None = None) -> float | None:
        """The least delay ≥ ``at_least`` of flight f that no operated partner forbids (None: none).
        ``jumps`` collects the delays the search jumps to (turnaround bound, window ends), in order."""
        a, b = self.a_ptr[f], self.a_ptr[f + 1]
        on = operated[self.a_other[a:b]]
        lb = max(at_least, float(np.max(delay[self.a_other[a:b]][on] + self.a_need[a:b][on], initial=0.0)))
        a, b = self.b_ptr[f], self.b_ptr[f + 1]
        on = operated[self.b_other[a:b]]
        ub = min(float(self.upper[f]), float(np.min(delay[self.b_other[a:b]][on] - self.b_need[a:b][on], initial=np.inf)))
        a, b = self.w_ptr[f], self.w_ptr[f + 1]
        on = operated[self.w_other[a:b]]
        base = delay[self.w_other[a:b]][on]
        lo, hi = base + self.w_lo[a:b][on], base + self.w_hi[a:b][on]
        keep = hi > lb
        lo, hi = lo[keep], hi[keep]
        d = lb
        if jumps is not None and lb > at_least:
            jumps.append(lb)
        for j in np.argsort(lo, kind="stable").tolist():  # one pass suffices (intervals by their starts)
            if lo[j] < d < hi[j]:
                d = float(hi[j])
                if jumps is not None:
                    jumps.append(d)
            elif lo[j] >= d:
                break
        return d if d <= ub else None

    def gain(self, f: int, d: float) -> float:
        """The objective's change when flight f is added with delay d (negative: better)."""
        o = self.objective
        return float(o.delay_cost(np.array([d]), np.array([f]))[0]) - o.per_flight

    def allowed(self, f: int, operated: np.ndarray) -> bool:
        """Whether f's precedence groups each have an operated member."""
        return all(operated[g].any() for g in self.needs.get(f, ()))

    def drop(self, f: int, operated: np.ndarray, delay: np.ndarray) -> list[int]:
        """Cancel f and every flight left without its required group; returns the cancelled flights."""
        out, todo = [], [f]
        while todo:
            g = todo.pop()
            if not operated[g]:
                continue
            operated[g], delay[g] = False, 0.0
            out.append(g)
            todo += [h for h in self.dependants.get(g, ()) if operated[h] and not self.allowed(h, operated)]
        return out


def _insert(nb: Neighbours, flights: list[int], operated: np.ndarray, delay: np.ndarray, dep: np.ndarray) -> None:
    """Put ``flights`` back (earliest departure first; a required flight before those needing it) where they fit."""
    pending = sorted(flights, key=lambda g: (dep[g], g))
    progress = True
    while pending and progress:
        progress, left = False, []
        for g in pending:
            if not nb.allowed(g, operated):
                left.append(g)
                continue
            d = nb.earliest(g, operated, delay)
            if d is not None and nb.gain(g, d) < 0:
                operated[g], delay[g] = True, d
                progress = True
            else:
                left.append(g)
        pending = left


def mend(problem: SchedulingProblem, nb: Neighbours, operated: np.ndarray, delay_s: np.ndarray
         ) -> tuple[np.ndarray, np.ndarray]:
    """A feasible schedule from a point that breaks some rows (module docstring)."""
    from uamopt.solvers.discovery import Constraints

    operated, delay = operated.copy(), np.where(operated, delay_s, 0.0)
    dep = problem.planned_departure_s + delay
    cons = Constraints.of(problem)
    out: list[int] = []
    for f in np.flatnonzero(operated).tolist():  # a flight operated without its required one
        if operated[f] and not nb.allowed(f, operated):
            out += nb.drop(f, operated, delay)
    for _ in range(problem.n_flights + 1):
        pair, turn = cons.broken(operated, delay)
        if not len(pair) and not len(turn):
            break
        p = np.concatenate([cons.p[pair], cons.te[turn]])
        q = np.concatenate([cons.q[pair], cons.tf[turn]])
        later = np.where(dep[q] >= dep[p], q, p)
        for g in np.unique(later).tolist():
            if operated[g]:
                out += nb.drop(g, operated, delay)
    _insert(nb, out, operated, delay, dep)
    return operated, delay


def polish(problem: SchedulingProblem, nb: Neighbours, operated: np.ndarray, delay_s: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    """Left shifts and insertions while the objective improves (module docstring)."""
    operated, delay = operated.copy(), np.where(operated, delay_s, 0.0)
    value = evaluate(problem, operated, delay)
    dep0 = problem.planned_departure_s
    for _ in range(PASSES):
        for f in np.argsort(dep0 + delay, kind="stable").tolist():
            if operated[f] and delay[f] > 0:
                was = delay[f]
                operated[f] = False
                d = nb.earliest(f, operated, delay)
                operated[f] = True
                if d is not None and d < was:
                    delay[f] = d
        _insert(nb, [g for g in np.flatnonzero(~operated).tolist()], operated, delay, dep0 + delay)
        new = evaluate(problem, operated, delay)
        if new >= value - 1e-12:
            break
        value = new
    return operated, delay
