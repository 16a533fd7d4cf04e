"""``flights.json``: a :class:`~uamopt.schedule.flights.FlightSet` read, validated against the
rules of Eqs. 26-29 and written (docs/interfaces.md). The rules are checked once, here, at the
boundary; the model trusts a FlightSet afterwards.

``flights.json`` (docs/interfaces.md)::

    {"cell": [dx, dy, dz], "conflict_radius": r,
     "service_start_s": 0, "service_end_s": 3600, "outbound_gap_s": 240, "return_gap_s": 360,
     "flights": [{"id", "aircraft", "route", "origin", "destination", "speed_mps",
                  "planned_departure_s", "max_delay_s", "waypoints": [[x, y, z], ...],
                  "vertical_rate_mps" (optional), "turnaround_after_s" (optional)}]}

The four service/gap keys are optional (defaults: 0, 3600 s, the scenario's T_D and T_R) and
``max_delay_s`` may be omitted (Eq. 29 with equality). A flight with ``waypoints`` is
self-contained; one without must name a route of the given ``network``. ``vertical_rate_mps``
(the vertiport variant): the first segment is a vertical take-off and the last a vertical landing,
both flown at that rate; the rest at ``speed_mps``. ``turnaround_after_s`` (optional): the
aircraft's turnaround ΔT after this flight, where it is not the leg-parity default (T_D after an
odd leg of its aircraft, T_R after an even one); the writer puts it where a flight has its own.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from uamopt.bounds import (
    CONFLICT_RADIUS,
    DURATION_S,
    SPEED_MPS,
    TIME_S,
    VERTICAL_RATE_MPS,
    check_cell,
    check_number,
    check_points,
    outside_grid,
    read_json,
)
from uamopt.errors import InputFileError
from uamopt.schedule.flights import DEFAULT_SERVICE_S, TIME_TOL_S, Flight, FlightSet, round_half_up, track_length_m

if TYPE_CHECKING:
    from uamopt.grid import AirspaceGrid
    from uamopt.scenario import Scenario


def flight_from_dict(raw: Any, where: str, network: Mapping[str, np.ndarray] | None) -> Flight:
    """One flight record of flights.json, checked for keys and types (not yet for the rules)."""
    if not isinstance(raw, dict):
        raise InputFileError("a flight is not a JSON object", where, 'write each flight as {"id": ..., ...}')
    fid = raw.get("id")
    where = f"{where}: flight {str(fid)[:40]}" if fid is not None else where
    required = ["id", "aircraft", "route", "origin", "destination", "speed_mps", "planned_departure_s"]
    missing = [k for k in required if k not in raw]
    if missing:
        raise InputFileError(f"missing key '{missing[0]}'", where, f"every flight needs {', '.join(required)}")
    # every number through the one boundary check (uamopt/bounds.py), before any arithmetic
    speed = check_number(raw["speed_mps"], "speed_mps", where, "give v_g in m/s (the paper's eVTOL cruises at 25 m/s)",
                         SPEED_MPS)
    departure = check_number(raw["planned_departure_s"], "planned_departure_s", where,
                             "give times in seconds from the start of service", TIME_S)
    max_delay = raw.get("max_delay_s")
    if max_delay is not None:
        max_delay = check_number(max_delay, "max_delay_s", where, "give 'max_delay_s' ≥ 0 (Δd, Eq. 29) in seconds",
                                 DURATION_S)
    if "waypoints" in raw:
        wp = check_points(raw["waypoints"], "'waypoints'", where, "give the track in metres")
    elif network is not None and isinstance(raw["route"], str) and raw["route"] in network:
        wp = np.array(network[raw["route"]], dtype=float)
    else:
        known = ", ".join(sorted(network)) if network else "none (no network given)"
        raise InputFileError(f"unknown route '{str(raw['route'])[:80]}'", where,
                             f"give 'waypoints' or one of the routes: {known}")
    if track_length_m(wp) <= 0:
        raise InputFileError("the track has zero length", where, "give an origin and a destination that differ")
    turnaround = raw.get("turnaround_after_s")
    if turnaround is not None:
        turnaround = check_number(turnaround, "'turnaround_after_s'", where,
                                  "give the aircraft's turnaround after this flight in seconds (≥ 0), or omit the key "
                                  "for the file's outbound_gap_s / return_gap_s", DURATION_S)
    rate = raw.get("vertical_rate_mps")
    if rate is not None:
        rate = check_number(rate, "'vertical_rate_mps'", where,
                            "give the climb/descent rate of the vertical phases, or omit the key", VERTICAL_RATE_MPS)
        if len(wp) < 4 or not _vertical(wp[0], wp[1], up=True) or not _vertical(wp[-2], wp[-1], up=False):
            raise InputFileError("'vertical_rate_mps' needs a vertical climb as the first segment and a vertical "
                                 "descent as the last (at least 4 waypoints)", where,
                                 "write the take-off and landing as vertical segments, or omit vertical_rate_mps")
    wp.setflags(write=False)
    return Flight(
        id=str(raw["id"]), aircraft=str(raw["aircraft"]), route=str(raw["route"]), origin=str(raw["origin"]),
        destination=str(raw["destination"]), speed_mps=speed, planned_departure_s=departure,
        max_delay_s=float("nan") if max_delay is None else max_delay, waypoints=wp, vertical_rate_mps=rate,
        turnaround_after_s=turnaround,
    )


def _vertical(a: np.ndarray, b: np.ndarray, up: bool) -> bool:
    """Segment a→b is vertical (same x, y within 1e-6 m) and climbs (``up``) or descends."""
    return bool(np.all(np.abs(b[:2] - a[:2]) <= 1e-6) and ((b[2] > a[2]) if up else (b[2] < a[2])))


def check_flightset(flightset: FlightSet, grid: AirspaceGrid | None = None, source: str = "flights.json") -> None:
    """Validate the rules (once, at the boundary); raise :class:`InputFileError`.

    Checks: unique ids; waypoints inside the grid (when given; :func:`uamopt.bounds.outside_grid`,
    the verifier's rule); planned departure ≥ T_s and planned arrival ≤ T_f; per aircraft, no two
    flights overlap in planned time (next planned departure ≥ previous planned arrival + ΔT, Eq. 27).
    """
    seen: set[str] = set()
    for f in flightset.flights:
        if f.id in seen:
            raise InputFileError(f"duplicate flight id '{f.id}'", f"{source}: flight {f.id}", "give every flight its own id")
        seen.add(f.id)
    if flightset.conflict_radius < 0 or any(c <= 0 for c in flightset.cell):
        raise InputFileError(
            f"invalid cell {flightset.cell} or conflict_radius {flightset.conflict_radius}", source,
            "give positive cell sizes (m) and a conflict_radius ≥ 0",
        )
    if grid is not None:
        extent = np.asarray(grid.extent)
        for f in flightset.flights:
            bad = outside_grid(f.waypoints, extent)  # the rule of uamopt/schedule/airspace.py and of uamopt verify
            if np.any(bad):
                p = tuple(float(v) for v in f.waypoints[np.argmax(bad)])
                raise InputFileError(
                    f"waypoint {p} is outside the grid [0, {tuple(float(e) for e in extent)}]",
                    f"{source}: flight {f.id}", "move the track inside the airspace or enlarge grid.extent",
                )
    dep, arr = flightset.planned_departure_s, flightset.planned_arrival_s
    for i, f in enumerate(flightset.flights):
        if dep[i] < flightset.service_start_s - TIME_TOL_S:
            raise InputFileError(
                f"planned departure {dep[i]:g} s is before the service start {flightset.service_start_s:g} s",
                f"{source}: flight {f.id}", "plan it later or set service_start_s",
            )
        if arr[i] > flightset.service_end_s + TIME_TOL_S:
            raise InputFileError(
                f"planned arrival {arr[i]:.1f} s is after the service end {flightset.service_end_s:g} s (Eq. 26)",
                f"{source}: flight {f.id}", "plan it earlier or lengthen the service window (service_end_s)",
            )
    gap = flightset.turnaround_after_s
    for i, p in enumerate(flightset.previous):
        if p >= 0 and dep[i] < arr[p] + gap[p] - TIME_TOL_S:
            f, fp = flightset.flights[i], flightset.flights[p]
            raise InputFileError(
                f"planned departure {dep[i]:.1f} s overlaps aircraft {f.aircraft}'s flight {fp.id} "
                f"(arrival {arr[p]:.1f} s + turnaround {gap[p]:g} s)",
                f"{source}: flight {f.id}", "plan consecutive flights of one aircraft at least ΔT apart (Eq. 27)",
            )


def _fill_max_delay(flightset: FlightSet) -> FlightSet:
    """Δd = round(L/v_g) + ΔT (Eq. 29 with equality) where the file gives none."""
    gaps = flightset.turnaround_after_s.tolist()  # every flight's ΔT, filled in by FlightSet
    flights = tuple(
        replace(f, max_delay_s=round_half_up(f.flight_time_s) + gap) if math.isnan(f.max_delay_s) else f
        for f, gap in zip(flightset.flights, gaps, strict=True)
    )
    return replace(flightset, flights=flights)


def load_flights(
    path: str | Path,
    scenario: Scenario | None = None,
    grid: AirspaceGrid | None = None,
    network: Mapping[str, np.ndarray] | None = None,
) -> FlightSet:
    """Read and validate ``flights.json`` (docs/interfaces.md).

    Parameters
    ----------
    path : str or Path
        The flights file.
    scenario : Scenario, optional
        Supplies defaults the file does not give: cell, conflict radius r, T_D, T_R.
    grid : AirspaceGrid, optional
        When given, every waypoint must lie inside its extent.
    network : mapping route name -> (n, 3) waypoints, optional
        Tracks of flights that carry no ``waypoints``.

    Raises
    ------
    InputFileError
        Missing file, malformed JSON, missing key, unknown route, non-positive speed, a waypoint
        outside the grid, overlapping flights of one aircraft, a flight outside the service window.
    """
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise InputFileError(f"flights file not found: {path}", source, "give the path of a flights.json")
    raw = read_json(path, "the flights file", source, "a flights.json as docs/interfaces.md describes")
    if not isinstance(raw, dict) or not isinstance(raw.get("flights"), list):
        raise InputFileError("missing key 'flights' (a list)", source,
                             'write {"cell": [...], "conflict_radius": r, "flights": [...]}')
    if not raw["flights"]:
        raise InputFileError("the file holds no flights", source, "add at least one flight")
    sched = scenario.schedule if scenario is not None else None
    cell = raw.get("cell", grid.cell if grid is not None else (scenario.grid.cell if scenario is not None else None))
    if cell is None:
        raise InputFileError("missing key 'cell'", source, "give the cell size [dx, dy, dz] in metres")
    radius = raw.get("conflict_radius", sched.conflict_radius if sched is not None else 1)
    numbers: dict[str, float] = {}
    for key, default in (
        ("service_start_s", 0.0), ("service_end_s", DEFAULT_SERVICE_S),
        ("outbound_gap_s", sched.outbound_gap_s if sched else 240.0), ("return_gap_s", sched.return_gap_s if sched else 360.0),
    ):
        numbers[key] = check_number(raw.get(key, default), f"'{key}'", source, "give it in seconds", DURATION_S)
    cell_t = check_cell(cell, source)
    radius = check_number(radius, "'conflict_radius'", source, "1 = 3×3×3 zone, 0 = same cell (schedule.conflict_radius)",
                          CONFLICT_RADIUS)
    if grid is not None and cell_t != tuple(grid.cell):
        from uamopt.grid.grid import file_grid

        # the file's cell overrides the scenario's, within the same memory limit (tiny cells are refused)
        grid = file_grid(grid.extent, cell_t, scenario.grid.memory_limit_gb if scenario else None, source)
    flights = tuple(flight_from_dict(f, source, network) for f in raw["flights"])
    flightset = _fill_max_delay(FlightSet(cell=cell_t, conflict_radius=radius, flights=flights,
                                          service_start_s=numbers["service_start_s"], service_end_s=numbers["service_end_s"],
                                          outbound_gap_s=numbers["outbound_gap_s"], return_gap_s=numbers["return_gap_s"]))
    check_flightset(flightset, grid, source)
    return flightset


def flightset_to_dict(flightset: FlightSet) -> dict:
    """The JSON-ready content of flights.json; every flight self-contained (with waypoints). A
    flight's ``turnaround_after_s`` is written where it differs from the file's leg-parity default
    (``outbound_gap_s`` after an odd leg of its aircraft, ``return_gap_s`` after an even one)."""
    default = np.where(flightset.leg % 2 == 1, flightset.outbound_gap_s, flightset.return_gap_s)
    own = flightset.turnaround_after_s != default
    return {
        "cell": list(flightset.cell),
        "conflict_radius": flightset.conflict_radius,
        "service_start_s": flightset.service_start_s,
        "service_end_s": flightset.service_end_s,
        "outbound_gap_s": flightset.outbound_gap_s,
        "return_gap_s": flightset.return_gap_s,
        "flights": [
            {
                "id": f.id, "aircraft": f.aircraft, "route": f.route, "origin": f.origin,
                "destination": f.destination, "speed_mps": f.speed_mps,
                "planned_departure_s": f.planned_departure_s, "max_delay_s": f.max_delay_s,
                "waypoints": f.waypoints.tolist(),
                **({} if f.vertical_rate_mps is None else {"vertical_rate_mps": f.vertical_rate_mps}),
                **({"turnaround_after_s": f.turnaround_after_s} if mine else {}),
            }
            for f, mine in zip(flightset.flights, own.tolist(), strict=True)
        ],
    }


def save_flights(path: str | Path, flightset: FlightSet) -> None:
    """Write flights.json (floats in shortest round-trip form, so a reload is exact)."""
    from uamopt.outputs import write_json

    write_json(path, flightset_to_dict(flightset))
