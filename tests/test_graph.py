"""The networkx reference graph of the airspace."""

from __future__ import annotations

import itertools

import networkx as nx
import numpy as np
import pytest
from oracles import grid_shortest_length

from uamopt.planning.graph import neighbour_moves, to_networkx


@pytest.fixture(scope="module")
def coarse(coarse_run):
    return coarse_run.field


def test_nodes_are_the_passable_cells_with_attributes(coarse):
    G = to_networkx(coarse)
    passable = ~(coarse.obstacle | coarse.no_fly)
    assert G.number_of_nodes() == int(passable.sum())
    i, j, k = map(int, np.argwhere(passable)[0])
    data = G.nodes[(i, j, k)]
    assert data["pos"] == coarse.grid.centre_of((i, j, k))
    assert data["risk"] == coarse.risk[i, j, k] and data["unsafe"] == bool(coarse.unsafe[i, j, k])


def test_edges_match_a_brute_force_enumeration(coarse):
    """Every edge joins 26-neighbours whose bounding box is free; every such pair is an edge."""
    G = to_networkx(coarse)
    passable = ~(coarse.obstacle | coarse.no_fly)
    shape = passable.shape
    cell = np.asarray(coarse.grid.cell)
    expected = set()
    sub = np.argwhere(passable)
    for c in map(tuple, sub[:: max(1, len(sub) // 400)]):  # a sample of sources, checked exhaustively
        for d in itertools.product((-1, 0, 1), repeat=3):
            if d == (0, 0, 0):
                continue
            n = tuple(a + b for a, b in zip(c, d, strict=True))
            if not all(0 <= v < s for v, s in zip(n, shape, strict=True)):
                continue
            box_free = all(passable[tuple(a + o for a, o in zip(c, corner, strict=True))]
                           for corner in itertools.product(*[(0, x) if x else (0,) for x in d]))
            assert G.has_edge(c, n) == box_free, (c, n)
            if box_free:
                assert G.edges[c, n]["length"] == pytest.approx(float(np.linalg.norm(np.asarray(d) * cell)))
                expected.add((c, n))
    assert expected


def test_no_corner_cutting_on_a_tiny_grid():
    passable = np.ones((2, 2, 1), dtype=bool)
    passable[1, 0, 0] = False
    moves = neighbour_moves(passable, (1, 1, 0))
    assert not moves[0, 0, 0]  # the diagonal (0,0) -> (1,1) would cut the blocked (1,0)
    passable[1, 0, 0] = True
    assert neighbour_moves(passable, (1, 1, 0))[0, 0, 0]


def test_shortest_path_on_the_graph_is_a_valid_track(coarse):
    """V1 → V4 at 150 m and at 90 m (a fifth of that layer's cells blocked): networkx's A* on the
    graph is as long as the exact optimum of an independent Dijkstra over the passable cells
    (tests/oracles.py: the same moves and lengths, written without the graph or uamopt), and every
    step of its path is a 26-neighbour move whose bounding box is free."""
    G = to_networkx(coarse)
    passable = ~(coarse.obstacle | coarse.no_fly)
    cell = np.asarray(coarse.grid.cell)
    for z in (150.0, 90.0):
        s = coarse.grid.index_of((300.0, 300.0, z))
        t = coarse.grid.index_of((2220.0, 4220.0, z))
        path = nx.astar_path(G, s, t, weight="length")
        optimum = grid_shortest_length(passable.tolist(), coarse.grid.cell, s, t)
        assert nx.path_weight(G, path, weight="length") == pytest.approx(optimum, rel=1e-12), z
        assert path[0] == s and path[-1] == t
        walked = 0.0
        for a, b in itertools.pairwise(path):
            d = np.subtract(b, a)
            assert np.abs(d).max() == 1, (a, b)  # a 26-neighbour
            box = itertools.product(*[(0, x) if x else (0,) for x in d])
            assert all(passable[tuple(np.add(a, corner))] for corner in box), (a, b)  # no corner cut
            walked += float(np.linalg.norm(d * cell))
        assert walked == pytest.approx(optimum, rel=1e-12)


def test_neighbourhood_choice(coarse):
    g6, g26 = to_networkx(coarse, neighbourhood=6), to_networkx(coarse, neighbourhood=26)
    assert g6.number_of_nodes() == g26.number_of_nodes() and g6.number_of_edges() < g26.number_of_edges()
    with pytest.raises(ValueError, match="neighbourhood must be 6, 18 or 26, got 8"):
        to_networkx(coarse, neighbourhood=8)
