"""Solver ``timeindexed``: the scheduling model of Sec. 4.3 on a delay grid, as a 0-1 program.

Model (one step s, the paper's ΔT_a = 10 s by default)
-------------------------------------------------------
Binary x_{f,k} = 1: flight f operates with delay index k ∈ {0, …, K_f}, K_f = ⌊U_f / s⌋ (Eqs. 26,
29); all x_{f,·} = 0 cancels f. Rows:

- assignment    Σ_k x_{f,k} ≤ 1 (c_f = Σ_k x_{f,k});
- precedence    Σ_k x_{f,k} ≤ Σ_{r ∈ group} Σ_k x_{r,k} (group: the outbound, or any copy of it with speed
  options): a cancelled outbound cancels its return;
- pair rows     for a pair (p, q) whose index difference z = k_q − k_p may not lie in a set Z
  (a union of integer intervals): for every a, x_{p,a} + Σ_{b ∈ a + Z} x_{q,b} ≤ 1 — the
  *aggregated* conflict inequality, exact for 0-1 points because Σ_b x_{q,b} ≤ 1, and far tighter
  in the LP than big-M rows. Pairs are (i) every conflicting pair of ``problem.conflicts`` (its
  forbidden open intervals (lo, hi) of δ = dep_q − dep_p, read from ``problem.pairs``) and
  (ii) every ordered pair e before f of one aircraft (turnaround, Eqs. 27-28: dep_f − dep_e ≥
  A_ef = T_e + ΔT_e with both operated; the all-pairs form is exact, model.py);
- capacity rows (shape ``cumulative``: more than one pad, families/pads.py) a hold of event e with
  index k is the interval [D_f + k s + o_e, D_f + k s + o_e + l_e); for every maximal set of such
  intervals at one resource that share an instant (a maximal clique of the interval graph, found
  by one sweep) holding more than C flights, Σ x_{f,k} ≤ C. Exact on the grid: the load is largest at some hold's start, which
  lies in a maximal clique. ``relaxed``: only the part of a hold every delay of its cell covers,
  [D_f + (k+1) s + o_e, D_f + k s + o_e + l_e), enters the rows (a relaxation);
- objective     Σ_{f,k} (w_d · k s − w_c) x_{f,k}: Eq. 20 (w_d = ω6/G, w_c = ω7) or the
  lexicographic scalar (w_d = 1/(ΣU + 1), w_c = 1).

Two readings of Z, with ΔD = D_q − D_p and η = 10⁻⁹ s / s of round-off:

``grid`` — delays *are* k·s (the paper's ΔT_a grid, as its GA/SOA chromosomes). z is forbidden iff
  lo < ΔD + s z < hi: Z = [⌊(lo − ΔD)/s + η⌋ + 1, ⌈(hi − ΔD)/s − η⌉ − 1]; turnaround forbids
  z < ⌈(A − ΔD_ef)/s − η⌉. This model is **exact for the grid-restricted problem**: its optimum is
  the best schedule with delays on the ΔT_a grid, every solution is feasible for the continuous
  model (Sec. 4.3), and so its optimum is ≥ the continuous optimum (a *restriction*).
``relaxed`` — k is the grid *cell* of a continuous delay, d ∈ [k s, (k+1) s). A cell pair (a, b)
  is forbidden only if *every* delay pair in it is: δ then ranges over the open interval
  (ΔD + s(z − 1), ΔD + s(z + 1)), so z is forbidden iff lo + τ ≤ ΔD + s(z − 1) and
  ΔD + s(z + 1) ≤ hi − τ (τ = ``TIME_TOL_S``: conservative, forbid less); turnaround forbids z
  only when s(z + 1) ≤ A − ΔD_ef − τ; the cost of a cell is its lower end k s. Every continuous
  schedule maps to a feasible point of no greater cost, so this model is a **relaxation of the
  continuous model**: its optimum (and any bound of it, e.g. its LP) is a valid lower bound for
  continuous delays. Its solutions are not schedules; only its bound is used.

So  relaxed(s) ≤ continuous optimum ≤ grid(s),  and both gaps close as s → 0.

Delay bounds are first capped by dominance (:func:`~uamopt.solvers.warmstart.reduced`, weighted
objective: no optimum changes), which shrinks the model several-fold.

Engines: ``engine = "highs"`` (highspy directly; MIP start from :mod:`warmstart` via
``setSolution``) or ``"cpsat"`` (OR-Tools CP-SAT on the same 0-1 model: at-most-one rows, the
objective scaled to integers exactly as in cpsat.py; hints from the warm start; pair rows written
from both sides), ``"hybrid"`` (HiGHS without presolve for ``HYBRID_HIGHS_SHARE`` of the time —
it finds good incumbents fast — then CP-SAT hinted with HiGHS's best, whose clique-merged LP gives
the far better bound; the better incumbent and the larger bound of the two, both of this model) or
``"auto"`` (default: HiGHS up to ``AUTO_HIGHS_COLUMNS`` columns, else hybrid — HiGHS proved the
300- and 600-flight rungs optimal, but at 1,000 its presolve used the whole 300 s).

Options: ``step_s`` (s, default 10), ``model`` ("grid" | "relaxed", default "grid"), ``engine``
("auto" | "highs" | "cpsat" | "hybrid", default "auto"), ``warm_soa_s`` (seconds of SOA in the warm start, default 0),
``continuous_bound_s`` (default 0: seconds kept, at most half the limit, for after a ``grid`` solve on the ``relaxed``
model at ``continuous_bound_step_s`` (default ``step_s``), whose bound is reported as
``extras["continuous_bound"]``), ``mip_rel_gap`` (default 0), ``cliques`` (default true: the clique
rows of cliques.py), ``refine_step_s`` (default 0: none; coarse to fine, :func:`_refine`: 40 % of the
engine's time on the ``step_s`` grid, the rest on the finer grid started from its best). The summary names the model:
``extras["model"]`` = e.g. "delay grid 10 s (exact for delays on the grid)".
Termination: from the engine's own — ``optimal`` when its bound meets its schedule (proved on the
named model: ``proved_for`` ``restricted``, or ``continuous`` when the grid is exact or the relaxed
cells' bound meets it), ``stopped`` at a ``mip_rel_gap`` above that, ``time_limit``; never inferred
from elapsed time.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from uamopt.errors import UamoptError
from uamopt.interrupts import stopping
from uamopt.schedule.flights import TIME_TOL_S
from uamopt.schedule.model import ProvedFor, Schedule, SchedulingProblem, Termination, closes, evaluate, make_schedule
from uamopt.solvers.highs import highs_can_start, mip_solver, run_mip, start_solution
from uamopt.solvers.warmstart import Start, no_schedule, no_worse, reduced, warm_start
from uamopt.solvers.watchdog import report_incumbent

if TYPE_CHECKING:
    from uamopt.solvers import SolverProfile

SHAPES = frozenset({"bounds", "must_operate", "precedence", "turnaround", "pairs", "cumulative"})  # build_grid_model
OBJECTIVES = frozenset({"weighted", "lexicographic", "earliness_tardiness"})
ETA_S = 1e-9  # float round-off accepted when rounding a time to grid steps, s
AUTO_HIGHS_COLUMNS = 8000  # engine "auto": HiGHS up to this many columns, "hybrid" above
HYBRID_HIGHS_SHARE = 0.3  # engine "hybrid": this share of the time to HiGHS (no presolve), the rest to CP-SAT


@dataclass(frozen=True)
class GridModel:
    """The 0-1 model as arrays (module docstring). Column of (f, k): ``start[f] + k``."""

    step_s: float
    kind: str  # "grid" | "relaxed"
    start: np.ndarray  # (n + 1,) first column of each flight
    cost: np.ndarray  # (N,) objective coefficient per column
    row_ptr: np.ndarray  # pair and assignment rows (all "≤ 1", coefficients 1): CSR
    row_col: np.ndarray
    prec: list  # [(f, group)]: Σ x_f ≤ Σ_{r ∈ group} Σ x_r (families/turnaround.py Precedence)
    must: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))  # flights with Σ x_f = 1 (core.py)
    #: capacity rows Σ x ≤ cap_rhs (shape cumulative): CSR over columns
    cap_ptr: np.ndarray = field(default_factory=lambda: np.zeros(1, np.int64))
    cap_col: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    cap_rhs: np.ndarray = field(default_factory=lambda: np.zeros(0))
    cliques: int = 0  # clique rows among the "≤ 1" rows (cliques.py), after the pair rows
    dominated_pair_rows: int = 0  # pair rows dropped because a clique row implies them

    @property
    def n_cols(self) -> int:
        return int(self.start[-1])

    @property
    def n_rows(self) -> int:
        return len(self.row_ptr) - 1 + len(self.prec) + len(self.must) + len(self.cap_rhs)

    def columns_of(self, operated: np.ndarray, delay_s: np.ndarray) -> np.ndarray | None:
        """The 0-1 vector of a schedule whose delays are on the grid, or None if one is not."""
        k = np.rint(delay_s / self.step_s).astype(np.int64)
        on = np.asarray(operated, dtype=bool)
        if np.any(on & (np.abs(k * self.step_s - delay_s) > 1e-6)) or np.any(on & (k > np.diff(self.start) - 1)):
            return None
        x = np.zeros(self.n_cols)
        x[self.start[:-1][on] + k[on]] = 1.0
        return x

    def decode(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Operated flags and delays k·s of a 0-1 vector."""
        n = len(self.start) - 1
        col = np.flatnonzero(np.asarray(x) > 0.5)
        flight = np.searchsorted(self.start, col, side="right") - 1
        operated, delay = np.zeros(n, dtype=bool), np.zeros(n)
        operated[flight] = True
        delay[flight] = (col - self.start[flight]) * self.step_s
        return operated, delay


def delay_indices(problem: SchedulingProblem, step_s: float) -> np.ndarray:
    """K_f = ⌊U_f / s⌋ (round-off ``ETA_S`` forgiven): each flight's largest delay index on the grid of ``step_s``."""
    return np.floor(problem.delay_upper_s / step_s + ETA_S / step_s).astype(np.int64)


def _forbidden_steps(problem: SchedulingProblem, step_s: float, kind: str, k_max: np.ndarray):
    """(p, q, z_lo, z_hi): the integer intervals of forbidden z = k_q − k_p, conflicts then turnarounds."""
    eta = ETA_S / step_s
    s = step_s
    view = problem.pairs  # forbidden intervals of δ, less the pair's shift: of z = d_q − d_p (core.py)
    p, q = view.p[view.row_pair], view.q[view.row_pair]
    lo, hi = view.lo - view.shift[view.row_pair], view.hi - view.shift[view.row_pair]
    if kind == "grid":
        z_lo, z_hi = np.floor(lo / s + eta) + 1, np.ceil(hi / s - eta) - 1
    else:
        z_lo, z_hi = np.ceil((lo + TIME_TOL_S) / s + 1 + eta), np.floor((hi - TIME_TOL_S) / s - 1 - eta)
    t = problem.turnaround  # rows (e, f, need): k_f s − k_e s must reach need (families/turnaround.py)
    tp, tq, need = t.e, t.f, t.need_s
    t_hi = np.ceil(need / s - eta) - 1 if kind == "grid" else np.floor((need - TIME_TOL_S) / s - 1 - eta)
    p, q = np.concatenate([p, tp]), np.concatenate([q, tq])
    z_lo = np.concatenate([z_lo, np.full(len(tp), -np.inf)])
    z_hi = np.concatenate([z_hi, t_hi])
    # clip to reachable differences z ∈ [−K_p, K_q]; keep non-empty intervals
    z_lo = np.maximum(z_lo, -k_max[p]).astype(np.int64) if len(p) else z_lo.astype(np.int64)
    z_hi = np.minimum(z_hi, k_max[q]).astype(np.int64) if len(p) else z_hi.astype(np.int64)
    keep = z_lo <= z_hi
    return p[keep], q[keep], z_lo[keep], z_hi[keep]


def _capacity_rows(problem: SchedulingProblem, step_s: float, kind: str, k_max: np.ndarray, start: np.ndarray):
    """(ptr, cols, rhs) of the capacity rows of the module docstring: one per maximal clique of
    each cumulative resource's hold intervals that holds more flights than the capacity."""
    ptr, cols, rhs = [0], [], []
    dep = problem.planned_departure_s
    for family in problem.of_shape("cumulative"):
        rest = family.residual()
        for r, cap in enumerate(rest.capacity.tolist()):
            ev = np.flatnonzero(rest.resource == r)
            if not len(ev):
                continue
            f = rest.flight[ev]
            count = k_max[f] + 1
            rep = np.repeat(np.arange(len(ev)), count)
            k = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
            base = dep[f[rep]] + rest.offset_s[ev[rep]]
            length = rest.duration_s[ev[rep]]
            if kind == "grid":
                a, b = base + k * step_s, base + k * step_s + length
            else:  # the part of the hold every delay of the cell [k s, (k+1) s) covers
                a, b = base + (k + 1) * step_s, base + k * step_s + length
            b = b - ETA_S * np.maximum(1.0, np.abs(b))  # an end at a start's instant: apart (half-open)
            col = start[f[rep]] + k
            keep = b > a
            a, b, col = a[keep], b[keep], col[keep]
            flight_of = f[rep][keep]  # a row binds only where more flights than pads meet
            if len(col) <= cap:
                continue
            # sweep: ends before starts at one instant; a start followed by an end closes a maximal clique
            times = np.concatenate([a, b])
            kinds = np.concatenate([np.ones(len(a), np.int8), np.zeros(len(b), np.int8)])
            which = np.concatenate([np.arange(len(a)), np.arange(len(b))])
            active: dict[int, None] = {}
            grew = False
            for j in np.lexsort((kinds, times)).tolist():
                if kinds[j]:
                    active[int(which[j])] = None
                    grew = True
                    continue
                if grew and len(active) > cap and len(set(flight_of[list(active)].tolist())) > cap:
                    cols.append(col[list(active)])
                    ptr.append(ptr[-1] + len(active))
                    rhs.append(float(cap))
                grew = False
                active.pop(int(which[j]), None)
    cols_all = np.concatenate(cols).astype(np.int64) if cols else np.zeros(0, np.int64)
    return np.asarray(ptr, dtype=np.int64), cols_all, np.asarray(rhs, dtype=float)


def build_grid_model(problem: SchedulingProblem, step_s: float = 10.0, kind: str = "grid", both_ways: bool = False,
                     cliques: bool = False) -> GridModel:
    """The time-indexed model of the module docstring, vectorised over pairs and delay indices.

    ``both_ways`` also writes each pair's rows from q's side (x_{q,b} + Σ_{a: b − a ∈ Z} x_{p,a} ≤ 1):
    twice the rows, a tighter relaxation for CP-SAT's propagation and LP. ``cliques`` adds the
    occupancy's clique rows and drops the pair rows one of them implies (cliques.py): the same
    integer points, a far tighter LP."""
    if kind not in ("grid", "relaxed"):
        raise UamoptError(f"unknown time-indexed model '{kind}'", "solver timeindexed", "use model = \"grid\" or \"relaxed\"")
    if not (math.isfinite(step_s) and step_s > 0):
        raise UamoptError(f"step_s must be positive, got {step_s}", "solver timeindexed",
                          "give the delay grid step in s, e.g. 10")
    n = problem.n_flights
    k_max = delay_indices(problem, step_s)
    start = np.concatenate([[0], np.cumsum(k_max + 1)]).astype(np.int64)
    flight_of_col = np.repeat(np.arange(n), k_max + 1)
    k_of_col = np.arange(start[-1]) - start[flight_of_col]
    o = problem.objective
    if kind == "relaxed" and o.per_flight_terms:  # a cell's least cost: at the point nearest the target
        at = np.clip(o.terms[0][flight_of_col], k_of_col * step_s, (k_of_col + 1) * step_s)
    else:  # the grid point; for the relaxed linear kinds the cell's lower end
        at = k_of_col * step_s
    cost = o.delay_cost(at, flight_of_col) - o.per_flight
    p, q, z_lo, z_hi = _forbidden_steps(problem, step_s, kind, k_max)
    if both_ways:
        p, q = np.concatenate([p, q]), np.concatenate([q, p])
        z_lo, z_hi = np.concatenate([z_lo, -z_hi]), np.concatenate([z_hi, -z_lo])
    # one row per (pair interval, a): b ∈ [max(0, a + z_lo), min(K_q, a + z_hi)], then rows merged per (p, q, a)
    a_count = k_max[p] + 1
    iv = np.repeat(np.arange(len(p)), a_count)
    a = np.arange(a_count.sum()) - np.repeat(np.cumsum(a_count) - a_count, a_count)
    b_lo = np.maximum(0, a + z_lo[iv])
    b_hi = np.minimum(k_max[q[iv]], a + z_hi[iv])
    live = b_lo <= b_hi
    iv, a, b_lo, b_hi = iv[live], a[live], b_lo[live], b_hi[live]
    width = b_hi - b_lo + 1
    ent_iv = np.repeat(np.arange(len(iv)), width)
    b = np.arange(width.sum()) - np.repeat(np.cumsum(width) - width, width) + b_lo[ent_iv]
    col_q = start[q[iv[ent_iv]]] + b
    # row key: (p, q, a); one pair may have several intervals (and turnaround + conflict never share a pair)
    key_row = (p[iv] * n + q[iv]) * (int(k_max.max()) + 1) + a
    key_ent = key_row[ent_iv]
    col_p = start[p[iv]] + a
    packed = np.unique(np.concatenate([key_row, key_ent]) * start[-1] + np.concatenate([col_p, col_q]))  # x_{p,a} once per row
    row_key, col = np.divmod(packed, start[-1])
    _, first = np.unique(row_key, return_index=True)
    pair_ptr = np.append(first, len(packed)).astype(np.int64)
    # assignment rows Σ_k x_{f,k} ≤ 1 (only for flights with more than one column)
    multi = np.flatnonzero(k_max > 0)
    assign_cols = np.concatenate([np.arange(start[f], start[f + 1]) for f in multi]) if len(multi) else np.zeros(0, np.int64)
    assign_ptr = np.concatenate([[0], np.cumsum(k_max[multi] + 1)]).astype(np.int64)
    row_ptr = np.concatenate([assign_ptr, assign_ptr[-1] + pair_ptr[1:]])
    row_col = np.concatenate([assign_cols, col]).astype(np.int64)
    n_cliques = n_dominated = 0
    if cliques:  # clique rows from the occupancy (cliques.py); the pair rows they imply dropped
        from uamopt.solvers.cliques import drop_dominated, occupancy_cliques

        clique_ptr, clique_col = occupancy_cliques(problem, start, step_s, kind)
        n_cliques = len(clique_ptr) - 1
        if n_cliques:
            pair_ptr, col, n_dominated = drop_dominated(pair_ptr, col, clique_ptr, clique_col, int(start[-1]))
            row_ptr = np.concatenate([assign_ptr, assign_ptr[-1] + pair_ptr[1:], assign_ptr[-1] + pair_ptr[-1] + clique_ptr[1:]])
            row_col = np.concatenate([assign_cols, col, clique_col]).astype(np.int64)
    prec = [(f, group) for family in problem.of_shape("precedence") for f, group in family.groups()]
    cap_ptr, cap_col, cap_rhs = _capacity_rows(problem, step_s, kind, k_max, start)
    return GridModel(step_s=float(step_s), kind=kind, start=start, cost=cost, row_ptr=row_ptr, row_col=row_col, prec=prec,
                     must=np.flatnonzero(problem.must_operate).astype(np.int64), cap_ptr=cap_ptr, cap_col=cap_col,
                     cap_rhs=cap_rhs, cliques=n_cliques, dominated_pair_rows=n_dominated)


def model_name(kind: str, step_s: float) -> str:
    """What a bound or an optimum of the model is about (summary.json ``model``)."""
    if kind == "grid":
        return f"delay grid {step_s:g} s (exact for delays on the grid; a restriction of the continuous model)"
    return f"delay cells {step_s:g} s (relaxation of the continuous model; its bound holds for continuous delays)"


# --- engines -------------------------------------------------------------------------------------
@dataclass
class EngineResult:
    x: np.ndarray | None  # incumbent 0-1 vector (None: none)
    bound: float | None
    proved: bool
    termination: str
    seconds: float
    first_incumbent_s: float | None = None  # s after the engine started (the warm start is ready before)
    best_incumbent_s: float | None = None


def _left(deadline: float) -> float:
    """Seconds to ``deadline`` (a ``time.perf_counter`` time), at least 0.05."""
    return max(0.05, deadline - time.perf_counter())


def load_model(h, model: GridModel, integer: bool) -> None:
    """Load a :class:`GridModel` into ``highspy.Highs`` ``h``: 0-1 columns (continuous in [0, 1]
    unless ``integer``), its "≤ 1", precedence, must-operate and capacity rows."""
    import highspy

    n = model.n_cols
    inf = highspy.kHighsInf
    h.addVars(n, np.zeros(n), np.ones(n))
    h.changeColsCost(n, np.arange(n, dtype=np.int32), model.cost)
    if integer:
        h.changeColsIntegrality(n, np.arange(n, dtype=np.int32), np.full(n, highspy.HighsVarType.kInteger))
    m = len(model.row_ptr) - 1
    h.addRows(m, np.full(m, -inf), np.ones(m), len(model.row_col), model.row_ptr[:-1].astype(np.int32),
              model.row_col.astype(np.int32), np.ones(len(model.row_col)))
    if len(model.prec):  # Σ x_f − Σ x_r ≤ 0
        cols, vals, ptr = [], [], [0]
        for f, group in model.prec:
            cols += list(range(model.start[f], model.start[f + 1]))
            vals += [1.0] * int(model.start[f + 1] - model.start[f])
            for r in group.tolist():
                cols += list(range(model.start[r], model.start[r + 1]))
                vals += [-1.0] * int(model.start[r + 1] - model.start[r])
            ptr.append(len(cols))
        k = len(model.prec)
        h.addRows(k, np.full(k, -inf), np.zeros(k), len(cols), np.array(ptr[:-1], dtype=np.int32),
                  np.array(cols, dtype=np.int32), np.array(vals))
    if len(model.must):  # Σ_k x_{f,k} ≥ 1: must operate
        spans = [np.arange(model.start[f], model.start[f + 1]) for f in model.must.tolist()]
        must_ptr = np.concatenate([[0], np.cumsum([len(c) for c in spans])[:-1]]).astype(np.int32)
        must_cols = np.concatenate(spans).astype(np.int32)
        h.addRows(len(spans), np.ones(len(spans)), np.full(len(spans), inf), len(must_cols), must_ptr, must_cols,
                  np.ones(len(must_cols)))
    if len(model.cap_rhs):  # Σ x ≤ C: capacity
        c = len(model.cap_rhs)
        h.addRows(c, np.full(c, -inf), model.cap_rhs, len(model.cap_col), model.cap_ptr[:-1].astype(np.int32),
                  model.cap_col.astype(np.int32), np.ones(len(model.cap_col)))


def run_highs(model: GridModel, deadline: float, threads: int, seed: int, gap: float, hint: np.ndarray | None,
              presolve: bool = True) -> EngineResult:
    """HiGHS on a :class:`GridModel` until ``deadline`` (a ``time.perf_counter`` time), from the MIP
    start ``hint`` when given (discovery.py runs its rounds through it too)."""
    # at 1,000 flights HiGHS's presolve took the whole limit; without it HiGHS finds incumbents fast
    h = mip_solver(threads, seed, gap, presolve)
    load_model(h, model, integer=True)
    if hint is not None:
        h.setSolution(start_solution(hint))
    run = run_mip(h, deadline, "solver timeindexed")  # what the model's loading left of the limit
    x = run.x
    if hint is not None and x is not None and abs(float(model.cost @ x) - run.objective) > 1e-6 * (
            1.0 + abs(run.objective)):  # a solution that is not the one reported: trust neither (the dual bound holds)
        again = run_highs(model, deadline, threads, seed, gap, None, presolve)
        if run.bound is not None and (again.bound is None or again.bound < run.bound):
            again = dataclasses.replace(again, bound=run.bound)
        return again
    bound = run.bound
    if run.proved and x is not None:
        bound = min(bound, float(model.cost @ np.round(x))) if bound is not None else float(model.cost @ np.round(x))
    return EngineResult(x=x, bound=bound, proved=run.proved, termination=run.termination, seconds=run.seconds,
                        first_incumbent_s=run.found[0] if run.found else None,
                        best_incumbent_s=run.found[-1] if run.found else None)


def _cpsat(model: GridModel, problem: SchedulingProblem, deadline: float, threads: int, seed: int, gap: float,
           hint: np.ndarray | None) -> EngineResult:
    from ortools.sat.python import cp_model

    from uamopt.solvers.cpsat import integer_objective, objective_bound

    k_max = np.diff(model.start) - 1
    per_unit, per_flight, divisor, how = integer_objective(problem, model.step_s, k_max)
    m = cp_model.CpModel()
    x = [m.new_bool_var(f"x{j}") for j in range(model.n_cols)]
    for r in range(len(model.row_ptr) - 1):
        m.add_at_most_one([x[j] for j in model.row_col[model.row_ptr[r]:model.row_ptr[r + 1]].tolist()])
        if r % 20000 == 19999 and time.perf_counter() > deadline:  # the limit ran out while loading the model
            return EngineResult(x=None, bound=None, proved=False, termination="not run (the limit ran out building)",
                                seconds=0.0)
    for f, group in model.prec:
        m.add(sum(x[model.start[f]:model.start[f + 1]])
              <= sum(x[j] for r in group.tolist() for j in range(model.start[r], model.start[r + 1])))
    for f in model.must.tolist():
        m.add_exactly_one(x[model.start[f]:model.start[f + 1]])
    for r, cap in enumerate(model.cap_rhs.tolist()):
        m.add(sum(x[j] for j in model.cap_col[model.cap_ptr[r]:model.cap_ptr[r + 1]].tolist()) <= int(cap))
    k_of_col = np.arange(model.n_cols) - np.repeat(model.start[:-1], k_max + 1)
    if problem.objective.per_flight_terms:  # earliness/tardiness in integers (cpsat.integer_terms)
        from uamopt.solvers.cpsat import integer_terms

        target_k, e_int, l_int, per_flight, divisor, how = integer_terms(problem, model.step_s, k_max)
        f_of_col = np.repeat(np.arange(len(k_max)), k_max + 1)
        a = target_k[f_of_col] - (1 if model.kind == "relaxed" else 0)  # a cell is charged its least earliness
        coef = (e_int[f_of_col] * np.maximum(0, a - k_of_col) + l_int[f_of_col] * np.maximum(0, k_of_col - target_k[f_of_col])
                - per_flight).astype(np.int64).tolist()
    else:
        from uamopt.solvers.cpsat import operate_units

        f_of_col = np.repeat(np.arange(len(k_max)), k_max + 1)
        coef = (per_unit * (k_of_col + operate_units(problem, model.step_s)[f_of_col]) - per_flight).astype(np.int64).tolist()
    m.minimize(cp_model.LinearExpr.weighted_sum(x, coef))
    if hint is not None:
        for j in range(model.n_cols):
            m.add_hint(x[j], bool(hint[j] > 0.5))
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = _left(deadline)
    solver.parameters.num_workers = int(threads)
    solver.parameters.random_seed = int(seed)
    solver.parameters.relative_gap_limit = float(gap)
    solver.parameters.catch_sigint_signal = False  # its own Ctrl-C handler swallows the interrupt (uamopt.interrupts)
    found: list[float] = []

    class _Times(cp_model.CpSolverSolutionCallback):
        def on_solution_callback(self) -> None:
            found.append(self.wall_time)

    with stopping(solver.stop_search):
        code = solver.solve(m, _Times())
    has = code in (cp_model.OPTIMAL, cp_model.FEASIBLE)
    values = np.array([solver.boolean_value(v) for v in x], dtype=float) if has else None
    bound = objective_bound(problem, solver.best_objective_bound, per_flight, divisor, model.step_s, how)
    return EngineResult(x=values, bound=bound, proved=code == cp_model.OPTIMAL, termination=solver.status_name(code),
                        seconds=float(solver.wall_time), first_incumbent_s=found[0] if found else None,
                        best_incumbent_s=found[-1] if found else None)


def run_engine(engine: str, model: GridModel, problem: SchedulingProblem, limit_s: float, threads: int, seed: int,
               gap: float = 0.0, hint: np.ndarray | None = None) -> EngineResult:
    """Solve a :class:`GridModel` with HiGHS or CP-SAT within ``limit_s`` seconds, loading the model
    into the solver included."""
    deadline = time.perf_counter() + limit_s
    if engine == "highs" and not highs_can_start(model.n_rows, limit_s):
        return EngineResult(x=None, bound=None, proved=False, seconds=0.0,
                            termination="not run (HiGHS could not start within the limit: solvers/highs.py)")
    if engine == "highs":
        return run_highs(model, deadline, threads, seed, gap, hint)
    if engine == "cpsat":
        return _cpsat(model, problem, deadline, threads, seed, gap, hint)
    if engine == "hybrid" and not highs_can_start(model.n_rows, HYBRID_HIGHS_SHARE * limit_s, presolve=False):
        return _cpsat(model, problem, deadline, threads, seed, gap, hint)  # HiGHS could not even start in its share
    if engine == "hybrid":  # HiGHS without presolve for incumbents, then CP-SAT from its best for the bound
        first = run_highs(model, time.perf_counter() + HYBRID_HIGHS_SHARE * limit_s, threads, seed, gap, hint, presolve=False)
        if first.proved:
            return first
        start = first.x if first.x is not None else hint
        second = _cpsat(model, problem, deadline, threads, seed, gap, start)
        xs = [r.x for r in (first, second) if r.x is not None]
        x = min(xs, key=lambda v: float(model.cost @ v)) if xs else None
        bounds = [b for b in (first.bound, second.bound) if b is not None]  # both bound the same model
        best_t = second.best_incumbent_s if x is second.x and second.best_incumbent_s is not None else first.best_incumbent_s
        return EngineResult(x=x, bound=max(bounds) if bounds else None, proved=first.proved or second.proved,
                            termination=f"highs: {first.termination}; cpsat: {second.termination}",
                            seconds=first.seconds + second.seconds, first_incumbent_s=first.first_incumbent_s,
                            best_incumbent_s=(best_t + (first.seconds if x is second.x else 0.0)) if best_t is not None else None)
    raise UamoptError(f"unknown engine '{engine}'", "solver timeindexed",
                      "use engine = \"auto\", \"highs\", \"cpsat\" or \"hybrid\"")


def _grid_is_exact(problem: SchedulingProblem, step_s: float) -> bool:
    """Whether the grid model of step s has the continuous model's optimum: the lattice test of
    cpsat.py (every time of the data a multiple of s, the objective's integer scaling exact)."""
    from uamopt.solvers.cpsat import integer_objective, lattice_is_exact

    k_max = delay_indices(problem, step_s)
    return lattice_is_exact(problem, step_s, integer_objective(problem, step_s, k_max)[3])


# --- the solver ------------------------------------------------------------------------------------
REFINE_COARSE_SHARE = 0.4  # refine_step_s > 0: this share of the engine's time to the coarse grid
REFINE_MIN_S = 5.0  # no refinement with less time than this for the finer grid
BOUND_MIN_STEP_S = 1.0  # the continuous bound's cells are halved down to this width at most, s
#: no refinement to a grid of more columns: models/benchmark_1000.toml's 5 s grid (25,500 columns,
#: 373,000 rows with its cliques) gave the best schedule in 300 s; the 3,000-flight rung's (76,500) would
#: take minutes and gigabytes to build
REFINE_MAX_COLUMNS = 40_000


def _columns(problem: SchedulingProblem, step_s: float) -> int:
    """The number of columns of the grid model of ``step_s``."""
    return int(np.sum(delay_indices(problem, step_s) + 1))


def _refine(small: SchedulingProblem, problem: SchedulingProblem, profile: SolverProfile, coarse: GridModel,
            result: EngineResult, start: Start, fine_step: float, engine: str, gap: float, deadline: float
            ) -> tuple[GridModel, EngineResult, str]:
    """Coarse to fine: the grid model of ``fine_step`` started from the coarse grid's best point (a
    point of the fine grid when the coarse step is a multiple of the fine one). Returns the model and
    result to report: the fine one when it gave a schedule no worse than the coarse one's, else the coarse."""
    left = deadline - time.perf_counter()
    if left < REFINE_MIN_S:
        return coarse, result, f"not run: {left:.0f} s left after the {coarse.step_s:g} s grid (needs {REFINE_MIN_S:g})"
    decisions = coarse.decode(result.x) if result.x is not None else start.decisions
    if result.x is not None and start.found and start.objective < evaluate(problem, *decisions) - 1e-12:
        decisions = start.decisions
    report_incumbent(problem, *decisions, f"the {coarse.step_s:g} s grid's best")  # a watched child's answer so far
    t = time.perf_counter()
    fine = build_grid_model(small, fine_step, "grid", both_ways=engine == "cpsat", cliques=profile.option("cliques"))
    hint = fine.columns_of(*decisions)
    second = run_engine(engine, fine, problem, max(0.1, deadline - time.perf_counter()), profile.threads, profile.seed,
                        gap, hint)
    took = time.perf_counter() - t
    if second.x is None:
        return coarse, result, (f"{fine_step:g} s grid: no schedule in {took:.0f} s ({second.termination}); "
                                f"the {coarse.step_s:g} s grid's kept")
    coarse_value = float(coarse.cost @ result.x) if result.x is not None else math.inf
    if float(fine.cost @ second.x) > coarse_value + 1e-9 * (1.0 + abs(coarse_value)):
        return coarse, result, f"{fine_step:g} s grid: worse in {took:.0f} s; the {coarse.step_s:g} s grid's kept"
    return fine, second, (f"{coarse.step_s:g} s grid {coarse_value:.6f}, then the {fine_step:g} s grid from it "
                          f"({took:.0f} s, {fine.n_cols} columns, {fine.cliques} cliques)")


def solve(problem: SchedulingProblem, profile: SolverProfile) -> Schedule:
    """Build the time-indexed model, warm-start it, solve it; see the module docstring."""
    o = profile.option  # typed and checked by the profile (uamopt.solvers.options)
    step, kind, engine, gap, cont_s = (o(k) for k in ("step_s", "model", "engine", "mip_rel_gap", "continuous_bound_s"))
    t0 = time.perf_counter()
    start: Start = warm_start(problem, step, soa_s=o("warm_soa_s"), seed=profile.seed, on_grid=True)
    small = reduced(problem)  # dominance caps: the same optima (warmstart.py)
    model = build_grid_model(small, step, kind, both_ways=engine == "cpsat", cliques=o("cliques"))
    if engine == "auto":  # measured (docs/exact_scheduling.md): with clique rows HiGHS leads at every rung;
        # without them HiGHS proves ≤ 600 flights and CP-SAT's merged cliques get further beyond
        engine = "highs" if model.cliques or model.n_cols <= AUTO_HIGHS_COLUMNS else "hybrid"
    built = time.perf_counter() - t0
    hint = model.columns_of(*start.decisions) if kind == "grid" and start.found else None
    refine = o("refine_step_s")
    cont_s = min(cont_s, 0.5 * profile.time_limit_s)  # a short limit: the grid keeps half of it
    limit = max(0.1, profile.time_limit_s - built - cont_s)
    refining = (kind == "grid" and 0 < refine < step and _columns(small, refine) <= REFINE_MAX_COLUMNS
                and limit * (1 - REFINE_COARSE_SHARE) >= REFINE_MIN_S)
    result = run_engine(engine, model, problem, limit * (REFINE_COARSE_SHARE if refining else 1.0), profile.threads,
                        profile.seed, gap, hint)
    coarse_termination = result.termination
    if refining and (result.x is not None or start.found):  # even a coarse optimum: the finer grid holds more
        model, result, fine_note = _refine(small, problem, profile, model, result, start, refine, engine, gap,
                                           t0 + profile.time_limit_s - cont_s)
        step = model.step_s
    else:
        fine_note = None
    extras = {"model": model_name(kind, step), "engine": engine, "engine_termination": result.termination,
              "columns": model.n_cols, "rows": model.n_rows, "cliques": model.cliques,
              "dominated_pair_rows": model.dominated_pair_rows, "build_seconds": round(built, 3),
              "warm_start": f"{start.source} {start.objective:.6f}", "warm_start_s": round(start.seconds, 3),
              "engine_first_incumbent_s": result.first_incumbent_s, "engine_best_incumbent_s": result.best_incumbent_s,
              "engine_seconds": round(result.seconds, 3)}
    if kind == "grid" and 0 < refine < step and not refining:
        extras["refined"] = (f"not run: the {refine:g} s grid would have {_columns(small, refine)} columns (at most "
                             f"{REFINE_MAX_COLUMNS}), or less than {REFINE_MIN_S:g} s would be left for it")
    if fine_note is not None:
        extras.update(refined=fine_note, coarse_termination=coarse_termination, model_kind=f"delay grid {step:g} s")
    n = problem.n_flights
    if result.x is None and "infeasible" in result.termination.lower() and not len(model.cap_rhs):
        # infeasible on the grid, a restriction: the continuous MILP (milp.py) decides, in the time left
        from uamopt.solvers import milp

        left = max(0.1, profile.time_limit_s - (time.perf_counter() - t0))
        proof = milp.solve(problem, dataclasses.replace(profile, solver="highs", time_limit_s=left, options={}))
        if proof.status == "infeasible":  # proved for continuous delays
            extras.update(reason=proof.extras.get("reason"), infeasible_proof="the continuous MILP (highs)")
            return make_schedule(problem, "timeindexed", "infeasible", np.zeros(n, bool), np.zeros(n), proved_for="continuous",
                                 solve_seconds=time.perf_counter() - t0, seed=profile.seed, extras=extras)
        extras.update(grid="infeasible on the grid; schedule from the continuous MILP", model_kind="continuous")
        return make_schedule(problem, "timeindexed", proof.termination, proof.operated, proof.delay_s,
                             proved_for=proof.proved_for, bound=proof.bound,
                             solve_seconds=time.perf_counter() - t0, seed=profile.seed, extras={**proof.extras, **extras})
    if not start.found and (kind == "relaxed" or result.x is None):
        raise no_schedule(problem, profile.name or "timeindexed", f"the engine stopped ({result.termination}) with none")
    if kind == "relaxed":  # a bound only: the incumbent shown is the warm start (feasible, continuous)
        extras["incumbent"] = f"warm start ({start.source}); the relaxation's points are not schedules"
        return make_schedule(problem, "timeindexed", "time_limit", *start.decisions, bound=result.bound,
                             solve_seconds=time.perf_counter() - t0, seed=profile.seed, extras=extras)
    if result.x is None:
        operated, delay = np.zeros(n, dtype=bool), np.zeros(n)
    else:
        operated, delay = model.decode(result.x)
    # The grid model is a restriction: "optimal" on it is not optimal for continuous delays, and its
    # bound is no bound of the continuous problem. Status optimal_on_grid; the grid bound is kept in
    # extras["restricted_bound"]; ``bound`` holds only the relaxed model's bound, when computed.
    extras["restricted_bound"] = result.bound
    exact = _grid_is_exact(problem, step)  # every time on the grid: the grid's optimum and bound are the continuous ones
    extras["grid_exact"] = exact
    # proved: the engine closed its gap (to its tolerance; a gap limit above that is its own rule, no proof)
    closed = result.proved and result.x is not None and closes(float(model.cost @ np.round(result.x)), result.bound)
    termination: Termination = "optimal" if closed else "stopped" if result.proved else "time_limit"
    proved_for: ProvedFor = ("continuous" if exact else "restricted") if closed else "none"
    schedule = make_schedule(problem, "timeindexed", termination, operated, delay, proved_for=proved_for,
                             bound=result.bound if exact else None,
                             solve_seconds=time.perf_counter() - t0, seed=profile.seed, extras=extras)
    schedule = no_worse(problem, schedule, start)
    if cont_s > 0:
        c_step = o("continuous_bound_step_s", step)
        relaxed = build_grid_model(small, c_step, "relaxed", cliques=o("cliques"))
        left = max(0.1, profile.time_limit_s - (time.perf_counter() - t0))
        r = run_engine(engine, relaxed, problem, left, profile.threads, profile.seed, gap, None)
        schedule.extras.update(continuous_bound=r.bound, continuous_bound_model=model_name("relaxed", c_step),
                               continuous_bound_termination=r.termination)
        # coarse to fine for the bound too: while a relaxation is proved with time left, the cells of half
        # the width (each one's optimum is a bound of the continuous problem; the largest is kept)
        while (r.proved and o("refine_step_s") > 0 and c_step / 2 >= BOUND_MIN_STEP_S
               and _columns(small, c_step / 2) <= REFINE_MAX_COLUMNS
               and profile.time_limit_s - (time.perf_counter() - t0) >= REFINE_MIN_S):
            c_step /= 2
            finer = build_grid_model(small, c_step, "relaxed", cliques=o("cliques"))
            left = max(0.1, profile.time_limit_s - (time.perf_counter() - t0))
            r = run_engine(engine, finer, problem, left, profile.threads, profile.seed, gap, None)
            if r.bound is not None and (schedule.extras["continuous_bound"] is None
                                        or r.bound > schedule.extras["continuous_bound"]):
                schedule.extras.update(continuous_bound=r.bound, continuous_bound_model=model_name("relaxed", c_step),
                                       continuous_bound_termination=r.termination)
        r = dataclasses.replace(r, bound=schedule.extras["continuous_bound"])
        if r.bound is not None and schedule.objective is not None:
            schedule.extras["optimal_within"] = schedule.objective - r.bound
        termination, proved_for = schedule.termination, schedule.proved_for
        if closes(schedule.objective, r.bound):  # the continuous bound meets the grid's schedule
            termination, proved_for = "optimal", "continuous"
        schedule = make_schedule(problem, "timeindexed", termination, schedule.operated, schedule.delay_s,
                                 proved_for=proved_for,
                                 bound=r.bound, solve_seconds=time.perf_counter() - t0, seed=profile.seed,
                                 extras=schedule.extras)
    return schedule
