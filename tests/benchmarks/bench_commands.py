"""Benchmark: whole commands as a user runs them (process start, imports, work, files).

Run on demand (not collected by pytest; about a minute):

    .venv/bin/python tests/benchmarks/bench_commands.py [--repeat 3]

Each command runs ``--repeat`` times in a fresh process; the table gives the fastest and the
median wall time, and the machine's load average before the runs (a loaded machine inflates
every figure alike). Targets (issue "Library first", item 4):

- ``uamopt --help``                                           ≤ 0.5 s
- ``uamopt plan models/paper_case.toml --no-figures`` (50 m)  ≤ 2.5 s
- the same at 10 m cells (``--set grid.cell=[10,10,10]``)     ≤ 5 s

Peers measured in the same run, to read the figures on any machine: ``python -c pass`` (process
start) and ``python -c "import numpy, scipy.ndimage, numba, cvxpy"`` (the libraries ``plan``
cannot avoid: numpy/scipy for the risk field, numba for A*, cvxpy for the optimal stage).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
UAMOPT = [sys.executable, "-m", "uamopt"]
CASES = [
    ("python -c pass (peer: process start)", [sys.executable, "-c", "pass"], None),
    ("import numpy, scipy.ndimage, numba, cvxpy (peer)", [sys.executable, "-c", "import numpy, scipy.ndimage, numba, cvxpy"],
     None),
    ("uamopt --help", [*UAMOPT, "--help"], 0.5),
    ("uamopt plan, 50 m, --no-figures", [*UAMOPT, "plan", "models/paper_case.toml", "--no-figures", "--out", "{out}"], 2.5),
    ("uamopt plan, 50 m, figures", [*UAMOPT, "plan", "models/paper_case.toml", "--out", "{out}"], None),
    ("uamopt plan, 10 m, --no-figures", [*UAMOPT, "plan", "models/paper_case.toml", "--set", "grid.cell=[10,10,10]",
                                         "--no-figures", "--out", "{out}"], 5.0),
]


def timed(argv: list[str]) -> float:
    with tempfile.TemporaryDirectory() as tmp:
        argv = [a.replace("{out}", str(Path(tmp) / "out")) for a in argv]
        start = time.perf_counter()
        subprocess.run(argv, cwd=ROOT, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        return time.perf_counter() - start


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    timed([*UAMOPT, "plan", "models/paper_case.toml", "--no-figures", "--out", "{out}"])  # numba's cache written
    print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())}; {os.cpu_count()} cores")
    print(f"{'command':52s} {'fastest':>8s} {'median':>8s} {'target':>7s}")
    failed = 0
    for name, argv, target in CASES:
        times = [timed(argv) for _ in range(args.repeat)]
        best, median = min(times), statistics.median(times)
        verdict = "" if target is None else ("ok" if best <= target else "OVER")
        failed += verdict == "OVER"
        print(f"{name:52s} {best:7.2f}s {median:7.2f}s {'' if target is None else f'{target:.1f}s':>7s} {verdict}")
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
