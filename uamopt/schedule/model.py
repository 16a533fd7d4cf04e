"""The scheduling model as data (Sec. 4.3) and the result every solver returns.

A :class:`SchedulingProblem` holds everything a solver needs and nothing it must derive from the
paper: per flight its planned departure D, flight time, delay bound, turnaround gap and
predecessors; per conflicting pair the forbidden open intervals of δ = dep_q − dep_p; the
objective. Decisions: c_f ∈ {0, 1} (operated) and 0 ≤ d_f ≤ ``delay_upper_s[f]``; dep_f = D_f + d_f.

Constraints (docs/readings.md, Scheduling):

1. Conflicts: for each pair (p, q, intervals) of ``conflicts`` with c_p = c_q = 1,
   dep_q − dep_p ∉ (lo, hi) for every row — i.e. δ ≤ lo or δ ≥ hi.
2. Precedence: c_f ≤ c_{requires[f]} for a return (the aircraft never left without its outbound).
3. Turnaround (Eq. 27): an operated flight departs at least ΔT after the arrival of the previous
   *operated* flight of its aircraft. Equivalently, for every earlier flight e of the same
   aircraft (``chains``): c_e = c_f = 1 ⇒ dep_f ≥ dep_e + flight_time_e + turnaround_after_s[e];
   the pairs with an operated flight in between are implied, so this all-pairs form is exact.
4. Service end (Eq. 26) and delay threshold (Eq. 29): 0 ≤ d_f ≤ delay_upper_s[f]
   = min(Δd_f, T_f − planned arrival_f).

5. Must operate: c_f = 1 where ``must_operate[f]`` (none in the paper's model).

Objective (Eqs. 20-22): ``"weighted"``: W = ω6·Σ_f c_f d_f / G − ω7·Σ_f c_f (minimised);
``"lexicographic"`` (the scenario default, docs/readings.md *Objective*: the paper's stated aim
"minimize delays and maximize the number of flights", Sec. 4.3): most operated flights first, then
least total delay, as the scalar −S + Σ c d / (Σ delay_upper + 1) (the delay term lies in [0, 1),
so S decides first).

The objective, the pair view of the conflicts and "must operate" are defined once, in
:mod:`uamopt.schedule.core`, as ``problem.objective``, ``problem.pairs`` and ``problem.must_operate``.
"""

from __future__ import annotations

import csv
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Literal, TypeVar

import numpy as np

from uamopt.errors import UamoptError
from uamopt.schedule.core import Objective, PairView, pair_view
from uamopt.schedule.flights import TIME_TOL_S, FlightSet
from uamopt.schedule.flights_file import save_flights
from uamopt.schedule.occupancy import ConflictTable, conflict_table

if TYPE_CHECKING:
    from uamopt.scenario import Scenario

T = TypeVar("T")
#: why the solver stopped, and whether that is a proof (``proved_for`` says of which model):
#: ``optimal`` proved optimal (the bound meets the objective to 1e-9 relative); ``infeasible`` proved
#: that no schedule operates the must-operate flights; ``time_limit`` stopped by the limit with a
#: schedule and no proof; ``stopped`` ended by its own rule (a heuristic's iterations, a gap limit
#: above 1e-9, a search that stalled) with a schedule and no proof; ``no_solution`` found no schedule
#: and proved nothing (a heuristic, or an exact solver stopped before its first incumbent).
#: A Ctrl-C or SIGTERM raises (uamopt.interrupts): no schedule is returned for it.
Termination = Literal["optimal", "infeasible", "time_limit", "stopped", "no_solution"]
TERMINATIONS = ("optimal", "infeasible", "time_limit", "stopped", "no_solution")
#: what a proof is about: ``continuous`` the problem with continuous delays (Sec. 4.3); ``restricted`` a
#: restriction of it (delays on a grid or lattice, ``extras["model_kind"]``); ``none`` no proof
ProvedFor = Literal["continuous", "restricted", "none"]
PROVED_FOR = ("continuous", "restricted", "none")
#: the one-word status of files and tables, derived from (termination, proved_for) by :func:`status_of`
#: (no solver stops on a restriction's infeasibility: cpsat and timeindexed hand it to the continuous MILP)
Status = Literal["optimal", "optimal_on_grid", "feasible", "time_limit", "infeasible", "no_solution"]
_STATUS_OF = {("optimal", "continuous"): "optimal", ("optimal", "restricted"): "optimal_on_grid",
              ("infeasible", "continuous"): "infeasible",
              ("time_limit", "none"): "time_limit", ("stopped", "none"): "feasible",
              ("no_solution", "none"): "no_solution"}
STATUSES = tuple(_STATUS_OF.values())
#: a bound "meets" an objective (a proof of optimality) within these: the MIP solvers' default absolute
#: gap (HiGHS mip_abs_gap 1e-6) or a relative 1e-9 of float round-off, whichever is larger
PROOF_ABS = 1e-6
PROOF_REL = 1e-9


def closes(objective: float | None, bound: float | None) -> bool:
    """Whether ``bound`` meets ``objective`` within :data:`PROOF_ABS` / :data:`PROOF_REL` (a proof)."""
    if objective is None or bound is None:
        return False
    return objective - bound <= max(PROOF_ABS, PROOF_REL * abs(objective))


#: the terminations that carry a proof (and only they): ``proved_for`` is not ``none`` exactly for them
PROOFS = ("optimal", "infeasible")


def status_of(termination: str, proved_for: str) -> Status:
    """The status word of a (termination, proved_for) pair (the table in docs/interfaces.md)."""
    try:
        return _STATUS_OF[(termination, proved_for)]  # type: ignore[return-value]
    except KeyError:
        raise UamoptError(f"termination '{termination}' with proved_for '{proved_for}' is no valid result",
                          "a solver's schedule", "optimal needs proved_for continuous or restricted, infeasible "
                          "proved_for continuous, every other termination proved_for none") from None


def termination_of(status: str) -> tuple[Termination, ProvedFor]:
    """The (termination, proved_for) of a status word (reading a summary.json that has only ``status``)."""
    for pair, word in _STATUS_OF.items():
        if word == status:
            return pair  # type: ignore[return-value]
    raise UamoptError(f"unknown status '{status}'", "summary.json", f"use one of {', '.join(STATUSES)}")


ObjectiveKind = Literal["weighted", "lexicographic", "earliness_tardiness"]


@dataclass(frozen=True, eq=False)
class SchedulingProblem:
    """The model (data). Build it with :func:`build_problem`; any solver takes it as it is."""

    flights: FlightSet
    conflicts: ConflictTable  # a sequence of PairConflict(p, q, intervals); named arrays in ``pairs``
    weights: tuple[float, float] = (0.6, 0.4)  # (ω6, ω7), Eq. 20
    aircraft_count: int = 0  # G, Eq. 21: the number of distinct aircraft in ``flights`` (0: fill it in)
    objective_kind: ObjectiveKind = "weighted"
    time_step_s: float = 10.0  # ΔT_a (Table B.3): the heuristics' delay grid unless a profile sets step_s
    #: (n,) bool: flights that may not be cancelled (core.py); None: none. Typed as what __post_init__ makes of it
    #: (always an (n,) bool array), so that readers need not narrow it: the None default is the ignore's reason
    must_operate: np.ndarray = None  # type: ignore[assignment]  # None default: __post_init__ makes the array
    #: families beyond the paper's five (uamopt.schedule.families), e.g. a departure spacing
    extra_families: tuple = ()
    #: the objective itself when it is not made from the weights and the delay bounds (kind
    #: earliness_tardiness; speed options' operating costs)
    objective_terms: Objective | None = None
    #: families that replace the paper's five (a model whose flights are not one plan's flights:
    #: speed options' copies, families/speed.py); None: :func:`~uamopt.schedule.families.paper_families`
    core_families: tuple | None = None

    def __post_init__(self) -> None:
        if self.objective_kind not in ("weighted", "lexicographic", "earliness_tardiness"):
            raise UamoptError(f"unknown objective '{self.objective_kind}'", "schedule objective", "use weighted or lexicographic")
        if self.objective_kind == "earliness_tardiness" and self.objective_terms is None:
            raise UamoptError("objective earliness_tardiness needs its terms "
                              "(objective_terms=Objective.earliness_tardiness(...))", "SchedulingProblem", "give objective_terms")
        if self.objective_terms is not None and self.objective_terms.kind != self.objective_kind:
            raise UamoptError(f"objective_terms is of kind {self.objective_terms.kind}, not {self.objective_kind}",
                              "SchedulingProblem", "give terms of the problem's objective kind")
        object.__setattr__(self, "extra_families", tuple(self.extra_families))
        if self.aircraft_count <= 0:
            object.__setattr__(self, "aircraft_count", self.flights.n_aircraft)
        must = np.zeros(len(self.flights), dtype=bool) if self.must_operate is None else np.asarray(self.must_operate, dtype=bool)
        if must.shape != (len(self.flights),):
            raise UamoptError(f"must_operate has shape {must.shape}, not ({len(self.flights)},)", "SchedulingProblem",
                              "give one bool per flight")
        must.setflags(write=False)
        object.__setattr__(self, "must_operate", must)

    @cached_property
    def families(self) -> tuple:
        """Every constraint family of the model: the paper's five, then ``extra_families``
        (uamopt.schedule.families)."""
        from uamopt.schedule.families import paper_families

        core = paper_families(self) if self.core_families is None else tuple(self.core_families)
        return core + self.extra_families

    def of_shape(self, shape: str) -> list:
        """The families of one shape (``pairs``, ``turnaround``, ...), in order."""
        return [f for f in self.families if f.shape == shape]

    @cached_property
    def turnaround(self):
        """The turnaround rows (e, f, need_s) of every ``turnaround`` family (families/turnaround.py)."""
        from uamopt.schedule.families.turnaround import Turnaround

        rows = self.of_shape("turnaround")
        if len(rows) == 1:
            return rows[0]
        return Turnaround(e=np.concatenate([r.e for r in rows]), f=np.concatenate([r.f for r in rows]),
                          need_s=np.concatenate([r.need_s for r in rows]))

    @cached_property
    def objective(self) -> Objective:
        """The objective's coefficients (Eqs. 20-22 or the lexicographic scalar; core.py)."""
        if self.objective_terms is not None:
            return self.objective_terms
        if self.objective_kind == "lexicographic":
            return Objective.lexicographic(self.delay_upper_s)
        w6, w7 = self.weights
        return Objective.weighted(w6, w7, self.aircraft_count)

    @cached_property
    def pairs(self) -> PairView:
        """The conflicting pairs: forbidden intervals, reach and admissible gaps of δ (core.py)."""
        from uamopt.schedule.families.pairs import merged

        # a cumulative family's one-pad resources are pairs too (families/pads.py)
        p, q, ptr, intervals = merged(self.of_shape("pairs") + [f.disjunctive(self.planned_departure_s, self.delay_upper_s)
                                                              for f in self.of_shape("cumulative")])
        return pair_view(p, q, ptr, intervals, self.planned_departure_s, self.delay_upper_s)

    @property
    def n_flights(self) -> int:
        return len(self.flights)

    # convenient views of the flight set, computed once
    @cached_property
    def planned_departure_s(self) -> np.ndarray:
        return self.flights.planned_departure_s

    @cached_property
    def flight_time_s(self) -> np.ndarray:
        return self.flights.flight_time_s

    @cached_property
    def delay_upper_s(self) -> np.ndarray:
        """Largest admissible delay of each flight: the least bound of every ``bounds`` family;
        the paper's is min(Δd, T_f − planned arrival) (Eqs. 26, 29), s."""
        bounds = [f.upper_of(self) for f in self.of_shape("bounds")]
        out = bounds[0] if len(bounds) == 1 else np.minimum.reduce(bounds)
        out = np.array(out, dtype=float)
        out.setflags(write=False)
        return out

    @cached_property
    def turnaround_after_s(self) -> np.ndarray:
        return self.flights.turnaround_after_s

    @cached_property
    def requires(self) -> np.ndarray:
        """Index of the flight each flight needs operated (a return: its outbound), −1 for none
        (the ``precedence`` family)."""
        out = np.full(self.n_flights, -1, dtype=np.int64)
        for family in self.of_shape("precedence"):
            single = family.single(self.n_flights)
            if single is None:
                raise AttributeError("requires: a precedence family with groups of several flights (use the family's groups)")
            out = np.where(single >= 0, single, out)
        out.setflags(write=False)
        return out

    @cached_property
    def previous(self) -> np.ndarray:
        return self.flights.previous

    @property
    def chains(self) -> tuple[np.ndarray, ...]:
        """Flight indices of each aircraft, in order."""
        return self.flights.chains


def build_problem(
    flightset: FlightSet,
    scenario: Scenario | None = None,
    *,
    weights: tuple[float, float] | None = None,
    objective: ObjectiveKind = "weighted",
) -> SchedulingProblem:
    """Compute the pair conflicts of ``flightset`` and assemble the model: the paper's five
    families and any the scenario's keys switch on (uamopt.schedule.families.scenario_families).

    ``weights`` default to the scenario's (ω6, ω7) = (0.6, 0.4); G defaults to the number of
    distinct aircraft in the flight set (docs/interfaces.md); ΔT_a is ``schedule.time_step_s``.
    """
    from uamopt.schedule.families import scenario_families
    from uamopt.schedule.occupancy import candidate_count
    from uamopt.schedule.plan import check_plan_memory

    copies = len(scenario.schedule.speed_options) if scenario is not None else 1  # speed control: a copy per factor
    check_plan_memory(scenario, len(flightset) * copies, 0, candidate_count(flightset) * copies**2,
                      "schedule.aircraft / schedule.flights / --flights")
    if weights is None:
        weights = tuple(scenario.schedule.weights) if scenario is not None else (0.6, 0.4)
    if scenario is not None and scenario.schedule.speed_change_cost_s > 0 and tuple(scenario.schedule.speed_options) == (1.0,):
        from uamopt.errors import ScenarioError

        raise ScenarioError("schedule.speed_change_cost_s is set but no speed other than the cruise speed is offered",
                            "schedule.speed_change_cost_s", "set schedule.speed_options, e.g. [0.8, 0.9, 1.0], or drop the cost")
    if scenario is not None and tuple(scenario.schedule.speed_options) != (1.0,):  # speed control (families/speed.py)
        from uamopt.schedule.families.speed import speed_problem

        factors = scenario.schedule.speed_options
        return speed_problem(flightset, factors, change_cost_s=scenario.schedule.speed_change_cost_s,
                             weights=tuple(float(w) for w in weights), objective=objective,
                             time_step_s=float(scenario.schedule.time_step_s),
                             families_of=lambda fs: scenario_families(fs, scenario))
    return SchedulingProblem(
        flights=flightset, conflicts=conflict_table(flightset), weights=tuple(float(w) for w in weights),  # type: ignore[arg-type]  # 2 in, 2 out
        aircraft_count=flightset.n_aircraft, objective_kind=objective,
        time_step_s=float(scenario.schedule.time_step_s) if scenario is not None else 10.0,
        extra_families=scenario_families(flightset, scenario),
    )


def evaluate(problem: SchedulingProblem, operated: np.ndarray, delay_s: np.ndarray) -> float:
    """The objective of a decision (feasible or not): Eq. 20, the lexicographic scalar or the
    earliness/tardiness cost."""
    return problem.objective.cost(operated, delay_s)


def violations(problem: SchedulingProblem, operated: np.ndarray, delay_s: np.ndarray, tol_s: float = TIME_TOL_S) -> list[str]:
    """The constraints a decision breaks (empty: feasible): each family's ``violations``, in order.

    This checks against the model's own data; ``uamopt verify`` checks written files independently.
    """
    c = np.asarray(operated, dtype=bool)
    d = np.where(c, np.asarray(delay_s, dtype=float), 0.0)
    out: list[str] = []
    for family in problem.families:
        out += family.violations(problem, c, d, tol_s)
    return out


@dataclass(frozen=True, eq=False)
class Schedule:
    """What every solver returns (linopy-style result): decisions, status, objective, bound."""

    solver: str
    termination: Termination  # why it stopped, and whether that is a proof (TERMINATIONS)
    operated: np.ndarray  # c_f, bool (n,)
    delay_s: np.ndarray  # d_f, s (n,); 0 for cancelled flights
    objective: float | None
    bound: float | None = None
    gap: float | None = None
    solve_seconds: float = 0.0
    seed: int | None = None
    aircraft_count: int = 1  # G, for Eq. 21
    extras: dict = field(default_factory=dict)  # solver-specific figures (iterations, nodes, ...)
    flight_ids: tuple[str, ...] = ()  # row i of operated/delay_s is flight flight_ids[i]
    proved_for: ProvedFor = "none"  # what the proof is about (PROVED_FOR); "none" unless termination is a proof

    def __post_init__(self) -> None:
        if self.termination not in TERMINATIONS:
            raise UamoptError(f"unknown termination '{self.termination}'", f"solver {self.solver}",
                              f"use one of {', '.join(TERMINATIONS)}")
        status_of(self.termination, self.proved_for)  # a consistent pair, or one clear error

    @property
    def status(self) -> Status:
        """The one-word status of files and tables (:func:`status_of`): ``optimal`` (proved for continuous
        delays), ``optimal_on_grid`` (proved for a restriction only), ``feasible`` (a schedule, stopped by
        the solver's own rule), ``time_limit`` (a schedule, stopped by the limit), ``infeasible`` /
        (proved: no schedule exists, for continuous delays), ``no_solution`` (none found, nothing proved)."""
        return status_of(self.termination, self.proved_for)

    @property
    def found(self) -> bool:
        """Whether this is a schedule (termination neither ``infeasible`` nor ``no_solution``)."""
        return self.termination not in ("infeasible", "no_solution")

    @property
    def continuous_bound(self) -> float | None:
        """A lower bound valid for continuous delays (the same as ``bound``, which holds only such bounds)."""
        return self.bound

    @property
    def restricted_bound(self) -> float | None:
        """The restricted model's own bound (a delay grid's or lattice's), not valid for continuous delays."""
        value = self.extras.get("restricted_bound")
        return None if value is None else float(value)

    def raise_for_status(self) -> Schedule:
        """``self``, or :class:`~uamopt.errors.InfeasibleScheduleError` when the status is
        ``infeasible`` (no schedule operates the must-operate flights within the families), with the
        solver's reason: ``ua.solve(problem, "highs").raise_for_status()`` for code that wants an
        exception rather than a status (as ``requests``' ``Response.raise_for_status``). Any other
        status, ``time_limit`` included, is a schedule and returns it."""
        if self.found:
            return self
        from uamopt.errors import InfeasibleScheduleError

        proved = self.extras.get("reason") or "no schedule operates every must-operate flight"
        what = (f"the problem is infeasible: {proved}" if self.termination == "infeasible" else
                "no schedule operating every must-operate flight was found (not a proof)")
        raise InfeasibleScheduleError(what, f"solver {self.solver}",
                                      "pin fewer flights (must_operate) or widen their delay bounds")

    @property
    def operated_count(self) -> int:
        """S (Eq. 22)."""
        return int(np.sum(self.operated))

    @property
    def cancelled(self) -> np.ndarray:
        """1 − c_f: the flights not operated, bool (n,), as :attr:`operated`."""
        return ~np.asarray(self.operated, dtype=bool)

    @property
    def cancelled_count(self) -> int:
        """N − S: how many flights are cancelled."""
        return int(len(self.operated) - self.operated_count)

    @property
    def total_delay_s(self) -> float:
        return float(np.sum(np.where(self.operated, self.delay_s, 0.0)))

    @property
    def avg_delay_s(self) -> float:
        """T_d = total delay of operated flights / G (Eq. 21)."""
        return self.total_delay_s / self.aircraft_count

    def to_frame(self):
        """One row per flight: operated, delay_s (pandas DataFrame indexed by flight id; the
        problem's planned times are in ``FlightSet.to_frame()``, join on the index)."""
        import pandas as pd

        ids = list(self.flight_ids) or [str(i) for i in range(len(self.operated))]
        frame = pd.DataFrame({"flight": ids, "operated": np.asarray(self.operated, dtype=bool),
                              "delay_s": np.asarray(self.delay_s, dtype=float)})
        return frame.set_index("flight")

    def summary(self) -> dict:
        """The keys of summary.json (docs/interfaces.md), plus ``model_kind`` (continuous, delay grid
        with its step, discretised with its unit; what the status is about), ``model`` (the same in
        words), ``continuous_bound`` (a bound valid for continuous delays; ``bound`` holds only such
        bounds) and ``optimal_within`` (objective − continuous_bound) when the solver gives them."""
        named = {key: self.extras[key] for key in ("model_kind", "model", "continuous_bound", "continuous_bound_model",
                                                   "optimal_within", "restricted_bound")
                 if key in self.extras}
        return {
            "solver": self.solver, "status": self.status, "termination": self.termination,
            "proved_for": self.proved_for, "objective": self.objective, "bound": self.bound,
            "gap": self.gap, **named, "operated": self.operated_count, "cancelled": self.cancelled_count,
            "total_delay_s": self.total_delay_s, "avg_delay_s": self.avg_delay_s,
            "solve_seconds": self.solve_seconds, "seed": self.seed,
        }


def make_schedule(
    problem: SchedulingProblem, solver: str, termination: Termination, operated: np.ndarray, delay_s: np.ndarray, *,
    proved_for: ProvedFor = "none", bound: float | None = None, solve_seconds: float = 0.0, seed: int | None = None,
    extras: dict | None = None,
) -> Schedule:
    """A :class:`Schedule` with the objective evaluated and the relative gap |obj − bound| / |obj|
    (``proved_for`` must name the model when ``termination`` is a proof, :data:`PROOFS`)."""
    c = np.asarray(operated, dtype=bool).copy()
    d = np.where(c, np.asarray(delay_s, dtype=float), 0.0)
    objective = evaluate(problem, c, d) if termination not in ("infeasible", "no_solution") else None
    gap = None
    if objective is not None and bound is not None:
        gap = abs(objective - bound) / max(abs(objective), 1e-10)
    return Schedule(solver=solver, termination=termination, proved_for=proved_for, operated=c, delay_s=d,
                    objective=objective, bound=bound, gap=gap,
                    solve_seconds=solve_seconds, seed=seed, aircraft_count=problem.aircraft_count, extras=dict(extras or {}),
                    flight_ids=tuple(f.id for f in problem.flights.flights))


def _fmt(value: float) -> str:
    return repr(float(value))


def write_schedule(out_dir: str | Path, problem: SchedulingProblem, schedule: Schedule, *, extra: dict | None = None,
                   check: Callable[[Path], T] | None = None) -> T | None:
    """Write flights.json, schedule.csv and summary.json into ``out_dir``, all or nothing.

    ``check`` (optional) is called on the staged folder, complete, before anything is published
    into ``out_dir``: an exception it raises leaves ``out_dir`` as it was; what it returns is
    returned (``uamopt schedule`` verifies the files it is about to publish,
    :func:`uamopt.workflows.schedule_folder`).

    ``schedule.csv``: flight, aircraft, route, operated (1/0), planned_departure_s, delay_s,
    departure_s, arrival_s; a cancelled flight has delay 0 and empty departure and arrival.
    ``summary.json`` carries the docs/interfaces.md keys plus ``weights``, ``objective_kind``,
    ``aircraft`` (G) and ``flights`` so the verifier can recompute the objective; ``extra`` adds
    keys (``uamopt schedule`` adds ``frame`` and ``scenario`` for the exports, uamopt.export.frame).
    An ``infeasible`` schedule is no schedule: :meth:`Schedule.raise_for_status` raises before anything is written.
    """
    schedule.raise_for_status()
    from uamopt.outputs import staged_output, write_json
    from uamopt.schedule.families.speed import collapse, speed_choice_of

    choice = speed_choice_of(problem)
    if choice is not None:  # one row per flight at its chosen speed; the choice recorded for the verifier
        extra = dict(extra or {}, families=[choice.record()] + [f.record() if hasattr(f, "record") else {"name": f.name}
                                                                 for f in problem.extra_families])
        problem, schedule = collapse(problem, schedule)
    fs = problem.flights
    dep = problem.planned_departure_s + schedule.delay_s
    arr = dep + problem.flight_time_s
    summary = schedule.summary() | {
        "weights": list(problem.weights), "objective_kind": problem.objective_kind,
        "aircraft": problem.aircraft_count, "flights": problem.n_flights,
    } | (extra or {})
    if schedule.extras:
        summary["extras"] = schedule.extras
    if fs.notes:
        summary["plan_notes"] = list(fs.notes)
    if problem.extra_families:  # what uamopt verify needs to check them from the files (verify_variants.py)
        summary["families"] = [f.record() if hasattr(f, "record") else {"name": f.name, "shape": f.shape}
                               for f in problem.extra_families]
    with staged_output(out_dir) as stage:
        save_flights(stage / "flights.json", fs)
        with open(stage / "schedule.csv", "w", newline="", encoding="utf-8") as fh:
            writer = csv.writer(fh)
            writer.writerow(["flight", "aircraft", "route", "operated", "planned_departure_s", "delay_s", "departure_s",
                             "arrival_s"])
            for i, f in enumerate(fs.flights):
                on = bool(schedule.operated[i])
                writer.writerow([
                    f.id, f.aircraft, f.route, int(on), _fmt(f.planned_departure_s), _fmt(schedule.delay_s[i] if on else 0.0),
                    _fmt(dep[i]) if on else "", _fmt(arr[i]) if on else "",
                ])
        write_json(stage / "summary.json", summary)
        return check(stage) if check is not None else None
