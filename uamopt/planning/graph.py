"""The airspace as a networkx graph: the reference backend for analysis and for checking the
fast planners of later stages.

Nodes are passable cells (i, j, k) (neither obstacle nor no-fly; Eqs. 9 and 15 make both
impassable). Edges join 26-neighbours; a move may not cut the corner of an impassable cell:
every cell of the move's bounding box must be passable (docs/readings.md; this also reproduces the
Moving AI benchmark's optimal lengths).
"""

from __future__ import annotations

import itertools

import networkx as nx
import numpy as np

from uamopt.risk import RiskField

#: The 13 offsets of one half of the 26-neighbourhood; the other half are their negatives.
HALF_NEIGHBOURHOOD = tuple(
    d for d in itertools.product((-1, 0, 1), repeat=3) if d > (0, 0, 0)
)


def passable_cells(field: RiskField) -> np.ndarray:
    """Cells an aircraft may enter (bool, (nx, ny, nz))."""
    return ~(field.obstacle | field.no_fly)


def _shifted(mask: np.ndarray, offset: tuple[int, int, int]) -> np.ndarray:
    """``out[c] = mask[c + offset]``, False where c + offset leaves the grid."""
    out = np.zeros_like(mask)
    src = tuple(slice(max(o, 0), n + min(o, 0)) for o, n in zip(offset, mask.shape, strict=True))
    dst = tuple(slice(max(-o, 0), n + min(-o, 0)) for o, n in zip(offset, mask.shape, strict=True))
    out[dst] = mask[src]
    return out


def neighbour_moves(passable: np.ndarray, offset: tuple[int, int, int]) -> np.ndarray:
    """Cells c from which the move c → c + offset is allowed: every cell of the move's bounding
    box is passable (no corner cutting). Bool, same shape as ``passable``."""
    ok = passable.copy()
    for corner in itertools.product(*[(0, o) if o else (0,) for o in offset]):
        if any(corner):
            ok &= _shifted(passable, corner)
    return ok


def grid_graph(passable: np.ndarray, cell: tuple[float, float, float], *, neighbourhood: int = 26) -> nx.Graph:
    """Undirected graph of the ``passable`` cells (bool (nx, ny, nz)): node (i, j, k), edges between
    neighbours whose move keeps clear of impassable corners, edge attribute ``length`` (m)."""
    if neighbourhood not in (6, 18, 26):
        raise ValueError(f"neighbourhood must be 6, 18 or 26, got {neighbourhood}")
    graph = nx.Graph(cell=tuple(cell), shape=passable.shape)
    graph.add_nodes_from(map(tuple, np.argwhere(passable).tolist()))
    reach = {6: 1, 18: 2, 26: 3}[neighbourhood]
    for offset in HALF_NEIGHBOURHOOD:
        if sum(map(abs, offset)) > reach:
            continue
        src = np.argwhere(neighbour_moves(passable, offset))
        dst = src + np.asarray(offset)
        length = float(np.linalg.norm(np.asarray(offset) * np.asarray(cell, dtype=float)))
        graph.add_edges_from(zip(map(tuple, src.tolist()), map(tuple, dst.tolist()), strict=True), length=length)
    return graph


def to_networkx(field: RiskField, *, neighbourhood: int = 26) -> nx.Graph:
    """The passable airspace as an undirected :class:`networkx.Graph`.

    Parameters
    ----------
    field : RiskField
        Risk field and obstacles on the grid.
    neighbourhood : {6, 18, 26}
        Moves along faces (6), faces and edges (18), or also corners (26, the paper's A*).

    Returns
    -------
    networkx.Graph
        Node (i, j, k) carries ``pos`` (centre, m), ``risk`` (Eq. 8), ``unsafe`` (Eq. 9, bool);
        edge attribute ``length`` is the distance between the cell centres, m.

    Examples
    --------
    >>> from uamopt import load_scenario, scenario_grid, load_city, risk_field
    >>> s = load_scenario("models/paper_case.toml", ["grid.cell=[250,250,120]"])
    >>> g = scenario_grid(s); f = risk_field(s, g, load_city(s, g))
    >>> G = to_networkx(f)
    >>> G.number_of_nodes() == int((~(f.obstacle | f.no_fly)).sum())
    True
    """
    passable = passable_cells(field)
    graph = grid_graph(passable, field.grid.cell, neighbourhood=neighbourhood)
    idx = np.argwhere(passable)
    centres = (idx + 0.5) * np.asarray(field.grid.cell)
    attrs = {
        (int(i), int(j), int(k)): {"pos": tuple(map(float, p)), "risk": float(r), "unsafe": bool(u)}
        for (i, j, k), p, r, u in zip(idx, centres, field.risk[passable], field.unsafe[passable], strict=True)
    }
    nx.set_node_attributes(graph, attrs)
    return graph
