"""summary.json checks of the independent verifier (uamopt/schedule/verify.py): counts, delays
and the objective recomputed from the schedule (Eqs. 20-22), the recorded grid extent, and the
summary's own fields (an object, two finite weights), since the folder is untrusted input."""

from __future__ import annotations

import json
import math
from pathlib import Path

from uamopt.errors import InputFileError

TOL_S = 1e-6  # tolerance on every time and total, s (relative above 1)


def close(a: float, b: float) -> bool:
    """Equal within ``TOL_S`` relative; an infinite or NaN value is never close (inf ≤ inf would be)."""
    return math.isfinite(a) and math.isfinite(b) and abs(a - b) <= TOL_S * max(1.0, abs(a), abs(b))


def check_summary(path: Path, spec: dict, flown: list[dict], n_aircraft: int) -> list[str]:
    """Violations of summary.json against the schedule: ``spec`` is the verifier's reading of
    flights.json, ``flown`` its operated flights, ``n_aircraft`` G (Eq. 21)."""
    try:
        summary = json.loads(path.read_text(encoding="utf-8-sig"))
    except (json.JSONDecodeError, UnicodeDecodeError, RecursionError, OSError) as exc:
        raise InputFileError(f"malformed JSON: {exc}", str(path), "rewrite it with uamopt schedule") from None
    if not isinstance(summary, dict):
        raise InputFileError("summary.json does not hold a JSON object", str(path), "rewrite it with uamopt schedule")
    out: list[str] = []
    total = sum(f["delay"] for f in flown)
    expect = {"operated": len(flown), "cancelled": len(spec["flights"]) - len(flown),
              "total_delay_s": total, "avg_delay_s": total / n_aircraft}
    out += _off_grid(summary.get("extent_m"), spec, str(path))
    from uamopt.schedule.verify_variants import check_families, objective_checked_here

    out += check_families(summary, spec, flown, str(path))
    if objective_checked_here(summary):
        pass  # against the instance file or the speed choice (verify_variants.py)
    elif summary.get("status") != "infeasible" and summary.get("objective") is not None and "weights" in summary:
        w6, w7 = read_weights(summary["weights"], str(path))
        if summary.get("objective_kind", "weighted") == "weighted":
            expect["objective"] = w6 * total / n_aircraft - w7 * len(flown)
        else:
            upper = sum(max(0.0, min(f["max_delay"], spec["service_end_s"] - f["planned"] - f["duration"]))
                        for f in spec["flights"])
            expect["objective"] = -len(flown) + total / (upper + 1.0)
    for key, value in expect.items():
        got = summary.get(key)
        if not isinstance(got, (int, float)) or not close(float(got), float(value)):
            out.append(f"summary.json: {key} = {got!r}, the schedule gives {value:.6g}")
    if summary.get("status") not in ("optimal", "optimal_on_grid", "feasible", "time_limit", "infeasible", "error"):
        out.append(f"summary.json: unknown status {summary.get('status')!r}")
    return out


def read_weights(raw, where: str) -> tuple[float, float]:
    """(ω6, ω7) of summary.json: two finite numbers, else the folder is malformed."""
    if not isinstance(raw, list) or len(raw) != 2 or not all(
            isinstance(w, (int, float)) and not isinstance(w, bool) and math.isfinite(w) for w in raw):
        raise InputFileError(f"weights must be two finite numbers (ω6, ω7), got {raw!r}", where,
                             "rewrite it with uamopt schedule")
    return float(raw[0]), float(raw[1])


def _off_grid(extent, spec: dict, where: str) -> list[str]:
    """Flights with a waypoint outside the grid ``extent_m`` that summary.json records (Sec. 3)."""
    if extent is None:
        return []
    if not isinstance(extent, list) or len(extent) != 3 or not all(
            isinstance(e, (int, float)) and not isinstance(e, bool) and math.isfinite(e) and e > 0 for e in extent):
        raise InputFileError(f"extent_m must be three positive sizes in metres, got {extent!r}", where,
                             "rewrite it with uamopt schedule")
    out = []
    for f in spec["flights"]:
        p = next((p for p in f["waypoints"] if any(p[k] > extent[k] + 1e-6 for k in range(3))), None)
        if p is not None:
            out.append(f"flight {f['id']}: waypoint ({', '.join(f'{v:g}' for v in p)}) outside the grid "
                       f"[0, {', '.join(f'{e:g}' for e in extent)}] m of summary.json (Sec. 3)")
    return out
