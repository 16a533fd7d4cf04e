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
import json
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from uamopt.errors import InputFileError, NoTrackError
from uamopt.planning.problem import PlanningModel
from uamopt.planning.tracks import (
    TrackPlan,
    TrackWeightsWarning,
    plan_track,
    weight_scale_message,
)


def route_pairs(model: PlanningModel) -> list[tuple[str, str]]:
    """The scenario's routes, or every pair of vertiports (10 for V1–V5)."""
    return model.scenario.network.route_list()


def direction_layers(model: PlanningModel) -> tuple[int, int]:
    """Cell layers of the two directions: the cruise altitude's layer, and the first layer above it
    outside its conflict zone (r + 1 layers up, r = ``schedule.conflict_radius``), so opposite
    directions of a route never conflict."""
    grid = model.field.grid
    k, up = grid.direction_layers(model.scenario.network.cruise_altitude_m, model.scenario.schedule.conflict_radius)
    if up >= grid.shape[2] or up not in set(model.field.band_layers().tolist()):
        raise NoTrackError("no cell layer in the altitude band for the return direction",
                           "network.cruise_altitude_m", "lower the cruise altitude or widen the band")
    return k, up


def _confined(model: PlanningModel, k: int) -> PlanningModel:
    mask = np.zeros_like(model.admissible)
    mask[:, :, k] = model.admissible[:, :, k]
    return dataclasses.replace(model, admissible=mask, risk=np.where(mask, model.risk, np.zeros((), model.risk.dtype)))


@dataclass(frozen=True, eq=False)
class RouteTrack:
    """One directed route of the network and its planned track (the ``optimal`` stage by default)."""

    name: str
    origin: str
    destination: str
    waypoints: np.ndarray  # (n, 3), m
    length_m: float
    risk_cost: float  # Eq. 11
    transport_cost: float  # Eq. 12, ¥
    buffer_cost: float  # Σ μ·R(t), Eq. 34
    layer_k: int | None  # the cell layer the track is confined to (directional layering), or None
    plan: TrackPlan | None = None  # all four stages, when planned in this process (not in network.json)


@dataclass(frozen=True, eq=False)
class RouteNetwork:
    """Every route in both directions (``"A-B"`` → :class:`RouteTrack`): what ``network.json`` holds."""

    routes: dict[str, RouteTrack]
    cell: tuple[float, float, float]
    scenario: str = ""
    stage: str = "optimal"
    layering: str = "direction"

    def __len__(self) -> int:
        return len(self.routes)

    def __iter__(self):
        return iter(self.routes)

    def __getitem__(self, name: str) -> RouteTrack:
        return self.routes[name]

    def waypoints(self) -> dict[str, np.ndarray]:
        """Route name → (n, 3) waypoints: the tracks the flights fly."""
        return {name: r.waypoints for name, r in self.routes.items()}

    def to_frame(self):
        """One row per directed route: origin, destination, layer_k, length_m, risk_cost,
        transport_cost, buffer_cost, n_waypoints (pandas DataFrame indexed by route)."""
        import pandas as pd

        rows = [{"route": r.name, "origin": r.origin, "destination": r.destination, "layer_k": r.layer_k,
                 "length_m": r.length_m, "risk_cost": r.risk_cost, "transport_cost": r.transport_cost,
                 "buffer_cost": r.buffer_cost, "n_waypoints": len(r.waypoints)} for r in self.routes.values()]
        return pd.DataFrame(rows).set_index("route")

    def to_document(self) -> dict:
        """The JSON document of ``network.json`` (module docstring)."""
        routes = {name: {"origin": r.origin, "destination": r.destination, "waypoints": r.waypoints.tolist(),
                         "length_m": r.length_m, "risk_cost": r.risk_cost, "transport_cost": r.transport_cost,
                         "buffer_cost": r.buffer_cost, "layer_k": r.layer_k} for name, r in self.routes.items()}
        return {"scenario": self.scenario, "cell": list(self.cell), "stage": self.stage, "layering": self.layering,
                "routes": routes}

    @classmethod
    def from_document(cls, doc: dict) -> RouteNetwork:
        """The network of a ``network.json`` document, checked field by field (untrusted input).

        Raises ``ValueError`` naming the route: no routes, waypoints that are not at least two
        finite [x, y, z] points, a track of zero length, a cell that is not three positive sizes."""
        from uamopt.bounds import Range, check_cell, check_number, check_points

        COST, LAYER = Range(0.0, 1e300), Range(0, 10**6, integer=True)

        if not isinstance(doc, dict) or not isinstance(doc.get("routes"), dict) or not doc["routes"]:
            raise ValueError("'routes' must be a non-empty object of route name -> track")
        routes = {}
        fix = "regenerate it with `uamopt network`"
        for name, r in doc["routes"].items():
            where = f"route {name[:40]}"
            if not isinstance(r, dict):
                raise _Invalid(f"{where}: not an object with 'waypoints'")
            # every number through the one boundary check (uamopt/bounds.py): 400-digit integers, NaN, inf refused
            waypoints = check_points(r.get("waypoints"), f"{where}: waypoints", where, fix, error=_Invalid)
            length = float(np.linalg.norm(np.diff(waypoints, axis=0), axis=1).sum())
            if not length > 0:
                raise ValueError(f"route {name}: the track has zero length (its flights would take no time)")
            # the optional costs: NaN when absent (null), else a finite number ≥ 0
            metric = {key: np.nan if r.get(key) is None else check_number(r[key], f"{where}: {key}", where, fix, COST,
                                                                          error=_Invalid)
                      for key in ("length_m", "risk_cost", "transport_cost", "buffer_cost")}
            layer = r.get("layer_k")
            routes[name] = RouteTrack(
                name=name, origin=str(r.get("origin", name.split("-")[0])),
                destination=str(r.get("destination", name.split("-")[-1])), waypoints=waypoints,
                length_m=length if r.get("length_m") is None else metric["length_m"], risk_cost=metric["risk_cost"],
                transport_cost=metric["transport_cost"], buffer_cost=metric["buffer_cost"],
                layer_k=None if layer is None else check_number(layer, f"{where}: layer_k", where, fix, LAYER,
                                                                error=_Invalid))
        cell = (np.nan, np.nan, np.nan)
        if "cell" in doc:
            cell = check_cell(doc["cell"], "network.json", fix, error=_Invalid)
        return cls(routes=routes, cell=cell, scenario=str(doc.get("scenario", "")),  # type: ignore[arg-type]
                   stage=str(doc.get("stage", "optimal")), layering=str(doc.get("layering", "direction")))


def plan_network(model: PlanningModel, progress=None, stage: str = "optimal") -> RouteNetwork:
    """Plan every route in both directions (Sec. 6.2, layering as in the module docstring).

    ``progress`` (optional) gets ``update(1)`` after each track; ``stage`` picks the track the
    flights fly (Table 2's ``optimal`` by default)."""
    if model.scenario.network.tracks == "straight":
        return straight_routes(model, progress)
    ports = {v.name: v for v in model.scenario.network.vertiports}
    layered = model.scenario.tracks.layering == "direction"
    dz = model.field.grid.cell[2]
    cruise = model.scenario.network.cruise_altitude_m
    if layered:
        k_out, k_back = direction_layers(model)
        confined = {k_out: _confined(model, k_out), k_back: _confined(model, k_back)}
    routes: dict[str, RouteTrack] = {}
    for a, b in route_pairs(model):
        for origin, destination, up in ((a, b, False), (b, a, True)):
            z = cruise + ((k_back - k_out) * dz if (layered and up) else 0.0)
            k = (k_back if up else k_out) if layered else None
            sub = confined[k] if layered else model
            p, q = ports[origin], ports[destination]
            try:
                plan = plan_track(sub, (p.x, p.y, z), (q.x, q.y, z), scale_check=False)
            except NoTrackError as exc:
                raise NoTrackError(f"route {origin}-{destination}: {exc.what}", exc.where, exc.fix) from None
            s = plan.stages[stage]
            name = f"{origin}-{destination}"
            routes[name] = RouteTrack(name, origin, destination, s.waypoints, s.length_m, s.risk_cost,
                                      s.transport_cost, s.buffer_cost, k, plan)
            if progress is not None:
                progress.update(1)
    # one warning for the network, on its first route, when Eq. 10's two terms are scales apart
    first = next(iter(routes.values()), None)
    message = weight_scale_message(model, first.plan.stages["shortest"]) if first is not None else None
    if message:
        warnings.warn(f"route {first.name}: {message}", TrackWeightsWarning, stacklevel=2)
    return RouteNetwork(routes, tuple(model.field.grid.cell), model.scenario.name, stage,  # type: ignore[arg-type]
                        model.scenario.tracks.layering)


def straight_routes(model: PlanningModel, progress=None) -> RouteNetwork:
    """``network.tracks = "straight"``: each direction a straight line between its vertiports, on
    the layers of :func:`direction_layers` (a→b at the cruise altitude, b→a r + 1 layers up); the
    city is not avoided. Metrics are Eqs. 10–12 of the line (scheduler benchmarks)."""
    from uamopt.planning.tracks import track_metrics

    ports = {v.name: v for v in model.scenario.network.vertiports}
    k_out, k_back = direction_layers(model)
    cruise, dz = model.scenario.network.cruise_altitude_m, model.field.grid.cell[2]
    extent = np.asarray(model.field.grid.extent)
    routes: dict[str, RouteTrack] = {}
    for a, b in route_pairs(model):
        for origin, destination, k in ((a, b, k_out), (b, a, k_back)):
            z = cruise + (k - k_out) * dz
            p, q = ports[origin], ports[destination]
            waypoints = np.array([[p.x, p.y, z], [q.x, q.y, z]], dtype=float)
            if np.any(waypoints < 0) or np.any(waypoints > extent):
                raise NoTrackError(f"route {origin}-{destination} leaves the grid (extent {tuple(extent.tolist())})",
                                   "network.vertiports", "move the vertiports inside grid.extent")
            m = track_metrics(model, waypoints)
            name = f"{origin}-{destination}"
            routes[name] = RouteTrack(name, origin, destination, waypoints, m["length_m"], m["risk_cost"],
                                      m["transport_cost"], m["buffer_cost"], k)
            if progress is not None:
                progress.update(1)
    return RouteNetwork(routes, tuple(model.field.grid.cell), model.scenario.name, "straight",  # type: ignore[arg-type]
                        model.scenario.tracks.layering)


class _Invalid(ValueError):
    """A field of network.json out of its range (``from_document`` raises ValueError: the loader names the file)."""

    def __init__(self, what: str, where: str = "", fix: str = "") -> None:
        super().__init__(what)


def load_network(path: str | Path) -> RouteNetwork:
    """A :class:`RouteNetwork` from ``network.json`` (a file, or the folder holding it)."""
    path = Path(path)
    if path.is_dir():
        path = path / "network.json"
    try:
        doc = json.loads(path.read_text(encoding="utf-8-sig"))
        return RouteNetwork.from_document(doc)
    except ValueError as exc:  # malformed JSON (an integer of more than 4300 digits too) or a field out of range
        from uamopt.bounds import parse_error

        raise InputFileError(f"malformed network file: {parse_error(exc)}", str(path),
                             "regenerate it with `uamopt network`") from None
    except FileNotFoundError:
        raise InputFileError(f"network file not found: {path}", "network.json", "run `uamopt network` first") from None
    except (KeyError, TypeError, AttributeError, RecursionError) as exc:
        raise InputFileError(f"malformed network file: {exc}", str(path), "regenerate it with `uamopt network`") from None
    except OSError as exc:
        raise InputFileError(f"cannot read the network file: {exc.strerror or exc}", str(path),
                             "check the path and the file's permissions") from None
