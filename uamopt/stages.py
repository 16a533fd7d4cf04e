"""The pipeline's stages as plain functions a notebook can call one by one (PyPSA's pattern):
scenario → city layers → grid → risk field. Later stages (tracks, schedules) append here."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from uamopt.city import CityLayers, load_city
from uamopt.grid import AirspaceGrid, build_grid
from uamopt.risk import RiskField, risk_field
from uamopt.scenario import Scenario


@dataclass(frozen=True)
class RiskRun:
    """The risk stage's result with its timings (seconds)."""

    scenario: Scenario
    grid: AirspaceGrid
    city: CityLayers
    field: RiskField
    seconds: dict


def compute_risk(scenario: Scenario) -> RiskRun:
    """Build the grid and city layers, then the risk field, timing each step."""
    t0 = time.perf_counter()
    grid = build_grid(scenario)
    city = load_city(scenario, grid)
    t1 = time.perf_counter()
    field = risk_field(scenario, grid, city)
    t2 = time.perf_counter()
    return RiskRun(scenario, grid, city, field, {"city": t1 - t0, "risk": t2 - t1, "total": t2 - t0})


def risk_summary(run: RiskRun) -> dict:
    """Cell counts, unsafe shares (whole grid and altitude band), risk statistics and timings."""
    f, g = run.field, run.grid
    band = f.band_layers()
    free = ~f.obstacle
    in_band = np.zeros(g.shape[2], dtype=bool)
    in_band[band] = True
    band_free = free & in_band[None, None, :]
    no_fly_cells = f.no_fly & free
    w = run.scenario.risk.weights
    threshold = f.threshold

    def share(mask, of):
        n = int(of.sum())
        return float(mask[of].sum() / n) if n else 0.0

    with np.errstate(invalid="ignore"):
        road_driven = (w[1] * f.risk_V > threshold) & free
    risk_free = f.risk[free]
    c = f.constants
    return {
        "scenario": run.scenario.name,
        "source": run.city.source,
        "attribution": run.city.attribution,
        "grid": {"cell_m": list(g.cell), "shape": list(g.shape), "extent_m": list(g.extent)},
        "cells": g.n_cells,
        "obstacle_cells": int(f.obstacle.sum()),
        "no_fly_cells": int(no_fly_cells.sum()),
        "unsafe_cells": int(f.unsafe.sum()),
        "unsafe_share": float(f.unsafe.mean()),
        "band_m": list(f.band),
        "band_layers": [int(k) for k in band],
        "band_free_cells": int(band_free.sum()),
        "band_unsafe_share": share(f.unsafe, band_free),
        "unsafe_share_by_layer": {f"{z:g}": share(f.unsafe[:, :, k], free[:, :, k]) for k, z in enumerate(g.z)},
        "road_columns_share": float((run.city.road_length > 0).mean()),
        "road_driven_unsafe_share": share(road_driven, free),
        "risk_per_flight_hour": {
            "threshold_R0": threshold,
            "min": float(risk_free.min()) if risk_free.size else None,
            "median": float(np.median(risk_free)) if risk_free.size else None,
            "max": float(risk_free.max()) if risk_free.size else None,
        },
        "constants": {
            "mass_kg": c.mass_kg,
            "crash_area_m2": c.crash_area_m2,
            "drag_k_per_m": c.k_per_m,
            "terminal_speed_mps": c.terminal_speed_mps,
            "mean_relative_speed_mps": c.mean_relative_speed_mps,
            "vehicle_collision_probability": c.vehicle_collision_probability,
        },
        "city": run.city.notes,
        "seconds": run.seconds,
    }
