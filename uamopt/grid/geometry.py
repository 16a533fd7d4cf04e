"""Polylines on the grid: the cells a piecewise-linear track passes through, exactly.

Each segment is cut at every grid plane it crosses (x = iΔx, y = jΔy, z = kΔz); each piece then
lies in one cell, found from its midpoint. Vectorised over segments and crossings (no loop over
cells). Works in any dimension: the city rasteriser uses it in 2-D for road lengths.
"""

from __future__ import annotations

import itertools

import numpy as np


def split_segments(starts: np.ndarray, ends: np.ndarray, cell) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cut segments (M, D) → (M, D) at the grid planes they cross.

    Returns
    -------
    owner : int array (P,)
        Index of the segment each piece belongs to; pieces are in order along each segment.
    t0, t1 : float arrays (P,)
        Segment parameters (0 at start, 1 at end) bounding each piece; pieces of zero length
        (a crossing exactly at a vertex or two planes crossed at once) are dropped.
    """
    starts = np.asarray(starts, dtype=float)
    ends = np.asarray(ends, dtype=float)
    m = len(starts)
    ts = [np.zeros(m), np.ones(m)]
    owners = [np.arange(m), np.arange(m)]
    for axis, step in enumerate(np.asarray(cell, dtype=float)):
        a0, a1 = starts[:, axis], ends[:, axis]
        lo = np.ceil(np.minimum(a0, a1) / step).astype(np.int64)
        hi = np.floor(np.maximum(a0, a1) / step).astype(np.int64)
        count = np.where(a1 != a0, np.maximum(hi - lo + 1, 0), 0)
        owner = np.repeat(np.arange(m), count)
        offset = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        plane = (np.repeat(lo, count) + offset) * step
        ts.append((plane - a0[owner]) / (a1[owner] - a0[owner]))
        owners.append(owner)
    t = np.clip(np.concatenate(ts), 0.0, 1.0)
    owner = np.concatenate(owners)
    order = np.lexsort((t, owner))
    t, owner = t[order], owner[order]
    same = owner[1:] == owner[:-1]
    t0, t1, who = t[:-1][same], t[1:][same], owner[:-1][same]
    keep = t1 > t0
    return who[keep], t0[keep], t1[keep]


def polyline_pieces(waypoints: np.ndarray, cell) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pieces of a polyline (n, D) in order: their cell index (P, D), start and end arc length (m)."""
    pts = np.asarray(waypoints, dtype=float)
    seg_len = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    s_start = np.concatenate([[0.0], np.cumsum(seg_len)])
    owner, t0, t1 = split_segments(pts[:-1], pts[1:], cell)
    mid = pts[owner] + (0.5 * (t0 + t1))[:, None] * (pts[owner + 1] - pts[owner])
    cells = np.floor(mid / np.asarray(cell, dtype=float)).astype(np.int64)
    return cells, s_start[owner] + t0 * seg_len[owner], s_start[owner] + t1 * seg_len[owner]


def points_in_mask(points: np.ndarray, mask: np.ndarray, cell, tol: float = 1e-6) -> np.ndarray:
    """True where a point lies in the closed box of at least one True cell of ``mask``.

    A point on a face, edge or corner belongs to every cell sharing it; points outside the grid
    are False.
    """
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    size = np.asarray(cell, dtype=float)
    shape = np.asarray(mask.shape)
    ok = np.zeros(len(pts), dtype=bool)
    for shift in itertools.product((-tol, tol), repeat=pts.shape[1]):
        idx = np.floor((pts + np.asarray(shift)) / size).astype(np.int64)
        inside = np.all((idx >= 0) & (idx < shape), axis=1)
        hit = np.zeros(len(pts), dtype=bool)
        hit[inside] = mask[tuple(idx[inside].T)]
        ok |= hit
    return ok


def polyline_in_mask(waypoints: np.ndarray, mask: np.ndarray, cell) -> np.ndarray:
    """Per segment of the polyline: every piece's midpoint and every vertex lie in ``mask``'s cells."""
    pts = np.asarray(waypoints, dtype=float)
    owner, t0, t1 = split_segments(pts[:-1], pts[1:], cell)
    mid = pts[owner] + (0.5 * (t0 + t1))[:, None] * (pts[owner + 1] - pts[owner])
    good_piece = points_in_mask(mid, mask, cell)
    good = np.ones(len(pts) - 1, dtype=bool)
    np.logical_and.at(good, owner, good_piece)
    vertex_ok = points_in_mask(pts, mask, cell)
    return good & vertex_ok[:-1] & vertex_ok[1:]
