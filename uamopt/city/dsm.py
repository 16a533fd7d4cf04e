"""City layers from a digital surface model (DSM) GeoTIFF, through rasterio.

The DSM must be in a projected CRS in metres (UTM, a national grid). The local frame's (0, 0) is
the raster's (left, bottom) corner, x east, y north (docs/readings.md). Each grid column takes the
maximum DSM value over its footprint (conservative: the column is an obstacle up to its highest
point), then

- ground datum = ``city.ground_m``, or the minimum of the raster under the grid (nodata ignored);
- surface_height = max(DSM − ground, 0); building_height = surface_height where it exceeds
  ``city.building_min_height_m`` (trees and cars below it count as ground), else 0;
- c_s from the Table B.3 height rule, unless ``city.shelter`` gives a c_s GeoTIFF (averaged).

Optional GeoJSON road centre lines (``city.roads``) and no-fly polygons (``city.no_fly``) are in
the raster's CRS, or say otherwise (a "crs" member, or lon/lat; uamopt/city/geojson.py). Population density is
uniform (``city.population_density``).

Bounded memory: nothing reads the whole raster. Column maxima and the ground are GDAL warps onto
the grid's columns, which read only the window under the grid, a chunk at a time; a window of more
pixels than ``grid.memory_limit_gb`` could hold is refused before any read (a 112 KB sparse
GeoTIFF may declare 60,000 × 60,000 pixels). Infinite elevations are refused, not taken as nodata:
nodata columns become ground, and a corrupt roof must not become flyable ground.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import rasterio
import shapely
import shapely.geometry
from affine import Affine
from rasterio.warp import Resampling, reproject

from uamopt.city.geojson import read_geojson_in, require_on_grid
from uamopt.city.layers import CityLayers, burn_mask, line_segments, segment_length_per_cell, shelter_rule
from uamopt.errors import InputFileError, ScenarioError

if TYPE_CHECKING:
    from uamopt.grid import AirspaceGrid
    from uamopt.scenario import Scenario

def _open(path: Path, where: str):
    if not path.is_file():
        raise InputFileError(f"GeoTIFF not found: {path}", where, "give the path of a GeoTIFF raster")
    try:
        return rasterio.open(path)
    except rasterio.errors.RasterioError as exc:
        raise InputFileError(f"cannot read GeoTIFF {path}: {exc}", where, "give a valid GeoTIFF raster") from None


def _dsm_path(scenario: Scenario) -> Path:
    if not scenario.city.dsm:
        raise ScenarioError("city.source is 'dsm' but no DSM GeoTIFF is given", "city.dsm",
                            "set city.dsm to the path of a GeoTIFF digital surface model")
    return scenario.resolve_path(scenario.city.dsm)


def _check_frame(src, path: Path) -> tuple[float, float, float, float]:
    """(left, bottom, right, top) of a north-up raster in a metric projected CRS."""
    fix = "reproject it to a projected CRS in metres, e.g. gdalwarp -t_srs EPSG:32633 in.tif out.tif"
    if src.crs is None:
        raise InputFileError(f"GeoTIFF {path} has no coordinate reference system", "city.dsm", fix)
    if not src.crs.is_projected or (src.crs.linear_units or "").lower() not in ("metre", "meter", "m"):
        raise InputFileError(f"GeoTIFF {path} is not in a projected CRS in metres ({src.crs})", "city.dsm", fix)
    t = src.transform
    if t.b != 0 or t.d != 0 or t.e >= 0:
        raise InputFileError(f"GeoTIFF {path} is rotated or not north-up", "city.dsm",
                             "resample it to a north-up raster, e.g. gdalwarp in.tif out.tif")
    return tuple(src.bounds)


def dsm_extent(scenario: Scenario) -> tuple[float, float]:
    """(x_max, y_max) of the DSM in the local frame: the raster's width and height, m."""
    path = _dsm_path(scenario)
    with _open(path, "city.dsm") as src:
        left, bottom, right, top = _check_frame(src, path)
    return right - left, top - bottom


def dsm_frame(scenario: Scenario) -> tuple[str, float, float]:
    """(CRS, left, bottom): the DSM's projected CRS and the CRS coordinates of the local (0, 0), m."""
    path = _dsm_path(scenario)
    with _open(path, "city.dsm") as src:
        left, bottom, _, _ = _check_frame(src, path)
        return src.crs.to_string(), float(left), float(bottom)


def _on_grid(src, grid: AirspaceGrid, frame: tuple, resampling: Resampling) -> np.ndarray:
    """Band 1 of ``src`` on the grid's columns, (nx, ny) indexed [i, j] with j northward; NaN outside.

    ``frame`` = (crs, left, bottom) of the local frame: the DSM's CRS and its south-west corner, m.
    """
    crs, left, bottom = frame
    nx, ny = grid.shape[:2]
    dx, dy = grid.cell[:2]
    # North-up destination: row 0 is the northernmost row of columns, so flip rows then transpose.
    dst_transform = Affine(dx, 0.0, left, 0.0, -dy, bottom + ny * dy)
    rows_cols = np.full((ny, nx), np.nan)
    try:
        reproject(rasterio.band(src, 1), rows_cols, src_nodata=src.nodata, dst_transform=dst_transform,
                  dst_crs=crs, dst_nodata=np.nan, resampling=resampling)
    except rasterio.errors.RasterioError as exc:
        raise InputFileError(f"cannot resample GeoTIFF {src.name}: {exc}", "city.dsm", "check the raster") from None
    return np.ascontiguousarray(rows_cols[::-1].T)


def _check_window(src, grid: AirspaceGrid, left: float, bottom: float, limit_gb: float | None) -> None:
    """Refuse a raster whose window under the grid holds more pixels than memory could (module docstring)."""
    from uamopt.grid.grid import memory_limit_bytes

    res_x, res_y = abs(src.transform.a), abs(src.transform.e)
    width = min(grid.shape[0] * grid.cell[0], src.width * res_x) / res_x
    height = min(grid.shape[1] * grid.cell[1], src.height * res_y) / res_y
    pixels = math.ceil(width) * math.ceil(height)
    need, limit = pixels * np.dtype(src.dtypes[0]).itemsize, memory_limit_bytes(limit_gb)
    if need > limit:
        raise InputFileError(
            f"the DSM window under the grid holds {pixels:,} pixels ({need / 2**30:.1f} GB), more than the limit of "
            f"{limit / 2**30:.1f} GB", "city.dsm / grid.extent", "shrink grid.extent, resample the DSM to coarser "
            "pixels (gdalwarp -tr 5 5 in.tif out.tif) or raise grid.memory_limit_gb")


def _refuse_infinite(values: np.ndarray, grid: AirspaceGrid, path: Path) -> None:
    """Infinite elevations: refused (module docstring), naming the first column that holds one."""
    bad = np.isinf(values)
    if bad.any():
        i, j = (int(v) for v in np.argwhere(bad)[0])
        x, y = grid.centre_of((i, j, 0))[:2]
        raise InputFileError(f"GeoTIFF {path} holds infinite elevations (first under column ({i}, {j}) at x = {x:g}, "
                             f"y = {y:g} m)", "city.dsm", "set those pixels to the raster's nodata value, or fix the DSM")


def load_dsm(scenario: Scenario, grid: AirspaceGrid) -> CityLayers:
    """The scenario's DSM city on the grid's columns.

    Returns
    -------
    CityLayers
        surface and building heights (m above the ground datum), road length l_r (m), c_s, no-fly.

    Raises
    ------
    ScenarioError
        No ``city.dsm`` given.
    InputFileError
        A GeoTIFF or GeoJSON is missing, unreadable, or the DSM is not in a metric projected CRS.
    """
    cfg = scenario.city
    path = _dsm_path(scenario)
    with _open(path, "city.dsm") as src:
        bounds = _check_frame(src, path)
        left, bottom, crs = bounds[0], bounds[1], src.crs
        _check_window(src, grid, left, bottom, scenario.grid.memory_limit_gb)
        dsm = _on_grid(src, grid, (crs, left, bottom), Resampling.max)
        _refuse_infinite(dsm, grid, path)
        if cfg.ground_m is not None:
            ground = float(cfg.ground_m)
        else:  # the lowest pixel under the grid: a second warp, never a read of the whole raster
            lowest = _on_grid(src, grid, (crs, left, bottom), Resampling.min)
            _refuse_infinite(lowest, grid, path)
            if np.isnan(lowest).all():
                raise InputFileError(f"GeoTIFF {path} holds no valid data under the grid", "city.dsm",
                                     "check its nodata value")
            ground = float(np.nanmin(lowest))
    surface = np.nan_to_num(np.maximum(dsm - ground, 0.0), nan=0.0)  # outside the raster: ground
    building = np.where(surface > cfg.building_min_height_m, surface, 0.0)

    if cfg.shelter:
        spath = scenario.resolve_path(cfg.shelter)
        with _open(spath, "city.shelter") as src:
            shelter = _on_grid(src, grid, (crs, left, bottom), Resampling.average)
        shelter = np.where(np.isnan(shelter), shelter_rule(building, cfg), shelter)
    else:
        shelter = shelter_rule(building, cfg)

    def local(geoms: list) -> list:
        return list(shapely.transform(np.asarray(geoms, dtype=object), lambda xy: xy - np.array([left, bottom])))

    def layer(key: str, kind: str) -> list:  # in the raster's CRS (or reprojected to it), on the grid
        path_ = scenario.resolve_path(getattr(cfg, key))
        geoms = local(read_geojson_in(path_, f"city.{key}", (kind,), crs.to_wkt(), bounds))
        require_on_grid(geoms, grid.extent[:2], path_, f"city.{key}")
        return geoms

    roads = layer("roads", "LineString") if cfg.roads else []
    no_fly = layer("no_fly", "Polygon") if cfg.no_fly else []
    return CityLayers(
        surface_height=surface,
        building_height=building,
        road_length=segment_length_per_cell(line_segments(roads), grid),
        population_density=np.full((grid.shape[0], grid.shape[1]), cfg.population_density),
        shelter=shelter,
        no_fly=burn_mask(no_fly, grid),
        open_space=np.zeros((grid.shape[0], grid.shape[1]), dtype=bool),
        source="dsm",
        crs=crs.to_string(),
        origin=(float(left), float(bottom)),
        notes={"ground_m": ground, "dsm_file": str(path), "roads": len(roads), "no_fly_zones": len(no_fly)},
    )
