"""The pipeline's stages as plain functions a notebook can call one by one (PyPSA's pattern):
scenario → city layers → grid → risk field. Later stages (tracks, schedules) append here."""

from __future__ import annotations

import time
from dataclasses import dataclass

from uamopt.city import CityLayers, load_city
from uamopt.grid import AirspaceGrid, build_grid
from uamopt.risk import RiskField, risk_field
from uamopt.scenario import Scenario


@dataclass(frozen=True)
class RiskRun:
    """The risk stage's result with its timings (seconds)."""

    scenario: Scenario
    grid: AirspaceGrid
    city: CityLayers
    field: RiskField
    seconds: dict


def compute_risk(scenario: Scenario) -> RiskRun:
    """Build the grid and city layers, then the risk field, timing each step."""
    t0 = time.perf_counter()
    grid = build_grid(scenario)
    city = load_city(scenario, grid)
    t1 = time.perf_counter()
    field = risk_field(scenario, grid, city)
    t2 = time.perf_counter()
    return RiskRun(scenario, grid, city, field, {"city": t1 - t0, "risk": t2 - t1, "total": t2 - t0})


def risk_summary(run: RiskRun) -> dict:
    """Cell counts, unsafe shares, risk statistics and timings (:meth:`RiskField.summary`)."""
    return run.field.summary(run.seconds)
