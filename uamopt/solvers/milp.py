"""Solver ``highs``: the exact MILP of Sec. 4.3 (Eqs. 20-31) in Pyomo, solved by HiGHS.

The model (PyPSA style: ``build_model`` calls one ``define_*`` per constraint family), on the
data of a :class:`SchedulingProblem`:

Variables
    c_f ∈ {0, 1}  (``operate``), operated or cancelled;
    d_f ∈ [0, U_f] (``delay``, s), U_f = ``delay_upper_s[f]`` = min(Δd_f, T_f − A_f) (Eqs. 26, 29);
    d_f ≤ U_f c_f, so a cancelled flight's delay is 0 and Σ_f d_f = Σ_f c_f d_f exactly (Eq. 21
    is bilinear otherwise).
(a) precedence   c_f ≤ c_{requires[f]}: a return needs its outbound.
(b) turnaround   (Eqs. 27-28), every ordered pair e before f of one aircraft:
    dep_f − dep_e ≥ T_e + ΔT_e when c_e = c_f = 1. With A = D_e + T_e + ΔT_e − D_f this is
    d_f − d_e ≥ A − M_f (1 − c_f) − M_e (1 − c_e), M_f = (A + U_e)⁺, M_e = A⁺: the smallest M that
    cut no point with a cancelled flight (its delay is 0); dropped when A + U_e ≤ 0 (never binds).
(c) conflicts    (Eq. 24 via the exact core of docs/readings.md): pair (p, q) must keep δ = dep_q − dep_p
    out of its open intervals (lo_k, hi_k). Within δ's reachable range R = [D_q − D_p − U_p,
    D_q − D_p + U_q] the admissible δ form closed gaps [g_j, h_j]; one binary y_j per gap,
    Σ_j y_j ≥ c_p + c_q − 1, and y_j = 1 ⇒ g_j ≤ δ ≤ h_j with M = g_j − min R and max R − h_j (the
    bound is dropped where M = 0). A pair with one gap needs no y (y = c_p + c_q − 1 is implied);
    a pair with none cannot fly both: c_p + c_q ≤ 1.
(d) pads         (shape ``cumulative``, more than C = 1 pad; families/pads.py): for each pair of holds
    a, b at one resource that can meet (:meth:`Pads.meetings`), binaries β_ab (a ends before b
    starts) and α_ab (b ends before a starts), β + α ≤ 1, each forcing its order with a tight big-M
    relaxed where either flight is cancelled; and for every set S of C + 1 holds that can all meet
    pairwise, Σ_{pairs of S} (β + α) ≥ 1: some two of them are apart. Exact, with no tie rule: if
    no C + 1 holds overlap pairwise, no instant holds C + 1 (intervals on a line, Helly), and a
    schedule within capacity sets β, α from its own order. The sets are enumerated (networkx
    cliques of the meeting graph); a problem needing more than ``MAX_PAD_SETS`` refuses in one line.
Objective (Eqs. 20-22) ``weighted``: W = ω6 Σ d_f / G − ω7 Σ c_f; ``lexicographic``:
    −Σ c_f + Σ d_f / (Σ U_f + 1) (model.py).

The returned delays are *polished*: for the MILP's choices (c and one gap per operated pair), the
remaining constraints are difference constraints dep_j − dep_i ≥ w, whose least solution (it
minimises Σ d) is a longest path from d = 0 (Bellman-Ford), computed exactly in floating point. This
removes the big-M slack that integrality tolerances allow (y = 1 − 10⁻⁶ times M = 500 s is a
0.5 ms conflict) and is never worse than the MILP's own delays.

Profile options: ``mip_rel_gap`` (default 0.0); every other key goes to HiGHS as written, after HiGHS
has accepted it (uamopt.solvers.options; e.g. ``mip_feasibility_tolerance``). ``threads`` → HiGHS
threads, ``seed`` → ``random_seed``. ``time_limit_s`` covers the whole solve: warm start, model
building (skipped, with the warm start returned as ``time_limit``, when its estimated time exceeds
what is left) and HiGHS, which gets the rest.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import pyomo.environ as pyo
from pyomo.contrib.solver.common.factory import SolverFactory
from pyomo.contrib.solver.common.results import SolutionStatus, TerminationCondition

from uamopt.errors import UamoptError
from uamopt.interrupts import quiet_on_interrupt, stopping
from uamopt.schedule.flights import TIME_TOL_S
from uamopt.schedule.model import Schedule, SchedulingProblem, Termination, closes, make_schedule
from uamopt.solvers.highs import interrupt_at, start_solution
from uamopt.solvers.watchdog import report_bound, report_incumbent, watched

if TYPE_CHECKING:
    from uamopt.solvers import SolverProfile

quiet_on_interrupt("pyomo.core")  # Ctrl-C while a model is built: no "ERROR: Constructing component" line


class _OurInterrupt(logging.Filter):
    """Pyomo warns "Received unhandled status=<HighsModelStatus.kInterrupt: 17> from solver HiGHS"
    whenever HiGHS stops by interrupt, and that is always ours: the deadline callback
    (solvers/highs.py, read as the time limit) or Ctrl-C (read as the interrupt)."""

    def filter(self, record: logging.LogRecord) -> bool:
        return "kInterrupt" not in record.getMessage()


_PYOMO_HIGHS_LOG = logging.getLogger("pyomo.contrib.solver.solvers.highs")
if not any(isinstance(f, _OurInterrupt) for f in _PYOMO_HIGHS_LOG.filters):
    _PYOMO_HIGHS_LOG.addFilter(_OurInterrupt())

SOLVER_NAME = "highs"  # Pyomo 6.10.x name of the HiGHS interface (newer upstream: "highs_persistent")


def admissible_gaps(problem: SchedulingProblem) -> list[tuple[int, int, list[tuple[float, float]], float, float]]:
    """Per conflicting pair: (p, q, closed gaps [(g, h), ...] of admissible δ, min R, max R), s
    (the admissible-gap view of ``problem.pairs``, uamopt.schedule.core)."""
    v = problem.pairs
    return [(int(v.p[k]), int(v.q[k]), v.gaps_of(k), float(v.reach_lo[k]), float(v.reach_hi[k])) for k in range(len(v))]


def define_variables(m: pyo.ConcreteModel, problem: SchedulingProblem) -> None:
    """c_f binary, 0 ≤ d_f and d_f ≤ U_f c_f (U_f: the bounds families, encoded as the variable bound)."""
    upper = problem.delay_upper_s
    m.flights = pyo.RangeSet(0, problem.n_flights - 1)
    m.operate = pyo.Var(m.flights, within=pyo.Binary)
    m.delay = pyo.Var(m.flights, bounds=lambda _, f: (0.0, float(upper[f])))
    m.delay_if_operated = pyo.Constraint(m.flights, rule=lambda m, f: m.delay[f] <= float(upper[f]) * m.operate[f])


def define_bounds(m: pyo.ConcreteModel, problem: SchedulingProblem, family) -> None:
    """Shape ``bounds`` (Eqs. 26, 29): already the variables' upper bound U_f, the least over every
    bounds family (``problem.delay_upper_s``; define_variables)."""


def define_must_operate(m: pyo.ConcreteModel, problem: SchedulingProblem, family) -> None:
    """Shape ``must_operate``: c_f fixed to 1."""
    for f in np.flatnonzero(family.mask).tolist():
        m.operate[f].fix(1)


def define_precedence(m: pyo.ConcreteModel, problem: SchedulingProblem, family) -> None:
    """(a) c_f ≤ Σ_{g ∈ group} c_g: a cancelled outbound cancels its return (groups of one in the paper)."""
    rows = family.groups()
    block = pyo.Constraint(range(len(rows)),
                           rule=lambda m, r: m.operate[rows[r][0]] <= sum(m.operate[int(g)] for g in rows[r][1]))
    m.add_component(family.name if not hasattr(m, family.name) else f"{family.name}_{len(m.component_map())}", block)


def define_turnaround(m: pyo.ConcreteModel, problem: SchedulingProblem, family=None) -> None:
    """(b) Eq. 27 for every ordered pair of one aircraft's flights (``problem.turnaround``), tight big-M."""
    t, upper = problem.turnaround, problem.delay_upper_s
    rows = {}
    for e, f, need in zip(t.e.tolist(), t.f.tolist(), t.need_s.tolist(), strict=True):  # d_f − d_e must reach need
        if need + upper[e] > 0:
            rows[e, f] = (need, max(need + upper[e], 0.0), max(need, 0.0))
    m.turnaround = pyo.Constraint(list(rows), rule=lambda m, e, f: m.delay[f] - m.delay[e] >= rows[e, f][0]
                                  - rows[e, f][1] * (1 - m.operate[f]) - rows[e, f][2] * (1 - m.operate[e]))


def define_conflicts(m: pyo.ConcreteModel, problem: SchedulingProblem, family=None) -> None:
    """(c) the exact core: one binary per admissible gap of each conflicting pair (Eq. 24), on the
    merged view of every ``pairs`` family (``problem.pairs``)."""
    dep = problem.planned_departure_s
    m.gaps_of = admissible_gaps(problem)
    never: list[int] = []
    single: list[int] = []
    multi: list[int] = []
    for k, (_, _, gaps, _, _) in enumerate(m.gaps_of):
        (never if not gaps else single if len(gaps) == 1 else multi).append(k)
    m.not_both = pyo.Constraint(never, rule=lambda m, k: m.operate[m.gaps_of[k][0]] + m.operate[m.gaps_of[k][1]] <= 1)
    m.gap_index = pyo.Set(initialize=[(k, j) for k in multi for j in range(len(m.gaps_of[k][2]))], dimen=2)
    m.in_gap = pyo.Var(m.gap_index, within=pyo.Binary)
    m.pick_gap = pyo.Constraint(multi, rule=lambda m, k: sum(m.in_gap[k, j] for j in range(len(m.gaps_of[k][2])))
                                >= m.operate[m.gaps_of[k][0]] + m.operate[m.gaps_of[k][1]] - 1)
    both = [(k, 0) for k in single] + list(m.gap_index)

    def delta(m, k):
        p, q = m.gaps_of[k][:2]
        return m.delay[q] - m.delay[p] + float(dep[q] - dep[p])

    def slack(m, k, j):  # 1 − y_j, or 2 − c_p − c_q for a single gap
        p, q, gaps = m.gaps_of[k][:3]
        return 2 - m.operate[p] - m.operate[q] if len(gaps) == 1 else 1 - m.in_gap[k, j]

    def above(m, k, j):
        low, r_lo = m.gaps_of[k][2][j][0], m.gaps_of[k][3]
        return pyo.Constraint.Skip if low <= r_lo else delta(m, k) >= low - (low - r_lo) * slack(m, k, j)

    def below(m, k, j):
        high, r_hi = m.gaps_of[k][2][j][1], m.gaps_of[k][4]
        return pyo.Constraint.Skip if high >= r_hi else delta(m, k) <= high + (r_hi - high) * slack(m, k, j)

    m.gap_above = pyo.Constraint(both, rule=above)
    m.gap_below = pyo.Constraint(both, rule=below)


MAX_PAD_SETS = 200_000  # (C + 1)-sets of holds that can meet: beyond this the pads rows refuse (use cpsat)


def define_cumulative(m: pyo.ConcreteModel, problem: SchedulingProblem, family) -> None:
    """(d) the pads of more than one (``family.residual()``); one-pad resources are rows of
    ``problem.pairs`` (define_conflicts)."""
    import itertools

    import networkx as nx

    res = family.residual()
    dep, upper = problem.planned_departure_s, problem.delay_upper_s
    a, b = res.meetings(np.arange(len(res.flight)), dep, upper)
    fa, fb = res.flight[a], res.flight[b]
    oa, la, ob, lb = res.offset_s[a], res.duration_s[a], res.offset_s[b], res.duration_s[b]
    # start_b − start_a = dep_fb − dep_fa + o_b − o_a, over d ∈ [0, U]: its least and largest values
    shift = dep[fb] - dep[fa] + ob - oa
    big_before = np.maximum(0.0, la - (shift - upper[fa]))  # a before b: start_b − start_a ≥ l_a
    big_after = np.maximum(0.0, lb + (shift + upper[fb]))  # b before a: start_a − start_b ≥ l_b
    pairs = list(range(len(a)))
    rows = [(int(fa[k]), int(fb[k]), float(oa[k]), float(la[k]), float(ob[k]), float(lb[k]),
             float(big_before[k]), float(big_after[k])) for k in pairs]
    sets = []
    for r, cap in enumerate(res.capacity.tolist()):
        graph = nx.Graph()
        graph.add_edges_from((int(a[k]), int(b[k]), {"k": k}) for k in pairs if res.resource[a[k]] == r)
        for clique in nx.enumerate_all_cliques(graph):
            if len(clique) > cap + 1:
                break
            if len(clique) == cap + 1:
                sets.append([graph.edges[u, v]["k"] for u, v in itertools.combinations(clique, 2)])
                if len(sets) > MAX_PAD_SETS:
                    raise UamoptError(f"the pads need more than {MAX_PAD_SETS:,} rows of {cap + 1} holds that can meet "
                                      f"at {res.resources[r]}", "solver highs (family pads)",
                                      "use cpsat (AddCumulative) for this many pads, or fewer flights")
    m.pad_rows = rows
    m.pad_pairs = pyo.RangeSet(0, len(rows) - 1) if rows else pyo.Set(initialize=[])
    m.pad_before = pyo.Var(m.pad_pairs, within=pyo.Binary)
    m.pad_after = pyo.Var(m.pad_pairs, within=pyo.Binary)
    m.pad_one_order = pyo.Constraint(m.pad_pairs, rule=lambda m, k: m.pad_before[k] + m.pad_after[k] <= 1)

    def gap(m, k):  # start_b − start_a
        f, g, o_a, _, o_b = m.pad_rows[k][:5]
        return m.delay[g] - m.delay[f] + float(dep[g] - dep[f] + o_b - o_a)

    def off(m, k):  # 2 − c_fa − c_fb
        return 2 - m.operate[m.pad_rows[k][0]] - m.operate[m.pad_rows[k][1]]

    m.pad_order_before = pyo.Constraint(m.pad_pairs, rule=lambda m, k: gap(m, k) >= m.pad_rows[k][3]
                                        - m.pad_rows[k][6] * (1 - m.pad_before[k] + off(m, k)))
    m.pad_order_after = pyo.Constraint(m.pad_pairs, rule=lambda m, k: -gap(m, k) >= m.pad_rows[k][5]
                                       - m.pad_rows[k][7] * (1 - m.pad_after[k] + off(m, k)))
    m.pad_sets = sets
    m.pad_apart = pyo.Constraint(range(len(sets)), rule=lambda m, s: sum(m.pad_before[k] + m.pad_after[k]
                                                                        for k in m.pad_sets[s]) >= 1)


def define_objective(m: pyo.ConcreteModel, problem: SchedulingProblem) -> None:
    """``problem.objective`` (Eqs. 20-22 or the lexicographic scalar), with Σ d_f = Σ c_f d_f by
    d_f ≤ U_f c_f; earliness/tardiness: early_f ≥ a_f c_f − d_f and late_f ≥ d_f − a_f, both ≥ 0
    (exact at the optimum: each is minimised with a positive cost)."""
    o = problem.objective
    delay, flown = sum(m.delay[f] for f in m.flights), sum(m.operate[f] for f in m.flights)
    expr = o.per_delay * delay - o.per_flight * flown
    if o.operate_cost_s is not None:  # per-flight operating costs in seconds of delay (a speed change)
        expr = expr + o.per_delay * sum(float(o.operate_cost_s[f]) * m.operate[f] for f in m.flights)
    if o.per_flight_terms:
        a, e_cost, l_cost = o.terms
        m.early = pyo.Var(m.flights, bounds=(0.0, None))
        m.late = pyo.Var(m.flights, bounds=(0.0, None))
        m.early_row = pyo.Constraint(m.flights, rule=lambda m, f: m.early[f] >= float(a[f]) * m.operate[f] - m.delay[f])
        m.late_row = pyo.Constraint(m.flights, rule=lambda m, f: m.late[f] >= m.delay[f] - float(a[f]))
        expr = expr + sum(float(e_cost[f]) * m.early[f] + float(l_cost[f]) * m.late[f] for f in m.flights)
    m.objective = pyo.Objective(expr=expr)


#: one encoder per family shape (uamopt.schedule.families); ``pairs`` and ``turnaround`` encode the
#: merged view of every family of their shape once
ENCODERS = {"bounds": define_bounds, "must_operate": define_must_operate, "precedence": define_precedence,
            "turnaround": define_turnaround, "pairs": define_conflicts, "cumulative": define_cumulative}
SHAPES = frozenset(ENCODERS)
OBJECTIVES = frozenset({"weighted", "lexicographic", "earliness_tardiness"})


def build_model(problem: SchedulingProblem, extra=None) -> pyo.ConcreteModel:
    """The Pyomo model of Eqs. 20-31 (see the module docstring), ready for any Pyomo solver: the
    variables, one encoder call per family shape, the objective, then ``extra(m, problem)`` if given
    (PyPSA's ``extra_functionality``: add rows to ``m`` for a one-off experiment; docs/variants.md)."""
    m = pyo.ConcreteModel(name="uam_schedule")
    define_variables(m, problem)
    done = set()
    for family in problem.families:
        if family.shape == "cumulative" and not len(family.residual().flight):  # one pad: rows of problem.pairs
            continue
        if family.shape in ("pairs", "turnaround"):  # merged views: encoded once
            if family.shape in done:
                continue
            done.add(family.shape)
        ENCODERS[family.shape](m, problem, family)
    if "pairs" not in done:
        define_conflicts(m, problem)  # m.gaps_of is read by the polishing step
    define_objective(m, problem)
    if extra is not None:
        extra(m, problem)
    return m


def _model_status(solver) -> str:
    """HiGHS's own model status, which Pyomo reads as ``unknown`` when it has no name for it (an
    interrupt, a solve error): the words the error line needs to be acted on."""
    try:
        highs = solver._solver_model
        return f"HiGHS model status: {highs.modelStatusToString(highs.getModelStatus())}"
    except Exception:  # noqa: BLE001 - an interface without the highspy object: say nothing more
        return "HiGHS model status unavailable"


def least_delays(problem: SchedulingProblem, operated: np.ndarray, chosen: dict[int, tuple[float, float]],
                 orders: Sequence[tuple[int, int, float]] = ()) -> np.ndarray | None:
    """The least delays (minimal Σ d) of the operated flights for fixed gap choices, or None if none fit.

    ``chosen`` maps a pair's row in ``admissible_gaps`` to its gap [g, h]; ``orders`` adds edges
    (i, j, w): dep_j ≥ dep_i + w (the pads' chosen orders, :func:`pad_orders`). Bellman-Ford longest
    path on dep_j ≥ dep_i + w from d = 0; at most n rounds, vectorised over the edges.
    """
    dep, upper, t = problem.planned_departure_s, problem.delay_upper_s, problem.turnaround
    both = operated[t.e] & operated[t.f]
    # (i, j, w): dep_j ≥ dep_i + w
    edges = list(zip(t.e[both].tolist(), t.f[both].tolist(), t.gap_s(problem)[both].tolist(), strict=True))
    edges += list(orders)
    for k, (low, high) in chosen.items():
        p, q = int(problem.pairs.p[k]), int(problem.pairs.q[k])
        edges += [(p, q, low), (q, p, -high)]  # g ≤ dep_q − dep_p ≤ h
    table = np.array(edges, dtype=float).reshape(-1, 3)
    src, dst, weight = table[:, 0].astype(np.int64), table[:, 1].astype(np.int64), table[:, 2]
    departure = dep.astype(float).copy()
    for _ in range(problem.n_flights + 1):
        pull = np.full_like(departure, -np.inf)
        np.maximum.at(pull, dst, departure[src] + weight)
        nxt = np.maximum(departure, pull)
        if np.array_equal(nxt, departure):
            delay = np.where(operated, departure - dep, 0.0)
            return delay if np.all(delay <= upper + TIME_TOL_S / 10) else None
        departure = nxt
    return None  # a positive cycle: the choices admit no delays


def least_cost_delays(problem: SchedulingProblem, operated: np.ndarray, chosen: dict[int, tuple[float, float]],
                      orders: Sequence[tuple[int, int, float]] = ()) -> np.ndarray | None:
    """The earliness/tardiness objective's optimal delays for fixed gap choices: the LP
    min Σ e_f E_f + l_f L_f over the same difference constraints as :func:`least_delays`
    (scipy's HiGHS, exact to its tolerances), or None if it fails."""
    from scipy.optimize import linprog
    from scipy.sparse import coo_matrix

    o, t, n = problem.objective, problem.turnaround, problem.n_flights
    flown = np.flatnonzero(operated)
    if not len(flown):
        return np.zeros(n)
    col = np.full(n, -1)
    col[flown] = np.arange(len(flown))
    rows = []  # (i, j, b): d_i − d_j ≤ b
    both = operated[t.e] & operated[t.f]
    rows += list(zip(t.e[both].tolist(), t.f[both].tolist(), (-t.need_s[both]).tolist(), strict=True))
    dep = problem.planned_departure_s
    for k, (low, high) in chosen.items():
        p, q = int(problem.pairs.p[k]), int(problem.pairs.q[k])
        shift = dep[q] - dep[p]
        rows += [(p, q, shift - low), (q, p, high - shift)]
    rows += [(i, j, float(dep[j] - dep[i] - w)) for i, j, w in orders]  # dep_j ≥ dep_i + w: d_i − d_j ≤ D_j − D_i − w
    target, early, late = o.terms
    m = len(flown)  # variables: d (m), early (m), late (m)
    r_i, r_j, data, b = [], [], [], []
    for r, (i, j, bound) in enumerate(rows):
        r_i += [r, r]
        r_j += [col[i], col[j]]
        data += [1.0, -1.0]
        b.append(bound)
    for k, f in enumerate(flown.tolist()):  # a − d − E ≤ 0 and d − a − L ≤ 0
        base = len(rows) + 2 * k
        r_i += [base, base, base + 1, base + 1]
        r_j += [k, m + k, k, 2 * m + k]
        data += [-1.0, -1.0, 1.0, -1.0]
        b += [-float(target[f]), float(target[f])]
    a_ub = coo_matrix((data, (r_i, r_j)), shape=(len(b), 3 * m)).tocsr()
    cost = np.concatenate([np.full(m, o.per_delay), early[flown], late[flown]])
    upper = problem.delay_upper_s[flown]
    bounds = [(0.0, float(u)) for u in upper] + [(0.0, None)] * (2 * m)
    res = linprog(cost, A_ub=a_ub, b_ub=np.array(b), bounds=bounds, method="highs")
    if res.status != 0:
        return None
    delay = np.zeros(n)
    delay[flown] = np.clip(res.x[:m], 0.0, upper)
    return delay


def chosen_gaps(m: pyo.ConcreteModel, operated: np.ndarray) -> dict[int, tuple[float, float]]:
    """The gap each operated pair sits in, read from the MILP's binaries."""
    chosen = {}
    for k, (p, q, gaps, _, _) in enumerate(m.gaps_of):
        if operated[p] and operated[q] and gaps:
            j = 0 if len(gaps) == 1 else max(range(len(gaps)), key=lambda j: pyo.value(m.in_gap[k, j]))
            chosen[k] = gaps[j]
    return chosen


def pad_orders(m: pyo.ConcreteModel, operated: np.ndarray) -> list[tuple[int, int, float]]:
    """The pads' orders the MILP chose between operated flights, as edges dep_j ≥ dep_i + w."""
    out = []
    for k, (f, g, o_a, l_a, o_b, l_b, _, _) in enumerate(getattr(m, "pad_rows", ())):
        if not (operated[f] and operated[g]):
            continue
        if pyo.value(m.pad_before[k]) > 0.5:  # a ends before b starts: dep_g + o_b ≥ dep_f + o_a + l_a
            out.append((f, g, o_a + l_a - o_b))
        elif pyo.value(m.pad_after[k]) > 0.5:
            out.append((g, f, o_b + l_b - o_a))
    return out


def mip_start(m: pyo.ConcreteModel, problem: SchedulingProblem, operated: np.ndarray, delay_s: np.ndarray) -> dict:
    """Values of every variable of ``build_model`` for a feasible schedule (a MIP start), keyed by
    ``id(var)``: c, d, and y = 1 on the admissible gap that holds δ for each operated pair (else 0)."""
    values = {}
    for f in range(problem.n_flights):
        values[id(m.operate[f])] = float(operated[f])
        values[id(m.delay[f])] = float(delay_s[f]) if operated[f] else 0.0
    dep = problem.planned_departure_s + np.where(operated, delay_s, 0.0)
    for k, (p, q, gaps, _, _) in enumerate(m.gaps_of):
        if len(gaps) < 2:
            continue
        pick = -1
        if operated[p] and operated[q]:
            delta = dep[q] - dep[p]
            pick = min(range(len(gaps)), key=lambda j: max(gaps[j][0] - delta, delta - gaps[j][1], 0.0))
        for j in range(len(gaps)):
            values[id(m.in_gap[k, j])] = float(j == pick)
    for k, (f, g, o_a, l_a, o_b, l_b, _, _) in enumerate(getattr(m, "pad_rows", ())):
        apart_before = not (operated[f] and operated[g]) or dep[g] + o_b >= dep[f] + o_a + l_a - TIME_TOL_S
        apart_after = not apart_before and dep[f] + o_a >= dep[g] + o_b + l_b - TIME_TOL_S
        values[id(m.pad_before[k])], values[id(m.pad_after[k])] = float(apart_before), float(apart_after)
    return values


def solve(problem: SchedulingProblem, profile: SolverProfile, extra=None) -> Schedule:
    """Build and solve the MILP with HiGHS; a linopy-style status, never an exception on a limit.

    Termination: ``optimal`` (HiGHS's bound meets its objective, :func:`~uamopt.schedule.model.closes`),
    ``stopped`` (HiGHS met a ``mip_rel_gap`` above that: no proof), ``time_limit`` (limit hit; the
    incumbent with HiGHS's bound), ``infeasible`` (proved, for continuous delays). HiGHS starts from
    the best cheap heuristic schedule (:func:`~uamopt.solvers.warmstart.warm_start`, a MIP start
    through ``Highs.setSolution``) and never returns a worse one
    (:func:`~uamopt.solvers.warmstart.no_worse`). The model is built on
    :func:`~uamopt.solvers.warmstart.reduced` (dominated delays cut off; the optima are unchanged).
    """
    from uamopt.solvers.warmstart import infeasible_reason, no_schedule, no_start, no_worse, reduced, warm_start

    t0 = time.perf_counter()
    options = dict(profile.options)
    options.setdefault("mip_rel_gap", 0.0)
    options.setdefault("random_seed", int(profile.seed))
    start = no_start() if extra is not None else warm_start(problem, seed=profile.seed)
    # (a heuristic schedule knows nothing of the callback's rows: no start, and no fallback to one)
    solver = SolverFactory(SOLVER_NAME)
    if solver is None or not solver.available():
        raise UamoptError("HiGHS is not available to Pyomo", f"solver {profile.name or 'highs'}", "pip install highspy")
    left = profile.time_limit_s - (time.perf_counter() - t0)
    if left <= 0 or estimated_build_s(problem) > left:  # the model could not even be built in time
        return _start_only(problem, profile, start, t0, "the MILP was not built: the time limit would not cover its build")
    m = build_model(reduced(problem), extra)  # delay bounds capped by dominance: the same optima (warmstart.py)
    build_s = time.perf_counter() - t0
    solver.set_instance(m)  # the persistent interface: load the model, then hand HiGHS the MIP start
    _own_thread_pool(solver)
    if start.found:
        _set_mip_start(solver, mip_start(m, problem, *start.decisions))
    stopped: list = []
    if getattr(solver, "_solver_model", None) is not None:  # pyomo 6.10's persistent HiGHS object
        stopped = interrupt_at(solver._solver_model, t0 + profile.time_limit_s,  # where HiGHS listens (solvers/highs.py)
                               on_bound=lambda b: report_bound(problem, b, "HiGHS's dual bound"),
                               on_solution=_incumbent_reporter(problem, m, solver))
    left = profile.time_limit_s - (time.perf_counter() - t0)
    if left <= 0.05:
        return _start_only(problem, profile, start, t0, f"the time limit ran out while building the MILP ({build_s:.1f} s)")
    with stopping(cancel(solver)):  # Ctrl-C and SIGTERM stop HiGHS at once
        result = solver.solve(m, time_limit=left, threads=int(profile.threads), solver_options=options,
                              load_solutions=False, raise_exception_on_nonoptimal_result=False)
    if _stale_solution(m, result):  # highspy 1.16: the start's values beside a better objective; solve cold
        m = build_model(reduced(problem), extra)
        left = max(0.05, profile.time_limit_s - (time.perf_counter() - t0))
        solver = SolverFactory(SOLVER_NAME)
        with stopping(cancel(solver)):
            result = solver.solve(m, time_limit=left, threads=int(profile.threads), solver_options=options,
                                  load_solutions=False, raise_exception_on_nonoptimal_result=False)
    tc, has_solution = result.termination_condition, result.solution_status in (SolutionStatus.optimal, SolutionStatus.feasible)
    extras = {"engine_termination": tc.name, "nodes": getattr(result.extra_info, "mip_node_count", None),
              "highs_objective": result.incumbent_objective, "highs_seconds": result.timing_info.highs_time,
              "build_seconds": build_s}
    bound = result.objective_bound if result.objective_bound is not None and np.isfinite(result.objective_bound) else None
    n = problem.n_flights
    if tc in (TerminationCondition.provenInfeasible, TerminationCondition.infeasibleOrUnbounded):
        extras["reason"] = infeasible_reason(problem)
        return make_schedule(problem, "highs", "infeasible", np.zeros(n, bool), np.zeros(n), proved_for="continuous",
                             solve_seconds=time.perf_counter() - t0, seed=profile.seed, extras=extras)
    termination: Termination
    if tc == TerminationCondition.convergenceCriteriaSatisfied and has_solution:
        # HiGHS stops at mip_rel_gap: optimal only when its bound meets its objective (to 1e-9), else its gap rule
        termination = "optimal" if closes(result.incumbent_objective, bound) else "stopped"
    elif tc in (TerminationCondition.maxTimeLimit, TerminationCondition.iterationLimit, TerminationCondition.interrupted
                ) or (stopped and tc == TerminationCondition.unknown):  # our deadline interrupt (solvers/highs.py)
        termination = "time_limit"
    else:
        raise UamoptError(f"HiGHS stopped with {tc.name} ({_model_status(solver)})", f"solver {profile.name or 'highs'}",
                          "see the HiGHS log (tee=True)")
    operated, delay = np.zeros(n, bool), np.zeros(n)
    if has_solution:
        result.solution_loader.load_vars()
        operated = np.array([pyo.value(m.operate[f]) > 0.5 for f in range(n)])
        chosen, orders = chosen_gaps(m, operated), pad_orders(m, operated)
        polished = (least_delays(problem, operated, chosen, orders) if not problem.objective.per_flight_terms
                    else least_cost_delays(problem, operated, chosen, orders))
        if extra is not None and polished is not None:  # rows of the callback the polishing does not know
            polished = None
        extras["polished"] = polished is not None
        raw = np.clip([pyo.value(m.delay[f]) for f in range(n)], 0.0, problem.delay_upper_s)
        delay = polished if polished is not None else np.where(operated, raw, 0.0)
    elif not start.found:
        raise no_schedule(problem, profile.name or "highs", f"HiGHS stopped ({tc.name}) with no incumbent")
    else:
        extras["incumbent"] = "none found: every flight cancelled"
    extras["warm_start"] = f"{start.source} {start.objective:.6f}"
    extras["model"] = MODEL
    return no_worse(problem, make_schedule(problem, "highs", termination, operated, delay,
                                           proved_for="continuous" if termination == "optimal" else "none", bound=bound,
                                           solve_seconds=time.perf_counter() - t0, seed=profile.seed, extras=extras), start)


#: model-building rate of build_model + set_instance (Pyomo 6.10): measured 10 µs per estimated row
#: (7.3 s for the 716,000 rows of models/benchmark_3000.toml on a loaded 2-core machine); 1.5× margin
BUILD_S_PER_ROW = 15e-6
MODEL = "continuous delays (the exact MILP of Eqs. 20-31)"


def estimated_build_s(problem: SchedulingProblem) -> float:
    """A cheap upper estimate of the seconds ``build_model`` + ``set_instance`` take: rows × rate."""
    ptr = problem.pairs.gaps[0]
    rows = 2 * problem.n_flights + len(problem.turnaround) + 3 * int(ptr[-1]) + len(problem.pairs)
    return rows * BUILD_S_PER_ROW


def _start_only(problem: SchedulingProblem, profile, start, t0: float, why: str) -> Schedule:
    """The warm start as the answer when the limit leaves HiGHS no time (status ``time_limit``, no bound)."""
    if not start.found:
        from uamopt.solvers.warmstart import no_schedule

        raise no_schedule(problem, profile.name or "highs", why)
    return make_schedule(problem, "highs", "time_limit", start.operated, start.delay_s, solve_seconds=time.perf_counter() - t0,
                         seed=profile.seed, extras={"engine_termination": "not run", "incumbent": why, "model": MODEL,
                                                    "warm_start": f"{start.source} {start.objective:.6f}"})


def cancel(solver):
    """What stops Pyomo's HiGHS ``solver`` mid-solve (uamopt.interrupts.stopping): its highspy model,
    which exists once the solve has begun (Pyomo's warning about the interrupted status: _OurInterrupt)."""
    def stop() -> None:
        solver._solver_model.cancelSolve()

    return stop


def _stale_solution(m: pyo.ConcreteModel, result) -> bool:
    """Whether the solution HiGHS hands back does not have the objective it reports."""
    if result.solution_status not in (SolutionStatus.optimal, SolutionStatus.feasible) or result.incumbent_objective is None:
        return False
    result.solution_loader.load_vars()
    return abs(pyo.value(m.objective) - result.incumbent_objective) > 1e-6 * (1.0 + abs(result.incumbent_objective))


def _own_thread_pool(solver) -> None:
    """HiGHS keeps one thread pool per process, sized by the first run: a later run asking for
    more threads stops at once with model status "Not Set" (seen after a 1-thread time-indexed
    solve in the same process, with no MIP start to reset it). Reset it before every solve."""
    highs = getattr(solver, "_solver_model", None)
    if highs is not None:
        highs.resetGlobalScheduler(True)


def _incumbent_reporter(problem, m, solver):
    """HiGHS's improving MIP solutions, passed on as schedules (watchdog.report_incumbent; the
    parent checks them) when the solve is watched or traced; None otherwise or without the
    persistent interface's column map."""
    index = getattr(solver, "_pyomo_var_to_solver_var_map", None)
    if not index or not watched(problem):
        return None
    n = problem.n_flights
    try:
        op_cols = np.array([index[id(m.operate[f])] for f in range(n)], dtype=np.int64)
        delay_cols = np.array([index[id(m.delay[f])] for f in range(n)], dtype=np.int64)
    except KeyError:
        return None
    upper = np.asarray(problem.delay_upper_s, dtype=float)

    def report(x: np.ndarray) -> None:
        if len(x) <= max(int(op_cols.max(initial=0)), int(delay_cols.max(initial=0))):
            return
        operated = x[op_cols] > 0.5
        report_incumbent(problem, operated, np.where(operated, np.clip(x[delay_cols], 0.0, upper), 0.0),
                         "HiGHS's incumbent")

    return report


def _set_mip_start(solver, values: dict) -> None:
    """``Highs.setSolution`` on the persistent Pyomo interface's HiGHS model (pyomo 6.10: the column
    of a variable is ``_pyomo_var_to_solver_var_map[id(var)]``). Without that map (another Pyomo
    version) HiGHS starts cold; :func:`no_worse` still guards the result."""

    index = getattr(solver, "_pyomo_var_to_solver_var_map", None)
    highs = getattr(solver, "_solver_model", None)
    if not index or highs is None:
        return
    x = np.zeros(highs.getNumCol())
    for var_id, value in values.items():
        col = index.get(var_id)
        if col is not None:
            x[col] = value
    highs.setSolution(start_solution(x))
