"""Track figures and the risk–transport Pareto front (Fig. 18, Fig. 21) on the paper case at
coarse 100 × 100 × 60 m cells: PNGs of the promised size showing the stages' colours, a front
whose points do not dominate one another and whose ends are the single-objective optima."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from matplotlib import colors, image

from uamopt.planning import SearchProblem, grid_search, plan_track, planning_model
from uamopt.planning.pareto import ParetoPoint, non_dominated, pareto_front, plot_pareto, weight_sweep
from uamopt.planning.tracks import endpoint_cell, track_metrics
from uamopt.plot_tracks import STAGE_STYLE, along_track_m, pair_directions, plot_network, plot_tracks
from uamopt.plots import DPI, FIGSIZE_IN, OSM_CREDIT

PIXELS = (round(FIGSIZE_IN[1] * DPI), round(FIGSIZE_IN[0] * DPI))  # (rows, columns)
ORIGIN, DESTINATION = (300.0, 300.0, 120.0), (2220.0, 4220.0, 120.0)  # V1 → V4


@pytest.fixture(scope="module")
def coarse(coarse_run):
    model = planning_model(coarse_run.scenario, coarse_run.field)
    return model, plan_track(model, ORIGIN, DESTINATION)


def _has_colour(png: np.ndarray, colour: str, tol: float = 4 / 255) -> bool:
    return bool(np.any(np.all(np.abs(png[:, :, :3] - np.asarray(colors.to_rgb(colour))) <= tol, axis=2)))


# --- figures ----------------------------------------------------------------------------------


def test_plot_tracks_writes_png_with_every_stage(coarse, tmp_path):
    model, plan = coarse
    path = plot_tracks(model, plan, tmp_path / "tracks.png", title="paper_case")
    assert path == tmp_path / "tracks.png"
    png = image.imread(path)
    assert png.shape[:2] == PIXELS
    for name in ("shortest", "initial", "equivalent", "optimal"):  # Fig. 18: red, orange, gold, green
        assert _has_colour(png, STAGE_STYLE[name][1]), name


def test_plot_tracks_credits_openstreetmap(coarse, tmp_path):
    model, plan = coarse
    pictures = {}
    for label, text, source in (("osm", OSM_CREDIT, "osm"), ("blank", "", "synthetic")):
        city = dataclasses.replace(model.field.city, attribution=text, source=source)
        credited = dataclasses.replace(model, field=dataclasses.replace(model.field, city=city))
        pictures[label] = image.imread(plot_tracks(credited, plan, tmp_path / f"{label}.png"))
    corner = (slice(-12, None), slice(-PIXELS[1] // 4, None))
    assert pictures["osm"][corner][..., :3].min() < 0.5  # dark text in the bottom-right corner
    assert pictures["blank"][corner][..., :3].min() > 0.9


def test_plot_network_writes_png(coarse, tmp_path):
    model, plan = coarse
    out = plan.stages["optimal"].waypoints
    back = out[::-1] + np.array([0.0, 0.0, 60.0])  # the way back one layer up
    other = plan.stages["shortest"].waypoints
    tracks = {"V1-V4": out, "V4-V1": back, "V1-X": other[: len(other) // 2]}
    path = plot_network(model, tracks, tmp_path / "network.png", vertiports=model.scenario.network.vertiports)
    png = image.imread(path)
    assert png.shape[:2] == PIXELS
    with pytest.raises(ValueError, match="at least one route"):
        plot_network(model, {}, tmp_path / "empty.png")


def test_directions_pair_into_routes():
    a, b, c = [0.0, 0.0, 120.0], [1000.0, 0.0, 120.0], [0.0, 800.0, 120.0]
    tracks = {"A-B": np.array([a, b]), "A-C": np.array([a, c]), "B-A": np.array([b, a]) + [0, 0, 30]}
    assert pair_directions(tracks, tolerance_m=10.0) == [("A-B", "B-A"), ("A-C", None)]
    np.testing.assert_allclose(along_track_m(np.array([[0, 0, 0], [3, 4, 10], [3, 4, 20]])), [0, 5, 5])


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


def test_plot_pareto_writes_png(coarse, tmp_path):
    model, plan = coarse
    points = weight_sweep(model, ORIGIN, DESTINATION, 7, buffer=False)
    points.append(ParetoPoint(0.5, 0.5, max(p.risk_cost for p in points) + 50.0,
                              max(p.transport_cost for p in points) + 5.0, np.zeros((2, 3))))  # dominated
    png = image.imread(plot_pareto(points, tmp_path / "pareto.png", plan=plan, title="paper_case"))
    assert png.shape[:2] == (round(5.5 * DPI), round(8.0 * DPI))
    assert _has_colour(png, "0.7")  # the dominated point, greyed
    with pytest.raises(ValueError, match="at least one"):
        plot_pareto([], tmp_path / "none.png")
