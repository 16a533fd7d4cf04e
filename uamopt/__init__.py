"""uamopt: Urban Air Mobility operations research toolkit.

Data flows one way: scenario → city layers → airspace grid → risk field → planning model →
tracks → route network → flight plan → scheduling problem → solver → schedule → verification.
Every stage is one call from ``import uamopt`` (see ``docs/interfaces.md``)::

    import uamopt as ua
    scenario = ua.load_scenario("models/paper_case.toml", ["grid.cell=[25,25,30]"])
    field = ua.compute_risk(scenario)
    model = ua.planning_model(scenario, field)
    plan = ua.plan_track(model, "V1", "V4")
    network = ua.plan_network(model)
    flights = ua.generate_flights(scenario, network)
    problem = ua.build_problem(flights, scenario)
    schedule = ua.solve(problem, "highs", time_limit_s=30)
    assert ua.verify(problem, schedule).ok

Names are resolved on first use, so ``import uamopt`` stays light (no solver, plotting or GIS
library is imported until a stage needs it).
"""

from __future__ import annotations

import importlib

from uamopt.errors import (  # re-exported: the "X as X" form marks them public for linters and type checkers
    GridError as GridError,
    InfeasibleScheduleError as InfeasibleScheduleError,
    InputFileError as InputFileError,
    NoTrackError as NoTrackError,
    ScenarioError as ScenarioError,
    UamoptError as UamoptError,
)
from uamopt.lazy import lazy_getattr

__version__ = "0.1.0"

#: public name -> module that defines it (imported on first access, PEP 562)
_LAZY = {
    "Scenario": "uamopt.scenario", "load_scenario": "uamopt.scenario",
    "AirspaceGrid": "uamopt.grid", "build_grid": "uamopt.grid", "scenario_grid": "uamopt.pipeline",
    "CityLayers": "uamopt.city", "load_city": "uamopt.city",
    "RiskField": "uamopt.risk", "risk_field": "uamopt.risk",
    "compute_risk": "uamopt.pipeline", "planning_model": "uamopt.pipeline", "plan_track": "uamopt.pipeline",
    "plan_network": "uamopt.pipeline", "generate_flights": "uamopt.pipeline", "build_problem": "uamopt.pipeline",
    "solve": "uamopt.pipeline", "solver_profile": "uamopt.pipeline", "verify": "uamopt.pipeline",
    "Verification": "uamopt.pipeline",
    "PlanningModel": "uamopt.planning.problem", "TrackPlan": "uamopt.planning.tracks",
    "RouteNetwork": "uamopt.planning.network", "weight_sweep": "uamopt.planning.pareto",
    "FlightSet": "uamopt.schedule.flights", "SchedulingProblem": "uamopt.schedule.model",
    "Schedule": "uamopt.schedule.model", "SolverProfile": "uamopt.solvers",
    "read_airland": "uamopt.schedule.airland", "Objective": "uamopt.schedule.core",
    "load_risk": "uamopt.io", "load_tracks": "uamopt.io", "load_network": "uamopt.io",
    "load_flights": "uamopt.io", "load_schedule": "uamopt.io",
    "write_model": "uamopt.solvers.model_files", "read_solution": "uamopt.solvers.model_files",
    # experiments: not modules of these names, so that importing one never shadows the function
    "sweep": "uamopt.experiments.engine", "load_sweep": "uamopt.experiments.spec",
    "plot_sweep": "uamopt.plotting.sweeps", "benchmark": "uamopt.experiments.benchmark",
}

__all__ = sorted([*_LAZY, "GridError", "InfeasibleScheduleError", "InputFileError", "NoTrackError",
                  "ScenarioError", "UamoptError"])


_lazy = lazy_getattr(__name__, _LAZY)


def __getattr__(name: str):
    if name == "plotting":  # a package
        return importlib.import_module(f"uamopt.{name}")
    return _lazy(name)


def __dir__() -> list[str]:
    return sorted([*globals(), *_LAZY])
