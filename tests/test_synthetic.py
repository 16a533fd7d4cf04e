"""The seeded synthetic Nanjing-like city and the shared rasteriser."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from shapely.geometry import LineString, box

from uamopt.city import load_city
from uamopt.city.layers import VectorCity, burn_max, rasterize_city, segment_length_per_cell
from uamopt.city.synthetic import synthetic_city
from uamopt.grid import AirspaceGrid
from uamopt.pipeline import scenario_grid
from uamopt.scenario import CityConfig, load_scenario


@pytest.fixture(scope="module")
def paper(root):
    return load_scenario(root / "models" / "paper_case.toml")


def test_same_seed_same_city_other_seed_other_city(paper):
    a, b = synthetic_city(paper), synthetic_city(paper)
    assert np.array_equal(a.heights_m, b.heights_m)
    assert all(x.equals(y) for x, y in zip(a.buildings, b.buildings, strict=True))
    c = synthetic_city(paper.with_overrides(["city.seed=8"]))
    assert len(c.buildings) != len(a.buildings) or not np.array_equal(c.heights_m, a.heights_m)


def test_city_covers_the_paper_case(paper):
    city = synthetic_city(paper)
    assert city.extent == (2500.0, 4500.0)
    assert city.notes["buildings"] > 500
    assert city.notes["towers_above_90m"] >= 10  # tracks at 120 m must detour
    assert 1 <= city.notes["no_fly_zones"] <= 2
    assert city.notes["parks"] >= 5 and len(city.open_space) > city.notes["parks"]  # parks + river
    heights = city.heights_m
    assert np.median(heights) < 40 and heights.min() >= 6
    # vertiport pads: no building within 60 m, nothing above h_min within the clearance ring
    for v in paper.network.vertiports:
        for shape, h in zip(city.buildings, heights, strict=True):
            d = shape.distance(box(v.x, v.y, v.x, v.y))
            assert d > 30.0, v.name
            if shape.centroid.distance(box(v.x, v.y, v.x, v.y)) < paper.network.vertiport_clearance_m:
                assert h < paper.aircraft.h_min, v.name
        for zone in city.no_fly:
            assert zone.distance(box(v.x, v.y, v.x, v.y)) > 300.0, v.name


def test_towers_stand_near_the_long_diagonals(paper):
    """Business districts sit across V1-V4 and V2-V3 so that the straight tracks meet towers."""
    city = synthetic_city(paper)
    ports = {v.name: (v.x, v.y) for v in paper.network.vertiports}
    for a, b in (("V1", "V4"), ("V2", "V3")):
        line = LineString([ports[a], ports[b]]).buffer(200.0)
        tall = [s for s, h in zip(city.buildings, city.heights_m, strict=True) if h > 120.0 and s.intersects(line)]
        assert len(tall) >= 3, (a, b)


def test_layers_on_the_paper_grid(paper):
    grid = scenario_grid(paper)
    layers = load_city(paper, grid)
    assert layers.surface_height.shape == (50, 90)
    assert layers.building.mean() > 0.2
    assert 0.2 < (layers.road_length > 0).mean() < 0.8
    assert layers.no_fly.any() and layers.open_space.any()
    assert set(np.unique(layers.shelter)) == {0.5, 0.75}
    assert np.all(layers.population_density == 2.5e-4)


def test_total_road_length_is_preserved_across_resolutions(paper):
    city = synthetic_city(paper)
    total = sum(r.length for r in city.roads)
    for cell in (50.0, 10.0):
        grid = AirspaceGrid.from_extent((cell, cell, 30.0), (2500.0, 4500.0, 300.0))
        layers = rasterize_city(city, grid, paper.city)
        assert layers.road_length.sum() == pytest.approx(total, rel=1e-9)


def test_segment_length_per_cell_by_hand():
    grid = AirspaceGrid(cell=(10.0, 10.0, 10.0), shape=(3, 3, 1))
    # a diagonal through the middle of cells (0,0), (1,1), (2,2), and a horizontal on row j = 1
    seg = np.array([[0.0, 0.0, 30.0, 30.0], [5.0, 15.0, 25.0, 15.0]])
    got = segment_length_per_cell(seg, grid)
    expected = np.zeros((3, 3))
    expected[[0, 1, 2], [0, 1, 2]] += 10.0 * math.sqrt(2)
    expected[0, 1] += 5.0
    expected[1, 1] += 10.0
    expected[2, 1] += 5.0
    np.testing.assert_allclose(got, expected, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(*[st.floats(-20, 120).map(lambda v: round(v, 6))] * 4), min_size=1, max_size=8))
def test_segment_lengths_add_up_inside_the_grid(segments):
    """Every segment's length inside the grid is handed out to columns, no more, no less."""
    grid = AirspaceGrid(cell=(7.0, 11.0, 1.0), shape=(14, 9, 1))  # 98 m × 99 m
    seg = np.asarray(segments)
    got = segment_length_per_cell(seg, grid).sum()
    domain = box(0, 0, 98, 99)
    expected = sum(LineString([(a, b), (c, d)]).intersection(domain).length for a, b, c, d in seg)
    assert got == pytest.approx(expected, rel=1e-9, abs=1e-9)


def test_burn_max_keeps_the_tallest_and_touches_conservatively():
    grid = AirspaceGrid(cell=(10.0, 10.0, 10.0), shape=(4, 4, 1))
    shapes = [box(0, 0, 20, 20), box(5, 5, 12, 12), box(31, 31, 32, 32)]
    out = burn_max(shapes, np.array([30.0, 80.0, 10.0]), grid)
    assert out[0, 0] == 80.0 and out[1, 1] == 80.0 and out[1, 0] == 80.0  # the tall box touches 4 cells
    assert out[3, 3] == 10.0 and out[2, 2] == 0.0
    # orientation: a box in the north-east (large x, small y) lands at i = 3, j = 0
    ne = burn_max([box(31, 1, 39, 9)], np.array([5.0]), grid)
    assert ne[3, 0] == 5.0 and ne.sum() == 5.0


def test_rasterize_city_shelter_and_no_fly():
    grid = AirspaceGrid(cell=(10.0, 10.0, 10.0), shape=(4, 4, 2))
    city = VectorCity(
        extent=(40.0, 40.0), buildings=[box(1, 1, 9, 9), box(21, 21, 29, 29)], heights_m=np.array([10.0, 40.0]),
        roads=[LineString([(0, 15), (40, 15)])], no_fly=[box(31, 31, 39, 39)], open_space=[], source="test",
    )
    layers = rasterize_city(city, grid, CityConfig())
    assert layers.shelter[0, 0] == 0.5 and layers.shelter[2, 2] == 0.75 and layers.shelter[3, 0] == 0.5
    assert layers.no_fly[3, 3] and layers.no_fly.sum() == 1
    np.testing.assert_allclose(layers.road_length[:, 1], 10.0)
