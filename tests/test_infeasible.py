"""Infeasible is a status, never a crash: pinned (must-operate) flights that cannot all fly.

Before, ``highs``, ``cpsat`` and ``timeindexed`` ended in a bare AssertionError in the warm start
("the all-cancelled schedule is always feasible"), and HiGHS's infeasible branch used an undefined
name. Each instance here is infeasible by hand (the reason in its docstring); the brute force, which
shares no code with the solvers' models, agrees."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from instances import CROSS_A, CROSS_C

import uamopt as ua
from uamopt.schedule import Flight, FlightSet, build_problem
from uamopt.solvers import bruteforce

EXACT = ["highs", "cpsat", "timeindexed", "exact", "scip"]
HEURISTICS = ["greedy", "ga", "soa", "rolling"]


def flight(fid, aircraft, track, dep, max_delay=0.0):
    return Flight(id=fid, aircraft=aircraft, route=fid, origin="a", destination="b", speed_mps=25.0,
                  planned_departure_s=dep, max_delay_s=max_delay, waypoints=track)


def pinned(flights, kind):
    problem = build_problem(FlightSet(cell=(50.0, 50.0, 30.0), conflict_radius=1, flights=flights),
                            weights=(0.6, 0.4), objective=kind)
    return dataclasses.replace(problem, must_operate=np.ones(len(flights), dtype=bool))


def crossing(kind):
    """A1 (east, t = 0) and C1 (north across it, t = 0) share the conflict zone whenever
    dep_C − dep_A ∈ (−4, 8) s (tests/instances.py); neither may wait, both must fly."""
    return pinned((flight("A1", "A", CROSS_A, 0.0), flight("C1", "C", CROSS_C, 0.0)), kind)


def turnaround(kind):
    """One aircraft: A1 flies 20 s from t = 0, its next flight A2 is planned at t = 5 s and may not
    wait: the aircraft would be in two places at once (Eqs. 27-28); both must fly."""
    back = CROSS_A[::-1].copy()
    return pinned((flight("A1", "A", CROSS_A, 0.0), flight("A2", "A", back, 5.0)), kind)


@pytest.mark.parametrize("make", [crossing, turnaround], ids=["conflict", "turnaround"])
@pytest.mark.parametrize("kind", ["weighted", "lexicographic"])
def test_every_solver_says_infeasible(make, kind):
    problem = make(kind)
    assert bruteforce.solve(problem).status == "infeasible"  # the oracle: no schedule exists
    for name in EXACT + HEURISTICS:
        schedule = ua.solve(problem, name, time_limit_s=20)
        # an exact solver proves it for continuous delays; a heuristic finds none and proves nothing
        want = ("infeasible", "continuous") if name in EXACT else ("no_solution", "none")
        assert (schedule.termination, schedule.proved_for) == want, (name, schedule.termination, schedule.proved_for)
        assert schedule.status == want[0] and not schedule.found
        assert schedule.objective is None
        if name in EXACT:  # a proof, with the pinned flights named
            assert "A1" in schedule.extras["reason"] and schedule.extras["reason"].startswith("no schedule operates")


@pytest.mark.parametrize("name", EXACT)
def test_a_feasible_pin_still_solves(name):
    """Pinning only A1 of the crossing is feasible (C1 is cancelled): no false "infeasible"."""
    problem = dataclasses.replace(crossing("lexicographic"), must_operate=np.array([True, False]))
    schedule = ua.solve(problem, name, time_limit_s=20)
    assert schedule.status in ("optimal", "optimal_on_grid") and schedule.operated.tolist() == [True, False]
    assert ua.verify(problem, schedule).ok


@pytest.mark.parametrize("name", ["highs", "greedy"])
def test_raise_for_status_names_the_reason_and_nothing_is_written(name, tmp_path):
    """``InfeasibleScheduleError`` where the API promises an exception: ``raise_for_status`` (the
    status stays the answer of ``solve``), and ``write_schedule`` / ``ua.verify``, which have no
    schedule to write; a proof names the pinned flights, a heuristic says it proves nothing."""
    from uamopt.errors import InfeasibleScheduleError
    from uamopt.schedule import write_schedule

    problem = crossing("lexicographic")
    schedule = ua.solve(problem, name, time_limit_s=20)
    assert schedule.status == ("infeasible" if name == "highs" else "no_solution")
    with pytest.raises(InfeasibleScheduleError) as raised:
        schedule.raise_for_status()
    line = raised.value.line()
    assert f"(solver {name})" in line and "must_operate" in line
    assert ("A1" in line and "infeasible" in line) if name == "highs" else "not a proof" in line
    with pytest.raises(InfeasibleScheduleError):
        write_schedule(tmp_path / "out", problem, schedule)
    assert not (tmp_path / "out").exists()
    with pytest.raises(InfeasibleScheduleError):
        ua.verify(problem, schedule)
    feasible = dataclasses.replace(problem, must_operate=np.array([True, False]))
    solved = ua.solve(feasible, name, time_limit_s=20)
    assert solved.raise_for_status() is solved  # a schedule: returned as it is


def test_highs_after_a_one_thread_solve_in_the_same_process(monkeypatch):
    """HiGHS sizes one thread pool per process at its first run. A 1-thread time-indexed solve, then
    the MILP with 2 threads and no MIP start (nothing feasible to start from): before, that run
    stopped at once with model status "Not Set" (an error line, seen in `make test` when a file of
    1-thread solves ran before this one); now it proves the instance infeasible. Both in this process
    (``isolated = false``: a watched solve has a process of its own) and with no thread cap."""
    from uamopt.solvers import THREADS_ENV

    monkeypatch.delenv(THREADS_ENV, raising=False)
    feasible = dataclasses.replace(crossing("weighted"), must_operate=np.array([True, False]))
    first = ua.solve(feasible, "timeindexed", time_limit_s=20, threads=1, isolated=False)
    assert first.status == "optimal_on_grid"
    schedule = ua.solve(crossing("weighted"), "highs", time_limit_s=20, threads=2, isolated=False)
    assert schedule.status == "infeasible" and "A1" in schedule.extras["reason"]
