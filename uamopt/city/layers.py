"""Ground-truth city layers on the grid's footprint, and the rasterisation every source shares.

Every source (synthetic, OpenStreetMap, DSM GeoTIFF) ends in the same :class:`CityLayers`:
arrays of shape (nx, ny), one value per column of cells. Vector sources first produce a
:class:`VectorCity` in the local metric frame and go through :func:`rasterize_city`, so the
synthetic city and a real one are rasterised by the same code.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import shapely
from affine import Affine
from rasterio import features

from uamopt.grid import AirspaceGrid
from uamopt.grid.geometry import split_segments
from uamopt.scenario import CityConfig


@dataclass(frozen=True)
class CityLayers:
    """City layers, each an array of shape (nx, ny) over the grid's columns.

    Attributes
    ----------
    surface_height : float array, m
        Building top, or ground, above the datum (z = 0).
    building_height : float array, m
        Height of the building above the ground; 0 where there is none.
    road_length : float array, m
        l_r: length of road centre line inside the column's footprint (docs/readings.md).
    population_density : float array, 1/m²
        ρ_P under the column.
    shelter : float array
        c_s under the column (Table B.1/B.3 rule or a user layer).
    no_fly : bool array
        Column inside a no-fly zone (Eq. 9: impassable at every altitude).
    open_space : bool array
        Park or water (no buildings, no roads by construction); for maps only.
    """

    surface_height: np.ndarray
    building_height: np.ndarray
    road_length: np.ndarray
    population_density: np.ndarray
    shelter: np.ndarray
    no_fly: np.ndarray
    open_space: np.ndarray
    source: str
    attribution: str = ""
    crs: str = ""
    origin: tuple[float, float] = (0.0, 0.0)
    notes: dict = field(default_factory=dict)

    @property
    def building(self) -> np.ndarray:
        """Building footprint (bool, (nx, ny))."""
        return self.building_height > 0


@dataclass(frozen=True)
class VectorCity:
    """A city as geometry in the local metric frame (x east, y north, metres from the SW corner).

    ``buildings`` and ``heights_m`` are parallel; roads are centre lines; ``origin`` is the local
    (0, 0) in ``crs`` coordinates, for the record.
    """

    extent: tuple[float, float]
    buildings: list[shapely.Geometry]
    heights_m: np.ndarray
    roads: list[shapely.Geometry]
    no_fly: list[shapely.Geometry]
    open_space: list[shapely.Geometry]
    source: str
    attribution: str = ""
    crs: str = ""
    origin: tuple[float, float] = (0.0, 0.0)
    notes: dict = field(default_factory=dict)


def _grid_transform(grid: AirspaceGrid) -> Affine:
    # Row r = y / Δy, column c = x / Δx: rasters come out as (ny, nx), transposed to (nx, ny).
    return Affine(grid.cell[0], 0.0, 0.0, 0.0, grid.cell[1], 0.0)


def burn_max(shapes: list[shapely.Geometry], values: np.ndarray, grid: AirspaceGrid, all_touched: bool = True) -> np.ndarray:
    """Maximum of ``values`` over every shape touching each column, 0 elsewhere, (nx, ny).

    ``all_touched`` marks every column the shape touches (conservative: a column partly covered
    by a building is an obstacle up to the building's top).
    """
    out_shape = (grid.shape[1], grid.shape[0])
    if len(shapes) == 0:
        return np.zeros(grid.shape[:2])
    order = np.argsort(values, kind="stable")  # later shapes overwrite: tallest last wins
    pairs = [(shapes[i], float(values[i])) for i in order if not shapes[i].is_empty]
    if not pairs:
        return np.zeros(grid.shape[:2])
    burned = features.rasterize(
        pairs, out_shape=out_shape, transform=_grid_transform(grid), fill=0.0,
        all_touched=all_touched, dtype="float64",
    )
    return np.ascontiguousarray(burned.T)


def burn_mask(shapes: list[shapely.Geometry], grid: AirspaceGrid, all_touched: bool = True) -> np.ndarray:
    """Columns touched by any of the shapes (bool, (nx, ny))."""
    return burn_max(shapes, np.ones(len(shapes)), grid, all_touched) > 0


def line_segments(lines: list[shapely.Geometry]) -> np.ndarray:
    """All straight segments (M, 4) = x0, y0, x1, y1 of (multi)line geometries."""
    parts = shapely.get_parts(np.asarray(lines, dtype=object)) if len(lines) else np.empty(0, dtype=object)
    chunks = []
    for line in parts:
        xy = shapely.get_coordinates(line)
        if len(xy) >= 2:
            chunks.append(np.hstack([xy[:-1], xy[1:]]))
    return np.vstack(chunks) if chunks else np.empty((0, 4))


def segment_length_per_cell(segments: np.ndarray, grid: AirspaceGrid) -> np.ndarray:
    """Length of the segments inside each column's footprint, m, (nx, ny).

    Each segment is cut at every vertical (x = iΔx) and horizontal (y = jΔy) grid line it crosses;
    each piece lies in one column, found from its midpoint. Pieces outside the grid are dropped.
    Vectorised over segments and crossings: no Python loop over cells.
    """
    nx, ny = grid.shape[:2]
    seg = np.asarray(segments, dtype=float).reshape(-1, 4)
    if len(seg) == 0:
        return np.zeros((nx, ny))
    starts, ends = seg[:, :2], seg[:, 2:]
    owner, t0, t1 = split_segments(starts, ends, grid.cell[:2])
    mid = starts[owner] + (0.5 * (t0 + t1))[:, None] * (ends[owner] - starts[owner])
    length = (t1 - t0) * np.linalg.norm(ends - starts, axis=1)[owner]
    i = np.floor(mid[:, 0] / grid.cell[0]).astype(np.int64)
    j = np.floor(mid[:, 1] / grid.cell[1]).astype(np.int64)
    inside = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
    flat = np.bincount(i[inside] * ny + j[inside], weights=length[inside], minlength=nx * ny)
    return flat.reshape(nx, ny)


def shelter_rule(building_height: np.ndarray, cfg: CityConfig) -> np.ndarray:
    """c_s per column (Table B.3): ``shelter_high`` over buildings taller than
    ``shelter_height_m`` (15 m), ``shelter_low`` elsewhere, including open ground (docs/readings.md)."""
    return np.where(building_height > cfg.shelter_height_m, cfg.shelter_high, cfg.shelter_low).astype(float)


def rasterize_city(city: VectorCity, grid: AirspaceGrid, cfg: CityConfig) -> CityLayers:
    """Put a :class:`VectorCity` on the grid's columns."""
    building_height = burn_max(city.buildings, np.asarray(city.heights_m, dtype=float), grid)
    road_length = segment_length_per_cell(line_segments(city.roads), grid)
    return CityLayers(
        surface_height=building_height.copy(),  # flat ground at the datum
        building_height=building_height,
        road_length=road_length,
        population_density=np.full(grid.shape[:2], cfg.population_density),
        shelter=shelter_rule(building_height, cfg),
        no_fly=burn_mask(city.no_fly, grid),
        open_space=burn_mask(city.open_space, grid, all_touched=False),
        source=city.source,
        attribution=city.attribution,
        crs=city.crs,
        origin=city.origin,
        notes=dict(city.notes),
    )
