"""Benchmark: the exact solvers on a ladder of instances (issue 12). Run on demand, e.g.

    nice -n 10 .venv/bin/python tests/benchmarks/bench_exact.py --rungs 120,300,600,1000 \\
        --solvers exact,highs,cpsat,rolling --time-limit 300

Per rung and solver it prints: status, the model the status and bound are about, objective,
bound, gap, time to the first incumbent and to the best one (s, from the solver's start), solve
time, operated flights, the independent verifier's violation count, and the 1-minute load average
before and after (the CPU is shared: times are inflated when the load exceeds the 2 cores).

Rungs: ``120`` is the paper case (models/paper_case.toml, seed 0); the others are
:func:`ladder_problem` instances — bench_occupancy.py's synthetic city (8 vertiports in a 20 km
square, straight tracks, 50 × 50 × 30 m cells), 3-hour service for up to 1,000 flights and 9 hours
for 3,000 (the density of the 1,000-flight rung). ``--ladder toml`` takes the rungs from
``models/benchmark_*.toml`` instead (planned tracks on the synthetic city; :func:`toml_problem`). Solvers: profile
names or paths (``exact`` is solvers/exact.toml); ``--time-limit`` overrides every profile's limit.
``--continuous-bound STEP`` also solves the relaxed time-indexed model (cells of STEP s) for a bound
valid for continuous delays, with the same time limit.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_occupancy import instance  # noqa: E402

from uamopt.schedule import build_problem, write_schedule  # noqa: E402
from uamopt.schedule.verify import verify_dir  # noqa: E402
from uamopt.solvers import SolverProfile, load_profile, solve  # noqa: E402


def toml_problem(flights: int):
    """The rung from ``models/benchmark_<flights>.toml`` (the ladder on main): risk field, planned
    network, ``uamopt flights``' generator (``--ladder toml``)."""
    from uamopt.pipeline import (
        build_problem as pipeline_problem,
        compute_risk,
        generate_flights,
        plan_network,
        planning_model,
    )
    from uamopt.scenario import load_scenario

    scenario = load_scenario(ROOT / "models" / f"benchmark_{flights}.toml")
    network = plan_network(planning_model(scenario, compute_risk(scenario)))
    return pipeline_problem(generate_flights(scenario, network), scenario)


def ladder_problem(flights: int):
    """The benchmark instance of a rung (module docstring)."""
    if flights == 120:
        from uamopt.grid import AirspaceGrid
        from uamopt.scenario import load_scenario
        from uamopt.schedule import generate_plan, straight_network

        scenario = load_scenario(ROOT / "models" / "paper_case.toml")
        grid = AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent)
        return build_problem(generate_plan(scenario, straight_network(scenario, grid), seed=0), scenario)
    hours = 3.0 if flights <= 1000 else 9.0 * flights / 3000
    scenario, _, fs = instance(flights, 8, 20_000.0, hours * 3600.0)
    return build_problem(fs, scenario)


def _times(schedule) -> tuple[float | None, float | None]:
    """(time to first incumbent, time to best), s from the solver's start, where the solver says."""
    x = schedule.extras
    if "build_seconds" in x:  # timeindexed: the warm start is ready when the model is built
        first = x["build_seconds"]
        best = first + x["engine_best_incumbent_s"] if x.get("engine_best_incumbent_s") is not None else first
        if x.get("incumbent", "").startswith("warm start"):
            best = first
        return first, best
    return None, None


def fmt(v, spec=".4f") -> str:
    return "-" if v is None else format(v, spec)


def run(problem, rung: int, profile: SolverProfile) -> None:
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    schedule = solve(problem, profile)
    wall = time.perf_counter() - t0
    with tempfile.TemporaryDirectory() as tmp:
        write_schedule(tmp, problem, schedule)
        found = verify_dir(tmp)
    first, best = _times(schedule)
    model = schedule.extras.get("model", schedule.extras.get("bound_of", "-"))
    print(f"| {rung} | {profile.name or profile.solver} | {schedule.status} | {fmt(schedule.objective)} | "
          f"{fmt(schedule.bound)} | "
          f"{fmt(schedule.gap, '.2%') if schedule.gap is not None else '-'} | {fmt(first, '.1f')} | {fmt(best, '.1f')} | "
          f"{wall:.1f} | {schedule.operated_count}/{problem.n_flights} | {len(found)} | {load0:.1f}/{os.getloadavg()[0]:.1f} | "
          f"{model} |", flush=True)
    if "continuous_bound" in schedule.extras:
        print(f"|   | (continuous bound) | {schedule.extras['continuous_bound_termination']} | | "
              f"{fmt(schedule.extras['continuous_bound'])} | | | | | | | | {schedule.extras['continuous_bound_model']} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rungs", default="120,300,600,1000")
    parser.add_argument("--solvers", default="exact,highs,cpsat,rolling")
    parser.add_argument("--time-limit", type=float, default=300.0)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--continuous-bound", type=float, default=0.0, help="cell width s of the relaxed model (0: skip)")
    parser.add_argument("--ladder", choices=["generator", "toml"], default="generator",
                        help="instances: bench_occupancy's generator (measured in docs/exact_scheduling.md) "
                             "or models/benchmark_*.toml")
    args = parser.parse_args()
    print("| flights | solver | status | objective | bound | gap | first s | best s | wall s | operated | violations | "
          "load | model |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for rung in (int(r) for r in args.rungs.split(",")):
        t0 = time.perf_counter()
        problem = ladder_problem(rung) if args.ladder == "generator" else toml_problem(rung)
        print(f"| {rung} | instance: {problem.n_flights} flights, {problem.aircraft_count} aircraft, "
              f"{len(problem.conflicts):,} conflicting pairs, built in {time.perf_counter() - t0:.1f} s | | | | | | | | | | | |",
              flush=True)
        for name in args.solvers.split(","):
            profile = dataclasses.replace(load_profile(name), time_limit_s=args.time_limit, threads=args.threads)
            run(problem, rung, profile)
        if args.continuous_bound > 0:
            profile = SolverProfile("timeindexed", name="relaxed", time_limit_s=args.time_limit, threads=args.threads,
                                    options={"model": "relaxed", "step_s": args.continuous_bound})
            run(problem, rung, profile)


if __name__ == "__main__":
    main()
