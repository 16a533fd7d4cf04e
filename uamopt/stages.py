"""The risk stage bundled with its grid, city layers and timings (``RiskRun``), for the tests and
benchmarks that want all of them; the public stages live in :mod:`uamopt.pipeline`."""

from __future__ import annotations

from dataclasses import dataclass

from uamopt.city import CityLayers
from uamopt.grid import AirspaceGrid
from uamopt.risk import RiskField
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
    """The risk stage with its grid, city and timings (:func:`uamopt.pipeline.compute_risk`)."""
    from uamopt.pipeline import compute_risk as risk

    field = risk(scenario)
    return RiskRun(scenario, field.grid, field.city, field, dict(field.meta["seconds"]))


def risk_summary(run: RiskRun) -> dict:
    """Cell counts, unsafe shares, risk statistics and timings (:meth:`RiskField.summary`)."""
    return run.field.summary(run.seconds)
