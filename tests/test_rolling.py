"""The rolling-horizon solver (uamopt/solvers/rolling.py) on the paper case: a feasible schedule,
a valid lower bound, never better than the exact optimum, reproducible.

``rolling`` may not be in ``SOLVERS`` yet, so the module is called directly with a profile that
names a registered solver (the profile's ``solver`` field is not read by ``rolling.solve``).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import PAPER_CASE

from uamopt.grid import AirspaceGrid
from uamopt.scenario import load_scenario
from uamopt.schedule import (
    build_problem,
    evaluate,
    generate_plan,
    straight_network,
    violations,
)
from uamopt.solvers import SolverProfile, milp, rolling

OBJ_TOL = 1e-6


@pytest.fixture(scope="module")
def paper_problem():
    scenario = load_scenario(PAPER_CASE)
    grid = AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent)
    return build_problem(generate_plan(scenario, straight_network(scenario, grid), 0), scenario)


def profile(**options) -> SolverProfile:
    return SolverProfile("cpsat", time_limit_s=20.0, threads=1, seed=0, options={"window_s": 900.0, **options})


def test_rolling_paper_case(paper_problem):
    problem = paper_problem
    first = rolling.solve(problem, profile())
    exact = milp.solve(problem, SolverProfile("highs", time_limit_s=30.0, threads=2))
    assert exact.status == "optimal"
    assert first.status in ("feasible", "time_limit") and first.solver == "rolling"
    assert violations(problem, first.operated, first.delay_s) == []
    assert first.objective == pytest.approx(evaluate(problem, first.operated, first.delay_s), abs=1e-12)
    assert first.bound is not None and first.bound <= exact.objective + OBJ_TOL <= first.objective + 2 * OBJ_TOL
    assert first.extras["windows"] > 1
    again = rolling.solve(problem, profile())
    assert np.array_equal(again.operated, first.operated) and np.array_equal(again.delay_s, first.delay_s)
    assert again.objective == first.objective


def test_rolling_highs_inner_and_bound(paper_problem):
    problem = paper_problem
    s = rolling.solve(problem, profile(inner="highs", window_s=1200.0))
    assert violations(problem, s.operated, s.delay_s) == []
    assert s.bound <= s.objective
    # the bound is at least the trivial one (every flight operated on time)
    assert s.bound >= -problem.weights[1] * problem.n_flights


def test_rolling_rejects_unknown_option(paper_problem):
    from uamopt.errors import UamoptError

    with pytest.raises(UamoptError):
        rolling.solve(paper_problem, profile(bogus=1))
    with pytest.raises(UamoptError):
        rolling.solve(paper_problem, profile(inner="ga"))
