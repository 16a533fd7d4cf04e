"""Benchmark: the solvers on large instances. Run on demand:

    .venv/bin/python tests/benchmarks/bench_large.py medium [--flights 1000] [--time-limit 60]
    .venv/bin/python tests/benchmarks/bench_large.py day [--flights 10000] [--time-limit 480] [--window 900]

``medium``: about 1,000 flights (8 vertiports in a 20 km square, a 3-hour service window, the
instance generator of bench_occupancy.py); greedy, soa, highs and cpsat (``--solvers``; ``rolling`` may be added) each
with the time limit: objective, bound, gap, seconds, and the independent verifier on the written schedule.
``day``: bench_occupancy's city-wide day (about 10,000 flights, 12 vertiports, 12 hours) with the
rolling-horizon solver (inner CP-SAT): total time (target < 10 min), objective, lower bound,
verified. ``rolling`` is called as a module, so it need not be registered in SOLVERS.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_occupancy import instance  # noqa: E402

from uamopt.schedule import build_problem, violations, write_schedule  # noqa: E402
from uamopt.schedule.verify import verify_dir  # noqa: E402
from uamopt.solvers import SolverProfile, rolling, solve as run_solver  # noqa: E402


def report(problem, schedule, wall: float) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        write_schedule(tmp, problem, schedule)
        t0 = time.perf_counter()
        found = verify_dir(tmp)
        t_verify = time.perf_counter() - t0
    model_ok = not violations(problem, schedule.operated, schedule.delay_s)

    def fmt(v):
        return "-" if v is None else f"{v:.4f}"

    print(f"{schedule.solver:8s} {schedule.status:10s} obj {fmt(schedule.objective):>10s} bound {fmt(schedule.bound):>10s} "
          f"gap {fmt(schedule.gap):>8s} operated {schedule.operated_count:5d}/{problem.n_flights} "
          f"delay {schedule.total_delay_s:9.1f} s  solve {schedule.solve_seconds:7.2f} s wall {wall:7.2f} s  "
          f"model-feasible {model_ok} verify {len(found)} violations ({t_verify:.1f} s)", flush=True)


def build(flights: int, vertiports: int, extent: float, hours: float):
    t0 = time.perf_counter()
    scenario, _, fs = instance(flights, vertiports, extent, hours * 3600.0)
    problem = build_problem(fs, scenario)
    print(f"instance: {problem.n_flights:,} flights, {problem.aircraft_count} aircraft, {vertiports} vertiports, "
          f"{hours:g} h, {len(problem.conflicts):,} conflicting pairs (built in {time.perf_counter() - t0:.1f} s)", flush=True)
    return problem


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("which", choices=["medium", "day"])
    parser.add_argument("--flights", type=int)
    parser.add_argument("--vertiports", type=int)
    parser.add_argument("--extent", type=float, default=20_000.0)
    parser.add_argument("--hours", type=float)
    parser.add_argument("--time-limit", type=float)
    parser.add_argument("--window", type=float, default=900.0)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--solvers", default="greedy,soa,highs,cpsat")
    args = parser.parse_args()
    if args.which == "medium":
        problem = build(args.flights or 1000, args.vertiports or 8, args.extent, args.hours or 3.0)
        for name in args.solvers.split(","):
            t0 = time.perf_counter()
            limit = args.time_limit or 60.0
            if name == "rolling":  # not necessarily registered: call the module
                schedule = rolling.solve(problem, SolverProfile("cpsat", time_limit_s=limit, threads=args.threads,
                                                                options={"window_s": args.window}))
            else:
                schedule = run_solver(problem, SolverProfile(name, time_limit_s=limit, threads=args.threads))
            report(problem, schedule, time.perf_counter() - t0)
    else:
        problem = build(args.flights or 10_000, args.vertiports or 12, args.extent, args.hours or 12.0)
        t0 = time.perf_counter()
        schedule = rolling.solve(problem, SolverProfile("cpsat", time_limit_s=args.time_limit or 480.0, threads=args.threads,
                                                        options={"window_s": args.window, "inner": "cpsat"}))
        wall = time.perf_counter() - t0
        report(problem, schedule, wall)
        print(f"rolling extras: {schedule.extras}; total {wall:.1f} s (target < 600 s)")


if __name__ == "__main__":
    main()
