"""The pipeline as plain functions: what every command runs, one call per stage (PyPSA's pattern).

::

    import uamopt as ua
    scenario = ua.load_scenario("models/paper_case.toml", ["grid.cell=[25,25,30]"])
    field    = ua.compute_risk(scenario)                  # RiskField; field.summary() -> dict
    model    = ua.planning_model(scenario, field)         # admissible cells, edge costs (Sec. 4.2)
    plan     = ua.plan_track(model, "V1", "V4")           # or (x, y, z) in metres; plan.to_frame()
    network  = ua.plan_network(model)                     # RouteNetwork; network.to_frame()
    flights  = ua.generate_flights(scenario, network)     # FlightSet; flights.to_frame()
    problem  = ua.build_problem(flights, scenario)        # SchedulingProblem (conflicts computed)
    schedule = ua.solve(problem, "highs", time_limit_s=30)  # Schedule; schedule.to_frame()
    check    = ua.verify(problem, schedule)               # Verification: .ok, .violations

Data flows one way; each stage takes the previous stage's typed value and never reaches back
into its internals. The CLI (``uamopt.cli``) only parses arguments and writes files.
"""

from __future__ import annotations

import dataclasses
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from uamopt.checks import expect
from uamopt.errors import UamoptError
from uamopt.scenario import Scenario

if TYPE_CHECKING:
    import pandas as pd

    from uamopt.grid import AirspaceGrid
    from uamopt.planning.network import RouteNetwork
    from uamopt.planning.problem import PlanningModel
    from uamopt.risk import RiskField
    from uamopt.schedule.flights import FlightSet
    from uamopt.schedule.model import Schedule, SchedulingProblem
    from uamopt.solvers import SolverProfile


def scenario_grid(scenario: Scenario, *, use: str = "risk") -> AirspaceGrid:
    """The scenario's grid: ``grid.extent`` (default: the city source's extent up to h'_max) in
    ``grid.cell`` cells, refused before allocation when its run (``use``: ``"risk"`` keeps the
    field's terms, ``"plan"`` does not: :data:`uamopt.grid.grid.MEMORY_MODEL`) would need more than
    ``grid.memory_limit_gb``."""
    from uamopt.city import source_extent
    from uamopt.grid import build_grid

    expect(scenario, Scenario, "scenario", "scenario_grid")
    if not isinstance(use, str) or use not in ("risk", "plan"):
        raise ValueError(f"scenario_grid(): use must be 'risk' or 'plan', got {use!r}"[:200])
    if scenario.grid.extent is not None:
        extent = scenario.grid.extent
    else:
        ex, ey = source_extent(scenario)
        extent = (ex, ey, scenario.grid.h_max_airspace)
    return build_grid(extent, scenario.grid.cell, memory_limit_gb=scenario.grid.memory_limit_gb, use=use)


def compute_risk(scenario: Scenario, *, keep_risk: bool = True) -> RiskField:
    """Grid, city layers and the risk field of Eqs. 1–9 / A.1–A.9 (Sec. 3, 4.1.1, App. A).

    The returned field carries its timings in ``meta["seconds"]`` (city, risk, total) and
    ``summary()`` gives the risk command's ``summary.json``. With ``keep_risk=False`` the
    continuous risk (Eq. 8 and its three terms) is computed again when first used instead of kept:
    a planning run's memory (:func:`uamopt.risk.risk_field`).
    """
    from uamopt.city import load_city
    from uamopt.risk import risk_field

    expect(scenario, Scenario, "scenario", "compute_risk")
    expect(keep_risk, bool, "keep_risk", "compute_risk")
    t0 = time.perf_counter()
    grid = scenario_grid(scenario, use="risk" if keep_risk else "plan")
    city = load_city(scenario, grid)
    t1 = time.perf_counter()
    field = risk_field(scenario, grid, city, keep_risk=keep_risk)
    t2 = time.perf_counter()
    field.meta["seconds"] = {"city": t1 - t0, "risk": t2 - t1, "total": t2 - t0}
    return field


def planning_model(scenario: Scenario, field: RiskField) -> PlanningModel:
    """Admissible cells, Eq. 11 risk, the safety buffer R(t) of Eq. 35 and transport rates."""
    from uamopt.planning.problem import planning_model as build
    from uamopt.risk import RiskField

    expect(scenario, Scenario, "scenario", "planning_model")
    expect(field, RiskField, "field", "planning_model")
    from uamopt.risk import field_inputs

    made_for = field.meta.get("scenario")
    inputs, expected = field.meta.get("inputs") or {}, field_inputs(scenario)
    differ = [name for name in expected if name in inputs and inputs[name] != expected[name]]
    if differ:
        raise UamoptError(f"the risk field was computed for another scenario: its [{'], ['.join(differ)}] settings "
                          f"differ from those of {scenario.name!r}", "planning_model(scenario, field)",
                          "pass the field ua.compute_risk(scenario) returned for this scenario, or recompute it")
    if (made_for is not None and made_for != scenario.name) or tuple(field.grid.cell) != tuple(map(float, scenario.grid.cell)):
        raise UamoptError(f"the risk field was computed for another scenario ({made_for!r}, cells {field.grid.cell}), "
                          f"not {scenario.name!r} (cells {tuple(scenario.grid.cell)})", "planning_model(scenario, field)",
                          "pass the field ua.compute_risk(scenario) returned for this scenario")
    return build(scenario, field)


def plan_track(model: PlanningModel, origin=None, destination=None, **options):
    """The four stages of Fig. 18 / Table 2 between two points (x, y, z m) or vertiport names;
    omitted: the scenario's route (``tracks.route``, else the first and farthest vertiports)."""
    from uamopt.planning.endpoints import default_endpoints
    from uamopt.planning.problem import PlanningModel
    from uamopt.planning.tracks import plan_track as plan

    expect(model, PlanningModel, "model", "plan_track")
    if origin is None or destination is None:
        o, d = default_endpoints(model.scenario)
        origin = o if origin is None else origin
        destination = d if destination is None else destination
    return plan(model, origin, destination, **options)


def plan_network(model: PlanningModel, progress=None) -> RouteNetwork:
    """One planned track per route and direction, directions on separate layers (Sec. 4.1.2, 6.2)."""
    from uamopt.planning.network import plan_network as plan
    from uamopt.planning.problem import PlanningModel

    expect(model, PlanningModel, "model", "plan_network")
    if progress is not None and not callable(getattr(progress, "update", None)):
        raise TypeError(f"plan_network(): progress must be None or an object with update(n) (a tqdm bar, "
                        f"uamopt.progress.Progress), got {type(progress).__name__}")
    return plan(model, progress=progress)


def generate_flights(scenario: Scenario, network, seed: int | None = None) -> FlightSet:
    """The initial flight plan of Sec. 6.2 (Eqs. 23–29) on ``network`` (a RouteNetwork or route
    name → waypoints); ``seed`` defaults to ``schedule.plan_seed``."""
    from collections.abc import Mapping

    import numpy as np

    from uamopt.schedule.plan import generate_plan

    expect(scenario, Scenario, "scenario", "generate_flights")
    rule = "generate_flights(): network must be a RouteNetwork (ua.plan_network) or a mapping route name -> (n, 3) waypoints"
    if callable(getattr(network, "waypoints", None)):  # a RouteNetwork (not imported here: the planner is heavy)
        network = network.waypoints()
    if not isinstance(network, Mapping):
        raise TypeError(f"{rule}, got {type(network).__name__}")
    for name, waypoints in network.items():
        if not isinstance(name, str):
            raise TypeError(f"{rule} (names such as 'V1-V2'), got a route named by a {type(name).__name__}")
        try:
            np.asarray(waypoints, dtype=float)
        except (TypeError, ValueError):
            raise TypeError(f"{rule}, got {type(waypoints).__name__} {str(waypoints)[:40]!r} for route '{name}'") from None
    return generate_plan(scenario, network, scenario.schedule.plan_seed if seed is None else seed)


def build_problem(flights: FlightSet, scenario: Scenario | None = None, *, objective: str | None = None,
                  weights: tuple[float, float] | None = None) -> SchedulingProblem:
    """The scheduling model as data (pair conflicts computed); ``objective`` defaults to
    ``schedule.objective`` (weighted Eq. 20, or lexicographic)."""
    import math

    from uamopt.bounds import MAX_WEIGHT
    from uamopt.schedule.flights import FlightSet
    from uamopt.schedule.model import build_problem as build

    expect(flights, FlightSet, "flights", "build_problem")
    if not flights.flights:  # nothing to schedule (a FlightSet filtered to nothing)
        raise UamoptError("the flight set is empty: there is nothing to schedule", "build_problem(flights)",
                          "give at least one flight (ua.generate_flights or ua.load_flights)")
    if scenario is not None:
        expect(scenario, Scenario, "scenario", "build_problem")
    if weights is not None:
        if not (isinstance(weights, (list, tuple)) and len(weights) == 2
                and all(isinstance(w, (int, float)) and not isinstance(w, bool) for w in weights)):
            raise TypeError(f"build_problem(): weights must be a pair of numbers (ω6, ω7), got {weights!r}")
        if not all(math.isfinite(w) and 0 <= w <= MAX_WEIGHT for w in weights) or not sum(weights) > 0:
            raise UamoptError(f"the objective weights must be finite numbers in [0, {MAX_WEIGHT:g}] (the range of "
                              f"schedule.weights), not both 0, got {tuple(weights)}",
                              "build_problem(weights=...)", "give e.g. (0.6, 0.4), as schedule.weights")
    kind = objective or (scenario.schedule.objective if scenario is not None else "weighted")
    return build(flights, scenario, weights=weights, objective=kind)  # type: ignore[arg-type]


def checked_network(scenario: Scenario, network_file):
    """``--network``: the file's routes, each inside the grid, airborne and clear of the city's
    buildings (uamopt/schedule/airspace.py), before anything is generated or written."""
    import math

    from uamopt.io import load_network

    network = load_network(network_file)
    cell = network.cell if all(math.isfinite(c) for c in network.cell) else scenario.grid.cell
    _check_file_tracks(scenario, scenario_grid(scenario).extent, network.waypoints(), cell, f"--network {network_file}",
                       "route")
    return network


def _check_file_tracks(scenario: Scenario, extent, tracks, cell, source: str, kind: str) -> None:
    """Tracks from a file inside the airspace, then (unless ``network.tracks = "straight"``) above
    the city's surface on the file's own cells (uamopt/schedule/airspace.py)."""
    from uamopt.city import load_city
    from uamopt.grid.grid import file_grid
    from uamopt.schedule.airspace import check_above_surface, check_in_airspace

    check_in_airspace(extent, tracks, source, kind)
    if scenario.network.tracks == "straight":
        return
    grid = file_grid(tuple(extent), tuple(cell), scenario.grid.memory_limit_gb, source)
    check_above_surface(tracks, load_city(scenario, grid).surface_height, grid.cell, source, kind)


def scenario_flights(scenario: Scenario, flights_file=None, network_file=None, seed: int | None = None):
    """The flights to schedule: ``flights_file`` (self-contained, or on ``network_file``'s routes),
    else the generated plan on ``network_file`` or on the network planned now. Tracks from files
    are checked against the scenario's grid and city first (uamopt/schedule/airspace.py)."""
    from uamopt.io import load_flights

    if not (flights_file or network_file):
        scenario.network.route_list()  # a network without routes is refused before anything is computed
    if not flights_file:  # a plan too large for the memory is refused before the network is planned
        from uamopt.schedule.plan import check_plan_memory

        check_plan_memory(scenario, scenario.schedule.flights or 0, scenario.schedule.aircraft)
    network = checked_network(scenario, network_file) if network_file else None
    if flights_file:
        grid = scenario_grid(scenario)
        flights = load_flights(flights_file, scenario, grid, network and network.waypoints())
        _check_file_tracks(scenario, grid.extent, {f.id: f.waypoints for f in flights.flights}, flights.cell,
                           str(flights_file), "flight")
        return flights
    if network is None:
        network = plan_network(planning_model(scenario, compute_risk(scenario, keep_risk=False)))
    return generate_flights(scenario, network, seed)


def solver_profile(profile: SolverProfile | str | Path, **overrides) -> SolverProfile:
    """A profile by name (``highs``), path or object, with ``time_limit_s``, ``seed``,
    ``threads`` or ``options`` replaced."""
    import os
    from collections.abc import Mapping

    from uamopt.solvers import SolverProfile, load_profile

    expect(profile, (SolverProfile, str, os.PathLike), "profile", "solver_profile")
    fields = [f.name for f in dataclasses.fields(SolverProfile) if f.name != "solver"]
    unknown = sorted(set(overrides) - set(fields))
    if unknown:
        raise TypeError(f"solver_profile(): unknown override {unknown[0]!r}; a profile takes {', '.join(fields)}")
    if "options" in overrides and not isinstance(overrides["options"], Mapping):
        raise TypeError(f"solver_profile(): options must be a dict of the solver's options (e.g. {{'step_s': 5.0}}), "
                        f"got {type(overrides['options']).__name__}")
    base = profile if isinstance(profile, SolverProfile) else load_profile(profile)
    if "options" in overrides:
        overrides["options"] = {**base.options, **overrides["options"]}
    return dataclasses.replace(base, **overrides) if overrides else base


def solve(problem: SchedulingProblem, profile: SolverProfile | str | Path = "greedy", *, extra=None, **overrides) -> Schedule:
    """Run one solver profile on the problem, e.g. ``solve(problem, "highs", time_limit_s=30)``;
    ``extra``: a callback that edits the exact model before it is solved (highs, cpsat; docs/variants.md)."""
    from uamopt.schedule.model import SchedulingProblem
    from uamopt.solvers import solve as run

    expect(problem, SchedulingProblem, "problem", "solve")
    if extra is not None and not callable(extra):
        raise TypeError(f"solve(): extra must be None or a callable that edits the exact model, got {type(extra).__name__}")
    return run(problem, solver_profile(profile, **overrides), extra=extra)


@dataclass(frozen=True)
class Verification:
    """The independent verifier's verdict on a schedule (``uamopt verify``)."""

    ok: bool
    messages: tuple[str, ...]

    @property
    def violations(self) -> pd.DataFrame:
        """One row per violation: ``kind`` (conflict, turnaround, delay, ...) and ``message``."""
        import pandas as pd

        return pd.DataFrame({"kind": [m.split(":", 1)[0] for m in self.messages], "message": list(self.messages)})

    def __bool__(self) -> bool:
        return self.ok


def verify(problem: SchedulingProblem, schedule: Schedule) -> Verification:
    """Write the schedule as its files and check them with the independent verifier, which shares
    no code with the model (``uamopt.schedule.verify``)."""
    from uamopt.schedule.model import Schedule, SchedulingProblem, write_schedule
    from uamopt.schedule.verify import verify_dir

    expect(problem, SchedulingProblem, "problem", "verify")
    expect(schedule, Schedule, "schedule", "verify")
    if len(schedule.operated) != problem.n_flights or (schedule.flight_ids and tuple(schedule.flight_ids) != problem.flights.ids):
        raise UamoptError(f"the schedule is of another problem ({len(schedule.operated)} flights, the problem has "
                          f"{problem.n_flights})", "verify(problem, schedule)",
                          "pass the schedule ua.solve(problem, ...) returned for this problem")
    with tempfile.TemporaryDirectory(prefix="uamopt-verify-") as tmp:
        folder = Path(tmp) / "schedule"
        write_schedule(folder, problem, schedule)
        messages = tuple(verify_dir(folder))
    return Verification(ok=not messages, messages=messages)
