"""Shared fixtures: the repository root and the paper-case stages, each computed once per session."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

pytest.register_assert_rewrite("checks", "oracles")

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
def paper_model(paper_run):
    """The planning model (admissible cells, costs, buffer) of the paper case at 50 × 50 × 30 m."""
    from uamopt.planning import planning_model

    return planning_model(paper_run.scenario, paper_run.field)


@pytest.fixture(scope="session")
def coarse_run():
    """The paper case at 100 × 100 × 60 m cells: small enough for graph and figure tests."""
    from uamopt.scenario import load_scenario
    from uamopt.stages import compute_risk

    return compute_risk(load_scenario(PAPER_CASE, ["grid.cell=[100,100,60]"]))


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


@pytest.fixture(scope="session")
def paper_schedule_dir(tmp_path_factory) -> Path:
    """A schedule folder of the paper case (highs, planned network) written by ``uamopt schedule``.

    Read-only for tests: copy it before changing anything in it.
    """
    from uamopt.cli import main

    out = tmp_path_factory.mktemp("paper_schedule") / "highs"
    assert main(["schedule", str(PAPER_CASE), "--solver", "highs", "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="session")
def paper_export(paper_schedule_dir, tmp_path_factory):
    """``paper_export(kind)``: a fresh copy of ``paper_schedule_dir`` after ``uamopt export KIND``."""
    import shutil

    from uamopt.cli import main

    def export(kind: str) -> Path:
        folder = tmp_path_factory.mktemp(kind) / "highs"
        shutil.copytree(paper_schedule_dir, folder)
        assert main(["export", kind, str(folder)]) == 0
        return folder

    return export


@pytest.fixture(scope="session")
def paper_problem(paper_straight_plan):
    """The scheduling model of the generated paper-case plan (120 flights, seed 0, straight tracks)."""
    from uamopt.schedule import build_problem

    scenario, _, _, flights = paper_straight_plan
    return build_problem(flights, scenario)


@pytest.fixture(scope="session")
def calibrated_problem(paper_straight_plan):
    """The scheduling model of the calibrated paper-case plan (uamopt/solvers/calibration.py)."""
    from uamopt.schedule import build_problem
    from uamopt.solvers.calibration import paper_case_plan

    scenario, _, network, _ = paper_straight_plan
    return build_problem(paper_case_plan(scenario, network, seed=0), scenario)


@pytest.fixture(scope="session")
def paper_highs(paper_problem):
    """HiGHS's proven optimum of ``paper_problem`` (a few seconds; solved once per session)."""
    from uamopt.solvers import SolverProfile, milp

    return milp.solve(paper_problem, SolverProfile("highs", time_limit_s=30.0, threads=2))
