"""A seeded synthetic Nanjing-like city that covers the paper's case study (Sec. 6, Table B.3).

The paper's Nanjing DSM is not public, so the case is rebuilt from what the paper states: a
~2.5 km × 4.5 km domain holding vertiports V1–V5 of Table B.3, a street grid carrying traffic,
blocks of buildings with a realistic height mix, a river and parks as open ground, and no-fly
zones. Towers above h_min = 90 m stand in two business districts across the V1–V4 and V2–V3
diagonals, so tracks at the 120 m cruise altitude must detour (Fig. 18).

Everything is drawn from ``numpy.random.default_rng(city.seed)``: the same seed gives the same
city. The generator returns geometry (:class:`VectorCity`); the shared rasteriser puts it on any
grid, so the same city can be studied at 50 m, 10 m or 5 m cells (Table 4).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from shapely.geometry import LineString, Point, Polygon, box

from uamopt.city.layers import VectorCity
from uamopt.scenario import Scenario

DEFAULT_EXTENT = (2500.0, 4500.0)  # m: encloses V1..V4 of Table B.3 with a margin
ARTERIAL_WIDTH_M = 30.0
LOCAL_WIDTH_M = 16.0
SETBACK_M = 6.0  # building line behind the kerb


def synthetic_extent(scenario: Scenario) -> tuple[float, float]:
    """(x_max, y_max) of the synthetic city, m."""
    return DEFAULT_EXTENT


def _street_lines(rng: np.random.Generator, length: float) -> list[tuple[float, float]]:
    """Positions and widths of parallel streets: blocks of 130–230 m, every third an arterial."""
    streets, pos, n = [], rng.uniform(40.0, 90.0), 0
    while pos < length - 40.0:
        width = ARTERIAL_WIDTH_M if n % 3 == 0 else LOCAL_WIDTH_M
        streets.append((pos, width))
        pos += rng.uniform(130.0, 230.0)
        n += 1
    return streets


def _river(extent: tuple[float, float]) -> Polygon:
    """A gently meandering river crossing the city west to east, about 90 m wide."""
    xs = np.linspace(-50.0, extent[0] + 50.0, 60)
    centre = 3750.0 + 80.0 * np.sin(2.0 * math.pi * xs / 1900.0)
    return LineString(np.column_stack([xs, centre])).buffer(45.0, cap_style="flat")


def _height(rng: np.random.Generator, in_cbd: bool) -> float:
    """Building height, m: Nanjing-like mix of low-rise, mid-rise slabs and towers."""
    u = rng.uniform()
    if in_cbd:
        if u < 0.45:
            return float(rng.uniform(95.0, 240.0))  # business-district towers
        return float(rng.uniform(20.0, 80.0))
    if u < 0.55:
        return float(rng.uniform(6.0, 24.0))  # 2-8 storeys
    if u < 0.90:
        return float(rng.uniform(24.0, 50.0))  # 8-16 storeys
    if u < 0.98:
        return float(rng.uniform(50.0, 85.0))  # residential high-rise
    return float(rng.uniform(92.0, 150.0))  # scattered towers


def synthetic_city(scenario: Scenario) -> VectorCity:
    """Generate the seeded synthetic city of ``scenario.city.seed`` (geometry in metres)."""
    rng = np.random.default_rng(scenario.city.seed)
    ex, ey = synthetic_extent(scenario)
    ports = [(v.x, v.y) for v in scenario.network.vertiports]
    clear_r = scenario.network.vertiport_clearance_m
    low_cap = max(scenario.aircraft.h_min - 60.0, 12.0)  # low-rise ring around each vertiport

    # Business districts straddle the diagonals V1-V4 and V2-V3 (the paper's longest routes).
    cbds = [Point(900 + rng.uniform(-80, 80), 1525 + rng.uniform(-80, 80)).buffer(260.0),
            Point(1700 + rng.uniform(-80, 80), 3160 + rng.uniform(-80, 80)).buffer(220.0),
            Point(800 + rng.uniform(-80, 80), 3200 + rng.uniform(-80, 80)).buffer(200.0)]
    river = _river((ex, ey))
    # No-fly zones: a government compound and a military site, away from the vertiports.
    compound = Point(rng.uniform(1650, 1900), rng.uniform(1500, 1800)).buffer(rng.uniform(150, 190))
    sx, sy = rng.uniform(250, 450), rng.uniform(1900, 2100)
    military = box(sx, sy, sx + rng.uniform(220, 300), sy + rng.uniform(180, 240))
    no_fly = [compound, military]

    xs = _street_lines(rng, ex)
    ys = _street_lines(rng, ey)
    roads = []
    for x, w in xs:
        line = LineString([(x, 0.0), (x, ey)])
        roads.append(line if w == ARTERIAL_WIDTH_M else line.difference(river))  # bridges: arterials only
    for y, _w in ys:
        roads.append(LineString([(0.0, y), (ex, y)]))
    roads = [r for r in roads if not r.is_empty]

    # Blocks between consecutive streets (and the domain edge).
    def bounds(lines, length):
        cuts = [(0.0, 0.0), *lines, (length, 0.0)]
        return [(a + wa / 2 + SETBACK_M, b - wb / 2 - SETBACK_M) for (a, wa), (b, wb) in itertools.pairwise(cuts)]

    buildings, heights, parks = [], [], []
    for x0, x1 in bounds(xs, ex):
        for y0, y1 in bounds(ys, ey):
            if x1 - x0 < 30 or y1 - y0 < 30:
                continue
            block = box(x0, y0, x1, y1)
            if block.intersection(river).area > 0.3 * block.area:
                continue
            if rng.uniform() < 0.08:  # parks: open ground with trees
                parks.append(block)
                continue
            in_cbd = any(block.intersects(c) for c in cbds)
            # parcels: split the block into a 2-D lattice of plots, one building on each
            nx_p = max(1, int((x1 - x0) // rng.uniform(45, 75)))
            ny_p = max(1, int((y1 - y0) // rng.uniform(45, 75)))
            px = np.linspace(x0, x1, nx_p + 1)
            py = np.linspace(y0, y1, ny_p + 1)
            for a, b in itertools.pairwise(px):
                for c, d in itertools.pairwise(py):
                    if rng.uniform() < 0.15:
                        continue  # courtyard or car park
                    fx = rng.uniform(0.55, 0.85) * (b - a)
                    fy = rng.uniform(0.55, 0.85) * (d - c)
                    cx, cy = rng.uniform(a + fx / 2, b - fx / 2), rng.uniform(c + fy / 2, d - fy / 2)
                    footprint = box(cx - fx / 2, cy - fy / 2, cx + fx / 2, cy + fy / 2)
                    if footprint.intersects(river):
                        continue
                    near = min(math.hypot(cx - px_, cy - py_) for px_, py_ in ports) if ports else math.inf
                    if near < 60.0:
                        continue  # the vertiport pad itself
                    h = _height(rng, in_cbd)
                    if near < clear_r:
                        h = min(h, low_cap)
                    buildings.append(footprint)
                    heights.append(h)
    heights_arr = np.asarray(heights)
    notes = {
        "buildings": len(buildings),
        "towers_above_90m": int((heights_arr > 90.0).sum()),
        "max_height_m": float(heights_arr.max()) if len(heights_arr) else 0.0,
        "parks": len(parks),
        "road_km": float(sum(r.length for r in roads) / 1000.0),
        "no_fly_zones": len(no_fly),
    }
    return VectorCity(
        extent=(ex, ey), buildings=buildings, heights_m=heights_arr, roads=roads, no_fly=no_fly,
        open_space=[river, *parks], source="synthetic", attribution="synthetic city (uamopt), seed "
        f"{scenario.city.seed}", notes=notes,
    )
