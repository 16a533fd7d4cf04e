"""``uamopt export geojson DIR``: tracks, vertiports and unsafe airspace for GIS tools.

Writes three RFC 7946 files into the schedule folder DIR, in WGS 84 (longitude, latitude[, z]),
through the folder's :class:`~uamopt.export.frame.LocalFrame`; QGIS, GeoPandas, Shapely and
kepler.gl read them as they are (every position has two or three elements):

- ``tracks.geojson``: one LineString per flight, positions [lon, lat, z] with z (m above the
  ground datum) at every waypoint; properties id, aircraft, route, origin, destination, operated,
  departure_s, arrival_s (null when cancelled), speed_mps, length_m. An operated flight also
  carries the time of its vertices in the properties ``timestamps`` (s on the schedule's clock,
  the clock of departure_s, one per vertex: departure + :func:`~uamopt.schedule.flights.waypoint_times_s`)
  and ``time_origin_utc``; a cancelled flight has neither. The schedule records no calendar date,
  so clock 0 s is the fixed :data:`TIME_ORIGIN_UTC` (Unix time :data:`TIME_ORIGIN_UNIX_S` + clock),
  also in the collection's ``uamopt`` member.
- ``vertiports.geojson``: one Point per vertiport named in the flights (a track's first point is
  its origin, its last point its destination).
- ``unsafe.geojson``: one (Multi)Polygon per altitude layer, the union of that layer's unsafe
  cells (Eq. 9: risk above R_0, obstacle or no-fly); properties layer, z_bottom_m, z_top_m,
  z_centre_m, in_band (Eq. 14; null when read from a risk.npz), unsafe_cells, obstacle_cells.

It also writes ``trips.kepler.json`` for trip layers: the operated flights only, in kepler.gl's trip-layer
convention, a FeatureCollection of LineStrings whose positions have four elements
[lon, lat, z, t], t the Unix time in seconds rounded to the millisecond (kepler.gl's time
detection takes at most 3 decimals), with the same properties as in tracks.geojson and the time
origin in the collection's ``uamopt`` member. Four-element positions are not RFC 7946 (positions
SHOULD NOT have more than three elements, and Shapely refuses them), which is why that file is a
``.json`` and not a ``.geojson``; kepler.gl loads it by its content.

The unsafe airspace needs the risk field. By default it is recomputed from the scenario the folder
records (summary.json ``scenario``: file and overrides); ``risk=`` takes a ``risk.npz`` written by
``uamopt risk`` instead, and ``scenario=`` names the scenario file when the folder records none.
"""

from __future__ import annotations

import json
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import shapely
import shapely.geometry
from shapely.geometry.polygon import orient

from uamopt.errors import InputFileError
from uamopt.export.folder import (
    OperatedFlight,
    ScheduleFolder,
    read_schedule_folder,
    recorded_scenario,
    write_texts,
)
from uamopt.io import read_npz
from uamopt.schedule.flights import waypoint_times_s

DEGREE_DIGITS = 7  # ~1 cm
METRE_DIGITS = 2
#: the UTC instant of the schedule clock's 0 s: a schedule records no calendar date (summary.json,
#: the scenario and the frame carry none), so the trip layers' Unix times start at a fixed day
TIME_ORIGIN_UTC = "2026-01-01T00:00:00Z"
TIME_ORIGIN_UNIX_S = int(datetime(2026, 1, 1, tzinfo=UTC).timestamp())  # 1767225600
#: decimals of trips.kepler.json's 4th coordinate (ms): kepler.gl recognises Unix seconds with at most 3 decimals
UNIX_DIGITS = 3


def _collection(features: list[dict], folder: ScheduleFolder, what: str, extra: dict | None = None) -> str:
    doc = {"type": "FeatureCollection", "name": what, "features": features,
           "uamopt": {"folder": folder.path.name, "frame": folder.frame.as_dict(), "frame_recorded": folder.frame_recorded,
                      **(extra or {})}}
    return json.dumps(doc, separators=(",", ":")) + "\n"


def vertex_times_s(o: OperatedFlight) -> np.ndarray:
    """Clock time of each waypoint of the operated flight ``o``, s: its departure
    plus the time to reach the waypoint at ``speed_mps``, the vertical phases at their rate."""
    f = o.flight
    return o.departure_s + waypoint_times_s(f.waypoints, f.speed_mps, f.vertical_rate_mps)


def _lonlat(frame, xy: np.ndarray) -> np.ndarray:
    lon, lat = frame.to_lonlat(xy[:, 0], xy[:, 1])
    return np.column_stack([np.round(lon, DEGREE_DIGITS), np.round(lat, DEGREE_DIGITS)])


def _tracks(folder: ScheduleFolder) -> list[tuple[np.ndarray, dict, np.ndarray | None]]:
    """Per flight of the folder: its [lon, lat, z] positions, its properties and, when it is
    operated, the clock time of every vertex (s; None when cancelled)."""
    times = {o.flight.id: o for o in folder.operated}
    out = []
    for f in folder.flights.flights:
        wp = np.asarray(f.waypoints, float)
        coords = np.column_stack([_lonlat(folder.frame, wp), np.round(wp[:, 2], METRE_DIGITS)])
        o = times.get(f.id)
        properties = {"id": f.id, "aircraft": f.aircraft, "route": f.route, "origin": f.origin,
                      "destination": f.destination, "operated": o is not None,
                      "departure_s": o.departure_s if o else None, "arrival_s": o.arrival_s if o else None,
                      "speed_mps": f.speed_mps, "length_m": round(f.length_m, METRE_DIGITS)}
        clock = None
        if o is not None:
            clock = vertex_times_s(o)
            properties.update(timestamps=clock.tolist(), time_origin_utc=TIME_ORIGIN_UTC)
        out.append((coords, properties, clock))
    return out


def _line(coords: np.ndarray, properties: dict) -> dict:
    return {"type": "Feature", "geometry": {"type": "LineString", "coordinates": coords.tolist()},
            "properties": properties}


def track_features(folder: ScheduleFolder) -> list[dict]:
    """One LineString Z feature per flight of the folder, RFC 7946 positions [lon, lat, z]; an
    operated flight's with the time of every vertex (``timestamps``, clock s)."""
    return [_line(coords, properties) for coords, properties, _ in _tracks(folder)]


def trip_features(folder: ScheduleFolder) -> list[dict]:
    """kepler.gl's trip layer: one LineString per operated flight with positions [lon, lat, z, t],
    t its Unix time in s rounded to the millisecond (not RFC 7946: four elements)."""
    return [_line(np.column_stack([coords, np.round(TIME_ORIGIN_UNIX_S + clock, UNIX_DIGITS)]), properties)
            for coords, properties, clock in _tracks(folder) if clock is not None]


def vertiport_features(folder: ScheduleFolder) -> list[dict]:
    """One Point per vertiport label: a track's first point (origin) or last point (destination)."""
    places: dict[str, np.ndarray] = {}
    for f in folder.flights.flights:
        places.setdefault(f.origin, np.asarray(f.waypoints[0], float))
        places.setdefault(f.destination, np.asarray(f.waypoints[-1], float))
    out = []
    for name, p in places.items():
        lon, lat = _lonlat(folder.frame, p[None, :2])[0]
        out.append({"type": "Feature", "geometry": {"type": "Point", "coordinates": [lon, lat]},
                    "properties": {"name": name, "x_m": float(p[0]), "y_m": float(p[1])}})
    return out


def _layer_polygons(mask: np.ndarray, cell: tuple[float, float]) -> shapely.Geometry:
    """The union of the True cells of an (nx, ny) layer as polygons in the local frame."""
    from affine import Affine
    from rasterio import features

    grid = np.ascontiguousarray(mask.T.astype(np.uint8))  # rows = y, columns = x
    transform = Affine(cell[0], 0.0, 0.0, 0.0, cell[1], 0.0)
    parts = [shapely.geometry.shape(g) for g, v in features.shapes(grid, mask=grid.astype(bool), transform=transform) if v]
    return shapely.union_all(parts)


def unsafe_features(folder: ScheduleFolder, unsafe: np.ndarray, obstacle: np.ndarray, cell, z: np.ndarray,
                    band: tuple[float, float] | None) -> list[dict]:
    """One (Multi)Polygon feature per layer with unsafe cells, right-hand rule (RFC 7946)."""
    out = []
    for k in range(unsafe.shape[2]):
        if not unsafe[:, :, k].any():
            continue
        local = _layer_polygons(unsafe[:, :, k], cell[:2])
        geo = shapely.transform(local, lambda xy: _lonlat(folder.frame, xy))
        polys = [orient(p, sign=1.0) for p in shapely.get_parts(geo)]
        geom = polys[0] if len(polys) == 1 else shapely.MultiPolygon(polys)
        out.append({"type": "Feature", "geometry": shapely.geometry.mapping(geom),
                    "properties": {"layer": k, "z_bottom_m": float(z[k] - cell[2] / 2), "z_top_m": float(z[k] + cell[2] / 2),
                                   "z_centre_m": float(z[k]),
                                   "in_band": None if band is None else bool(band[0] - 1e-9 <= z[k] <= band[1] + 1e-9),
                                   "unsafe_cells": int(unsafe[:, :, k].sum()), "obstacle_cells": int(obstacle[:, :, k].sum())}})
    return out


def _unsafe_layers(folder: ScheduleFolder, risk: str | Path | None, scenario: str | None, overrides: list[str] | None):
    """(unsafe, obstacle, cell, z, band) from a risk.npz or from the recorded scenario."""
    if risk is not None:
        path = Path(risk)
        if not path.is_file():
            raise InputFileError(f"risk file not found: {path}", "--risk", "give a risk.npz written by uamopt risk")
        fix = "give a risk.npz written by uamopt risk"
        data = read_npz(path, fix, ("unsafe", "obstacle", "z", "cell"))  # sizes checked before decompressing
        try:
            unsafe, obstacle, z = data["unsafe"].astype(bool), data["obstacle"].astype(bool), data["z"]
            cell = tuple(float(c) for c in data["cell"])
            band = None  # risk.npz does not record the altitude band
        except (KeyError, ValueError, TypeError) as exc:
            raise InputFileError(f"cannot read {path.name}: {exc}", str(path), fix) from None
        return unsafe, obstacle, cell, z, band
    from uamopt.pipeline import compute_risk

    field = compute_risk(recorded_scenario(folder, scenario, overrides))
    return field.unsafe, field.obstacle, tuple(field.grid.cell), field.grid.z, tuple(field.band)


def export_geojson(path: str | Path, *, risk: str | Path | None = None, scenario: str | None = None,
                   overrides: list[str] | None = None) -> list[Path]:
    """Write tracks.geojson, vertiports.geojson, unsafe.geojson (RFC 7946) and trips.kepler.json
    (kepler.gl's trip layer) into the schedule folder ``path``, all or nothing; returns their paths.

    Raises
    ------
    InputFileError
        The folder, a file in it or ``risk`` is missing or malformed, or the folder records no
        scenario and neither ``risk`` nor ``scenario`` is given.
    ScenarioError
        The scenario file is missing or malformed.
    """
    folder = read_schedule_folder(path)
    layers = _unsafe_layers(folder, risk, scenario, overrides)  # before writing anything
    origin = {"time_origin_utc": TIME_ORIGIN_UTC, "time_origin_unix_s": TIME_ORIGIN_UNIX_S}
    files = {"tracks.geojson": ("tracks", track_features(folder), origin),
             "vertiports.geojson": ("vertiports", vertiport_features(folder), None),
             "unsafe.geojson": ("unsafe", unsafe_features(folder, *layers), None),
             "trips.kepler.json": ("trips", trip_features(folder), origin)}
    return write_texts(folder.path, {name: _collection(features, folder, what, extra)
                                     for name, (what, features, extra) in files.items()})
