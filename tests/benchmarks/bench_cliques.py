"""Benchmark: the time-indexed model's LP bound with and without clique rows (issue 19). On demand:

    nice -n 10 .venv/bin/python tests/benchmarks/bench_cliques.py models/paper_case.toml \\
        --set schedule.flights=1000 --set schedule.aircraft=125 --set schedule.plan_seed=11 \\
        --set 'schedule.objective="weighted"' --step 10

Per model kind (grid, relaxed) and with/without the rows of uamopt/solvers/cliques.py: columns,
rows, clique rows, dominated pair rows dropped, the build's seconds, and the LP relaxation's optimum
(HiGHS interior point, 2 threads) with its seconds. The LP optimum is a lower bound of the model's
own optimum (the grid's, or for ``relaxed`` the continuous problem's). The 1-minute load average is
printed before and after (the CPU is shared).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from uamopt.pipeline import build_problem, compute_risk, generate_flights, plan_network, planning_model  # noqa: E402
from uamopt.scenario import load_scenario  # noqa: E402
from uamopt.solvers.timeindexed import GridModel, build_grid_model  # noqa: E402
from uamopt.solvers.warmstart import reduced  # noqa: E402


def lp_bound(model: GridModel, limit_s: float) -> tuple[float, float, str]:
    """(LP optimum, seconds, HiGHS's status) of the model's "≤ 1" and precedence rows, x ∈ [0, 1]."""
    import highspy

    h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("threads", 2)
    h.setOptionValue("solver", "ipm")
    h.setOptionValue("time_limit", float(limit_s))
    n, inf = model.n_cols, highspy.kHighsInf
    h.addVars(n, np.zeros(n), np.ones(n))
    h.changeColsCost(n, np.arange(n, dtype=np.int32), model.cost)
    m = len(model.row_ptr) - 1
    h.addRows(m, np.full(m, -inf), np.ones(m), len(model.row_col), model.row_ptr[:-1].astype(np.int32),
              model.row_col.astype(np.int32), np.ones(len(model.row_col)))
    for f, group in model.prec:  # Σ x_f − Σ x_r ≤ 0
        cols = list(range(model.start[f], model.start[f + 1]))
        back = [j for r in group.tolist() for j in range(model.start[r], model.start[r + 1])]
        h.addRow(-inf, 0.0, len(cols) + len(back), np.array(cols + back, dtype=np.int32),
                 np.array([1.0] * len(cols) + [-1.0] * len(back)))
    t = time.perf_counter()
    h.run()
    return h.getInfo().objective_function_value, time.perf_counter() - t, h.modelStatusToString(h.getModelStatus())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scenario")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument("--step", type=float, default=10.0, help="delay grid step, s")
    parser.add_argument("--kinds", default="grid,relaxed")
    parser.add_argument("--lp-limit", type=float, default=300.0, help="seconds per LP")
    args = parser.parse_args()
    print(f"load before: {os.getloadavg()[0]:.2f}")
    scenario = load_scenario(args.scenario, args.set)
    network = plan_network(planning_model(scenario, compute_risk(scenario, keep_risk=False)))
    problem = reduced(build_problem(generate_flights(scenario, network), scenario, objective="weighted"))
    print(f"{problem.n_flights} flights, {len(problem.conflicts)} conflicting pairs, step {args.step:g} s")
    print("| model | cliques | columns | rows | clique rows | dominated pair rows | build s | LP bound | LP s | LP status |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for kind in args.kinds.split(","):
        for cliques in (False, True):
            t = time.perf_counter()
            model = build_grid_model(problem, args.step, kind, cliques=cliques)
            built = time.perf_counter() - t
            value, seconds, status = lp_bound(model, args.lp_limit)
            print(f"| {kind} | {cliques} | {model.n_cols} | {model.n_rows} | {model.cliques} | {model.dominated_pair_rows} "
                  f"| {built:.1f} | {value:.4f} | {seconds:.1f} | {status} |", flush=True)
    print(f"load after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
