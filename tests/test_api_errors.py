"""Python API errors (issue 22, item 5): a wrong type raises ``TypeError`` naming the function, the
parameter and the expected type; a wrong value or mismatched objects raise a ``UamoptError``
subclass with a one-line what/where/fix; nothing bad is accepted silently."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import PAPER_CASE

import uamopt as ua


@pytest.fixture(scope="module")
def scenario():
    return ua.load_scenario(PAPER_CASE)


@pytest.fixture(scope="module")
def network(scenario):
    from uamopt.grid import AirspaceGrid
    from uamopt.schedule import straight_network

    return dict(straight_network(scenario, AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent)))


@pytest.fixture(scope="module")
def flights(scenario, network):
    return ua.generate_flights(scenario, network, seed=0)


@pytest.fixture(scope="module")
def small_problem(network):
    small = ua.load_scenario(PAPER_CASE, ["schedule.flights=30"])
    return ua.build_problem(ua.generate_flights(small, network, seed=0), small)


def one_line(exc: ua.UamoptError) -> None:
    assert "\n" not in exc.line() and exc.where and exc.fix


def test_verify_schedule_of_another_problem(scenario, flights, small_problem):
    """Was: ValueError 'operands could not be broadcast together with shapes (120,) (30,)'."""
    problem = ua.build_problem(flights, scenario)
    with pytest.raises(ua.UamoptError, match="another problem") as info:
        ua.verify(problem, ua.solve(small_problem, "greedy"))
    one_line(info.value)


@pytest.mark.parametrize("cell", [(0, 50, 30), (50, -1, 30), (50, 50, math.nan)])
def test_build_grid_bad_cell(cell):
    """Was: ZeroDivisionError (a zero cell); a negative or NaN cell gave an empty or broken grid."""
    with pytest.raises(ua.GridError, match="cell") as info:
        ua.build_grid((1000, 1000, 300), cell)
    one_line(info.value)


def test_plan_network_of_a_scenario(scenario):
    """Was: AttributeError "'Scenario' object has no attribute 'scenario'"."""
    with pytest.raises(TypeError, match=r"plan_network\(\): model must be a PlanningModel, got Scenario"):
        ua.plan_network(scenario)


def test_load_scenario_none_overrides_means_none():
    assert ua.load_scenario(PAPER_CASE, None) == ua.load_scenario(PAPER_CASE)


def test_planning_model_field_of_another_scenario(scenario):
    """Was accepted silently: a risk field on another scenario's grid."""
    coarse = ua.compute_risk(ua.load_scenario(PAPER_CASE, ["grid.cell=[100,100,60]"]))
    with pytest.raises(ua.UamoptError, match="another scenario") as info:
        ua.planning_model(scenario, coarse)
    one_line(info.value)


def test_generate_flights_fractional_seed(scenario, network):
    """Was accepted silently: seed=1.5 truncated to 1."""
    with pytest.raises(ua.UamoptError, match="seed"):
        ua.generate_flights(scenario, network, seed=1.5)


def test_profile_fractional_seed(small_problem):
    with pytest.raises(ua.UamoptError, match="seed"):
        ua.solve(small_problem, "greedy", seed=1.5)


def test_zero_length_tracks(scenario, network):
    """Was accepted silently: every flight of length 0 m."""
    points = {name: np.array([wp[0], wp[0]]) for name, wp in network.items()}
    with pytest.raises(ua.UamoptError, match="zero length") as info:
        ua.generate_flights(scenario, points, seed=0)
    one_line(info.value)


@pytest.mark.parametrize("weights", [(math.nan, 0.4), (-0.6, 0.4), (0.6, math.inf)])
def test_build_problem_bad_weights(flights, scenario, weights):
    """Was accepted silently: NaN or negative objective weights."""
    with pytest.raises(ua.UamoptError, match="weights") as info:
        ua.build_problem(flights, scenario, weights=weights)
    one_line(info.value)


def test_build_problem_weights_type(flights, scenario):
    with pytest.raises(TypeError, match=r"build_problem\(\): weights"):
        ua.build_problem(flights, scenario, weights="0.6,0.4")


def test_benchmark_no_solvers(small_problem):
    """Was accepted silently: an empty table."""
    with pytest.raises(ua.UamoptError, match="no solver") as info:
        ua.benchmark(small_problem, [], progress=False)
    one_line(info.value)


#: (function, arguments before the bad one, parameter, expected type) for a wrong-typed argument
WRONG_TYPE = [
    ("scenario_grid", (), "scenario", "Scenario"),
    ("compute_risk", (), "scenario", "Scenario"),
    ("planning_model", (), "scenario", "Scenario"),
    ("plan_track", (), "model", "PlanningModel"),
    ("plan_network", (), "model", "PlanningModel"),
    ("generate_flights", (), "scenario", "Scenario"),
    ("build_problem", (), "flights", "FlightSet"),
    ("solve", (), "problem", "SchedulingProblem"),
    ("verify", (), "problem", "SchedulingProblem"),
]


@pytest.mark.parametrize("bad", [None, "models/paper_case.toml", 3])
@pytest.mark.parametrize(("name", "before", "parameter", "expected"), WRONG_TYPE)
def test_wrong_type_first_argument(name, before, parameter, expected, bad):
    """Was: AttributeError or TypeError from deep inside ('NoneType' object has no attribute 'grid')."""
    args = (*before, bad, *([None] * 2))[:2] if name in ("planning_model", "generate_flights", "verify") else (*before, bad)
    with pytest.raises(TypeError, match=rf"{name}\(\): {parameter} must be an? {expected}, got {type(bad).__name__}"):
        getattr(ua, name)(*args)


@pytest.mark.parametrize("bad", ["no", 0, None])
def test_compute_risk_keep_risk_type(scenario, bad):
    """A truthy string would have kept the terms: "no" must be refused, not read as True."""
    with pytest.raises(TypeError, match=rf"compute_risk\(\): keep_risk must be a bool, got {type(bad).__name__}"):
        ua.compute_risk(scenario, keep_risk=bad)


def test_planning_model_field_type(scenario):
    with pytest.raises(TypeError, match=r"planning_model\(\): field must be a RiskField, got str"):
        ua.planning_model(scenario, "risk.npz")


def test_verify_schedule_type(small_problem):
    with pytest.raises(TypeError, match=r"verify\(\): schedule must be a Schedule, got NoneType"):
        ua.verify(small_problem, None)


PATH_FUNCTIONS = ["load_scenario", "load_risk", "load_tracks", "load_network", "load_flights", "load_schedule",
                  "load_sweep", "sweep", "read_airland"]


@pytest.mark.parametrize("bad", [None, 3])
@pytest.mark.parametrize("name", PATH_FUNCTIONS)
def test_wrong_type_path(name, bad):
    """Was: TypeError 'expected str, bytes or os.PathLike object, not NoneType', naming no function."""
    with pytest.raises(TypeError, match=rf"{name}\(\): path must be a str or os.PathLike \(a path\), got {type(bad).__name__}"):
        getattr(ua, name)(bad)


@pytest.mark.parametrize("bad", [None, 3])
def test_benchmark_wrong_type(bad):
    """Was: UamoptError 'cannot benchmark a NoneType' (a wrong type, so TypeError)."""
    with pytest.raises(TypeError, match=rf"benchmark\(\): problem_or_scenarios must be .*got {type(bad).__name__}"):
        ua.benchmark(bad, ["greedy"], progress=False)


@pytest.mark.parametrize("bad", [None, "results.parquet", 3])
def test_plot_sweep_wrong_type(bad):
    """Was: AttributeError "'NoneType' object has no attribute 'columns'"."""
    with pytest.raises(TypeError, match=rf"plot_sweep\(\): table must be a DataFrame, got {type(bad).__name__}"):
        ua.plot_sweep(bad)


# --- the second pass (each was accepted silently or ended in a raw exception on 31937a6) -----------


def test_planning_model_field_of_a_scenario_with_other_risk_settings(scenario):
    """Same name and cells, other [risk] settings: the field's summary digests tell them apart."""
    other = ua.load_scenario(PAPER_CASE, ["risk.weights=[0.2,0.3,0.5]"])
    field = ua.compute_risk(other)
    with pytest.raises(ua.UamoptError, match=r"another scenario: its \[risk\] settings differ") as info:
        ua.planning_model(scenario, field)
    one_line(info.value)


def test_a_saved_field_of_other_settings_is_recognised_after_loading(scenario, tmp_path):
    """The digests travel through summary.json: a field written and read back is still recognised."""
    from uamopt.io import save_risk

    other = ua.load_scenario(PAPER_CASE, ["aircraft.empty_mass_kg=350"])
    save_risk(ua.compute_risk(other), tmp_path / "risk")
    loaded = ua.load_risk(tmp_path / "risk")
    with pytest.raises(ua.UamoptError, match=r"\[aircraft\] settings differ"):
        ua.planning_model(scenario, loaded)
    ua.planning_model(other, loaded)  # its own scenario still plans


@pytest.mark.parametrize("bad", [3, None, 2.5])
def test_solver_profile_wrong_type(bad):
    """Was: a raw AttributeError/TypeError from deep in load_profile."""
    with pytest.raises(TypeError, match=r"solver_profile\(\): profile must be"):
        ua.solver_profile(bad)


def test_solve_with_a_profile_of_the_wrong_type(small_problem):
    with pytest.raises(TypeError, match="profile must be"):
        ua.solve(small_problem, 3)


def test_build_problem_zero_weights(flights, scenario):
    """Was accepted silently: (0, 0) makes every schedule cost 0."""
    with pytest.raises(ua.UamoptError, match="not both 0") as info:
        ua.build_problem(flights, scenario, weights=(0.0, 0.0))
    one_line(info.value)


@pytest.mark.parametrize(("key", "value"), [("risk.weights", "[0,0,0]"), ("tracks.weights", "[0,0]"),
                                        ("schedule.weights", "[0.0,0.0]")])
def test_all_zero_scenario_weights_are_refused(key, value):
    with pytest.raises(ua.ScenarioError, match="weights are all 0") as info:
        ua.load_scenario(PAPER_CASE, [f"{key}={value}"])
    one_line(info.value)
