"""The clearance of Eq. 15 (uamopt.planning.problem.clearance_ok): ``edt``'s float32 squared
transform with an exact cut gives the cells scipy's float64 transform gives (the reference, as
the code used before), and both agree with a brute-force check of every building cell on a
small grid (an oracle sharing no code with either)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy import ndimage

from uamopt.planning.problem import clearance_ok, clearance_threshold_sq


def columns(shape, seed: int, share: float = 0.08) -> np.ndarray:
    """Buildings as the city makes them: columns from the ground to a random top layer."""
    rng = np.random.default_rng(seed)
    top = np.where(rng.random(shape[:2]) < share, rng.integers(1, shape[2] + 1, shape[:2]), 0)
    return np.arange(shape[2])[None, None, :] < top[:, :, None]


def scipy_reference(building, cell, clearance_m):
    return ndimage.distance_transform_edt(~building, sampling=cell) >= clearance_m - 1e-9


def brute_force(building, cell, clearance_m):
    """Every free cell against every building cell, in float64."""
    ok = np.ones(building.shape, dtype=bool)
    b = np.argwhere(building) * np.asarray(cell)
    for idx in itertools.product(*map(range, building.shape)):
        if building[idx]:
            ok[idx] = False
            continue
        d = np.sqrt(np.sum((b - np.asarray(idx) * np.asarray(cell)) ** 2, axis=1))
        ok[idx] = not np.any(d < clearance_m - 1e-9)
    return ok


CELLS = [((10.0, 10.0, 10.0), 50.0), ((50.0, 50.0, 30.0), 50.0), ((25.0, 25.0, 30.0), 50.0),
         ((7.3, 7.3, 7.3), 21.9), ((10.0, 20.0, 5.0), 30.0), ((12.5, 12.5, 30.0), 37.5), ((5.0, 5.0, 5.0), 50.0)]


@pytest.mark.parametrize(("cell", "clearance"), CELLS)
def test_clearance_equals_scipys_float64_transform(cell, clearance):
    for seed in range(3):
        building = columns((60, 50, 30), seed)
        assert np.array_equal(clearance_ok(building, cell, clearance), scipy_reference(building, cell, clearance))


@pytest.mark.parametrize(("cell", "clearance"), [((10.0, 10.0, 10.0), 30.0), ((7.3, 7.3, 7.3), 21.9),
                                                 ((10.0, 20.0, 5.0), 25.0)])
def test_clearance_equals_a_brute_force_check(cell, clearance):
    building = columns((14, 12, 8), seed=5, share=0.1)
    assert building.any() and not building.all()
    assert np.array_equal(clearance_ok(building, cell, clearance), brute_force(building, cell, clearance))


def test_a_cut_float32_cannot_resolve_falls_back_to_float64():
    """Two centre distances within 10⁻⁵ of each other around s_min: the float64 transform decides."""
    cell = (10.0, 10.0, 10.00001)
    clearance = math.sqrt(2500.0002)  # between (5, 0, 0) cells = 2500 and (0, 0, 5) = 2500.0005
    assert clearance_threshold_sq(cell, clearance) is None
    building = columns((30, 30, 20), seed=2)
    assert np.array_equal(clearance_ok(building, cell, clearance), scipy_reference(building, cell, clearance))
    # and the cut is where a centre 5 cells away along x is too close, along z far enough
    one = np.zeros((11, 11, 11), dtype=bool)
    one[5, 5, 0] = True
    ok = clearance_ok(one, cell, clearance)
    assert not ok[10, 5, 0] and ok[5, 5, 5]


@pytest.mark.parametrize("measure", ["structures", "count", "share"])
def test_shell_counts_of_the_band_equal_the_whole_grids(measure):
    """The model counts R(t) (Eq. 35) on the band's layers only, from the layers within reach; in
    the band it must equal the count over the whole grid (buffer_shell_count, itself checked
    against a brute force in tests/test_tracks.py), and be 0 outside it."""
    import uamopt as ua
    from uamopt.planning.problem import buffer_shell_count

    scenario = ua.load_scenario("paper_case", ["grid.cell=[25,25,10]", f"tracks.buffer_measure={measure!r}"])
    field = ua.compute_risk(scenario)
    model = ua.planning_model(scenario, field)
    occupied = (field.obstacle | field.no_fly) if measure == "structures" else field.unsafe
    whole = buffer_shell_count(occupied, model.n_s).astype(float)
    if measure == "share":
        whole /= float(np.prod(model.n_s) - np.prod([max(n - 2, 0) for n in model.n_s]))
    band = np.zeros(field.grid.shape[2], dtype=bool)
    band[field.band_layers()] = True
    assert 0 < band.sum() < len(band) and model.n_s[2] > 1
    assert np.array_equal(model.shell_count[:, :, band], whole[:, :, band])
    assert not model.shell_count[:, :, ~band].any()
