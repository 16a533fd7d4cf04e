"""Track planning stages (Sec. 4.2, 5.1): constraints, exact equivalent track, smoothing, network."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.spatial import cKDTree

from uamopt.errors import UamoptError
from uamopt.grid.geometry import polyline_pieces
from uamopt.pipeline import compute_risk
from uamopt.planning import plan_track, planning_model
from uamopt.planning.network import load_network, plan_network
from uamopt.planning.problem import SHORTEST_TIE_BREAK, box_counts, buffer_cells, buffer_shell_count, load_factor, transport_rates
from uamopt.planning.tracks import corner_fillets, exact_equivalent_track, midpoint_track
from uamopt.scenario import Scenario, load_scenario

P_O, P_D = (300.0, 300.0, 120.0), (2220.0, 4220.0, 120.0)


@pytest.fixture(scope="module")
def model(paper_model):
    return paper_model


@pytest.fixture(scope="module")
def plan(model):
    return plan_track(model, P_O, P_D)


def test_transport_cost_of_the_straight_segment_matches_table2():
    """docs/readings.md: m_p ≈ 145.6 kg makes the straight 4365 m level track cost ¥27.15 (±0.5 %)."""
    c_h, _ = transport_rates(Scenario())
    assert load_factor(Scenario()) == pytest.approx(1 + 145.6 / 220 * 1.56)
    assert c_h * 4365.0 == pytest.approx(27.1527, rel=5e-3)


def test_buffer_size_per_axis():
    assert buffer_cells((50.0, 50.0, 30.0), 50.0) == (3, 3, 5)
    assert buffer_cells((10.0, 10.0, 10.0), 50.0) == (11, 11, 11)


def test_shell_count_against_brute_force():
    rng = np.random.default_rng(1)
    unsafe = rng.uniform(size=(7, 8, 6)) < 0.3
    n_s = (3, 5, 5)
    got = buffer_shell_count(unsafe, n_s)
    h = [(n - 1) // 2 for n in n_s]
    for i, j, k in [(0, 0, 0), (3, 4, 2), (6, 7, 5), (2, 1, 4)]:
        count = 0
        for a in range(-h[0], h[0] + 1):
            for b in range(-h[1], h[1] + 1):
                for c in range(-h[2], h[2] + 1):
                    on_shell = abs(a) == h[0] or abs(b) == h[1] or abs(c) == h[2]
                    x, y, z = i + a, j + b, k + c
                    if on_shell:  # beyond the grid counts as unsafe
                        inside = 0 <= x < 7 and 0 <= y < 8 and 0 <= z < 6
                        count += int(unsafe[x, y, z]) if inside else 1
        assert got[i, j, k] == count
    assert box_counts(np.ones((4, 4, 4), dtype=bool), (1, 1, 1))[0, 0, 0] == 8


def test_four_stages_and_their_metrics(model, plan):
    st_ = plan.stages
    assert list(st_) == ["shortest", "initial", "equivalent", "optimal"]
    # the search's own cost is the stage's Eq. 10 objective plus the buffer exposure
    for name in ("shortest", "initial"):
        s = st_[name]
        expected = (s.transport_cost + SHORTEST_TIE_BREAK * s.risk_cost if name == "shortest"
                    else s.objective + s.buffer_cost)
        assert s.extra["search_cost"] == pytest.approx(expected, rel=1e-9)
    # the initial track trades transport cost for a lower planner objective
    assert st_["initial"].objective + st_["initial"].buffer_cost < st_["shortest"].objective + st_["shortest"].buffer_cost
    assert st_["initial"].transport_cost > st_["shortest"].transport_cost
    # equivalent and optimal are shorter than the initial track; optimal never longer than equivalent
    assert st_["equivalent"].length_m < st_["initial"].length_m
    assert st_["optimal"].length_m <= st_["equivalent"].length_m + 1e-9
    assert st_["optimal"].transport_cost <= st_["equivalent"].transport_cost + 1e-9
    # exact equivalent track never longer than the paper's midpoint rule
    assert st_["equivalent"].length_m <= plan.midpoint.length_m + 1e-6
    assert np.allclose(st_["optimal"].waypoints[0], P_O) and np.allclose(st_["optimal"].waypoints[-1], P_D)


def _assert_admissible(model, waypoints):
    """Every piece of the track lies in admissible cells: in the band, clear of obstacles and
    no-fly zones, and each cell's centre ≥ s_min from every obstacle cell's centre (checked here
    with a k-d tree, independently of the planner's distance transform)."""
    grid = model.field.grid
    cells, _s0, _s1 = polyline_pieces(waypoints, grid.cell)
    low, high = model.field.band
    z_centre = (cells[:, 2] + 0.5) * grid.cell[2]
    assert np.all((z_centre >= low - 1e-9) & (z_centre <= high + 1e-9))
    assert not model.field.obstacle[tuple(cells.T)].any()
    assert not model.field.no_fly[tuple(cells.T)].any()
    tree = cKDTree((np.argwhere(model.field.obstacle) + 0.5) * np.asarray(grid.cell))
    dist, _ = tree.query((cells + 0.5) * np.asarray(grid.cell))
    assert dist.min() >= model.scenario.tracks.clearance_m - 1e-9


def test_optimal_track_keeps_clearance_and_band(model, plan):
    for name in ("initial", "equivalent", "optimal"):
        _assert_admissible(model, plan.stages[name].waypoints)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000))
def test_exact_equivalent_never_longer_than_midpoint(model, seed):
    rng = np.random.default_rng(seed)
    ports = [(v.x, v.y) for v in model.scenario.network.vertiports]
    a, b = rng.choice(len(ports), size=2, replace=False)
    origin, destination = (*ports[a], 120.0), (*ports[b], 120.0)
    path = plan_track(model, origin, destination).stages["initial"]
    cells = np.floor(path.waypoints / np.asarray(model.field.grid.cell)).astype(int)
    exact = exact_equivalent_track(cells, model.field.grid.cell, origin, destination)
    mid = midpoint_track(cells, model.field.grid.cell, origin, destination)

    def length(p):
        return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())

    assert length(exact) <= length(mid) * (1 + 1e-7)
    assert length(exact) >= math.dist(origin, destination) - 1e-6


def test_corner_fillet_is_shorter_than_the_corner():
    pts = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 5.0]])
    rounded = corner_fillets(pts, np.array([4.0]))

    def length(p):
        return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())

    assert length(rounded) < length(pts)
    assert np.allclose(rounded[0], pts[0]) and np.allclose(rounded[-1], pts[-1])
    assert np.allclose(corner_fillets(pts, np.array([0.0])), pts)


@pytest.mark.parametrize(("point", "fragment"), [
    ((300.0, 300.0, 50.0), "outside the band"),
    ((300.0, 300.0, 320.0), "outside the band"),
    ((-10.0, 300.0, 120.0), "outside the grid"),
])
def test_bad_endpoints(model, point, fragment):
    with pytest.raises(UamoptError, match=fragment):
        plan_track(model, point, P_D)


def test_origin_inside_a_building(model):
    tall = np.argwhere(model.field.obstacle[:, :, 4])[0]
    inside = (*tuple((tall + 0.5) * np.asarray(model.field.grid.cell[:2])), 135.0)
    with pytest.raises(UamoptError, match="inside a building"):
        plan_track(model, inside, P_D)


def test_range_limit(root):
    s = load_scenario(root / "models" / "paper_case.toml", ["aircraft.range_m=3000"])
    m = planning_model(s, compute_risk(s))
    with pytest.raises(UamoptError, match="range"):
        plan_track(m, P_O, P_D)


def test_aircraft_limits(root):
    s = load_scenario(root / "models" / "paper_case.toml", ["tracks.wind_speed_mps=30"])
    with pytest.raises(UamoptError, match="wind"):
        planning_model(s, compute_risk(s))
    s = load_scenario(root / "models" / "paper_case.toml", ["aircraft.mass_max_kg=600"])
    with pytest.raises(UamoptError, match="take-off mass"):
        planning_model(s, compute_risk(s))


def test_network_directions_on_separate_layers(model, tmp_path):
    network = plan_network(model)
    assert len(network) == 20
    assert network["V1-V4"].layer_k != network["V4-V1"].layer_k
    for name, route in network.routes.items():
        cells, _, _ = polyline_pieces(route.waypoints, model.field.grid.cell)
        assert np.all(cells[:, 2] == route.layer_k), name
        np.testing.assert_array_equal(route.waypoints, route.plan.stages["optimal"].waypoints)
    import json
    path = tmp_path / "network.json"
    path.write_text(json.dumps(network.to_document()))
    loaded = load_network(path)
    assert set(loaded.routes) == set(network.routes)
    for name, route in network.routes.items():
        back = loaded[name]
        np.testing.assert_array_equal(back.waypoints, route.waypoints)
        assert (back.origin, back.destination, back.layer_k, back.length_m, back.transport_cost) == \
            (route.origin, route.destination, route.layer_k, route.length_m, route.transport_cost)
    frame = network.to_frame()
    assert len(frame) == 20 and frame.loc["V1-V4", "origin"] == "V1"
    assert frame.loc["V1-V4", "length_m"] >= 4365.0  # no track is shorter than the straight line


def test_share_variant_gives_table2_shape(root):
    """With R(t) as the unsafe share of the buffer's shell, the initial, equivalent and optimal
    tracks carry less risk than the shortest and cost more (the shape of the paper's Table 2)."""
    s = load_scenario(root / "models" / "paper_case.toml", ["tracks.buffer_measure=share"])
    m = planning_model(s, compute_risk(s))
    assert m.shell_count.max() <= 1.0
    st_ = plan_track(m, P_O, P_D).stages
    for name in ("initial", "equivalent", "optimal"):
        assert st_[name].risk_cost < st_["shortest"].risk_cost, name
        assert st_[name].transport_cost > st_["shortest"].transport_cost, name
    for name in ("equivalent", "optimal"):
        assert st_[name].length_m < st_["initial"].length_m, name
    assert st_["initial"].extra["search_cost"] == pytest.approx(st_["initial"].objective + st_["initial"].buffer_cost, rel=1e-9)


def test_the_optimal_track_keeps_the_buffer_the_initial_track_kept(model):
    """With μ > 0 the corner fillets may leave the corridor only through cells outside every buffer
    shell (R(t) = 0 of Eq. 35): the paper case's initial track pays no buffer (Eq. 34), so the
    smoothed track may not either. Smoothing that ignored the shells entered one here (μ·R(t) = 100)."""
    plan = plan_track(model, P_O, P_D)
    assert plan.stages["initial"].buffer_cost == 0.0
    assert plan.stages["optimal"].buffer_cost == 0.0
    assert plan.stages["optimal"].extra["rounded_corners"] > 0  # the fillets still round corners
    assert plan.stages["optimal"].length_m < plan.stages["equivalent"].length_m


def test_the_heuristic_key_changes_the_search_not_its_cost(model):
    """``tracks.heuristic`` reaches the search: on the paper case's initial stage (50 m) the three
    bounds give the same optimal cost, and the stronger the bound, the fewer cells A* expands
    (recorded values: relaxed 255, transport 22 411, zero 23 354)."""
    import dataclasses

    initial = {}
    for heuristic in ("relaxed", "transport", "zero"):
        keyed = dataclasses.replace(model, scenario=model.scenario.with_overrides([f'tracks.heuristic="{heuristic}"']))
        initial[heuristic] = plan_track(keyed, P_O, P_D).stages["initial"]
    costs = [s.extra["search_cost"] for s in initial.values()]
    assert costs == pytest.approx([costs[0]] * 3, rel=1e-9)
    expansions = {h: s.extra["expansions"] for h, s in initial.items()}
    assert expansions["relaxed"] * 50 < expansions["transport"] <= expansions["zero"], expansions
