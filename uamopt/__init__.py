"""uamopt: Urban Air Mobility operations research toolkit.

Data flows one way (STYLE.md): scenario → city layers → airspace grid → risk field → graph →
tracks → flight plan → schedule. Each stage is importable on its own from a notebook::

    from uamopt import load_scenario, build_grid, load_city, risk_field
    scenario = load_scenario("models/paper_case.toml")
    grid = build_grid(scenario)
    city = load_city(scenario, grid)
    field = risk_field(scenario, grid, city)
"""

from uamopt.errors import (
    GridError,
    InfeasibleScheduleError,
    InputFileError,
    NoTrackError,
    ScenarioError,
    UamoptError,
)
from uamopt.scenario import Scenario, load_scenario
from uamopt.grid import AirspaceGrid, build_grid
from uamopt.city import CityLayers, load_city
from uamopt.risk import RiskField, risk_field
from uamopt.experiments import benchmark, sweep

__all__ = [
    "AirspaceGrid",
    "CityLayers",
    "GridError",
    "InfeasibleScheduleError",
    "InputFileError",
    "NoTrackError",
    "RiskField",
    "Scenario",
    "ScenarioError",
    "UamoptError",
    "benchmark",
    "build_grid",
    "load_city",
    "load_scenario",
    "risk_field",
    "sweep",
]
__version__ = "0.1.0"
