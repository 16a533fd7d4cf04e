"""Optimal grid search for the track planner: four backends that must agree on the optimal cost.

The move n → m between 26-neighbour cells (docs/readings.md) costs

    w_risk · ½(R_n + R_m) · d  +  c_h' · horizontal  +  c_v' · |vertical|  +  s_p · penalty_m

where d is the centre distance, c_h' = ω5 c_h c_e τ(m_p) and c_v' = ω5 c_v c_e τ(m_p) fold Eq. 12's
constants, w_risk = ω4 (Eqs. 10–11) and s_p · penalty_m = μ·R(t_m) is the safety-buffer term
(Eq. 35): the planning model passes its shell counts R(t) and s_p = μ (``penalty_scale``), so no
grid-sized product is ever made. An optional ``priority`` array, times ``priority_scale``, is
added to a cell's open-list key only (φ′ of Eq. 34 without carrying the term along the path): the
search is then guided, not optimal, for that term.

The arrays may be integer (the binary risk as uint8 0/1, shell counts as uint16): every product
is taken in float64, so the costs are those of float64 arrays of the same values, bit for bit.
A move may not cut the corner of an impassable cell: every cell of its bounding box must be
passable.

Backends (``backend=``):

- ``"fast"`` (default): A* compiled with numba over the implicit grid (flat arrays; no Python
  object per cell or edge). A query fills its per-cell arrays only where the search reaches
  (they start as calloc's untouched zero pages), and settles the relaxed bound lazily, a column
  when the search first needs its H (a reverse-resumable Dijkstra on the plan-view relaxation,
  Silver 2005; the same values as ``column_bound``'s whole-grid table): a short query costs what
  it expands, not a pass over the grid.
- ``"python"``: the same A* in pure Python with ``heapq`` — the paper's algorithm, as a readable
  reference.
- ``"networkx"``: ``networkx.astar_path`` on the explicit grid graph with the same weights.

Heuristics (``heuristic=``, ``heuristic.py``): ``"zero"`` (the paper's A*, i.e. Dijkstra),
``"transport"`` (the cheapest transport cost to the goal) and ``"relaxed"`` (default: the exact
cost to the goal in the plan-view relaxation, which also charges the risk and buffer a track
cannot avoid at any altitude). All three are lower bounds of every path's cost and consistent, so
A* returns the same optimal cost with each; the stronger the bound, the fewer cells it expands.
"""

from __future__ import annotations

import heapq
import itertools
import math
import time
from dataclasses import dataclass

import numpy as np
from numba import njit

from uamopt.errors import NoTrackError
from uamopt.planning.heuristic import HEURISTICS, column_bound


@dataclass(frozen=True)
class SearchProblem:
    """A grid search instance. Arrays have shape (nx, ny, nz); costs as in the module docstring."""

    passable: np.ndarray  # bool
    risk: np.ndarray  # float or integer, R of Eq. 11 per cell (0 where unused)
    penalty: np.ndarray  # float or integer; penalty_scale · penalty is charged on entering a cell (μ·R(t))
    cell: tuple[float, float, float]
    w_risk: float  # ω4
    c_h: float  # ω5 · c_h · c_e · τ, ¥ per horizontal metre (or 1 for plain distance)
    c_v: float  # ω5 · c_v · c_e · τ, ¥ per vertical metre
    priority: np.ndarray | None = None  # times priority_scale, added to a cell's open-list key only (not to its cost)
    penalty_scale: float = 1.0
    priority_scale: float = 1.0

    @property
    def shape(self) -> tuple[int, int, int]:
        return self.passable.shape  # type: ignore[return-value]

    def entry_penalty(self) -> np.ndarray:
        """The cost of entering each cell, ``penalty_scale · penalty``, as float64 (a grid-sized array)."""
        return self.penalty_scale * np.asarray(self.penalty, dtype=float)

    def open_priority(self) -> np.ndarray:
        """The open-list term of each cell, ``priority_scale · priority`` (zeros without one), as float64."""
        if self.priority is None:
            return np.zeros(self.shape)
        return self.priority_scale * np.asarray(self.priority, dtype=float)


@dataclass(frozen=True)
class SearchResult:
    """An optimal path of cells (n, 3), its cost, the number of expanded cells and the time."""

    path: np.ndarray
    cost: float
    expansions: int
    seconds: float
    backend: str
    heuristic: str


OFFSETS = np.array([d for d in itertools.product((-1, 0, 1), repeat=3) if d != (0, 0, 0)], dtype=np.int64)


def _corner_table() -> tuple[np.ndarray, np.ndarray]:
    """For each of the 26 offsets, the cells of its bounding box other than the source."""
    corners = np.zeros((26, 7, 3), dtype=np.int64)
    counts = np.zeros(26, dtype=np.int64)
    for n, d in enumerate(OFFSETS):
        box = [c for c in itertools.product(*[(0, int(o)) if o else (0,) for o in d]) if any(c)]
        counts[n] = len(box)
        corners[n, : len(box)] = box
    return corners, counts


CORNERS, CORNER_COUNTS = _corner_table()


def move_costs(cell: tuple[float, float, float], c_h: float, c_v: float) -> tuple[np.ndarray, np.ndarray]:
    """Per offset: centre distance d and transport cost c_h'·horizontal + c_v'·|vertical|."""
    step = OFFSETS * np.asarray(cell, dtype=float)
    length = np.linalg.norm(step, axis=1)
    transport = c_h * np.hypot(step[:, 0], step[:, 1]) + c_v * np.abs(step[:, 2])
    return length, transport


# --- fast backend: numba ----------------------------------------------------------------------


def _compiled(func):
    """``func`` compiled by numba and cached on disk; where no cache folder is writable (a
    read-only install without a writable NUMBA_CACHE_DIR or home), numba refuses ``cache=True``
    with a RuntimeError, and the function is compiled afresh in each process instead."""
    try:
        return njit(cache=True)(func)
    except RuntimeError:
        return njit(func)


@_compiled
def _heap_push(keys, nodes, size, key, node):
    if size == keys.shape[0]:
        new_keys = np.empty(2 * size, dtype=keys.dtype)
        new_nodes = np.empty(2 * size, dtype=nodes.dtype)
        new_keys[:size] = keys
        new_nodes[:size] = nodes
        keys, nodes = new_keys, new_nodes
    i = size
    keys[i] = key
    nodes[i] = node
    while i > 0:
        p = (i - 1) >> 1
        if keys[p] > keys[i] or (keys[p] == keys[i] and nodes[p] > nodes[i]):
            keys[p], keys[i] = keys[i], keys[p]
            nodes[p], nodes[i] = nodes[i], nodes[p]
            i = p
        else:
            break
    return keys, nodes, size + 1


@_compiled
def _heap_pop(keys, nodes, size):
    key, node = keys[0], nodes[0]
    size -= 1
    keys[0], nodes[0] = keys[size], nodes[size]
    i = 0
    while True:
        left = 2 * i + 1
        if left >= size:
            break
        c = left
        right = left + 1
        if right < size and (keys[right] < keys[left] or (keys[right] == keys[left] and nodes[right] < nodes[left])):
            c = right
        if keys[c] < keys[i] or (keys[c] == keys[i] and nodes[c] < nodes[i]):
            keys[c], keys[i] = keys[i], keys[c]
            nodes[c], nodes[i] = nodes[i], nodes[c]
            i = c
        else:
            break
    return key, node, size


@_compiled
def _column_ok(c, passable, risk, penalty, penalty_scale, nz, info, min_risk, min_penalty):
    """Whether column ``c`` (index i·ny + j) has an admissible cell; on its first call also its
    least risk and least ``penalty_scale`` · penalty over those cells (heuristic.py's minima)."""
    if info[c] == 0:
        least_risk, least_penalty, ok = np.inf, np.inf, False
        for k in range(c * nz, (c + 1) * nz):
            if passable[k]:
                ok = True
                least_risk = min(least_risk, np.float64(risk[k]))
                least_penalty = min(least_penalty, np.float64(penalty[k]))
        info[c] = 1 if ok else 2
        min_risk[c] = least_risk if ok else 0.0
        min_penalty[c] = penalty_scale * least_penalty if ok else 0.0
    return info[c] == 1


@_compiled
def _settle_column(target, column_h, column_state, keys, nodes, size, passable, risk, penalty, penalty_scale, nx, ny,
                   nz, w_risk, c_h, plan_steps, info, min_risk, min_penalty):
    """Resume the plan-view relaxation's Dijkstra, run backwards from the goal column, until column
    ``target`` is settled (``column_h[target]`` is then heuristic.py's H; infinite when the search
    runs out first). Only the columns nearer the goal than ``target`` are settled on the way."""
    while column_state[target] != 2 and size > 0:
        _, b, size = _heap_pop(keys, nodes, size)
        if column_state[b] == 2:
            continue
        column_state[b] = 2
        bi, bj = b // ny, b % ny
        for n in range(plan_steps.shape[0]):
            ai, aj = bi + int(plan_steps[n, 0]), bj + int(plan_steps[n, 1])
            if ai < 0 or ai >= nx or aj < 0 or aj >= ny:
                continue
            a = ai * ny + aj
            if column_state[a] == 2 or not _column_ok(a, passable, risk, penalty, penalty_scale, nz, info, min_risk,
                                                      min_penalty):
                continue
            horizontal = plan_steps[n, 2]
            # the move a -> b of the relaxation, weighed as heuristic.py's _plan_view_graph does
            cand = column_h[b] + (w_risk * 0.5 * (min_risk[a] + min_risk[b]) * horizontal + c_h * horizontal
                                  + min_penalty[b])
            if cand < column_h[a]:
                column_h[a] = cand
                column_state[a] = 1
                keys, nodes, size = _heap_push(keys, nodes, size, cand, a)
    column_state[target] = 2  # settled, or out of reach (column_h stays infinite)
    return keys, nodes, size


@_compiled
def _astar_numba(passable, risk, penalty, penalty_scale, priority, priority_scale, nx, ny, nz, w_risk, start, goal,
                 column_h, column_state, vertical_h, c_h, plan_steps, state, offsets, flat_offsets, flat_corners,
                 counts, lengths, transports):
    n_cells = nx * ny * nz
    # g and parent are valid where state > 0 (1 open, 2 closed); state comes zeroed from calloc, so
    # a query touches the memory of the cells it reaches only, not the grid's
    g = np.empty(n_cells)
    parent = np.empty(n_cells, dtype=np.int32)  # the caller checks n_cells < 2**31
    keys = np.empty(1024, dtype=np.float64)
    nodes = np.empty(1024, dtype=np.int64)
    size = 0
    # the relaxed bound, lazily: a column whose column_state is not 2 is settled on first use
    info = np.zeros(nx * ny, dtype=np.uint8)
    min_risk = np.empty(nx * ny)
    min_penalty = np.empty(nx * ny)
    column_keys = np.empty(1024, dtype=np.float64)
    column_nodes = np.empty(1024, dtype=np.int64)
    column_size = 0
    goal_column = goal // nz
    if column_state[goal_column] != 2:
        _column_ok(goal_column, passable, risk, penalty, penalty_scale, nz, info, min_risk, min_penalty)
        column_h[goal_column] = 0.0
        column_state[goal_column] = 1
        column_keys, column_nodes, column_size = _heap_push(column_keys, column_nodes, column_size, 0.0, goal_column)
    gk = goal % nz
    g[start] = 0.0
    state[start] = 1
    keys, nodes, size = _heap_push(keys, nodes, size, 0.0, start)
    expansions = 0
    while size > 0:
        _, u, size = _heap_pop(keys, nodes, size)
        if state[u] == 2:
            continue
        state[u] = 2
        expansions += 1
        if u == goal:
            break
        ui, uj, uk = u // (ny * nz), (u // nz) % ny, u % nz
        gu = g[u]
        ru = np.float64(risk[u])
        for n in range(26):
            vi, vj, vk = ui + offsets[n, 0], uj + offsets[n, 1], uk + offsets[n, 2]
            if vi < 0 or vi >= nx or vj < 0 or vj >= ny or vk < 0 or vk >= nz:
                continue
            v = u + flat_offsets[n]
            if state[v] == 2 or not passable[v]:
                continue
            ok = True
            for c in range(counts[n] - 1):  # the rest of the box: the target v is its last cell
                if not passable[u + flat_corners[n, c]]:
                    ok = False
                    break
            if not ok:
                continue
            column = vi * ny + vj
            if column_state[column] != 2:
                column_keys, column_nodes, column_size = _settle_column(
                    column, column_h, column_state, column_keys, column_nodes, column_size, passable, risk, penalty,
                    penalty_scale, nx, ny, nz, w_risk, c_h, plan_steps, info, min_risk, min_penalty)
            h = column_h[column]
            if h == np.inf:  # the goal is out of reach from this column even in the relaxation
                continue
            # float64 throughout: an integer or float32 array's value converts exactly
            cand = (gu + w_risk * 0.5 * (ru + np.float64(risk[v])) * lengths[n] + transports[n]
                    + penalty_scale * np.float64(penalty[v]))
            if state[v] == 0 or cand < g[v]:
                g[v] = cand
                parent[v] = u
                state[v] = 1
                h += vertical_h * abs(vk - gk)
                keys, nodes, size = _heap_push(keys, nodes, size, cand + h + priority_scale * np.float64(priority[v]), v)
    return (g[goal] if state[goal] == 2 else np.inf), parent, expansions


def _path_from_parents(parent: np.ndarray, start: int, goal: int, shape) -> np.ndarray:
    path = [goal]
    while path[-1] != start:
        path.append(int(parent[path[-1]]))
    return np.column_stack(np.unravel_index(np.asarray(path[::-1]), shape))


#: the array types the compiled search takes as they are (any other is converted to float64)
_KERNEL_TYPES = (np.dtype(np.float64), np.dtype(np.uint8), np.dtype(np.uint16), np.dtype(np.uint32))


def _flat(values: np.ndarray) -> np.ndarray:
    """``values`` as the compiled search reads them: flat, C order, and of a type in
    :data:`_KERNEL_TYPES` (no copy when it already is; a bool array is viewed as uint8)."""
    values = np.asarray(values)
    if values.dtype == np.bool_:
        values = np.ascontiguousarray(values).view(np.uint8)
    elif values.dtype not in _KERNEL_TYPES:
        values = values.astype(float)
    return np.ascontiguousarray(values).ravel()


def _layer_slab(problem: SearchProblem) -> tuple[int, int]:
    """The layers [k0, k1) the compiled search runs on: those from the lowest to the highest with a
    passable cell (no move enters or cuts a corner of an impassable layer), when copying them
    costs less memory than the search's own arrays (13 bytes a cell) over the layers left out;
    else every layer."""
    nz = problem.shape[2]
    layers = np.flatnonzero(problem.passable.any(axis=(0, 1)))
    if len(layers) == 0:
        return 0, nz
    k0, k1 = int(layers[0]), int(layers[-1]) + 1
    arrays = [problem.passable, problem.risk, problem.penalty] + ([problem.priority] if problem.priority is not None else [])
    copied = sum(np.asarray(a).dtype.itemsize for a in arrays) * (k1 - k0)
    return (k0, k1) if 13 * (nz - (k1 - k0)) > copied else (0, nz)


def _flat_moves(ny: int, nz: int) -> tuple[np.ndarray, np.ndarray]:
    """Per offset: its step in flat cell index (grid (·, ny, nz)), and the steps to its bounding
    box's cells other than the source, in CORNERS' order (the target, every offset nonzero, last)."""
    stride = np.array([ny * nz, nz, 1], dtype=np.int64)
    return OFFSETS @ stride, CORNERS @ stride


def _plan_steps(cell: tuple[float, float, float]) -> np.ndarray:
    """The relaxation's 8 plan-view moves, rows (di, dj, horizontal length)."""
    dx, dy, _ = cell
    return np.array([(di, dj, math.hypot(di * dx, dj * dy)) for di in (-1, 0, 1) for dj in (-1, 0, 1) if di or dj])


def _fast(problem: SearchProblem, start: int, goal: int, bound: tuple[np.ndarray | None, float]):
    nx, ny, nz = problem.shape
    if nx * ny * nz >= 2**31:
        raise ValueError(f"a grid of {nx * ny * nz:,} cells is beyond the fast search's 2**31 cells")
    k0, k1 = _layer_slab(problem)
    slab = (slice(None), slice(None), slice(k0, k1))

    def cut(values):
        return values if (k0, k1) == (0, nz) else np.asarray(values)[slab]

    def index(flat: int) -> int:  # a cell's index in the slab
        i, j, k = np.unravel_index(flat, (nx, ny, nz))
        return int(np.ravel_multi_index((i, j, k - k0), (nx, ny, k1 - k0)))

    lengths, transports = move_costs(problem.cell, problem.c_h, problem.c_v)
    penalty = _flat(cut(problem.penalty))
    # no priority: the penalty array again, weighted 0 (no grid-sized array of zeros)
    priority, priority_scale = ((penalty, 0.0) if problem.priority is None
                                else (_flat(cut(problem.priority)), float(problem.priority_scale)))
    if bound[0] is None:  # "relaxed", settled column by column as the search reaches them (heuristic.py)
        column_h, column_state = np.full(nx * ny, np.inf), np.zeros(nx * ny, dtype=np.uint8)
    else:
        column_h, column_state = np.ascontiguousarray(bound[0], dtype=float), np.full(nx * ny, 2, dtype=np.uint8)
    cost, parent, expansions = _astar_numba(
        np.ascontiguousarray(cut(problem.passable)).ravel(), _flat(cut(problem.risk)), penalty,
        float(problem.penalty_scale), priority, priority_scale, nx, ny, k1 - k0, float(problem.w_risk), index(start),
        index(goal), column_h, column_state, float(bound[1]), float(problem.c_h), _plan_steps(problem.cell),
        np.zeros(nx * ny * (k1 - k0), dtype=np.uint8), OFFSETS, *_flat_moves(ny, k1 - k0), CORNER_COUNTS, lengths,
        transports,
    )
    if not np.isfinite(cost):
        return None, math.inf, int(expansions)
    path = _path_from_parents(parent, index(start), index(goal), (nx, ny, k1 - k0))
    path[:, 2] += k0
    return path, float(cost), int(expansions)


# --- reference backends -------------------------------------------------------------------------


def _python(problem: SearchProblem, start: int, goal: int, bound: tuple[np.ndarray | None, float]):
    shape = problem.shape
    passable, risk = problem.passable, np.asarray(problem.risk, dtype=float)
    penalty, priority = problem.entry_penalty(), problem.open_priority()
    lengths, transports = move_costs(problem.cell, problem.c_h, problem.c_v)
    goal_c = np.unravel_index(goal, shape)
    start_c = tuple(int(v) for v in np.unravel_index(start, shape))
    column_h, vertical_h = bound
    assert column_h is not None  # whole for every backend but "fast" (grid_search)

    def heuristic(v):
        return float(column_h[v[0] * shape[1] + v[1]]) + vertical_h * abs(v[2] - int(goal_c[2]))
    g = {start_c: 0.0}
    parent: dict = {}
    closed: set = set()
    heap = [(0.0, start, start_c)]
    expansions = 0
    while heap:
        _, _, u = heapq.heappop(heap)
        if u in closed:
            continue
        closed.add(u)
        expansions += 1
        if u == tuple(goal_c):
            break
        for n, d in enumerate(OFFSETS):
            v = (u[0] + int(d[0]), u[1] + int(d[1]), u[2] + int(d[2]))
            if not all(0 <= a < s for a, s in zip(v, shape, strict=False)) or v in closed:
                continue
            if not all(passable[u[0] + c[0], u[1] + c[1], u[2] + c[2]] for c in CORNERS[n, : CORNER_COUNTS[n]]):
                continue
            h = heuristic(v)
            if h == math.inf:
                continue
            cand = g[u] + problem.w_risk * 0.5 * (risk[u] + risk[v]) * lengths[n] + transports[n] + penalty[v]
            if cand < g.get(v, math.inf):
                g[v] = cand
                parent[v] = u
                heapq.heappush(heap, (cand + h + priority[v], int(np.ravel_multi_index(v, shape)), v))
    goal_t = tuple(int(v) for v in goal_c)
    if goal_t not in g:
        return None, math.inf, expansions
    path = [goal_t]
    while path[-1] != start_c:
        path.append(parent[path[-1]])
    return np.asarray(path[::-1], dtype=np.int64), float(g[goal_t]), expansions


def _networkx(problem: SearchProblem, start: int, goal: int, bound: tuple[np.ndarray | None, float]):
    import networkx as nx

    from uamopt.planning.graph import grid_graph

    if problem.priority is not None and problem.priority_scale != 0 and np.any(problem.priority):
        raise ValueError("the networkx backend has no open-list priority term; use backend 'fast' or 'python'")
    graph = grid_graph(problem.passable, problem.cell)
    risk, penalty = np.asarray(problem.risk, dtype=float), problem.entry_penalty()
    cell = np.asarray(problem.cell)

    def weight(u, v, data):
        step = (np.asarray(v) - np.asarray(u)) * cell
        transport = problem.c_h * math.hypot(step[0], step[1]) + problem.c_v * abs(step[2])
        return problem.w_risk * 0.5 * (risk[u] + risk[v]) * data["length"] + transport + penalty[v]

    column_h, vertical_h = bound
    assert column_h is not None  # whole for every backend but "fast" (grid_search)

    def heuristic(u, v):  # v is the goal
        return float(column_h[u[0] * problem.shape[1] + u[1]]) + vertical_h * abs(u[2] - v[2])

    s, t = (tuple(int(x) for x in np.unravel_index(i, problem.shape)) for i in (start, goal))
    try:
        path = nx.astar_path(graph, s, t, heuristic=heuristic, weight=weight)
    except (nx.NetworkXNoPath, nx.NodeNotFound):
        return None, math.inf, 0
    cost = sum(weight(a, b, graph.edges[a, b]) for a, b in itertools.pairwise(path))
    return np.asarray(path, dtype=np.int64), float(cost), 0


BACKENDS = {"fast": _fast, "python": _python, "networkx": _networkx}

_WARM: set[str] = set()


def warm_up(backend: str = "fast") -> float:
    """Compile (or load from numba's cache) the ``fast`` search once per process, on a 2-cell grid,
    for float64 arrays and for the planning model's own (uint8 binary risk, uint16 shell counts),
    so that a stage's reported time is its search, not the compiler. Returns the seconds spent
    (0.0 when already warm or for the uncompiled backends)."""
    if backend != "fast" or backend in _WARM:
        return 0.0
    started = time.perf_counter()
    free, zero = np.ones((2, 1, 1), dtype=bool), np.zeros((2, 1, 1))
    for risk, penalty in ((zero, zero), (zero.astype(np.uint8), zero.astype(np.uint16))):
        _fast(SearchProblem(free, risk, penalty, (1.0, 1.0, 1.0), 0.0, 1.0, 1.0), 0, 1, (np.zeros(2), 0.0))
    _WARM.add(backend)
    return time.perf_counter() - started


def grid_search(problem: SearchProblem, start: tuple[int, int, int], goal: tuple[int, int, int], *,
                backend: str = "fast", heuristic: str = "relaxed") -> SearchResult:
    """Cheapest path of cells from ``start`` to ``goal``.

    Parameters
    ----------
    problem : SearchProblem
    start, goal : (i, j, k)
        Passable cells.
    backend : {"fast", "python", "networkx"}
    heuristic : {"relaxed", "transport", "zero"}
        See ``uamopt/planning/heuristic.py``; the time to build the bound is part of ``seconds``.

    Returns
    -------
    SearchResult

    Raises
    ------
    NoTrackError
        When ``start`` or ``goal`` is impassable or no path joins them.

    Examples
    --------
    >>> import numpy as np
    >>> free = np.ones((3, 3, 1), dtype=bool); zero = np.zeros((3, 3, 1))
    >>> p = SearchProblem(free, zero, zero, (1.0, 1.0, 1.0), 0.0, 1.0, 1.0)
    >>> r = grid_search(p, (0, 0, 0), (2, 2, 0))
    >>> round(r.cost, 6), len(r.path)
    (2.828427, 3)
    """
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {sorted(BACKENDS)}, got {backend!r}")
    if heuristic not in HEURISTICS:
        raise ValueError(f"heuristic must be one of {list(HEURISTICS)}, got {heuristic!r}")
    for name, c in (("start", start), ("goal", goal)):
        if len(c) != 3 or not all(0 <= int(v) < n for v, n in zip(c, problem.shape, strict=True)):
            raise ValueError(f"{name} {tuple(c)} is not a cell of the grid of shape {problem.shape}")
        if not problem.passable[tuple(c)]:
            raise NoTrackError(f"the {name} cell {tuple(int(v) for v in c)} is not passable", "track search",
                               "move it out of buildings, no-fly zones and the clearance margin")
    s = int(np.ravel_multi_index(tuple(start), problem.shape))
    t = int(np.ravel_multi_index(tuple(goal), problem.shape))
    started = time.perf_counter()
    bound = column_bound(problem, tuple(goal), heuristic, lazy=backend == "fast")
    path, cost, expansions = BACKENDS[backend](problem, s, t, bound)
    seconds = time.perf_counter() - started
    if path is None:
        raise NoTrackError(f"no admissible track joins cell {tuple(start)} and cell {tuple(goal)}", "track search",
                           "the destination is walled off by buildings, no-fly zones or the altitude band; "
                           "move it or relax grid.h_*/tracks.clearance_m")
    return SearchResult(path=path, cost=cost, expansions=expansions, seconds=seconds, backend=backend,
                        heuristic=heuristic)
