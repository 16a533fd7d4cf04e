"""summary.json checks of the independent verifier (uamopt/schedule/verify.py): counts (flights and
aircraft when recorded, operated, cancelled), delays and the objective recomputed from the schedule
(Eqs. 20-22; G = 0 aircraft, an empty schedule, has average delay 0; an objective that cannot be
recomputed as a finite number is a violation, never a pass), the recorded grid extent (by
:func:`uamopt.bounds.outside_grid`, the readers' rule), and the summary's own fields (an object, two
finite weights in the range of ``schedule.weights``), since the folder is untrusted input: a number
is a JSON number (not a bool) finite as a float (``finite``: a 400-digit integer is not)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TypeGuard

from uamopt.bounds import MAX_WEIGHT, outside_grid
from uamopt.errors import InputFileError

TOL_S = 1e-6  # tolerance on every time and total, s (relative above 1)
#: each status word and the (termination, proved_for) it stands for (docs/interfaces.md, *Statuses*),
#: written out here, not imported: the verifier shares nothing with the code that wrote the files
STATUS_WORDS = {"optimal": ("optimal", "continuous"), "optimal_on_grid": ("optimal", "restricted"),
                "infeasible": ("infeasible", "continuous"),
                "time_limit": ("time_limit", "none"), "feasible": ("stopped", "none"),
                "no_solution": ("no_solution", "none")}
NO_SCHEDULE = ("infeasible", "no_solution")  # statuses that carry no schedule


def shown(value, limit: int = 40) -> str:
    """``repr(value)`` cut to ``limit`` characters (a 400-digit number in an error line)."""
    text = repr(value)
    return text if len(text) <= limit else f"{text[:limit]}… ({len(text)} characters)"


def read_json(path: Path, fix: str = "rewrite the file with uamopt schedule"):
    """The JSON document in ``path``; a file that is not UTF-8, not JSON, nested too deeply or holds an
    integer of more than 4300 digits (Python's limit, a ``ValueError``) is an ``InputFileError``."""
    try:
        return json.loads(path.read_text(encoding="utf-8-sig"))
    except (ValueError, UnicodeDecodeError, RecursionError, OSError) as exc:  # JSONDecodeError is a ValueError
        raise InputFileError(f"malformed JSON: {' '.join(str(exc).split())}", str(path), fix) from None


def finite(value) -> TypeGuard[float]:
    """A JSON number (not a bool) that is finite as a float: NaN, inf and an integer beyond the
    float range (JSON allows 400 digits; ``math.isfinite`` would overflow) are not."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def close(a: float, b: float) -> bool:
    """Equal within ``TOL_S`` relative; an infinite or NaN value is never close (inf ≤ inf would be)."""
    return math.isfinite(a) and math.isfinite(b) and abs(a - b) <= TOL_S * max(1.0, abs(a), abs(b))


def check_summary(path: Path, spec: dict, flown: list[dict], n_aircraft: int) -> list[str]:
    """Violations of summary.json against the schedule: ``spec`` is the verifier's reading of
    flights.json, ``flown`` its operated flights, ``n_aircraft`` G (Eq. 21)."""
    summary = read_json(path, "rewrite it with uamopt schedule")
    if not isinstance(summary, dict):
        raise InputFileError("summary.json does not hold a JSON object", str(path), "rewrite it with uamopt schedule")
    out: list[str] = []
    total = sum(f["delay"] for f in flown)
    per_aircraft = total / n_aircraft if n_aircraft else 0.0  # no aircraft (an empty schedule): no delay
    expect = {"operated": len(flown), "cancelled": len(spec["flights"]) - len(flown),
              "total_delay_s": total, "avg_delay_s": per_aircraft}
    for key, value in (("flights", len(spec["flights"])), ("aircraft", n_aircraft)):  # recorded by uamopt schedule
        got = summary.get(key, value)
        if isinstance(got, bool) or not isinstance(got, int) or got != value:
            out.append(f"summary.json: {key} = {shown(got)}, flights.json holds {value}")
    out += _off_grid(summary.get("extent_m"), spec, str(path))
    from uamopt.schedule.verify_variants import check_families, objective_checked_here

    out += check_families(summary, spec, flown, str(path))
    if objective_checked_here(summary):
        pass  # against the instance file or the speed choice (verify_variants.py)
    elif summary.get("status") not in NO_SCHEDULE and summary.get("objective") is not None and "weights" in summary:
        w6, w7 = read_weights(summary["weights"], str(path))
        if summary.get("objective_kind", "weighted") == "weighted":
            expect["objective"] = w6 * per_aircraft - w7 * len(flown)
        else:
            upper = sum(max(0.0, min(f["max_delay"], spec["service_end_s"] - f["planned"] - f["duration"]))
                        for f in spec["flights"])
            expect["objective"] = -len(flown) + total / (upper + 1.0)
        if not math.isfinite(expect["objective"]):  # never a pass: the recorded objective cannot be checked
            out.append(f"summary.json: the objective cannot be recomputed (weights = {shown(summary['weights'])}, "
                       f"{expect['objective']:g} from the schedule)")
            del expect["objective"]
    for key, value in expect.items():
        got = summary.get(key)
        if not finite(got) or not close(float(got), float(value)):
            out.append(f"summary.json: {key} = {shown(got)}, the schedule gives {value:.6g}")
    status = summary.get("status")
    if status not in STATUS_WORDS:
        out.append(f"summary.json: unknown status {shown(status)}")
    elif "termination" in summary or "proved_for" in summary:  # written since the statuses were split (issue 40)
        pair = (summary.get("termination"), summary.get("proved_for"))
        if STATUS_WORDS[status] != pair:
            out.append(f"summary.json: status {status} with termination {shown(pair[0])} and proved_for "
                       f"{shown(pair[1])}; {status} means termination {STATUS_WORDS[status][0]}, proved_for "
                       f"{STATUS_WORDS[status][1]}")
    return out


def read_weights(raw, where: str) -> tuple[float, float]:
    """(ω6, ω7) of summary.json: two finite numbers in [0, ``MAX_WEIGHT``] (the range of
    ``schedule.weights``, in which ω6·delay − ω7·S stays finite), else the folder is malformed."""
    if not isinstance(raw, list) or len(raw) != 2 or not all(finite(w) and 0 <= w <= MAX_WEIGHT for w in raw):
        raise InputFileError(f"weights must be two finite numbers (ω6, ω7) in [0, {MAX_WEIGHT:g}] (the range of "
                             f"schedule.weights), got {shown(raw)}", where, "rewrite it with uamopt schedule")
    return float(raw[0]), float(raw[1])


def _off_grid(extent, spec: dict, where: str) -> list[str]:
    """Flights with a waypoint outside the grid ``extent_m`` that summary.json records (Sec. 3)."""
    if extent is None:
        return []
    if not isinstance(extent, list) or len(extent) != 3 or not all(finite(e) and e > 0 for e in extent):
        raise InputFileError(f"extent_m must be three positive sizes in metres, got {shown(extent)}", where,
                             "rewrite it with uamopt schedule")
    out = []
    for f in spec["flights"]:
        off = outside_grid(f["waypoints"], extent)  # the readers' rule (uamopt/bounds.py): one tolerance
        p = f["waypoints"][int(off.argmax())] if off.any() else None
        if p is not None:
            out.append(f"flight {f['id']}: waypoint ({', '.join(f'{v:g}' for v in p)}) outside the grid "
                       f"[0, {', '.join(f'{e:g}' for e in extent)}] m of summary.json (Sec. 3)")
    return out
