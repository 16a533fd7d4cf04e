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
    Flight,
    FlightSet,
    round_half_up,
    waypoint_times_s,
    with_vertical_phases,
)
from uamopt.schedule.flights_file import check_flightset

if TYPE_CHECKING:
    from uamopt.grid import AirspaceGrid
    from uamopt.scenario import Scenario, Vertiport


def route_name(origin: str, destination: str) -> str:
    """The name of the directed route origin → destination, e.g. ``"V1-V4"``."""
    return f"{origin}-{destination}"


def scenario_routes(scenario: Scenario) -> list[tuple[str, str]]:
    """The network's routes (a, b) (:meth:`uamopt.scenario.NetworkConfig.route_list`)."""
    return scenario.network.route_list()


def straight_network(scenario: Scenario, grid: AirspaceGrid, *, layer_offset_cells: int | None = None
                     ) -> dict[str, np.ndarray]:
    """Straight tracks for every route of the network, both directions.

    a→b flies at ``network.cruise_altitude_m``; b→a flies on the layers of
    :meth:`AirspaceGrid.direction_layers` (r + 1 cell layers higher, outside the conflict zone: the
    rule of the planned network, ``network.tracks = "straight"``), or ``layer_offset_cells`` layers
    higher when given. Each track is ``[origin, destination]`` as (2, 3) points, m.

    Examples
    --------
    >>> from uamopt.scenario import Scenario
    >>> from uamopt.grid import AirspaceGrid
    >>> net = straight_network(Scenario(), AirspaceGrid((50.0, 50.0, 30.0), (50, 90, 12)))
    >>> len(net), net["V4-V1"][0].tolist()
    (20, [2220.0, 4220.0, 180.0])
    """
    ports = {v.name: v for v in scenario.network.vertiports}
    z_out = scenario.network.cruise_altitude_m
    if layer_offset_cells is None:
        k_out, k_back = grid.direction_layers(z_out, scenario.schedule.conflict_radius)
        layer_offset_cells = k_back - k_out
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
    """``n`` vertiports V1..Vn at seeded random whole-metre points of [margin, extent − margin]², at
    least 500 m apart (:func:`uamopt.scenario.random_vertiports`, the ``network.random_vertiports`` key)."""
    from uamopt.scenario import random_vertiports

    try:
        return random_vertiports(n, extent_m, margin_m=margin_m, seed=seed)
    except ValueError as exc:
        raise UamoptError(str(exc), f"extent {extent_m}", "enlarge the domain or place fewer vertiports") from None


#: Peak memory of scheduling a plan, bytes, the guard of ``schedule.memory_limit_gb`` (measured: `uamopt flights`
#: with straight tracks, 1,200 to 300,000 flights: 530-740 B per flight; 12,000 flights with 12.6 M pairs of
#: overlapping flying windows: 77 B per pair in the conflict search), with a margin.
BYTES_PER_FLIGHT = 1000
BYTES_PER_AIRCRAFT = 200
BYTES_PER_WINDOW_PAIR = 120


def check_plan_memory(scenario: Scenario | None, flights: int, aircraft: int = 0, window_pairs: int = 0,
                      where: str = "schedule.aircraft / schedule.flights") -> None:
    """Refuse, before it is made, a plan (``flights`` flights of ``aircraft`` aircraft) or a conflict
    search (``window_pairs`` pairs of flights whose flying windows overlap,
    :func:`uamopt.schedule.occupancy.candidate_count`) that would need more memory than
    ``schedule.memory_limit_gb`` (default ``grid.memory_limit_gb``, else 80 % of this machine's)."""
    from uamopt.grid.grid import gigabytes, memory_limit_bytes

    limit_gb = None
    if scenario is not None:
        limit_gb = scenario.schedule.memory_limit_gb
        limit_gb = scenario.grid.memory_limit_gb if limit_gb is None else limit_gb
    limit = memory_limit_bytes(limit_gb)
    need = flights * BYTES_PER_FLIGHT + aircraft * BYTES_PER_AIRCRAFT + window_pairs * BYTES_PER_WINDOW_PAIR
    if need > limit:
        what = f"a plan of {flights:,} flights of {aircraft:,} aircraft" if aircraft else f"scheduling {flights:,} flights"
        if window_pairs:
            what += f" with {window_pairs:,} pairs of flights whose flying windows overlap"
        raise UamoptError(f"{what} needs about {gigabytes(need)} GB, more than the limit of {gigabytes(limit)} GB", where,
                          "plan fewer flights or aircraft (schedule.flights, schedule.aircraft), or raise "
                          "schedule.memory_limit_gb")


def flights_per_aircraft_list(total: int, n_aircraft: int) -> list[int]:
    """F per aircraft when the plan holds ``total`` flights: ⌊total/G⌋ each, the remainder spread
    one each over the first aircraft.

    >>> flights_per_aircraft_list(125, 20)[:6], sum(flights_per_aircraft_list(125, 20))
    ([7, 7, 7, 7, 7, 6], 125)
    """
    base, extra = divmod(int(total), int(n_aircraft))
    return [base + (1 if g < extra else 0) for g in range(n_aircraft)]


def generate_plan(
    scenario: Scenario,
    network: Mapping[str, np.ndarray],
    seed: int,
    *,
    aircraft: int | None = None,
    flights: int | None = None,
    service_s: float | None = None,
    service_start_s: float = 0.0,
    first_departure_window_s: float | None = None,
    departure_step_s: float | None = None,
    max_delay_scale: float | None = None,
    cell: tuple[float, float, float] | None = None,
) -> FlightSet:
    """The initial flight plan: G aircraft on round trips (Sec. 6.2, Eqs. 23-29).

    Every keyword defaults to the scenario's ``[schedule]`` key of the same meaning.

    Parameters
    ----------
    scenario : Scenario
        Supplies the routes, v_g (``aircraft.cruise_speed_mps``), T_D, T_R, χ, G, r and the cell.
    network : RouteNetwork, or mapping route name -> (n, 3) waypoints
        Both directions of every route, named ``"a-b"`` (:func:`~uamopt.planning.network.plan_network`
        or :func:`straight_network`).
    seed : int
        Seeds the first departures.
    aircraft : int, optional
        G (``schedule.aircraft``). Aircraft k flies route k mod R, starting at the route's first
        vertiport (20 aircraft over 10 routes: 2 per route).
    flights : int, optional
        Total planned flights (``schedule.flights``): ⌊flights/G⌋ per aircraft, the remainder one
        each over the first aircraft. ``None``: F per aircraft from Eq. 23 with L_g = the longest
        route of the network (Table B.3's 4365 m) and the scenario's speed and service window.
    service_s, service_start_s : float
        T_f − T_s (``schedule.service_s``) and T_s, s.
    first_departure_window_s : float
        Each aircraft's first planned departure is drawn uniformly from
        T_s + {0, step, 2·step, ...} ≤ T_s + window. Where an aircraft's chain leaves less slack
        before T_f than the window, its window shrinks to the slack and a note says so
        (``FlightSet.notes``, written to summary.json).
    departure_step_s : float
        Resolution of that draw, s (``schedule.time_step_s``, ΔT_a).
    max_delay_scale : float
        Δd_f = round(scale × (round(L/v_g) + ΔT)) (Eq. 29 as an inequality; ``schedule.max_delay_scale``).
    cell : (Δx, Δy, Δz), optional
        Default ``grid.cell``.

    Each next planned departure is the previous planned arrival + ΔT (Eq. 27 with equality),
    ΔT = T_D after an outbound, T_R after a return (Eq. 28).

    Raises
    ------
    UamoptError
        A route missing from ``network``, a bad scale, or flights that cannot fit in the service
        window even with no slack.
    """
    waypoints = getattr(network, "waypoints", None)
    if callable(waypoints):  # a RouteNetwork
        network = waypoints()
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise UamoptError(f"the plan seed must be a whole number ≥ 0, got {seed!r}", "--seed / schedule.plan_seed",
                          "give 0, 1, 2, ...")
    sched = scenario.schedule
    n_aircraft = sched.aircraft if aircraft is None else int(aircraft)
    total = sched.flights if flights is None else int(flights)
    service_s = sched.service_s if service_s is None else float(service_s)
    window = sched.first_departure_window_s if first_departure_window_s is None else float(first_departure_window_s)
    step = sched.time_step_s if departure_step_s is None else float(departure_step_s)
    scale = sched.max_delay_scale if max_delay_scale is None else float(max_delay_scale)
    if not 0.0 < scale <= 1.0:
        raise UamoptError(f"max_delay_scale must be in (0, 1], got {scale}", "schedule.max_delay_scale",
                          "Eq. 29 bounds Δd by round(L/v_g) + ΔT; give a fraction of that bound")
    speed = scenario.aircraft.cruise_speed_mps
    routes = scenario_routes(scenario)
    rate = scenario.aircraft.vertical_rate_mps if scenario.network.vertical_phases else None
    for name, wp in network.items():
        points = np.asarray(wp, dtype=float)
        if points.ndim != 2 or points.shape[1] != 3 or len(points) < 2 or not np.isfinite(points).all():
            raise UamoptError(f"route '{name}' must be at least two finite [x, y, z] waypoints, got shape {points.shape}",
                              "network", "give each route's track as an (n, 3) array of waypoints, n ≥ 2")
        if not np.linalg.norm(np.diff(points, axis=0), axis=1).sum() > 0:
            raise UamoptError(f"route '{name}' has zero length (all its waypoints are one point)", "network",
                              "give a track that joins two different points")
    if rate is not None:  # the vertiport variant: take-off from and landing to the ground (z = 0) below P_O, P_D
        network = {name: with_vertical_phases(wp) for name, wp in network.items()}
    for a, b in routes:
        for name in (route_name(a, b), route_name(b, a)):
            if name not in network:
                raise UamoptError(f"unknown route '{name}'", "network",
                                  f"give tracks for every route; known: {', '.join(network)}")
    if total is None:
        longest = speed * max(waypoint_times_s(t, speed, rate)[-1] for t in network.values())  # L_g/v_g: the longest flight time
        each = flights_per_aircraft(service_s, longest, speed, sched.outbound_gap_s, sched.return_gap_s, sched.interference)
        if each < 1:
            raise UamoptError(f"the service window of {service_s:g} s holds no round trip (Eq. 23)",
                              "schedule.service_s", "lengthen the service window or set schedule.flights")
        check_plan_memory(scenario, each * n_aircraft, n_aircraft)  # before a flight is made (G = 10⁷: 60 GB)
        per_aircraft = [each] * n_aircraft
    else:
        check_plan_memory(scenario, total, n_aircraft)
        per_aircraft = flights_per_aircraft_list(total, n_aircraft)
    service_end = service_start_s + service_s
    rng = np.random.default_rng(seed)
    width = max(len(str(n_aircraft)), 2)
    plan: list[Flight] = []
    narrowed: list[float] = []
    for g in range(n_aircraft):
        n_flights = per_aircraft[g]
        a, b = routes[g % len(routes)]
        legs = [(a, b) if f % 2 == 0 else (b, a) for f in range(n_flights)]
        times = [float(waypoint_times_s(network[route_name(o, d)], speed, rate)[-1]) for o, d in legs]
        gaps = [sched.outbound_gap_s if f % 2 == 0 else sched.return_gap_s for f in range(n_flights)]  # f is 0-based here
        slack = service_s - (sum(times) + sum(gaps[:-1]))
        if slack < -1e-9:
            raise UamoptError(
                f"aircraft {g + 1}'s {n_flights} flights need {service_s - slack:.0f} s, more than the "
                f"{service_s:g} s service window", "schedule.flights / schedule.service_s",
                "plan fewer flights, more aircraft (schedule.aircraft), a longer window or a faster aircraft")
        width_g = window
        if window > slack + 1e-9:
            width_g = max(slack, 0.0)
            narrowed.append(width_g)
        steps = math.floor(width_g / step + 1e-9)
        departure = service_start_s + step * float(rng.integers(0, steps + 1))
        aircraft_id = f"A{g + 1:0{width}d}"
        for (o, d), t, gap in zip(legs, times, gaps, strict=True):
            plan.append(Flight(
                id=f"F{len(plan) + 1:03d}", aircraft=aircraft_id, route=route_name(o, d), origin=o, destination=d,
                speed_mps=speed, planned_departure_s=departure, max_delay_s=round_half_up(scale * (round_half_up(t) + gap)),
                waypoints=network[route_name(o, d)], turnaround_after_s=gap, vertical_rate_mps=rate,
            ))
            departure = departure + t + gap
    notes: tuple[str, ...] = ()
    if narrowed:
        notes = (f"first_departure_window_s = {window:g} s does not fit {len(narrowed)} of {n_aircraft} aircraft; "
                 f"their first departures were drawn from the slack they have (down to {min(narrowed):.0f} s)",)
    flightset = FlightSet(
        cell=tuple(cell) if cell is not None else tuple(scenario.grid.cell),  # type: ignore[arg-type]  # tuple() of 3 is 3 long
        conflict_radius=sched.conflict_radius, flights=tuple(plan), service_start_s=service_start_s,
        service_end_s=service_end, outbound_gap_s=sched.outbound_gap_s, return_gap_s=sched.return_gap_s, notes=notes,
    )
    check_flightset(flightset, None, "generate_plan")
    return flightset
