"""The one place uamopt drives highspy directly: quiet instances, the wall-clock deadline, MIP
starts, and a run of a 0-1 program with its result. ``highs`` (milp.py) reaches HiGHS through
Pyomo and uses the start and the deadline from here; ``timeindexed`` hands its matrix model to
:func:`mip_solver` and :func:`run_mip`.

Keeping HiGHS to a wall-clock deadline. HiGHS checks its ``time_limit`` only at some points. Measured on the time-indexed model of
models/benchmark_3000.toml (39,000 columns, 173,000 rows, a loaded 2-core machine): with a 1.5 s
limit it ran 11.7 s (presolve off, MIP start given), 7.6 s (no start) and 22 s (presolve on), and its
interrupt callbacks were not called in those stretches either. So a deadline is kept two ways:
:func:`interrupt_at` stops it at the deadline wherever it does listen, and
:func:`highs_can_start` skips a HiGHS run whose unlistening start (rows × a measured rate) would
not fit in the time left (the caller then keeps its warm start, status ``time_limit``)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from uamopt.errors import UamoptError
from uamopt.interrupts import stopping


def interrupt_at(highs, deadline: float, grace_s: float = 0.05, on_bound=None, on_solution=None) -> list:
    """Make ``highs`` (a ``highspy.Highs``) stop once ``time.perf_counter()`` passes ``deadline``.
    Returns a list that is non-empty once it has stopped HiGHS (HiGHS then reports "interrupted by
    user", which Pyomo reads as an unknown termination: it is the time limit). ``on_bound(value)``,
    if given, hears the MIP's dual bound at each of HiGHS's MIP callbacks (a watched child passes it
    on: uamopt.solvers.watchdog); ``on_solution(x)`` each improving MIP solution's column values."""
    fired: list = []

    def stop(event) -> None:
        if on_bound is not None:
            bound = getattr(getattr(event, "data_out", None), "mip_dual_bound", None)
            if bound is not None and math.isfinite(bound):
                on_bound(float(bound))
        if time.perf_counter() > deadline + grace_s:
            fired.append(True)
            event.interrupt()

    for callback in (highs.cbSimplexInterrupt, highs.cbIpmInterrupt, highs.cbMipInterrupt):
        callback.subscribe(stop)
    if on_solution is not None:
        def improved(event) -> None:
            solution = getattr(getattr(event, "data_out", None), "mip_solution", None)
            if solution is not None:
                on_solution(np.asarray(solution, dtype=float))

        highs.cbMipImprovingSolution.subscribe(improved)
    return fired


#: seconds per model row before HiGHS first listens (measured above: 7.6 s / 173,000 rows ≈ 44 µs,
#: presolve off; presolve on is about three times that)
UNLISTENING_S_PER_ROW = {False: 44e-6, True: 130e-6}


def highs_can_start(rows: int, seconds_left: float, presolve: bool = True) -> bool:
    """Whether HiGHS's first uninterruptible stretch on a model of ``rows`` rows fits ``seconds_left``."""
    return rows * UNLISTENING_S_PER_ROW[bool(presolve)] <= seconds_left


def quiet_highs():
    """A ``highspy.Highs`` with its output off, made without the banner HiGHS prints on stdout at
    construction (file descriptor 1 is pointed at /dev/null for that moment)."""
    import os
    import sys

    import highspy

    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            highs = highspy.Highs()
            highs.setOptionValue("output_flag", False)
    finally:
        os.dup2(saved, 1)
        os.close(saved)
    return highs


def start_solution(x):
    """A ``highspy.HighsSolution`` holding the column values ``x``: a MIP start for ``setSolution``."""
    import highspy

    sol = highspy.HighsSolution()
    sol.col_value = [float(v) for v in x]
    sol.value_valid = True
    return sol


def mip_solver(threads: int, seed: int, gap: float, presolve: bool = True):
    """A quiet ``highspy.Highs`` for a MIP: its threads, seed and relative gap (presolve on or off)."""
    h = quiet_highs()
    h.resetGlobalScheduler(True)  # HiGHS keeps one thread pool per process: a new thread count needs a new pool
    h.setOptionValue("threads", int(threads))
    h.setOptionValue("random_seed", int(seed))
    h.setOptionValue("mip_rel_gap", float(gap))
    if not presolve:
        h.setOptionValue("presolve", "off")
    return h


@dataclass
class MipRun:
    """What one HiGHS MIP run gave: the column values of its incumbent (None: none), whether
    HiGHS proved it optimal, its dual bound (None: not finite), its model status in words, the
    run's seconds and the times of its improving solutions (s after the start)."""

    x: np.ndarray | None
    objective: float
    proved: bool
    bound: float | None
    termination: str
    seconds: float
    found: list[float]


def run_mip(h, deadline: float, where: str) -> MipRun:
    """Run the loaded MIP of ``h`` until ``deadline`` (a ``time.perf_counter`` time): HiGHS's own
    time limit and :func:`interrupt_at`, Ctrl-C and SIGTERM stopping it at once (uamopt.interrupts).

    Raises
    ------
    UamoptError
        HiGHS stopped with an error (``where`` names the solver).
    """
    import highspy

    h.setOptionValue("time_limit", max(0.05, deadline - time.perf_counter()))
    interrupt_at(h, deadline)
    t0 = time.perf_counter()
    found: list[float] = []
    h.cbMipImprovingSolution.subscribe(lambda *_: found.append(time.perf_counter() - t0))
    with stopping(h.cancelSolve):
        run_status = h.run()
    if run_status == highspy.HighsStatus.kError:
        raise UamoptError("HiGHS stopped with an error", where, "rerun with output_flag = true to see why")
    seconds = time.perf_counter() - t0
    status = h.getModelStatus()
    info = h.getInfo()
    sol = h.getSolution()
    return MipRun(x=np.array(sol.col_value) if sol.value_valid else None, objective=float(info.objective_function_value),
                  proved=status == highspy.HighsModelStatus.kOptimal,
                  bound=float(info.mip_dual_bound) if math.isfinite(info.mip_dual_bound) else None,
                  termination=h.modelStatusToString(status), seconds=seconds, found=found)
