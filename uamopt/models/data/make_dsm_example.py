"""Writes the example DSM city of ``models/dsm_example.toml``: ``dsm_example.tif`` (digital surface
model), ``dsm_example_roads.geojson`` (road centre lines) and ``dsm_example_no_fly.geojson``.

The city is invented (a seeded generator, not a survey), 1200 m east × 1000 m north, in UTM zone
33N (EPSG:32633), south-west corner at E 400 000, N 5 800 000:

- flat ground 34.0-35.2 m above sea level (a gentle west-east slope, less than the 2 m that
  ``city.building_min_height_m`` counts as a building);
- a street grid turned 14° anticlockwise from north (avenues 170 m apart, streets 140 m apart)
  and a diagonal boulevard, kept free of buildings in the DSM and drawn as road centre lines;
- a river across the north, 60 m wide, crossed by two avenues; a park in the west; a station
  square in the south-east (the vertiports of ``models/dsm_example.toml`` stand in the park, on the
  station square and on the two river banks);
- blocks of buildings whose height falls with the distance from a downtown at (650, 430) m:
  towers of 110-180 m on podiums within about 230 m, mid-rise 25-70 m around them, low-rise
  8-25 m further out;
- one no-fly zone (a hospital block in the east).

The files are in the repository; this script is how they were made (``python
models/data/make_dsm_example.py`` rewrites them; needs numpy, rasterio and shapely). The DSM has
2 m pixels and is deflate-compressed (about 30 KB).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import rasterio
import shapely
from affine import Affine
from shapely.geometry import LineString, box

HERE = Path(__file__).resolve().parent
CRS = "EPSG:32633"
LEFT, BOTTOM = 400_000.0, 5_800_000.0  # UTM 33N, m
WIDTH_M, HEIGHT_M = 1200.0, 1000.0
PIXEL_M = 2.0
GROUND_M = 34.0
SEED = 2024
THETA = math.radians(14.0)  # the street grid's turn from north, anticlockwise
CENTRE = (600.0, 500.0)  # the grid turns about this point (local frame, m)

# In the street grid's own frame (u along the streets, v along the avenues; u = x, v = y at THETA = 0):
AVENUES = [(u, 24.0 if n % 2 == 0 else 14.0) for n, u in enumerate(np.arange(-280.0, 1500.0, 170.0))]
STREETS = [(v, 24.0 if n % 3 == 1 else 14.0) for n, v in enumerate(np.arange(-230.0, 1250.0, 140.0))]
BOULEVARD = ((-100.0, 40.0), (640.0, 800.0), 30.0)  # from, to (u, v), width (m)
PARK = (2, 2, 4, 5)  # blocks: avenue gap index range, street gap index range (inclusive)
STATION_SQUARE = (6, 6, 2, 2)
HOSPITAL = (7, 7, 5, 5)
DOWNTOWN = (650.0, 430.0)  # x, y
RIVER_Y, RIVER_HALF_WIDTH = 870.0, 30.0
BRIDGES = (3, 6)  # indices of the avenues that cross the river
SETBACK_M = 5.0  # building line behind the street's edge


def to_grid(x, y):
    """Local (x, y) → street-grid frame (u, v)."""
    dx, dy = np.asarray(x) - CENTRE[0], np.asarray(y) - CENTRE[1]
    c, s = math.cos(THETA), math.sin(THETA)
    return CENTRE[0] + c * dx + s * dy, CENTRE[1] - s * dx + c * dy


def from_grid(u, v):
    """Street-grid frame (u, v) → local (x, y)."""
    du, dv = np.asarray(u) - CENTRE[0], np.asarray(v) - CENTRE[1]
    c, s = math.cos(THETA), math.sin(THETA)
    return CENTRE[0] + c * du - s * dv, CENTRE[1] + s * du + c * dv


def river_centre(x):
    return RIVER_Y + 15.0 * np.sin(2.0 * math.pi * np.asarray(x) / 1400.0)


def block(index: tuple[int, int, int, int]) -> tuple[float, float, float, float]:
    """(u0, u1, v0, v1) between the centre lines bounding a range of blocks."""
    a0, a1, s0, s1 = index
    return AVENUES[a0][0], AVENUES[a1 + 1][0], STREETS[s0][0], STREETS[s1 + 1][0]


def block_centre(index) -> tuple[float, float]:
    u0, u1, v0, v1 = block(index)
    x, y = from_grid((u0 + u1) / 2, (v0 + v1) / 2)
    return float(x), float(y)


def _in(u, v, rect) -> np.ndarray:
    u0, u1, v0, v1 = rect
    return (u >= u0) & (u <= u1) & (v >= v0) & (v <= v1)


def _open_ground(x, y, u, v) -> np.ndarray:
    """Streets, the boulevard, the river and the squares: no building stands there."""
    free = np.zeros(x.shape, dtype=bool)
    for cu, w in AVENUES:
        free |= np.abs(u - cu) <= w / 2 + SETBACK_M
    for cv, w in STREETS:
        free |= np.abs(v - cv) <= w / 2 + SETBACK_M
    (u0, v0), (u1, v1), w = BOULEVARD
    du, dv = u1 - u0, v1 - v0
    t = np.clip(((u - u0) * du + (v - v0) * dv) / (du * du + dv * dv), 0.0, 1.0)
    free |= np.hypot(u - (u0 + t * du), v - (v0 + t * dv)) <= w / 2 + SETBACK_M
    free |= np.abs(y - river_centre(x)) <= RIVER_HALF_WIDTH + 20.0  # water and its promenades
    for index in (PARK, STATION_SQUARE):
        free |= _in(u, v, block(index))
    return free


def surface_model() -> np.ndarray:
    """The DSM (rows north to south, cols west to east), metres above sea level."""
    rng = np.random.default_rng(SEED)
    xs = (np.arange(int(WIDTH_M / PIXEL_M)) + 0.5) * PIXEL_M
    ys = HEIGHT_M - (np.arange(int(HEIGHT_M / PIXEL_M)) + 0.5) * PIXEL_M
    x, y = np.meshgrid(xs, ys)
    u, v = to_grid(x, y)
    ground = GROUND_M + 1.2 * x / WIDTH_M
    dsm = ground.copy()
    open_ground = _open_ground(x, y, u, v)
    hospital = _in(u, v, block(HOSPITAL))
    for a in range(len(AVENUES) - 1):
        for b in range(len(STREETS) - 1):
            u0, u1, v0, v1 = block((a, a, b, b))
            cols = 3 if u1 - u0 > 150 else 2  # lots: 3 x 2 per block
            for i in range(cols):
                for j in range(2):
                    lot_rect = (u0 + (u1 - u0) * i / cols, u0 + (u1 - u0) * (i + 1) / cols,
                                v0 + (v1 - v0) * j / 2, v0 + (v1 - v0) * (j + 1) / 2)
                    cu, cv = (lot_rect[0] + lot_rect[1]) / 2, (lot_rect[2] + lot_rect[3]) / 2
                    cx, cy = from_grid(cu, cv)
                    r = math.hypot(cx - DOWNTOWN[0], cy - DOWNTOWN[1])
                    gap = rng.uniform(3.0, 8.0)  # half the space between neighbouring buildings
                    shrunk = (lot_rect[0] + gap, lot_rect[1] - gap, lot_rect[2] + gap, lot_rect[3] - gap)
                    lot = _in(u, v, shrunk) & ~open_ground
                    if not lot.any():
                        continue
                    if (hospital & lot).any():
                        dsm = np.where(lot, ground + 28.0, dsm)
                    elif r < 230.0 and rng.uniform() < 0.75:  # a tower on a podium
                        dsm = np.where(lot, ground + rng.uniform(15.0, 25.0), dsm)
                        side = rng.uniform(24.0, 40.0)
                        tu, tv = cu + rng.uniform(-8, 8), cv + rng.uniform(-8, 8)
                        tower = lot & (np.abs(u - tu) <= side / 2) & (np.abs(v - tv) <= side / 2)
                        top = min(180.0, 110.0 + 75.0 * (1 - r / 230.0) + rng.uniform(-6, 6))
                        dsm = np.where(tower, ground + round(top), dsm)
                    elif r < 420.0:
                        dsm = np.where(lot, ground + round(rng.uniform(25.0, 70.0)), dsm)
                    else:
                        dsm = np.where(lot, ground + round(rng.uniform(8.0, 25.0)), dsm)
    return np.round(dsm * 4) / 4  # quarter-metre steps: the raster compresses well


def _feature_collection(features: list[dict]) -> dict:
    return {"type": "FeatureCollection", "name": "dsm_example",
            "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32633"}}, "features": features}


def _feature(name: str, geometry, **properties) -> dict:
    shifted = shapely.transform(geometry, lambda xy: np.round(xy + np.array([LEFT, BOTTOM]), 2))
    return {"type": "Feature", "properties": {"name": name, **properties}, "geometry": shapely.geometry.mapping(shifted)}


def roads() -> dict:
    """Road centre lines (the driving network) inside the raster: avenues, streets, the boulevard."""
    extent = box(0.0, 0.0, WIDTH_M, HEIGHT_M)
    river = shapely.buffer(LineString(np.column_stack([np.linspace(-50, 1250, 131), river_centre(np.linspace(-50, 1250, 131))])),
                           RIVER_HALF_WIDTH + 20.0)
    features = []

    def add(name, line, width, keep_over_river=False):
        part = line.intersection(extent)
        if not keep_over_river:
            part = part.difference(river)
        for piece in getattr(part, "geoms", [part]):
            if isinstance(piece, LineString) and piece.length > 20.0:
                features.append(_feature(name, piece, width_m=width))

    for n, (cu, w) in enumerate(AVENUES):
        add(f"avenue {n}", LineString(np.column_stack(from_grid([cu, cu], [-400.0, 1500.0]))), w, n in BRIDGES)
    for n, (cv, w) in enumerate(STREETS):
        add(f"street {n}", LineString(np.column_stack(from_grid([-400.0, 1600.0], [cv, cv]))), w)
    (u0, v0), (u1, v1), w = BOULEVARD
    add("boulevard", LineString(np.column_stack(from_grid([u0, u1], [v0, v1]))), w)
    return _feature_collection(features)


def no_fly() -> dict:
    u0, u1, v0, v1 = block(HOSPITAL)
    ring = np.column_stack(from_grid([u0, u1, u1, u0, u0], [v0, v0, v1, v1, v0]))
    return _feature_collection([_feature("hospital", shapely.Polygon(ring))])


def main(out: Path = HERE) -> None:
    """Write the three files into ``out`` (default: beside this script)."""
    dsm = surface_model().astype("float32")
    transform = Affine(PIXEL_M, 0.0, LEFT, 0.0, -PIXEL_M, BOTTOM + HEIGHT_M)
    with rasterio.open(out / "dsm_example.tif", "w", driver="GTiff", height=dsm.shape[0], width=dsm.shape[1],
                       count=1, dtype="float32", crs=CRS, transform=transform, nodata=-9999.0,
                       compress="deflate", predictor=3, zlevel=9, tiled=True, blockxsize=256, blockysize=256) as dst:
        dst.write(dsm, 1)
    (out / "dsm_example_roads.geojson").write_text(json.dumps(roads(), indent=1) + "\n")
    (out / "dsm_example_no_fly.geojson").write_text(json.dumps(no_fly(), indent=1) + "\n")


if __name__ == "__main__":
    main()
