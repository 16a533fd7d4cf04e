"""Exact cell occupancy and forbidden departure gaps (uamopt/schedule/occupancy.py)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from uamopt.schedule import occupancy
from uamopt.schedule.flights import Flight, FlightSet
from uamopt.schedule.occupancy import (
    conflict_table,
    flight_occupancies,
    forbidden_gaps,
    track_occupancy,
    track_pair_gaps,
)
from uamopt.schedule.verify import cell_visits

CUBE = (10.0, 10.0, 10.0)


def visits(occ):
    return [(tuple(c), a, b) for c, a, b in zip(occ.cells.tolist(), occ.t_in.tolist(), occ.t_out.tolist(), strict=True)]


def test_axis_aligned_track_known_times():
    occ = track_occupancy(np.array([[5.0, 5, 5], [35.0, 5, 5]]), 10.0, CUBE)
    assert occ.cells.tolist() == [[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]
    np.testing.assert_allclose(occ.t_in, [0.0, 0.5, 1.5, 2.5])
    np.testing.assert_allclose(occ.t_out, [0.5, 1.5, 2.5, 3.0])


def test_diagonal_through_corners_has_no_spurious_neighbour_visits():
    # (0,0) -> (30,30) crosses x and y planes together at the cell corners
    occ = track_occupancy(np.array([[0.0, 0, 5], [30.0, 30, 5]]), np.sqrt(2.0), CUBE)
    assert occ.cells.tolist() == [[0, 0, 0], [1, 1, 0], [2, 2, 0]]
    np.testing.assert_allclose(occ.t_in, [0.0, 10.0, 20.0], atol=1e-12)
    # a 3-D diagonal through the corners of cubes
    occ = track_occupancy(np.array([[0.0, 0, 0], [20.0, 20, 20]]), np.sqrt(3.0), CUBE)
    assert occ.cells.tolist() == [[0, 0, 0], [1, 1, 1]]
    np.testing.assert_allclose(occ.t_out, [10.0, 20.0])


def test_vertical_and_polyline_and_plane_conventions():
    # climb from 5 to 25 m, then level exactly in the plane z = 30? no: along z = 25, then descend
    track = np.array([[5.0, 5, 5], [5.0, 5, 25], [15.0, 5, 25], [15.0, 5, 5]])
    occ = track_occupancy(track, 5.0, CUBE)
    assert occ.cells.tolist() == [[0, 0, 0], [0, 0, 1], [0, 0, 2], [1, 0, 2], [1, 0, 1], [1, 0, 0]]
    np.testing.assert_allclose(occ.t_in, [0, 1, 3, 5, 7, 9])
    np.testing.assert_allclose(occ.t_out[-1], 10.0)
    # level flight exactly in a grid plane is in the upper cell; descending from a plane is in the lower
    occ = track_occupancy(np.array([[5.0, 5, 20], [25.0, 5, 20], [25.0, 5, 0]]), 10.0, CUBE)
    assert occ.cells.tolist() == [[0, 0, 2], [1, 0, 2], [2, 0, 2], [2, 0, 1], [2, 0, 0]]
    np.testing.assert_allclose(occ.t_in, [0.0, 0.5, 1.5, 2.0, 3.0])


def test_occupied_time_equals_flight_time():
    rng = np.random.default_rng(3)
    for _ in range(20):
        track = rng.uniform(0, 200, size=(rng.integers(2, 7), 3))
        length = np.sum(np.linalg.norm(np.diff(track, axis=0), axis=1))
        occ = track_occupancy(track, 7.0, (10.0, 20.0, 5.0))
        assert np.isclose(np.sum(occ.t_out - occ.t_in), length / 7.0)
        np.testing.assert_array_equal(occ.t_out[:-1], occ.t_in[1:])
        assert np.all(occ.t_out > occ.t_in)
        assert np.all(np.max(np.abs(np.diff(occ.cells, axis=0)), axis=1) <= 1)  # moves to a neighbour


# whole metres hit grid planes, edges and corners exactly; µm-rounded floats avoid denormal underflow
coord = st.one_of(st.integers(0, 60).map(float), st.floats(0.0, 60.0).map(lambda v: round(v, 6)))


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(points=st.lists(st.tuples(coord, coord, coord), min_size=2, max_size=6),
       speed=st.floats(0.5, 50.0), cell=st.sampled_from([(10.0, 10.0, 10.0), (7.0, 10.0, 3.0), (0.3, 0.7, 1.1)]))
def test_vectorised_occupancy_equals_verifier(points, speed, cell):
    track = np.array(points)
    if np.sum(np.linalg.norm(np.diff(track, axis=0), axis=1)) / speed < 1e-6:
        return  # a flight of no duration
    fast = visits(track_occupancy(track, speed, cell))
    slow = cell_visits([tuple(p) for p in points], speed, cell)
    assert [c for c, _, _ in fast] == [c for c, _, _ in slow]
    np.testing.assert_allclose([a for _, a, _ in fast], [a for _, a, _ in slow], atol=1e-6)
    np.testing.assert_allclose([b for _, _, b in fast], [b for _, _, b in slow], atol=1e-6)


def _flight(fid, aircraft, track, dep, max_delay, speed=10.0):
    wp = np.asarray(track, dtype=float)
    return Flight(fid, aircraft, "r", "a", "b", speed, dep, max_delay, wp)


def _overlap_brute(occ_p, occ_q, delta, radius):
    """Direct check: do the two flights (p departs at 0, q at delta) conflict?"""
    near = np.max(np.abs(occ_p.cells[:, None, :] - occ_q.cells[None, :, :]), axis=2) <= radius
    lo = np.maximum(occ_p.t_in[:, None], occ_q.t_in[None, :] + delta)
    hi = np.minimum(occ_p.t_out[:, None], occ_q.t_out[None, :] + delta)
    return bool(np.any(near & (hi - lo > 0)))


@pytest.mark.parametrize("radius", [0, 1])
def test_forbidden_intervals_match_brute_force(radius):
    rng = np.random.default_rng(11)
    tracks = [
        [[5, 5, 15], [95, 5, 15]],            # along x
        [[95, 5, 25], [5, 5, 25]],            # the reverse, one layer up
        [[50, -0.0, 15], [50, 90, 15]],       # crossing at x = 50 (on a plane)
        [[10, 80, 5], [60, 20, 35], [90, 90, 15]],  # a bent 3-D track
    ]
    tracks = [np.abs(np.array(t, dtype=float)) for t in tracks]
    flights = tuple(_flight(f"F{i}", f"A{i}", tracks[i % 4], float(rng.integers(0, 20)), 30.0) for i in range(8))
    fs = FlightSet(cell=CUBE, conflict_radius=radius, flights=flights, service_end_s=10_000.0)
    occs, key = flight_occupancies(fs)
    conflicts = {(c.p, c.q): c.intervals for c in forbidden_gaps(fs)}
    dep, upper = fs.planned_departure_s, fs.delay_upper_s
    checked = 0
    for p, q in itertools.combinations(range(len(fs)), 2):
        deltas = np.linspace(dep[q] - dep[p] - upper[p], dep[q] - dep[p] + upper[q], 997)
        iv = conflicts.get((p, q), np.zeros((0, 2)))
        for delta in deltas:
            edge = np.min(np.abs(iv - delta)) if len(iv) else 1.0
            if edge < 1e-6:
                continue
            inside = bool(np.any((iv[:, 0] < delta) & (delta < iv[:, 1])))
            assert inside == _overlap_brute(occs[key[p]], occs[key[q]], delta, radius), (p, q, delta)
            checked += 1
    assert checked > 20000 and len(conflicts) > 5


def _clipped(fs, table):
    """{(p, q): intervals clipped to the pair's feasible range of δ}."""
    dep, upper = fs.planned_departure_s, fs.delay_upper_s
    out = {}
    for c in table:
        lo, hi = dep[c.q] - dep[c.p] - upper[c.p], dep[c.q] - dep[c.p] + upper[c.q]
        out[(c.p, c.q)] = np.clip(c.intervals, lo, hi)
    return out


@pytest.mark.parametrize("radius", [0, 1])
def test_flight_level_join_equals_track_level(radius, monkeypatch):
    """Forcing the per-flight join (as for many distinct tracks) gives the same constraints."""
    rng = np.random.default_rng(5)
    base = [[[5, 5, 15], [95, 5, 15]], [[95, 5, 25], [5, 5, 25]], [[50, 0, 15], [50, 90, 15]],
            [[10, 80, 5], [60, 20, 35], [90, 90, 15]]]
    flights = []
    for i in range(60):
        track = np.array(base[i % 4], dtype=float)
        if i % 3 == 0:  # a third of the flights get a track of their own
            track[1:-1 if len(track) > 2 else None, :2] += rng.uniform(-4, 4, 2)
        flights.append(_flight(f"F{i}", f"A{i % 17}", np.clip(track, 0, 100), 100.0 * (i // 17) + float(rng.integers(0, 60)),
                               25.0))
    fs = FlightSet(cell=CUBE, conflict_radius=radius, flights=tuple(flights), service_end_s=10_000.0,
                   outbound_gap_s=0.0, return_gap_s=0.0)
    track_level, flight_level = conflict_table(fs), conflict_table(fs, max_track_pairs=0)
    a, b = _clipped(fs, track_level), _clipped(fs, flight_level)
    assert len(a) > 50 and a.keys() == b.keys()
    for k in a:
        np.testing.assert_allclose(a[k], b[k], atol=1e-9)
    # many small chunks of groups and passes of rows (as for millions of pairs) give the same table
    monkeypatch.setattr(occupancy, "OFFSET_LIMIT", 300.0)
    monkeypatch.setattr(occupancy, "ROWS_PER_PASS", 500)  # the per-flight join in many passes
    for forced in (None, 0):
        small = conflict_table(fs) if forced is None else conflict_table(fs, max_track_pairs=0)
        big = track_level if forced is None else flight_level
        assert np.array_equal(small.p, big.p) and np.array_equal(small.q, big.q)
        np.testing.assert_array_equal(small.intervals, big.intervals)


def test_track_pair_gaps_same_track():
    """Following on one track: cells of 1 s each, so in the 3×3×3 zone the follower must stay
    two cells (2 s) behind or ahead: δ ∉ (−2, 2); with r = 0 one cell: δ ∉ (−1, 1)."""
    occ = track_occupancy(np.array([[5.0, 5, 5], [95.0, 5, 5]]), 10.0, CUBE)
    for radius, half in ((1, 2.0), (0, 1.0)):
        code, ptr, lo, hi = track_pair_gaps([occ], radius)
        assert code.tolist() == [0] and ptr.tolist() == [0, 1]
        np.testing.assert_allclose([lo[0], hi[0]], [-half, half])


def test_pruning_by_departure_windows():
    track = [[5, 5, 5], [95, 5, 5]]
    early = _flight("F1", "A1", track, 0.0, 5.0)
    late = _flight("F2", "A2", track, 100.0, 5.0)  # can never meet the first
    close = _flight("F3", "A3", track, 3.0, 0.0)
    fs = FlightSet(cell=CUBE, conflict_radius=1, flights=(early, late, close), service_end_s=1000.0)
    pairs = {(c.p, c.q) for c in forbidden_gaps(fs)}
    assert pairs == {(0, 2)}


def test_docstring_examples_run():
    import doctest

    from uamopt.schedule import occupancy, plan

    for module in (occupancy, plan):
        assert doctest.testmod(module).failed == 0
