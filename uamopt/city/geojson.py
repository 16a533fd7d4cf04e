"""Reading GeoJSON vector layers (roads, no-fly zones) with json and shapely only."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import shapely
import shapely.geometry

from uamopt.errors import InputFileError

_KINDS = {"LineString": (1, 5), "Polygon": (3, 6)}  # shapely type ids of a kind and its Multi form


def read_geojson(path: Path, where: str, kinds: tuple[str, ...]) -> list[shapely.Geometry]:
    """Geometries of a GeoJSON file (FeatureCollection, Feature or bare geometry), split into parts.

    Parameters
    ----------
    path : Path
        The GeoJSON file; coordinates are taken as they are (no CRS conversion).
    where : str
        The scenario key that named the file, for error messages (``city.roads``).
    kinds : tuple of str
        Geometry kinds kept, ``"LineString"`` and/or ``"Polygon"`` (their Multi forms included).

    Raises
    ------
    InputFileError
        Missing or malformed file, or a file with geometries none of which is of ``kinds``.
    """
    if not path.is_file():
        raise InputFileError(f"GeoJSON file not found: {path}", where, "give the path of a .geojson file")
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        if doc.get("type") == "FeatureCollection":
            raw = [f.get("geometry") for f in doc["features"]]
        elif doc.get("type") == "Feature":
            raw = [doc.get("geometry")]
        else:
            raw = [doc]
        geoms = np.asarray([shapely.geometry.shape(g) for g in raw if g], dtype=object)
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError, AttributeError, shapely.errors.ShapelyError) as exc:
        raise InputFileError(f"cannot read GeoJSON {path}: {exc.__class__.__name__}: {exc}", where,
                             "give a valid GeoJSON FeatureCollection (RFC 7946)") from None
    parts = shapely.get_parts(geoms) if len(geoms) else geoms
    wanted = [t for kind in kinds for t in _KINDS[kind]]
    kept = parts[np.isin(shapely.get_type_id(parts), wanted) & ~shapely.is_empty(parts)] if len(parts) else parts
    if len(parts) and not len(kept):
        raise InputFileError(f"GeoJSON {path} holds no {' or '.join(kinds)} geometry", where,
                             f"give {' or '.join(kinds)} features")
    return list(kept)
