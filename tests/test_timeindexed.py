"""The time-indexed solver (uamopt/solvers/timeindexed.py) and the warm starts of every exact solver.

Checked outside the models:
- on tiny instances, the ``grid`` model's optimum equals an enumeration of every delay vector on
  the grid, and the ``relaxed`` model's bound is ≤ the continuous optimum ≤ the grid optimum: the
  enumeration, its constraint check, the scoring (Eqs. 20-22) and the continuous optimum all come
  from tests/oracles.py, which rebuilds the model from the flights and imports nothing of uamopt;
- on the paper case, the grid optimum is ≥ the continuous optimum (HiGHS), the relaxed bound ≤ it,
  and the written schedule passes the independent verifier;
- every exact solver, stopped almost at once, returns a verified schedule, never better than the
  recorded optimum of its instance, with a bound (if any) below that optimum.
"""

from __future__ import annotations

import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest
from conftest import PAPER_CASE
from hypothesis import HealthCheck, given, settings
from oracles import broken, exact_optimum, grid_optimum, model_data, objective_from_folder, score
from strategies import tiny_problems

from uamopt.errors import UamoptError
from uamopt.schedule import (
    build_problem,
    generate_plan,
    write_schedule,
)
from uamopt.schedule.verify import verify_dir
from uamopt.solvers import SolverProfile, load_profile, solve

OBJ_TOL = 1e-6


def ti(model="grid", step_s=5.0, engine="highs", **kw) -> SolverProfile:
    return SolverProfile("timeindexed", time_limit_s=30.0, threads=1, options={"model": model, "step_s": step_s,
                                                                               "engine": engine, **kw})


@settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(tiny_problems(max_flights=5))
def test_grid_model_is_exact_on_its_grid_and_relaxed_bounds_the_continuous_optimum(case):
    """Every expectation from tests/oracles.py (no uamopt code): the grid optimum by enumeration
    of the 5 s delay grid, the continuous optimum by enumeration of gap choices, each decision
    checked against the model rebuilt from the flights and scored by Eqs. 20-22."""
    _, problem = case
    data = model_data(problem)
    step = 5.0  # delays ≤ 20 s: at most 5 grid points and "cancel" per flight
    expected = grid_optimum(data, step)
    continuous, _, _ = exact_optimum(data)
    assert continuous <= expected + OBJ_TOL  # the grid restricts the continuous model (both oracles)
    for engine in ("highs", "cpsat", "hybrid"):
        grid = solve(problem, ti(step_s=step, engine=engine))
        # proved on the grid only (a restriction): its own bound is kept aside, never reported as `bound`
        assert grid.status == "optimal_on_grid" and broken(data, grid.operated, grid.delay_s) == [], engine
        np.testing.assert_allclose(grid.delay_s / step, np.rint(grid.delay_s / step), atol=1e-9)  # on the grid
        assert score(data, grid.operated, grid.delay_s) == pytest.approx(expected, abs=OBJ_TOL), engine
        assert grid.objective == pytest.approx(expected, abs=OBJ_TOL), engine
        assert grid.extras["restricted_bound"] == pytest.approx(expected, abs=OBJ_TOL)
        # `bound` is the separable one (valid for continuous delays), never the grid's
        assert grid.extras["bound_source"].startswith("the separable bound") and grid.bound <= continuous + OBJ_TOL
    for step_s in (5.0, 1.0):
        relaxed = solve(problem, ti(model="relaxed", step_s=step_s))
        assert relaxed.bound <= continuous + OBJ_TOL
        assert broken(data, relaxed.operated, relaxed.delay_s) == []  # the warm start it shows
        assert score(data, relaxed.operated, relaxed.delay_s) >= continuous - OBJ_TOL


@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(tiny_problems(max_flights=5))
def test_coarse_to_fine_ends_at_the_fine_grids_optimum(case):
    """refine_step_s: the 10 s grid, then the 5 s grid from its best; the result is the 5 s grid's
    optimum by enumeration (tests/oracles.py), whatever the 10 s grid gave."""
    _, problem = case
    data = model_data(problem)
    expected = grid_optimum(data, 5.0)
    result = solve(problem, ti(step_s=10.0, refine_step_s=5.0))  # 30 s: 18 s for the 5 s grid (≥ REFINE_MIN_S)
    assert "then the 5 s grid" in result.extras["refined"]
    assert broken(data, result.operated, result.delay_s) == []
    assert score(data, result.operated, result.delay_s) == pytest.approx(expected, abs=OBJ_TOL), result.extras.get("refined")
    np.testing.assert_allclose(result.delay_s / 5.0, np.rint(result.delay_s / 5.0), atol=1e-9)


@pytest.fixture(scope="module")
def paper_problem(paper_straight_plan):
    scenario, _, _, plan = paper_straight_plan
    return build_problem(plan, scenario)


def test_exact_profile_on_the_paper_case(paper_problem, tmp_path):
    problem = paper_problem
    profile = load_profile("exact")
    assert profile.solver == "timeindexed"
    grid = solve(problem, profile)
    continuous = solve(problem, SolverProfile("highs", time_limit_s=60.0, threads=2))
    print(f"\ngrid: {grid.summary()}\ncontinuous: {continuous.summary()}")
    assert grid.status == "optimal_on_grid" and continuous.status == "optimal"
    assert grid.extras["restricted_bound"] == pytest.approx(grid.objective, abs=1e-6 * abs(grid.objective))
    assert grid.objective >= continuous.objective - OBJ_TOL  # a restriction: never below the continuous optimum
    # the reported bound is the relaxed grid's (continuous_bound_s in solvers/exact.toml): valid for
    # continuous delays, so the HiGHS optimum lies in [bound, objective]
    assert grid.bound == grid.extras["continuous_bound"] and grid.bound <= continuous.objective + OBJ_TOL
    assert grid.gap == pytest.approx((grid.objective - grid.bound) / abs(grid.objective))
    write_schedule(tmp_path, problem, grid)
    assert verify_dir(tmp_path) == []
    summary = grid.summary()  # solvers/exact.toml refines the 10 s grid to the 5 s grid (refine_step_s)
    assert summary["model"].startswith("delay grid 5 s") and summary["status"] == "optimal_on_grid"
    assert summary["model_kind"] == "delay grid 5 s" and "then the 5 s grid" in grid.extras["refined"]
    relaxed = solve(problem, ti(model="relaxed", step_s=10.0))
    assert relaxed.bound <= continuous.objective + OBJ_TOL
    assert relaxed.summary()["model"].startswith("delay cells 10 s (relaxation")


#: the proved optimum of ``medium_problem`` (240 flights, weighted): a regression value, from
#: ``solve(medium_problem, SolverProfile("highs", time_limit_s=300, threads=2))`` (status optimal, bound
#: equal, 1.9 s; working tree on commit 7eefcd2)
MEDIUM_OPTIMUM = -74.1616460230027


@pytest.fixture(scope="module")
def medium_problem(paper_straight_plan):
    scenario, _, network, _ = paper_straight_plan
    return build_problem(generate_plan(scenario, network, seed=1, aircraft=40), scenario)


@pytest.mark.parametrize("profile", [
    SolverProfile("highs", time_limit_s=0.05, threads=1),
    SolverProfile("cpsat", time_limit_s=0.05, threads=1),
    SolverProfile("rolling", time_limit_s=0.05, threads=1, options={"window_s": 900.0}),
    SolverProfile("timeindexed", time_limit_s=0.05, threads=1),
    SolverProfile("timeindexed", time_limit_s=0.05, threads=1, options={"engine": "cpsat"}),
    SolverProfile("timeindexed", time_limit_s=0.05, threads=1, options={"engine": "hybrid"}),
], ids=["highs", "cpsat", "rolling", "timeindexed-highs", "timeindexed-cpsat", "timeindexed-hybrid"])
def test_exact_solvers_never_worse_than_greedy_at_a_tiny_limit(medium_problem, profile, tmp_path):
    """At a 0.05 s limit: a verified schedule scored from its files by the oracle (tests/oracles.py,
    no uamopt code), a status the bound supports ("optimal" only with a bound equal to the objective,
    "time_limit" only with a bound below it or none), and both sides of the instance's optimum: no
    schedule below it, no bound above it. (Not asserted: "no worse than greedy". Every exact solver
    starts from the best cheap heuristic schedule, greedy among them, and returns it when its own is
    worse, so that held by construction; here the greedy solver's schedule scores +20.0 and the
    start −59.95.)"""
    problem = medium_problem
    weights = problem.weights
    schedule = solve(problem, profile)
    write_schedule(tmp_path / "exact", problem, schedule)
    assert verify_dir(tmp_path / "exact") == []
    found = objective_from_folder(tmp_path / "exact", weights, problem.objective_kind)
    print(f"\n{profile.solver}: {schedule.status} {found:.4f} (optimum {MEDIUM_OPTIMUM:.4f}) {schedule.extras.get('incumbent')}")
    assert found == pytest.approx(schedule.objective, abs=1e-6)  # the reported objective is the files' one
    assert found >= MEDIUM_OPTIMUM - 1e-6
    assert schedule.bound is None or schedule.bound <= MEDIUM_OPTIMUM + 1e-6
    if schedule.status in ("optimal", "optimal_on_grid"):
        assert schedule.bound is not None and schedule.bound >= found - 1e-6 * max(1.0, abs(found))
    else:
        assert schedule.status == "time_limit"
        assert schedule.bound is None or schedule.bound < found


def test_relaxed_model_rejects_bad_options(paper_problem):
    with pytest.raises(UamoptError, match="option model = 'loose' is not one of 'grid', 'relaxed'"):
        solve(paper_problem, ti(model="loose"))
    with pytest.raises(UamoptError, match="unknown option 'bogus'"):
        solve(paper_problem, replace(ti(), options={"bogus": 1}))


def test_highs_and_cpsat_in_one_process_either_order(root):
    """highspy 1.16.0 links HiGHS statically, so OR-Tools' bundled libhighs.so.1 cannot clash with it:
    both solvers load and solve in one interpreter, whichever is imported first (pyproject.toml)."""
    script = (
        "import sys\n"
        "from uamopt.scenario import load_scenario\n"
        "from uamopt.grid import AirspaceGrid\n"
        "from uamopt.schedule import build_problem, generate_plan, straight_network\n"
        "from uamopt.solvers import SolverProfile, solve\n"
        f"sc = load_scenario({str(PAPER_CASE)!r})\n"
        "grid = AirspaceGrid.from_extent(sc.grid.cell, sc.grid.extent)\n"
        "pb = build_problem(generate_plan(sc, straight_network(sc, grid), seed=0, aircraft=4), sc)\n"
        "names = sys.argv[1].split(',')\n"
        "res = [solve(pb, SolverProfile(n, time_limit_s=30, isolated=False)) for n in names]\n"  # in this process
        "loaded = sorted({m.split('.')[0] for m in sys.modules\n"
        "                 if m in ('highspy._core', 'ortools.sat.python.cp_model_helper')})\n"
        "print(' '.join(r.status for r in res), res[0].objective - res[1].objective, ','.join(loaded))\n"
    )
    for order in ("cpsat,highs", "highs,cpsat"):
        out = subprocess.run([sys.executable, "-c", script, order], check=False, capture_output=True, text=True, cwd=root,
                             timeout=120)
        assert out.returncode == 0, out.stderr
        status_a, status_b, difference, loaded = out.stdout.split()[-4:]
        assert status_a == status_b == "optimal" and loaded == "highspy,ortools"
        sign = 1.0 if order.startswith("cpsat") else -1.0  # CP-SAT's lattice optimum is ≥ the continuous one
        assert -OBJ_TOL <= sign * float(difference) <= 0.1


def test_benchmark_names_the_model_and_reports_only_continuous_bounds(paper_problem):
    """`exact` proves the 10 s delay grid, then the 5 s grid from it (refine_step_s), a restriction:
    its row says so (status optimal_on_grid, model "delay grid 5 s"), and its bound, like every bound in the table, lies below the
    continuous optimum that HiGHS proves in the same table."""
    import uamopt as ua

    table = ua.benchmark(paper_problem, ["exact", "highs"], seeds=[0], time_limit_s=60, progress=False)
    exact, highs = (table[table["profile"] == name].iloc[0] for name in ("exact", "highs"))
    assert (exact["status"], exact["model"]) == ("optimal_on_grid", "delay grid 5 s")
    assert (highs["status"], highs["model"]) == ("optimal", "continuous")
    assert exact["bound"] <= highs["objective"] + OBJ_TOL and highs["bound"] <= highs["objective"] + OBJ_TOL
    assert exact["objective"] >= highs["objective"] - OBJ_TOL and table["verified"].all()
