"""Reading GeoJSON vector layers (roads, no-fly zones) with json and shapely, and putting them in
the city's CRS with pyproj.

Which CRS a file is in: the one its ``"crs"`` member names (GDAL writes it for projected data);
without one, WGS 84 longitude/latitude (RFC 7946) when every coordinate is one and the city's own
coordinates are not; else the city's CRS. A layer none of whose geometries touches the grid is
refused: a file for another place or in another CRS would otherwise silently do nothing.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import shapely
import shapely.geometry

from uamopt.bounds import parse_error
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
    return _read(path, where, kinds)[0]


def _read(path: Path, where: str, kinds: tuple[str, ...]) -> tuple[list[shapely.Geometry], str | None]:
    """(geometries, the CRS named by the file's "crs" member or None)."""
    if not path.is_file():
        raise InputFileError(f"GeoJSON file not found: {path}", where, "give the path of a .geojson file")
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        named = doc.get("crs")
        named = None if named is None else str(named["properties"]["name"])
        if doc.get("type") == "FeatureCollection":
            raw = [f.get("geometry") for f in doc["features"]]
        elif doc.get("type") == "Feature":
            raw = [doc.get("geometry")]
        else:
            raw = [doc]
        with np.errstate(invalid="ignore"):  # a NaN coordinate: refused below, in one line, not warned about
            geoms = np.asarray([shapely.geometry.shape(g) for g in raw if g], dtype=object)
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError, AttributeError, RecursionError,
            OverflowError, shapely.errors.ShapelyError) as exc:  # OverflowError: a 400-digit coordinate
        text = parse_error(exc) if isinstance(exc, ValueError) else " ".join(str(exc).split())
        raise InputFileError(f"cannot read GeoJSON {path}: {exc.__class__.__name__}: {text}", where,
                             "give a valid GeoJSON FeatureCollection (RFC 7946)") from None
    if len(geoms) and not np.isfinite(shapely.get_coordinates(geoms)).all():
        raise InputFileError(f"GeoJSON {path} holds a coordinate that is not a finite number (NaN or inf)", where,
                             "give every coordinate as a number")
    parts = shapely.get_parts(geoms) if len(geoms) else geoms
    wanted = [t for kind in kinds for t in _KINDS[kind]]
    kept = parts[np.isin(shapely.get_type_id(parts), wanted) & ~shapely.is_empty(parts)] if len(parts) else parts
    if len(parts) and not len(kept):
        raise InputFileError(f"GeoJSON {path} holds no {' or '.join(kinds)} geometry", where,
                             f"give {' or '.join(kinds)} features")
    return list(kept), named


def _is_lonlat(bounds) -> bool:
    west, south, east, north = bounds
    return -180.0 <= west <= east <= 180.0 and -90.0 <= south <= north <= 90.0


def read_geojson_in(path: Path, where: str, kinds: tuple[str, ...], crs: str,
                    city_bounds: tuple[float, float, float, float] | None = None) -> list[shapely.Geometry]:
    """The geometries of :func:`read_geojson` in ``crs``, the city's CRS (module docstring).

    ``city_bounds`` (west, south, east, north in ``crs``) tells lon/lat files from files in ``crs``;
    ``None``: the file must name its CRS or be lon/lat.

    Raises
    ------
    InputFileError
        As :func:`read_geojson`; a "crs" member pyproj does not know; a file that is neither in
        lon/lat nor names its CRS where the city's CRS cannot be assumed.
    """
    from pyproj import CRS, Transformer
    from pyproj.exceptions import CRSError

    geoms, named = _read(path, where, kinds)
    if not geoms:
        return geoms
    if named is not None:
        try:
            source = CRS.from_user_input(named)
        except CRSError:
            raise InputFileError(f"GeoJSON {path} names an unknown CRS {named!r}", where,
                                 "name an EPSG code, e.g. urn:ogc:def:crs:EPSG::32633, or write lon/lat") from None
    elif _is_lonlat(shapely.total_bounds(np.asarray(geoms, dtype=object))) and not (
            city_bounds is not None and _is_lonlat(city_bounds)):
        source = CRS.from_epsg(4326)
    elif city_bounds is not None:
        return geoms  # in the city's CRS, as the dsm source documents
    else:
        raise InputFileError(f"GeoJSON {path} is not in longitude/latitude and names no CRS", where,
                             "write WGS 84 lon/lat (RFC 7946) or add a \"crs\" member naming its EPSG code")
    target = CRS.from_user_input(crs)
    if source == target:
        return geoms
    move = Transformer.from_crs(source, target, always_xy=True)
    return list(shapely.transform(np.asarray(geoms, dtype=object),
                                  lambda xy: np.column_stack(move.transform(xy[:, 0], xy[:, 1]))))


def require_on_grid(geoms: list[shapely.Geometry], extent: tuple[float, float], path: Path, where: str) -> None:
    """Refuse a layer none of whose geometries touches [0, x_max] × [0, y_max] of the local frame."""
    if geoms and not shapely.intersects(np.asarray(geoms, dtype=object), shapely.box(0.0, 0.0, *extent)).any():
        west, south, east, north = shapely.total_bounds(np.asarray(geoms, dtype=object))
        raise InputFileError(
            f"none of the {len(geoms)} geometries of {path} lies on the grid (they span x {west:.0f} to {east:.0f}, "
            f"y {south:.0f} to {north:.0f} m in the local frame; the grid is 0 to {extent[0]:g}, 0 to {extent[1]:g})",
            where, "check the file's CRS (a \"crs\" member, or lon/lat) and that it covers this city")

