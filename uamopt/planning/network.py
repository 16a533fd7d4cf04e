"""The vertiport route network (Sec. 6.2): one planned track per route and direction.

Airspace layering (Sec. 4.1.2), ``tracks.layering = "direction"`` (default): the two directions of
a route fly on separate cruise layers. The direction from the first-named vertiport to the second
flies the cell layer that holds the cruise altitude (120 m), starting and ending at that altitude;
the opposite direction flies r + 1 layers higher (r = ``schedule.conflict_radius``, so 60 m higher
with 30 m layers and the default 3×3×3 conflict zone), starting and ending at that layer's floor.
Each direction's search is confined to its layer, so the two directions never conflict. ``"none"`` lets both directions
use the whole altitude band.

``network.json``::

    {"cell": [Δx, Δy, Δz], "stage": "optimal", "routes": {"V1-V4": {"origin": "V1",
     "destination": "V4", "waypoints": [[x, y, z], ...], "length_m", "risk_cost", "transport_cost",
     "layer_k"}, ...}, "scenario": "..."}
"""

from __future__ import annotations

import dataclasses
import itertools
import json
from pathlib import Path

import numpy as np

from uamopt.errors import InputFileError, NoTrackError
from uamopt.planning.problem import PlanningModel
from uamopt.planning.tracks import TrackPlan, plan_track


def route_pairs(model: PlanningModel) -> list[tuple[str, str]]:
    """The scenario's routes, or every pair of vertiports (10 for V1–V5)."""
    net = model.scenario.network
    if net.routes is not None:
        return [tuple(r) for r in net.routes]  # type: ignore[misc]
    return list(itertools.combinations([v.name for v in net.vertiports], 2))


def direction_layers(model: PlanningModel) -> tuple[int, int]:
    """Cell layers of the two directions: the cruise altitude's layer, and the first layer above it
    outside its conflict zone (r + 1 layers up, r = ``schedule.conflict_radius``), so opposite
    directions of a route never conflict."""
    grid = model.field.grid
    k = int(np.floor(model.scenario.network.cruise_altitude_m / grid.cell[2]))
    up = k + model.scenario.schedule.conflict_radius + 1
    if up >= grid.shape[2] or up not in set(model.field.band_layers().tolist()):
        raise NoTrackError("no cell layer in the altitude band for the return direction",
                           "network.cruise_altitude_m", "lower the cruise altitude or widen the band")
    return k, up


def _confined(model: PlanningModel, k: int) -> PlanningModel:
    mask = np.zeros_like(model.admissible)
    mask[:, :, k] = model.admissible[:, :, k]
    return dataclasses.replace(model, admissible=mask, risk=np.where(mask, model.risk, 0.0))


def plan_network(model: PlanningModel, progress=None) -> dict[str, tuple[str, str, TrackPlan, int | None]]:
    """Plan every route in both directions: name ``"A-B"`` → (origin, destination, plan, layer k)."""
    ports = {v.name: v for v in model.scenario.network.vertiports}
    layered = model.scenario.tracks.layering == "direction"
    dz = model.field.grid.cell[2]
    cruise = model.scenario.network.cruise_altitude_m
    if layered:
        k_out, k_back = direction_layers(model)
        confined = {k_out: _confined(model, k_out), k_back: _confined(model, k_back)}
    out: dict[str, tuple[str, str, TrackPlan, int | None]] = {}
    for a, b in route_pairs(model):
        for origin, destination, up in ((a, b, False), (b, a, True)):
            z = cruise + ((k_back - k_out) * dz if (layered and up) else 0.0)
            k = (k_back if up else k_out) if layered else None
            sub = confined[k] if layered else model
            p, q = ports[origin], ports[destination]
            try:
                plan = plan_track(sub, (p.x, p.y, z), (q.x, q.y, z))
            except NoTrackError as exc:
                raise NoTrackError(f"route {origin}-{destination}: {exc.what}", exc.where, exc.fix) from None
            out[f"{origin}-{destination}"] = (origin, destination, plan, k)
            if progress is not None:
                progress.update(1)
    return out


def network_document(model: PlanningModel, network: dict, stage: str = "optimal") -> dict:
    """The JSON document of ``network.json``."""
    routes = {}
    for name, (origin, destination, plan, k) in network.items():
        s = plan.stages[stage]
        routes[name] = {"origin": origin, "destination": destination, "waypoints": s.waypoints.tolist(),
                        "length_m": s.length_m, "risk_cost": s.risk_cost, "transport_cost": s.transport_cost,
                        "buffer_cost": s.buffer_cost, "layer_k": k}
    return {"scenario": model.scenario.name, "cell": list(model.field.grid.cell), "stage": stage,
            "layering": model.scenario.tracks.layering, "routes": routes}


def load_network(path: str | Path) -> dict[str, np.ndarray]:
    """Route name → waypoints (n, 3) from a ``network.json``."""
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        return {name: np.asarray(r["waypoints"], dtype=float) for name, r in doc["routes"].items()}
    except FileNotFoundError:
        raise InputFileError(f"network file not found: {path}", "network.json", "run `uamopt network` first") from None
    except (ValueError, KeyError, TypeError) as exc:
        raise InputFileError(f"malformed network file {path}: {exc}", "network.json",
                             "regenerate it with `uamopt network`") from None
