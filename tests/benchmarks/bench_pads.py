"""Benchmark: the vertiport variant on the paper case (issue 18, item 2). Run on demand, e.g.

    nice -n 10 .venv/bin/python tests/benchmarks/bench_pads.py --pads 1 \\
        --solvers highs,cpsat,timeindexed,greedy,ga,soa,rolling --out /tmp/padsbench

For each pad count and solver profile: ``uamopt schedule models/paper_case.toml`` with
``network.vertical_phases = true`` and ``network.pads = N`` (the profile's own time limit), then
the independent verifier ``uamopt verify`` on the written folder. Prints status, operated and
cancelled flights, total and average delay, the solver's time, the verifier's exit code, and the
1-minute load average (the CPU is shared: times are inflated when it exceeds the 2 cores).
A solver without an encoder for more than one pad refuses (exit 2): printed as ``refused``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def run(pads: int, solver: str, out: Path, extra: list[str]) -> dict:
    folder = out / f"pads{pads}_{solver}"
    cmd = [sys.executable, "-m", "uamopt", "schedule", str(ROOT / "models" / "paper_case.toml"), "--solver", solver,
           "--out", str(folder), "--set", "network.vertical_phases=true", "--set", f"network.pads={pads}"]
    for e in extra:
        cmd += ["--set", e]
    load = os.getloadavg()[0]
    done = subprocess.run(cmd, capture_output=True, text=True)
    row = {"pads": pads, "solver": solver, "load": load}
    if done.returncode != 0:
        row["status"] = "refused" if done.returncode == 2 else f"exit {done.returncode}"
        row["line"] = (done.stderr.strip().splitlines() or [""])[-1]
        return row
    s = json.loads((folder / "summary.json").read_text())
    check = subprocess.run([sys.executable, "-m", "uamopt", "verify", str(folder)], capture_output=True, text=True)
    row.update(status=s.get("status"), operated=s.get("operated"), cancelled=s.get("cancelled"),
               total_delay_s=s.get("total_delay_s"), objective=s.get("objective"), bound=s.get("bound"),
               seconds=s.get("solve_seconds", s.get("seconds")), verify_exit=check.returncode)
    row["avg_delay_s"] = (row["total_delay_s"] / row["operated"]) if row.get("operated") else None
    return row


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pads", default="1", help="pad counts, comma-separated (default 1)")
    ap.add_argument("--solvers", default="highs,cpsat,timeindexed,greedy,ga,soa,rolling")
    ap.add_argument("--out", default="/tmp/uamopt_bench_pads")
    ap.add_argument("--set", action="append", default=[], help="more scenario keys (KEY=VALUE)")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    print("| pads | solver | status | operated | cancelled | total delay (s) | avg delay (s) | objective | bound "
          "| time (s) | verify exit | load |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for pads in [int(p) for p in args.pads.split(",")]:
        for solver in args.solvers.split(","):
            r = run(pads, solver, out, args.set)
            rows.append(r)
            if "line" in r:
                print(f"| {pads} | {solver} | {r['status']}: {r['line']} | | | | | | | | | {r['load']:.2f} |", flush=True)
                continue
            fmt = lambda v, f="{:.1f}": "" if v is None else (f.format(v) if isinstance(v, float) else str(v))  # noqa: E731
            print(f"| {pads} | {solver} | {r['status']} | {r['operated']} | {r['cancelled']} | {fmt(r['total_delay_s'])} "
                  f"| {fmt(r['avg_delay_s'])} | {fmt(r['objective'])} | {fmt(r['bound'])} | {fmt(r['seconds'], '{:.2f}')} "
                  f"| {r['verify_exit']} | {r['load']:.2f} |", flush=True)
    (out / "bench_pads.json").write_text(json.dumps(rows, indent=1) + "\n")
    return 0 if all(r.get("verify_exit", 0) == 0 for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
