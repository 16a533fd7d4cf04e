"""The independent verifier's checks of families beyond the paper's (uamopt/schedule/verify.py).

``summary.json`` lists each extra family with what is needed to check it (``"families"``:
``[{"name", "shape", ...}]``). The checks here read the files and those records only, with
their own parsing and arithmetic; they share no code with ``uamopt.schedule.families``. A family
the verifier does not know is a violation ("cannot be checked"), never a pass.

- ``separation`` with ``airland_file`` (OR-Library aircraft landing, Beasley et al. 2000): the
  file is read again here (its own parser; its SHA-256 must match the record), and every aircraft
  must land (be operated) at x_i = its departure in [E_i, L_i], every pair i ≠ j must keep
  x_j ≥ x_i + S_ij or x_i ≥ x_j + S_ji, and summary.json's objective must equal
  Σ g_i (T_i − x_i)⁺ + h_i (x_i − T_i)⁺.
- ``speed_choice`` with ``factors``, ``cruise_speed_mps`` and ``change_cost_s``: each operated
  flight's speed in flights.json is an allowed factor of its cruise speed (its arrival then follows
  from the times, checked by verify.py), and summary.json's objective, with the change costs, is
  recomputed (lexicographic: the delay weight over every speed of every flight).
- ``departure_spacing`` with ``spacing_s``: operated flights that start at one point (the first
  waypoint of flights.json: one vertiport) depart at least ``spacing_s`` apart.
- ``pads`` (shape ``cumulative``) with ``pads`` {vertiport: capacity, an integer ≥ 1, or null for a
  vertiport without a limit, which is not checked}: an operated
  flight holds one pad of its ``origin`` (flights.json) during [departure, departure + climb_s)
  and one of its ``destination`` during [arrival − descent_s, arrival + ΔT), ΔT its turnaround gap
  (outbound_gap_s after an odd leg of its aircraft, return_gap_s after an even leg); climb_s and
  descent_s are 0 without ``vertical_rate_mps`` (verify.py). Intervals are half-open and may
  overlap by ``TOL_S``; at no instant may a vertiport hold more pads than its capacity (one
  violation per period over capacity). A vertiport a flight names but the record omits, or a
  flight without an origin or destination name, is a violation (it cannot be checked).
"""

from __future__ import annotations

import hashlib
import itertools
import math
from pathlib import Path

from uamopt.errors import InputFileError
from uamopt.schedule.verify_summary import TOL_S, finite, shown

TOL = 1e-6  # on landing times and the objective (relative above 1)
MAX_AIRLAND_BYTES = 64 * 2 ** 20  # the largest OR-Library airland file is about 2 MB


def _objective_off(got, expect: float) -> bool:
    """summary.json's objective ``got`` is not ``expect`` within ``TOL`` (relative above 1); a value
    that is not a finite number (NaN, inf, a 400-digit integer, a string) is always off."""
    return not finite(got) or not math.isfinite(expect) or abs(float(got) - expect) > TOL * max(1.0, abs(expect))


def _airland(path: Path, digest: str | None, where: str) -> tuple[list[list[float]], list[list[float]]]:
    """(per aircraft [appearance, E, T, L, g, h], separation rows) of an airland file."""
    try:
        if not path.is_file() or path.stat().st_size > MAX_AIRLAND_BYTES:  # /dev/zero or a FIFO would be read forever
            raise InputFileError(f"the instance file {path} is not a regular file of at most {MAX_AIRLAND_BYTES // 2 ** 20} MB",
                                 where, "give the OR-Library airland file the schedule was made from")
        data = path.read_bytes()
    except OSError as exc:
        raise InputFileError(f"cannot read the instance file {path}: {exc.strerror or exc}", where,
                             "keep the airland file where the schedule was made, or solve it again") from None
    if digest is not None and hashlib.sha256(data).hexdigest() != digest:
        raise InputFileError(f"the instance file {path} changed since the schedule was written", where,
                             "solve the instance again")
    try:
        numbers = [float(x) for x in data.decode("utf-8").split()]
    except (UnicodeDecodeError, ValueError):
        raise InputFileError(f"the instance file {path} is not an airland file", where, "give the OR-Library file") from None
    # every number finite (int() of inf or NaN raises; a NaN window would pass every comparison) and a whole count
    count = int(numbers[0]) if numbers and all(math.isfinite(x) for x in numbers) and numbers[0] == int(numbers[0]) else 0
    if count < 1 or len(numbers) != 2 + count * (6 + count):
        raise InputFileError(f"the instance file {path} is not an airland file", where, "give the OR-Library file")
    head, sep, at = [], [], 2
    for _ in range(count):
        head.append(numbers[at:at + 6])
        sep.append(numbers[at + 6:at + 6 + count])
        at += 6 + count
    return head, sep


def _check_airland(record: dict, summary: dict, landing: dict[str, float | None], where: str) -> list[str]:
    head, sep = _airland(Path(str(record.get("airland_file"))), record.get("sha256"), where)
    out = []
    times = []
    for i, (_, earliest, _, latest, _, _) in enumerate(head):
        x = landing.get(f"a{i + 1}")
        if x is None:
            out.append(f"aircraft a{i + 1}: does not land (every aircraft of the landing problem must)")
        elif x < earliest - TOL or x > latest + TOL:
            out.append(f"aircraft a{i + 1}: lands at {x:g}, outside its window [{earliest:g}, {latest:g}]")
        times.append(x)
    for i in range(len(head)):
        for j in range(i + 1, len(head)):
            t_i, t_j = times[i], times[j]
            if t_i is None or t_j is None:
                continue
            if not (t_j >= t_i + sep[i][j] - TOL or t_i >= t_j + sep[j][i] - TOL):
                out.append(f"aircraft a{i + 1} and a{j + 1}: land at {t_i:g} and {t_j:g}, closer than "
                           f"their separation ({sep[i][j]:g} after a{i + 1}, {sep[j][i]:g} after a{j + 1})")
    landed = [x for x in times if x is not None]
    if len(landed) == len(times) and summary.get("objective") is not None:
        cost = sum(g * max(0.0, t - x) + h * max(0.0, x - t) for (_, _, t, _, g, h), x in zip(head, landed, strict=True))
        got = summary["objective"]
        if _objective_off(got, cost):
            out.append(f"summary.json: objective = {shown(got)}, the landing times cost {cost:.6g} (earliness/tardiness)")
    return out


def _check_spacing(record: dict, flown: list[dict], where: str) -> list[str]:
    """Operated flights from one vertiport — one first waypoint (x, y), to the millimetre — depart
    at least ``spacing_s`` apart (sorted by departure, so neighbours suffice)."""
    spacing = record.get("spacing_s")
    if isinstance(spacing, bool) or not isinstance(spacing, (int, float)) or not 0 <= spacing < 1e7:
        raise InputFileError(f"departure_spacing: spacing_s must be a number of seconds ≥ 0, got {spacing!r}", where,
                             "rewrite it with uamopt schedule")
    out: list[str] = []
    by_origin: dict[tuple[float, ...], list[dict]] = {}
    for f in flown:
        by_origin.setdefault(tuple(round(v, 3) for v in f["waypoints"][0][:2]), []).append(f)
    for origin, group in sorted(by_origin.items()):
        group.sort(key=lambda f: f["departure"])
        for a, b in itertools.pairwise(group):
            if b["departure"] - a["departure"] < spacing - TOL:
                out.append(f"flights {a['id']} and {b['id']}: leave ({origin[0]:g}, {origin[1]:g}) "
                           f"{b['departure'] - a['departure']:.3f} s apart, "
                           f"less than the departure spacing {spacing:g} s")
    return out


def _slack_s(t: float) -> float:
    """The overlap two pad holds may share at time ``t``: ``TOL_S`` plus the float round-off of
    that magnitude (as verify.close_s: absolute at any magnitude of time)."""
    return TOL_S + 1e-14 * abs(t)


def _check_pads(record: dict, flown: list[dict], where: str) -> list[str]:
    """Pads held at each vertiport never exceed its capacity (module docstring): a sweep over the
    holds' start and end times, ends first on a tie (half-open), each end moved ``_slack_s``
    earlier so that holds overlapping by at most ``TOL_S`` do not count together."""
    pads = record.get("pads")
    if not isinstance(pads, dict) or not all(
            c is None or (isinstance(c, int) and not isinstance(c, bool) and c >= 1) for c in pads.values()):
        raise InputFileError(f"pads: 'pads' must be an object of vertiport name -> capacity (an integer ≥ 1, or null "
                             f"for unlimited), got {pads!r}",
                             where, "rewrite it with uamopt schedule")
    out: list[str] = []
    holds: dict[str, list[tuple[float, float, str]]] = {}
    unnamed: list[str] = []
    for f in flown:
        if f.get("origin") is None or f.get("destination") is None:
            unnamed.append(f["id"])
            continue
        take_off = (f["departure"], f["departure"] + f["climb_s"])
        landing = (f["arrival"] - f["descent_s"], f["arrival"] + f["gap_after_s"])
        for port, (a, b) in ((f["origin"], take_off), (f["destination"], landing)):
            holds.setdefault(port, [])
            if b > a:
                holds[port].append((a, b, f["id"]))
    if unnamed:
        out.append(f"pads: flights {', '.join(unnamed)} have no origin or destination vertiport in flights.json, "
                   "their pads cannot be checked")
    for port in sorted(holds):
        if port not in pads:
            users = sorted({fid for _, _, fid in holds[port]})
            out.append(f"pads: vertiport {port} has no pad capacity in the pads record"
                       + (f" (flights {', '.join(users)} hold a pad there)" if users else ""))
            continue
        cap = pads[port]
        if cap is None:  # unlimited
            continue
        events = []  # (time, 0 = end / 1 = start, hold number)
        for n, (a, b, _) in enumerate(holds[port]):
            events.append((a, 1, n))
            events.append((b - _slack_s(b), 0, n))
        events.sort()
        active: set[int] = set()
        breach = None  # (start time, peak count, flights involved)
        for t, kind, n in events:
            if kind == 0:
                active.discard(n)
                if breach is not None and len(active) <= cap:
                    out.append(f"pads: vertiport {port} holds {breach[1]} pads at {breach[0]:.3f} s, more than its "
                               f"capacity {cap} (flights {', '.join(sorted(breach[2]))})")
                    breach = None
                continue
            active.add(n)
            if len(active) > cap:
                ids = {holds[port][m][2] for m in active}
                breach = (t, len(active), ids) if breach is None else (breach[0], max(breach[1], len(active)), breach[2] | ids)
    return out


def _check_speeds(record: dict, summary: dict, spec: dict, flown: list[dict], where: str) -> list[str]:
    """Each operated flight's speed (flights.json) is an allowed factor of its cruise speed, and the
    objective with the change costs (weights, or the lexicographic weight over every speed copy)."""
    factors, cruise, cost = record.get("factors"), record.get("cruise_speed_mps"), record.get("change_cost_s", 0.0)
    if not (isinstance(factors, list) and factors and all(finite(k) and 0 < k <= 1 for k in factors)
            and isinstance(cruise, dict) and all(finite(v) for v in cruise.values()) and finite(cost) and cost >= 0):
        raise InputFileError("speed_choice: factors, cruise_speed_mps or change_cost_s malformed (finite numbers: "
                             "factors in (0, 1], cruise speeds in m/s, a change cost ≥ 0 s)", where,
                             "rewrite it with uamopt schedule")
    out, changed = [], 0
    for f in flown:
        v = cruise.get(f["id"])
        if not finite(v) or v <= 0:
            raise InputFileError(f"speed_choice: no cruise speed for flight {f['id']}", where, "rewrite it with uamopt schedule")
        match = [k for k in factors if abs(f["speed"] - k * v) <= 1e-9 * max(1.0, v)]
        if not match:
            out.append(f"flight {f['id']}: flies at {f['speed']:g} m/s, not one of {factors} × its cruise speed {v:g} m/s")
        elif match[0] != 1.0:
            changed += 1
    total = sum(f["delay"] for f in flown) + changed * float(cost)
    kind = summary.get("objective_kind", "weighted")
    if summary.get("objective") is None:
        return out
    if kind == "weighted":
        from uamopt.schedule.verify_summary import read_weights

        w6, w7 = read_weights(summary.get("weights"), where)
        n_aircraft = len({f["aircraft"] for f in spec["flights"]})
        expect = (w6 * total / n_aircraft if n_aircraft else 0.0) - w7 * len(flown)  # no aircraft: no delay
    else:
        upper = 0.0
        for f in spec["flights"]:
            v = cruise.get(f["id"], f["speed"])
            for k in factors:
                duration = f["climb_s"] + f["cruise_length"] / (k * v) + f["descent_s"]  # length / (k v) without phases
                upper += max(0.0, min(f["max_delay"], spec["service_end_s"] - f["planned"] - duration))
                upper += float(cost) if k != 1.0 else 0.0
        expect = -len(flown) + total / (upper + 1.0)
    got = summary["objective"]
    if _objective_off(got, expect):
        out.append(f"summary.json: objective = {shown(got)}, the schedule at its speeds gives {expect:.6g}")
    return out


def check_families(summary: dict, spec: dict, flown: list[dict], where: str) -> list[str]:
    """Violations of the extra families that ``summary`` lists (module docstring); ``spec``: the
    verifier's reading of flights.json, ``flown``: its operated flights (with ``departure``)."""
    all_ids = [f["id"] for f in spec["flights"]]
    records = summary.get("families", [])
    if not isinstance(records, list) or not all(isinstance(r, dict) for r in records):
        raise InputFileError("'families' is not a list of objects", where, "rewrite it with uamopt schedule")
    departure = {f["id"]: f["departure"] for f in flown}
    landing = {fid: departure.get(fid) for fid in all_ids}
    out, objective_checked = [], False
    for record in records:
        if record.get("name") == "separation" and "airland_file" in record:
            out += _check_airland(record, summary, landing, where)
            objective_checked = True
        elif record.get("name") == "departure_spacing":
            out += _check_spacing(record, flown, where)
        elif record.get("name") == "pads":
            out += _check_pads(record, flown, where)
        elif record.get("name") == "speed_choice":
            out += _check_speeds(record, summary, spec, flown, where)
            objective_checked = True
        else:
            out.append(f"summary.json: family {record.get('name')!r} cannot be checked by this verifier")
    if summary.get("objective_kind") == "earliness_tardiness" and not objective_checked and summary.get("objective") is not None:
        out.append("summary.json: an earliness_tardiness objective cannot be checked without its instance file")
    return out


def objective_checked_here(summary: dict) -> bool:
    """Whether this module checks summary.json's objective (then the generic check does not)."""
    records = summary.get("families", [])
    return summary.get("objective_kind") == "earliness_tardiness" or (
        isinstance(records, list) and any(isinstance(r, dict) and r.get("name") == "speed_choice" for r in records))

