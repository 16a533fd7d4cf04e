"""The risk–transport Pareto front (Fig. 21) on the paper case at coarse 100 × 100 × 60 m cells:
a front whose points do not dominate one another and whose ends are the single-objective optima."""

from __future__ import annotations

import numpy as np
import pytest

from uamopt.planning import SearchProblem, grid_search, plan_track, planning_model
from uamopt.planning.pareto import (
    ParetoPoint,
    non_dominated,
    pareto_front,
    weight_sweep,
)
from uamopt.planning.tracks import endpoint_cell, track_metrics

ORIGIN, DESTINATION = (300.0, 300.0, 120.0), (2220.0, 4220.0, 120.0)  # V1 → V4


@pytest.fixture(scope="module")
def coarse(coarse_run):
    model = planning_model(coarse_run.scenario, coarse_run.field)
    return model, plan_track(model, ORIGIN, DESTINATION)


# --- Pareto front -----------------------------------------------------------------------------


def test_non_dominated_on_a_hand_case():
    def point(r, t):
        return ParetoPoint(1.0, 1.0, r, t, np.zeros((2, 3)))

    pts = [point(10, 5), point(8, 6), point(9, 7), point(8, 6 + 1e-13), point(3, 9), point(12, 5 + 1e-13)]
    front = non_dominated(pts)
    assert [(p.risk_cost, p.transport_cost) for p in front] == [(10, 5), (8, 6), (3, 9)]


def test_pareto_front_is_sorted_non_dominated_and_reaches_both_optima(coarse):
    model, plan = coarse
    weights = model.scenario.tracks.weights
    front = pareto_front(model, ORIGIN, DESTINATION, 9, buffer=False)
    assert model.scenario.tracks.weights == weights  # the frozen scenario is not touched
    assert len(front) >= 2
    t = np.array([p.transport_cost for p in front])
    r = np.array([p.risk_cost for p in front])
    assert np.all(np.diff(t) > 0) and np.all(np.diff(r) < 0)
    for p in front:
        assert not any(q.risk_cost <= p.risk_cost and q.transport_cost <= p.transport_cost
                       for q in front if q is not p)
    # the cheapest point is the standard A* of the shortest stage (transport only)
    start, goal = endpoint_cell(model, ORIGIN, "origin"), endpoint_cell(model, DESTINATION, "destination")
    shortest = grid_search(model.search_problem("shortest"), start, goal)
    assert t[0] == pytest.approx(shortest.cost, rel=1e-6)  # the shortest search adds a 1e-9 risk tie-break
    assert t[0] == pytest.approx(plan.stages["shortest"].transport_cost, rel=1e-9)
    # the safest point is the least-risk search (transport only breaking ties)
    zero = np.zeros(model.admissible.shape)
    safest = grid_search(SearchProblem(model.admissible, model.risk, zero, model.field.grid.cell, 1.0,
                                       1e-9 * model.c_h, 1e-9 * model.c_v), start, goal)
    least_risk = track_metrics(model, (safest.path + 0.5) * np.asarray(model.field.grid.cell))["risk_cost"]
    assert r[-1] == pytest.approx(least_risk, rel=1e-9)
    assert front[-1].w4 == 1.0 and front[0].w5 == 1.0  # the extremes of the sweep


def test_weight_sweep_at_the_scenario_weights_is_the_initial_track(coarse):
    model, plan = coarse
    (point,) = weight_sweep(model, ORIGIN, DESTINATION, [model.scenario.tracks.weights])
    initial = plan.stages["initial"]
    assert point.risk_cost == pytest.approx(initial.risk_cost, rel=1e-12)
    assert point.transport_cost == pytest.approx(initial.transport_cost, rel=1e-12)
    np.testing.assert_allclose(point.waypoints, initial.waypoints)
    # with the buffer the front still is non-empty and its own non-dominated set
    front = pareto_front(model, ORIGIN, DESTINATION, 5)
    assert front and non_dominated(front) == front


def test_weights_are_validated(coarse):
    model, _ = coarse
    for bad in (1, [], [(-1.0, 1.0)], [(0.0, 0.0)], [(1.0, float("nan"))], [(1.0,)]):
        with pytest.raises(ValueError, match="weights"):
            weight_sweep(model, ORIGIN, DESTINATION, bad)
    # a zero weight becomes the tie-break ε, not a free objective
    (point,) = weight_sweep(model, ORIGIN, DESTINATION, [(1.0, 0.0)], buffer=False)
    assert 0.0 < point.w5 < 1e-3
