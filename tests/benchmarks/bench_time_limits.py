"""Benchmark: how long each solver profile takes against its time limit (issue 42). On demand:

    .venv/bin/python tests/benchmarks/bench_time_limits.py --limit 30 --out out/time_limits.csv \\
        models/benchmark_1000.toml models/benchmark_3000.toml \\
        "models/paper_case.toml schedule.flights=600 schedule.aircraft=100 schedule.plan_seed=7"

Per instance (a scenario file, optionally followed by KEY=VALUE overrides in one quoted argument;
the weighted objective unless an override sets it) and per profile (``--profiles``, default every
shipped profile): the wall-clock seconds of the whole ``ua.solve`` call (process start, model
building and the engine included), its ratio to the limit, whether it kept the promise
``limit × 1.05 + 5 s`` (uamopt/solvers/watchdog.py), the status, objective, bound, and how the
solve ended (``extras.watchdog``). ``--isolated false`` measures the same in the calling process
(the overrun the watchdog removes). The 1-minute load average is recorded beside every row: run it
on a machine doing nothing else.
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from uamopt.pipeline import build_problem, scenario_flights, solve  # noqa: E402
from uamopt.scenario import load_scenario  # noqa: E402
from uamopt.solvers import watchdog  # noqa: E402

PROFILES = ["greedy", "ga", "soa", "highs", "cpsat", "rolling", "timeindexed", "exact", "discovery", "windows"]


def instance(text: str):
    path, *overrides = text.split()
    if not any(o.startswith("schedule.objective=") for o in overrides):
        overrides.append('schedule.objective="weighted"')
    scenario = load_scenario(path, overrides)
    return build_problem(scenario_flights(scenario), scenario)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("instances", nargs="+")
    parser.add_argument("--limit", type=float, default=30.0)
    parser.add_argument("--profiles", nargs="+", default=PROFILES)
    parser.add_argument("--isolated", choices=["true", "false"], default="true")
    parser.add_argument("--out", type=Path, default=Path("out/time_limits.csv"))
    args = parser.parse_args()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    watchdog.warm()
    fields = ["instance", "flights", "profile", "limit_s", "wall_s", "ratio", "promise_s", "kept", "status", "objective",
              "bound", "ended", "load_1min"]
    new = not args.out.exists()
    with args.out.open("a", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=fields)
        if new:
            writer.writeheader()
        for text in args.instances:
            problem = instance(text)
            for name in args.profiles:
                t0 = time.monotonic()
                schedule = solve(problem, name, time_limit_s=args.limit, isolated=args.isolated == "true")
                wall = time.monotonic() - t0
                row = {"instance": text, "flights": problem.n_flights, "profile": name, "limit_s": args.limit,
                       "wall_s": round(wall, 2), "ratio": round(wall / args.limit, 3),
                       "promise_s": round(watchdog.promised_s(args.limit), 2),
                       "kept": wall <= watchdog.promised_s(args.limit), "status": schedule.status,
                       "objective": schedule.objective, "bound": schedule.bound,
                       "ended": str(schedule.extras.get("watchdog", "")).split(";")[0][:60],
                       "load_1min": round(os.getloadavg()[0], 2)}
                writer.writerow(row)
                fh.flush()
                print(row, flush=True)


if __name__ == "__main__":
    main()
