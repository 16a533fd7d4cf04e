"""The heuristic solvers: greedy (Sec. 5.2.1), ga and soa (Sec. 5.2.2), and the calibrated paper plan."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import PAPER_CASE
from hypothesis import given, settings
from hypothesis import strategies as st

from uamopt.errors import UamoptError
from uamopt.grid import AirspaceGrid
from uamopt.scenario import load_scenario
from uamopt.schedule import (
    Flight,
    FlightSet,
    build_problem,
    evaluate,
    straight_network,
    violations,
    write_schedule,
)
from uamopt.schedule.verify import verify_dir
from uamopt.solvers import SolverProfile, solve
from uamopt.solvers.calibration import paper_case_plan
from uamopt.solvers.genetic import fitness, objective_values
from uamopt.solvers.greedy import CANCEL, decoder_for, greedy_decisions

EAST = np.array([[25.0, 25.0, 45.0], [525.0, 25.0, 45.0]])  # 500 m along one row of 50 m cells: 20 s at 25 m/s
WEST = np.array([[525.0, 25.0, 105.0], [25.0, 25.0, 105.0]])  # the way back, two layers up (no conflict with EAST)


def _flight(fid, aircraft, track, dep, max_delay=400.0):
    return Flight(id=fid, aircraft=aircraft, route="E" if track is EAST else "W", origin="a", destination="b",
                  speed_mps=25.0, planned_departure_s=dep, max_delay_s=max_delay, waypoints=track)


def _problem(*flights):
    return build_problem(FlightSet(cell=(50.0, 50.0, 30.0), conflict_radius=1, flights=tuple(flights)))


def test_same_route_same_time_forbidden_gap_is_4_s():
    """Same track, same speed, 3×3×3 zone: the follower must be 2 cells (100 m = 4 s) behind."""
    problem = _problem(_flight("A1", "A", EAST, 0.0), _flight("B1", "B", EAST, 0.0))
    (pair,) = list(problem.conflicts)
    np.testing.assert_allclose(pair.intervals, [[-4.0, 4.0]])


@pytest.mark.parametrize("options, delays", [
    ({}, [0.0, 10.0, 20.0]),  # the 4 s gaps rounded up to ΔT_a = 10 s; C clears B (at 10 s) only at 14 s -> 20 s
    ({"step_s": 3.0}, [0.0, 6.0, 12.0]),
    ({"exact_gaps": True}, [0.0, 4.0, 8.0]),
])
def test_greedy_delays_followers_to_the_gap_end(options, delays):
    problem = _problem(*(_flight(f"{g}1", g, EAST, 0.0) for g in "ABC"))
    schedule = solve(problem, SolverProfile("greedy", options=options))
    assert schedule.operated.all() and schedule.status == "feasible" and schedule.bound is None
    np.testing.assert_allclose(schedule.delay_s, delays, atol=1e-9)
    assert violations(problem, schedule.operated, schedule.delay_s) == []


def test_greedy_delay_propagates_through_the_turnaround():
    """B1 delayed 10 s arrives 10 s late, so its return (planned exactly ΔT = T_D after) leaves 10 s late."""
    problem = _problem(_flight("A1", "A", EAST, 0.0), _flight("B1", "B", EAST, 0.0), _flight("B2", "B", WEST, 260.0))
    operated, delay = greedy_decisions(problem)
    assert operated.all()
    np.testing.assert_allclose(delay, [0.0, 10.0, 10.0])


def test_greedy_cancels_beyond_the_threshold_with_its_return():
    # B1 needs 10 s (4 s rounded up to ΔT_a) but may wait only 8 s: cancelled, and B2 with it
    problem = _problem(_flight("A1", "A", EAST, 0.0), _flight("B1", "B", EAST, 0.0, max_delay=8.0),
                       _flight("B2", "B", WEST, 260.0))
    schedule = solve(problem, SolverProfile("greedy"))
    assert schedule.operated.tolist() == [True, False, False]
    assert schedule.cancelled == 2 and schedule.total_delay_s == 0.0
    # exactly to the gap end, 4 s fits in the 8 s threshold
    exact = solve(problem, SolverProfile("greedy", options={"exact_gaps": True}))
    assert exact.operated.all() and exact.delay_s.tolist() == pytest.approx([0.0, 4.0, 4.0])


def test_genetic_on_a_small_instance_beats_or_matches_greedy():
    problem = _problem(*(_flight(f"{g}1", g, EAST, 0.0) for g in "ABCD"))
    greedy = solve(problem, SolverProfile("greedy"))
    for solver in ("ga", "soa"):
        result = solve(problem, SolverProfile(solver, options={"generations": 20, "population": 10}))
        assert result.objective <= greedy.objective + 1e-12
        assert violations(problem, result.operated, result.delay_s) == []


@pytest.fixture(scope="module")
def paper_problem():
    scenario = load_scenario(PAPER_CASE)
    grid = AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent)
    return build_problem(paper_case_plan(scenario, straight_network(scenario, grid), seed=0), scenario)


SHORT = {"generations": 40}


@pytest.fixture(scope="module")
def paper_results(paper_problem):
    return {
        "greedy": solve(paper_problem, SolverProfile("greedy")),
        "greedy_exact": solve(paper_problem, SolverProfile("greedy", options={"exact_gaps": True})),
        "ga": solve(paper_problem, SolverProfile("ga", seed=3, options=SHORT)),
        "soa": solve(paper_problem, SolverProfile("soa", seed=3, options=SHORT)),
        "soa_exact": solve(paper_problem, SolverProfile("soa", seed=3, options=SHORT | {"exact_gaps": True})),
    }


def test_calibrated_paper_plan_greedy_figures(paper_results):
    """The calibration (uamopt/solvers/calibration.py): seed 0 gives 104 operated, 16 cancelled, 2260 s."""
    greedy = paper_results["greedy"]
    assert (greedy.operated_count, greedy.cancelled, greedy.total_delay_s) == (104, 16, 2260.0)
    assert np.all(np.mod(greedy.delay_s, 10.0) == 0.0)  # whole ΔT_a steps


@pytest.mark.parametrize("name", ["greedy", "greedy_exact", "ga", "soa", "soa_exact"])
def test_every_heuristic_passes_model_and_verifier(paper_problem, paper_results, tmp_path, name):
    schedule = paper_results[name]
    assert schedule.status == "feasible" and schedule.bound is None and schedule.gap is None
    assert violations(paper_problem, schedule.operated, schedule.delay_s) == []
    assert schedule.objective == pytest.approx(evaluate(paper_problem, schedule.operated, schedule.delay_s))
    write_schedule(tmp_path / name, paper_problem, schedule)
    assert verify_dir(tmp_path / name) == []


@pytest.mark.parametrize("solver", ["ga", "soa"])
def test_genetic_at_least_as_good_as_its_greedy_seed(paper_results, solver):
    greedy, result = paper_results["greedy"], paper_results[solver]
    assert result.extras["greedy_objective"] == pytest.approx(greedy.objective)
    assert result.objective <= greedy.objective
    history = result.extras["history"]
    assert len(history) == SHORT["generations"] + 1 and all(np.diff(history) <= 0)


@pytest.mark.parametrize("solver", ["ga", "soa"])
def test_same_seed_same_result(paper_problem, paper_results, solver):
    again = solve(paper_problem, SolverProfile(solver, seed=3, options=SHORT))
    first = paper_results[solver]
    assert np.array_equal(again.operated, first.operated) and np.array_equal(again.delay_s, first.delay_s)
    other = solve(paper_problem, SolverProfile(solver, seed=4, options=SHORT))
    assert other.extras["history"] != first.extras["history"]


@pytest.mark.parametrize("solver", ["ga", "soa"])
def test_time_limit_is_honoured(paper_problem, solver):
    result = solve(paper_problem, SolverProfile(solver, time_limit_s=0.2, options={"generations": 1_000_000}))
    assert result.status == "time_limit" and result.solve_seconds < 1.5
    assert 0 < result.extras["generations"] < 1_000_000
    assert violations(paper_problem, result.operated, result.delay_s) == []


def test_soa_stops_when_cold(paper_problem):
    # T = T_0 ξ^l: 1, 0.5, 0.25, 0.125, then 0.0625 < T_F = 0.1 -> four generations
    result = solve(paper_problem, SolverProfile("soa", options={"t0": 1.0, "xi": 0.5, "t_final": 0.1}))
    assert result.status == "feasible" and result.extras["generations"] == 4


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), cancel=st.floats(0.0, 0.3), dense=st.floats(0.0, 1.0))
def test_any_chromosome_decodes_feasibly(paper_problem, seed, cancel, dense):
    rng = np.random.default_rng(seed)
    n = paper_problem.n_flights
    top = np.floor(paper_problem.delay_upper_s / 10.0).astype(np.int64)
    genes = np.where(rng.random((8, n)) < dense, rng.integers(0, top + 1, size=(8, n)), 0)
    genes = np.where(rng.random((8, n)) < cancel, CANCEL, genes)
    operated, delay = decoder_for(paper_problem).decode(paper_problem, genes)
    w = objective_values(paper_problem, operated, delay)
    for i in range(len(genes)):
        assert violations(paper_problem, operated[i], delay[i]) == []
        assert w[i] == pytest.approx(evaluate(paper_problem, operated[i], delay[i]))
        assert not operated[i][genes[i] == CANCEL].any()


def test_a_feasible_schedule_decodes_from_its_own_delays(paper_results, paper_problem):
    """Every feasible schedule on the ΔT_a grid is reachable: its delays, as genes, decode to itself."""
    best = paper_results["soa"]
    genes = np.where(best.operated, np.round(best.delay_s / 10.0), CANCEL).astype(np.int64)
    operated, delay = decoder_for(paper_problem).decode(paper_problem, genes)
    assert np.array_equal(operated[0], best.operated) and np.array_equal(delay[0], best.delay_s)


def test_fitness_eq36():
    np.testing.assert_allclose(fitness(np.array([3.0, 1.0, 2.0])), [0.0, 1.0, 0.5])
    np.testing.assert_allclose(fitness(np.array([2.0, 2.0])), [1.0, 1.0])


@pytest.mark.parametrize("solver, options, match", [
    ("greedy", {"step": 10}, "unknown option 'step'"),
    ("greedy", {"step_s": 0}, "step_s must be positive"),
    ("soa", {"xi": 1.5}, "option xi = 1.5 out of range"),
    ("ga", {"population": 2.5}, "option population must be int"),
])
def test_bad_options_are_one_line_errors(paper_problem, solver, options, match):
    with pytest.raises(UamoptError, match=match):
        solve(paper_problem, SolverProfile(solver, options=options))


def test_paper_case_plan_scales_only_the_delay_threshold():
    scenario = load_scenario(PAPER_CASE)
    network = straight_network(scenario, AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent))
    full, tight = paper_case_plan(scenario, network, max_delay_scale=1.0), paper_case_plan(scenario, network)
    np.testing.assert_array_equal(full.planned_departure_s, tight.planned_departure_s)
    np.testing.assert_array_equal(tight.max_delay_s, np.floor(0.3 * full.max_delay_s + 0.5))  # Eq. 29, ≤
    assert len(tight) == 120 and tight.n_aircraft == 20
    with pytest.raises(UamoptError, match="max_delay_scale"):
        paper_case_plan(scenario, network, max_delay_scale=1.5)
