"""Shared fixtures: the repository root and small scenarios computed once per session."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAPER_CASE = ROOT / "models" / "paper_case.toml"

os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def paper_run():
    """The paper case at its default 50 × 50 × 30 m cells."""
    from uamopt.scenario import load_scenario
    from uamopt.stages import compute_risk

    return compute_risk(load_scenario(PAPER_CASE))


@pytest.fixture(scope="session")
def paper_straight_plan():
    """(scenario, grid, straight network, generated plan) of the paper case, seed 0, with Eq. 29
    taken with equality (max_delay_scale = 1, not the calibrated 0.3)."""
    from uamopt.grid import AirspaceGrid
    from uamopt.scenario import load_scenario
    from uamopt.schedule import generate_plan, straight_network

    scenario = load_scenario(PAPER_CASE)
    grid = AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent)
    network = straight_network(scenario, grid)
    return scenario, grid, network, generate_plan(scenario, network, seed=0, max_delay_scale=1.0)
