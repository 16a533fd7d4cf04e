"""Flights and flight sets: the input of the scheduling model (Sec. 4.3), and ``flights.json``.

A :class:`Flight` is one planned flight of one aircraft along one track, flown at constant speed
``v_g`` with no en-route holding (docs/readings.md). A :class:`FlightSet` is every flight of a day with
the rules that tie them: the service window [T_s, T_f] (Eq. 26) and the turnaround gaps of
Eqs. 27-28. Per aircraft, flights are ordered by planned departure; the f-th flight (1-based) of an
aircraft is an outbound when f is odd and a return when f is even, and the gap after it is
T_D (odd f) or T_R (even f). That gap is stored explicitly per flight (``turnaround_after_s``)
so solvers need no parity logic.

``flights.json`` (docs/interfaces.md)::

    {"cell": [dx, dy, dz], "conflict_radius": r,
     "service_start_s": 0, "service_end_s": 3600, "outbound_gap_s": 240, "return_gap_s": 360,
     "flights": [{"id", "aircraft", "route", "origin", "destination", "speed_mps",
                  "planned_departure_s", "max_delay_s", "waypoints": [[x, y, z], ...],
                  "vertical_rate_mps" (optional)}]}

The four service/gap keys are optional (defaults: 0, 3600 s, the scenario's T_D and T_R) and
``max_delay_s`` may be omitted (Eq. 29 with equality). A flight with ``waypoints`` is
self-contained; one without must name a route of the given ``network``. ``vertical_rate_mps``
(the vertiport variant): the first segment is a vertical take-off and the last a vertical landing,
both flown at that rate; the rest at ``speed_mps``.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
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
    parse_error,
)
from uamopt.errors import InputFileError

if TYPE_CHECKING:
    from uamopt.grid import AirspaceGrid
    from uamopt.scenario import Scenario

DEFAULT_SERVICE_S = 3600.0  # T_f − T_s, s: one hour reproduces F = 6 per aircraft (Eq. 23, Table B.3)
TIME_TOL_S = 1e-6  # slack for float round-off in time comparisons, s
# a flights file's numbers are held to uamopt/bounds.py's ranges, the verifier's own (a file the verifier would
# refuse is refused first; tests/test_numbers_hostile.py checks that the two agree)


def _frozen(array: np.ndarray) -> np.ndarray:
    """A read-only array: the cached views of a frozen flight set must not be edited in place."""
    array.setflags(write=False)
    return array


def round_half_up(value: float) -> float:
    """The paper's round() (Eqs. 23, 29): halves go up, unlike Python's banker's rounding."""
    return float(math.floor(value + 0.5))


def track_length_m(waypoints: np.ndarray) -> float:
    """Length of a piecewise-linear track (Eq. 31 times v_g), m."""
    return float(np.sum(np.linalg.norm(np.diff(np.asarray(waypoints, float), axis=0), axis=1)))


def waypoint_times_s(waypoints: np.ndarray, speed_mps: float, vertical_rate_mps: float | None = None) -> np.ndarray:
    """Time of each waypoint from departure, s: every segment flown at ``speed_mps`` (Eq. 31), except,
    with ``vertical_rate_mps``, the first (vertical take-off) and last (vertical landing) segments,
    flown at that climb/descent rate (the vertiport variant, docs/variants.md).

    >>> waypoint_times_s(np.array([[0.0, 0, 0], [0, 0, 100], [250, 0, 100], [250, 0, 0]]), 25.0, 2.5).tolist()
    [0.0, 40.0, 50.0, 90.0]
    """
    seg = np.linalg.norm(np.diff(np.asarray(waypoints, float), axis=0), axis=1)
    rate = np.full(len(seg), float(speed_mps))
    if vertical_rate_mps is not None:
        rate[[0, -1]] = vertical_rate_mps
    return np.concatenate([[0.0], np.cumsum(seg / rate)])


def with_vertical_phases(waypoints: np.ndarray, ground_z_m: float = 0.0) -> np.ndarray:
    """A cruise track with a vertical take-off from the ground below its first point and a vertical
    landing to the ground below its last (the vertiport variant).

    >>> with_vertical_phases(np.array([[0.0, 0, 120], [250, 0, 120]])).tolist()
    [[0.0, 0.0, 0.0], [0.0, 0.0, 120.0], [250.0, 0.0, 120.0], [250.0, 0.0, 0.0]]
    """
    wp = np.asarray(waypoints, dtype=float)
    first, last = wp[0].copy(), wp[-1].copy()
    first[2] = last[2] = ground_z_m
    out = np.vstack([first, wp, last])
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class Flight:
    """One planned flight f of aircraft g (Sec. 4.3).

    Attributes
    ----------
    id, aircraft, route, origin, destination : str
        Labels; ``aircraft`` groups flights into an aircraft's chain.
    speed_mps : float
        v_g, constant ground speed along the track, m/s.
    planned_departure_s : float
        D_{g,f}, planned departure, s.
    max_delay_s : float
        Δd_{g,f}, the largest admissible departure delay, s (Eq. 29).
    waypoints : ndarray (n, 3)
        The track, m; flown from the first to the last point.
    turnaround_after_s : float or None
        ΔT after this flight before the aircraft's next flight (Eq. 28), s. ``None`` is filled
        by :class:`FlightSet` from the flight's position in its aircraft's chain.
    """

    id: str
    aircraft: str
    route: str
    origin: str
    destination: str
    speed_mps: float
    planned_departure_s: float
    max_delay_s: float
    waypoints: np.ndarray
    turnaround_after_s: float | None = None
    #: climb/descent rate of the vertical take-off (first segment) and landing (last segment), m/s;
    #: None: the track is the cruise only, flown at v_g throughout (the paper's model)
    vertical_rate_mps: float | None = None

    @property
    def length_m(self) -> float:
        return track_length_m(self.waypoints)

    @property
    def flight_time_s(self) -> float:
        """T_n of the last waypoint (Eq. 31): track length / v_g, s (with vertical phases, those at
        their rate: :func:`waypoint_times_s`)."""
        if self.vertical_rate_mps is None:
            return self.length_m / self.speed_mps
        return float(waypoint_times_s(self.waypoints, self.speed_mps, self.vertical_rate_mps)[-1])

    @property
    def takeoff_s(self) -> float:
        """Duration of the vertical take-off, s (0 without vertical phases)."""
        if self.vertical_rate_mps is None:
            return 0.0
        return float(np.linalg.norm(self.waypoints[1] - self.waypoints[0])) / self.vertical_rate_mps

    @property
    def landing_s(self) -> float:
        """Duration of the vertical landing, s (0 without vertical phases)."""
        if self.vertical_rate_mps is None:
            return 0.0
        return float(np.linalg.norm(self.waypoints[-1] - self.waypoints[-2])) / self.vertical_rate_mps

    @property
    def planned_arrival_s(self) -> float:
        """A_{g,f} = D_{g,f} + flight time, s."""
        return self.planned_departure_s + self.flight_time_s


@dataclass(frozen=True, eq=False)
class FlightSet:
    """Every flight of the day with the rules that tie them (Eqs. 26-29).

    ``flights`` keeps the given order (index i is row i of ``schedule.csv``). Derived arrays
    (``leg``, ``previous``, ``requires``, ``delay_upper_s``, ...) are computed once, on demand, and
    are read-only.
    """

    cell: tuple[float, float, float]  # (Δx, Δy, Δz), m
    conflict_radius: int  # r: conflict zone of (2r+1)³ cells (Sec. 5.2.1)
    flights: tuple[Flight, ...]
    service_start_s: float = 0.0  # T_s, s (Eq. 23)
    service_end_s: float = DEFAULT_SERVICE_S  # T_f, s (Eqs. 23, 26)
    outbound_gap_s: float = 240.0  # T_D, s (Eq. 28)
    return_gap_s: float = 360.0  # T_R, s (Eq. 28)
    notes: tuple[str, ...] = ()  # how the generator adapted the plan (written to summary.json)
    # A window of a larger day (the rolling solver's sub-problems) keeps the day's aircraft chains
    # and precedence: a fixed flight's new departure must not re-sort its chain, and a sub-chain may
    # start with a return. None: derived from the flights (:attr:`chains`, :attr:`requires`).
    chain_order: tuple[np.ndarray, ...] | None = field(default=None, repr=False)
    outbound_of: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "cell", tuple(float(c) for c in self.cell))
        flights = list(self.flights)
        leg = self.leg
        for i, f in enumerate(flights):
            if f.turnaround_after_s is None:
                gap = self.outbound_gap_s if leg[i] % 2 == 1 else self.return_gap_s
                flights[i] = replace(f, turnaround_after_s=float(gap))
        object.__setattr__(self, "flights", tuple(flights))

    def __len__(self) -> int:
        return len(self.flights)

    def to_frame(self):
        """One row per flight: aircraft, route, origin, destination, speed_mps,
        planned_departure_s, planned_arrival_s, max_delay_s, turnaround_after_s, length_m,
        n_waypoints (pandas DataFrame indexed by flight id)."""
        import pandas as pd

        arrival = self.planned_arrival_s
        rows = [{"flight": f.id, "aircraft": f.aircraft, "route": f.route, "origin": f.origin,
                 "destination": f.destination, "speed_mps": f.speed_mps, "planned_departure_s": f.planned_departure_s,
                 "planned_arrival_s": float(arrival[i]), "max_delay_s": f.max_delay_s,
                 "turnaround_after_s": f.turnaround_after_s, "length_m": f.length_m,
                 "n_waypoints": len(f.waypoints)} for i, f in enumerate(self.flights)]
        return pd.DataFrame(rows).set_index("flight")

    # --- per-aircraft chains ------------------------------------------------------------
    @cached_property
    def chains(self) -> tuple[np.ndarray, ...]:
        """Flight indices of each aircraft in planned-departure order, aircraft in first-seen order
        (or :attr:`chain_order` when given)."""
        if self.chain_order is not None:
            return tuple(_frozen(np.asarray(c, dtype=np.int64)) for c in self.chain_order)
        by_aircraft: dict[str, list[int]] = {}
        for i, f in enumerate(self.flights):
            by_aircraft.setdefault(f.aircraft, []).append(i)
        dep = np.array([f.planned_departure_s for f in self.flights], dtype=float)
        return tuple(_frozen(np.array(sorted(ix, key=lambda i: (dep[i], i)), dtype=np.int64)) for ix in by_aircraft.values())

    @cached_property
    def ids(self) -> tuple[str, ...]:
        """The flight ids, in index order."""
        return tuple(f.id for f in self.flights)

    @property
    def aircraft_ids(self) -> tuple[str, ...]:
        return tuple(self.flights[int(c[0])].aircraft for c in self.chains)

    @property
    def n_aircraft(self) -> int:
        """G: the number of distinct aircraft."""
        return len(self.chains)

    @cached_property
    def leg(self) -> np.ndarray:
        """f: 1-based position of each flight in its aircraft's chain (odd = outbound, even = return)."""
        out = np.zeros(len(self.flights), dtype=np.int64)
        for chain in self.chains:
            out[chain] = np.arange(1, len(chain) + 1)
        return _frozen(out)

    @cached_property
    def previous(self) -> np.ndarray:
        """Index of the aircraft's previous flight, −1 for its first."""
        out = np.full(len(self.flights), -1, dtype=np.int64)
        for chain in self.chains:
            out[chain[1:]] = chain[:-1]
        return _frozen(out)

    @cached_property
    def requires(self) -> np.ndarray:
        """For a return (even leg): the index of its outbound, which it needs operated; else −1.

        A cancelled outbound cancels its return: the aircraft never left (docs/readings.md).
        Given as :attr:`outbound_of` for a window of a larger day.
        """
        if self.outbound_of is not None:
            return _frozen(np.asarray(self.outbound_of, dtype=np.int64))
        return _frozen(np.where(self.leg % 2 == 0, self.previous, -1))

    @cached_property
    def aircraft_index(self) -> np.ndarray:
        """g: 0-based aircraft number of each flight (order of :attr:`chains`)."""
        out = np.zeros(len(self.flights), dtype=np.int64)
        for g, chain in enumerate(self.chains):
            out[chain] = g
        return _frozen(out)

    # --- times --------------------------------------------------------------------------
    @cached_property
    def flight_time_s(self) -> np.ndarray:
        return _frozen(np.array([f.flight_time_s for f in self.flights], dtype=float))

    @cached_property
    def speed_mps(self) -> np.ndarray:
        return _frozen(np.array([f.speed_mps for f in self.flights], dtype=float))

    @cached_property
    def planned_departure_s(self) -> np.ndarray:
        return _frozen(np.array([f.planned_departure_s for f in self.flights], dtype=float))

    @property
    def planned_arrival_s(self) -> np.ndarray:
        return self.planned_departure_s + self.flight_time_s

    @cached_property
    def max_delay_s(self) -> np.ndarray:
        """Δd per flight (Eq. 29), s."""
        return _frozen(np.array([f.max_delay_s for f in self.flights], dtype=float))

    @cached_property
    def turnaround_after_s(self) -> np.ndarray:
        """ΔT after each flight (Eq. 28), s."""
        return _frozen(np.array([f.turnaround_after_s for f in self.flights], dtype=float))

    @cached_property
    def delay_upper_s(self) -> np.ndarray:
        """Tightest delay bound: min(Δd, T_f − planned arrival) (Eqs. 26, 29), s.

        Eq. 26 bounds the last arrival of each aircraft; since an aircraft's flights are in
        sequence, it is the same as every operated flight arriving by T_f.
        """
        return _frozen(np.maximum(0.0, np.minimum(self.max_delay_s, self.service_end_s - self.planned_arrival_s)))


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
    )


def _vertical(a: np.ndarray, b: np.ndarray, up: bool) -> bool:
    """Segment a→b is vertical (same x, y within 1e-6 m) and climbs (``up``) or descends."""
    return bool(np.all(np.abs(b[:2] - a[:2]) <= 1e-6) and ((b[2] > a[2]) if up else (b[2] < a[2])))


def check_flightset(flightset: FlightSet, grid: AirspaceGrid | None = None, source: str = "flights.json") -> None:
    """Validate the rules (STYLE.md: once, at the boundary); raise :class:`InputFileError`.

    Checks: unique ids; waypoints inside the grid (when given); planned departure ≥ T_s and
    planned arrival ≤ T_f; per aircraft, no two flights overlap in planned time
    (next planned departure ≥ previous planned arrival + ΔT, Eq. 27).
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
            bad = np.any((f.waypoints < -TIME_TOL_S) | (f.waypoints > extent + TIME_TOL_S), axis=1)
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
    try:
        raw = json.loads(path.read_text(encoding="utf-8-sig"))
    except json.JSONDecodeError as exc:
        raise InputFileError(f"malformed JSON: {exc.msg} at line {exc.lineno} column {exc.colno}", source,
                             "fix the syntax") from None
    except UnicodeDecodeError:
        raise InputFileError("flights file is not UTF-8 text", source, "save it as UTF-8 JSON") from None
    except ValueError as exc:  # an integer of more than 4300 digits (Python's int-string limit)
        raise InputFileError(f"malformed JSON: {parse_error(exc)}", source, "write every number in its range "
                             "(docs/interfaces.md, flights.json)") from None
    except RecursionError:
        raise InputFileError("the flights file is nested too deeply to read", source, "give a flights.json as "
                             "docs/interfaces.md describes") from None
    except OSError as exc:
        raise InputFileError(f"cannot read the flights file: {exc.strerror or exc}", source,
                             "check that the file is readable") from None
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
    """The JSON-ready content of flights.json; every flight self-contained (with waypoints)."""
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
            }
            for f in flightset.flights
        ],
    }


def save_flights(path: str | Path, flightset: FlightSet) -> None:
    """Write flights.json (floats in shortest round-trip form, so a reload is exact)."""
    from uamopt.outputs import write_json

    write_json(path, flightset_to_dict(flightset))
