"""Where a single track starts and ends: coordinates, vertiport names, or the scenario's route.

``tracks.origin`` / ``tracks.destination`` (x, y, z in metres) win; else ``tracks.route`` names two
vertiports, flown at ``network.cruise_altitude_m``; else the first vertiport and the one farthest
from it. In the paper case that is V1 → V4, i.e. Table B.3's P_O = (300, 300, 120) m →
P_D = (2220, 4220, 120) m. Every end point remembers how the user named it, so an error names the
user's own input (``--from Kamppi``, ``tracks.route``), never a value they did not pass.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from uamopt.errors import ScenarioError, UamoptError
from uamopt.scenario import Scenario

#: Table B.3's P_O and P_D (m): the paper's Table 2 / Table 4 / Fig. 21 track.
PAPER_ORIGIN = (300.0, 300.0, 120.0)
PAPER_DESTINATION = (2220.0, 4220.0, 120.0)


@dataclass(frozen=True)
class Endpoint:
    """A track end: the point (m), a vertiport name when it is one, and how the user gave it."""

    point: tuple[float, float, float]
    where: str
    name: str | None = None

    @property
    def label(self) -> str:
        return self.name or "(" + ", ".join(f"{v:g}" for v in self.point) + ")"


def vertiport_endpoint(scenario: Scenario, name: str, where: str) -> Endpoint:
    """The vertiport ``name`` at the cruise altitude."""
    ports = {v.name: v for v in scenario.network.vertiports}
    if name not in ports:
        known = ", ".join(ports) or "none"
        raise ScenarioError(f"unknown vertiport '{name}'", where, f"use one of {known}, or X,Y,Z in metres")
    v = ports[name]
    return Endpoint((float(v.x), float(v.y), float(scenario.network.cruise_altitude_m)), where, name)


def parse_endpoint(scenario: Scenario, text: str, option: str) -> Endpoint:
    """``X,Y,Z`` in metres or a vertiport name, as given to ``--from`` / ``--to``."""
    where = f"{option} {text}"
    parts = text.split(",")
    if len(parts) == 1:
        return vertiport_endpoint(scenario, text.strip(), where)
    try:
        values = tuple(float(v) for v in parts)
    except ValueError:
        values = ()
    if len(values) != 3 or not all(map(math.isfinite, values)):
        raise UamoptError(f"{option} {text!r} is not a point or a vertiport", where,
                          "write X,Y,Z in metres, e.g. 300,300,120, or a vertiport name")
    return Endpoint(values, where)  # type: ignore[arg-type]


def default_endpoints(scenario: Scenario) -> tuple[Endpoint, Endpoint]:
    """The scenario's single-track end points (module docstring)."""
    t = scenario.tracks
    ports = scenario.network.vertiports
    if t.route is not None:
        a, b = t.route
        if a == b:
            raise ScenarioError(f"tracks.route joins '{a}' to itself", "tracks.route", "name two different vertiports")
        origin, destination = (vertiport_endpoint(scenario, n, "tracks.route") for n in (a, b))
    elif len(ports) >= 2:
        first = ports[0]
        far = max(ports[1:], key=lambda v: math.hypot(v.x - first.x, v.y - first.y))
        origin = vertiport_endpoint(scenario, first.name, "network.vertiports (first)")
        destination = vertiport_endpoint(scenario, far.name, "network.vertiports (farthest from the first)")
    elif t.origin is None or t.destination is None:
        raise ScenarioError("no track end points: fewer than two vertiports and no tracks.origin/destination",
                            "network.vertiports", "add vertiports, or set tracks.route or tracks.origin and tracks.destination")
    if t.origin is not None:
        origin = Endpoint(tuple(float(v) for v in t.origin), "tracks.origin")  # type: ignore[arg-type]
    if t.destination is not None:
        destination = Endpoint(tuple(float(v) for v in t.destination), "tracks.destination")  # type: ignore[arg-type]
    return origin, destination


def as_endpoint(scenario: Scenario, value, label: str, function: str = "plan_track") -> Endpoint:
    """An :class:`Endpoint` from an Endpoint, a vertiport name or (x, y, z) metres; anything else
    (a 2-D point, None, a string among the numbers) is a ``TypeError`` naming ``function``'s
    ``label`` argument (``origin``, ``destination``)."""
    if isinstance(value, Endpoint):
        return value
    if isinstance(value, str):
        return vertiport_endpoint(scenario, value, f"{label} {value}")
    import numbers

    import numpy as np

    items = list(value) if isinstance(value, (list, tuple, np.ndarray)) and np.ndim(value) == 1 else None
    if items is None or len(items) != 3 or not all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in items):
        got = f"{len(items)} values {tuple(items)!r}"[:80] if items is not None else type(value).__name__
        raise TypeError(f"{function}(): {label} must be a vertiport name or a point of 3 numbers (x, y, z) in metres, "
                        f"got {got}")
    point = tuple(float(v) for v in items)
    return Endpoint(point, f"{label} (" + ", ".join(f"{v:g}" for v in point) + ")")  # type: ignore[arg-type]


def is_paper_track(origin: Endpoint, destination: Endpoint) -> bool:
    """True when the end points are the paper's P_O → P_D, so its Tables 2 and 4 compare."""
    return tuple(origin.point) == PAPER_ORIGIN and tuple(destination.point) == PAPER_DESTINATION
