"""The scheduling core (uamopt/schedule/core.py): the objective, the pair view and "must operate",
checked against hand-worked cases; every solver reads them from there."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from checks import assert_verified
from instances import crossing_problem
from oracles import objective as oracle_objective

from uamopt.schedule.core import Objective, pair_view
from uamopt.solvers import SolverProfile, bruteforce, solve


def test_pair_view_gaps_by_hand():
    # D_p = 0, D_q = 100, U_p = 50, U_q = 80: δ = dep_q − dep_p reaches [100 − 50, 100 + 80] = [50, 180].
    # Forbidden (60, 90), (120, 130) and (200, 300) (beyond reach) leave [50, 60], [90, 120], [130, 180].
    # A second pair q → r with D_r = 100, U_r = 0: δ reaches [100 − 80, 100] = [20, 100], all inside (0, 500).
    dep, upper = np.array([0.0, 100.0, 200.0]), np.array([50.0, 80.0, 0.0])
    view = pair_view([0, 1], [1, 2], [0, 3, 4], [[60, 90], [120, 130], [200, 300], [0, 500]], dep, upper)
    assert view.shift.tolist() == [100.0, 100.0]
    assert view.reach_lo.tolist() == [50.0, 20.0] and view.reach_hi.tolist() == [180.0, 100.0]
    assert view.gaps_of(0) == [(50.0, 60.0), (90.0, 120.0), (130.0, 180.0)]
    assert view.gaps_of(1) == []  # no admissible δ: p and q cannot both operate
    assert view.row_pair.tolist() == [0, 0, 0, 1]


def test_pair_view_touching_interval_keeps_the_closed_end():
    # reach [0, 10]; forbidden (0, 4) and (4, 10): δ = 0, 4 and 10 stay admissible (open intervals)
    view = pair_view([0], [1], [0, 2], [[0, 4], [4, 10]], np.array([0.0, 0.0]), np.array([0.0, 10.0]))
    assert view.gaps_of(0) == [(0.0, 0.0), (4.0, 4.0), (10.0, 10.0)]


def test_objective_by_hand():
    # Table 3's initial plan: S = 109, Σ d = 2401 s, G = 20: W = 0.6 · 120.05 − 0.4 · 109 = 28.43
    assert Objective.weighted(0.6, 0.4, 20).value(109, 2401.0) == pytest.approx(28.43)
    lex = Objective.lexicographic(np.array([100.0, 199.0]))  # Σ U + 1 = 300
    assert lex.value(2, 150.0) == pytest.approx(-2 + 0.5)
    assert lex.value(2, 299.0) < lex.value(1, 0.0)  # one more flight beats any delay
    rows = Objective.weighted(0.5, 1.0, 2).values(np.array([[1, 1], [1, 0]], bool), np.array([[10.0, 20.0], [4.0, 99.0]]))
    assert rows.tolist() == pytest.approx([0.25 * 30 - 2, 0.25 * 4 - 1])  # a cancelled flight's delay is ignored


# tests/instances.py's crossing instance (hand-checked there): A1 may wait, B1 and C1 may not.
# Free optimum (weights 0.6, 0.4; G = 3): cancel A1, fly B1 and C1: W = −0.8. With A1 a must-operate
# flight: A1 on time and B1, C1 cancelled gives −0.4; flying B1 or C1 too needs d_A ≥ 4 s
# (with C1: 0.6·4/3 − 0.8 = 0) or d_A ≥ 6 s (with both: 1.2 − 1.2 = 0; with B1 alone: 1.2 − 0.8 = 0.4),
# so the optimum is −0.4.
FREE_OPTIMUM, MUST_A1_OPTIMUM = -0.8, -0.4


@pytest.fixture(scope="module")
def pinned():
    problem = crossing_problem("weighted", (0.6, 0.4))
    ids = [f.id for f in problem.flights.flights]
    return problem, dataclasses.replace(problem, must_operate=np.array([i == "A1" for i in ids])), ids.index("A1")


def test_bruteforce_free_and_pinned_optimum(pinned):
    free, pin, a1 = pinned
    assert bruteforce.solve(free).objective == pytest.approx(FREE_OPTIMUM)
    best = bruteforce.solve(pin)
    assert best.operated[a1] and best.objective == pytest.approx(MUST_A1_OPTIMUM)


@pytest.mark.parametrize("solver", ["greedy", "ga", "soa", "highs", "cpsat", "timeindexed", "rolling"])
def test_every_solver_keeps_must_operate(pinned, solver):
    _, pin, a1 = pinned
    schedule = solve(pin, SolverProfile(solver, time_limit_s=5.0, threads=1, options={"generations": 20}
                                        if solver in ("ga", "soa") else {}))
    assert schedule.operated[a1], f"{solver} cancelled a must-operate flight"
    w = assert_verified(pin, schedule)
    assert w == pytest.approx(oracle_objective(schedule.operated, schedule.delay_s, (0.6, 0.4), 3))
    assert w >= MUST_A1_OPTIMUM - 1e-9
    if solver in ("greedy", "highs", "cpsat", "timeindexed", "rolling"):  # greedy places A1 first: on time
        assert w == pytest.approx(MUST_A1_OPTIMUM, abs=1e-6)
