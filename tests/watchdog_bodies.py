"""Solver bodies for tests/test_watchdog.py, run in a watched child process: module-level and light
(a child imports this module before it runs one, inside the time limit)."""

from __future__ import annotations

import os
import signal
import time

import numpy as np

from uamopt.errors import UamoptError
from uamopt.solvers import watchdog


def quick_body(problem, profile, extra):
    """Answers at once: every flight cancelled (starts the forkserver for the tests that time a child)."""
    from uamopt.schedule.model import make_schedule

    n = problem.n_flights
    return make_schedule(problem, "highs", "time_limit", np.zeros(n, bool), np.zeros(n))


def hanging_body(problem, profile, extra):
    """Reports the all-cancelled schedule and a bound, then hangs in a C call (never answers)."""
    n = problem.n_flights
    watchdog.report_incumbent(problem, np.zeros(n, bool), np.zeros(n), "test: all cancelled")
    watchdog.report_bound(problem, -1.0e6, "test: a weak bound")
    time.sleep(3600)


def silent_hanging_body(problem, profile, extra):
    """Reports nothing and hangs."""
    time.sleep(3600)


def failing_body(problem, profile, extra):
    raise UamoptError("the test's own failure", "a test body", "nothing to fix")


def crashing_body(problem, profile, extra):
    os.kill(os.getpid(), signal.SIGKILL)


def pid_body(problem, profile, extra):
    """Writes the child's pid where the test can read it, then hangs."""
    with open(extra, "w") as fh:
        fh.write(str(os.getpid()))
    time.sleep(3600)


def extra_rows(m, problem):
    """A module-level extra= callback (picklable): operate at most two flights."""
    import pyomo.environ as pyo

    m.at_most_two = pyo.Constraint(expr=sum(m.operate[f] for f in m.flights) <= 2)


def broken_report_body(problem, profile, extra):
    """Reports a schedule with two conflicts, then one the model accepts, then hangs."""
    watchdog.report_incumbent(problem, np.ones(3, bool), np.zeros(3), "test: all on time (conflicts)")
    watchdog.report_incumbent(problem, np.array([True, False, False]), np.zeros(3), "test: only A1")
    time.sleep(3600)


def watched_in_a_worker() -> str:
    """Run on a Dask worker of uamopt's own LocalCluster: how a highs solve there was run."""
    from instances import crossing_problem

    from uamopt.solvers import SolverProfile, solve

    return solve(crossing_problem("weighted", (0.6, 0.4)), SolverProfile("highs", time_limit_s=30.0)).extras["watchdog"]
