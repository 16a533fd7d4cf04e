"""Geometry the figures need: the layer holding an altitude and the columns of a map window;
distance flown, where a detour starts, the unsafe pieces of a track, and which tracks are the two
directions of one route.

Plain numpy (no matplotlib), vectorised over waypoints and samples.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from uamopt.grid.geometry import polyline_pieces


def layer_of(field, altitude_m: float) -> int:
    """Layer index holding ``altitude_m`` (a face goes to the upper layer), clipped to the grid."""
    g = field.grid
    return int(np.clip(math.floor(altitude_m / g.cell[2] + 1e-9), 0, g.shape[2] - 1))


def window_slices(field, window=None) -> tuple[slice, slice]:
    """Column slices of the grid covering ``window`` (x0, x1, y0, y1) m with one cell to spare."""
    g = field.grid
    if window is None:
        return slice(0, g.shape[0]), slice(0, g.shape[1])
    x0, x1, y0, y1 = window[:4]
    i0, i1 = int(max(math.floor(x0 / g.cell[0]) - 1, 0)), int(min(math.ceil(x1 / g.cell[0]) + 1, g.shape[0]))
    j0, j1 = int(max(math.floor(y0 / g.cell[1]) - 1, 0)), int(min(math.ceil(y1 / g.cell[1]) + 1, g.shape[1]))
    return slice(i0, i1), slice(j0, j1)


def along_track_m(waypoints: np.ndarray) -> np.ndarray:
    """Horizontal distance flown to each waypoint (n,), m: a profile's abscissa."""
    step = np.diff(np.asarray(waypoints, dtype=float)[:, :2], axis=0)
    return np.concatenate([[0.0], np.cumsum(np.hypot(step[:, 0], step[:, 1]))])


def point_at(waypoints: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points (m, 2) at horizontal distances ``s`` (m,) along a track."""
    d = along_track_m(waypoints)
    return np.column_stack([np.interp(s, d, waypoints[:, 0]), np.interp(s, d, waypoints[:, 1])])


def distance_to_polyline(points: np.ndarray, line: np.ndarray) -> np.ndarray:
    """Horizontal distance (m,) from each point (m, 2) to a polyline (n, 2); (m × n) at once."""
    a, b = line[:-1, None, :2], line[1:, None, :2]
    ab = b - a
    t = np.clip(np.einsum("sij,sij->si", points[None, :, :2] - a, ab)
                / np.maximum(np.einsum("sij,sij->si", ab, ab), 1e-12), 0.0, 1.0)
    foot = a + t[..., None] * ab
    return np.linalg.norm(points[None, :, :2] - foot, axis=2).min(axis=0)


def detour_window(plan, field, aspect: float = 1.0) -> tuple[float, float, float, float, int]:
    """(x0, x1, y0, y1, k): a window of width/height ``aspect``, 16–30 cells high, on the fork
    where the initial track leaves the shortest one for its largest detour, and the layer the
    initial track flies at the fork.

    The window is shifted towards the detour so that both the fork and the first part of the
    detour are in view; without a detour (tracks within two cells) it shows the largest gap.
    """
    g = field.grid
    initial, shortest = plan.stages["initial"].waypoints, plan.stages["shortest"].waypoints
    # sample the initial track every half cell so long straight segments are seen too
    d = along_track_m(initial)
    s = np.linspace(0.0, d[-1], max(int(d[-1] / (0.5 * min(g.cell[:2]))), 2))
    pts = point_at(initial, s)
    gap = distance_to_polyline(pts, shortest)
    at = int(np.argmax(gap))
    near = gap <= 2.0 * max(g.cell[:2])
    fork = at - int(np.argmax(near[at::-1])) if near[:at + 1].any() else at
    side = float(np.clip(2.0 * gap[at] + 8 * g.cell[1], 16 * g.cell[1], 30 * g.cell[1]))
    ex, ey = g.extent[:2]
    w, h = min(aspect * side, ex), min(side, ey)
    toward = pts[at] - pts[fork]
    reach = float(np.hypot(*toward))
    cx, cy = pts[fork] + (toward * min(1.0, 0.35 * min(w, h) / reach) if reach > 0 else 0.0)
    x0, y0 = np.clip(cx - w / 2, 0.0, ex - w), np.clip(cy - h / 2, 0.0, ey - h)
    k = layer_of(field, float(np.interp(s[fork], d, initial[:, 2])))
    return float(x0), float(x0 + w), float(y0), float(y0 + h), k


def unsafe_spans(model, waypoints: np.ndarray) -> np.ndarray:
    """(K, 2) horizontal-distance intervals (m) in which a track flies through unsafe cells
    (Eq. 9: R > R_0) — the pieces that the binary risk cost of Eq. 11 counts."""
    pts = np.asarray(waypoints, dtype=float)
    cells, s0, s1 = polyline_pieces(pts, model.field.grid.cell)
    cells = np.clip(cells, 0, np.asarray(model.field.grid.shape) - 1)
    unsafe = model.field.unsafe[tuple(cells.T)]
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    ground = along_track_m(pts)
    return np.column_stack([np.interp(s0[unsafe], arc, ground), np.interp(s1[unsafe], arc, ground)])


def corridor_columns(field, waypoints: np.ndarray) -> np.ndarray:
    """(nx, ny) bool: columns holding a cell of a cell-centre path."""
    g = field.grid
    idx = np.clip(np.floor(waypoints[:, :2] / np.asarray(g.cell[:2])).astype(int), 0, np.asarray(g.shape[:2]) - 1)
    mask = np.zeros(g.shape[:2], dtype=bool)
    mask[idx[:, 0], idx[:, 1]] = True
    return mask


def pair_directions(tracks: Mapping[str, np.ndarray], tolerance_m: float) -> list[tuple[str, str | None]]:
    """Group tracks into routes: (forward, reverse) where one track's origin is the other's
    destination (within ``tolerance_m`` horizontally), else (track, None); in the given order.

    >>> a, b = [0.0, 0.0, 120.0], [1000.0, 0.0, 150.0]
    >>> pair_directions({"A-B": np.array([a, b]), "B-A": np.array([b, a])}, 10.0)
    [('A-B', 'B-A')]
    """
    ends = {n: (np.asarray(w, dtype=float)[0, :2], np.asarray(w, dtype=float)[-1, :2]) for n, w in tracks.items()}

    def close(p: np.ndarray, q: np.ndarray) -> bool:
        return float(np.hypot(*(p - q))) <= tolerance_m
    pairs, used = [], set()
    for a in tracks:
        if a in used:
            continue
        used.add(a)
        partner = next((b for b in tracks if b not in used and close(ends[b][0], ends[a][1])
                        and close(ends[b][1], ends[a][0])), None)
        if partner is not None:
            used.add(partner)
        pairs.append((a, partner))
    return pairs


def cruise_altitude_m(waypoints: np.ndarray) -> float:
    """Median altitude over the horizontal distance flown, m (the layer a track cruises on)."""
    wp = np.asarray(waypoints, dtype=float)
    d = along_track_m(wp)
    if d[-1] <= 0:
        return float(np.median(wp[:, 2]))
    return float(np.median(np.interp(np.linspace(0.0, d[-1], 512), d, wp[:, 2])))


def route_waypoints(routes) -> dict[str, np.ndarray]:
    """Name → waypoints (n, 3) from what a network is held as: a mapping of names to arrays, to
    track plans (their optimal stage), to ``network.json`` route entries (``{"waypoints": ...}``)
    or to the tuples of :func:`uamopt.planning.network.plan_network`; or an object or document
    holding such a mapping under ``routes``."""
    if not isinstance(routes, Mapping) or "routes" in routes:
        routes = routes["routes"] if isinstance(routes, Mapping) else routes.routes

    def waypoints(value) -> np.ndarray:
        if isinstance(value, tuple):
            value = next(v for v in value if hasattr(v, "stages"))
        if hasattr(value, "stages"):
            return np.asarray(value.stages["optimal"].waypoints, dtype=float)
        if hasattr(value, "waypoints"):
            return np.asarray(value.waypoints, dtype=float)
        if isinstance(value, Mapping):
            return np.asarray(value["waypoints"], dtype=float)
        return np.asarray(value, dtype=float)
    return {str(name): waypoints(value) for name, value in routes.items()}
