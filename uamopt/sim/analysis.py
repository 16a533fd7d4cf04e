"""What the replay measures from BlueSky's recorded traffic, against our plan.

Everything is in the local frame (metres): BlueSky's latitudes and longitudes go back through the
folder's :class:`~uamopt.export.frame.LocalFrame`, its altitudes are z. The plan of a flight at
time t is the point its track reaches at distance v_g·(t − departure) (constant speed, Eq. 31);
with vertical phases (the vertiport variant) the first and last segments at the flight's vertical
rate (:func:`uamopt.schedule.flights.waypoint_times_s`).
"""

from __future__ import annotations

import itertools

import numpy as np


def planned_positions(waypoints: np.ndarray, speed_mps: float, departure_s: float, t: np.ndarray,
                      vertical_rate_mps: float | None = None) -> np.ndarray:
    """Planned positions (n, 3) at times ``t``: each waypoint at its planned time from the departure
    (v_g; the vertical phases at ``vertical_rate_mps``), linear in time between, clipped to the track."""
    from uamopt.schedule.flights import waypoint_times_s

    times = departure_s + waypoint_times_s(waypoints, speed_mps, vertical_rate_mps)
    tt = np.clip(np.asarray(t, float), times[0], times[-1])
    return np.column_stack([np.interp(tt, times, waypoints[:, a]) for a in range(3)])


def distance_to_track(points: np.ndarray, waypoints: np.ndarray, chunk: int = 4096) -> np.ndarray:
    """Shortest 3-D distance from each point (n, 3) to the polyline ``waypoints`` (m, 3), m."""
    a, ab = waypoints[:-1], np.diff(waypoints, axis=0)
    ab2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-12)
    out = np.empty(len(points))
    for lo in range(0, len(points), chunk):
        p = points[lo:lo + chunk, None, :] - a[None, :, :]
        u = np.clip(np.einsum("nmj,mj->nm", p, ab) / ab2, 0.0, 1.0)
        out[lo:lo + chunk] = np.linalg.norm(p - u[..., None] * ab[None], axis=2).min(axis=1)
    return out


def flight_deviation(operated, t: np.ndarray, xyz: np.ndarray) -> dict:
    """Deviations of one flown flight from its plan.

    ``t`` (n,) and ``xyz`` (n, 3): the recorded samples of its aircraft. The flown arrival is the
    last sample's time plus its remaining distance to the last waypoint (along the last leg) / v_g
    (/ the vertical rate for a vertical landing).
    """
    f = operated.flight
    wp = np.asarray(f.waypoints, float)
    rate = f.vertical_rate_mps
    plan = planned_positions(wp, f.speed_mps, operated.departure_s, t, rate)
    err_h = np.linalg.norm((xyz - plan)[:, :2], axis=1)
    err_v = np.abs(xyz[:, 2] - plan[:, 2])
    leg = wp[-1] - wp[-2]
    remaining = float(np.dot(wp[-1] - xyz[-1], leg) / np.linalg.norm(leg))
    arrival = float(t[-1]) + remaining / (f.speed_mps if rate is None else rate)
    k = int(np.argmax(err_h))
    return {
        "flight": f.id, "aircraft": f.aircraft, "route": f.route, "departure_s": operated.departure_s,
        "arrival_s": operated.arrival_s, "flown_arrival_s": arrival, "arrival_deviation_s": arrival - operated.arrival_s,
        "max_cross_track_m": float(distance_to_track(xyz, wp).max()),
        "max_horizontal_error_m": float(err_h[k]), "max_horizontal_error_at_s": float(t[k]),
        "max_vertical_error_m": float(err_v.max()), "samples": len(t),
    }


def pair_separations(tracks: dict[str, tuple[np.ndarray, np.ndarray]], aircraft: dict[str, str], zone,
                     step_allowance_m: float) -> list[dict]:
    """Closest approaches of the pairs of flights that come near each other.

    ``tracks``: flight id -> (step numbers (n,), positions (n, 3)) on the common clock. A pair is
    reported when at some common step it is inside the near box of ``zone`` widened by
    ``step_allowance_m`` (the relative motion of one step), or inside the LoS cylinder. Flights of
    the same aircraft are never airborne together and are skipped. Per pair: the closest approach
    by the normalised distance max(h / r_pz, |Δz| / h_pz) (< 1 is a LoS by our measure) and the
    smallest horizontal distance, each with its time and the other component.
    """
    near = np.asarray(zone.near_m) + step_allowance_m
    spans = {fid: (int(steps[0]), int(steps[-1])) for fid, (steps, _) in tracks.items()}
    out = []
    for a, b in itertools.combinations(sorted(tracks, key=lambda f: spans[f][0]), 2):
        lo, hi = max(spans[a][0], spans[b][0]), min(spans[a][1], spans[b][1])
        if lo > hi or aircraft[a] == aircraft[b]:
            continue
        (sa, pa), (sb, pb) = tracks[a], tracks[b]
        common, ia, ib = np.intersect1d(sa, sb, assume_unique=True, return_indices=True)
        if not len(common):
            continue
        d = pb[ib] - pa[ia]
        horizontal, vertical = np.hypot(d[:, 0], d[:, 1]), np.abs(d[:, 2])
        inside_near = np.all(np.abs(d) < near, axis=1)
        normalised = np.maximum(horizontal / zone.rpz_m, vertical / zone.hpz_m)
        if not inside_near.any() and normalised.min() >= 1.0:
            continue
        k, h = int(np.argmin(normalised)), int(np.argmin(horizontal))
        out.append({
            "flights": [a, b], "near_steps": int(inside_near.sum()),
            "closest_step": int(common[k]), "closest_horizontal_m": float(horizontal[k]),
            "closest_vertical_m": float(vertical[k]),
            "closest_normalised": float(normalised[k]), "los_steps": int((normalised < 1.0).sum()),
            "min_horizontal_step": int(common[h]), "min_horizontal_m": float(horizontal[h]),
            "vertical_at_min_horizontal_m": float(vertical[h]),
        })
    return out
