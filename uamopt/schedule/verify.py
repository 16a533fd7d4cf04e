"""The independent verifier behind ``uamopt verify DIR``.

It reads ``DIR/flights.json`` and ``DIR/schedule.csv`` (and ``DIR/summary.json`` when present)
and checks the schedule against the rules of docs/readings.md, sharing no code with the model: its own
file reading (json, csv), its own occupancy by a different algorithm (a 3-D digital differential
analyser that walks each segment cell by cell in plain Python, Amanatides & Woo 1987, instead of
the model's vectorised sort of all plane-crossing times) and its own conflict search (a hash of
(block of cells, time bucket) instead of the model's forbidden departure gaps).

Rules checked (tolerance ``TOL_S`` = 1e-6 s on every time, absolute at any magnitude of time plus
the float round-off of that magnitude, ``close_s``):

- each flight of flights.json appears once in schedule.csv with the same aircraft, route and
  planned departure; departure = planned + delay; arrival = departure + length / speed (Eq. 31);
  a flight with ``vertical_rate_mps`` r (the vertiport variant: take-off and landing phases) has a
  vertical climbing first and descending last segment, flown at r, and arrival = departure +
  climb_s + cruise_s + descent_s (climb_s = (z1 − z0) / r, descent_s = (z[-2] − z[-1]) / r,
  cruise_s = the middle segments' length / speed);
- 0 ≤ delay ≤ max_delay_s (Eq. 29), service start ≤ planned departure and departure (Eq. 23),
  arrival ≤ service end (Eq. 26); turnaround gaps are never negative;
- a return (even leg of its aircraft) is not operated without its outbound;
- an operated flight departs ≥ the previous operated flight's arrival + ΔT (Eqs. 27-28:
  the previous flight's own ``turnaround_after_s`` where flights.json gives one, else T_D after an
  odd leg, T_R after an even leg);
- no two operated flights of different aircraft occupy cells within ``conflict_radius`` in every
  axis during overlapping times of more than ``TOL_S`` (touching is not a conflict); the vertical
  phases count like any other segment, timed at the vertical rate;
- the extra families summary.json lists (``pads``, ``departure_spacing``, ...:
  uamopt/schedule/verify_variants.py);
- summary.json's counts (``flights`` and ``aircraft`` when it records them, operated, cancelled),
  delays and (when its weights are given) objective agree. A folder without flights (an empty
  flights list, a header-only schedule.csv) is trivially feasible when summary.json agrees (its
  average delay over G = 0 aircraft is 0); a summary that claims flights the files lack is a
  violation.

The folder is untrusted input: a field out of its range (a negative or non-integer conflict
radius, a cell that is not positive, waypoints that are not finite or lie outside the local
frame, a number beyond the float range (a JSON integer of 400 digits), JSON that Python cannot
read (an integer of more than 4300 digits), a short row of schedule.csv, a speed outside
0.1–200 m/s, a ``vertical_rate_mps`` outside (0, 50] m/s or without a vertical first and last
segment, times beyond 10⁷ s, a flight id twice, a conflict search beyond ``MAX_VISITS`` cells
(millimetre cells), a summary that is not an object or whose weights are not two finite
numbers, text that is not UTF-8) is an ``InputFileError`` (exit 2), never a pass; a waypoint
outside the grid ``extent_m`` that summary.json records is a violation (exit 1). Verify only
reads: a folder it refuses leaves nothing written.

Cell convention (shared by definition with the model, not by code): cell = floor(coordinate / Δ);
when a segment starts exactly on a plane and moves down that axis it is in the lower cell; a
segment lying in a plane is in the upper cell. Visits shorter than 1e-9 s are dropped.
"""

from __future__ import annotations

import csv
import itertools
import math
from collections import defaultdict
from pathlib import Path
from typing import Any

from uamopt.errors import InputFileError
from uamopt.schedule.verify_summary import TOL_S, check_summary, read_json, shown

TIE_S = 1e-9  # crossings closer than this are simultaneous, s
BUCKET_S = 30.0  # time bucket of the conflict hash, s
BLOCK = 3  # cells per axis in a block of the conflict hash (≥ r)
MAX_RADIUS = 10  # conflict zone of at most 21³ cells
SPEED_RANGE_MPS = (0.1, 200.0)  # ground speeds a flight file may claim, m/s
MAX_TIME_S = 1e7  # |planned departure| and delay bounds, s (about 116 days)
MAX_COORD_M = 1e6  # waypoint coordinates of the local frame, m (1,000 km)
VERTICAL_RATE_MPS = 50.0  # largest vertical_rate_mps a flight file may claim (exclusive lower bound 0), m/s
VERTICAL_XY_M = 1e-6  # a vertical segment's waypoints share x and y within this, m
MAX_VISITS = 10_000_000  # cell visits and time buckets the conflict search may hold (about 1 GB)
MAX_CONFLICTS = 10_000  # conflicting pairs listed; past it the search stops (the schedule is already infeasible)
ULP = 1e-14  # float round-off per unit of magnitude allowed on top of TOL_S (1e-7 s at 10⁷ s)


def close_s(a: float, b: float) -> bool:
    """Two times equal within ``TOL_S`` seconds *absolute* (plus the round-off of their magnitude):
    a relative tolerance would let a departure at 9·10⁶ s be 9 s early."""
    return math.isfinite(a) and math.isfinite(b) and abs(a - b) <= TOL_S + ULP * max(abs(a), abs(b))


COLUMNS = ["flight", "aircraft", "route", "operated", "planned_departure_s", "delay_s", "departure_s", "arrival_s"]


def _next_crossing(p0, d, dur: float, idx: list[int], step: list[int], cell, a: int) -> float:
    """Time since the segment start at which it leaves cell ``idx`` through a plane of axis ``a``."""
    if step[a] == 0:
        return math.inf
    plane = (idx[a] + 1) * cell[a] if step[a] > 0 else idx[a] * cell[a]
    return (plane - p0[a]) / d[a] * dur


def cell_visits(waypoints, speed_mps: float, cell,
                segment_speeds=None) -> list[tuple[tuple[int, int, int], float, float]]:
    """(cell, t_in, t_out) of every cell a track passes through from t = 0, at ``speed_mps`` or,
    when ``segment_speeds`` is given (one speed per segment, m/s), segment i at segment_speeds[i]
    (the vertiport variant: climb and descent at the vertical rate).

    Walks each segment cell by cell: per axis, the time of the next plane crossing; step the
    axis (or axes, on a tie) that crosses first.
    """
    n_segments = max(0, len(waypoints) - 1)
    speeds = [speed_mps] * n_segments if segment_speeds is None else list(segment_speeds)
    if len(speeds) != n_segments:
        raise ValueError(f"segment_speeds has {len(speeds)} speeds for {n_segments} segments")
    raw: list[tuple[tuple[int, int, int], float, float]] = []
    t = 0.0
    for (p0, p1), speed in zip(itertools.pairwise(waypoints), speeds, strict=True):
        d = [p1[a] - p0[a] for a in range(3)]
        length = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        if length == 0.0:
            continue
        dur = length / speed
        idx, step = [0, 0, 0], [0, 0, 0]
        for a in range(3):
            s = p0[a] / cell[a]
            if d[a] < 0:
                idx[a], step[a] = math.ceil(s) - 1, -1
            else:
                idx[a], step[a] = math.floor(s), (1 if d[a] > 0 else 0)

        nxt = [_next_crossing(p0, d, dur, idx, step, cell, a) for a in range(3)]
        u = 0.0
        while True:
            first = min(nxt)
            if first >= dur - TIE_S:
                raw.append(((idx[0], idx[1], idx[2]), t + u, t + dur))
                break
            raw.append(((idx[0], idx[1], idx[2]), t + u, t + first))
            for a in range(3):
                if nxt[a] <= first + TIE_S:
                    idx[a] += step[a]
                    nxt[a] = _next_crossing(p0, d, dur, idx, step, cell, a)
            u = first
        t += dur
    kept = [v for v in raw if v[2] - v[1] > TIE_S]
    visits: list[tuple[tuple[int, int, int], float, float]] = []
    for c, _, b in kept:
        start = visits[-1][2] if visits else 0.0
        if visits and visits[-1][0] == c:
            visits[-1] = (c, visits[-1][1], b)
        else:
            visits.append((c, start, b))
    return visits


def _number(value, what: str, where: str) -> float:
    try:
        out = float(value)
    except OverflowError:  # an integer beyond the float range (JSON allows 400 digits)
        out = math.inf
    except (TypeError, ValueError):
        raise InputFileError(f"{what} is not a number: {shown(value)}", where, "rewrite the file with uamopt schedule") from None
    if not math.isfinite(out):
        raise InputFileError(f"{what} is not finite: {shown(value)}", where, "rewrite the file with uamopt schedule")
    return out


def _coordinate(value) -> float:
    """A waypoint coordinate as a float; an integer beyond the float range (400 digits) is inf,
    which the finite check then refuses."""
    try:
        return float(value)
    except OverflowError:
        return math.inf


def _read_flights(path: Path) -> dict:
    if not path.is_file():
        raise InputFileError(f"missing {path.name}", str(path.parent), "give a folder written by uamopt schedule")
    raw = read_json(path)
    try:
        flights = raw["flights"]
        cell = [_number(c, "cell", str(path)) for c in raw["cell"]]
    except (KeyError, TypeError, ValueError):
        raise InputFileError("missing or malformed 'flights' or 'cell'", str(path),
                             "rewrite the file with uamopt schedule") from None
    if len(cell) != 3 or min(cell) <= 0 or not isinstance(flights, list):
        raise InputFileError(f"cell must be three positive sizes in metres and flights a list, got cell {shown(raw['cell'])}",
                             str(path), "rewrite the file with uamopt schedule")
    radius = raw.get("conflict_radius", 1)
    if isinstance(radius, bool) or not isinstance(radius, int) or not 0 <= radius <= MAX_RADIUS:
        raise InputFileError(f"conflict_radius must be an integer in [0, {MAX_RADIUS}], got {shown(radius)}", str(path),
                             "rewrite the file with uamopt schedule (the scenario's schedule.conflict_radius)")
    out: dict[str, Any] = {
        "cell": cell, "radius": radius, "flights": [],
        "service_start_s": _number(raw.get("service_start_s", 0.0), "service_start_s", str(path)),
        "service_end_s": _number(raw.get("service_end_s", 3600.0), "service_end_s", str(path)),
        "gaps": (_number(raw.get("outbound_gap_s", 240.0), "outbound_gap_s", str(path)),
                 _number(raw.get("return_gap_s", 360.0), "return_gap_s", str(path))),
    }
    if min(out["gaps"]) < 0 or abs(out["service_start_s"]) > MAX_TIME_S:
        raise InputFileError(f"outbound_gap_s and return_gap_s must be ≥ 0 (a negative turnaround puts one aircraft in "
                             f"two places at once) and service_start_s within ±{MAX_TIME_S:g} s, got gaps "
                             f"{list(out['gaps'])}, service_start_s {out['service_start_s']:g}", str(path),
                             "rewrite the file with uamopt schedule")
    seen: set[str] = set()
    for f in flights:
        where = f"{path}: flight {str(f.get('id'))[:40] if isinstance(f, dict) else '?'}"
        if not isinstance(f, dict) or "waypoints" not in f:
            raise InputFileError("flight without waypoints", where,
                                 "the verifier needs self-contained flights (uamopt schedule writes them)")
        try:
            wps = [tuple(_coordinate(v) for v in p) for p in f["waypoints"]]
            rec: dict[str, Any] = {
                "id": str(f["id"]), "aircraft": str(f["aircraft"]), "route": str(f["route"]),
                "speed": _number(f["speed_mps"], "speed_mps", where),
                "planned": _number(f["planned_departure_s"], "planned_departure_s", where),
                "max_delay": _number(f["max_delay_s"], "max_delay_s", where), "waypoints": wps,
            }
        except (KeyError, TypeError, ValueError) as exc:
            raise InputFileError(f"missing or malformed key {exc}", where, "rewrite the file with uamopt schedule") from None
        if len(wps) < 2 or any(len(p) != 3 for p in wps) or not all(math.isfinite(v) for p in wps for v in p):
            raise InputFileError("waypoints must be at least two finite [x, y, z] points", where,
                                 "rewrite the file with uamopt schedule")
        if not SPEED_RANGE_MPS[0] <= rec["speed"] <= SPEED_RANGE_MPS[1]:
            raise InputFileError(f"speed_mps {rec['speed']:g} outside the physical range "
                                 f"[{SPEED_RANGE_MPS[0]:g}, {SPEED_RANGE_MPS[1]:g}] m/s", where,
                                 "rewrite the file with uamopt schedule")
        if abs(rec["planned"]) > MAX_TIME_S or not 0 <= rec["max_delay"] <= MAX_TIME_S:
            raise InputFileError(f"planned_departure_s or max_delay_s beyond ±{MAX_TIME_S:g} s", where,
                                 "rewrite the file with uamopt schedule")
        if any(v < 0 for p in wps for v in p) or any(abs(v) > MAX_COORD_M for p in wps for v in p):
            raise InputFileError(f"waypoints outside the local frame [0, {MAX_COORD_M:g}] m (below the ground datum "
                                 "or west/south of the grid's origin)", where, "rewrite the file with uamopt schedule")
        if rec["id"] in seen:
            raise InputFileError(f"flight id {shown(rec['id'])} appears twice", where, "give every flight its own id")
        seen.add(rec["id"])
        rec["length"] = sum(math.dist(a, b) for a, b in itertools.pairwise(wps))
        rec["gap"] = None  # its own turnaround after it; None: the leg-parity default (outbound_gap_s / return_gap_s)
        if f.get("turnaround_after_s") is not None:
            rec["gap"] = _number(f["turnaround_after_s"], "turnaround_after_s", where)
            if not 0 <= rec["gap"] <= MAX_TIME_S:
                raise InputFileError(f"turnaround_after_s {rec['gap']:g} s outside [0, {MAX_TIME_S:g}] s (a negative "
                                     "turnaround puts one aircraft in two places at once)", where,
                                     "rewrite the file with uamopt schedule")
        rec["origin"] = None if f.get("origin") is None else str(f["origin"])
        rec["destination"] = None if f.get("destination") is None else str(f["destination"])
        _phases(rec, f.get("vertical_rate_mps"), where)
        out["flights"].append(rec)
    _check_work(out, str(path), path)
    return out


def _phases(rec: dict, rate, where: str) -> None:
    """Add the flight's phases to ``rec``: ``climb_s``, ``cruise_s``, ``descent_s``, ``duration``
    (s), ``cruise_length`` (m) and ``segment_speeds`` (m/s, one per segment). Without a vertical
    rate the whole track is cruise at ``speed_mps`` (duration = length / speed, as in Eq. 31)."""
    wps, n = rec["waypoints"], len(rec["waypoints"]) - 1
    if rate is None:
        rec.update(rate=None, climb_s=0.0, descent_s=0.0, cruise_length=rec["length"],
                   cruise_s=rec["length"] / rec["speed"], duration=rec["length"] / rec["speed"],
                   segment_speeds=[rec["speed"]] * n)
        return
    # the range first: it is exact on an integer of any size (math.isfinite would overflow) and refuses NaN and inf
    if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not 0 < rate <= VERTICAL_RATE_MPS:
        raise InputFileError(f"flight {rec['id']}: vertical_rate_mps must be a number in (0, {VERTICAL_RATE_MPS:g}] m/s, "
                             f"got {shown(rate)}", where, "rewrite the file with uamopt schedule")
    rate = float(rate)

    def vertical(a, b) -> bool:
        return abs(a[0] - b[0]) <= VERTICAL_XY_M and abs(a[1] - b[1]) <= VERTICAL_XY_M

    if len(wps) < 4 or not (vertical(wps[0], wps[1]) and wps[1][2] > wps[0][2]
                            and vertical(wps[-2], wps[-1]) and wps[-2][2] > wps[-1][2]):
        raise InputFileError(f"flight {rec['id']}: vertical_rate_mps needs a vertical first and last segment: "
                             "at least 4 waypoints, "
                             "ground -> top of climb (same x, y, higher z) ... top of descent -> ground (same x, y, "
                             f"lower z), got {len(wps)} waypoints", where, "rewrite the file with uamopt schedule")
    cruise_length = sum(math.dist(a, b) for a, b in itertools.pairwise(wps[1:-1]))
    climb_s, descent_s = (wps[1][2] - wps[0][2]) / rate, (wps[-2][2] - wps[-1][2]) / rate
    cruise_s = cruise_length / rec["speed"]
    rec.update(rate=rate, climb_s=climb_s, descent_s=descent_s, cruise_length=cruise_length, cruise_s=cruise_s,
               duration=climb_s + cruise_s + descent_s, segment_speeds=[rate] + [rec["speed"]] * (n - 2) + [rate])


def _check_work(spec: dict, where: str, path: Path | None = None) -> None:
    """Refuse a folder whose conflict search would walk more than ``MAX_VISITS`` cells and time
    buckets (millimetre cells or week-long crawls): bounded memory on hostile input."""
    cell, work = spec["cell"], 0.0
    for f in spec["flights"]:
        for a, b in itertools.pairwise(f["waypoints"]):
            work += 1 + sum(abs(b[k] - a[k]) / cell[k] for k in range(3))
        work += f["duration"] / BUCKET_S
    check_memory(*([path] if path is not None else []), visits=min(work, MAX_VISITS), where=where)
    if work > MAX_VISITS:
        raise InputFileError(f"the conflict search would visit about {work:.3g} cells and time buckets "
                             f"(cell {', '.join(f'{c:g}' for c in cell)} m), more than {MAX_VISITS:.0e}", where,
                             "rewrite the folder with uamopt schedule (cells in metres, as planned)")


def read_schedule_csv(path: Path) -> dict[str, dict]:
    """The rows of a ``schedule.csv`` by flight id, every field checked (``InputFileError`` on the
    first malformed one): ``operated`` (bool), ``planned``, ``delay``, and for an operated flight
    ``departure`` and ``arrival`` (s); ``line`` (its line in the file), ``duplicate`` (the id
    appears more than once; the first row is kept) and the raw ``row``. ``uamopt export`` reads
    folders with it too, so a file the verifier refuses is refused there the same way."""
    if not path.is_file():
        raise InputFileError(f"missing {path.name}", str(path.parent), "give a folder written by uamopt schedule")
    rows: dict[str, dict] = {}
    try:
        return _parse_schedule(path, rows)
    except UnicodeDecodeError:
        raise InputFileError("schedule.csv is not UTF-8 text", str(path), "save it as UTF-8 CSV") from None
    except (csv.Error, OSError) as exc:
        raise InputFileError(f"malformed CSV: {exc}", str(path), "rewrite it with uamopt schedule") from None


def _parse_schedule(path: Path, rows: dict[str, dict]) -> dict[str, dict]:
    with open(path, newline="", encoding="utf-8-sig") as fh:  # -sig: a spreadsheet's BOM is not a column name
        reader = csv.DictReader(fh)
        if reader.fieldnames is None or any(c not in reader.fieldnames for c in COLUMNS):
            raise InputFileError(f"schedule.csv needs the columns {','.join(COLUMNS)}", str(path),
                                 "rewrite it with uamopt schedule")
        for n, row in enumerate(reader, start=2):
            where = f"{path}: line {n}"
            if any(row.get(c) is None for c in COLUMNS[:5]):  # a short row: DictReader fills the missing fields with None
                raise InputFileError(f"line {n} has fewer fields than the header's {len(reader.fieldnames)} columns", where,
                                     "rewrite it with uamopt schedule")
            flag = row["operated"].strip().lower()
            if flag not in ("1", "0", "true", "false"):
                raise InputFileError(f"operated must be 1 or 0, got {shown(row['operated'])}", where,
                                     "rewrite it with uamopt schedule")
            on = flag in ("1", "true")
            rec = {"row": row, "line": n, "operated": on, "duplicate": row["flight"] in rows,
                   "planned": _number(row["planned_departure_s"], "planned_departure_s", where),
                   "delay": _number(row["delay_s"] or 0.0, "delay_s", where)}
            if on:
                rec["departure"] = _number(row["departure_s"], "departure_s", where)
                rec["arrival"] = _number(row["arrival_s"], "arrival_s", where)
            rows.setdefault(row["flight"], rec)
            if rec["duplicate"]:
                rows[row["flight"]]["duplicate"] = True
    return rows


def _conflicts(flights: list[dict], cell, radius: int) -> list[str]:
    """Conflicts among the given (operated) flights, via a hash of (block of cells, time bucket).

    A block is ``BLOCK`` cells per axis (≥ r), so cells within r of each other lie in the same or
    adjacent blocks; each unordered pair of neighbouring keys is visited once (half the offsets),
    and every candidate pair of visits is tested exactly: Chebyshev distance of the cells ≤ r
    and an overlap in time longer than ``TOL_S``. The search stops at ``MAX_CONFLICTS`` pairs, and
    says so: 8,000 flights through one cell at once are 32 million pairs, each a conflict, which
    took the search past 3 GB and minutes to list; one is enough for the verdict.
    """
    block = max(1, radius, BLOCK)
    cache: dict = {}
    table: dict[tuple, list] = defaultdict(list)
    for n, f in enumerate(flights):
        key = (tuple(f["waypoints"]), tuple(f["segment_speeds"]))
        if key not in cache:
            cache[key] = cell_visits(f["waypoints"], f["speed"], cell, f["segment_speeds"])
        for c, a, b in cache[key]:
            a, b = f["departure"] + a, f["departure"] + b
            home = (c[0] // block, c[1] // block, c[2] // block)
            for bucket in range(math.floor(a / BUCKET_S), math.floor(b / BUCKET_S) + 1):
                table[(*home, bucket)].append((n, a, b, c))
    reach = 1 if radius > 0 else 0
    offsets = [o for o in itertools.product(range(-reach, reach + 1), repeat=3) if o > (0, 0, 0)]
    worst: dict[tuple[int, int], tuple] = {}

    def compare(entries, others, same_key):
        for n1, a1, b1, c1 in entries:
            for n2, a2, b2, c2 in others:
                if n1 == n2 or (same_key and n1 > n2):
                    continue
                overlap = min(b1, b2) - max(a1, a2)
                if overlap <= TOL_S or flights[n1]["aircraft"] == flights[n2]["aircraft"]:
                    continue
                if max(abs(c1[0] - c2[0]), abs(c1[1] - c2[1]), abs(c1[2] - c2[2])) > radius:
                    continue
                pair, info = ((n1, n2), (overlap, c1, c2)) if n1 < n2 else ((n2, n1), (overlap, c2, c1))
                if overlap > worst.get(pair, (0.0,))[0]:
                    worst[pair] = (*info, max(a1, a2), min(b1, b2))
                    if len(worst) >= MAX_CONFLICTS:
                        raise _Enough

    stopped = False
    try:
        for (i, j, k, bucket), entries in table.items():
            compare(entries, entries, True)
            for o in offsets:
                others = table.get((i + o[0], j + o[1], k + o[2], bucket))
                if others:
                    compare(entries, others, False)
    except _Enough:
        stopped = True
    out = []
    for (n1, n2), (_, c1, c2, a, b) in sorted(worst.items()):
        f1, f2 = flights[n1], flights[n2]
        out.append(f"conflict: flights {f1['id']} ({f1['aircraft']}) in cell {c1} and {f2['id']} ({f2['aircraft']}) "
                   f"in cell {c2} overlap from {a:.3f} s to {b:.3f} s")
    if stopped:
        out.append(f"conflict: the search stopped at {MAX_CONFLICTS:,} conflicting pairs (more may exist; the first "
                   "found are listed, each with its overlap when found)")
    return out


class _Enough(Exception):
    """MAX_CONFLICTS conflicting pairs found: the conflict search stops."""


#: peak bytes of the verifier per byte of its input files: flights.json parsed into Python objects
#: (measured 2.7 on a 600-flight file of the paper city), schedule.csv's rows the same; with a margin
BYTES_PER_INPUT_BYTE = 4.0
BYTES_PER_VISIT = 100  # the conflict search's hash, per cell visit and time bucket (MAX_VISITS: about 1 GB)


def check_memory(*paths: Path, visits: float = 0.0, where: str = "uamopt verify") -> None:
    """Refuse a folder whose verification would need more memory than this machine can give (80 %
    of it, within ``ulimit -v``): one line with the estimate and the limit. Called before anything
    is read (the files' sizes), and again with the conflict search's ``visits`` once they are known."""
    from uamopt.grid.grid import gigabytes, memory_limit_bytes

    size = sum(p.stat().st_size for p in paths if p.is_file())
    need, limit = int(BYTES_PER_INPUT_BYTE * size + BYTES_PER_VISIT * visits), memory_limit_bytes(None)
    if need > limit:
        raise InputFileError(f"verifying {gigabytes(size)} GB of flights.json and schedule.csv needs about "
                             f"{gigabytes(need)} GB, more than the limit of {gigabytes(limit)} GB", where,
                             "verify on a machine with more memory, or split the plan into smaller folders")


def verify_files(flights_path: Path, schedule_path: Path, summary_path: Path | None = None) -> list[str]:
    """Violations of the schedule in ``schedule_path`` for the flights of ``flights_path``."""
    check_memory(flights_path, schedule_path, where=str(flights_path.parent))
    spec = _read_flights(flights_path)
    rows = read_schedule_csv(schedule_path)
    out: list[str] = []
    ids = {f["id"] for f in spec["flights"]}
    out += [f"flight {fid}: in schedule.csv but not in flights.json" for fid in rows if fid not in ids]
    flown: list[dict] = []
    by_aircraft: dict[str, list[dict]] = defaultdict(list)
    for f in spec["flights"]:
        by_aircraft[f["aircraft"]].append(f)
        row = rows.get(f["id"])
        if row is None:
            out.append(f"flight {f['id']}: missing from schedule.csv")
            f["operated"] = False
            continue
        if row["duplicate"]:
            out.append(f"flight {f['id']}: listed more than once in schedule.csv")
        if row["row"]["aircraft"] != f["aircraft"] or row["row"]["route"] != f["route"]:
            out.append(f"flight {f['id']}: aircraft/route in schedule.csv differ from flights.json")
        if f["planned"] < spec["service_start_s"] - TOL_S:
            out.append(f"flight {f['id']}: planned departure {f['planned']:g} s before the service start "
                       f"{spec['service_start_s']:g} s (Eq. 23)")
        if not close_s(row["planned"], f["planned"]):
            out.append(f"flight {f['id']}: planned departure {row['planned']} differs from flights.json's {f['planned']}")
        f["operated"] = row["operated"]
        if not row["operated"]:
            continue
        d = f["delay"] = row["delay"]
        f["departure"], f["arrival"] = row["departure"], row["arrival"]
        if d < -TOL_S or d > f["max_delay"] + TOL_S:
            out.append(f"flight {f['id']}: delay {d:g} s outside [0, {f['max_delay']:g}] s (Eq. 29)")
        if f["departure"] < spec["service_start_s"] - TOL_S:
            out.append(f"flight {f['id']}: departs at {f['departure']:.3f} s, before the service start "
                       f"{spec['service_start_s']:g} s (Eq. 23)")
        if not close_s(f["departure"], f["planned"] + d):
            out.append(f"flight {f['id']}: departure {f['departure']} s ≠ planned {f['planned']} + delay {d} s")
        if f["rate"] is None and not close_s(f["arrival"], f["departure"] + f["duration"]):
            out.append(f"flight {f['id']}: arrival {f['arrival']} s ≠ departure + track length / speed "
                       f"= {f['departure'] + f['duration']:.6f} s")
        elif f["rate"] is not None and not close_s(f["arrival"], f["departure"] + f["duration"]):
            out.append(f"flight {f['id']}: arrival {f['arrival']} s ≠ departure + climb {f['climb_s']:.6f} s + cruise "
                       f"{f['cruise_s']:.6f} s + descent {f['descent_s']:.6f} s = {f['departure'] + f['duration']:.6f} s")
        if f["arrival"] > spec["service_end_s"] + TOL_S:
            out.append(f"flight {f['id']}: arrives at {f['arrival']:.3f} s, after the service end "
                       f"{spec['service_end_s']:g} s (Eq. 26)")
        flown.append(f)
    t_out, t_back = spec["gaps"]
    for chain in by_aircraft.values():
        chain = sorted(chain, key=lambda f: f["planned"])  # stable: file order on ties
        last = None
        for leg, f in enumerate(chain, start=1):
            # its turnaround ΔT (Eqs. 27-28; pads): its own where the file gives one, else by leg parity
            f["gap_after_s"] = f["gap"] if f["gap"] is not None else (t_out if leg % 2 == 1 else t_back)
            if leg % 2 == 0 and f["operated"] and not chain[leg - 2]["operated"]:
                out.append(f"flight {f['id']}: return operated without its outbound {chain[leg - 2]['id']}")
            if not f["operated"]:
                continue
            if last is not None:
                prev, _ = last
                gap = prev["gap_after_s"]
                if f["departure"] < prev["arrival"] + gap - TOL_S:
                    out.append(f"flight {f['id']}: departs at {f['departure']:.3f} s, less than {gap:g} s after "
                               f"{prev['id']} arrives at {prev['arrival']:.3f} s (Eqs. 27-28)")
            last = (f, leg)
    out += _conflicts(flown, spec["cell"], spec["radius"])
    if summary_path is not None and summary_path.is_file():
        out += check_summary(summary_path, spec, flown, len(by_aircraft))
    return out


def verify_dir(path: str | Path) -> list[str]:
    """Check ``path``/schedule.csv against ``path``/flights.json (and summary.json if present).

    Returns the violations, one line each; empty means feasible and conflict-free.

    Raises
    ------
    InputFileError
        The folder or a file is missing or malformed.
    """
    folder = Path(path)
    if not folder.is_dir():
        raise InputFileError(f"not a folder: {folder}", "uamopt verify", "give the --out folder of uamopt schedule")
    return verify_files(folder / "flights.json", folder / "schedule.csv", folder / "summary.json")
