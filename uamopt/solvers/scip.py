"""Solver ``scip``: the exact MILP of Eqs. 20-31 solved by SCIP (pyscipopt), through the model file.

A third exact solver, open source (Apache 2.0), for benchmarkers who compare MILP engines on one
model. It takes the model exactly as any outside solver would (issue 40, point 9): the continuous
MILP that ``highs`` solves is written as free MPS (uamopt/solvers/model_files.py ``write_model``,
Pyomo's writer, every family of the problem), SCIP reads the file, and its best answer is read
back as any solver's is (``decisions``: the operate columns at 0.5, SCIP's delays checked, then
recomputed exactly from its gap and pad-order choices). So SCIP solves the very file a user can
hand to CBC or Gurobi, and what it proves is about that model: the continuous problem.

Termination: ``optimal`` when SCIP says optimal and its dual bound meets our evaluation of its
schedule (:func:`~uamopt.schedule.model.closes`), ``stopped`` at a ``mip_rel_gap`` above that,
``time_limit`` at the limit, ``infeasible`` (proved for continuous delays). SCIP starts cold (no
MIP start); the result is never worse than the cheap heuristic start
(:func:`~uamopt.solvers.warmstart.no_worse`). The bound is SCIP's dual bound. SCIP runs one
thread; ``threads`` is not read. Option: ``mip_rel_gap`` (SCIP's ``limits/gap``, default 0).
Needs the ``[scip]`` extra (``pip install 'uamopt[scip]'``).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import pyscipopt

from uamopt.interrupts import stopping
from uamopt.schedule.model import Schedule, SchedulingProblem, Termination, closes, evaluate, make_schedule
from uamopt.solvers.milp import OBJECTIVES, SHAPES  # noqa: F401 (the same model: the same shapes and objectives)
from uamopt.solvers.watchdog import report_bound, report_incumbent


def solve(problem: SchedulingProblem, profile) -> Schedule:
    """Write the MILP, solve it with SCIP within the profile's limit, read its answer back."""
    from uamopt.solvers.model_files import decisions, read_mapping, write_model
    from uamopt.solvers.warmstart import infeasible_reason, no_schedule, no_worse, warm_start

    t0 = time.perf_counter()
    start = warm_start(problem, problem.time_step_s, seed=profile.seed)
    with tempfile.TemporaryDirectory(prefix="uamopt-scip-") as folder:
        model_file, _ = write_model(problem, Path(folder) / "model.mps")
        mapping = read_mapping(problem, model_file)
        build_s = time.perf_counter() - t0
        scip = pyscipopt.Model()
        scip.hideOutput()
        scip.readProblem(str(model_file))
    scip.setParam("limits/time", max(0.1, profile.time_limit_s - (time.perf_counter() - t0)))
    scip.setParam("limits/gap", float(profile.option("mip_rel_gap", 0.0)))
    scip.setParam("randomization/randomseedshift", int(profile.seed))
    with stopping(scip.interruptSolve):  # Ctrl-C and SIGTERM stop SCIP at once
        scip.optimize()
    status = scip.getStatus()
    extras = {"engine_termination": status, "model": "continuous MILP of Eqs. 20-31, read by SCIP from free MPS",
              "model_kind": "continuous", "nodes": int(scip.getNNodes()), "build_seconds": build_s,
              "scip_seconds": float(scip.getSolvingTime()), "warm_start": f"{start.source} {start.objective:.6f}"}
    n = problem.n_flights
    if status == "infeasible":
        extras["reason"] = infeasible_reason(problem)
        return make_schedule(problem, "scip", "infeasible", np.zeros(n, bool), np.zeros(n), proved_for="continuous",
                             solve_seconds=time.perf_counter() - t0, seed=profile.seed, extras=extras)
    dual = float(scip.getDualbound())
    bound = dual if np.isfinite(dual) else None
    if scip.getNSols() == 0:
        if not start.found:
            raise no_schedule(problem, profile.name or "scip", f"SCIP stopped ({status}) with no incumbent")
        return make_schedule(problem, "scip", "time_limit", *start.decisions, bound=bound,
                             solve_seconds=time.perf_counter() - t0, seed=profile.seed, extras=extras)
    best = scip.getBestSol()
    values = {v.name: float(scip.getSolVal(best, v)) for v in scip.getVars()}
    operated, delay = decisions(problem, mapping, values, "SCIP's best solution")
    value = evaluate(problem, operated, delay)
    report_incumbent(problem, operated, delay, "SCIP")
    if bound is not None:
        report_bound(problem, bound, "SCIP's dual bound")
    termination: Termination = "time_limit"
    if status in ("optimal", "gaplimit"):
        termination = "optimal" if closes(value, bound) else "stopped"
    schedule = make_schedule(problem, "scip", termination, operated, delay,
                             proved_for="continuous" if termination == "optimal" else "none", bound=bound,
                             solve_seconds=time.perf_counter() - t0, seed=profile.seed, extras=extras)
    return no_worse(problem, schedule, start)
