"""Benchmark: how closely BlueSky flies our plans (the measured tables of docs/export.md).

Needs BlueSky (uamopt[sim]); each replay is a fresh BlueSky process (~10 s of start-up). Run on demand:

    .venv/bin/python tests/benchmarks/bench_replay.py single [--bank 45]
    .venv/bin/python tests/benchmarks/bench_replay.py banks DIR [--window 0,600] [--banks 25,35,45,60]
        [--trajectories designed,waypoints]

``single``: one flight at a time at 25 m/s (cells 50 × 50 × 30 m): an unrounded 90° and 81°
corner between 600 m legs, and 300 m climbs or descents between level 300 m legs; each flown as
the designed trajectory and as the track's own waypoints. ``banks``: the schedule folder DIR
(e.g. ``uamopt schedule models/paper_case.toml --solver highs --out DIR``) replayed in the window
at every bank limit and trajectory. Both print Markdown tables: the designed trajectory's own
largest distance to the plan, then what BlueSky flew (largest horizontal error against the plan
at the same time, cross-track distance, vertical error, arrival deviation) and the CPU time.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from uamopt.sim.replay import replay  # noqa: E402

SPEED = 25.0
HEADER = ("| case | trajectory | designed error | max horizontal error | max cross-track | max vertical error "
          "| arrival deviation | flights beyond e_h | LoS | BlueSky CPU |\n|---|---|---|---|---|---|---|---|---|---|")


def _corner(theta_deg: float) -> list[list[float]]:
    th = math.radians(theta_deg)
    return [[0.0, 0.0, 120.0], [600.0, 0.0, 120.0], [600.0 + 600.0 * math.cos(th), 600.0 * math.sin(th), 120.0]]


def _slope(rise_m: float) -> list[list[float]]:
    low, high = (120.0, 120.0 + rise_m) if rise_m > 0 else (120.0 - rise_m, 120.0)
    return [[0.0, 0.0, low], [300.0, 0.0, low], [600.0, 0.0, high], [900.0, 0.0, high]]


CASES = {"90° corner": _corner(90.0), "81° corner": _corner(81.0), "10 % climb": _slope(30.0),
         "10 % descent": _slope(-30.0), "30 % climb": _slope(90.0), "60 % climb": _slope(180.0)}


def _single_folder(parent: Path, name: str, waypoints: list[list[float]]) -> Path:
    """A schedule folder of one flight departing at 10 s (flights.json and schedule.csv only)."""
    folder = parent / name.replace(" ", "").replace("%", "pc").replace("°", "deg")
    folder.mkdir()
    flight = {"id": "S1", "aircraft": "A1", "route": "S", "origin": "S0", "destination": "S1", "speed_mps": SPEED,
              "planned_departure_s": 10.0, "max_delay_s": 0.0, "waypoints": waypoints}
    doc = {"cell": [50.0, 50.0, 30.0], "conflict_radius": 1, "service_end_s": 3600.0, "flights": [flight]}
    (folder / "flights.json").write_text(json.dumps(doc), encoding="utf-8")
    arrival = 10.0 + float(np.linalg.norm(np.diff(np.asarray(waypoints), axis=0), axis=1).sum()) / SPEED
    with open(folder / "schedule.csv", "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["flight", "aircraft", "route", "operated", "planned_departure_s", "delay_s", "departure_s", "arrival_s"])
        w.writerow(["S1", "A1", "S", 1, 10.0, 0.0, 10.0, repr(arrival)])
    return folder


def _row(case: str, trajectory: str, result) -> str:
    f = result.flights
    top = max(f, key=lambda g: g["max_horizontal_error_m"])
    arrival = [g["arrival_deviation_s"] for g in f]
    return (f"| {case} | {trajectory} | {max(g['designed_error_m'] for g in f):.2f} m "
            f"| {top['max_horizontal_error_m']:.2f} m | {max(g['max_cross_track_m'] for g in f):.2f} m "
            f"| {max(g['max_vertical_error_m'] for g in f):.3f} m | {min(arrival):+.2f} … {max(arrival):+.2f} s "
            f"| {len(result.over_budget)} of {len(f)} | {result.los_count} | {result.seconds['bluesky_cpu']:.0f} s |")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="what", required=True)
    single = sub.add_parser("single")
    single.add_argument("--bank", type=float, default=45.0)
    banks = sub.add_parser("banks")
    banks.add_argument("dir")
    banks.add_argument("--window", default="0,600")
    banks.add_argument("--banks", default="25,35,45,60")
    banks.add_argument("--trajectories", default="designed,waypoints")
    args = parser.parse_args(argv)
    print(HEADER)
    with tempfile.TemporaryDirectory(prefix="bench-replay-") as tmp:
        if args.what == "single":
            for case, waypoints in CASES.items():
                folder = _single_folder(Path(tmp), case, waypoints)
                for trajectory in ("designed", "waypoints"):
                    print(_row(case, trajectory, replay(folder, bank_deg=args.bank, trajectory=trajectory, write=False)),
                          flush=True)
            return 0
        folder = Path(tmp) / "schedule"
        shutil.copytree(args.dir, folder)
        window = tuple(float(v) for v in args.window.split(","))
        for trajectory in args.trajectories.split(","):
            for bank in (float(b) for b in args.banks.split(",")):
                result = replay(folder, bank_deg=bank, trajectory=trajectory, window_s=window, write=False)
                print(_row(f"bank {bank:g}°", trajectory, result), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
