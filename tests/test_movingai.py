"""The planner's optimal cost against the public Moving AI benchmarks' optimal lengths.

A sample of every map's scenario rows (about 40, evenly spread over the file, which is sorted by
bucket, so the shortest and the longest bucket are both in it) is solved with the fast backend;
a few rows also with the pure-Python backend. The lengths must match to 1e-3, the files' precision.
The benchmark over every row is ``tests/benchmarks/bench_planning.py``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from uamopt.errors import InputFileError
from uamopt.planning import grid_search
from uamopt.planning.movingai import (
    movingai_problem,
    read_map,
    read_map_text,
    read_scenarios,
)

# The public benchmark files (N. Sturtevant's Moving AI grids; credits in tests/data/movingai/README.md)
# ship with the tests.
BENCHMARKS = Path(__file__).resolve().parent / "data" / "movingai"
MAPS = ("arena.map", "maze512-32-9.map")
SAMPLE_SIZE = 40
TOLERANCE = 1e-3  # the .scen files print lengths to 5-8 decimals


@pytest.fixture(scope="module", params=MAPS)
def benchmark(request):
    """(map, its problem, all scenario rows) for one benchmark map."""
    folder = BENCHMARKS
    if not folder.is_dir():
        pytest.fail(f"Moving AI benchmarks not found at {folder}", pytrace=False)
    octile = read_map(folder / request.param)
    rows = read_scenarios(folder / f"{request.param}.scen")
    return octile, movingai_problem(octile), rows


def sample(rows: list, size: int = SAMPLE_SIZE) -> list:
    """Every k-th row counted back from the last, so the longest row is always included."""
    step = max(1, len(rows) // size)
    return rows[len(rows) - 1::-step][::-1]


def test_map_is_read_with_rows_as_y():
    octile = read_map_text("type octile\nheight 2\nwidth 3\nmap\n.@T\nGSW\n")
    assert (octile.width, octile.height) == (3, 2)
    # row y=0 is ".@T", row y=1 is "GSW": passable[x, y]
    np.testing.assert_array_equal(octile.passable, [[True, True], [False, True], [False, False]])


@pytest.mark.parametrize(("text", "match"), [
    ("type octile\nheight 2\nwidth 3\nmap\n...\n..\n", "does not have 2 rows of 3 characters"),  # short row
    ("type octile\nheight 3\nwidth 3\nmap\n...\n...\n", "does not have 3 rows of 3 characters"),  # missing row
    ("type hex\nheight 1\nwidth 1\nmap\n.\n", "has type 'hex'"),
    ("type octile\nwidth 1\nmap\n.\n", "lacks an integer height or width"),
])
def test_malformed_map_raises(text, match):
    with pytest.raises(InputFileError, match=match):
        read_map_text(text)


def test_scenarios_fit_their_map(benchmark):
    octile, problem, rows = benchmark
    assert problem.shape == (octile.width, octile.height, 1)
    assert all((r.width, r.height) == (octile.width, octile.height) for r in rows)
    starts = np.array([r.start for r in rows])
    goals = np.array([r.goal for r in rows])
    assert octile.passable[tuple(starts.T)].all() and octile.passable[tuple(goals.T)].all()


def test_fast_backend_matches_optimal_lengths(benchmark):
    _, problem, rows = benchmark
    chosen = sample(rows)
    buckets = {r.bucket for r in chosen}
    assert min(buckets) == min(r.bucket for r in rows) and max(buckets) == max(r.bucket for r in rows)
    assert chosen[-1] == rows[-1]
    for row in chosen:
        result = grid_search(problem, *row.cells(), backend="fast", heuristic="transport")
        assert result.cost == pytest.approx(row.optimal_length, abs=TOLERANCE), row
        assert len(result.path) >= 1 and tuple(result.path[0]) == row.cells()[0] and tuple(result.path[-1]) == row.cells()[1]


def test_python_backend_matches_optimal_lengths(benchmark):
    """The reference backend on a few rows: the three longest of arena; on the 512² maze one row
    of buckets 5 and 10 (pure Python expands about 10⁴ cells per second; a bucket-10 row takes
    0.4 s with heuristic zero)."""
    octile, problem, rows = benchmark
    chosen = rows[-3:] if octile.width < 100 else [next(r for r in rows if r.bucket == b) for b in (5, 10)]
    assert chosen
    for row in chosen:
        for heuristic in ("transport", "zero"):
            result = grid_search(problem, *row.cells(), backend="python", heuristic=heuristic)
            assert result.cost == pytest.approx(row.optimal_length, abs=TOLERANCE), (row, heuristic)
