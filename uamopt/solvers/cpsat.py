"""Solver ``cpsat``: the scheduling model of Sec. 4.3 (Eqs. 20-31) in OR-Tools CP-SAT.

CP-SAT works on integers, so time is counted in units of u = ``time_unit_s`` (default 0.01 s):
the delay of flight f is d_f = u·k_f with k_f ∈ {0, …, ⌊U_f/u⌋} (Eqs. 26, 29). Planned
departures stay real; every constraint is written on k with its real constant rounded so that
the integer set is *inside* the real one:

- cancelled ⇒ k_f = 0; precedence c_f ⇒ c_{requires[f]} (an implication);
- turnaround (Eqs. 27-28), e before f of one aircraft, enforced only if c_e ∧ c_f:
  k_f − k_e ≥ ⌈(D_e + T_e + ΔT_e − D_f)/u⌉;
- conflicts (Eq. 24), enforced only if c_p ∧ c_q (an enforcement list: the b ⇔ both of the
  paper's linearisation without an extra variable): k_q − k_p avoids every integer z of the
  open interval ((lo − ΔD)/u, (hi − ΔD)/u), ΔD = D_q − D_p, i.e. z ∉ [⌊x_lo⌋ + 1, ⌈x_hi⌉ − 1];
  with no admissible z left, ¬c_p ∨ ¬c_q.

Every rounding is outward, so any CP-SAT solution is feasible in the real model (up to
``ROUND_S`` = 10⁻⁹ s of float round-off, far below the model's ``TIME_TOL_S``) and its objective is
≥ the real optimum. When every time of the data is a multiple of u (planned departures, flight and
cell-crossing times, gaps, delay bounds), the rounding is exact and, the constraints being
difference constraints (totally unimodular for fixed choices), CP-SAT's optimum *is* the real one.
Otherwise a feasible window narrower than u may hold no integer point, so the discretised optimum
can be worse; the paper-case test bounds the difference empirically.

Objective, made integral: ``weighted`` ω6·u·Σk/G − ω7·Σc times L, the least common denominator of
ω6·u/G and ω7 read as decimals (``Fraction(repr(w))``); if L would overflow int64 arithmetic, the
two coefficients are scaled to 10⁹ and rounded (``extras["objective_scale"]`` says which).
``lexicographic``: Σk − (Σ⌊U/u⌋ + 1)·Σc, the same order as model.py's scalar. The returned
objective is ``make_schedule``'s evaluation of d = u·k on the real model; the returned bound is
CP-SAT's bound mapped back, a bound of the *discretised* model (``extras["bound_of"]``).

Profile options: ``time_unit_s`` (default 0.01); ``threads`` → ``num_workers``, ``seed`` →
``random_seed``, ``time_limit_s`` → ``max_time_in_seconds``; other options are CP-SAT parameters
(a list extends a repeated one). Defaults: ``linearization_level = 2`` with one thread,
``subsolvers = ["max_lp", "default_lp"]`` with more (see ``solve``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from uamopt.errors import UamoptError
from uamopt.interrupts import stopping
from uamopt.schedule.flights import TIME_TOL_S
from uamopt.schedule.model import ProvedFor, Schedule, SchedulingProblem, Termination, closes, evaluate, make_schedule
from uamopt.solvers.watchdog import report_incumbent, watched

if TYPE_CHECKING:
    from ortools.sat.python import cp_model

    from uamopt.solvers import SolverProfile

ROUND_S = 1e-9  # float round-off accepted when rounding a real time to units, s
INT_LIMIT = 2**62  # keep |objective| below this (CP-SAT uses int64)


def integer_objective(problem: SchedulingProblem, unit_s: float, delay_max: np.ndarray) -> tuple[int, int, float, str]:
    """Integer coefficients (per unit of delay, per operated flight) of ``problem.objective``, the
    divisor back to W, and how (the linear kinds; earliness/tardiness: :func:`integer_terms`)."""
    objective = problem.objective
    total = int(delay_max.sum()) + int(operate_units(problem, unit_s).sum()) + 1
    if objective.exact is None:  # lexicographic: one flight outweighs every delay unit together
        return 1, total, 1.0, "lexicographic"
    if objective.per_flight_terms:
        _, _, _, per_flight, divisor, how = integer_terms(problem, unit_s, delay_max)
        return 0, per_flight, divisor, how
    per_unit, per_flight = objective.scaled_delay(unit_s), objective.exact[1]
    scale = math.lcm(per_unit.denominator, per_flight.denominator)
    a, b = int(per_unit * scale), int(per_flight * scale)
    if (abs(a) * total + abs(b) * len(delay_max)) < INT_LIMIT:
        return a, b, float(scale), "exact"
    top = max(float(per_unit), float(per_flight))
    return round(float(per_unit) / top * 1e9), round(float(per_flight) / top * 1e9), 1e9 / top, "approximate"


def operate_units(problem: SchedulingProblem, unit_s: float) -> np.ndarray:
    """(n,) the objective's operating cost of each flight in delay units (0 without one), rounded."""
    cost = problem.objective.operate_cost_s
    return np.zeros(problem.n_flights, dtype=np.int64) if cost is None else np.rint(cost / unit_s).astype(np.int64)


def integer_terms(problem: SchedulingProblem, unit_s: float, delay_max: np.ndarray):
    """The earliness/tardiness objective on the u-lattice: (target in units (n,), early and late
    cost per unit (n,) int, per-flight reward int, divisor back to W, how). ``how`` is ``exact`` when
    every target is a multiple of u and the costs are decimals whose scaled sum fits int64."""
    from fractions import Fraction

    o = problem.objective
    target_s, early_per_s, late_per_s = o.terms
    assert o.exact is not None, "Objective.earliness_tardiness sets the exact weights"
    target = target_s / unit_s
    target_k = np.rint(target).astype(np.int64)
    fr_u = Fraction(repr(float(unit_s)))
    early = [Fraction(repr(float(c))) * fr_u for c in early_per_s]
    late = [Fraction(repr(float(c))) * fr_u for c in late_per_s]
    reward = o.exact[1]
    scale = math.lcm(*(x.denominator for x in early + late + [reward]))
    e_int = np.array([int(x * scale) for x in early], dtype=object)
    l_int = np.array([int(x * scale) for x in late], dtype=object)
    worst = (sum(int(a) * int(m) + int(b) * int(m) for a, b, m in zip(e_int, l_int, delay_max, strict=True))
             + int(reward * scale) * len(delay_max))
    how = "exact" if np.all(np.abs(target - target_k) <= 1e-9) else "approximate"
    if worst >= INT_LIMIT:
        raise UamoptError("the earliness/tardiness costs overflow CP-SAT's 64-bit objective", "solver cpsat",
                          "use a coarser time_unit_s or round the costs")
    return target_k, e_int.astype(np.int64), l_int.astype(np.int64), int(reward * scale), float(scale), how


@dataclass
class _Vars:
    """What the encoders share: the model, c_f, k_f (delay in units), the unit, the rounding."""

    model: cp_model.CpModel
    operate: list
    delay: list
    delay_max: np.ndarray
    unit_s: float
    rounding: str

    @property
    def eta(self) -> float:
        return ROUND_S / self.unit_s


def encode_bounds(v: _Vars, problem: SchedulingProblem, family) -> None:
    """Shape ``bounds``: the domain 0 ≤ k_f ≤ ⌊U_f/u⌋ of the delay variables (U: every bounds family)."""


def encode_must_operate(v: _Vars, problem: SchedulingProblem, family) -> None:
    for f in np.flatnonzero(family.mask).tolist():
        v.model.add(v.operate[f] == 1)


def encode_precedence(v: _Vars, problem: SchedulingProblem, family) -> None:
    for f, group in family.groups():  # c_f ⇒ some c_g of its group (one in the paper: the outbound)
        v.model.add_bool_or([v.operate[f].Not()] + [v.operate[int(g)] for g in group])


def encode_turnaround(v: _Vars, problem: SchedulingProblem, family=None) -> None:
    """k_f − k_e ≥ ⌈need/u⌉ if c_e ∧ c_f, for every row of ``problem.turnaround``."""
    t, eta, u = problem.turnaround, v.eta, v.unit_s
    for e, f, need in zip(t.e.tolist(), t.f.tolist(), t.need_s.tolist(), strict=True):
        need = (math.ceil(need / u - eta) if v.rounding == "outer"
                else math.floor((need - TIME_TOL_S) / u - 1 - eta) + 1)
        if need > -v.delay_max[e]:
            v.model.add(v.delay[f] - v.delay[e] >= need).only_enforce_if([v.operate[e], v.operate[f]])


def encode_pairs(v: _Vars, problem: SchedulingProblem, family=None) -> None:
    """k_q − k_p in the admissible integer set if c_p ∧ c_q, for every pair of ``problem.pairs``."""
    from ortools.util.python.sorted_interval_list import Domain

    view, eta, u, operate, delay = problem.pairs, v.eta, v.unit_s, v.operate, v.delay
    for k, (p, q) in enumerate(zip(view.p.tolist(), view.q.tolist(), strict=True)):
        shift, rows = float(view.shift[k]), slice(view.ptr[k], view.ptr[k + 1])
        reach = Domain(-int(v.delay_max[p]), int(v.delay_max[q]))
        if v.rounding == "outer":
            forbidden = [[math.floor((lo - shift) / u + eta) + 1, math.ceil((hi - shift) / u - eta) - 1]
                         for lo, hi in zip(view.lo[rows].tolist(), view.hi[rows].tolist(), strict=True)]
        else:
            forbidden = [[math.ceil((lo + TIME_TOL_S - shift) / u + 1 + eta),
                          math.floor((hi - TIME_TOL_S - shift) / u - 1 - eta)]
                         for lo, hi in zip(view.lo[rows].tolist(), view.hi[rows].tolist(), strict=True)]
        forbidden = [iv for iv in forbidden if iv[0] <= iv[1]]
        allowed = reach.intersection_with(Domain.from_intervals(forbidden).complement()) if forbidden else reach
        if allowed.is_empty():
            v.model.add_bool_or([operate[p].Not(), operate[q].Not()])
        elif allowed.size() < reach.size():
            v.model.add_linear_expression_in_domain(delay[q] - delay[p], allowed).only_enforce_if([operate[p], operate[q]])


def encode_cumulative(v: _Vars, problem: SchedulingProblem, family) -> None:
    """AddCumulative per resource over the events of ``family.residual()`` (one-capacity
    resources are pairs, encoded by :func:`encode_pairs`): optional fixed-size intervals present
    iff their flight operates. ``outer`` covers each continuous hold by whole units
    [⌊s/u⌋, ⌈e/u⌉) (feasible on the lattice ⇒ feasible); ``inner`` keeps only the units every
    delay of the cell [k u, (k+1) u) covers, [⌈s/u⌉ + 1, ⌊e/u⌋) (a relaxation)."""
    res, eta, u = family.residual(), v.eta, v.unit_s
    start_s = problem.planned_departure_s[res.flight] + res.offset_s
    for r in np.unique(res.resource).tolist():
        intervals = []
        for k in np.flatnonzero(res.resource == r).tolist():
            f, a, b = int(res.flight[k]), start_s[k] / u, (start_s[k] + res.duration_s[k]) / u
            lo, hi = ((math.floor(a + eta), math.ceil(b - eta)) if v.rounding == "outer"
                      else (math.ceil(a - eta) + 1, math.floor(b + eta)))
            if hi > lo:
                intervals.append(v.model.new_optional_fixed_size_interval_var(
                    v.delay[f] + lo, hi - lo, v.operate[f], f"pad{r}_{k}"))
        v.model.add_cumulative(intervals, [1] * len(intervals), int(res.capacity[r]))


#: one encoder per family shape (uamopt.schedule.families); pairs and turnaround: the merged views, once
ENCODERS = {"bounds": encode_bounds, "must_operate": encode_must_operate, "precedence": encode_precedence,
            "turnaround": encode_turnaround, "pairs": encode_pairs, "cumulative": encode_cumulative}
SHAPES = frozenset(ENCODERS)
OBJECTIVES = frozenset({"weighted", "lexicographic", "earliness_tardiness"})


@dataclass(frozen=True)
class CpsatModel:
    """A built CP-SAT model of a scheduling problem (:func:`build_cpsat`).

    ``operate[f]`` and ``delay[f]`` (in units of ``unit_s``) are the decision variables; the
    objective is ``per_unit · Σ delay − per_flight · Σ operate`` (plus the per-flight terms), an
    integer scaling of the problem's objective: divide by ``divisor`` (``how`` names the scaling,
    :func:`objective_bound` reads a bound back)."""

    model: cp_model.CpModel
    operate: list
    delay: list
    per_unit: int
    per_flight: int
    divisor: float
    how: str


def build_cpsat(problem: SchedulingProblem, unit_s: float = 0.01, rounding: str = "outer", extra=None) -> CpsatModel:
    """The CP-SAT model of ``problem`` on the delay lattice of ``unit_s`` (:class:`CpsatModel`).

    ``rounding = "inner"`` reads k as the *cell* [k u, (k+1) u) of a continuous delay and forbids
    only what every point of a cell pair breaks (as timeindexed.py's ``relaxed`` model): a
    relaxation, whose bound holds for continuous delays. ``extra(model, problem, operate, delay)``
    runs after the families, before the objective (docs/variants.md)."""
    from ortools.sat.python import cp_model  # imported on use: see ``solve``

    eta = ROUND_S / unit_s
    delay_max = np.floor(problem.delay_upper_s / unit_s + eta).astype(np.int64)
    model = cp_model.CpModel()
    n = problem.n_flights
    operate = [model.new_bool_var(f"c{f}") for f in range(n)]
    delay = [model.new_int_var(0, int(delay_max[f]), f"k{f}") for f in range(n)]
    for f in range(n):
        model.add(delay[f] == 0).only_enforce_if(operate[f].Not())
    v = _Vars(model, operate, delay, delay_max, unit_s, rounding)
    done = set()
    for family in problem.families:
        if family.shape in ("pairs", "turnaround"):
            if family.shape in done:
                continue
            done.add(family.shape)
        ENCODERS[family.shape](v, problem, family)
    if extra is not None:
        extra(model, problem, operate, delay)
    per_unit, per_flight, divisor, how = integer_objective(problem, unit_s, delay_max)
    if problem.objective.per_flight_terms:
        target_k, e_int, l_int, per_flight, divisor, how = integer_terms(problem, unit_s, delay_max)
        terms = []
        for f in range(n):  # early_f ≥ a_f − k_f and late_f ≥ k_f − a_f when operated; both ≥ 0
            a, top = int(target_k[f]), int(delay_max[f])
            a_early = a - 1 if rounding == "inner" else a  # a cell [k u, (k+1) u) is charged its least earliness
            early = model.new_int_var(0, max(0, a), f"e{f}")
            late = model.new_int_var(0, max(0, top - a), f"l{f}")
            model.add(early >= a_early - delay[f]).only_enforce_if(operate[f])
            model.add(late >= delay[f] - a)
            terms += [int(e_int[f]) * early, int(l_int[f]) * late]
        model.minimize(sum(terms) - per_flight * sum(operate))
    else:
        extra_units = operate_units(problem, unit_s)  # per-flight operating costs (a speed change), in delay units
        model.minimize(per_unit * sum(delay) - per_flight * sum(operate)
                       + per_unit * sum(int(c) * operate[f] for f, c in enumerate(extra_units.tolist()) if c))
    return CpsatModel(model, operate, delay, per_unit, per_flight, divisor, how)


def lattice_is_exact(problem: SchedulingProblem, unit_s: float, how: str) -> bool:
    """True when the u-lattice model has the continuous model's optimum (module docstring): every
    time of the data (planned departures, flight times, turnaround gaps, delay bounds, the pairs'
    forbidden intervals and shifts, the earliness/tardiness targets) is a multiple of u, and the
    objective's integer scaling is exact."""
    if how == "approximate":
        return False
    view = problem.pairs
    times = [problem.planned_departure_s, problem.turnaround.need_s, problem.delay_upper_s, view.lo, view.hi, view.shift]
    if problem.objective.per_flight_terms:  # the kinks of the cost, too (then every vertex stays on the lattice)
        times.append(problem.objective.target_s)
    if problem.objective.operate_cost_s is not None:
        times.append(problem.objective.operate_cost_s)
    for family in problem.of_shape("cumulative"):  # the holds' ends, too
        res = family.residual()
        start = problem.planned_departure_s[res.flight] + res.offset_s
        times += [start, start + res.duration_s]
    for values in times:
        units = np.asarray(values, dtype=float) / unit_s
        finite = units[np.isfinite(units)]
        if finite.size and np.max(np.abs(finite - np.rint(finite))) > 1e-6:
            return False
    return True


def objective_bound(problem: SchedulingProblem, raw: float, per_flight: int, divisor: float, unit_s: float, how: str) -> float:
    """CP-SAT's integer bound as a bound of W (weighted) or of model.py's lexicographic scalar."""
    if how != "lexicographic":
        return raw / divisor
    # Σk − M·S ≥ B with 0 ≤ Σk < M gives −S ≥ s0 = ⌈(B − M + 1)/M⌉ and, at −S = s0, Σk ≥ B − M·s0
    s0 = math.ceil((raw - per_flight + 1) / per_flight)
    return s0 + unit_s * max(0.0, raw - per_flight * s0) * problem.objective.per_delay


def cp_solver(limit_s: float, threads: int, seed: int, options: dict | None = None, where: str = "profile cpsat"):
    """A CpSolver with the time limit, threads, seed and CP-SAT ``options`` (``where`` names their
    source in the error of an unknown option); Ctrl-C stays with Python (uamopt.interrupts)."""
    from ortools.sat.python import cp_model

    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = float(limit_s)
    solver.parameters.num_workers = int(threads)
    solver.parameters.random_seed = int(seed)
    # CP-SAT's default small portfolios carry no max-LP worker and cannot close the bound of the
    # paper case in 60 s; with the big-M linear relaxation (level 2) they prove it in about 1 s
    options = dict(options or {})
    if int(threads) == 1:
        options.setdefault("linearization_level", 2)
    else:
        options.setdefault("subsolvers", ["max_lp", "default_lp"])
    for key, value in options.items():
        try:
            if isinstance(value, list):
                getattr(solver.parameters, key).extend(value)
            else:
                setattr(solver.parameters, key, value)
        except (AttributeError, TypeError, ValueError) as exc:
            raise UamoptError(f"unknown or invalid CP-SAT option '{key}': {exc}", where,
                              "see ortools/sat/sat_parameters.proto") from None
    solver.parameters.catch_sigint_signal = False  # its own Ctrl-C handler swallows the interrupt (uamopt.interrupts)
    return solver


def _solver(profile: SolverProfile, options: dict, limit_s: float):
    """A CpSolver for ``profile``."""
    return cp_solver(limit_s, profile.threads, profile.seed, options, f"profile {profile.name or 'cpsat'}")


def _reporter(problem: SchedulingProblem, operate, delay, unit_s: float):
    """A CP-SAT solution callback passing each incumbent on as a schedule (watchdog.report_incumbent:
    a watched child's parent, or the trace of a solve in this process; the receiver checks them)."""
    from ortools.sat.python import cp_model

    class Reporter(cp_model.CpSolverSolutionCallback):
        def on_solution_callback(self) -> None:
            operated = np.array([self.boolean_value(v) for v in operate], dtype=bool)
            delay_s = np.array([self.value(v) for v in delay], dtype=float) * unit_s
            report_incumbent(problem, operated, np.where(operated, delay_s, 0.0), "CP-SAT's incumbent")

    return Reporter()


def solve(problem: SchedulingProblem, profile: SolverProfile, extra=None) -> Schedule:
    """Solve the discretised model with CP-SAT; status optimal | time_limit | infeasible, from CP-SAT's
    own termination (OPTIMAL: proved on the u-lattice model; FEASIBLE: stopped by the time limit,
    the only limit set). Hinted with the best cheap heuristic schedule on the ΔT_a grid
    (:mod:`~uamopt.solvers.warmstart`), and never worse than it.

    Then (option ``continuous_bound``, default true) the ``inner`` model (cells of width u, a
    relaxation) is solved, hinted with that solution, for the rest of the time limit (skipped when
    less than 0.5 s is left; the limit covers both models' building): its bound L is valid for continuous delays, so
    OPT ∈ [L, objective] and the summary gives ``continuous_bound`` = L and ``optimal_within`` = objective − L (an ε
    proved on this instance; no a-priori ε exists, since a feasible window narrower than u may hold no lattice point).
    """
    import time

    from ortools.sat.python import cp_model

    from uamopt.solvers.warmstart import infeasible_reason, no_schedule, no_start, no_worse, reduced, warm_start

    unit_s, want_bound = profile.option("time_unit_s"), profile.option("continuous_bound")
    want_bound = want_bound and extra is None  # the callback's rows need not relax to cells: no continuous bound
    options = {k: v for k, v in profile.options.items() if k not in ("time_unit_s", "continuous_bound")}  # CP-SAT's own
    t0 = time.perf_counter()
    small = reduced(problem)  # dominance caps (warmstart.py): the same optima
    built = build_cpsat(small, unit_s, extra=extra)
    model, operate, delay, per_flight, divisor, how = (built.model, built.operate, built.delay, built.per_flight,
                                                       built.divisor, built.how)
    start = no_start() if extra is not None else warm_start(problem, seed=profile.seed, on_grid=True)
    # (a heuristic schedule knows nothing of the callback's rows: no start, and no fallback to one)
    if start.found:
        hint_operated, hint_delay = start.decisions
        for f in range(problem.n_flights):
            model.add_hint(operate[f], bool(hint_operated[f]))
            model.add_hint(delay[f], int(np.rint(hint_delay[f] / unit_s)) if hint_operated[f] else 0)
    build_s = time.perf_counter() - t0  # model, warm start and hints
    solver = _solver(profile, options, max(0.05, profile.time_limit_s - build_s))  # the limit covers the build too
    with stopping(solver.stop_search):  # Ctrl-C and SIGTERM stop the search at once
        code = solver.solve(model, _reporter(problem, operate, delay, unit_s)) if watched(problem) else solver.solve(model)
    seconds = time.perf_counter() - t0
    n = problem.n_flights
    extras = {"engine_termination": solver.status_name(code), "time_unit_s": unit_s, "objective_scale": how,
              "model": f"delay lattice {unit_s:g} s, constraints rounded outward (a restriction of the continuous model)",
              "branches": int(solver.num_branches), "warm_start": f"{start.source} {start.objective:.6f}",
              "build_seconds": build_s}
    if code == cp_model.MODEL_INVALID:
        why = model.validate() or solver.solution_info()
        raise UamoptError(f"CP-SAT rejected the run: {why}", f"profile {profile.name or 'cpsat'}",
                          "check the profile's [options]" if not model.validate() else "report this as a bug")
    if code == cp_model.INFEASIBLE and not lattice_is_exact(problem, unit_s, how):
        # a proof for the lattice model, a restriction: the continuous MILP (milp.py) decides, in the time left
        from uamopt.solvers import milp

        left = max(0.1, profile.time_limit_s - (time.perf_counter() - t0))
        proof = milp.solve(problem, dataclasses.replace(profile, solver="highs", time_limit_s=left, options={}))
        return dataclasses.replace(proof, solver="cpsat", solve_seconds=time.perf_counter() - t0, extras={
            **extras, **proof.extras, "lattice": "infeasible on the lattice; the continuous MILP (highs) decided"})
    if code == cp_model.INFEASIBLE:  # the lattice is exact: a proof for continuous delays
        extras["reason"] = infeasible_reason(problem)
        return make_schedule(problem, "cpsat", "infeasible", np.zeros(n, bool), np.zeros(n), proved_for="continuous",
                             solve_seconds=seconds,
                             seed=profile.seed, extras=extras)
    if code == cp_model.UNKNOWN and not start.found:
        raise no_schedule(problem, profile.name or "cpsat", "CP-SAT stopped at its limit with no incumbent")
    if code == cp_model.UNKNOWN:  # no incumbent before the limit: the warm start
        return no_worse(problem, make_schedule(problem, "cpsat", "time_limit", np.zeros(n, bool), np.zeros(n),
                                               solve_seconds=seconds, seed=profile.seed, extras=extras), start)
    operated = np.array([solver.boolean_value(v) for v in operate])
    delay_k = [solver.value(v) for v in delay]
    delay_s = np.array(delay_k, dtype=float) * unit_s
    # OPTIMAL proves the u-lattice model, a restriction: optimal_on_grid unless the continuous bound
    # below closes the gap; the lattice bound is no bound of the continuous problem (extras only).
    # When the lattice is exact (the data, not the dominance caps of `small`), its optimum and bound are the continuous ones.
    exact = lattice_is_exact(problem, unit_s, how)
    # OPTIMAL within a relative_gap_limit above round-off is CP-SAT's gap rule (stopped), not a proof
    lattice_bound = objective_bound(problem, solver.best_objective_bound, per_flight, divisor, unit_s, how)
    lattice_value = evaluate(problem, operated, delay_s)
    termination: Termination = "time_limit"  # FEASIBLE: the limit
    if code == cp_model.OPTIMAL:
        termination = "optimal" if closes(lattice_value, lattice_bound) else "stopped"
    proved_for: ProvedFor = ("continuous" if exact else "restricted") if termination == "optimal" else "none"
    extras.update(restricted_bound=lattice_bound, lattice_exact=exact)
    schedule = no_worse(problem, make_schedule(problem, "cpsat", termination, operated, delay_s, proved_for=proved_for,
                                               bound=lattice_bound if exact else None,
                                               solve_seconds=seconds, seed=profile.seed, extras=extras), start)
    assert schedule.objective is not None, "only an infeasible schedule has no objective (make_schedule)"
    # the exact lattice's bound is continuous-valid
    if want_bound and schedule.status == "optimal" and schedule.bound is not None:
        schedule.extras.update(continuous_bound=schedule.bound, continuous_bound_model="the exact lattice (lattice_exact)",
                               optimal_within=schedule.objective - schedule.bound)
    elif want_bound and profile.time_limit_s - (time.perf_counter() - t0) > 0.5:
        inner = build_cpsat(small, unit_s, rounding="inner", extra=extra)
        for f in range(n):  # the outer solution is a point of the relaxation
            inner.model.add_hint(inner.operate[f], bool(operated[f]))
            inner.model.add_hint(inner.delay[f], int(delay_k[f]))
        left = max(0.05, profile.time_limit_s - (time.perf_counter() - t0))
        relaxed = _solver(profile, options, left)
        with stopping(relaxed.stop_search):
            r_code = relaxed.solve(inner.model)
        if r_code in (cp_model.OPTIMAL, cp_model.FEASIBLE, cp_model.UNKNOWN):
            low = objective_bound(problem, relaxed.best_objective_bound, inner.per_flight, inner.divisor, unit_s,
                                  inner.how)
            schedule.extras.update(continuous_bound=low, continuous_bound_termination=relaxed.status_name(r_code),
                                   continuous_bound_model=f"delay cells {unit_s:g} s (relaxation of the continuous model)",
                                   optimal_within=schedule.objective - low)
            termination, proved_for = schedule.termination, schedule.proved_for
            if closes(schedule.objective, low):  # the continuous bound meets the lattice's schedule: proved for continuous
                termination, proved_for = "optimal", "continuous"
            bound = low if schedule.bound is None else max(low, schedule.bound)  # both valid: the larger
            schedule = make_schedule(problem, "cpsat", termination, schedule.operated, schedule.delay_s,
                                     proved_for=proved_for, bound=bound,
                                     solve_seconds=schedule.solve_seconds, seed=profile.seed, extras=schedule.extras)
    return dataclasses.replace(schedule, solve_seconds=time.perf_counter() - t0)
