"""The paper-case flight plan (Sec. 6.2): G aircraft flying round trips on the route network.

``straight_network`` stands in for planned tracks until they exist: straight tracks between
vertiports, a→b at the cruise altitude and b→a one cell layer higher (the airspace layering of
Sec. 4.1.2). ``generate_plan`` assigns aircraft to routes round-robin and chains each aircraft's
F flights (Eq. 23) with the turnaround gaps of Eqs. 27-28 taken with equality.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from uamopt.errors import UamoptError
from uamopt.schedule.flights import (
    DEFAULT_SERVICE_S,
    Flight,
    FlightSet,
    check_flightset,
    round_half_up,
    track_length_m,
)

if TYPE_CHECKING:
    from uamopt.grid import AirspaceGrid
    from uamopt.scenario import Scenario, Vertiport


def route_name(origin: str, destination: str) -> str:
    """The name of the directed route origin → destination, e.g. ``"V1-V4"``."""
    return f"{origin}-{destination}"


def scenario_routes(scenario: Scenario) -> list[tuple[str, str]]:
    """The network's routes (a, b): the scenario's list, or every pair in vertiport order."""
    if scenario.network.routes is not None:
        return [tuple(r) for r in scenario.network.routes]  # type: ignore[misc]
    names = [v.name for v in scenario.network.vertiports]
    return [(a, b) for i, a in enumerate(names) for b in names[i + 1:]]


def straight_network(scenario: Scenario, grid: AirspaceGrid, *, layer_offset_cells: int = 1) -> dict[str, np.ndarray]:
    """Straight tracks for every route of the network, both directions.

    a→b flies at ``network.cruise_altitude_m``; b→a flies ``layer_offset_cells`` cell layers
    higher (cruise + Δz by default). Each track is ``[origin, destination]`` as (2, 3) points, m.

    Note: with the default 3×3×3 conflict zone (r = 1), one layer apart is still within the zone;
    ``layer_offset_cells = 2`` separates the two directions completely.

    Examples
    --------
    >>> from uamopt.scenario import Scenario
    >>> from uamopt.grid import AirspaceGrid
    >>> net = straight_network(Scenario(), AirspaceGrid((50.0, 50.0, 30.0), (50, 90, 12)))
    >>> len(net), net["V4-V1"][0].tolist()
    (20, [2220.0, 4220.0, 150.0])
    """
    ports = {v.name: v for v in scenario.network.vertiports}
    z_out = scenario.network.cruise_altitude_m
    z_back = z_out + layer_offset_cells * grid.cell[2]
    network: dict[str, np.ndarray] = {}
    for a, b in scenario_routes(scenario):
        pa, pb = ports[a], ports[b]
        for (o, d), z in (((pa, pb), z_out), ((pb, pa), z_back)):
            track = np.array([[o.x, o.y, z], [d.x, d.y, z]], dtype=float)
            track.setflags(write=False)
            network[route_name(o.name, d.name)] = track
    extent = np.asarray(grid.extent)
    for name, track in network.items():
        if np.any(track < 0) or np.any(track > extent):
            raise UamoptError(
                f"route {name} leaves the grid (extent {tuple(extent.tolist())})", "network",
                "move the vertiports inside grid.extent or lower network.cruise_altitude_m",
            )
    return network


def flights_per_aircraft(
    service_s: float, track_length_m: float, speed_mps: float, outbound_gap_s: float, return_gap_s: float, interference: float
) -> int:
    """F = ⌊(T_f − T_s) / (2·round(L_g/v_g) + T_D + T_R + χ)⌋ × 2 (Eq. 23).

    >>> flights_per_aircraft(3600.0, 4365.0, 25.0, 240.0, 360.0, 0.3)  # Table B.3
    6
    """
    cycle = 2 * round_half_up(track_length_m / speed_mps) + outbound_gap_s + return_gap_s + interference
    return math.floor(service_s / cycle) * 2


def grid_vertiports(n: int, extent_m: tuple[float, float], *, margin_m: float = 300.0, seed: int = 0) -> tuple[Vertiport, ...]:
    """``n`` vertiports V1..Vn at seeded random whole-metre points of [margin, extent − margin]².

    For benchmarks on larger domains; at least 500 m apart where the domain allows it.
    """
    from uamopt.scenario import Vertiport

    rng = np.random.default_rng(seed)
    pts: list[tuple[float, float]] = []
    for _ in range(1000 * n):
        if len(pts) == n:
            break
        p = tuple(float(np.round(rng.uniform(margin_m, e - margin_m))) for e in extent_m)
        if all(math.dist(p, q) >= 500.0 for q in pts):
            pts.append(p)  # type: ignore[arg-type]
    if len(pts) < n:
        raise UamoptError(f"cannot place {n} vertiports 500 m apart", f"extent {extent_m}", "enlarge the domain")
    return tuple(Vertiport(name=f"V{i + 1}", x=x, y=y) for i, (x, y) in enumerate(pts))


def generate_plan(
    scenario: Scenario,
    network: Mapping[str, np.ndarray],
    seed: int,
    *,
    aircraft: int | None = None,
    service_s: float = DEFAULT_SERVICE_S,
    service_start_s: float = 0.0,
    first_departure_window_s: float = 600.0,
    departure_step_s: float = 1.0,
    flights_per_aircraft_override: int | None = None,
    cell: tuple[float, float, float] | None = None,
) -> FlightSet:
    """The initial flight plan: G aircraft on round trips, F flights each (Sec. 6.2, Eqs. 23-29).

    Parameters
    ----------
    scenario : Scenario
        Supplies the routes, v_g (``aircraft.cruise_speed_mps``), T_D, T_R, χ, G, r and the cell.
    network : mapping route name -> (n, 3) waypoints
        Both directions of every route, named ``"a-b"`` (e.g. :func:`straight_network`).
    seed : int
        Seeds the first departures.
    aircraft : int, optional
        G; default ``schedule.aircraft`` (20). Aircraft k flies route k mod R, starting at the
        route's first vertiport (20 aircraft over 10 routes: 2 per route).
    service_s, service_start_s : float
        T_f − T_s and T_s, s.
    first_departure_window_s : float
        Each aircraft's first planned departure is drawn uniformly from
        T_s + {0, step, 2·step, ...} ≤ T_s + window (a calibration knob).
    departure_step_s : float
        Resolution of that draw, s.
    flights_per_aircraft_override : int, optional
        F; default Eq. 23 with L_g = the longest route of the network (Table B.3's 4365 m).
    cell : (Δx, Δy, Δz), optional
        Default ``grid.cell``.

    Each next planned departure is the previous planned arrival + ΔT (Eq. 27 with equality),
    ΔT = T_D after an outbound, T_R after a return (Eq. 28); Δd = round(L/v_g) + ΔT with the
    flight's own track length L (Eq. 29 with equality).

    Raises
    ------
    UamoptError
        A route missing from ``network``, or a window so wide that some flight would end after T_f.
    """
    sched = scenario.schedule
    n_aircraft = sched.aircraft if aircraft is None else int(aircraft)
    speed = scenario.aircraft.cruise_speed_mps
    routes = scenario_routes(scenario)
    for a, b in routes:
        for name in (route_name(a, b), route_name(b, a)):
            if name not in network:
                raise UamoptError(f"unknown route '{name}'", "network", f"give tracks for every route; known: {', '.join(network)}")
    longest = max(track_length_m(t) for t in network.values())
    n_flights = flights_per_aircraft_override or flights_per_aircraft(
        service_s, longest, speed, sched.outbound_gap_s, sched.return_gap_s, sched.interference
    )
    if n_flights < 1:
        raise UamoptError(f"the service window of {service_s:g} s holds no round trip (Eq. 23)", "generate_plan", "lengthen service_s")
    service_end = service_start_s + service_s
    rng = np.random.default_rng(seed)
    width = max(len(str(n_aircraft)), 2)
    flights: list[Flight] = []
    for g in range(n_aircraft):
        a, b = routes[g % len(routes)]
        legs = [(a, b) if f % 2 == 0 else (b, a) for f in range(n_flights)]
        times = [track_length_m(network[route_name(o, d)]) / speed for o, d in legs]
        gaps = [sched.outbound_gap_s if f % 2 == 0 else sched.return_gap_s for f in range(n_flights)]  # f is 0-based here
        chain_s = sum(times) + sum(gaps[:-1])
        slack = service_s - chain_s
        if first_departure_window_s > slack + 1e-9:
            raise UamoptError(
                f"first_departure_window_s = {first_departure_window_s:g} s lets aircraft {g + 1}'s {n_flights} flights "
                f"end after the service end (slack {slack:.1f} s)",
                "generate_plan", f"use a window ≤ {math.floor(slack)} s or fewer flights per aircraft",
            )
        steps = math.floor(first_departure_window_s / departure_step_s + 1e-9)
        departure = service_start_s + departure_step_s * float(rng.integers(0, steps + 1))
        aircraft_id = f"A{g + 1:0{width}d}"
        for f, ((o, d), t, gap) in enumerate(zip(legs, times, gaps)):
            flights.append(Flight(
                id=f"F{len(flights) + 1:03d}", aircraft=aircraft_id, route=route_name(o, d), origin=o, destination=d,
                speed_mps=speed, planned_departure_s=departure, max_delay_s=round_half_up(t) + gap,
                waypoints=network[route_name(o, d)], turnaround_after_s=gap,
            ))
            departure = departure + t + gap
    flightset = FlightSet(
        cell=tuple(cell) if cell is not None else tuple(scenario.grid.cell),  # type: ignore[arg-type]
        conflict_radius=sched.conflict_radius, flights=tuple(flights), service_start_s=service_start_s,
        service_end_s=service_end, outbound_gap_s=sched.outbound_gap_s, return_gap_s=sched.return_gap_s,
    )
    check_flightset(flightset, None, "generate_plan")
    return flightset
