"""Speed control (Sec. 7: conflicts resolved by "velocity adjustments", not only ground delay).

``schedule.speed_options`` = [k_1, …] (factors of the cruise speed v_g, each in (0, 1]: no aircraft
flies faster than its cruise speed; default [1.0], the paper's model): each operated flight flies
its whole track at one speed k·v_g of its choice. Occupancy, the conflict intervals, the arrival
and the turnaround follow from that speed.

Model: each flight f becomes one *copy* per factor (``copy_of``, ``factor``), a flight of the same
aircraft, route, planned departure, Δd and ΔT at speed k·v_g, and the model is the paper's on the
copies, with these families in place of the paper's five:

- ``delay_bounds`` per copy (its own arrival for Eq. 26);
- ``conflicts``: the pair conflicts of the copies (uamopt.schedule.occupancy; copies of one aircraft
  are never a conflicting pair);
- ``speed_choice`` (shape ``pairs``): two copies of one flight never both operate (a pair whose
  forbidden interval covers every reachable δ) — so at most one speed per flight;
- ``speed_turnaround``: for every flight e before f of one aircraft and every copy pair
  (e_s, f_t): d_{f_t} − d_{e_s} ≥ D_e + T_{e_s} + ΔT_e − D_f;
- ``speed_precedence``: a return's copy operates only if some copy of its outbound does;
- ``must_operate``: none.

Objective: the scenario's kind on the copies; a copy at a factor ≠ 1 costs
``schedule.speed_change_cost_s`` seconds of delay when operated (``Objective.operate_cost_s``);
the lexicographic kind's delay weight is 1 / (Σ U + Σ change cost + 1) over the copies, so flights
still come first. Every solver with the ``pairs``, ``turnaround`` and ``precedence`` encoders solves
it exactly or heuristically; the heuristics try the speeds of a flight in order — the cruise speed
first, then the others as listed (copies are placed in that order by the decoder).

Output: :func:`collapse` turns a schedule of the copies back into one row per flight, flights.json
carrying the chosen speed (cancelled flights: v_g); summary.json records the factors, each flight's
cruise speed and the change cost (``families``), and ``uamopt verify`` checks from the files alone
that each operated flight's speed is an allowed factor of its cruise speed, its arrival follows
from that speed, and the objective with the change costs (uamopt/schedule/verify_variants.py).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from uamopt.errors import ScenarioError
from uamopt.schedule.families.pairs import PairIntervals

if TYPE_CHECKING:
    from uamopt.schedule.model import ObjectiveKind


@dataclass(frozen=True, eq=False)
class SpeedChoice(PairIntervals):
    """The ``speed_choice`` pairs, with the copies' origin: ``copy_of[j]`` (flight of the base
    flight set), ``factor[j]``, and the base flight set itself (for :func:`collapse`)."""

    copy_of: np.ndarray | None = None
    factor: np.ndarray | None = None
    base: object | None = None
    #: the same flights at the cruise speed only (the paper's model): solved first by the exact
    #: solvers, its schedule the start of the speed model (uamopt.solvers.solve)
    base_problem: object | None = None

    def lift(self, operated: np.ndarray, delay_s: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """A schedule of ``base_problem`` as one of the copies (each flight at the cruise speed), or
        None when the cruise speed is not an option."""
        if not np.any(self.factor == 1.0):
            return None
        assert self.copy_of is not None, "speed_problem sets copy_of"
        n_copies = len(self.copy_of)
        on, d = np.zeros(n_copies, dtype=bool), np.zeros(n_copies)
        cruise = np.flatnonzero(self.factor == 1.0)  # one per flight, in flight order
        on[cruise[np.asarray(operated, dtype=bool)]] = True
        d[cruise] = np.where(operated, delay_s, 0.0)
        return on, d


def check_factors(factors) -> tuple[float, ...]:
    out = tuple(float(k) for k in factors)
    if not out or len(set(out)) != len(out) or not all(0.0 < k <= 1.0 for k in out):
        raise ScenarioError(f"speed options {list(out)} must be distinct factors in (0, 1]", "schedule.speed_options",
                            "give factors of the cruise speed, e.g. [0.8, 0.9, 1.0]")
    return out


def try_order(factors: tuple[float, ...]) -> tuple[float, ...]:
    """The cruise speed first (when offered), then the others as listed."""
    return tuple(sorted(factors, key=lambda k: (k != 1.0,)))


def speed_problem(flightset, factors, *, change_cost_s: float = 0.0, weights=(0.6, 0.4),
                  objective: ObjectiveKind = "lexicographic", time_step_s: float = 10.0, families_of=None):
    """The scheduling model with a speed choice per flight (module docstring); ``families_of(flightset)``
    gives the extra families of a flight set (the scenario's, families.scenario_families), for the
    copies and for the cruise-speed model alike."""
    families_of = families_of or (lambda fs: ())
    from uamopt.schedule.core import Objective
    from uamopt.schedule.families.bounds import DelayBounds
    from uamopt.schedule.families.must import MustOperate
    from uamopt.schedule.families.turnaround import Precedence, Turnaround
    from uamopt.schedule.model import SchedulingProblem
    from uamopt.schedule.occupancy import conflict_table

    order = try_order(check_factors(factors))
    pair = (float(weights[0]), float(weights[1]))  # (ω6, ω7)
    base = flightset
    n, k = len(base), len(order)
    copies, copy_rows, factor_rows = [], [], []
    for i, f in enumerate(base.flights):
        for s in order:
            copies.append(dataclasses.replace(f, id=f"{f.id}@{s:g}" if s != 1.0 else f.id, speed_mps=f.speed_mps * s))
            copy_rows.append(i)
            factor_rows.append(s)
    copy_of, factor = np.array(copy_rows, dtype=np.int64), np.array(factor_rows, dtype=float)
    expanded = dataclasses.replace(base, flights=tuple(copies))
    index = np.arange(n * k).reshape(n, k)  # copies of flight i: index[i]
    upper = DelayBounds.of(expanded)
    u = upper.upper_s
    rows = [(int(a), int(b), -float(u[a]) - 1.0, float(u[b]) + 1.0) for i in range(n) for x, a in enumerate(index[i])
            for b in index[i][x + 1:]]  # δ = 0 ± the delays: the whole reachable range is forbidden
    record = {"factors": list(order), "change_cost_s": float(change_cost_s),
              "cruise_speed_mps": {f.id: f.speed_mps for f in base.flights}}
    choice = SpeedChoice.of_rows("speed_choice", rows, record_data=record,
                                 description="speed choice: one speed per flight (copies of a flight never both operate)")
    plain = SchedulingProblem(flights=base, conflicts=conflict_table(base), weights=pair,
                              aircraft_count=base.n_aircraft, objective_kind=objective, time_step_s=time_step_s,
                              extra_families=tuple(families_of(base)))
    choice = dataclasses.replace(choice, copy_of=copy_of, factor=factor, base=base, base_problem=plain)
    dep, gap = base.planned_departure_s, base.turnaround_after_s
    time = expanded.flight_time_s
    e_list, f_list = [], []
    for chain in base.chains:
        for x, e in enumerate(chain.tolist()):
            for f in chain[x + 1:].tolist():
                for a in index[e]:
                    for b in index[f]:
                        e_list.append(a)
                        f_list.append(b)
    e_rows, f_rows = np.array(e_list, dtype=np.int64), np.array(f_list, dtype=np.int64)
    turn = Turnaround(e=e_rows, f=f_rows,
                      need_s=dep[copy_of[e_rows]] + time[e_rows] + gap[copy_of[e_rows]] - dep[copy_of[f_rows]],
                      name="speed_turnaround",
                      description="turnaround (Eqs. 27-28) at the chosen speeds: every copy pair of an aircraft's flights")
    req = base.requires
    groups = [(int(a), index[req[i]]) for i in range(n) if req[i] >= 0 for a in index[i]]
    prec = Precedence(flight=np.array([g[0] for g in groups], dtype=np.int64),
                      ptr=np.arange(0, k * len(groups) + 1, k, dtype=np.int64),
                      idx=np.concatenate([g[1] for g in groups]).astype(np.int64) if groups else np.zeros(0, np.int64),
                      name="speed_precedence", description="precedence: a return's copy needs some copy of its outbound")
    c = conflict_table(expanded)
    conflicts = PairIntervals.of_table("conflicts", c.p, c.q, c.ptr, c.intervals)
    change = np.where(factor != 1.0, float(change_cost_s), 0.0)
    if objective == "lexicographic":
        terms = Objective("lexicographic", 1.0 / (float(np.sum(u)) + float(np.sum(change)) + 1.0), 1.0)
    else:
        terms = Objective.weighted(weights[0], weights[1], base.n_aircraft)
    if np.any(change > 0):
        terms = terms.with_operate_cost(change)
    core = (upper, MustOperate(np.zeros(n * k, dtype=bool)), prec, turn, conflicts, choice)
    return SchedulingProblem(flights=expanded, conflicts=c, weights=pair,
                             aircraft_count=base.n_aircraft, objective_kind=objective, time_step_s=time_step_s,
                             core_families=core, extra_families=tuple(families_of(expanded)), objective_terms=terms)


def speed_choice_of(problem) -> SpeedChoice | None:
    """The problem's ``speed_choice`` family, if it has speed options."""
    return next((f for f in problem.families if isinstance(f, SpeedChoice)), None)


def collapse(problem, schedule):
    """(problem over the base flights at their chosen speeds, schedule of those flights): the
    written form of a speed-choice schedule (one row per flight; module docstring)."""
    from uamopt.schedule.model import SchedulingProblem
    from uamopt.schedule.occupancy import ConflictTable

    choice = speed_choice_of(problem)
    base = choice.base
    n = len(base)
    operated, delay = np.zeros(n, dtype=bool), np.zeros(n)
    flights = list(base.flights)
    for j in np.flatnonzero(schedule.operated):
        i = int(choice.copy_of[j])
        operated[i], delay[i] = True, float(schedule.delay_s[j])
        flights[i] = dataclasses.replace(flights[i], speed_mps=base.flights[i].speed_mps * float(choice.factor[j]))
    fs = dataclasses.replace(base, flights=tuple(flights))
    flat = SchedulingProblem(flights=fs, conflicts=ConflictTable.empty(), weights=problem.weights,
                             aircraft_count=problem.aircraft_count, objective_kind=problem.objective_kind,
                             time_step_s=problem.time_step_s)
    chosen = {base.flights[int(choice.copy_of[j])].id: float(choice.factor[j]) for j in np.flatnonzero(schedule.operated)}
    out = dataclasses.replace(schedule, operated=operated, delay_s=delay, flight_ids=fs.ids,
                              extras=dict(schedule.extras, speed_factors=chosen))
    return flat, out

