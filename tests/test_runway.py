"""The one-runway method behind ``discovery`` (uamopt/solvers/runway.py): its path programme
against an exhaustive one written here, its bound against brute force, and its proofs against the
published airland optima.

The oracles here share nothing with runway.py: the paths are enumerated by a plain dynamic
programme over every (flight, time) pair and the full separation matrix (no classes, no prefix
minima, no best-two lists), and the optima come from :mod:`uamopt.solvers.bruteforce` or from
OR-Library (tests/data/airland/README.md)."""

from __future__ import annotations

import dataclasses
import itertools
from pathlib import Path

import numpy as np
import pytest

import uamopt as ua
from uamopt.errors import UamoptError
from uamopt.solvers import runway

DATA = Path(__file__).parent / "data" / "airland"
PUBLISHED = {1: 700, 2: 1480, 3: 820, 4: 2520, 5: 3100, 6: 24442, 7: 1550, 8: 1950}  # OR-Library, one runway
SLOW = {6, 7}


def write_instance(path: Path, rng: np.random.Generator, n: int, classes: int, window: int) -> Path:
    """A random airland file: n aircraft of ``classes`` wake classes (separation by class pair, 1-3
    time units), windows of ``window`` units, targets inside, costs in [1, 3]."""
    cls = rng.integers(0, classes, n)
    by_class = rng.integers(1, 4, (classes, classes))
    lines = [f"{n} 0"]
    for i in range(n):
        e = int(rng.integers(0, 6))
        t = e + int(rng.integers(0, window + 1))
        lines.append(f"0 {e} {t} {e + window} {rng.integers(1, 4)}.0 {rng.integers(1, 4)}.0")
        lines.append(" ".join(str(int(by_class[cls[i], cls[j]])) if i != j else "99999" for j in range(n)))
    path.write_text("\n".join(lines) + "\n")
    return path


def all_paths_min(r: runway.Runway, reduced: np.ndarray):
    """(least path value, least value through each landing) by plain dynamic programmes over every
    landing and the full separation matrix: a path lands flights at increasing times, consecutive
    landings (p, q) at least sep[p, q] apart, never one flight twice in a row; the empty path is 0."""
    landings = [(j, int(r.start[j] + k), int(r.offset[j] + k)) for j in range(r.n) for k in range(int(r.length[j]))]
    landings.sort(key=lambda x: x[1])
    ending, starting = {}, {}
    for j, t, at in landings:  # best path ending with this landing
        best = 0.0
        for i, s, other in landings:
            if i != j and s + r.sep[i, j] <= t and other in ending:
                best = min(best, ending[other])
        ending[at] = reduced[at] + best
    for j, t, at in reversed(landings):  # best path starting with it
        best = 0.0
        for i, s, other in landings:
            if i != j and t + r.sep[j, i] <= s and other in starting:
                best = min(best, starting[other])
        starting[at] = reduced[at] + best
    through = np.array([ending[a] + starting[a] - reduced[a] for a in range(r.offset[-1])])
    return min(0.0, min(ending.values())), through


def labels_two(r: runway.Runway, reduced: np.ndarray, backward: bool = False) -> dict:
    """{(landing, neighbour or -1): least value of a path ending (backward: starting) with that
    landing, its neighbour before (after) it as given}, when no flight may come back after one other
    either (no p, q, p): a plain programme over (landing, neighbour)."""
    landings = [(j, int(r.start[j] + k), int(r.offset[j] + k)) for j in range(r.n) for k in range(int(r.length[j]))]
    landings.sort(key=lambda x: -x[1] if backward else x[1])
    where = {a: (j, t) for j, t, a in landings}
    best: dict = {}
    for j, t, at in landings:
        best[(at, -1)] = reduced[at]
        for (other, before), value in list(best.items()):
            i, s = where[other]
            apart = s - t >= r.sep[j, i] if backward else t - s >= r.sep[i, j]
            if i != j and before != j and apart:
                best[(at, i)] = min(best.get((at, i), np.inf), reduced[at] + value)
    return best


def all_paths_min_two(r: runway.Runway, reduced: np.ndarray) -> float:
    """The least path value without p, q, p (:func:`labels_two`); the empty path is 0."""
    return min(0.0, min(labels_two(r, reduced).values()))


def through_two(r: runway.Runway, reduced: np.ndarray) -> np.ndarray:
    """The least value of a path without p, q, p through each landing: a path ending there and one
    starting there whose neighbours differ (or either is none)."""
    ending, starting = labels_two(r, reduced), labels_two(r, reduced, backward=True)
    out = np.full(r.offset[-1], np.inf)
    for (at, before), f in ending.items():
        for (at2, after), b in starting.items():
            if at2 == at and (before != after or before == -1):
                out[at] = min(out[at], f + b - reduced[at])
    return out


@pytest.mark.parametrize("seed", range(10))
def test_the_two_cycle_programme_matches_an_exhaustive_one(tmp_path, seed):
    rng = np.random.default_rng(50 + seed)
    problem = ua.read_airland(write_instance(tmp_path / "a.txt", rng, n=5, classes=2, window=5))
    r = runway.of(problem)
    for _ in range(3):
        lam = rng.uniform(0.0, 12.0, r.n)
        reduced = r.cost - np.repeat(lam, r.length)
        exact = lam.sum() + r.constant + all_paths_min_two(r, reduced)
        # with room for every label the programme is exact, and its path has no p, q, p
        value, flights, _ = runway.path_bound(r, lam, two_cycle=True, keep=4 * r.n)
        assert value == pytest.approx(exact, abs=1e-9)
        assert all(a != c for a, c in zip(flights, flights[2:], strict=False))
        # with the default room a label may stand in for an excluded one: between the two programmes' values
        value = runway.path_bound(r, lam, two_cycle=True)[0]
        assert runway.path_bound(r, lam)[0] - 1e-9 <= value <= exact + 1e-9
        # the value through each landing (reduced-cost fixing): a bound, never above the exact one
        exact_through = through_two(r, reduced)
        roomy = runway.through(r, lam, two_cycle=True, keep=4 * r.n) - lam.sum() - r.constant
        assert np.allclose(roomy, exact_through, atol=1e-9)
        got = runway.through(r, lam, two_cycle=True) - lam.sum() - r.constant
        assert np.all(got <= exact_through + 1e-9)
        assert np.all(got >= runway.through(r, lam) - lam.sum() - r.constant - 1e-9)


@pytest.mark.parametrize("seed", range(6))
def test_the_path_programme_matches_an_exhaustive_one(tmp_path, seed):
    rng = np.random.default_rng(seed)
    problem = ua.read_airland(write_instance(tmp_path / "a.txt", rng, n=5, classes=2, window=6))
    r = runway.of(problem)
    assert isinstance(r, runway.Runway), r
    for _ in range(3):
        lam = rng.uniform(0.0, 12.0, r.n)
        reduced = r.cost - np.repeat(lam, r.length)
        best, through = all_paths_min(r, reduced)
        value, flights, times = runway.path_bound(r, lam)
        assert value == pytest.approx(lam.sum() + r.constant + best, abs=1e-9)
        # the path it returns is a path, and its value is the one reported
        assert all(a != b for a, b in itertools.pairwise(flights))
        assert all(t2 - t1 >= r.sep[a, b] for (a, t1), (b, t2) in itertools.pairwise(zip(flights, times, strict=True)))
        got = sum(reduced[r.offset[j] + t - r.start[j]] for j, t in zip(flights, times, strict=True))
        assert lam.sum() + r.constant + got == pytest.approx(value, abs=1e-9)
        assert np.allclose(runway.through(r, lam), lam.sum() + r.constant + through, atol=1e-9)


@pytest.mark.parametrize("seed", range(8))
def test_the_bound_never_exceeds_the_brute_force_optimum_and_discovery_proves_it(tmp_path, seed):
    from uamopt.solvers import bruteforce

    rng = np.random.default_rng(100 + seed)
    problem = ua.read_airland(write_instance(tmp_path / "a.txt", rng, n=6, classes=3, window=12))
    brute = bruteforce.solve(problem)
    r = runway.of(problem)
    for _ in range(5):
        lam = rng.uniform(-5.0, 30.0, r.n)
        assert runway.path_bound(r, lam)[0] <= brute.objective + 1e-9
    schedule = ua.solve(problem, "discovery", time_limit_s=60, threads=1)
    assert schedule.status == "optimal"
    assert schedule.objective == pytest.approx(brute.objective, abs=1e-9)
    assert schedule.bound <= brute.objective + 1e-9
    assert ua.verify(problem, schedule).ok


@pytest.mark.parametrize("k", [pytest.param(k, marks=pytest.mark.slow) if k in SLOW else k for k in sorted(PUBLISHED)])
def test_discovery_proves_the_published_airland_optima(k):
    problem = ua.read_airland(DATA / f"airland{k}.txt")
    # 1 thread, load 0.8: airland6 and 7 in 18 s each, the others in under 3 s; limits with room for load 8
    schedule = ua.solve(problem, "discovery", time_limit_s=300 if k in SLOW else 60, threads=1)
    assert schedule.status == "optimal"
    assert schedule.objective == pytest.approx(PUBLISHED[k], abs=1e-6)
    assert schedule.bound == pytest.approx(PUBLISHED[k], rel=1e-9)
    assert ua.verify(problem, schedule).ok


def test_the_shape_is_recognised_and_anything_else_is_named():
    problem = ua.read_airland(DATA / "airland1.txt")
    assert isinstance(runway.of(problem), runway.Runway)
    optional = dataclasses.replace(problem, must_operate=np.zeros(problem.n_flights, dtype=bool))
    assert runway.of(optional) == "a flight that may be cancelled"
    with pytest.raises(UamoptError) as err:
        ua.solve(optional, "discovery", time_limit_s=10)
    text = str(err.value)
    assert "one-runway" in text and "a flight that may be cancelled" in text and "\n" not in text
