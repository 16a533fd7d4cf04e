"""Flights and flight sets: the input of the scheduling model (Sec. 4.3).

A :class:`Flight` is one planned flight of one aircraft along one track, flown at constant speed
``v_g`` with no en-route holding (docs/readings.md). A :class:`FlightSet` is every flight of a day with
the rules that tie them: the service window [T_s, T_f] (Eq. 26) and the turnaround gaps of
Eqs. 27-28. Per aircraft, flights are ordered by planned departure; the f-th flight (1-based) of an
aircraft is an outbound when f is odd and a return when f is even, and the gap after it is
T_D (odd f) or T_R (even f). That gap is stored explicitly per flight (``turnaround_after_s``)
so solvers need no parity logic.

Reading, validating and writing ``flights.json`` is :mod:`uamopt.schedule.flights_file`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    pass

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
