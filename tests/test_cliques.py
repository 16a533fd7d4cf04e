"""Clique rows of the time-indexed model (uamopt/solvers/cliques.py).

Checked outside the code that derives them:
- every clique row is a clique of the problem: for every two of its columns of different flights,
  operating just those two flights at those delays breaks a pair interval of ``problem.conflicts``
  or a turnaround, as tests/oracles.py's ``broken`` reads them (the conflict table is computed by
  a different join, occupancy.py; ``broken`` imports nothing of uamopt). For the ``relaxed`` model
  that holds for delays anywhere in the two cells (their ends and inner points are tried);
- with the rows, the grid model's optimum still equals the enumeration of every delay vector on
  the grid, and the relaxed bound stays ≤ the continuous optimum (both from tests/oracles.py);
- the rows are derived only for a conflict table computed from the flights' own tracks.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from oracles import broken, exact_optimum, grid_optimum, model_data, pair_broken, score
from strategies import tiny_problems

from uamopt.schedule import build_problem, generate_plan
from uamopt.solvers import SolverProfile, solve
from uamopt.solvers.cliques import applicable, occupancy_cliques
from uamopt.solvers.timeindexed import build_grid_model
from uamopt.solvers.warmstart import reduced

OBJ_TOL = 1e-6


def _check_cliques(problem, step_s: float, kind: str, samples: int = 400, seed: int = 0) -> int:
    """Check up to ``samples`` member pairs of the clique rows with the oracle; the rows checked."""
    small = reduced(problem)
    k_max = np.floor(small.delay_upper_s / step_s + 1e-9 / step_s).astype(np.int64)
    start = np.concatenate([[0], np.cumsum(k_max + 1)]).astype(np.int64)
    ptr, cols = occupancy_cliques(small, start, step_s, kind)
    data = model_data(problem)
    rng = np.random.default_rng(seed)
    rows = len(ptr) - 1
    for _ in range(min(samples, 50 * rows)):
        r = int(rng.integers(rows))
        members = cols[ptr[r]:ptr[r + 1]]
        a, b = rng.choice(members, size=2, replace=False)
        f, g = (int(np.searchsorted(start, c, side="right") - 1) for c in (a, b))
        if f == g:
            continue
        k_f, k_g = int(a - start[f]), int(b - start[g])
        offsets = [0.0] if kind == "grid" else [0.0, 0.37 * step_s, 0.999 * step_s]
        for u in offsets:
            for v in offsets:
                d_f, d_g = k_f * step_s + u, k_g * step_s + v
                assert pair_broken(data, f, g, d_f, d_g), (kind, r, f, g, d_f, d_g)
    return rows


@pytest.fixture(scope="module")
def dense_problem(paper_straight_plan):
    """The paper case's straight tracks, 160 flights of 20 eVTOLs in the hour (many share a cell at once)."""
    scenario, _, network, _ = paper_straight_plan
    scenario = scenario.model_copy(update={"schedule": scenario.schedule.model_copy(update={"flights": 160})})
    return build_problem(generate_plan(scenario, network, seed=3), scenario, objective="weighted")


@pytest.mark.parametrize(("kind", "step_s"), [("grid", 10.0), ("grid", 5.0), ("relaxed", 2.0)])
def test_every_clique_row_is_a_clique_of_the_problem(dense_problem, kind, step_s):
    rows = _check_cliques(dense_problem, step_s, kind)
    assert rows >= 20  # the instance is dense: the check is not vacuous


@settings(max_examples=30, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(tiny_problems(max_flights=5))
def test_with_clique_rows_the_grid_optimum_is_the_enumerated_one(case):
    _, problem = case
    data = model_data(problem)
    step = 5.0
    _check_cliques(problem, step, "grid", samples=60)
    _check_cliques(problem, 1.0, "relaxed", samples=60)
    expected = grid_optimum(data, step)
    continuous, _, _ = exact_optimum(data)
    profile = SolverProfile("timeindexed", time_limit_s=30.0, threads=1,
                            options={"step_s": step, "engine": "highs", "cliques": True})
    grid = solve(problem, profile)
    assert grid.status == "optimal_on_grid" and broken(data, grid.operated, grid.delay_s) == []
    assert score(data, grid.operated, grid.delay_s) == pytest.approx(expected, abs=OBJ_TOL)
    relaxed = solve(problem, dataclasses.replace(profile, options={"step_s": 1.0, "model": "relaxed", "cliques": True}))
    assert relaxed.bound <= continuous + OBJ_TOL


def test_tiny_instances_do_have_clique_rows():
    """The property test above is not vacuous: most of its instances with conflicts get clique rows."""

    seen = []

    @settings(max_examples=30, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
    @given(tiny_problems(max_flights=5))
    def count(case):
        _, problem = case
        if len(problem.conflicts):
            model = build_grid_model(reduced(problem), 5.0, "grid", cliques=True)
            seen.append(model.cliques)

    count()
    assert len(seen) >= 10 and sum(c > 0 for c in seen) >= len(seen) // 2, seen


def test_no_clique_rows_for_a_table_not_computed_from_the_tracks(dense_problem):
    assert applicable(dense_problem)
    table = dense_problem.conflicts
    hand_made = dataclasses.replace(dense_problem, conflicts=dataclasses.replace(table, from_tracks=False))
    assert not applicable(hand_made)
    assert build_grid_model(reduced(hand_made), 10.0, "grid", cliques=True).cliques == 0
    assert build_grid_model(reduced(dense_problem), 10.0, "grid", cliques=True).cliques > 0


def test_the_clique_rows_keep_the_grid_optimum_of_a_dense_instance(dense_problem):
    """On 160 flights, HiGHS proves the grid model with and without the rows: one optimum, and the
    schedule passes the model's own check (the LP with rows is the stronger start)."""
    results = {}
    for cliques in (False, True):
        profile = SolverProfile("timeindexed", time_limit_s=120.0, threads=2,
                                options={"step_s": 10.0, "engine": "highs", "cliques": cliques})
        results[cliques] = solve(dense_problem, profile)
        assert results[cliques].status == "optimal_on_grid"
    assert results[True].objective == pytest.approx(results[False].objective, abs=OBJ_TOL)
    assert results[True].extras["cliques"] > 0 and results[True].extras["dominated_pair_rows"] > 0
    # the option acts: off, the model is the pair rows alone (more rows: the dropped ones are back)
    assert results[False].extras["cliques"] == 0 and results[False].extras["dominated_pair_rows"] == 0
    assert results[False].extras["rows"] == results[True].extras["rows"] - results[True].extras["cliques"] \
        + results[True].extras["dominated_pair_rows"]
