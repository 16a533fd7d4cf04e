"""``uamopt export bluesky DIR``: a schedule folder as a BlueSky scenario (``DIR/bluesky.scn``).

BlueSky (TU Delft, PyPI ``bluesky-simulator``) replays the schedule with its own aircraft
dynamics and its own loss-of-separation detection (:mod:`uamopt.sim.replay`). Every operated flight
becomes one aircraft, created at its scheduled departure at the first point of its track, flying
its trajectory and deleted when it passes the last point. Writing needs no BlueSky.

The trajectory (``trajectory``): by default the flyable trajectory nearest to the plan
(:mod:`uamopt.export.trajectory`: the plan turns instantly, an aircraft cannot; the design keeps
to the plan's position *and time* within the acceleration of the bank limit, e.g. ≤ 7.81 m on
the paper case's tracks); ``"waypoints"`` hands BlueSky the track's own waypoints at v_g, whose
corners BlueSky cuts with its fly-by turns while flying on at v_g, ahead of the plan after each.

Faithful to the plan, within what the simulator can do (measured figures in docs/export.md):

- Positions are WGS 84 through the folder's :class:`~uamopt.export.frame.LocalFrame`; altitudes
  are z (above the ground datum), in feet; speeds are CAS in knots (``CASMACHTHR 0`` first, so low
  speeds are not read as Mach), converted from the true airspeed by the ISA (no wind: TAS = ground
  speed).
- BlueSky moves aircraft over a sphere of radius 6 371 km while the frame's metres are the CRS's:
  each leg is commanded at its length on that sphere / its time, so that it takes its time (for
  the plan's waypoints: v_g corrected by ≤ 0.3 %; without it the drift reaches ~10 m over 4 km).
- BlueSky steps its clock by ``dt``: an aircraft is created at the first step t_k ≥ departure, at
  the point its trajectory reaches at t_k (so the step does not delay it).
- The aircraft type is EC35 (a helicopter that hovers, ≤ 72 m/s, ±7.6 m/s vertical) standing in
  for the eVTOL, with bank limit ``bank_deg`` (default 45°: turn radius v²/(g tan φ) = 64 m at
  25 m/s; BlueSky's 25° gives 137 m). Points are fly-by, VNAV with top-of-climb/descent logic
  off, so climbs follow the planned gradient.
- Detection: ``CDMETHOD STATEBASED``, resolution off, protected zone (``ZONER``, ``ZONEDH``) from
  the replay's zone (see :func:`uamopt.export.zone.protected_zone`).
- Vertical phases (the vertiport variant: a flight with ``vertical_rate_mps``, first and last
  segments vertical): the aircraft is created on its vertiport's pad at the departure, hovering
  (speed 0), and climbs with ``ALT`` at the vertical rate; its cruise (the segments between, designed
  as above) is its LNAV route. The plan jumps from hover to v_g at the top of climb, which no
  aircraft can: BlueSky's rotorcraft accelerate at a = 3.5 m/s² (``ROTOR_ACCEL_MPS2``), so the
  speed is commanded v/(2a) before the top of climb, and 0 v/(2a) before the top of descent, which
  keeps the aircraft within v²/(8a) of the plan through each transition (22.3 m at 25 m/s:
  ``transition_error_m``, beyond the default budget e_h, so the replay lists these flights as over
  budget; docs/export.md). At the top of descent ``ALT`` takes it down at the vertical rate to the
  ground, where it is deleted at its planned arrival.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from uamopt.errors import UamoptError
from uamopt.export.defaults import DEFAULT_BANK_DEG, DEFAULT_DT_S, DEFAULT_TRAJECTORY, TRAJECTORIES
from uamopt.export.folder import ScheduleFolder, read_schedule_folder, write_texts
from uamopt.export.trajectory import (
    ACCEL_SHARE,
    DESIGN_STEP_S,
    Trajectory,
    flyable_trajectory,
    plan_trajectory,
)

FT_M = 0.3048
KT_MPS = 1852.0 / 3600.0
NM_M = 1852.0
R_EARTH_BLUESKY_M = 6371000.0  # bluesky.tools.aero.Rearth: the sphere aircraft move on
AIRCRAFT_TYPE = "EC35"
#: BlueSky 1.1.1's horizontal acceleration of every rotorcraft, m/s² (``axmax_rotor`` in
#: bluesky/traffic/performance/openap/perfoap.py ``calc_axmax``)
ROTOR_ACCEL_MPS2 = 3.5


def tas_to_cas(tas_mps: np.ndarray, altitude_m: np.ndarray) -> np.ndarray:
    """Calibrated airspeed of a true airspeed in the ISA troposphere (compressible), m/s.

    p = p₀ (T/T₀)^(−g₀/(L R)), q_c = p [(1 + (γ−1)/2 (V/a)²)^(γ/(γ−1)) − 1],
    CAS = √(2 a₀²/(γ−1) [(q_c/p₀ + 1)^((γ−1)/γ) − 1]).
    """
    gamma, r_air, g0, lapse = 1.4, 287.05287, 9.80665, -0.0065
    t0, p0 = 288.15, 101325.0
    temp = t0 + lapse * np.asarray(altitude_m, float)
    p = p0 * (temp / t0) ** (-g0 / (lapse * r_air))
    a, a0 = np.sqrt(gamma * r_air * temp), math.sqrt(gamma * r_air * t0)
    qc = p * ((1 + (gamma - 1) / 2 * (np.asarray(tas_mps, float) / a) ** 2) ** (gamma / (gamma - 1)) - 1)
    return np.sqrt(2 * a0 * a0 / (gamma - 1) * ((qc / p0 + 1) ** ((gamma - 1) / gamma) - 1))


def sphere_distance_m(lon1, lat1, lon2, lat2) -> np.ndarray:
    """Great-circle distance on BlueSky's sphere (R = 6 371 km), m (haversine)."""
    p1, p2 = np.radians(lat1), np.radians(lat2)
    h = np.sin((p2 - p1) / 2) ** 2 + np.cos(p1) * np.cos(p2) * np.sin(np.radians(np.subtract(lon2, lon1)) / 2) ** 2
    return 2 * R_EARTH_BLUESKY_M * np.arcsin(np.sqrt(h))


def sphere_bearing_deg(lon1, lat1, lon2, lat2) -> float:
    """Initial great-circle bearing from point 1 to point 2, degrees from north."""
    p1, p2, dl = math.radians(lat1), math.radians(lat2), math.radians(lon2 - lon1)
    y = math.sin(dl) * math.cos(p2)
    x = math.cos(p1) * math.sin(p2) - math.sin(p1) * math.cos(p2) * math.cos(dl)
    return math.degrees(math.atan2(y, x)) % 360.0


def first_step_s(departure_s: float, dt_s: float) -> float:
    """t_k: the first multiple of ``dt_s`` at or after the departure (BlueSky's clock is exact decimal)."""
    return math.ceil(departure_s / dt_s - 1e-9) * dt_s


def aircraft_ids(flight_ids: Sequence[str]) -> dict[str, str]:
    """BlueSky callsigns: the flight id in upper-case letters and digits, made unique."""
    out: dict[str, str] = {}
    used: set[str] = set()
    for n, fid in enumerate(flight_ids):
        base = re.sub(r"[^A-Z0-9]", "", fid.upper()) or f"F{n + 1}"
        if base[0].isdigit():
            base = "F" + base
        acid, k = base, 1
        while acid in used:
            k += 1
            acid = f"{base}X{k}"
        used.add(acid)
        out[fid] = acid
    return out


def _stamp(t_s: float) -> str:
    h, rem = divmod(max(t_s, 0.0), 3600.0)
    m, s = divmod(rem, 60.0)
    return f"{int(h):02d}:{int(m):02d}:{s:06.3f}>"


def flight_trajectories(flights: Sequence, bank_deg: float = DEFAULT_BANK_DEG,
                        trajectory: str = DEFAULT_TRAJECTORY) -> dict[str, Trajectory]:
    """What each operated flight commands, times from its departure (with vertical phases: from the
    top of climb, the cruise only): flight id -> :class:`Trajectory`.

    ``trajectory = "designed"``: the flyable trajectory nearest to the plan
    (:func:`~uamopt.export.trajectory.flyable_trajectory`, designed once per track);
    ``"waypoints"``: the track's own waypoints at v_g (BlueSky then cuts their corners on its own).
    """
    if trajectory not in TRAJECTORIES:
        raise UamoptError(f"unknown trajectory {trajectory!r}", "--trajectory", f"choose one of {', '.join(TRAJECTORIES)}")
    designed: dict[tuple, Trajectory] = {}
    out = {}
    for o in flights:
        wp = np.asarray(o.flight.waypoints, float)
        if o.flight.vertical_rate_mps is not None:
            wp = wp[1:-1]  # the cruise: the vertical phases are flown with ALT (vertical_commands)
        if trajectory == "waypoints":
            out[o.flight.id] = plan_trajectory(wp, o.flight.speed_mps)
            continue
        key = (wp.tobytes(), o.flight.speed_mps)
        if key not in designed:
            designed[key] = flyable_trajectory(wp, o.flight.speed_mps, bank_deg)
        out[o.flight.id] = designed[key]
    return out


def flight_commands(acid: str, trajectory: Trajectory, frame, bank_deg: float) -> list[str]:
    """CRE, BANK, ADDWPT..., AT-last-point DEL, LNAV/VNAV: one aircraft flying ``trajectory`` (clock times).

    Every leg is commanded at the airspeed that makes it last its time on BlueSky's sphere.
    """
    points, times = trajectory.points, trajectory.times_s
    lon, lat = frame.to_lonlat(points[:, 0], points[:, 1])
    z = points[:, 2]
    ground = sphere_distance_m(lon[:-1], lat[:-1], lon[1:], lat[1:])
    tas = ground / np.diff(times)  # no wind: TAS = ground speed; BlueSky's speeds are horizontal
    cas_kt = tas_to_cas(tas, 0.5 * (z[:-1] + z[1:])) / KT_MPS
    cas_kt = np.append(cas_kt, cas_kt[-1])  # VNAV speeds are "from" speeds: point i sets leg i
    alt_ft = np.maximum(z / FT_M, 0.1)  # ADDWPT ignores an altitude of exactly 0
    hdg = sphere_bearing_deg(lon[0], lat[0], lon[1], lat[1])
    end = f"{acid}_END"
    lines = [f"CRE {acid} {AIRCRAFT_TYPE} {lat[0]:.8f} {lon[0]:.8f} {hdg:.3f} {alt_ft[0]:.2f} {cas_kt[0]:.4f}",
             f"BANK {acid} {bank_deg:g}"]
    lines += [f"ADDWPT {acid} {lat[i]:.8f} {lon[i]:.8f} {alt_ft[i]:.2f} {cas_kt[i]:.4f}" for i in range(1, len(z) - 1)]
    lines += [f"DEFWPT {end} {lat[-1]:.8f} {lon[-1]:.8f}", f"ADDWPT {acid} {end} {alt_ft[-1]:.2f} {cas_kt[-1]:.4f}",
              f"{acid} AT {end} DO DEL {acid}",
              f"LNAV {acid} ON", f"SPD {acid} {cas_kt[0]:.4f}", f"SWTOC {acid} OFF", f"SWTOD {acid} OFF", f"VNAV {acid} ON"]
    return lines


def transition_error_m(speed_mps: float, accel_mps2: float = ROTOR_ACCEL_MPS2) -> float:
    """v²/(8a): the largest horizontal distance to the plan of a speed change 0 ↔ v at acceleration a
    centred on the plan's instant jump (started v/(2a) before it), m (module docstring)."""
    return speed_mps * speed_mps / (8.0 * accel_mps2)


def vertical_commands(acid: str, o, cruise: Trajectory, frame, bank_deg: float, dt_s: float) -> list[tuple[float, str]]:
    """(clock time, command) of one flight with vertical phases (module docstring): created on the
    ground hovering, ALT up at the vertical rate, the cruise ``cruise`` (times from the top of climb)
    as its LNAV/VNAV route with the speed commanded v/(2a) early, speed 0 v/(2a) before the top of
    descent, ALT down, DEL at the arrival."""
    f = o.flight
    rate = float(f.vertical_rate_mps)
    wp = np.asarray(f.waypoints, float)
    top, tod = o.departure_s + f.takeoff_s, o.arrival_s - f.landing_s  # top of climb, top of descent
    points, times = cruise.points, cruise.times_s
    lon, lat = frame.to_lonlat(points[:, 0], points[:, 1])
    z = points[:, 2]
    ground = sphere_distance_m(lon[:-1], lat[:-1], lon[1:], lat[1:])
    tas = ground / np.diff(times)
    cas_kt = tas_to_cas(tas, 0.5 * (z[:-1] + z[1:])) / KT_MPS
    cas_kt = np.append(cas_kt, cas_kt[-1])
    alt_ft = np.maximum(z / FT_M, 0.1)
    rate_fpm = rate / FT_M * 60.0
    t_k = first_step_s(o.departure_s, dt_s)
    z0 = min(wp[0, 2] + rate * (t_k - o.departure_s), wp[1, 2])  # where the climb is at t_k
    glon, glat = frame.to_lonlat(wp[0, 0], wp[0, 1])
    hdg = sphere_bearing_deg(float(glon), float(glat), lon[1], lat[1])
    at = t_k
    out = [(at, f"CRE {acid} {AIRCRAFT_TYPE} {float(glat):.8f} {float(glon):.8f} {hdg:.3f} {max(z0 / FT_M, 0.1):.2f} 0"),
           (at, f"BANK {acid} {bank_deg:g}"), (at, f"SWTOC {acid} OFF"), (at, f"SWTOD {acid} OFF")]
    out += [(at, f"ADDWPT {acid} {lat[i]:.8f} {lon[i]:.8f} {alt_ft[i]:.2f} {cas_kt[i]:.4f}") for i in range(1, len(z))]
    out += [(at, f"LNAV {acid} ON"), (at, f"ALT {acid} {alt_ft[0]:.2f} {rate_fpm:.3f}")]
    a = ROTOR_ACCEL_MPS2
    out += [(max(top - tas[0] / (2 * a), at), f"SPD {acid} {cas_kt[0]:.4f}"), (max(top, at), f"VNAV {acid} ON"),
            (max(tod - tas[-1] / (2 * a), at), f"SPD {acid} 0"),
            (max(tod, at), f"ALT {acid} {max(wp[-1, 2] / FT_M, 0.1):.2f} {rate_fpm:.3f}"),
            (max(first_step_s(o.arrival_s, dt_s), at), f"DEL {acid}")]
    return out


def scenario_text(folder: ScheduleFolder, zone_m: tuple[float, float], *, dt_s: float = DEFAULT_DT_S,
                  bank_deg: float = DEFAULT_BANK_DEG, flights: Sequence | None = None,
                  trajectory: str = DEFAULT_TRAJECTORY, designs: dict[str, Trajectory] | None = None) -> str:
    """The .scn text of the operated flights (or of ``flights``, a subset of ``folder.operated``).

    ``zone_m`` = (r_pz, h_pz): BlueSky's protected zone, horizontal radius and half height, m.
    ``designs``: the flights' trajectories when already computed (:func:`flight_trajectories`).
    """
    frame = folder.frame
    chosen = folder.operated if flights is None else tuple(flights)
    designs = designs or flight_trajectories(chosen, bank_deg, trajectory)
    ids = aircraft_ids([o.flight.id for o in folder.operated])
    rpz, hpz = zone_m
    lon0, lat0 = frame.to_lonlat(0.0, 0.0)
    how = (f"designed: nearest flyable to the plan, acceleration ≤ {ACCEL_SHARE:g}·g·tan({bank_deg:g}°), "
           f"nodes every {DESIGN_STEP_S:g} s" if trajectory == "designed" else "the tracks' own waypoints at v_g")
    head = [
        f"# uamopt schedule {folder.path.name}: {len(chosen)} operated flights replayed in BlueSky 1.1.1",
        (f"# frame ({frame.source}{'' if folder.frame_recorded else ': none recorded, synthetic anchor assumed'}): "
         f"local (0, 0) = lon {float(lon0):.7f}, lat {float(lat0):.7f}; CRS {frame.crs}"),
        f"# protected zone: r_pz = {rpz:.2f} m, h_pz = {hpz:.2f} m; clock step DT = {dt_s:g} s (creation times assume it)",
        f"# trajectory: {how}",
        "# aircraft: flight id -> callsign " + ", ".join(f"{o.flight.id}={ids[o.flight.id]}" for o in chosen),
    ]
    setup = ["CASMACHTHR 0", f"DT {dt_s:g}", "CDMETHOD STATEBASED", "RESO OFF",
             f"ZONER {rpz / NM_M:.6f}", f"ZONEDH {hpz / FT_M:.4f}", f"PAN {float(lat0):.6f} {float(lon0):.6f}"]
    lines = [_stamp(0.0) + c for c in setup]
    timed: list[tuple[float, int, str]] = []  # vertical flights' commands at their clock times, sorted below
    for o in chosen:
        if o.flight.vertical_rate_mps is not None:
            for when, cmd in vertical_commands(ids[o.flight.id], o, designs[o.flight.id], frame, bank_deg, dt_s):
                timed.append((when, len(timed), cmd))
            continue
        t_k = first_step_s(o.departure_s, dt_s)
        rest = designs[o.flight.id].rest_from(t_k - o.departure_s)  # created at t_k where the trajectory is then
        clock = Trajectory(rest.times_s + o.departure_s, rest.points, rest.max_error_m)
        base = len(timed)
        timed += [(t_k, base + k, c) for k, c in enumerate(flight_commands(ids[o.flight.id], clock, frame, bank_deg))]
    # BlueSky reads a scenario in file order: every command in clock order (ties in the order written);
    # a stamp half a step early executes at the step whose clock reads the time
    lines += [_stamp(when - dt_s / 2) + c for when, _, c in sorted(timed)]
    return "\n".join(head + lines) + "\n"


def export_bluesky(path: str | Path, zone_m: tuple[float, float] | None = None, *, dt_s: float = DEFAULT_DT_S,
                   bank_deg: float = DEFAULT_BANK_DEG, trajectory: str = DEFAULT_TRAJECTORY) -> Path:
    """Write ``DIR/bluesky.scn`` for the schedule folder ``path``; returns the file's path.

    ``zone_m`` defaults to :func:`uamopt.export.zone.protected_zone` of the folder's cell and r.

    Raises
    ------
    InputFileError
        The folder or one of its files is missing or malformed.
    """
    from uamopt.export.zone import protected_zone

    folder = read_schedule_folder(path)
    if zone_m is None:
        zone = protected_zone(folder.flights.cell, folder.flights.conflict_radius)
        zone_m = (zone.rpz_m, zone.hpz_m)
    text = scenario_text(folder, zone_m, dt_s=dt_s, bank_deg=bank_deg, trajectory=trajectory)
    return write_texts(folder.path, {"bluesky.scn": text})[0]
