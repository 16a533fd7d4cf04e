"""The risk figure: written, of the promised size, credited; the outline helper on a hand case."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from matplotlib import image

from uamopt.plots import (
    DPI,
    FIGSIZE_IN,
    OSM_CREDIT,
    _attribution,
    _outline,
    _runs,
    plot_risk,
)

PIXELS = (round(FIGSIZE_IN[1] * DPI), round(FIGSIZE_IN[0] * DPI))  # (rows, columns) = (1040, 1820)


@pytest.fixture(scope="module")
def paper(paper_run):
    return paper_run.scenario, paper_run.field


def _credited(field, text: str, source: str | None = None):
    city = dataclasses.replace(field.city, attribution=text, source=source or field.city.source)
    return dataclasses.replace(field, city=city)


@pytest.fixture(scope="module")
def pictures(paper, tmp_path_factory):
    """The paper case drawn with an OSM-style credit, and without any attribution."""
    scenario, field = paper
    folder = tmp_path_factory.mktemp("plots")
    credited = plot_risk(_credited(field, OSM_CREDIT, "osm"), folder / "risk.png",
                         vertiports=scenario.network.vertiports,
                         cruise_altitude_m=scenario.network.cruise_altitude_m, title=scenario.name)
    blank = plot_risk(_credited(field, ""), folder / "blank.png")
    return credited, blank, folder


def _corner(png: np.ndarray) -> np.ndarray:
    """The bottom-right strip where the attribution goes (RGB)."""
    return png[-12:, -PIXELS[1] // 4:, :3]


def test_plot_risk_writes_png_of_expected_size(pictures):
    credited, _, folder = pictures
    assert credited == folder / "risk.png"
    assert credited.stat().st_size > 50_000
    png = image.imread(credited)
    assert png.shape[:2] == PIXELS
    # a picture, not a blank page: many distinct colours
    rgb = (png[..., :3] * 255).astype(np.uint32)
    assert len(np.unique(rgb[..., 0] << 16 | rgb[..., 1] << 8 | rgb[..., 2])) > 500


def test_attribution_is_printed_in_the_corner(pictures):
    credited, blank, _ = pictures
    credited, blank = image.imread(credited), image.imread(blank)
    assert credited.shape == blank.shape
    assert np.all(_corner(blank) == 1.0)  # nothing there without attribution
    assert np.any(_corner(credited) < 0.5)  # dark text there with it


def test_osm_source_is_always_credited(paper):
    _, field = paper
    assert _attribution(_credited(field, "", "osm")) == OSM_CREDIT
    assert _attribution(_credited(field, "Helsinki extract. " + OSM_CREDIT, "osm")).count("OpenStreetMap") == 1
    assert _attribution(_credited(field, "", "synthetic")) == ""


def test_outline_and_runs_of_a_hand_mask():
    # cells (0, 0), (1, 0) and (1, 1) of a 3 x 2 grid of 10 m x 20 m cells: an L of 3 cells
    mask = np.array([[True, False], [True, True], [False, False]])
    xe, ye = np.array([0.0, 10.0, 20.0, 30.0]), np.array([0.0, 20.0, 40.0])
    segments = _outline(mask, xe, ye)
    lengths = np.hypot(*(segments[:, 1] - segments[:, 0]).T)
    # the L's perimeter, face by face: 4 faces of 10 m (x) and 4 of 20 m (y)
    assert len(segments) == 8
    assert lengths.sum() == pytest.approx(2 * 20 + 2 * 40)
    rectangles = _runs(mask, xe, ye)  # row y0-20: x 0-20; row y20-40: x 10-20
    assert sorted(map(tuple, rectangles[:, [0, 2]].reshape(-1, 4))) == [(0.0, 0.0, 20.0, 20.0),
                                                                       (10.0, 20.0, 20.0, 40.0)]
