"""The track search's A* heuristics: lower bounds of the cost from a cell to the goal.

Each heuristic has the form h(i, j, k) = H[i, j] + v·|k − k_goal|, a per-column table H and a
vertical rate v, so that every backend evaluates it the same way (``search.py``):

- ``"zero"``: H = 0, v = 0 (the paper's A*, i.e. Dijkstra).
- ``"transport"``: H = c_h'·octile(Δi Δx, Δj Δy) and v = c_v'·Δz, the cheapest transport cost to
  the goal in free space.
- ``"relaxed"`` (default): H is the exact cost to the goal column in the plan-view relaxation of
  the grid, and v = c_v'·Δz + ρ·(√(Δh² + Δz²) − Δh), where Δh = √(Δx² + Δy²) is the longest
  horizontal step and ρ = max(0, w_risk · min R), min R the least risk over the whole grid. The
  relaxation keeps one node per column (i, j) with an admissible cell and lets a 2-D move between
  neighbouring columns a, b cost

      w_risk · ½(min R_a + min R_b) · horizontal  +  c_h' · horizontal  +  min penalty_b,

  the minima over the admissible cells of each column. Every 3-D move with a vertical step costs
  at least the relaxation of its horizontal part h plus v: R and the penalty are at least their
  column minima, c_v'·Δz is paid, and its centre distance d exceeds h by √(h² + Δz²) − h, which
  is least for h = Δh (a vertical move projects onto no move at all and has d − h = Δz, more),
  each metre of that excess bearing risk ρ at least. So H + v·|Δk| is a lower bound of every
  path's cost, and, H being a shortest-path distance, it is consistent. ρ is 0 as soon as one
  cell has no risk; on a uniform risk (the Moving AI voxel maps, ``voxel.py``) it is what lets the
  bound see a climb. The relaxation charges what the transport bound
  cannot see: a road whose risk fills every admissible layer of its columns must be crossed, and
  it costs the same at every altitude. On the paper case at 10 m cells the relaxed bound at the
  origin equals the optimal Eq. 10 cost (140.37; the transport bound is 14.67), and A* expands
  the track's cells instead of 1.1 million.

H is infinite on columns the goal cannot be reached from even in the relaxation; the search
skips their cells. The relaxation is solved by ``scipy.sparse.csgraph.dijkstra`` on the reversed
column graph; the fast search runs the same Dijkstra lazily instead (``lazy=True``), settling a
column when it first needs its H, so that a short query does not pay for the whole grid.
Where the admissible cells lie in one layer (the route network's searches, each
confined to its direction's layer), the relaxation is the problem itself: solving it whole
costs more than A* with the transport bound (at 10 m cells, ``plan_network`` took 6.7 s of CPU
against 4.9 s), so ``"relaxed"`` falls back to ``"transport"`` there.
"""

from __future__ import annotations

import math

import numpy as np

HEURISTICS = ("relaxed", "transport", "zero")


def _plan_view_graph(problem):
    """The relaxation's column graph as a sparse matrix (rows: from-column, columns: to-column)."""
    from scipy.sparse import csr_matrix

    passable = problem.passable
    nx, ny, _ = passable.shape
    dx, dy, _ = problem.cell
    c_h = float(problem.c_h)
    column_ok = passable.any(axis=2)
    # the risk and penalty are charged only where the track may fly: their minima over admissible cells
    min_risk = _column_min(problem.risk, passable, column_ok)
    min_penalty = problem.penalty_scale * _column_min(problem.penalty, passable, column_ok)
    index = np.arange(nx * ny).reshape(nx, ny)
    sources, targets, weights = [], [], []
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            if di == dj == 0:
                continue
            a = (slice(max(0, -di), nx - max(0, di)), slice(max(0, -dj), ny - max(0, dj)))
            b = (slice(a[0].start + di, a[0].stop + di), slice(a[1].start + dj, a[1].stop + dj))
            ok = column_ok[a] & column_ok[b]
            horizontal = math.hypot(di * dx, dj * dy)
            cost = (problem.w_risk * 0.5 * (min_risk[a] + min_risk[b]) * horizontal + c_h * horizontal
                    + min_penalty[b])
            sources.append(index[a][ok])
            targets.append(index[b][ok])
            weights.append(cost[ok])
    # explicit zero weights stay edges in csgraph's sparse input (a free move is still a move)
    return csr_matrix((np.concatenate(weights), (np.concatenate(sources), np.concatenate(targets))),
                      shape=(nx * ny, nx * ny))


def _column_min(values: np.ndarray, passable: np.ndarray, column_ok: np.ndarray) -> np.ndarray:
    """The least value over each column's admissible cells, float64 ((nx, ny); 0 in columns with
    none: they have no edges). No temporary of the grid's size; integer arrays too."""
    values = np.asarray(values)
    if values.dtype == np.bool_:
        values = values.view(np.uint8)
    initial = np.inf if values.dtype.kind == "f" else np.iinfo(values.dtype).max
    least = np.min(values, axis=2, where=passable, initial=initial).astype(float)
    least[~column_ok] = 0.0
    return least


def column_bound(problem, goal: tuple[int, int, int], heuristic: str, *,
                 lazy: bool = False) -> tuple[np.ndarray | None, float]:
    """(H, v) of the module docstring for ``goal``: H flat over the columns (index i·ny + j).

    With ``lazy``, ``"relaxed"`` returns H = None where it would solve the relaxation whole: the
    fast search settles it itself, over the columns it reaches only (search.py)."""
    nx, ny, _ = problem.shape
    dx, dy, dz = problem.cell
    gi, gj, _ = (int(v) for v in goal)
    if heuristic == "zero":
        return np.zeros(nx * ny), 0.0
    vertical = float(problem.c_v) * float(dz)
    if heuristic == "transport":
        di = np.abs(np.arange(nx) - gi)[:, None]
        dj = np.abs(np.arange(ny) - gj)[None, :]
        m = np.minimum(di, dj)
        octile = m * math.hypot(dx, dy) + (di - m) * dx + (dj - m) * dy
        return (float(problem.c_h) * octile).ravel(), vertical
    if heuristic != "relaxed":
        raise ValueError(f"heuristic must be one of {list(HEURISTICS)}, got {heuristic!r}")
    if np.count_nonzero(problem.passable.any(axis=(0, 1))) <= 1:
        return column_bound(problem, goal, "transport")
    # ρ of the module docstring: the risk of the excess length of a move with a vertical step
    least_risk = float(problem.w_risk) * float(np.min(problem.risk)) if problem.risk.size else 0.0
    if least_risk > 0.0:  # (and not NaN)
        longest = math.hypot(dx, dy)
        vertical += least_risk * (math.hypot(longest, dz) - longest)
    return (None if lazy else plan_view_distance(problem, (gi, gj))), vertical


def plan_view_distance(problem, goal_column: tuple[int, int]) -> np.ndarray:
    """H of ``"relaxed"``: the exact cost from every column to ``goal_column`` in the plan-view
    relaxation (flat, index i·ny + j; infinite where the goal column is out of reach)."""
    from scipy.sparse.csgraph import dijkstra

    graph = _plan_view_graph(problem)
    return dijkstra(graph.T.tocsr(), indices=goal_column[0] * problem.shape[1] + goal_column[1])
