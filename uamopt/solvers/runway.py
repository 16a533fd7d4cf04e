"""One runway: a Lagrangian path bound and sequence schedules for problems in which every pair of
flights is separated (the aircraft-landing problem, Beasley et al. 2000; any :class:`SchedulingProblem`
of that shape).

**The shape** (:func:`of`). Every flight operates; the only constraints are the delay bounds and
one forbidden interval (−S_qp, S_pq) of δ = x_q − x_p for *every* pair p < q, with S ≥ 1 both ways
(two flights never share a time); no turnaround, precedence or pad rows; every time of the data
(planned departures, delay bounds, separations, the earliness/tardiness targets) a whole number of
seconds. Then an optimum with whole-second times exists: with the landing order fixed, the
constraints x_q − x_p ≥ S_pq and the windows form a totally unimodular system with whole right-hand
sides, and the objective is piecewise linear with whole breakpoints. So a bound on whole-second
schedules is a bound for continuous times.

**The bound.** Flights fall into classes of identical separation rows and columns (airland9–13:
four). A *path* is a sequence of landings (flight j at whole time t ∈ its window) in which
consecutive landings of classes a, b are at least sep(a, b) apart and no flight lands twice in a
row (with ``two_cycle``: nor p, q, p); it may skip flights and repeat others. Every schedule's
landing order is such a path (its consecutive pairs are separated), so with multipliers λ_j on
"flight j lands once",

    L(λ) = Σ_j λ_j + min over paths Σ_(j,t) ∈ path (c_j(t) − λ_j)

is a lower bound of every schedule for every λ (Lagrangian relaxation of the time-indexed
formulation with sequence-dependent separation: the arc-time-indexed bound of Pessoa, Uchoa,
Poggi de Aragão and Rodrigues, *Exact algorithm over an arc-time-indexed formulation for parallel
machine scheduling problems*, Math. Prog. Comp. 2, 2010, with classes in place of jobs, and the
usual one- and two-cycle elimination). The best path is a dynamic programme over time with, per
class and time, the best labels so far as prefix minima: O(n · W · C) per λ, W the window length,
C the classes (:func:`_best_path`, :func:`_best_path2`, compiled by numba). λ follows subgradient
steps (Polyak's, towards the best schedule's value).

**Fixing.** :func:`through` bounds every schedule that uses a given landing; the landings whose
bound exceeds the best schedule's value are in no better schedule, and what is left of each window
(:func:`windows_after_fixing`) bounds the exact model (:func:`exact_in_windows`).

**Schedules.** Each path read as an order (a flight's mean landing time in it; a skipped flight at
its target), the best times for that order by an LP (HiGHS; every pair of the order separated,
added where broken: :func:`timed`), then neighbourhoods of consecutive landings solved exactly
within the windows (:func:`neighbourhoods`).

Measured on airland9 (100 aircraft, 4 classes; optimum 5,611.70): HiGHS on the big-M model reaches
a bound of 3,421 in 300 s; paths with repeats converge to 5,127.47 (the LP of the class-flow
formulation, solved by HiGHS in 211 s to the same value); without p, p to 5,552.2; without p, q, p
the path becomes a schedule of 5,611.70 within 5 s (docs/exact_scheduling.md, *One runway*).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from numba import njit

from uamopt.schedule.model import SchedulingProblem

#: at most this many flights (the separation matrix is n × n)
MAX_FLIGHTS = 6000
#: the data's times must be whole numbers to this tolerance, s
WHOLE_TOL = 1e-9


def _compiled(func):
    """``func`` compiled by numba, cached on disk where a cache folder is writable
    (uamopt/planning/search.py does the same)."""
    try:
        return njit(cache=True)(func)
    except RuntimeError:
        return njit(func)


@dataclass(frozen=True, eq=False)
class Runway:
    """A one-runway problem on whole seconds: flight j may land at times start[j] + k, k < length[j]
    (time 0 = the earliest planned departure), at cost cost[offset[j] + k]."""

    start: np.ndarray  # (n,) int64
    length: np.ndarray  # (n,) int64: U_j + 1
    offset: np.ndarray  # (n + 1,) int64
    cost: np.ndarray  # (offset[-1],) float: the objective's part of flight j at delay k
    sep: np.ndarray  # (n, n) int64: sep[p, q] = S_pq, the least time from p's landing to q's when p lands first
    cls: np.ndarray  # (n,) int64: the separation class of each flight
    class_sep: np.ndarray  # (C, C) int64
    constant: float  # the objective's part that no decision changes (−per_flight · n)

    @property
    def n(self) -> int:
        return int(self.start.size)

    @property
    def horizon(self) -> int:
        return int(np.max(self.start + self.length))


def _whole(values) -> bool:
    v = np.asarray(values, dtype=float)
    return bool(np.all(np.isfinite(v)) and np.all(np.abs(v - np.round(v)) <= WHOLE_TOL))


def of(problem: SchedulingProblem) -> Runway | str:
    """The problem as a :class:`Runway`, or why it is not of that shape (one phrase)."""
    n = problem.n_flights
    if n < 2:
        return "fewer than two flights"
    if n > MAX_FLIGHTS:
        return f"more than {MAX_FLIGHTS} flights"
    if not bool(np.all(problem.must_operate)):
        return "a flight that may be cancelled"
    shapes = {f.shape for f in problem.families} - {"bounds", "must_operate", "pairs", "precedence", "turnaround"}
    if shapes:
        return f"a family of shape {sorted(shapes)[0]}"
    if problem.of_shape("turnaround") and len(problem.turnaround) > 0:
        return "turnaround rows"
    try:
        if np.any(problem.requires >= 0):
            return "precedence rows"
    except AttributeError:
        return "precedence rows"
    pairs = problem.pairs
    m = n * (n - 1) // 2
    counts = np.diff(pairs.ptr)
    if len(pairs) != m or np.any(counts != 1):
        return "a pair of flights that is not separated by exactly one interval"
    key = pairs.p * n + pairs.q
    if np.any(pairs.p >= pairs.q) or np.unique(key).size != m:
        return "a pair of flights that is not separated by exactly one interval"
    lo, hi = pairs.lo[pairs.ptr[:-1]], pairs.hi[pairs.ptr[:-1]]
    if not (_whole(lo) and _whole(hi)) or np.any(hi < 1) or np.any(-lo < 1):
        return "a separation that is not a whole number of seconds of at least 1 both ways"
    d0, upper = problem.planned_departure_s, problem.delay_upper_s
    if not (_whole(d0) and _whole(upper)):
        return "a planned time or delay bound that is not a whole number of seconds"
    objective = problem.objective
    if objective.per_flight_terms and not _whole(objective.terms[0]):
        return "a target time that is not a whole number of seconds"
    sep = np.zeros((n, n), dtype=np.int64)
    sep[pairs.p, pairs.q] = np.round(hi).astype(np.int64)
    sep[pairs.q, pairs.p] = np.round(-lo).astype(np.int64)
    base = round(float(np.min(d0)))
    start = np.round(d0).astype(np.int64) - base
    length = np.round(upper).astype(np.int64) + 1
    offset = np.zeros(n + 1, dtype=np.int64)
    offset[1:] = np.cumsum(length)
    flight = np.repeat(np.arange(n), length)
    delay = (np.arange(offset[-1]) - offset[flight]).astype(float)
    cost = objective.delay_cost(delay, flight)
    cls, class_sep = _classes(sep)
    return Runway(start=start, length=length, offset=offset, cost=np.ascontiguousarray(cost, dtype=float), sep=sep,
                  cls=cls, class_sep=class_sep, constant=-objective.per_flight * n)


def _classes(sep: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Flights with the same separations to and from every other flight (and the same both ways
    between them) share a class; (cls, class_sep) with class_sep[a, b] the least separation from
    a flight of class a to one of class b (exact within classes)."""
    n = sep.shape[0]
    big = np.iinfo(np.int64).max
    key = np.where(np.eye(n, dtype=bool), -1, sep)
    cls = np.full(n, -1, dtype=np.int64)
    count = 0
    for i in range(n):
        if cls[i] >= 0:
            continue
        free = np.flatnonzero(cls < 0)
        same = np.ones(free.size, dtype=bool)
        others = np.ones(n, dtype=bool)
        for idx, j in enumerate(free):
            if j == i:
                continue
            others[:] = True
            others[np.array([i, j])] = False
            same[idx] = (sep[i, j] == sep[j, i] and np.array_equal(key[i, others], key[j, others])
                         and np.array_equal(key[others, i], key[others, j]))
        cls[free[same]] = count
        cls[i] = count
        count += 1
    class_sep = np.full((count, count), big, dtype=np.int64)
    for a in range(count):
        rows = sep[cls == a]
        for b in range(count):
            block = rows[:, cls == b]
            if a == b:
                members = np.flatnonzero(cls == a)
                block = block[~np.eye(members.size, dtype=bool)] if members.size > 1 else np.empty(0, dtype=np.int64)
            if block.size:
                class_sep[a, b] = int(block.min())
    class_sep[class_sep == big] = 1  # a class of one flight never follows itself (no repeats)
    return cls, class_sep


@_compiled
def _advance(active, na, nxt, order, start, length, t):  # pragma: no cover (compiled)
    """The flights whose window holds time t: ``active[:na]`` kept where still open, then those
    opening at t (``order``: flights by start; ``nxt`` the first not yet opened). Returns (na, nxt)."""
    k = 0
    for i in range(na):
        j = active[i]
        if start[j] + length[j] > t:
            active[k] = j
            k += 1
    na = k
    while nxt < order.size and start[order[nxt]] <= t:
        active[na] = order[nxt]
        na += 1
        nxt += 1
    return na, nxt


@_compiled
def _best_path(start, length, offset, reduced, cls, class_sep, horizon):  # pragma: no cover (compiled)
    """The least-cost path (module docstring) for reduced costs ``reduced`` (flat, like Runway.cost):
    (its value, or 0 for the empty path; its flights and times in order)."""
    n = start.size
    classes = class_sep.shape[0]
    inf = np.inf
    v1 = np.full((classes, horizon), inf)
    j1 = np.full((classes, horizon), -1, dtype=np.int64)
    w1 = np.full((classes, horizon), -1, dtype=np.int64)
    v2 = np.full((classes, horizon), inf)
    j2 = np.full((classes, horizon), -1, dtype=np.int64)
    w2 = np.full((classes, horizon), -1, dtype=np.int64)
    pred_j = np.full(offset[n], -1, dtype=np.int64)
    pred_t = np.full(offset[n], -1, dtype=np.int64)
    ending = np.full(offset[n], np.inf)
    order = np.argsort(start, kind="mergesort")
    active = np.empty(n, dtype=np.int64)
    na = 0
    nxt = 0
    best = 0.0
    best_j = -1
    best_t = -1
    for t in range(horizon):
        na, nxt = _advance(active, na, nxt, order, start, length, t)
        if t > 0:
            for a in range(classes):
                v1[a, t] = v1[a, t - 1]
                j1[a, t] = j1[a, t - 1]
                w1[a, t] = w1[a, t - 1]
                v2[a, t] = v2[a, t - 1]
                j2[a, t] = j2[a, t - 1]
                w2[a, t] = w2[a, t - 1]
        for i in range(na):
            j = active[i]
            b = cls[j]
            prev = 0.0
            pj = -1
            pt = -1
            for a in range(classes):
                q = t - class_sep[a, b]
                if q < 0:
                    continue
                if j1[a, q] != j:
                    val = v1[a, q]
                    jj = j1[a, q]
                    tt = w1[a, q]
                else:
                    val = v2[a, q]
                    jj = j2[a, q]
                    tt = w2[a, q]
                if val < prev:
                    prev = val
                    pj = jj
                    pt = tt
            idx = offset[j] + t - start[j]
            value = reduced[idx] + prev
            ending[idx] = value
            pred_j[idx] = pj
            pred_t[idx] = pt
            if value < best:
                best = value
                best_j = j
                best_t = t
            if value < v1[b, t]:
                if j1[b, t] != j:
                    v2[b, t] = v1[b, t]
                    j2[b, t] = j1[b, t]
                    w2[b, t] = w1[b, t]
                v1[b, t] = value
                j1[b, t] = j
                w1[b, t] = t
            elif value < v2[b, t] and j != j1[b, t]:
                v2[b, t] = value
                j2[b, t] = j
                w2[b, t] = t
    size = 0
    j = best_j
    t = best_t
    while j >= 0:
        size += 1
        idx = offset[j] + t - start[j]
        j, t = pred_j[idx], pred_t[idx]
    flights = np.empty(size, dtype=np.int64)
    times = np.empty(size, dtype=np.int64)
    j = best_j
    t = best_t
    for k in range(size - 1, -1, -1):
        flights[k] = j
        times[k] = t
        idx = offset[j] + t - start[j]
        j, t = pred_j[idx], pred_t[idx]
    return best, flights, times, ending


#: entries kept per class and time by the two-cycle programme (the best K labels; when all K are
#: excluded for a flight, the one-cycle programme's best stands in, a smaller value: still a bound)
KEEP = 8


@_compiled
def _insert(ev, ej, ep, et, el, ecount, b, t, value, j, p, when, label):  # pragma: no cover (compiled)
    """Put the label (value, flight j, predecessor p, time, label) into one class-and-time list,
    sorted by value, keeping per flight only its best label and its best with another predecessor
    (all a query "not flight k, not after k" needs), and at most len(ev) labels."""
    keep = ev.size
    c = ecount[b, t]
    same = -1
    first = -1
    second = -1
    for e in range(c):
        if ej[e] == j:
            if ep[e] == p:
                same = e
            if first < 0:
                first = e
            else:
                second = e
    drop = -1
    if same >= 0:
        if value >= ev[same]:
            return
        drop = same
    elif second >= 0:  # the flight has two labels already: the new one replaces the worse if better
        if value >= ev[second]:
            return
        drop = second
    elif c == keep:
        if value >= ev[keep - 1]:
            return
        drop = keep - 1
    if drop >= 0:
        for e in range(drop, c - 1):
            ev[e] = ev[e + 1]
            ej[e] = ej[e + 1]
            ep[e] = ep[e + 1]
            et[e] = et[e + 1]
            el[e] = el[e + 1]
        c -= 1
    pos = c
    while pos > 0 and ev[pos - 1] > value:
        ev[pos] = ev[pos - 1]
        ej[pos] = ej[pos - 1]
        ep[pos] = ep[pos - 1]
        et[pos] = et[pos - 1]
        el[pos] = el[pos - 1]
        pos -= 1
    ev[pos] = value
    ej[pos] = j
    ep[pos] = p
    et[pos] = when
    el[pos] = label
    ecount[b, t] = c + 1


@_compiled
def _best_path2(start, length, offset, reduced, cls, class_sep, horizon, keep):  # pragma: no cover (compiled)
    """:func:`_best_path` without two-cycles either (no flight lands, then another, then the first
    again): each landing keeps its best label and its best with another predecessor; each class and
    time keeps its ``keep`` best labels. Returns (value, flights, times, best value ending at each
    landing, its predecessor flight (−1: none), best value ending there with another predecessor)."""
    n = start.size
    classes = class_sep.shape[0]
    inf = np.inf
    size = offset[n]
    # per landing: two labels (value, predecessor flight, its time, its label)
    lv = np.full((size, 2), inf)
    lp = np.full((size, 2), -1, dtype=np.int64)
    lt = np.full((size, 2), -1, dtype=np.int64)
    ll = np.full((size, 2), -1, dtype=np.int64)
    # per class and time: the best labels so far, sorted (value, flight, its predecessor, time, label)
    ev = np.full((classes, horizon, keep), inf)
    ej = np.full((classes, horizon, keep), -1, dtype=np.int64)
    ep = np.full((classes, horizon, keep), -1, dtype=np.int64)
    et = np.full((classes, horizon, keep), -1, dtype=np.int64)
    el = np.full((classes, horizon, keep), -1, dtype=np.int64)
    ecount = np.zeros((classes, horizon), dtype=np.int64)
    # the fallback: the best first labels of three distinct flights
    fv = np.full((classes, horizon, 3), inf)
    fj = np.full((classes, horizon, 3), -1, dtype=np.int64)
    fw = np.full((classes, horizon, 3), -1, dtype=np.int64)
    order = np.argsort(start, kind="mergesort")
    active = np.empty(n, dtype=np.int64)
    na = 0
    nxt = 0
    best = 0.0
    best_idx = -1
    best_label = -1
    for t in range(horizon):
        na, nxt = _advance(active, na, nxt, order, start, length, t)
        if t > 0:
            for a in range(classes):
                for e in range(keep):
                    ev[a, t, e] = ev[a, t - 1, e]
                    ej[a, t, e] = ej[a, t - 1, e]
                    ep[a, t, e] = ep[a, t - 1, e]
                    et[a, t, e] = et[a, t - 1, e]
                    el[a, t, e] = el[a, t - 1, e]
                ecount[a, t] = ecount[a, t - 1]
                for e in range(3):
                    fv[a, t, e] = fv[a, t - 1, e]
                    fj[a, t, e] = fj[a, t - 1, e]
                    fw[a, t, e] = fw[a, t - 1, e]
        for i in range(na):
            j = active[i]
            b = cls[j]
            idx = offset[j] + t - start[j]
            for label in range(2):
                # label 0: the best predecessor; label 1: the best whose flight differs from label 0's
                other = lp[idx, 0] if label == 1 else -3
                prev = 0.0
                pj = -1
                pt = -1
                pl = -1
                if label == 1 and other == -1:
                    prev = inf  # label 0 starts the path: label 1 needs a predecessor
                for a in range(classes):
                    q = t - class_sep[a, b]
                    if q < 0:
                        continue
                    found = False
                    for e in range(ecount[a, q]):
                        if ej[a, q, e] != j and ep[a, q, e] != j and ej[a, q, e] != other:
                            if ev[a, q, e] < prev:
                                prev = ev[a, q, e]
                                pj = ej[a, q, e]
                                pt = et[a, q, e]
                                pl = el[a, q, e]
                            found = True
                            break
                    if not found and ecount[a, q] == keep:
                        # every kept label excluded: the best of another flight, whatever came before
                        # it, stands in (no greater: still a bound)
                        val = inf
                        jj = -2
                        tt = -1
                        for e in range(3):
                            if fj[a, q, e] >= 0 and fj[a, q, e] != j and fj[a, q, e] != other:
                                val = fv[a, q, e]
                                jj = fj[a, q, e]
                                tt = fw[a, q, e]
                                break
                        if val < prev:
                            prev = val
                            pj = jj
                            pt = tt
                            pl = 0
                lv[idx, label] = reduced[idx] + prev
                lp[idx, label] = pj
                lt[idx, label] = pt
                ll[idx, label] = pl
            for label in range(2):
                value = lv[idx, label]
                if value == inf:
                    continue
                if value < best:
                    best = value
                    best_idx = idx
                    best_label = label
                _insert(ev[b, t], ej[b, t], ep[b, t], et[b, t], el[b, t], ecount, b, t, value, j, lp[idx, label], t, label)
            value = lv[idx, 0]
            present = -1
            for e in range(3):
                if fj[b, t, e] == j:
                    present = e
                    break
            if present >= 0 and value < fv[b, t, present]:
                for e in range(present, 2):
                    fv[b, t, e] = fv[b, t, e + 1]
                    fj[b, t, e] = fj[b, t, e + 1]
                    fw[b, t, e] = fw[b, t, e + 1]
                fv[b, t, 2] = inf
                fj[b, t, 2] = -1
                fw[b, t, 2] = -1
            if (present < 0 or fj[b, t, present] != j) and value < fv[b, t, 2]:
                pos = 2
                while pos > 0 and fv[b, t, pos - 1] > value:
                    fv[b, t, pos] = fv[b, t, pos - 1]
                    fj[b, t, pos] = fj[b, t, pos - 1]
                    fw[b, t, pos] = fw[b, t, pos - 1]
                    pos -= 1
                fv[b, t, pos] = value
                fj[b, t, pos] = j
                fw[b, t, pos] = t
    # the path, back from its end (a stand-in predecessor of unknown flight ends it early)
    count = 0
    idx = best_idx
    label = best_label
    j = -1
    flights_rev = np.empty(size + 1, dtype=np.int64)
    times_rev = np.empty(size + 1, dtype=np.int64)
    if best_idx >= 0:
        # the flight of a flat index: search offset
        j = np.searchsorted(offset, best_idx, side="right") - 1
        t = start[j] + best_idx - offset[j]
        while j >= 0 and count <= size:
            flights_rev[count] = j
            times_rev[count] = t
            count += 1
            idx = offset[j] + t - start[j]
            nj = lp[idx, label]
            nt = lt[idx, label]
            nl = ll[idx, label]
            if nj < 0 or nt < 0:
                break
            j, t, label = nj, nt, max(nl, 0)
    flights = flights_rev[:count][::-1].copy()
    times = times_rev[:count][::-1].copy()
    return best, flights, times, lv[:, 0].copy(), lp[:, 0].copy(), lv[:, 1].copy()


def path_bound(runway: Runway, lam: np.ndarray, two_cycle: bool = False, keep: int = 0) -> tuple[float, np.ndarray, np.ndarray]:
    """L(λ) (module docstring; a valid lower bound of the objective for every λ) and its path;
    ``two_cycle``: paths without two-cycles either (:func:`_best_path2`, a greater bound; ``keep``
    labels per class and time, default :data:`KEEP`)."""
    reduced = runway.cost - np.repeat(lam, runway.length)
    args = (runway.start, runway.length, runway.offset, reduced, runway.cls, runway.class_sep, runway.horizon)
    if two_cycle:
        value, flights, times, *_ = _best_path2(*args, keep or KEEP)
    else:
        value, flights, times, _ = _best_path(*args)
    return float(lam.sum() + value + runway.constant), flights, times


def through(runway: Runway, lam: np.ndarray, two_cycle: bool = False, keep: int = 0) -> np.ndarray:
    """Per (flight, time) (flat, like Runway.cost): the least L(λ)-value of a path through that
    landing, a lower bound of every schedule that lands that flight at that time (reduced-cost
    fixing: a landing whose value exceeds a schedule's objective is in no better schedule). The
    best path ending there plus the best starting there (the same programme on the reversed time
    line, separations transposed), less the landing counted twice; without two-cycles, the two
    halves may not meet the same neighbour on both sides."""
    reduced = runway.cost - np.repeat(lam, runway.length)
    # reversed time: a landing at t is at horizon − 1 − t; flight j's window reversed, its costs too
    rstart = runway.horizon - (runway.start + runway.length)
    flat = np.arange(runway.offset[-1])
    flight = np.repeat(np.arange(runway.n), runway.length)
    k = flat - runway.offset[flight]
    mirror = runway.offset[flight] + runway.length[flight] - 1 - k  # flat index of the same landing reversed
    forward = (runway.start, runway.length, runway.offset, reduced, runway.cls, runway.class_sep, runway.horizon)
    backward = (rstart, runway.length, runway.offset, reduced[mirror], runway.cls,
                np.ascontiguousarray(runway.class_sep.T), runway.horizon)
    if not two_cycle:
        ending = _best_path(*forward)[3]
        starting = _best_path(*backward)[3][mirror]
        return lam.sum() + runway.constant + ending + starting - reduced
    _, _, _, end1, pred1, end2 = _best_path2(*forward, keep or KEEP)
    _, _, _, start1, succ1, start2 = _best_path2(*backward, keep or KEEP)
    start1, succ1, start2 = start1[mirror], succ1[mirror], start2[mirror]
    clash = (pred1 == succ1) & (pred1 >= 0)
    both = np.where(clash, np.minimum(end1 + start2, end2 + start1), end1 + start1)
    return lam.sum() + runway.constant + both - reduced


def order_of(runway: Runway, flights: np.ndarray, times: np.ndarray) -> np.ndarray:
    """A landing order read from a path: each flight at its mean time in the path, a flight the path
    skips at its target (else its earliest) time."""
    n = runway.n
    total = np.bincount(flights, weights=times.astype(float), minlength=n)
    count = np.bincount(flights, minlength=n)
    at = np.where(count > 0, total / np.maximum(count, 1), _target_time(runway))
    return np.lexsort((np.arange(n), at))


def order_of_through(runway: Runway, value_through: np.ndarray) -> np.ndarray:
    """A landing order: each flight at the time whose path value through it (:func:`through`) is least."""
    best = np.array([int(np.argmin(value_through[runway.offset[j]:runway.offset[j + 1]])) for j in range(runway.n)])
    return np.lexsort((np.arange(runway.n), runway.start + best))


def _target_time(runway: Runway) -> np.ndarray:
    """Each flight's cheapest time (its target)."""
    best = np.array([int(np.argmin(runway.cost[runway.offset[j]:runway.offset[j + 1]])) for j in range(runway.n)])
    return (runway.start + best).astype(float)


def timed(runway: Runway, order: np.ndarray, objective) -> tuple[float, np.ndarray] | None:
    """The least objective over schedules landing in ``order`` and their delays (an LP: every pair of
    the order separated, pairs added where broken), or None when no schedule keeps that order."""
    import highspy

    n = runway.n
    pos = np.empty(n, dtype=np.int64)
    pos[order] = np.arange(n)
    from uamopt.solvers.highs import quiet_highs

    h = quiet_highs()
    inf = highspy.kHighsInf
    # columns: x_j (time, relative to start 0), e_j ≥ 0, l_j ≥ 0 where x_j − t_j = l_j − e_j
    lo = runway.start.astype(float)
    hi = (runway.start + runway.length - 1).astype(float)
    target, early, late, per_delay = _terms(runway, objective)
    costs = np.concatenate([np.full(n, per_delay), early, late])
    h.addVars(3 * n, np.concatenate([lo, np.zeros(2 * n)]), np.concatenate([hi, np.full(2 * n, inf)]))
    h.changeColsCost(3 * n, np.arange(3 * n, dtype=np.int32), costs)
    idx = np.arange(n, dtype=np.int32)
    for j in range(n):  # x_j + e_j − l_j = target_j
        h.addRow(float(target[j]), float(target[j]), 3, np.array([j, n + j, 2 * n + j], dtype=np.int32),
                 np.array([1.0, 1.0, -1.0]))
    rows = [(order[k], order[k + 1]) for k in range(n - 1)]
    added: set = set()
    for _ in range(n):
        for p, q in rows:
            h.addRow(float(runway.sep[p, q]), inf, 2, np.array([q, p], dtype=np.int32), np.array([1.0, -1.0]))
            added.add((p, q))
        h.run()
        if h.getModelStatus() != highspy.HighsModelStatus.kOptimal:
            return None
        x = np.asarray(h.getSolution().col_value[:n])
        xo = x[order]
        gaps = xo[None, :] - xo[:, None]  # gaps[a, b] = x(order b) − x(order a)
        need = runway.sep[np.ix_(order, order)]
        broken = np.argwhere(np.triu(gaps < need - 1e-6, 1))
        rows = [(int(order[a]), int(order[b])) for a, b in broken if (int(order[a]), int(order[b])) not in added]
        if not rows:
            x = np.round(x)
            delay = x - runway.start
            value = float(np.sum(runway.cost[runway.offset[:-1] + delay.astype(np.int64)])) + runway.constant
            return value, delay.astype(float)
    del idx
    return None


def _terms(runway: Runway, objective):
    """(target time, early cost, late cost, cost per second of delay) per flight, times relative to
    the runway's origin; the delay cost is per_delay · d plus the earliness/tardiness terms."""
    n = runway.n
    if objective.per_flight_terms:
        a, e, late = objective.terms
        target = runway.start + np.asarray(a, dtype=float)
        return target, np.asarray(e, dtype=float), np.asarray(late, dtype=float), float(objective.per_delay)
    return runway.start.astype(float), np.zeros(n), np.zeros(n), float(objective.per_delay)


def windows_after_fixing(runway: Runway, value_through: np.ndarray, upper: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Each flight's least and greatest landing time (relative) among the landings whose path
    value does not exceed ``upper`` (:func:`through`): every schedule of objective ≤ ``upper``
    lands inside them. None when some flight has no such landing (no schedule beats ``upper``)."""
    keep = value_through <= upper + 1e-9 * (1.0 + abs(upper))
    lo = np.empty(runway.n, dtype=np.int64)
    hi = np.empty(runway.n, dtype=np.int64)
    for j in range(runway.n):
        kept = np.flatnonzero(keep[runway.offset[j]:runway.offset[j + 1]])
        if kept.size == 0:
            return None
        lo[j], hi[j] = runway.start[j] + kept[0], runway.start[j] + kept[-1]
    return lo, hi


def exact_in_windows(runway: Runway, lo: np.ndarray, hi: np.ndarray, objective, deadline: float, threads: int,
                     seed: int = 0, start: np.ndarray | None = None):
    """The exact problem with each flight's landing time in [lo, hi] (relative), solved by HiGHS:
    the disjunctive model of Beasley et al. (2000) with one binary per pair whose windows admit both
    orders, a row per pair whose order the windows fix (none where the windows already keep it
    apart, none between two flights whose times are both fixed: lo = hi). Returns (status, value,
    delay, bound): status ``optimal`` (value proved within these windows), ``infeasible`` (no
    schedule lands in them), else ``time_limit`` with the best schedule found (or None) and
    HiGHS's bound within the windows (or None)."""
    import highspy

    from uamopt.solvers.highs import mip_solver, run_mip, start_solution

    n = runway.n
    sep = runway.sep
    target, early, late, per_delay = _terms(runway, objective)
    p_idx, q_idx = np.triu_indices(n, 1)
    fixed = lo == hi
    live = ~(fixed[p_idx] & fixed[q_idx])
    p_idx, q_idx = p_idx[live], q_idx[live]
    s_pq, s_qp = sep[p_idx, q_idx], sep[q_idx, p_idx]
    pq = lo[p_idx] + s_pq <= hi[q_idx]  # p may land first
    qp = lo[q_idx] + s_qp <= hi[p_idx]
    if np.any(~pq & ~qp):
        return "infeasible", None, None, None
    both = pq & qp
    # a forced order the windows already keep (the later one's earliest time far enough after the other's latest)
    need = (pq & ~qp & (lo[q_idx] - hi[p_idx] < s_pq)) | (qp & ~pq & (lo[p_idx] - hi[q_idx] < s_qp))
    h = mip_solver(threads, seed, 0.0)
    inf = highspy.kHighsInf
    h.addVars(3 * n, np.concatenate([lo.astype(float), np.zeros(2 * n)]),
              np.concatenate([hi.astype(float), np.full(2 * n, inf)]))
    h.changeColsCost(3 * n, np.arange(3 * n, dtype=np.int32), np.concatenate([np.full(n, per_delay), early, late]))
    for j in range(n):
        h.addRow(float(target[j]), float(target[j]), 3, np.array([j, n + j, 2 * n + j], dtype=np.int32),
                 np.array([1.0, 1.0, -1.0]))
    binaries = []
    keep = both | need
    for p, q, a, b in zip(p_idx[keep].tolist(), q_idx[keep].tolist(), pq[keep].tolist(), qp[keep].tolist(), strict=True):
        if a and not b:
            h.addRow(float(sep[p, q]), inf, 2, np.array([q, p], dtype=np.int32), np.array([1.0, -1.0]))
        elif b and not a:
            h.addRow(float(sep[q, p]), inf, 2, np.array([p, q], dtype=np.int32), np.array([1.0, -1.0]))
        else:
            y = h.getNumCol()
            h.addVar(0.0, 1.0)
            h.changeColIntegrality(y, highspy.HighsVarType.kInteger)
            m1 = float(sep[p, q] - (lo[q] - hi[p]))  # x_q − x_p ≥ S_pq − m1 (1 − y)
            m2 = float(sep[q, p] - (lo[p] - hi[q]))  # x_p − x_q ≥ S_qp − m2 y
            h.addRow(float(sep[p, q]) - m1, inf, 3, np.array([q, p, y], dtype=np.int32), np.array([1.0, -1.0, -m1]))
            h.addRow(float(sep[q, p]), inf, 3, np.array([p, q, y], dtype=np.int32), np.array([1.0, -1.0, m2]))
            binaries.append((p, q))
    if start is not None:
        x = runway.start + np.asarray(start, dtype=float)
        h.setSolution(start_solution(np.concatenate([x, np.maximum(0.0, target - x), np.maximum(0.0, x - target),
                                                     [1.0 if x[p] < x[q] else 0.0 for p, q in binaries]])))
    run = run_mip(h, deadline, "runway")
    if run.termination == "Infeasible":
        return "infeasible", None, None, None
    shift = runway.constant - per_delay * float(np.sum(runway.start))  # the model's objective → the problem's
    value = delay = None
    if run.x is not None:
        x = run.x[:n]
        x = np.where(np.abs(x - np.round(x)) <= 1e-6, np.round(x), x)  # the LP's whole times, without float dust
        delay = np.clip(x - runway.start, 0.0, (runway.length - 1).astype(float))
        value = float(np.sum(objective.delay_cost(delay))) + runway.constant
    bound = run.bound + shift if run.bound is not None else None
    return ("optimal" if run.proved and run.x is not None else "time_limit"), value, delay, bound


@dataclass
class Dual:
    """Where the subgradient steps got: the best L(λ), its λ, the steps taken, and the best
    schedule read from the paths (value, delays, order; value inf and None when none kept an order)."""

    bound: float
    lam: np.ndarray
    steps: int
    value: float
    delay: np.ndarray | None
    order: np.ndarray | None


#: subgradient steps: the step factor shrinks by STEP_SHRINK after STALL steps without a better
#: bound, and the steps end when it falls below STEP_MIN; a path is read as a schedule every READ_EVERY
#: steps (READ_EVERY_TWO on two-cycle-free paths, closer to schedules)
STALL, STEP_SHRINK, STEP_MIN, READ_EVERY, READ_EVERY_TWO = 40, 1.5, 1e-4, 10, 3
#: the steps stall while the bound rises by less than GAIN (relative) in all since the last gain;
#: they end once the bound is within CLOSE (relative) of the best schedule (the exact model within
#: the windows then proves it)
GAIN, CLOSE = 1e-5, 1e-5


def ascend(runway: Runway, objective, deadline: float, on_bound=None, on_schedule=None, *, two_cycle: bool = False,
           start: Dual | None = None, factor: float = 1.0) -> Dual:
    """Subgradient ascent on L(λ) (Polyak steps towards the best schedule read from the paths)
    until the step factor is spent or the deadline passes; from ``start`` (its λ, bound and
    schedule; else λ = 0 and the order of target times). With ``two_cycle`` the paths have no
    p, q, p either (a greater bound, each step about three times as long)."""
    if start is None:
        best = Dual(bound=-np.inf, lam=np.zeros(runway.n), steps=0, value=np.inf, delay=None, order=None)
        order0 = np.lexsort((np.arange(runway.n), _target_time(runway)))
        got = timed(runway, order0, objective)
        if got is not None:
            best.value, best.delay, best.order = got[0], got[1], order0
            if on_schedule is not None:
                on_schedule(best.delay, "runway: the order of target times")
    else:
        best = Dual(bound=-np.inf if two_cycle else start.bound, lam=start.lam.copy(), steps=start.steps,
                    value=start.value, delay=start.delay, order=start.order)
    lam = best.lam.copy()
    stall, step = 0, 0
    ref = best.bound
    every = READ_EVERY_TWO if two_cycle else READ_EVERY
    while factor >= STEP_MIN and time.perf_counter() < deadline:
        bound, flights, times = path_bound(runway, lam, two_cycle)
        step += 1
        if bound > best.bound:
            best.bound, best.lam = bound, lam.copy()
            if on_bound is not None:
                on_bound(bound)
        if best.bound - ref > GAIN * (1.0 + abs(best.bound)):  # a gain since the last one counted
            ref, stall = best.bound, 0
        else:
            stall += 1
            if stall >= STALL:
                factor, stall = factor / STEP_SHRINK, 0
        if (step - 1) % every == 0:
            order = order_of(runway, flights, times)
            got = timed(runway, order, objective)
            if got is not None and got[0] < best.value - 1e-9:
                best.value, best.delay, best.order = got[0], got[1], order
                if on_schedule is not None:
                    on_schedule(best.delay, f"runway: the path of subgradient step {best.steps + step}")
        if best.value - best.bound <= CLOSE * (1.0 + abs(best.value)):  # proved, or left to the exact model
            break
        g = 1.0 - np.bincount(flights, minlength=runway.n)
        norm = float(g @ g)
        if norm == 0.0:  # the path lands every flight once: a schedule whose cost is the bound
            break
        aim = best.value if np.isfinite(best.value) else bound + abs(bound) * 0.1 + 1.0
        lam = lam + factor * max(aim - bound, 1e-9 * (1.0 + abs(bound))) / norm * g
    if start is not None and two_cycle and start.bound > best.bound:  # never below where it started
        best.bound, best.lam = start.bound, start.lam.copy()
    best.steps += step
    return best


def neighbourhoods(runway: Runway, lo: np.ndarray, hi: np.ndarray, objective, delay: np.ndarray, value: float,
                   deadline: float, threads: int, seed: int, size: int, window_s: float, on_schedule=None,
                   narrowed=None):
    """Large neighbourhood search: ``size`` consecutive landings of the schedule are freed (each within
    its window [lo, hi]), every other flight kept at its time, and the part solved exactly
    (:func:`exact_in_windows`, at most ``window_s`` each); windows advance by half their size, every
    other pass shifted by a quarter; passes repeat while one gains. ``narrowed(value)``, if given,
    gives the windows again for a better schedule (reduced-cost fixing against it). Returns (value,
    delay, parts solved, parts improved)."""
    solved = improved = passes = 0
    gained = True
    while gained and time.perf_counter() < deadline:
        gained = False
        order = np.argsort(runway.start + delay, kind="stable")
        shift = (size // 4) * (passes % 2)
        passes += 1
        for first in range(-shift, max(1, runway.n - size // 2), max(1, size // 2)):
            if time.perf_counter() >= deadline:
                break
            free = order[max(0, first):first + size]
            x = np.round(runway.start + delay).astype(np.int64)
            wlo, whi = x.copy(), x.copy()
            wlo[free], whi[free] = lo[free], hi[free]
            _, got, new, _ = exact_in_windows(runway, wlo, whi, objective,
                                                   min(deadline, time.perf_counter() + window_s), threads, seed,
                                                   start=delay)
            solved += 1
            if got is not None and new is not None and got < value - 1e-9 * (1.0 + abs(value)):
                value, delay = got, new
                improved += 1
                gained = True
                if on_schedule is not None:
                    on_schedule(delay, f"runway: neighbourhood of landings {first}-{first + len(free)}")
        if gained and narrowed is not None:
            windows = narrowed(value)
            if windows is not None:
                lo, hi = windows
    return value, delay, solved, improved


#: shares of the time limit: subgradient steps on one-cycle-free paths until ONE_CYCLE_SHARE (or
#: spent), then on two-cycle-free paths from there (step factor TWO_CYCLE_FACTOR) until DUAL_SHARE, neighbourhood search until
#: SEARCH_END, then the exact model within the fixed windows; neighbourhoods of SEARCH_SIZE landings,
#: at most SEARCH_WINDOW_S each
ONE_CYCLE_SHARE, TWO_CYCLE_FACTOR = 0.15, 0.1
DUAL_SHARE, SEARCH_END, SEARCH_SIZE, SEARCH_WINDOW_S = 0.35, 0.75, 12, 3.0


def solve(problem: SchedulingProblem, profile, runway: Runway):
    """The certified method on a one-runway problem (module docstring): subgradient steps on the
    path bound with schedules read from the paths, neighbourhood search within the windows that
    reduced-cost fixing leaves, then HiGHS on the whole problem within those windows. Status
    ``optimal`` when the bound meets the schedule, else ``time_limit``; ``bound`` = max(the path
    bound, min(the schedule, HiGHS's bound within the windows))."""
    from uamopt.schedule.model import evaluate, make_schedule, violations
    from uamopt.solvers.watchdog import report_bound, report_incumbent

    t0 = time.perf_counter()
    limit = profile.time_limit_s
    objective = problem.objective
    operated = np.ones(runway.n, dtype=bool)

    def schedule_found(delay, source):
        report_incumbent(problem, operated, delay, source)

    def bound_found(bound):
        report_bound(problem, bound, "runway: Lagrangian path bound")

    dual = ascend(runway, objective, t0 + ONE_CYCLE_SHARE * limit, bound_found, schedule_found)
    one_cycle = dual.bound
    dual = ascend(runway, objective, t0 + DUAL_SHARE * limit, bound_found, schedule_found, two_cycle=True,
                  start=dual, factor=TWO_CYCLE_FACTOR)
    two_cycle = dual.bound > one_cycle
    if dual.delay is None:
        from uamopt.solvers.warmstart import no_schedule

        raise no_schedule(problem, profile.name or "discovery", "no landing order read from the paths could be timed")
    value, delay = dual.value, dual.delay
    bound = dual.bound
    extras: dict = {"lagrangian_bound": dual.bound, "one_cycle_bound": one_cycle, "subgradient_steps": dual.steps,
                    "separation_classes": int(runway.class_sep.shape[0])}
    through_value = through(runway, dual.lam, two_cycle)
    got = timed(runway, order_of_through(runway, through_value), objective)
    if got is not None and got[0] < value - 1e-9:
        value, delay = got
        schedule_found(delay, "runway: the order of least path values")
    windows = windows_after_fixing(runway, through_value, value)
    solved = improved = 0
    exact = None
    if windows is not None and value - bound > 1e-9 * (1.0 + abs(value)):
        lo, hi = windows
        value, delay, solved, improved = neighbourhoods(runway, lo, hi, objective, delay, value,
                                                        t0 + SEARCH_END * limit, profile.threads, profile.seed,
                                                        SEARCH_SIZE, SEARCH_WINDOW_S, schedule_found,
                                                        lambda upper: windows_after_fixing(runway, through_value, upper))
        windows = windows_after_fixing(runway, through_value, value)
    if windows is not None and value - bound > 1e-9 * (1.0 + abs(value)) and time.perf_counter() < t0 + limit:
        lo, hi = windows
        extras["window_width_median_s"] = float(np.median(hi - lo + 1))
        status, got, new, inner = exact_in_windows(runway, lo, hi, objective, t0 + limit, profile.threads,
                                                   profile.seed, start=delay)
        exact = status
        sound = got is not None and new is not None and not violations(problem, operated, new)
        if sound and got < value:
            value, delay = got, new
            schedule_found(delay, "runway: HiGHS within the windows")
        if status == "optimal" and got is not None:
            inner = got if sound else None  # a proof of a schedule that breaks a row proves nothing
        if inner is not None:  # every schedule of objective ≤ the incumbent's lands within the windows
            bound = max(bound, min(value, inner))
    value = evaluate(problem, operated, delay)
    bound = min(bound, value)
    report_bound(problem, bound, "runway")
    proved = value - bound <= 1e-9 * (1.0 + abs(value))
    extras.update({"model": "continuous (bound: Lagrangian path relaxation on one runway, then HiGHS within "
                            "the windows reduced-cost fixing leaves)", "model_kind": "continuous",
                   "continuous_bound": bound, "neighbourhoods_solved": solved, "neighbourhoods_improved": improved,
                   "exact_in_windows": exact})
    return make_schedule(problem, "discovery", "optimal" if proved else "time_limit", operated, delay,
                         proved_for="continuous" if proved else "none", bound=bound,
                         solve_seconds=time.perf_counter() - t0, seed=profile.seed, extras=extras)
