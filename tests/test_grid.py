"""The airspace grid of Sec. 3."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st

from uamopt.errors import GridError
from uamopt.grid import AirspaceGrid, altitude_band
from uamopt.pipeline import scenario_grid
from uamopt.scenario import Scenario


def test_paper_example_cell_centre():
    """The paper's 1-based (2, 3, 4) is 0-based (1, 2, 3) with centre (1.5Δx, 2.5Δy, 3.5Δz)."""
    g = AirspaceGrid(cell=(50.0, 50.0, 30.0), shape=(10, 10, 10))
    assert g.centre_of((1, 2, 3)) == (75.0, 125.0, 105.0)


def test_from_extent_counts_whole_cells():
    g = AirspaceGrid.from_extent((50.0, 50.0, 30.0), (2500.0, 4500.0, 360.0))
    assert g.shape == (50, 90, 12) and g.n_cells == 54000
    assert AirspaceGrid.from_extent((30.0, 30.0, 30.0), (100.0, 100.0, 100.0)).shape == (3, 3, 3)
    np.testing.assert_allclose(g.z[:3], [15.0, 45.0, 75.0])
    np.testing.assert_allclose(g.edges(0)[-1], 2500.0)


def test_empty_domain_and_bad_cells():
    with pytest.raises(GridError, match="no cells"):
        AirspaceGrid.from_extent((50.0, 50.0, 30.0), (40.0, 100.0, 100.0))
    with pytest.raises(GridError, match="positive"):
        AirspaceGrid(cell=(0.0, 1.0, 1.0), shape=(1, 1, 1))


def test_points_outside():
    g = AirspaceGrid(cell=(10.0, 10.0, 10.0), shape=(5, 5, 5))
    assert g.index_of((50.0, 50.0, 50.0)) == (4, 4, 4)  # the far boundary belongs to the last cell
    with pytest.raises(GridError, match="outside"):
        g.index_of((-1.0, 5.0, 5.0))
    with pytest.raises(GridError, match="outside"):
        g.index_of((5.0, 5.0, 50.5))


@given(
    cell=st.tuples(*[st.floats(1.0, 100.0)] * 3),
    shape=st.tuples(*[st.integers(1, 50)] * 3),
    frac=st.tuples(*[st.floats(0.0, 0.999)] * 3),
)
def test_index_coordinate_round_trip(cell, shape, frac):
    g = AirspaceGrid(cell=cell, shape=shape)
    idx = tuple(int(f * n) for f, n in zip(frac, shape, strict=True))
    assert g.index_of(g.centre_of(idx)) == idx


def test_altitude_band_eq14():
    s = Scenario()
    assert altitude_band(s) == (90.0, 300.0)
    g = AirspaceGrid(cell=(50.0, 50.0, 30.0), shape=(2, 2, 12))
    assert list(g.layers_in_band(*altitude_band(s))) == [3, 4, 5, 6, 7, 8, 9]  # 105 .. 285 m
    s2 = s.with_overrides(["aircraft.h_max=200", "grid.h_min_airspace=120"])
    assert altitude_band(s2) == (120.0, 200.0)


def test_build_grid_uses_extent_or_city(root):
    s = Scenario()
    g = scenario_grid(s)  # synthetic city extent, z up to h'_max
    assert g.extent == (2500.0, 4500.0, 300.0)
