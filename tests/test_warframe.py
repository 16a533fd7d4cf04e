"""The planner's optimal cost against the public Moving AI 3-D voxel benchmark's optimal lengths.

Two Warframe maps of Brewer and Sturtevant's voxel benchmark (SoCS 2018; credits in
tests/data/warframe/README.md) ship with the tests: ``Simple`` (105 x 132 x 105) and ``Complex``
(246 x 154 x 205), 10,000 scenario rows each. A sample of Simple's rows (about 40, evenly spread over
the file, plus its longest rows) is solved with the fast backend under the "relaxed" and the
"transport" heuristic (with no transport cost the latter is zero: Dijkstra); a few short rows also
with the pure-Python backend, and a few rows of Complex. The costs must match the published ones to
1e-3 (the files print 8 decimals), and every returned path is checked here, move by move, to be a
legal path of that length. The slow tests solve every Simple row and 200 Complex rows. The timing
against tcod is ``tests/benchmarks/bench_voxel.py``.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from uamopt.errors import InputFileError
from uamopt.planning import grid_search
from uamopt.planning.voxel import (
    VoxelScenario,
    read_voxel_map,
    read_voxel_map_text,
    read_voxel_scenarios,
    read_voxel_scenarios_text,
    voxel_problem,
)

BENCHMARKS = Path(__file__).resolve().parent / "data" / "warframe"
SAMPLE_SIZE = 40
LONGEST = 3  # Simple's longest rows, added to the sample
TOLERANCE = 1e-3  # the .3dscen files print costs to 8 decimals


def load(name: str):
    """(map, its problem, all scenario rows) for one benchmark map."""
    if not BENCHMARKS.is_dir():
        pytest.fail(f"Warframe benchmarks not found at {BENCHMARKS}", pytrace=False)
    voxels = read_voxel_map(BENCHMARKS / f"{name}.3dmap")
    return voxels, voxel_problem(voxels), read_voxel_scenarios(BENCHMARKS / f"{name}.3dmap.3dscen")


@pytest.fixture(scope="module")
def simple():
    return load("Simple")


@pytest.fixture(scope="module")
def complex_map():
    return load("Complex")


def sample(rows: list[VoxelScenario], size: int = SAMPLE_SIZE) -> list[VoxelScenario]:
    """Every k-th row counted back from the last (the files are in no order of length)."""
    step = max(1, len(rows) // size)
    return rows[len(rows) - 1::-step][::-1]


def longest(rows: list[VoxelScenario], n: int) -> list[VoxelScenario]:
    return sorted(rows, key=lambda r: r.optimal_cost)[-n:]


def assert_legal_path(passable: np.ndarray, row: VoxelScenario, path: np.ndarray, cost: float) -> None:
    """``path`` joins the row's start and goal by 26-neighbour moves through free voxels, no move cuts
    a corner (every voxel of its bounding box is free), and its Euclidean length is ``cost``."""
    path = np.asarray(path)
    assert path.ndim == 2 and path.shape[1] == 3
    assert tuple(path[0]) == row.start and tuple(path[-1]) == row.goal
    assert ((path >= 0) & (path < passable.shape)).all()
    assert passable[tuple(path.T)].all(), "the path enters a blocked voxel"
    steps = np.diff(path, axis=0)
    assert (np.abs(steps) <= 1).all() and (np.abs(steps).sum(axis=1) > 0).all(), "a move is not to a 26-neighbour"
    for cell, step in zip(path[:-1], steps, strict=True):
        box = itertools.product(*[(0, int(s)) if s else (0,) for s in step])
        assert all(passable[tuple(cell + np.asarray(corner))] for corner in box), f"the move {cell} + {step} cuts a corner"
    length = float(np.sqrt((steps**2).sum(axis=1)).sum())
    assert length == pytest.approx(cost, rel=1e-12, abs=1e-9)


def check_rows(problem, passable, rows, backend: str, heuristics) -> None:
    for row in rows:
        for heuristic in heuristics:
            result = grid_search(problem, row.start, row.goal, backend=backend, heuristic=heuristic)
            assert result.cost == pytest.approx(row.optimal_cost, abs=TOLERANCE), (row, backend, heuristic)
            assert_legal_path(passable, row, result.path, result.cost)


# --- the parser ---------------------------------------------------------------------------------


def test_map_is_read_as_x_y_z():
    voxels = read_voxel_map_text("voxel 3 2 4\n0 0 0\n2 1 3\n\n1 0 2\n")
    assert voxels.size == (3, 2, 4) and voxels.passable.dtype == bool
    blocked = {tuple(int(v) for v in c) for c in np.argwhere(~voxels.passable)}
    assert blocked == {(0, 0, 0), (2, 1, 3), (1, 0, 2)}


def test_map_without_blocked_voxels_is_all_free():
    voxels = read_voxel_map_text("voxel 2 3 1\n", name="open")
    assert voxels.name == "open" and voxels.size == (2, 3, 1) and voxels.passable.all()


def test_problem_costs_are_path_lengths():
    problem = voxel_problem(read_voxel_map_text("voxel 3 3 3\n"))
    assert problem.shape == (3, 3, 3) and (problem.risk == 1).all() and (problem.penalty == 0).all()
    assert (problem.w_risk, problem.c_h, problem.c_v, problem.cell) == (1.0, 0.0, 0.0, (1.0, 1.0, 1.0))
    assert grid_search(problem, (0, 0, 0), (2, 2, 2)).cost == pytest.approx(2 * math.sqrt(3))


def test_diagonal_may_not_cut_a_corner():
    # a single blocked voxel at (1, 0, 0): the diagonal (0,0,0) -> (1,1,0) has it in its box
    problem = voxel_problem(read_voxel_map_text("voxel 2 2 1\n1 0 0\n"))
    result = grid_search(problem, (0, 0, 0), (1, 1, 0))
    assert result.cost == pytest.approx(2.0)
    assert [tuple(c) for c in result.path] == [(0, 0, 0), (0, 1, 0), (1, 1, 0)]


@pytest.mark.parametrize(("text", "match"), [
    ("", "first line of <3dmap> is not 'voxel X Y Z'"),
    ("voxels 2 2 2\n", "is not 'voxel X Y Z'"),
    ("voxel 2 2\n", "is not 'voxel X Y Z'"),
    ("voxel 2 0 2\n", "is not 'voxel X Y Z'"),
    ("voxel 2 x 2\n", "is not 'voxel X Y Z'"),
    ("voxel 2 2 2\n0 0 0\n1 1\n", "line 3 of <3dmap> is not a voxel 'x y z': '1 1'"),
    ("voxel 2 2 2\n0 0 0 0\n", "line 2 of <3dmap> is not a voxel"),
    ("voxel 2 2 2\n0 0 0\n1 a 1\n", "line 3 of <3dmap> is not a voxel 'x y z': '1 a 1'"),
    ("voxel 2 2 2\n1.5 0 0\n", "line 2 of <3dmap> is not a voxel"),
    ("voxel 2 2 2\n0 0 0\n1 2 1\n", r"voxel \(1, 2, 1\) on line 3 of <3dmap> lies outside the map of 2 x 2 x 2"),
    ("voxel 2 2 2\n-1 0 0\n", r"voxel \(-1, 0, 0\) on line 2 .* lies outside"),
])
def test_malformed_map_raises(text, match):
    with pytest.raises(InputFileError, match=match) as error:
        read_voxel_map_text(text)
    assert "\n" not in str(error.value) and "Moving AI .3dmap" in str(error.value)


def test_scenarios_are_read():
    rows = read_voxel_scenarios_text("version 1\nSimple.3dmap\n1 2 3 4 5 6 7.5 1.25\n\n0 0 0 0 0 1 1.00000000 1.000\n")
    assert rows == [VoxelScenario((1, 2, 3), (4, 5, 6), 7.5, 1.25), VoxelScenario((0, 0, 0), (0, 0, 1), 1.0, 1.0)]


@pytest.mark.parametrize(("text", "match"), [
    ("", "first line of <3dscen> is not 'version 1'"),
    ("1 2 3 4 5 6 7.5 1.25\n", "first line of <3dscen> is not 'version 1'"),
    ("version 1\n1 2 3 4 5 6 7.5 1.25\n", "line 2 of <3dscen> is not a map name"),
    ("version 1\nm.3dmap\n1 2 3 4 5 6 7.5\n", "line 3 of <3dscen> is not a scenario row: '1 2 3 4 5 6 7.5'"),
    ("version 1\nm.3dmap\n1 2 3 4 5 6 7.5 1.2 9\n", "line 3 of <3dscen> is not a scenario row"),
    ("version 1\nm.3dmap\n1 2 3 4 5 6 7.5 1.2\n1 2 3 4 5 x 7.5 1.2\n", "line 4 of <3dscen> is not a scenario row"),
    ("version 1\nm.3dmap\n1 2 3 4 5 6 nan 1.2\n", "line 3 of <3dscen> is not a scenario row"),
])
def test_malformed_scenarios_raise(text, match):
    with pytest.raises(InputFileError, match=match) as error:
        read_voxel_scenarios_text(text)
    assert "\n" not in str(error.value) and "Moving AI .3dmap.3dscen" in str(error.value)


def test_missing_files_raise(tmp_path):
    with pytest.raises(InputFileError, match="map file not found"):
        read_voxel_map(tmp_path / "absent.3dmap")
    with pytest.raises(InputFileError, match="scenario file not found"):
        read_voxel_scenarios(tmp_path / "absent.3dmap.3dscen")


def test_files_are_read_by_name(tmp_path):
    (tmp_path / "tiny.3dmap").write_text("voxel 2 1 1\n0 0 0\n")
    (tmp_path / "tiny.3dmap.3dscen").write_text("version 1\ntiny.3dmap\n0 0 0 0 0 0 0.0 1.0\n0 0 0 9 9 q 0.0 1.0\n")
    assert read_voxel_map(tmp_path / "tiny.3dmap").name == "tiny.3dmap"
    with pytest.raises(InputFileError, match=r"line 4 of tiny\.3dmap\.3dscen is not a scenario row"):
        read_voxel_scenarios(tmp_path / "tiny.3dmap.3dscen")


# --- the benchmark --------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["Simple", "Complex"])
def test_scenarios_fit_their_map(name):
    voxels, problem, rows = load(name)
    assert len(rows) == 10_000 and problem.shape == voxels.size
    starts, goals = np.array([r.start for r in rows]), np.array([r.goal for r in rows])
    assert ((starts >= 0) & (starts < voxels.size)).all() and ((goals >= 0) & (goals < voxels.size)).all()
    assert voxels.passable[tuple(starts.T)].all() and voxels.passable[tuple(goals.T)].all()
    # the ratio column is the optimal cost over the free-space (3-D octile) length, printed to 3 decimals
    d = np.sort(np.abs(goals - starts), axis=1)  # smallest first
    free_space = math.sqrt(3) * d[:, 0] + math.sqrt(2) * (d[:, 1] - d[:, 0]) + (d[:, 2] - d[:, 1])
    costs = np.array([r.optimal_cost for r in rows])
    assert (costs >= free_space - 1e-6).all()
    np.testing.assert_allclose(costs / free_space, [r.ratio for r in rows], atol=5.1e-4)


def test_fast_backend_matches_optimal_costs(simple):
    voxels, problem, rows = simple
    chosen = sample(rows) + [r for r in longest(rows, LONGEST) if r not in sample(rows)]
    assert len(chosen) >= SAMPLE_SIZE and max(r.optimal_cost for r in chosen) == max(r.optimal_cost for r in rows)
    check_rows(problem, voxels.passable, chosen, "fast", ("relaxed", "transport"))


def test_python_backend_matches_optimal_costs(simple):
    """The reference backend on four short rows (pure Python expands about 10⁴ cells per second):
    the sample's rows at the 0th to 30th percentile of cost, with the relaxed bound, and the two
    shortest also with the transport bound, which is zero here (Dijkstra)."""
    voxels, problem, rows = simple
    ordered = sorted(sample(rows), key=lambda r: r.optimal_cost)
    chosen = [ordered[int(q * (len(ordered) - 1))] for q in (0.0, 0.1, 0.2, 0.3)]
    assert len({id(r) for r in chosen}) == 4
    check_rows(problem, voxels.passable, chosen, "python", ("relaxed",))
    check_rows(problem, voxels.passable, chosen[:2], "python", ("transport",))


def test_fast_backend_on_complex(complex_map):
    """Complex's obstacles are a real level: eight rows, evenly spread, of at most 80 voxels."""
    voxels, problem, rows = complex_map
    chosen = sample([r for r in rows if r.optimal_cost <= 80.0], 8)
    assert len(chosen) >= 8
    check_rows(problem, voxels.passable, chosen, "fast", ("relaxed",))


@pytest.mark.slow
def test_fast_backend_matches_every_simple_row(simple):
    voxels, problem, rows = simple
    check_rows(problem, voxels.passable, rows, "fast", ("relaxed",))


@pytest.mark.slow
def test_fast_backend_matches_200_complex_rows(complex_map):
    voxels, problem, rows = complex_map
    chosen = sample(rows, 200)
    assert len(chosen) == 200 and longest(rows, 1)[0].optimal_cost > 160
    check_rows(problem, voxels.passable, chosen + longest(rows, 1), "fast", ("relaxed",))
