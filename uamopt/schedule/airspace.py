"""Tracks read from files (``--network``, ``--flights``) must fly in the scenario's airspace.

A planned track (Sec. 4.2) stays in admissible cells by construction; a track from a file is
untrusted input. Before anything is scheduled each one must

- lie inside the scenario's grid, [0, x_max] × [0, y_max] × [0, z_max] (Sec. 3), by
  :func:`uamopt.bounds.outside_grid`, the rule the flights reader and ``uamopt verify`` apply too
  (1e-6 m of slack on the top faces, none below 0);
- stay above the ground datum, z > 0: flights are flown airborne (take-off and landing are not
  modelled, docs/readings.md), so a track at z = 0 is not a flight;
- stay above the city's surface (building tops and ground, the obstacles of Eq. 15) at every
  point, sampled every quarter of a cell along each segment, unless ``network.tracks =
  "straight"``, whose tracks ignore the city by definition (scheduler benchmarks).

The surface is the city source on the columns of the file's own cells, each column at its highest
point, the rule by which the planner marks obstacle cells (uamopt/risk.py), so a track planned on
those cells never fails; a track through a 239 m tower at 120 m does. The city itself is built by
the caller (:func:`uamopt.pipeline.scenario_flights`): the schedule stage only checks.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from uamopt.bounds import GRID_TOL_M, outside_grid
from uamopt.errors import InputFileError

TOL_M = GRID_TOL_M  # slack for a height on the ground or the city's surface, m
SAMPLES_PER_CELL = 4  # surface samples per cell side along a segment


def _points(waypoints: np.ndarray, cell: tuple[float, float, float]) -> np.ndarray:
    """Points along a track, at most a quarter of a cell apart horizontally (waypoints included)."""
    a, b = waypoints[:-1], waypoints[1:]
    step = min(cell[0], cell[1]) / SAMPLES_PER_CELL
    counts = np.maximum(1, np.ceil(np.hypot(*(b - a)[:, :2].T) / step).astype(np.int64))
    seg = np.repeat(np.arange(len(a)), counts)
    u = (np.arange(len(seg)) - np.repeat(np.cumsum(counts) - counts, counts)) / np.repeat(counts, counts)
    return np.vstack([a[seg] + u[:, None] * (b - a)[seg], waypoints[-1:]])


def _unique(tracks: Mapping[str, np.ndarray]) -> list[tuple[str, np.ndarray]]:
    """Each distinct track once, named by its first holder (flights on one route share a track)."""
    unique: dict[bytes, tuple[str, np.ndarray]] = {}
    for name, w in tracks.items():
        unique.setdefault(np.asarray(w, dtype=float).tobytes(), (name, np.asarray(w, dtype=float)))
    return list(unique.values())


def check_in_airspace(extent, tracks: Mapping[str, np.ndarray], source: str, kind: str = "route") -> None:
    """Refuse a track outside the grid or at or below the ground (module docstring).

    Parameters
    ----------
    extent : (x_max, y_max, z_max)
        The scenario's grid, m (``uamopt.pipeline.scenario_grid(scenario).extent``).
    tracks : mapping name -> (n, 3) waypoints, m
        Routes of a network file or flights of a flights file.
    source, kind : str
        The file as the user named it (``--network net.json``) and what a track is in it (``route``,
        ``flight``): errors say ``<source>: <kind> <name>``.

    Raises
    ------
    InputFileError
        The first track that breaks a rule, with the point.
    """
    extent = np.asarray(extent, dtype=float)
    for name, w in _unique(tracks):
        bad = outside_grid(w, extent)
        if bad.any():
            p = ", ".join(f"{v:g}" for v in w[np.argmax(bad)])
            raise InputFileError(f"waypoint ({p}) is outside the grid [0, {', '.join(f'{e:g}' for e in extent)}] m",
                                 f"{source}: {kind} {name}", "move the track inside the airspace or enlarge grid.extent")
        if np.any(w[:, 2] <= TOL_M):
            p = ", ".join(f"{v:g}" for v in w[np.argmax(w[:, 2] <= TOL_M)])
            raise InputFileError(f"waypoint ({p}) is on or below the ground (z ≤ 0)", f"{source}: {kind} {name}",
                                 "give the track's altitudes in metres above the ground datum (Eq. 14's band)")


def check_above_surface(tracks: Mapping[str, np.ndarray], surface: np.ndarray, cell, source: str,
                        kind: str = "route") -> None:
    """Refuse a track that passes below the city's surface (module docstring).

    Parameters
    ----------
    tracks : mapping name -> (n, 3) waypoints, m
        Tracks already inside the airspace (:func:`check_in_airspace`).
    surface : (nx, ny) array, m
        The city's surface height per column of the file's cells (``CityLayers.surface_height``
        of the city built on those cells).
    cell : (Δx, Δy, Δz)
        The file's cells, m (the grid its tracks were planned on).
    source, kind : str
        As :func:`check_in_airspace`.

    Raises
    ------
    InputFileError
        The first track that passes through a building, with the point and the column.
    """
    cell = tuple(float(c) for c in cell)
    shape = np.asarray(surface.shape[:2]) - 1
    for name, w in _unique(tracks):
        pts = _points(w, cell)
        ij = np.clip(np.floor(pts[:, :2] / np.asarray(cell[:2])).astype(np.int64), 0, shape)
        top = surface[ij[:, 0], ij[:, 1]]
        inside = pts[:, 2] < top - TOL_M
        if inside.any():
            k = int(np.argmax(inside))
            at = ", ".join(f"{v:.1f}" for v in pts[k])
            raise InputFileError(
                f"the track passes through a building: ({at}) is below the city's surface at {top[k]:.1f} m "
                f"(column {tuple(int(v) for v in ij[k])} of {', '.join(f'{c:g}' for c in cell)} m cells)",
                f"{source}: {kind} {name}", "re-plan it with `uamopt network` or lift it above the roofs; set "
                "network.tracks = 'straight' to schedule tracks that ignore the city")
