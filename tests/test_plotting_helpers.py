"""Helpers of the figures on hand cases: credit, cell outlines and runs, the page grid in inches,
track geometry; and the rendered track page shows every stage in its Fig. 18 colour."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from matplotlib import colors, image
from matplotlib.figure import Figure

from uamopt import plotting
from uamopt.plotting.draw import outline, runs
from uamopt.plotting.geometry import along_track_m, pair_directions, route_waypoints
from uamopt.plotting.layout import attribution, inch_grid
from uamopt.plotting.style import OSM_CREDIT


def _credited(field, text: str, source: str | None = None):
    city = dataclasses.replace(field.city, attribution=text, source=source or field.city.source)
    return dataclasses.replace(field, city=city)


def test_osm_source_is_always_credited(paper_run):
    field = paper_run.field
    assert attribution(_credited(field, "", "osm")) == OSM_CREDIT
    assert attribution(_credited(field, "Helsinki extract. " + OSM_CREDIT, "osm")).count("OpenStreetMap") == 1
    assert attribution(_credited(field, "", "synthetic")) == ""


def test_outline_and_runs_of_a_hand_mask():
    # cells (0, 0), (1, 0) and (1, 1) of a 3 x 2 grid of 10 m x 20 m cells: an L of 3 cells
    mask = np.array([[True, False], [True, True], [False, False]])
    xe, ye = np.array([0.0, 10.0, 20.0, 30.0]), np.array([0.0, 20.0, 40.0])
    segments = outline(mask, xe, ye)
    lengths = np.hypot(*(segments[:, 1] - segments[:, 0]).T)
    # the L's perimeter, face by face: 4 faces of 10 m (x) and 4 of 20 m (y)
    assert len(segments) == 8
    assert lengths.sum() == pytest.approx(2 * 20 + 2 * 40)
    rectangles = runs(mask, xe, ye)  # row y0-20: x 0-20; row y20-40: x 10-20
    assert sorted(map(tuple, rectangles[:, [0, 2]].reshape(-1, 4))) == [(0.0, 0.0, 20.0, 20.0),
                                                                       (10.0, 20.0, 20.0, 40.0)]


def test_inch_grid_keeps_margins_and_gaps_in_inches():
    fig = Figure(figsize=(10.0, 5.0))
    grid = inch_grid(fig, 2, 3, left=1.0, right=0.5, bottom=0.5, top=1.0, wgap=0.75, hgap=0.5,
                     width_ratios=[1.0, 2.0, 1.0])
    boxes = [[grid[r, c].get_position(fig) for c in range(3)] for r in range(2)]
    x = [(b.x0 * 10.0, b.x1 * 10.0) for b in boxes[0]]  # inches
    y = [(row[0].y0 * 5.0, row[0].y1 * 5.0) for row in boxes]
    # 10 in − 1 − 0.5 − 2 gaps of 0.75 = 7 in over ratios 1:2:1
    np.testing.assert_allclose(x, [(1.0, 2.75), (3.5, 7.0), (7.75, 9.5)])
    # 5 in − 0.5 − 1 − 0.5 = 3 in over two rows, top row first
    np.testing.assert_allclose(y, [(2.5, 4.0), (0.5, 2.0)])


def test_track_geometry_on_hand_cases():
    a, b, c = [0.0, 0.0, 120.0], [1000.0, 0.0, 120.0], [0.0, 800.0, 120.0]
    tracks = {"A-B": np.array([a, b]), "A-C": np.array([a, c]), "B-A": np.array([b, a]) + np.array([0, 0, 30])}
    assert pair_directions(tracks, tolerance_m=10.0) == [("A-B", "B-A"), ("A-C", None)]
    np.testing.assert_allclose(along_track_m(np.array([[0, 0, 0], [3, 4, 10], [3, 4, 20]])), [0, 5, 5])
    document = {"routes": {"A-B": {"waypoints": [a, b]}}}  # as network.json holds it
    np.testing.assert_array_equal(route_waypoints(document)["A-B"], np.array([a, b]))


def test_track_page_shows_every_stage_and_credits_openstreetmap(paper_run, tmp_path):
    from uamopt.planning import plan_track, planning_model

    model = planning_model(paper_run.scenario, paper_run.field)
    plan = plan_track(model, "V1", "V4")
    credited = dataclasses.replace(model, field=_credited(model.field, OSM_CREDIT, "osm"))
    page = plotting.tracks(plan, credited, title="paper_case")
    assert OSM_CREDIT in {t.get_text() for t in page.texts}
    png = image.imread(plotting.save(page, tmp_path / "tracks.png"))[:, :, :3]
    for name, colour in (("shortest", "#d62728"), ("initial", "#ff7f0e"), ("equivalent", "#f2c200"),
                         ("optimal", "#138a2e")):  # Fig. 18: red, orange, gold, green
        assert np.any(np.all(np.abs(png - np.asarray(colors.to_rgb(colour))) <= 4 / 255, axis=2)), name
