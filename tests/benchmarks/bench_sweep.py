"""Benchmark: scale-out of ``uamopt sweep``, a 16-case sweep on a 2-worker LocalCluster vs serial.

    nice -n 10 .venv/bin/python tests/benchmarks/bench_sweep.py [--workers 2] [--cases 16]

Both runs execute the same sweep file (written to a temporary folder: the paper case at 50 m cells, ``[grid]`` over
the number of aircraft and the cruise speed, the preliminary strategy and SOA's profile: about 5 CPU seconds a case,
so that the cluster's start-up, a few seconds, is amortised) into fresh results folders, one after the other in this
process: first with ``workers = 1`` (serial, the same local-cluster machinery), then with ``--workers``. Printed: the
wall time of each, the speed-up, a machine check (the same pure-Python loop in ``--workers`` processes at once against
one after the other: the ceiling any scale-out can reach on the machine as loaded now), the CPU seconds the run
consumed (this process and its workers) and so the cores it actually got on average, the summed per-case solver
seconds, the load average before and after each run (other processes sharing the cores slow the parallel run more than
the serial one), and whether the two tables agree row for row (timing aside).
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

SWEEP = """# scale-out benchmark: {cases} cases
base = "{base}"
stage = "schedule"
solvers = ["greedy", "soa"]
seeds = [0]
[grid]
"schedule.aircraft" = [16, 20]
"aircraft.cruise_speed_mps" = {speeds}
"""

def load() -> str:
    return " ".join(f"{v:.2f}" for v in os.getloadavg())


def cpu_seconds() -> float:
    """CPU time of this process and its finished children (the cluster's workers, once closed)."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def timed(path: Path, out: Path, workers: int):
    from uamopt.experiments.engine import sweep

    before, cpu = load(), cpu_seconds()
    t0 = time.perf_counter()
    table = sweep(path, out=out, workers=workers)
    wall = time.perf_counter() - t0
    cpu = cpu_seconds() - cpu
    print(f"workers={workers}: {wall:7.1f} s wall, {cpu:.1f} CPU s (= {cpu / wall:.2f} cores busy on average), "
          f"{len(table)} rows, {int((table['status'] == 'error').sum())} errors, solver seconds summed "
          f"{table['seconds'].sum():.1f} s; load average before {before}, after {load()}", flush=True)
    return wall, table


def _spin(n: int) -> int:
    total = 0
    for i in range(n):
        total += i * i % 7
    return total


def machine_check(workers: int, n: int = 15_000_000) -> float:
    """What the machine gives right now: a pure-Python loop in ``workers`` processes at once
    against the same loops one after the other (the ceiling of any scale-out measured now)."""
    import multiprocessing

    t0 = time.perf_counter()
    for _ in range(workers):
        _spin(n)
    serial = time.perf_counter() - t0
    with multiprocessing.get_context("spawn").Pool(workers) as pool:
        pool.map(_spin, [1] * workers)  # start the processes before timing
        t0 = time.perf_counter()
        pool.map(_spin, [n] * workers)
        parallel = time.perf_counter() - t0
    print(f"machine check: {workers} pure-Python loops {serial:.1f} s one after the other, {parallel:.1f} s at once: "
          f"speed-up ceiling {serial / parallel:.2f}x now", flush=True)
    return serial / parallel


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cases", type=int, default=16, help="an even number: 2 aircraft counts × cases/2 speeds")
    args = parser.parse_args()
    speeds = [round(19.0 + 12.0 * i / max(1, args.cases // 2 - 1), 2) for i in range(args.cases // 2)]
    with tempfile.TemporaryDirectory(prefix="bench-sweep-") as tmp:
        folder = Path(tmp)
        path = folder / "scale.toml"
        path.write_text(SWEEP.format(cases=args.cases, base=(ROOT / "models" / "paper_case.toml").as_posix(),
                                     speeds=speeds))
        print(f"{args.cases} cases, {os.cpu_count()} CPUs, load average at start {load()}", flush=True)
        machine_check(args.workers)
        serial, a = timed(path, folder / "serial", 1)
        parallel, b = timed(path, folder / f"w{args.workers}", args.workers)
        same = a.drop(columns="seconds").equals(b.drop(columns="seconds"))
        print(f"speed-up {serial / parallel:.2f}x ({serial:.1f} s -> {parallel:.1f} s with {args.workers} workers); "
              f"tables identical (timing aside): {same}", flush=True)


if __name__ == "__main__":
    main()
