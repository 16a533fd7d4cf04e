"""Independent recomputations for the tests: nothing here imports uamopt.

A test that checks a solver's objective with the library's own ``evaluate`` (or reads back the
``objective`` that ``make_schedule`` computed with it) cannot fail when Eq. 20 is coded wrong.
These functions recompute what the tests compare against, in a few lines, from the paper:

- Eq. 20: W = ω6·T_d − ω7·S;  Eq. 21: T_d = Σ_f c_f d_f / G;  Eq. 22: S = Σ_f c_f.
- The lexicographic variant (docs/readings.md): most operated flights first, then least total
  delay, as the scalar −S + Σ c d / (Σ_f U_f + 1) with U_f = min(Δd_f, T_f − planned arrival_f).
"""

from __future__ import annotations

import csv
import itertools
import json
import math
from pathlib import Path


def objective(operated, delay_s, weights, aircraft: int, kind: str = "weighted", upper_s=None) -> float:
    """Eqs. 20-22 (or the lexicographic scalar) of a decision, from plain lists of numbers."""
    flown = [bool(c) for c in operated]
    total = sum(float(d) for c, d in zip(flown, delay_s, strict=True) if c)
    served = sum(flown)
    if kind == "lexicographic":
        return -served + total / (sum(float(u) for u in upper_s) + 1.0)
    w6, w7 = weights
    return w6 * total / aircraft - w7 * served


def _length(waypoints) -> float:
    return sum(math.dist(a, b) for a, b in itertools.pairwise(waypoints))


def objective_from_folder(folder: str | Path, weights, kind: str = "weighted") -> float:
    """The objective of a schedule folder, read from ``schedule.csv`` and ``flights.json`` only.

    G is the number of distinct aircraft in schedule.csv (Eq. 21); the delay bound of a flight is
    min(max_delay_s, service_end_s − planned departure − length / speed) (Eqs. 26, 29, 31).
    """
    folder = Path(folder)
    with open(folder / "schedule.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    spec = json.loads((folder / "flights.json").read_text(encoding="utf-8"))
    end = float(spec.get("service_end_s", 3600.0))
    flights = {f["id"]: f for f in spec["flights"]}
    upper = []
    for r in rows:
        f = flights[r["flight"]]
        arrival = float(f["planned_departure_s"]) + _length(f["waypoints"]) / float(f["speed_mps"])
        upper.append(max(0.0, min(float(f["max_delay_s"]), end - arrival)))
    return objective([r["operated"] == "1" for r in rows], [float(r["delay_s"]) for r in rows], weights,
                     len({r["aircraft"] for r in rows}), kind, upper)
