"""Keeping HiGHS to a wall-clock deadline, and quiet.

HiGHS checks its ``time_limit`` only at some points. Measured on the time-indexed model of
models/benchmark_3000.toml (39,000 columns, 173,000 rows, a loaded 2-core machine): with a 1.5 s
limit it ran 11.7 s (presolve off, MIP start given), 7.6 s (no start) and 22 s (presolve on), and its
interrupt callbacks were not called in those stretches either. So a deadline is kept two ways:
:func:`interrupt_at` stops it at the deadline wherever it does listen, and
:func:`highs_can_start` skips a HiGHS run whose unlistening start (rows × a measured rate) would
not fit in the time left (the caller then keeps its warm start, status ``time_limit``)."""

from __future__ import annotations

import time


def interrupt_at(highs, deadline: float, grace_s: float = 0.05) -> list:
    """Make ``highs`` (a ``highspy.Highs``) stop once ``time.perf_counter()`` passes ``deadline``.
    Returns a list that is non-empty once it has stopped HiGHS (HiGHS then reports "interrupted by
    user", which Pyomo reads as an unknown termination: it is the time limit)."""
    fired: list = []

    def stop(event) -> None:
        if time.perf_counter() > deadline + grace_s:
            fired.append(True)
            event.interrupt()

    for callback in (highs.cbSimplexInterrupt, highs.cbIpmInterrupt, highs.cbMipInterrupt):
        callback.subscribe(stop)
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
