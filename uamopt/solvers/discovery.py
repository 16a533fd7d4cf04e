"""A bound for continuous delays by dynamic discretisation discovery (issue 19).

Why
---
The relaxed time-indexed model (timeindexed.py, ``model = "relaxed"``) cuts each flight's delay
range into cells of one width s and forbids a cell pair only when *every* delay pair in it
conflicts. Its optimum bounds the continuous problem, but with s = 5 s a forbidden interval of δ
shorter than 2 s is never seen, and on the city instances the median interval is 9 s: the bound
stayed 8–10 % below the best schedule at 1,000–3,000 flights, and finer uniform cells drown the
solver (2.5 s: 646,000 rows, no bound in 200 s).

Dynamic discretisation discovery (Boland, Hewitt, Savelsbergh, "The continuous-time service
network design problem", Operations Research 65(5), 2017) refines the cells only where the
relaxation's optimum cheats: each flight keeps its own sorted cut points, and a cut is added where
the relaxation put two conflicting flights at delays the continuous model forbids.

The relaxation (cells of any widths)
------------------------------------
Flight f's cells are [c_i, c_{i+1}) for its cut points 0 = c_0 < c_1 < … < c_m ≤ U_f, the last one
closed, [c_m, U_f]. Binary x_{f,i}: f operates with a delay in cell i, at the cost of the cell's
lower end (the objective is non-decreasing in the delay: ``weighted`` and ``lexicographic``). Rows,
as in timeindexed.py but for arbitrary cells:

- Σ_i x_{f,i} ≤ 1, the precedence and must-operate rows;
- a conflicting pair (p, q) with a forbidden open interval (lo, hi) of z = d_q − d_p: over cell a
  of p and cell b of q, z ranges over (b_lo − a_hi, b_hi − a_lo), an end included when its cell is
  a last one. The two cells are *forbidden together* iff that range lies inside (lo, hi) (10⁻⁹ s
  of float round-off forgiven, ``ROUND_S``); written as x_{p,a} + Σ_{b forbidden with a} x_{q,b}
  ≤ 1 (q's cells exclude each other, so the aggregated row is exact for 0-1 points). q's cells
  are sorted, so the b forbidden with a form one run, found by two binary searches;
- a turnaround row (e, f, need) (d_f − d_e ≥ need): cells forbidden together iff every difference
  stays below need;
- with option ``cliques`` (off by default), the clique rows of cliques.py, derived once on the
  uniform cells of the first width and *lifted*: a column of the first model is replaced by the sum
  of the cells it was cut into (each a subset of it, so every pair of the row still conflicts, and
  a flight's cells exclude each other). On the city instances and the paper case there are none at
  10 s or 5 s cells (no flight stays inside a block for a whole cell); they appear from 2 s cells.

Every continuous schedule maps to a feasible point (each delay to the cell holding it) of no
greater cost, since forbidden cell pairs hold only forbidden delay pairs. So the relaxation's
optimum, and any bound of it, bounds the continuous optimum, for every set of cuts.

Discovery
---------
Solve the relaxation (HiGHS, started from the best schedule known) and read its point at the
cells' lower ends. If that point breaks no pair interval or turnaround (as the verifier reads
them), it is a schedule whose cost is the relaxation's: *optimal* for continuous delays once a
round proves it (``mip_rel_gap`` 0). Else, for each broken pair interval with z₀ = d_q − d_p inside
(lo, hi), p's cell is cut at d_q − lo and q's at d_p + hi: the sub-cells holding the two delays
are then forbidden together (z ranges over (lo, z₀] and [z₀, hi)), and the next cells' lower ends
put z exactly at lo or hi, which the model allows. A broken turnaround cuts f at d_e + need. Each
flight of a broken row is also cut at every gap end on its way to its earliest admissible delay
(polish.py), so a chain of pushes is seen in one round. A round forbids the point it found, so the
bound never falls, and every round's bound is valid. Each round's point is also *mended* into a
schedule (polish.py: the later flight of each broken row taken out and put back at its earliest
admissible delay, then left shifts and insertions), which keeps an incumbent.

A round's MILP stops at the relative gap ``mip_rel_gap`` while the best schedule is far from the
bound, at a quarter of that distance once closer, or after ``round_s`` seconds (its bound is then
HiGHS's dual bound, still valid, and its incumbent gives the cuts), and at 0 with no time cap when
its point was a schedule (to prove it). Dynamic discretisation discovery is due to Boland, Hewitt,
Savelsbergh ("The continuous-time service network design problem", Operations Research 65(5),
2017); the cells here are delays, and the cuts are the forbidden intervals' ends.

Applies to problems without the ``cumulative`` shape (pads) and with a delay cost non-decreasing
in the delay: :data:`SHAPES`, :data:`OBJECTIVES`. A one-runway problem (every pair of flights
separated, every flight operated, whole-second data: the aircraft-landing problem) goes to
:mod:`uamopt.solvers.runway` instead, for every objective kind, earliness/tardiness included; an
earliness/tardiness problem of any other shape is refused in one line.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from uamopt.errors import UamoptError
from uamopt.schedule.flights import TIME_TOL_S
from uamopt.schedule.model import Schedule, SchedulingProblem, evaluate, make_schedule, violations
from uamopt.solvers.warmstart import no_worse
from uamopt.solvers.watchdog import report_bound, report_incumbent

ETA_S = 1e-9  # float round-off forgiven when mapping a delay to its cell, s
ROUND_S = 1e-9  # float round-off forgiven in the forbidden test, s
MIN_WIDTH_S = 1e-10  # no cut closer than this to another, s
REPAIR_S = 10.0  # at most this long for a round's exact repair, s


@dataclass
class Cells:
    """Per flight its sorted cut points (the cells' lower ends) and its delay bound U_f."""

    cuts: list[np.ndarray]
    upper: np.ndarray  # (n,) U_f, s

    @classmethod
    def uniform(cls, problem: SchedulingProblem, step_s: float) -> Cells:
        """Cells [k s, (k + 1) s] ∩ [0, U_f], k = 0 … ⌊U_f / s⌋: the relaxed grid model's cells."""
        from uamopt.solvers.timeindexed import delay_indices

        upper = np.asarray(problem.delay_upper_s, dtype=float)
        k = delay_indices(problem, step_s)
        return cls([np.arange(int(m) + 1) * float(step_s) for m in k.tolist()], upper)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(start (n + 1,), lower (C,), upper (C,), flight (C,)) of the columns, flight by flight."""
        counts = np.array([len(c) for c in self.cuts], dtype=np.int64)
        start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        lower = np.concatenate(self.cuts) if len(self.cuts) else np.zeros(0)
        flight = np.repeat(np.arange(len(self.cuts)), counts)
        nxt = np.append(lower[1:], 0.0)
        last = np.zeros(len(lower), dtype=bool)
        last[start[1:] - 1] = True
        upper = np.where(last, np.maximum(self.upper[flight], lower), nxt)
        return start, lower, upper, flight

    def add(self, flight: np.ndarray, at: np.ndarray) -> int:
        """Add cut points ``at`` to ``flight``'s cells (those not within ``MIN_WIDTH_S`` of a cut or
        outside (0, U_f)); returns how many were added."""
        added = 0
        for f in np.unique(flight).tolist():
            new = at[flight == f]
            new = new[(new > MIN_WIDTH_S) & (new < self.upper[f] - MIN_WIDTH_S)]
            if not len(new):
                continue
            old = self.cuts[f]
            merged = np.unique(np.concatenate([old, new]))
            keep = np.ones(len(merged), dtype=bool)  # drop a new cut too close to the cut before it
            keep[1:] = np.diff(merged) > MIN_WIDTH_S
            merged = merged[keep | np.isin(merged, old)]
            added += len(merged) - len(old)
            self.cuts[f] = merged
        return added

    def cell_of(self, delay_s: np.ndarray, operated: np.ndarray, start: np.ndarray) -> np.ndarray:
        """The 0-1 column vector of a schedule: each operated delay in the cell with the largest lower end
        not above it."""
        x = np.zeros(int(start[-1]))
        for f in np.flatnonzero(operated).tolist():
            i = int(np.searchsorted(self.cuts[f], delay_s[f] + ETA_S, side="right")) - 1
            x[start[f] + max(i, 0)] = 1.0
        return x


@dataclass
class Constraints:
    """The pair intervals (on z = d_q − d_p) and turnaround rows of a problem, as flat arrays."""

    p: np.ndarray
    q: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    te: np.ndarray
    tf: np.ndarray
    need: np.ndarray

    @classmethod
    def of(cls, problem: SchedulingProblem) -> Constraints:
        view = problem.pairs
        shift = view.shift[view.row_pair]
        t = problem.turnaround
        return cls(p=view.p[view.row_pair], q=view.q[view.row_pair], lo=view.lo - shift, hi=view.hi - shift,
                   te=t.e, tf=t.f, need=t.need_s)

    def broken(self, operated: np.ndarray, delay_s: np.ndarray, tol_s: float = TIME_TOL_S
               ) -> tuple[np.ndarray, np.ndarray]:
        """(pair rows, turnaround rows) a decision breaks by more than ``tol_s`` (default the verifier's τ)."""
        z = delay_s[self.q] - delay_s[self.p]
        pair = operated[self.p] & operated[self.q] & (self.lo + tol_s < z) & (z < self.hi - tol_s)
        zt = delay_s[self.tf] - delay_s[self.te]
        turn = operated[self.te] & operated[self.tf] & (zt < self.need - tol_s)
        return np.flatnonzero(pair), np.flatnonzero(turn)


def _runs(keys: np.ndarray, start: np.ndarray, flight: np.ndarray, query: np.ndarray, side: Literal["left", "right"],
          span: float) -> np.ndarray:
    """Per query, ``searchsorted`` within its flight's block of ``keys`` (sorted per flight), as an
    index relative to the block's start. ``span`` bounds every key: flights are offset by span apart."""
    offset = flight.astype(float) * span
    q = np.clip(query, -1.0, span - 2.0) + offset
    return np.searchsorted(keys, q, side=side) - start[flight]


@dataclass
class Lifted:
    """The first model's clique rows, in its (uniform) columns, to lift onto finer cells."""

    step_s: float
    ptr: np.ndarray = field(default_factory=lambda: np.zeros(1, np.int64))
    col: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    ustart: np.ndarray = field(default_factory=lambda: np.zeros(1, np.int64))


def build(problem: SchedulingProblem, cells: Cells, cons: Constraints, lifted: Lifted | None = None,
          drop_dominated: bool = True):
    """The relaxation of the module docstring on ``cells``, as a timeindexed.GridModel (kind
    ``relaxed``; its ``step_s`` is the first width, for the names only), with the cells' lower ends."""
    from uamopt.solvers.timeindexed import GridModel

    start, lower, upper, flight = cells.arrays()
    n, N = len(cells.cuts), int(start[-1])
    span = float(np.max(cells.upper, initial=0.0)) + 4.0
    key_lo = lower + flight * span  # sorted: flight by flight, each increasing
    key_hi = upper + flight * span
    count = np.diff(start)
    is_last = np.zeros(N, dtype=bool)
    is_last[start[1:] - 1] = True
    eta = ROUND_S
    rows_p, rows_q, rows_first, rows_last = [], [], [], []
    # cells are half-open [c_i, c_{i+1}) but the last, [c_m, U_f]: z = d_q − d_p over cell a of p and b of q
    # lies in (b_lo − a_hi, b_hi − a_lo), each end attained when its cell is a last one. Forbidden
    # together iff that range is inside the open (lo, hi); one run of b per a (q's cells are sorted)
    for p, q, lo, hi in ((cons.p, cons.q, cons.lo, cons.hi), (cons.te, cons.tf, None, cons.need)):
        if not len(p):
            continue
        iv = np.repeat(np.arange(len(p)), count[p])
        a_col = start[p[iv]] + (np.arange(len(iv)) - np.repeat(np.cumsum(count[p]) - count[p], count[p]))
        qq = q[iv]
        if lo is None:  # turnaround (e, f, need): every b whose differences all stay below need
            first = np.zeros(len(iv), dtype=np.int64)
        else:  # b_lo − a_hi ≥ lo (> lo when a is last: its upper end is attained)
            at = upper[a_col] + lo[iv] + np.where(is_last[a_col], 2 * eta, -eta)
            first = _runs(key_lo, start, qq, at, "left", span)
        last = _runs(key_hi, start, qq, lower[a_col] + hi[iv] + eta, "right", span) - 1
        last = np.minimum(last, count[qq] - 1)
        # q's last cell: its upper end U_q is attained, so U_q − a_lo must stay strictly below
        end = start[qq] + np.maximum(last, 0)
        last = np.where((last >= 0) & is_last[end] & (upper[end] - lower[a_col] >= hi[iv] - eta), last - 1, last)
        live = first <= last
        rows_p.append(a_col[live])
        rows_q.append(qq[live])
        rows_first.append(first[live])
        rows_last.append(last[live])
    if rows_p:
        a_col, qq, first, last = (np.concatenate(x) for x in (rows_p, rows_q, rows_first, rows_last))
    else:
        a_col = qq = first = last = np.zeros(0, np.int64)
    width = last - first + 1
    ent = np.repeat(np.arange(len(a_col)), width)
    b_col = start[qq[ent]] + first[ent] + (np.arange(int(width.sum())) - np.repeat(np.cumsum(width) - width, width))
    # one row per (cell of p, flight q): the runs of its intervals merged, x_{p,a} once
    key_row = a_col.astype(np.int64) * n + qq
    packed = np.unique(np.concatenate([key_row, key_row[ent]]) * N + np.concatenate([a_col, b_col]))
    row_key, col = np.divmod(packed, N)
    _, first_of_row = np.unique(row_key, return_index=True)
    pair_ptr = np.append(first_of_row, len(packed)).astype(np.int64)
    multi = np.flatnonzero(count > 1)
    assign_cols = (np.concatenate([np.arange(start[f], start[f + 1]) for f in multi.tolist()]) if len(multi)
                   else np.zeros(0, np.int64))
    assign_ptr = np.concatenate([[0], np.cumsum(count[multi])]).astype(np.int64)
    clique_ptr, clique_col = np.zeros(1, np.int64), np.zeros(0, np.int64)
    n_dominated = 0
    if lifted is not None and len(lifted.col):  # each uniform column → the run of cells cut from it
        parent = lifted.ustart[flight] + np.minimum(np.floor(lower / lifted.step_s + ETA_S).astype(np.int64),
                                                    np.diff(lifted.ustart)[flight] - 1)
        child_first = np.searchsorted(parent, np.arange(int(lifted.ustart[-1]) + 1), side="left")
        size = child_first[lifted.col + 1] - child_first[lifted.col]
        clique_col = (np.repeat(child_first[lifted.col], size)
                      + np.arange(int(size.sum())) - np.repeat(np.cumsum(size) - size, size))
        row_size = np.add.reduceat(size, lifted.ptr[:-1]) if len(lifted.ptr) > 1 else np.zeros(0, np.int64)
        clique_ptr = np.concatenate([[0], np.cumsum(row_size)]).astype(np.int64)
        if drop_dominated:
            from uamopt.solvers.cliques import drop_dominated as without_dominated

            pair_ptr, col, n_dominated = without_dominated(pair_ptr, col, clique_ptr, clique_col, N)
    row_ptr = np.concatenate([assign_ptr, assign_ptr[-1] + pair_ptr[1:], assign_ptr[-1] + pair_ptr[-1] + clique_ptr[1:]])
    row_col = np.concatenate([assign_cols, col, clique_col]).astype(np.int64)
    o = problem.objective
    cost = o.delay_cost(lower, flight) - o.per_flight
    prec = [(f, group) for family in problem.of_shape("precedence") for f, group in family.groups()]
    model = GridModel(step_s=float(lifted.step_s if lifted is not None else 0.0), kind="relaxed", start=start,
                      cost=np.asarray(cost, dtype=float), row_ptr=row_ptr.astype(np.int64), row_col=row_col, prec=prec,
                      must=np.flatnonzero(problem.must_operate).astype(np.int64), cliques=len(clique_ptr) - 1,
                      dominated_pair_rows=n_dominated)
    return model, lower, upper


def lifted_cliques(problem: SchedulingProblem, step_s: float) -> Lifted:
    """The clique rows of the relaxed uniform model of ``step_s`` (cliques.py), to lift."""
    from uamopt.solvers.cliques import occupancy_cliques
    from uamopt.solvers.timeindexed import delay_indices

    ustart = np.concatenate([[0], np.cumsum(delay_indices(problem, step_s) + 1)]).astype(np.int64)
    ptr, col = occupancy_cliques(problem, ustart, step_s, "relaxed")
    return Lifted(step_s=float(step_s), ptr=ptr, col=col, ustart=ustart)


def lp_bound(model, deadline: float, threads: int) -> float | None:
    """The LP relaxation's optimum of a relaxation model (a bound of it, so of the continuous
    problem), or None when HiGHS does not reach it by ``deadline``: the bound of a round whose
    MILP stopped before its root LP."""
    from uamopt.solvers.highs import mip_solver, run_mip
    from uamopt.solvers.timeindexed import load_model

    h = mip_solver(threads, 0, 0.0)
    load_model(h, model, integer=False)
    run = run_mip(h, deadline, "solver discovery (a round's LP bound)")
    return run.objective if run.proved else None


def point(x: np.ndarray, start: np.ndarray, lower: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Operated flags and the cells' lower ends of a 0-1 vector."""
    n = len(start) - 1
    col = np.flatnonzero(np.asarray(x) > 0.5)
    f = np.searchsorted(start, col, side="right") - 1
    operated, delay = np.zeros(n, dtype=bool), np.zeros(n)
    operated[f] = True
    delay[f] = lower[col]
    return operated, delay


def cut(cells: Cells, cons: Constraints, operated: np.ndarray, delay_s: np.ndarray, cell_hi: np.ndarray) -> int:
    """Cut the cells where the point breaks pair intervals or turnarounds (module docstring), each
    cut inside the flight's chosen cell (upper ends ``cell_hi``); returns the number of cuts added
    (0: the point breaks nothing, or nothing could be cut)."""
    pair, turn = cons.broken(operated, delay_s)
    dp, dq = delay_s[cons.p[pair]], delay_s[cons.q[pair]]
    flights = np.concatenate([cons.p[pair], cons.q[pair], cons.tf[turn]])
    at = np.concatenate([dq - cons.lo[pair], dp + cons.hi[pair], delay_s[cons.te[turn]] + cons.need[turn]])
    inside = at < cell_hi[flights] - MIN_WIDTH_S
    return cells.add(flights[inside], at[inside])


@dataclass
class Round:
    """One round of discovery: the model's size, its bound and point, what the point broke."""

    columns: int
    rows: int
    bound: float | None
    value: float | None
    proved: bool
    broken: int
    cuts: int
    repaired: float | None
    seconds: float
    build_s: float = 0.0
    milp_s: float = 0.0
    termination: str = ""  # HiGHS's, e.g. "Time limit reached"


@dataclass
class Discovery:
    """What :func:`discover` found: the best bound, the best schedule (from the points, their
    mending, or the start) and the rounds."""

    bound: float | None
    operated: np.ndarray | None
    delay_s: np.ndarray | None
    objective: float
    proved: bool  # the bound meets the schedule's objective: optimal for continuous delays
    rounds: list[Round]
    model: str


def discover(problem: SchedulingProblem, small: SchedulingProblem, deadline: float, threads: int, seed: int, *,
             step_s: float = 10.0, start: tuple[np.ndarray, np.ndarray] | None = None, gap: float = 0.0,
             cliques: bool = False, target_gap: float = 0.0, sweep: bool = True, max_rounds: int | None = None,
             exact_repair: bool = True, state: dict | None = None, round_s: float | None = None,
             log=None) -> Discovery:
    """Rounds of discovery on ``small`` (``problem`` reduced by dominance: the same optima) until
    ``deadline`` (a ``time.perf_counter`` time), the point is a schedule, or the best schedule lies
    within ``target_gap`` (relative) of the bound. Schedules are evaluated on ``problem``."""
    from uamopt.solvers import lns
    from uamopt.solvers.polish import Neighbours, mend, polish
    from uamopt.solvers.timeindexed import run_highs

    cons = Constraints.of(small)
    nb = Neighbours(small)
    state = {} if state is None else state  # a later call goes on from an earlier call's cells
    if "cells" not in state:
        state["cells"] = Cells.uniform(small, step_s)
        state["lifted"] = lifted_cliques(small, step_s) if cliques else None
        state["clique_rows"] = len(state["lifted"].ptr) - 1 if state["lifted"] is not None else 0
    cells, lifted = state["cells"], state["lifted"]
    best_x: tuple[np.ndarray, np.ndarray] | None = None
    best_value = math.inf
    if start is not None and not violations(problem, *start):
        best_x, best_value = (start[0].copy(), start[1].copy()), evaluate(problem, *start)
        p_op, p_d = polish(small, nb, *start)
        if not violations(problem, p_op, p_d) and evaluate(problem, p_op, p_d) < best_value - 1e-12:
            best_x, best_value = (p_op, p_d), evaluate(problem, p_op, p_d)
        if log is not None:
            log(None, None, best_value)
    bound: float | None = state.get("bound")
    round_s = state.get("round_s", round_s)  # as an earlier call left it (doubled where rounds needed it)
    rounds: list[Round] = []
    round_gap = gap
    while time.perf_counter() < deadline - 0.5 and (max_rounds is None or len(rounds) < max_rounds):
        t = time.perf_counter()
        model, lower, upper = build(small, cells, cons, lifted)
        st = model.start
        hint = cells.cell_of(best_x[1], best_x[0], st) if best_x is not None else None
        t_built = time.perf_counter()
        cap = deadline if round_gap == 0.0 or round_s is None else min(deadline, time.perf_counter() + round_s)
        run = run_highs(model, cap, threads, seed, round_gap, hint)
        t_solved = time.perf_counter()
        capped = round_s is not None and cap < deadline and run.termination != "Optimal"
        if capped and round_s is not None and bound is not None and (
                run.bound is None or run.bound < bound - max(gap, 1e-3) * abs(bound)):
            round_s *= 2.0  # the cap stopped HiGHS before its root's cuts: later rounds get twice as long
        if run.bound is None and bound is None and time.perf_counter() < deadline:
            run = dataclasses.replace(run, bound=lp_bound(model, deadline, threads))  # no bound yet: the LP's
        if run.bound is not None:  # every round's relaxation bounds the continuous optimum
            bound = run.bound if bound is None else max(bound, run.bound)
            report_bound(problem, bound, "a discovery round's relaxation")
        if run.x is None:  # no point within the round's cap: the next round gets twice as long
            rounds.append(Round(model.n_cols, model.n_rows, run.bound, None, run.proved, 0, 0, None,
                                time.perf_counter() - t, t_built - t, t_solved - t_built, run.termination))
            if log is not None:
                log(rounds[-1], bound, best_value)
            if round_s is None or cap >= deadline:
                break
            if not capped or bound is None:
                round_s *= 2.0
            continue
        operated, delay = point(run.x, st, lower)
        value = float(model.cost @ np.round(run.x))
        pair, turn = cons.broken(operated, delay)
        repaired = None
        added = 0
        if not len(pair) and not len(turn) and not violations(problem, operated, delay):
            v = evaluate(problem, operated, delay)  # the point is a schedule
            if v < best_value:
                best_x, best_value = (operated, delay), v
        else:
            candidates = [polish(small, nb, *mend(small, nb, operated, delay))]
            if exact_repair:  # the rows' flights re-solved exactly around the point (lns.py)
                fixed = lns.repair(problem, small, operated, delay, np.concatenate([cons.p[pair], cons.q[pair],
                                   cons.te[turn], cons.tf[turn]]), min(deadline, time.perf_counter() + REPAIR_S),
                                   threads, seed)
                if fixed is not None:
                    candidates.append(polish(small, nb, *fixed))
            for r_op, r_d in candidates:
                if not violations(problem, r_op, r_d):
                    v = evaluate(problem, r_op, r_d)
                    repaired = v if repaired is None else min(repaired, v)
                    if v < best_value - 1e-12:
                        best_x, best_value = (r_op, r_d), v
            chosen = np.flatnonzero(np.round(run.x) > 0.5)
            cell_hi = np.zeros(len(operated))
            cell_hi[np.searchsorted(st, chosen, side="right") - 1] = upper[chosen]
            added = cut(cells, cons, operated, delay, cell_hi)
            if sweep:  # each flight of a broken row: cuts along its way to its earliest admissible delay
                ends: list[float] = []
                who: list[int] = []
                for f in np.unique(np.concatenate([cons.p[pair], cons.q[pair], cons.tf[turn]])).tolist():
                    jumps: list[float] = []
                    nb.earliest(f, operated, delay, at_least=float(delay[f]), jumps=jumps)
                    ends += jumps
                    who += [f] * len(jumps)
                if ends:
                    added += cells.add(np.asarray(who, dtype=np.int64), np.asarray(ends))
        rounds.append(Round(model.n_cols, model.n_rows, run.bound, value, run.proved, len(pair) + len(turn), added,
                            repaired, time.perf_counter() - t, t_built - t, t_solved - t_built, run.termination))
        if best_x is not None:
            report_incumbent(problem, *best_x, f"discovery round {len(rounds)}")
        if log is not None:
            log(rounds[-1], bound, best_value)
        rel = (best_value - bound) / max(1e-9, abs(best_value)) if bound is not None and math.isfinite(best_value) else 1.0
        if rel <= max(target_gap, 1e-9):
            break
        if added == 0:  # a schedule that the round did not prove optimal: prove it (or find better) exactly
            if round_gap == 0.0:
                break
            round_gap = 0.0
            continue
        round_gap = min(gap, 0.25 * rel)  # coarse rounds while far, exact ones when close
    state["bound"] = bound
    state["round_s"] = round_s
    return Discovery(bound=bound, operated=None if best_x is None else best_x[0],
                     delay_s=None if best_x is None else best_x[1], objective=best_value,
                     proved=bound is not None and best_value - bound <= 1e-9 * (1 + abs(best_value)),
                     rounds=rounds, model=f"discovered cells from {step_s:g} s (relaxation of the continuous model)")


# --- the solver --------------------------------------------------------------------------------------
SHAPES = frozenset({"bounds", "must_operate", "precedence", "turnaround", "pairs"})
#: earliness/tardiness only on one-runway problems (runway.py); solve() refuses it elsewhere in one line
OBJECTIVES = frozenset({"weighted", "lexicographic", "earliness_tardiness"})
LNS_MIN_S = 2.0  # no neighbourhood search with less time than this left, s


def solve(problem: SchedulingProblem, profile) -> Schedule:
    """Discovery rounds for the bound and incumbents, then neighbourhood search on the best schedule
    (lns.py) for the last ``lns_share`` of the limit. Status ``optimal`` when the bound meets the
    schedule (proved for continuous delays), else ``time_limit``; ``bound`` is the best round's."""
    from uamopt.solvers import lns, runway
    from uamopt.solvers.warmstart import no_schedule, reduced, warm_start

    one_runway = runway.of(problem)
    if not isinstance(one_runway, str):
        return runway.solve(problem, profile, one_runway)
    if problem.objective.kind == "earliness_tardiness":
        raise UamoptError(f"discovery takes earliness/tardiness only on one-runway problems, and this one has {one_runway}",
                          f"profile {profile.name or 'discovery'}", "use highs or cpsat for this problem")
    o = profile.option
    t0 = time.perf_counter()
    limit = profile.time_limit_s
    start = warm_start(problem, o("step_s"), seed=profile.seed)
    small = reduced(problem)
    lns_s = o("lns_share") * limit
    state: dict = {}
    found = discover(problem, small, t0 + limit - lns_s, profile.threads, profile.seed, step_s=o("step_s"),
                     start=start.decisions if start.found else None, gap=o("mip_rel_gap"), cliques=o("cliques"),
                     round_s=o("round_time_limit_s"), state=state)
    rounds = list(found.rounds)
    operated, delay = found.operated, found.delay_s
    if operated is None or delay is None:
        raise no_schedule(problem, profile.name or "discovery", "no round gave a schedule within the limit")
    windows = passes = 0
    try:
        problem.requires  # noqa: B018 (lns.py frees returns with their outbounds: one required flight each)
        searchable = True
    except AttributeError:  # precedence groups of several flights (speed options): no neighbourhood search
        searchable = False
    while not found.proved and t0 + limit - time.perf_counter() >= LNS_MIN_S:
        better = 0
        if searchable:
            operated, delay, better = lns.improve(problem, small, operated, delay, t0 + limit, profile.threads,
                                                  profile.seed, size=o("lns_window"),
                                                  window_s=o("lns_window_time_limit_s"), pass_index=passes)
            windows += better
            passes += 1
            if better:
                report_incumbent(problem, operated, delay, f"neighbourhood search pass {passes}")
        if better:
            continue
        # the search is stuck: the time left goes back to discovery, from its cells and schedule
        found = discover(problem, small, t0 + limit, profile.threads, profile.seed, step_s=o("step_s"),
                         start=(operated, delay), gap=o("mip_rel_gap"), cliques=o("cliques"),
                         round_s=o("round_time_limit_s"), state=state)
        rounds += found.rounds
        if found.operated is not None and found.delay_s is not None and \
                evaluate(problem, found.operated, found.delay_s) < evaluate(problem, operated, delay):
            operated, delay = found.operated, found.delay_s
        if not found.rounds:
            break
    value = evaluate(problem, operated, delay)
    proved = found.bound is not None and value - found.bound <= 1e-9 * (1.0 + abs(value))
    extras = {"model": "continuous (bound: " + found.model + ")", "model_kind": "continuous",
              "rounds": len(rounds), "cuts": int(sum(r.cuts for r in rounds)),
              "columns": rounds[-1].columns if rounds else 0, "rows": rounds[-1].rows if rounds else 0,
              "clique_rows": state.get("clique_rows", 0),
              "discovery_objective": found.objective, "lns_passes": passes, "lns_windows_improved": windows,
              "warm_start": f"{start.source} {start.objective:.6f}",
              "continuous_bound": found.bound, "continuous_bound_model": found.model}
    schedule = make_schedule(problem, "discovery", "optimal" if proved else "time_limit", operated, delay,
                             proved_for="continuous" if proved else "none", bound=found.bound,
                             solve_seconds=time.perf_counter() - t0, seed=profile.seed, extras=extras)
    return no_worse(problem, schedule, start)
