"""Benchmark: cell occupancy + pair-conflict preprocessing for about 10,000 flights.

Target: under 30 s on a 2-core machine. Run on demand:

    .venv/bin/python tests/benchmarks/bench_occupancy.py [--flights 10000] [--vertiports 12]
        [--extent 20000] [--service-h 12] [--verify 1000] [--distinct]

The instance: ``--vertiports`` seeded vertiports in a square domain of ``--extent`` metres
(50 × 50 × 30 m cells), straight tracks on every route (both directions, a→b at 120 m and b→a
one layer up), G aircraft on round trips over ``--service-h`` hours with F flights each from
Eq. 23, G chosen to reach ``--flights``. Times: flight plan, occupancy of every track, and
``conflict_table`` (track-pair join + flight-pair matching; ``forbidden_gaps`` is the same as
a list of objects). ``--verify N`` also times the
independent verifier on an N-flight plan operated as planned (conflicts included).
``--distinct`` gives every flight its own track (no sharing), which exercises the per-flight join.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from uamopt.grid import AirspaceGrid  # noqa: E402
from uamopt.scenario import GridConfig, NetworkConfig, Scenario  # noqa: E402
from uamopt.schedule import (  # noqa: E402
    build_problem,
    conflict_table,
    flight_occupancies,
    flights_per_aircraft,
    forbidden_gaps,
    generate_plan,
    grid_vertiports,
    make_schedule,
    straight_network,
    write_schedule,
)
from uamopt.schedule.flights import track_length_m  # noqa: E402
from uamopt.schedule.occupancy import MAX_TRACK_PAIRS, candidate_pairs, track_pair_gaps  # noqa: E402
from uamopt.schedule.verify import verify_dir  # noqa: E402


def instance(n_flights: int, n_vertiports: int, extent_m: float, service_s: float, seed: int = 0):
    """A seeded benchmark instance: (scenario, grid, flight set)."""
    scenario = Scenario(
        grid=GridConfig(cell=(50.0, 50.0, 30.0), extent=(extent_m, extent_m, 360.0)),
        network=NetworkConfig(vertiports=grid_vertiports(n_vertiports, (extent_m, extent_m), seed=seed)),
    )
    grid = AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent)
    network = straight_network(scenario, grid)
    s = scenario.schedule
    per_aircraft = flights_per_aircraft(service_s, max(track_length_m(t) for t in network.values()),
                                        scenario.aircraft.cruise_speed_mps, s.outbound_gap_s, s.return_gap_s, s.interference)
    aircraft = math.ceil(n_flights / per_aircraft)
    flights = generate_plan(scenario, network, seed, aircraft=aircraft, service_s=service_s, first_departure_window_s=600.0)
    return scenario, grid, flights


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flights", type=int, default=10_000)
    parser.add_argument("--vertiports", type=int, default=12)
    parser.add_argument("--extent", type=float, default=20_000.0, help="domain side, m")
    parser.add_argument("--service-h", type=float, default=12.0, help="T_f − T_s, hours")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--verify", type=int, default=1000, help="flights in the verifier timing (0: skip)")
    parser.add_argument("--distinct", action="store_true",
                        help="give every flight a track of its own (mid-point jittered): the per-flight join")
    args = parser.parse_args()

    t0 = time.perf_counter()
    scenario, grid, fs = instance(args.flights, args.vertiports, args.extent, args.service_h * 3600.0)
    if args.distinct:
        rng = np.random.default_rng(1)
        fs = dataclasses.replace(fs, flights=tuple(
            dataclasses.replace(f, waypoints=np.insert(f.waypoints, 1, f.waypoints.mean(axis=0)
                                                       + np.array([*rng.uniform(-40, 40, 2), 0]), axis=0))
            for f in fs.flights))
    t_plan = time.perf_counter() - t0
    print(f"instance: {len(fs):,} flights, {fs.n_aircraft} aircraft, {args.vertiports} vertiports, "
          f"{len({f.route for f in fs.flights})} directed routes, grid {grid.shape}, r = {fs.conflict_radius} "
          f"(plan generated in {t_plan:.2f} s)")

    best = math.inf
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        occupancies, _ = flight_occupancies(fs)
        t_occ = time.perf_counter() - t0
        t0 = time.perf_counter()
        conflicts = conflict_table(fs)  # occupancy again + track pairs + flight pairs, end to end
        best = min(best, time.perf_counter() - t0)
    t0 = time.perf_counter()
    as_list = forbidden_gaps(fs)
    t_list = time.perf_counter() - t0
    visits = sum(len(o) for o in occupancies)
    joined = track_pair_gaps(occupancies, fs.conflict_radius, MAX_TRACK_PAIRS)
    p, _ = candidate_pairs(fs)
    n_iv = len(conflicts.intervals)
    print(f"occupancy: {len(occupancies)} distinct tracks, {visits:,} cell visits in {t_occ:.3f} s")
    if joined is None:
        print(f"track-level join over {MAX_TRACK_PAIRS:,} visit pairs: per-flight join used")
    else:
        print(f"track pairs with forbidden gaps: {len(joined[0]):,} ({len(joined[2]):,} merged intervals)")
    print(f"flight pairs: {len(p):,} candidates by time window -> {len(conflicts):,} conflicting pairs, {n_iv:,} intervals")
    print(f"conflict_table (occupancy + pair preprocessing), best of {args.repeat}: {best:.3f} s (target < 30 s)")
    print(f"forbidden_gaps (the same as a list of {len(as_list):,} PairConflict objects): {t_list:.3f} s")
    print(f"peak memory (process RSS): {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB")

    if args.verify:
        _, _, small = instance(args.verify, args.vertiports, args.extent, args.service_h * 3600.0)
        problem = build_problem(small, scenario)
        n = problem.n_flights
        with tempfile.TemporaryDirectory() as tmp:
            write_schedule(tmp, problem, make_schedule(problem, "as-planned", "stopped", np.ones(n, bool), np.zeros(n)))
            t0 = time.perf_counter()
            found = verify_dir(tmp)
            t_verify = time.perf_counter() - t0
        print(f"verifier: {n:,} flights operated as planned, {len(found):,} violations found in {t_verify:.2f} s")


if __name__ == "__main__":
    main()
