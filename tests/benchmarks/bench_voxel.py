"""Benchmark: the 3-D grid search on the Moving AI voxel benchmark, beside tcod's compiled A*.

Run on demand (not collected by pytest; 3-5 minutes with every Simple row):

    .venv/bin/python tests/benchmarks/bench_voxel.py [--rows N] [--complex-rows 200] [--heuristic relaxed]

For each Warframe map of tests/data/warframe (Simple: every row, or ``--rows N`` evenly spread;
Complex: ``--complex-rows`` rows evenly spread), the same queries in the same process:

(i)   uamopt's fast backend (numba, warmed up first) with ``--heuristic``: rows whose cost matches the
      published optimum to 1e-3, median and p90 milliseconds per query (the wall time of
      ``grid_search``: the per-query bound and the search), median expansions.
(ii)  tcod's A* (``tcod.path``, C): a ``CustomGraph`` of the map's shape with one edge rule per
      direction, costs round(10⁶ × length), each diagonal conditioned on its whole bounding box
      being free (no corner cutting), and tcod's heuristic 10⁶·octile(Δy, Δz) + 317,837·|Δx|
      (317,837 = round(√3·10⁶) − ⌊√2·10⁶⌋ − 1: no move costs less than the change it makes in it,
      so it is consistent and A* stays optimal). Per query: a new ``Pathfinder`` (its distance and travel arrays),
      ``add_root(start)``, ``path_to(goal)``. Rows whose path length (the Euclidean length of its
      moves) matches the optimum, median and p90 ms, median nodes reached (tcod counts no
      expansions), and the ratio of the medians uamopt / tcod.
(iii) Where a query's time goes, medians over 50 of the rows: the whole-grid bound alone
      (``column_bound``, the plan-view Dijkstra over every column for "relaxed"), and a start = goal
      ``grid_search``, what a query costs before it expands a cell (the bound it builds and the
      search's per-cell arrays); the rest of a query is expanding cells.

tcod is optional (not a dependency of uamopt): without it the tcod columns are skipped with one line.
Nothing is written: the table goes to standard output.
"""

from __future__ import annotations

import argparse
import itertools
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.dont_write_bytecode = True
ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from uamopt.planning import grid_search  # noqa: E402
from uamopt.planning.heuristic import column_bound  # noqa: E402
from uamopt.planning.search import warm_up  # noqa: E402
from uamopt.planning.voxel import read_voxel_map, read_voxel_map_text, read_voxel_scenarios, voxel_problem  # noqa: E402

WARFRAME = ROOT / "tests" / "data" / "warframe"
TOLERANCE = 1e-3  # the .3dscen files print costs to 8 decimals
SCALE = 1_000_000  # tcod's integer edge costs: round(SCALE × length)


def evenly(rows: list, n: int) -> list:
    """``n`` rows evenly spread over the file (every row when ``n`` is 0 or at least the file)."""
    if not n or n >= len(rows):
        return rows
    return [rows[i] for i in np.linspace(0, len(rows) - 1, n).round().astype(int)]


def load() -> float:
    return os.getloadavg()[0]


def tcod_graph(passable: np.ndarray):
    """tcod's graph of the voxel map: (graph, arrays it refers to, which must stay alive)."""
    import tcod.path

    cost = passable.astype(np.uint8)  # 1 free, 0 blocked: the cost multiplier of a move into a voxel
    graph = tcod.path.CustomGraph(passable.shape)
    padded = np.pad(passable, 1, constant_values=False)
    nx, ny, nz = passable.shape
    keep = [cost]
    for d in itertools.product((-1, 0, 1), repeat=3):
        if d == (0, 0, 0):
            continue
        edge_cost = round(SCALE * math.sqrt(sum(v * v for v in d)))
        if sum(map(abs, d)) == 1:  # a face move: its box is the target voxel, which ``cost`` checks
            graph.add_edge(d, edge_cost, cost=cost)
            continue
        # a diagonal from voxel u is legal iff every voxel of its box u + c, c ≠ 0, is free
        condition = np.ones(passable.shape, dtype=bool)
        for c in itertools.product(*[(0, v) if v else (0,) for v in d]):
            if any(c):
                condition &= padded[1 + c[0]:1 + c[0] + nx, 1 + c[1]:1 + c[1] + ny, 1 + c[2]:1 + c[2] + nz]
        condition = condition.view(np.uint8)
        keep.append(condition)
        graph.add_edge(d, edge_cost, cost=cost, condition=condition)
    # tcod's heuristic: cardinal/diagonal over the last two axes (octile), ``z`` per step of the first.
    # Consistent iff no move undercuts its change: a (1, 1, 1) move costs round(√3·SCALE) ≥ diagonal + z.
    diagonal = math.floor(SCALE * math.sqrt(2))
    z = round(SCALE * math.sqrt(3)) - diagonal - 1
    graph.set_heuristic(cardinal=SCALE, diagonal=diagonal, z=z)
    return graph, keep


def run_tcod(graph, rows) -> dict:
    import tcod.path

    seconds, setup, reached, lengths = [], [], [], []
    unreached = np.iinfo(np.int32).max
    for row in rows:
        t0 = time.perf_counter()
        pf = tcod.path.Pathfinder(graph)
        t1 = time.perf_counter()
        pf.add_root(row.start)
        path = pf.path_to(row.goal)
        seconds.append(time.perf_counter() - t0)
        setup.append(t1 - t0)
        reached.append(int(np.count_nonzero(pf.distance != unreached)))
        lengths.append(float(np.sqrt((np.diff(path, axis=0) ** 2).sum(axis=1)).sum()))
    optimal = sum(abs(length - row.optimal_cost) <= TOLERANCE for length, row in zip(lengths, rows, strict=True))
    return {"seconds": np.asarray(seconds), "setup_ms": 1e3 * float(np.median(setup)), "reached": int(np.median(reached)),
            "optimal": optimal}


def run_uamopt(problem, rows, heuristic: str) -> dict:
    seconds, expansions, optimal = [], [], 0
    for row in rows:
        t0 = time.perf_counter()
        result = grid_search(problem, row.start, row.goal, backend="fast", heuristic=heuristic)
        seconds.append(time.perf_counter() - t0)
        expansions.append(result.expansions)
        optimal += abs(result.cost - row.optimal_cost) <= TOLERANCE
    return {"seconds": np.asarray(seconds), "expansions": int(np.median(expansions)), "optimal": optimal}


def split(problem, rows, heuristic: str, n: int = 50) -> dict:
    """Medians over ``n`` of the rows: the bound alone, and a start = goal query (bound + fixed cost)."""
    bound, fixed = [], []
    for row in evenly(rows, n):
        t0 = time.perf_counter()
        column_bound(problem, row.goal, heuristic)
        bound.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        grid_search(problem, row.goal, row.goal, backend="fast", heuristic=heuristic)
        fixed.append(time.perf_counter() - t0)
    return {"bound_ms": 1e3 * float(np.median(bound)), "fixed_ms": 1e3 * float(np.median(fixed))}


def ms(seconds: np.ndarray) -> tuple[float, float]:
    return 1e3 * float(np.median(seconds)), 1e3 * float(np.percentile(seconds, 90))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=0, help="Simple rows, evenly spread; 0 = all 10,000")
    parser.add_argument("--complex-rows", type=int, default=200, help="Complex rows, evenly spread")
    parser.add_argument("--heuristic", default="relaxed", choices=("relaxed", "transport", "zero"))
    args = parser.parse_args()
    if not WARFRAME.is_dir():
        sys.exit(f"Warframe benchmarks not found at {WARFRAME}")
    try:
        import tcod.path  # noqa: F401

        have_tcod = True
    except ImportError:
        have_tcod = False
        print("tcod is not installed: the tcod columns are skipped (pip install tcod==21.2.2)")

    warm_up()
    tiny = voxel_problem(read_voxel_map_text("voxel 3 3 3\n1 1 1\n"))  # compile for the voxel problems' array types
    for heuristic in ("relaxed", "transport", "zero"):
        grid_search(tiny, (0, 0, 0), (2, 2, 2), heuristic=heuristic)
    print(f"load average at start {load():.2f}; uamopt fast backend, heuristic {args.heuristic!r}")
    header = (f"{'map':<8} {'rows':>5}  {'uamopt opt':>10} {'med ms':>7} {'p90 ms':>7} {'med exp':>8}"
              + (f"  {'tcod opt':>8} {'med ms':>7} {'p90 ms':>7} {'reached':>8} {'ratio':>6}" if have_tcod else "")
              + f"  {'bound ms':>8} {'fixed ms':>8}  {'load':>5}")
    lines = []
    for name, n in (("Simple", args.rows), ("Complex", args.complex_rows)):
        voxels = read_voxel_map(WARFRAME / f"{name}.3dmap")
        rows = evenly(read_voxel_scenarios(WARFRAME / f"{name}.3dmap.3dscen"), n)
        problem = voxel_problem(voxels)
        ours = run_uamopt(problem, rows, args.heuristic)
        med, p90 = ms(ours["seconds"])
        line = f"{name:<8} {len(rows):>5}  {ours['optimal']:>10} {med:>7.1f} {p90:>7.1f} {ours['expansions']:>8}"
        if have_tcod:
            t0 = time.perf_counter()
            graph, keep = tcod_graph(voxels.passable)
            build = time.perf_counter() - t0
            theirs = run_tcod(graph, rows)
            del graph, keep
            t_med, t_p90 = ms(theirs["seconds"])
            line += (f"  {theirs['optimal']:>8} {t_med:>7.1f} {t_p90:>7.1f} {theirs['reached']:>8} {med / t_med:>5.2f}x")
        parts = split(problem, rows, args.heuristic)
        line += f"  {parts['bound_ms']:>8.1f} {parts['fixed_ms']:>8.1f}  {load():>5.2f}"
        lines.append(line)
        if have_tcod:
            lines.append(f"{'':<8} tcod: graph built once per map in {build:.2f} s (not in its per-query times); "
                         f"median per-query Pathfinder set-up {theirs['setup_ms']:.1f} ms (in them)")
    print(header)
    print("\n".join(lines))
    print(("ratio = uamopt median / tcod median; " if have_tcod else "")
          + "bound = column_bound(problem, goal, heuristic) alone, the whole-grid table; fixed = a start = goal "
          "grid_search (what a query costs before it expands a cell), medians over 50 rows")


if __name__ == "__main__":
    main()
