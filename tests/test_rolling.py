"""The rolling-horizon solver (uamopt/solvers/rolling.py): a feasible schedule (verifier, objective
recomputed from the files), a valid lower bound (never above the proven optimum), never better
than the exact optimum, reproducible; through the registry (``solve(p, "rolling")``) and directly.
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from checks import OBJ_TOL, assert_verified
from hypothesis import HealthCheck, given, settings
from strategies import tiny_problems

from uamopt.errors import UamoptError
from uamopt.schedule import Flight, FlightSet, build_problem, generate_plan, violations
from uamopt.solvers import SolverProfile, bruteforce, load_profile, milp, rolling, solve
from uamopt.solvers.rolling import pair_matching_bound


def profile(**options) -> SolverProfile:
    return SolverProfile("rolling", time_limit_s=20.0, threads=1, seed=0, options={"window_s": 900.0, **options})


@pytest.fixture(scope="module")
def paper_optimum(paper_highs):
    assert paper_highs.status == "optimal"
    return paper_highs.objective


def windows_of(problem, window_s: float) -> int:
    """The non-empty windows of ``window_s`` seconds of planned departure, counted from the first
    (the rolling.py docstring), by hand from the flights."""
    departures = [f.planned_departure_s for f in problem.flights.flights]
    return len({math.floor((d - min(departures)) / window_s) for d in departures})


def test_rolling_paper_case(paper_problem, paper_optimum):
    """The paper case in its 900 s windows, each given 30 s: every window's CP-SAT solve proves its
    optimum (about 0.3 s each, a hundredfold margin), so the status is ``feasible`` (a schedule with
    a valid bound, never ``optimal``: the windows are not the whole day), with no greedy fallback and
    no swap for the warm start."""
    problem = paper_problem
    first = rolling.solve(problem, profile(window_time_limit_s=30.0))
    assert first.status == "feasible" and first.solver == "rolling"
    assert first.extras["windows"] == windows_of(problem, 900.0) == first.extras["proved"]
    assert first.extras["unproved"] == first.extras["greedy_windows"] == first.extras["cancelled_windows"] == 0
    assert "incumbent" not in first.extras and "fallback" not in first.extras and "windows_past_limit" not in first.extras
    assert violations(problem, first.operated, first.delay_s) == []
    assert_verified(problem, first)
    assert first.bound <= paper_optimum + OBJ_TOL <= first.objective + 2 * OBJ_TOL
    assert first.extras["windows"] > 1
    again = rolling.solve(problem, profile(window_time_limit_s=30.0))
    assert np.array_equal(again.operated, first.operated) and np.array_equal(again.delay_s, first.delay_s)
    assert again.objective == first.objective


def test_rolling_highs_inner_and_bound(paper_problem, paper_optimum):
    s = rolling.solve(paper_problem, profile(inner="highs", window_s=1200.0))
    assert_verified(paper_problem, s)
    assert s.bound <= paper_optimum + OBJ_TOL <= s.objective + 2 * OBJ_TOL


def test_solve_by_name_uses_the_shipped_profile(paper_straight_plan, root):
    """``solve(problem, "rolling")`` reads solvers/rolling.toml: the expectations come from that file,
    read here with tomllib (window_s → the number of windows, counted from the flights; inner;
    time_limit_s / windows → each window's limit; seed), not from uamopt's profile loader. On 6
    aircraft (36 flights) its windows cost it against the whole-day optimum, and its bound is valid."""
    shipped = tomllib.loads((root / "solvers" / "rolling.toml").read_text(encoding="utf-8"))
    scenario, _, network, _ = paper_straight_plan
    problem = build_problem(generate_plan(scenario, network, seed=0, aircraft=6, max_delay_scale=1.0), scenario)
    s = solve(problem, "rolling")
    exact = milp.solve(problem, SolverProfile("highs", time_limit_s=30.0, threads=2))
    windows = windows_of(problem, shipped["options"]["window_s"])
    assert s.solver == "rolling" and exact.status == "optimal" and windows > 1
    assert s.extras["windows"] == windows and s.extras["inner"] == shipped["options"]["inner"]
    # the watched child gets the limit less its own start (the forkserver's first start, seconds at load 8)
    assert s.extras["window_time_limit_s"] == pytest.approx(shipped["time_limit_s"] / windows, rel=0.1)
    assert s.extras["window_time_limit_s"] <= shipped["time_limit_s"] / windows and s.seed == shipped["seed"]
    # the options the file sets are also the solver's defaults (900 s, cpsat): what the loader read of them
    loaded = load_profile("rolling")
    assert (loaded.solver, loaded.time_limit_s, loaded.threads, loaded.seed, dict(loaded.options)) == (
        shipped["solver"], shipped["time_limit_s"], shipped["threads"], shipped["seed"], shipped["options"])
    assert_verified(problem, s)
    assert s.bound <= exact.objective + OBJ_TOL <= s.objective + 2 * OBJ_TOL


def test_pair_matching_bound_by_hand():
    """Two aircraft on one track at the same time, 50 m cells, r = 1, 25 m/s: δ must leave (−4, 4) s.
    Each pair member alone gives −ω7; together −2ω7 + ω6/G·4 (G = 2). (ω6, ω7) = (0.6, 0.4):
    min(−0.4, −0.8 + 1.2) = −0.4, which is the optimum (cancel one: −0.4; delay one 4 s: +0.4),
    above the trivial −ω7·n = −0.8."""
    track = np.array([[25.0, 25.0, 45.0], [525.0, 25.0, 45.0]])
    flights = tuple(Flight(id=f"{a}1", aircraft=a, route="E", origin="a", destination="b", speed_mps=25.0,
                           planned_departure_s=0.0, max_delay_s=100.0, waypoints=track) for a in "AB")
    problem = build_problem(FlightSet(cell=(50.0, 50.0, 30.0), conflict_radius=1, flights=flights))
    assert pair_matching_bound(problem) == pytest.approx(-0.4, abs=1e-5)  # dist reduced by 2e-6 s (tolerance)
    assert bruteforce.solve(problem).objective == pytest.approx(-0.4)


@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(tiny_problems())
def test_tiny_instances_rolling_against_bruteforce(case):
    """Short windows (5 s) on tiny instances: never better than the optimum, bound never above it."""
    _, problem = case
    optimum = bruteforce.solve(problem).objective
    s = rolling.solve(problem, SolverProfile("rolling", time_limit_s=10.0, threads=1, options={"window_s": 5.0}))
    assert_verified(problem, s)
    assert s.objective >= optimum - OBJ_TOL and s.bound <= optimum + OBJ_TOL


@pytest.mark.parametrize(("options", "match"), [
    ({"bogus": 1}, "unknown option 'bogus'"),
    ({"inner": "ga"}, "option inner = 'ga' is not one of 'cpsat', 'highs'"),
    ({"window_s": 0.0}, r"option window_s must be a number in \[1, 1e\+07\], got 0.0"),
])
def test_rolling_rejects_bad_options(paper_problem, options, match):
    with pytest.raises(UamoptError, match=match):
        rolling.solve(paper_problem, profile(**options))
