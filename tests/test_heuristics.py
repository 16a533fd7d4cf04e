"""The heuristic solvers: greedy (Sec. 5.2.1), ga and soa (Sec. 5.2.2), and the calibrated paper plan."""

from __future__ import annotations

import numpy as np
import pytest
from checks import OBJ_TOL, assert_verified
from hypothesis import given, settings, strategies as st
from instances import crossing_problem
from oracles import objective

from uamopt.errors import UamoptError
from uamopt.schedule import Flight, FlightSet, build_problem, violations
from uamopt.schedule.calibration import paper_case_plan
from uamopt.solvers import SolverProfile, bruteforce, solve
from uamopt.solvers.genetic import fitness, objective_values
from uamopt.solvers.greedy import CANCEL, decoder_for, greedy_decisions
from uamopt.solvers.rolling import pair_matching_bound

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


@pytest.mark.parametrize(("options", "delays"), [
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
    assert schedule.cancelled_count == 2 and schedule.total_delay_s == 0.0
    # exactly to the gap end, 4 s fits in the 8 s threshold
    exact = solve(problem, SolverProfile("greedy", options={"exact_gaps": True}))
    assert exact.operated.all() and exact.delay_s.tolist() == pytest.approx([0.0, 4.0, 4.0])


# (objective, weights, W of greedy, W of the best schedule on the 10 s grid, W of the optimum):
# weighted (ω6, ω7) = (0.1, 0.9), G = 3: −0.9·1;  0.1·10/3 − 0.9·3;  0.1·6/3 − 0.9·3
# lexicographic, ΣU = 400: −1;  −3 + 10/401;  −3 + 6/401
CROSSING = [
    ("weighted", (0.1, 0.9), -0.9, 0.1 * 10 / 3 - 2.7, 0.1 * 6 / 3 - 2.7),
    ("lexicographic", (0.6, 0.4), -1.0, -3 + 10 / 401, -3 + 6 / 401),
]


@pytest.mark.parametrize(("objective", "weights", "w_greedy", "w_grid", "w_optimum"), CROSSING)
def test_genetic_beats_greedy_where_greedy_is_suboptimal(objective, weights, w_greedy, w_grid, w_optimum):
    problem = crossing_problem(objective, weights)
    np.testing.assert_allclose([c.intervals[0] for c in problem.conflicts], [[-4.0, 8.0], [4.0, 15.0]])
    greedy = solve(problem, SolverProfile("greedy"))
    assert greedy.operated.tolist() == [True, False, False] and greedy.objective == pytest.approx(w_greedy)
    optimum = bruteforce.solve(problem)
    assert optimum.objective == pytest.approx(w_optimum) and optimum.delay_s.tolist() == pytest.approx([6.0, 0.0, 0.0])
    for solver in ("ga", "soa"):
        for seed in (0, 1, 2):  # Table B.3's population 50 and l = 200 generations: ~0.15 s each here
            result = solve(problem, SolverProfile(solver, seed=seed))
            # all three operated, A1 delayed one ΔT_a step: better than greedy by two flights less the delay
            assert result.operated.all() and result.delay_s.tolist() == [10.0, 0.0, 0.0], (solver, seed)
            assert result.objective == pytest.approx(w_grid) and result.objective <= w_greedy - 1.0
            assert_verified(problem, result)


SHORT = {"generations": 40}


@pytest.fixture(scope="module")
def paper_results(calibrated_problem):
    return {
        "greedy": solve(calibrated_problem, SolverProfile("greedy")),
        "greedy_exact": solve(calibrated_problem, SolverProfile("greedy", options={"exact_gaps": True})),
        "ga": solve(calibrated_problem, SolverProfile("ga", seed=3, options=SHORT)),
        "soa": solve(calibrated_problem, SolverProfile("soa", seed=3, options=SHORT)),
        "soa_exact": solve(calibrated_problem, SolverProfile("soa", seed=3, options=SHORT | {"exact_gaps": True})),
    }


# Regression values, not the paper's (Table 3 has 109 / 11 / 2401 s on its own, unpublished plan):
# what this code's preliminary strategy gave on the calibrated plan, seed 0, when the calibration
# was chosen (uamopt/schedule/calibration.py). A change here means the plan or greedy changed.
REGRESSION_GREEDY_SEED0 = (104, 16, 2260.0)  # operated, cancelled, total delay (s)


def test_calibrated_paper_plan_greedy_regression(paper_results):
    greedy = paper_results["greedy"]
    assert (greedy.operated_count, greedy.cancelled_count, greedy.total_delay_s) == REGRESSION_GREEDY_SEED0
    assert np.all(np.mod(greedy.delay_s, 10.0) == 0.0)  # whole ΔT_a steps


@pytest.mark.parametrize("name", ["greedy", "greedy_exact", "ga", "soa", "soa_exact"])
def test_every_heuristic_passes_model_and_verifier(calibrated_problem, paper_results, name):
    schedule = paper_results[name]
    assert schedule.status == "feasible" and schedule.bound is None and schedule.gap is None
    assert violations(calibrated_problem, schedule.operated, schedule.delay_s) == []
    assert_verified(calibrated_problem, schedule)
    # no heuristic can beat a valid lower bound of the optimum (uamopt/solvers/rolling.py)
    assert schedule.objective >= pair_matching_bound(calibrated_problem) - OBJ_TOL


@pytest.mark.parametrize("solver", ["ga", "soa"])
def test_same_seed_same_result(calibrated_problem, paper_results, solver):
    again = solve(calibrated_problem, SolverProfile(solver, seed=3, options=SHORT))
    first = paper_results[solver]
    assert np.array_equal(again.operated, first.operated) and np.array_equal(again.delay_s, first.delay_s)
    other = solve(calibrated_problem, SolverProfile(solver, seed=4, options=SHORT))
    assert other.extras["history"] != first.extras["history"]


@pytest.mark.parametrize("solver", ["ga", "soa"])
def test_time_limit_is_honoured(calibrated_problem, solver):
    # 3 s: at load 13 a 0.2 s limit ended before the first generation
    result = solve(calibrated_problem, SolverProfile(solver, time_limit_s=3.0, options={"generations": 1_000_000}))
    assert result.status == "time_limit"  # stopped by the clock, long before its generations ran out:
    assert 0 < result.extras["generations"] < 1_000_000
    assert violations(calibrated_problem, result.operated, result.delay_s) == []


def test_soa_stops_when_cold(calibrated_problem):
    # T = T_0 ξ^l: 1, 0.5, 0.25, 0.125, then 0.0625 < T_F = 0.1 -> four generations
    result = solve(calibrated_problem, SolverProfile("soa", options={"t0": 1.0, "xi": 0.5, "t_final": 0.1}))
    assert result.status == "feasible" and result.extras["generations"] == 4


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), cancel=st.floats(0.0, 0.3), dense=st.floats(0.0, 1.0))
def test_any_chromosome_decodes_feasibly(calibrated_problem, seed, cancel, dense):
    rng = np.random.default_rng(seed)
    n = calibrated_problem.n_flights
    top = np.floor(calibrated_problem.delay_upper_s / 10.0).astype(np.int64)
    genes = np.where(rng.random((8, n)) < dense, rng.integers(0, top + 1, size=(8, n)), 0)
    genes = np.where(rng.random((8, n)) < cancel, CANCEL, genes)
    operated, delay = decoder_for(calibrated_problem).decode(calibrated_problem, genes)
    w = objective_values(calibrated_problem, operated, delay)
    for i in range(len(genes)):
        assert violations(calibrated_problem, operated[i], delay[i]) == []
        assert w[i] == pytest.approx(objective(operated[i], delay[i], calibrated_problem.weights,
                                               calibrated_problem.aircraft_count))
        assert not operated[i][genes[i] == CANCEL].any()


def test_a_feasible_schedule_decodes_from_its_own_delays(paper_results, calibrated_problem):
    """Every feasible schedule on the ΔT_a grid is reachable: its delays, as genes, decode to itself."""
    best = paper_results["soa"]
    genes = np.where(best.operated, np.round(best.delay_s / 10.0), CANCEL).astype(np.int64)
    operated, delay = decoder_for(calibrated_problem).decode(calibrated_problem, genes)
    assert np.array_equal(operated[0], best.operated) and np.array_equal(delay[0], best.delay_s)


def test_fitness_eq36():
    np.testing.assert_allclose(fitness(np.array([3.0, 1.0, 2.0])), [0.0, 1.0, 0.5])
    np.testing.assert_allclose(fitness(np.array([2.0, 2.0])), [1.0, 1.0])


@pytest.mark.parametrize(("solver", "options", "match"), [
    ("greedy", {"step": 10}, "unknown option 'step'"),
    ("greedy", {"step_s": 0}, r"option step_s must be a number in \[0.001, 1e\+07\], got 0"),
    ("soa", {"xi": 1.5}, r"option xi must be a number in \(0, 1\], got 1.5"),
    ("ga", {"population": 2.5}, "option population must be int"),
])
def test_bad_options_are_one_line_errors(calibrated_problem, solver, options, match):
    with pytest.raises(UamoptError, match=match):
        solve(calibrated_problem, SolverProfile(solver, options=options))


def test_paper_case_plan_scales_only_the_delay_threshold(paper_straight_plan):
    scenario, _, network, _ = paper_straight_plan
    full, tight = paper_case_plan(scenario, network, max_delay_scale=1.0), paper_case_plan(scenario, network)
    np.testing.assert_array_equal(full.planned_departure_s, tight.planned_departure_s)
    np.testing.assert_array_equal(tight.max_delay_s, np.floor(0.3 * full.max_delay_s + 0.5))  # Eq. 29, ≤
    assert len(tight) == 120 and tight.n_aircraft == 20
    with pytest.raises(UamoptError, match="max_delay_scale"):
        paper_case_plan(scenario, network, max_delay_scale=1.5)
