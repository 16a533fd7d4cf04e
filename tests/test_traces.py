"""A solve's progress over time (``schedule.extras["trace"]``) and what ``uamopt bench`` draws from it:
incumbent and bound curves (convergence.png) and per-run times and primal integrals in bench.md.

The traces are checked against values nobody here computed: airland8's published optimum, 1950
(Beasley et al. 2000, OR-Library). Every incumbent of a trace is a schedule, so it can never lie
below the optimum; every bound of a trace can never lie above it.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import uamopt as ua
from uamopt.experiments.bench_report import over_time, write_bench
from uamopt.solvers import watchdog

pytest.importorskip("highspy")

DATA = Path(__file__).parent / "data" / "airland"
AIRLAND8_OPTIMUM = 1950.0  # published (OR-Library); proved by HiGHS here within seconds


@pytest.fixture(scope="module")
def airland8():
    return ua.read_airland(DATA / "airland8.txt")


def _check_trace(trace: list, solve_seconds: float) -> None:
    times = [t[0] for t in trace]
    objectives = [t[1] for t in trace if t[1] is not None]
    bounds = [t[2] for t in trace if t[2] is not None]
    assert times == sorted(times) and times[0] >= 0.0 and times[-1] <= solve_seconds + 1e-3
    assert objectives == sorted(objectives, reverse=True), "the best objective so far never rises"
    assert all(o >= AIRLAND8_OPTIMUM - 1e-6 for o in objectives), "a trace's incumbent below the optimum"
    assert all(b <= AIRLAND8_OPTIMUM + 1e-6 for b in bounds), "a trace's bound above the optimum"


@pytest.mark.parametrize("isolated", [True, False])
def test_a_highs_trace_holds_schedules_above_and_bounds_below_the_published_optimum(airland8, isolated):
    schedule = ua.solve(airland8, "highs", time_limit_s=120, threads=1, isolated=isolated)
    assert schedule.status == "optimal" and abs(schedule.objective - AIRLAND8_OPTIMUM) < 1e-6
    trace = schedule.extras["trace"]
    _check_trace(trace, schedule.solve_seconds)
    # HiGHS's own incumbents and dual bounds are in it, not only the warm start and the answer
    assert len({t[1] for t in trace if t[1] is not None}) >= 2
    assert len({t[2] for t in trace if t[2] is not None}) >= 2


def test_cpsat_reports_its_incumbents(airland8):
    schedule = ua.solve(airland8, "cpsat", time_limit_s=60, threads=1)
    trace = schedule.extras["trace"]
    _check_trace(trace, schedule.solve_seconds)
    assert len({t[1] for t in trace[:-1] if t[1] is not None}) >= 2  # more than the warm start before the answer


def test_a_heuristic_trace_is_its_answer(airland8):
    schedule = ua.solve(airland8, "greedy")
    assert schedule.extras["trace"] == [[round(schedule.solve_seconds, 3), schedule.objective, None]]


def test_a_reported_schedule_that_breaks_a_rule_is_not_in_the_trace(airland8):
    """trace_of takes an incumbent only if the model's own rules accept it."""
    n = airland8.n_flights
    fine = ua.solve(airland8, "greedy")
    crowded = (np.ones(n, dtype=bool), np.zeros(n))  # every aircraft at its earliest time: separations broken
    assert ua.verify(airland8, fine).ok
    events = [(10.0, ("incumbent", *crowded, "bad")), (11.0, ("incumbent", fine.operated, fine.delay_s, "good")),
              (12.0, ("bound", 100.0, "b")), (13.0, ("bound", 50.0, "worse bound")), (14.0, ("done", None))]
    trace = watchdog.trace_of(airland8, events, 9.0)
    assert trace == [[2.0, pytest.approx(fine.objective), None], [3.0, pytest.approx(fine.objective), 100.0]]


def _table(rows):
    base = {"flights": 1, "aircraft": 1, "conflicting_pairs": 0, "threads": 1, "objective_kind": "weighted",
            "verified": True, "model": "continuous"}
    return pd.DataFrame([{**base, **r} for r in rows])


def test_over_time_figures_by_hand():
    """Two runs with a 10 s limit; the best known objective is 5 (run b's answer).
    a: nothing until 1 s, then 10 (primal gap |10 − 5| / 10 = 0.5) until 3 s, then 5 (gap 0):
       primal integral 1 × 1 + 0.5 × 2 = 2.0; within 1 % at 3 s; bounds improved last at 4 s.
    b: 5 at 0.5 s, ends at 2 s, keeps gap 0 to the limit: 0.5 × 1 = 0.5.
    c: a heuristic answer of 20 at 0.1 s (gap 0.75) kept to the limit: 0.1 + 0.75 × 9.9 = 7.525."""
    table = _table([
        {"instance": "i", "profile": "a", "seed": 0, "time_limit_s": 10.0, "objective": 5.0, "gap": 0.2,
         "trace": json.dumps([[1.0, 10.0, None], [3.0, 5.0, 2.0], [4.0, 5.0, 4.0], [6.0, 5.0, 4.0]])},
        {"instance": "i", "profile": "b", "seed": 0, "time_limit_s": 10.0, "objective": 5.0, "gap": 0.0,
         "trace": json.dumps([[0.5, 5.0, None], [2.0, 5.0, 5.0]])},
        {"instance": "i", "profile": "c", "seed": 0, "time_limit_s": 10.0, "objective": 20.0, "gap": float("nan"),
         "trace": json.dumps([[0.1, 20.0, None]])},
    ])
    rows = over_time(table).set_index("profile")
    assert rows.loc["a", "primal integral s"] == pytest.approx(2.0)
    assert rows.loc["a", "within 1 % s"] == 3.0 and rows.loc["a", "first incumbent s"] == 1.0
    assert rows.loc["a", "last bound gain s"] == 4.0
    assert rows.loc["b", "primal integral s"] == pytest.approx(0.5)
    assert rows.loc["c", "primal integral s"] == pytest.approx(7.525)
    assert np.isnan(rows.loc["c", "within 1 % s"]) and np.isnan(rows.loc["c", "last bound gain s"])


def test_bench_draws_the_curves_and_lists_every_run(tmp_path, airland8):
    table = ua.benchmark({"airland8": airland8}, ["highs", "greedy"], time_limit_s=60, progress=False)
    assert all(json.loads(t) for t in table["trace"])
    write_bench(tmp_path / "b", table)
    assert (tmp_path / "b" / "convergence.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = (tmp_path / "b" / "bench.md").read_text()
    section = text.split("## Incumbent and bound over time")[1].split("\n## ")[0]
    assert "(convergence.png)" in section
    rows = [line for line in section.splitlines() if line.startswith("| airland8 |")]
    assert [r.split(" | ")[1] for r in rows] == ["highs", "greedy"]
    csv = pd.read_csv(tmp_path / "b" / "bench.csv")
    assert json.loads(csv["trace"][0]) == json.loads(table["trace"][0])


def test_the_progress_line_names_incumbent_bound_and_gap_while_an_exact_solve_runs(airland8):
    """`uamopt schedule` off a terminal: its lines during the solve carry what the watchdog hears."""
    import io

    from uamopt.progress import Steps
    from uamopt.solvers import load_profile
    from uamopt.workflows import solve_progress

    stream = io.StringIO()
    profile = load_profile("highs")
    with Steps(1, "schedule", after_s=0.0, interval_s=0.05, stream=stream) as bar, solve_progress(bar, profile):
        schedule = ua.solve(airland8, profile, time_limit_s=120, threads=1)
        time.sleep(0.3)  # the ticker writes the last improvement's line
    assert schedule.status == "optimal"
    during = [line for line in stream.getvalue().splitlines() if "solving (highs): " in line]
    assert any("incumbent" in line for line in during)
    last = during[-1]
    assert f"incumbent {AIRLAND8_OPTIMUM:.6g}" in last and "bound" in last and "gap" in last, last
