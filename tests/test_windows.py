"""Solver ``windows`` (uamopt/solvers/windows.py): windows of flights as Dask tasks, a global bound.

Checked against answers it does not compute itself:
- its bound (the sum of the windows' bounds) never exceeds the optimum that the continuous MILP
  (``highs``, a different model) proves for the whole day, and its schedule passes the oracle of
  tests/oracles.py;
- the same answer (decisions, objective, bound) on a 1-worker and a 2-worker LocalCluster and on a
  separately started ``dask scheduler`` with two ``dask worker`` processes (conftest.py).
"""

from __future__ import annotations

import numpy as np
import pytest
from oracles import broken, model_data, score

from uamopt.schedule import build_problem
from uamopt.solvers import SolverProfile, solve
from uamopt.solvers.windows import split, window_problem

pytest.importorskip("distributed", reason="the windows solver runs on Dask: the [sweep] extra")

OBJ_TOL = 1e-6


@pytest.fixture(scope="module")
def day(paper_straight_plan):
    """The paper case's 120 flights (weighted objective) and its optimum proved by the continuous MILP."""
    scenario, _, _, flights = paper_straight_plan
    problem = build_problem(flights, scenario, objective="weighted")
    best = solve(problem, SolverProfile("highs", time_limit_s=120.0, threads=2))
    assert best.status == "optimal"
    return problem, best.objective


def _run(problem, **options):
    options = {"window_flights": 40, "rounds": 40, "window_time_limit_s": 60.0, **options}
    return solve(problem, SolverProfile("windows", time_limit_s=90.0, threads=1, options=options))


def test_window_problems_keep_only_their_own_rows(day):
    problem, _ = day
    windows = split(problem, 40)
    assert sorted(np.concatenate(windows).tolist()) == list(range(problem.n_flights))
    pairs = {(int(p), int(q)) for p, q in zip(problem.conflicts.p, problem.conflicts.q, strict=True)}
    kept = 0
    for index in windows:
        sub = window_problem(problem, index)
        assert sub.n_flights == len(index)
        mapped = {(int(index[p]), int(index[q])) for p, q in zip(sub.conflicts.p, sub.conflicts.q, strict=True)}
        inside = {(p, q) for p, q in pairs if p in set(index.tolist()) and q in set(index.tolist())}
        assert mapped == inside
        kept += len(mapped)
    assert 0 < kept < len(pairs)  # some rows cross windows and are dropped


def test_bound_below_the_proved_optimum_and_schedule_feasible(day):
    problem, best = day
    result = _run(problem, workers=2)
    data = model_data(problem)
    assert broken(data, result.operated, result.delay_s) == []
    assert result.bound is not None and result.bound <= best + OBJ_TOL
    assert score(data, result.operated, result.delay_s) >= best - OBJ_TOL
    assert result.extras["windows"] == 3 and result.extras["windows_at_limit"] == 0
    assert result.extras["clique_rows"] == 0  # option cliques: off by default
    # the dropped rows cost little here: the bound is within 5 % of the optimum (regression value: 2.9 %)
    assert best - result.bound <= 0.05 * abs(best)


@pytest.mark.parametrize("solver", ["discovery", "windows"])
def test_the_cliques_option_acts_from_2_s_cells_and_the_bound_stays_valid(day, solver):
    """Option ``cliques`` with 2 s cells: clique rows in the relaxations (none at the default 10 s),
    the schedule feasible and the bound still below the optimum the continuous MILP proves."""
    problem, best = day
    options = {"step_s": 2.0, "cliques": True}
    result = (_run(problem, workers=1, **options) if solver == "windows"
              else solve(problem, SolverProfile("discovery", time_limit_s=60.0, threads=1, options=options)))
    assert result.extras["clique_rows"] > 0
    data = model_data(problem)
    assert broken(data, result.operated, result.delay_s) == []
    assert result.bound is not None and result.bound <= best + OBJ_TOL
    assert score(data, result.operated, result.delay_s) >= best - OBJ_TOL


def test_the_neighbourhood_options_act_on_the_joined_schedule(day):
    """``lns_window_time_limit_s`` and ``lns_window``: with a millisecond per neighbourhood no window
    is solved, so none improves the joined schedule; with the default time some do (the joined
    schedule of 40-flight windows is mended, not optimal: regression observation, 120 flights)."""
    problem, best = day
    starved = _run(problem, workers=1, lns_window_time_limit_s=0.001)
    fed = _run(problem, workers=1, lns_window=60)
    assert starved.extras["lns_windows_improved"] == 0 and starved.extras["lns_passes"] == 1
    assert fed.extras["lns_windows_improved"] > 0
    data = model_data(problem)
    assert score(data, fed.operated, fed.delay_s) < score(data, starved.operated, starved.delay_s) - 1e-6
    for result in (starved, fed):
        assert broken(data, result.operated, result.delay_s) == []
        assert score(data, result.operated, result.delay_s) >= best - OBJ_TOL


def test_same_answer_on_one_or_two_workers_and_on_a_started_cluster(day, cluster):
    problem, _ = day
    runs = [_run(problem, workers=1), _run(problem, workers=2), _run(problem, scheduler=cluster)]
    assert runs[2].extras["scheduler"] == cluster
    for other in runs[1:]:
        assert other.objective == runs[0].objective and other.bound == runs[0].bound
        assert np.array_equal(other.operated, runs[0].operated) and np.allclose(other.delay_s, runs[0].delay_s)
        assert other.extras["windows_at_limit"] == 0


def test_the_scheduler_flag_runs_the_windows_on_a_started_cluster(tmp_path, cluster):
    """``uamopt schedule --solver windows --scheduler ADDRESS``: the tasks on the started cluster, a
    verified folder; the flag with another solver is one line, exit code 2, and writes nothing."""
    import subprocess
    import sys

    profile = tmp_path / "w.toml"
    profile.write_text('solver = "windows"\ntime_limit_s = 60.0\nthreads = 1\n[options]\nwindow_flights = 40\n'
                       'rounds = 40\nwindow_time_limit_s = 30.0\n', encoding="utf-8")

    def run(*args):
        return subprocess.run([sys.executable, "-m", "uamopt", "schedule", "models/paper_case.toml", "--set",
                               'schedule.objective="weighted"', *args], capture_output=True, text=True, timeout=300)

    out = tmp_path / "out"
    done = run("--solver", str(profile), "--scheduler", cluster, "--out", str(out))
    assert done.returncode == 0, done.stderr
    import json

    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert summary["extras"]["scheduler"] == cluster and summary["extras"]["windows"] == 3
    refused = run("--solver", "greedy", "--scheduler", cluster, "--out", str(tmp_path / "nothing"))
    lines = refused.stderr.strip().splitlines()
    assert refused.returncode == 2 and len(lines) == 1 and "--scheduler is for the windows solver" in lines[0]
    assert not (tmp_path / "nothing").exists()


def test_bench_scheduler_flag_runs_the_windows_profile_on_a_started_cluster(tmp_path, cluster):
    """``uamopt bench --solver windows --scheduler ADDRESS``: a verified row from the started cluster's
    tasks; with no windows profile the flag is one line, exit code 2, and writes nothing."""
    import csv
    import subprocess
    import sys

    profile = tmp_path / "w.toml"
    profile.write_text('solver = "windows"\ntime_limit_s = 60.0\nthreads = 1\n[options]\nwindow_flights = 40\n'
                       'rounds = 40\nwindow_time_limit_s = 30.0\n', encoding="utf-8")

    def run(*args):
        return subprocess.run([sys.executable, "-m", "uamopt", "bench", "models/paper_case.toml", "--set",
                               'schedule.objective="weighted"', "--seeds", "1", *args], capture_output=True, text=True,
                              timeout=300)

    out = tmp_path / "out"
    done = run("--solver", str(profile), "--scheduler", cluster, "--out", str(out))
    assert done.returncode == 0, done.stderr
    with open(out / "bench.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 1 and rows[0]["verified"] == "True" and rows[0]["solver"] == "windows", rows
    gone = run("--solver", str(profile), "--scheduler", "tcp://127.0.0.1:9", "--out", str(tmp_path / "gone"))
    # nobody listens there: bad input, found before any instance is built (as `schedule` and `sweep`)
    lines = gone.stderr.strip().splitlines()
    assert gone.returncode == 2 and len(lines) == 1 and "cannot reach the Dask scheduler" in lines[0], gone.stderr
    assert not (tmp_path / "gone").exists()
    refused = run("--solver", "greedy", "--scheduler", cluster, "--out", str(tmp_path / "nothing"))
    lines = refused.stderr.strip().splitlines()
    assert refused.returncode == 2 and len(lines) == 1 and "--scheduler is for the windows solver" in lines[0]
    assert not (tmp_path / "nothing").exists()


def _quick():
    return {"done": True}


def _slow():
    import time

    time.sleep(120)


def _failing():
    raise ValueError("a window's own failure")


def test_collect_keeps_what_finished_and_names_what_was_lost():
    """A window still running at the deadline and one whose task failed are lost, each with its
    reason; the finished one is kept (a real LocalCluster, real tasks)."""
    import time

    from uamopt.cluster import connect
    from uamopt.solvers.windows import collect

    client, cluster = connect(None, 2, 3)
    try:
        futures = [client.submit(_quick, pure=False), client.submit(_slow, pure=False), client.submit(_failing, pure=False)]
        results, lost = collect(client, futures, time.perf_counter() + 5.0)
    finally:
        client.close()
        cluster.close()
    assert results[0] == {"done": True} and results[1] is None and results[2] is None
    assert lost[1] == "not done by the deadline" and "error" in lost[2] and 0 not in lost


def test_collect_returns_when_the_scheduler_dies(tmp_path):
    """The scheduler killed while its tasks run: every window is lost with a reason, and collect
    returns by its deadline instead of waiting on a cluster that is gone."""
    import json
    import subprocess
    import sys
    import time
    from pathlib import Path

    from distributed import Client

    from uamopt.solvers.windows import collect

    dask = Path(sys.executable).parent / "dask"
    file = tmp_path / "scheduler.json"
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "cwd": tmp_path}
    scheduler = subprocess.Popen([str(dask), "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                  "--scheduler-file", str(file)], **quiet)
    worker = None
    try:
        for _ in range(600):
            try:
                address = json.loads(file.read_text())["address"]
                break
            except (OSError, ValueError, KeyError):
                time.sleep(0.1)
        worker = subprocess.Popen([str(dask), "worker", address, "--nthreads", "1", "--no-dashboard", "--host",
                                   "127.0.0.1"], **quiet)
        client = Client(address, timeout=30)
        client.wait_for_workers(1, timeout=120)
        futures = [client.submit(_slow, pure=False) for _ in range(2)]
        time.sleep(1.0)
        scheduler.kill()
        results, lost = collect(client, futures, time.perf_counter() + 5.0)
        client.close(timeout=5)
    finally:
        for p in (scheduler, worker):
            if p is not None:
                p.kill()
                p.wait(timeout=30)
    assert results == [None, None] and sorted(lost) == [0, 1]


def test_windows_lost_at_the_deadline_are_replaced_and_the_bound_stays_valid(day):
    """Windows given far more time than the solve has (window_time_limit_s 600 s, limit 4 s): those not
    done by the deadline are replaced by the warm start on their flights; the schedule is feasible,
    the bound (their relaxations' separable bounds in the sum) stays below the proved optimum, and
    every window is either finished or named as lost."""
    problem, best = day
    schedule = solve(problem, SolverProfile("windows", time_limit_s=4.0, threads=1,
                                            options={"window_flights": 40, "window_time_limit_s": 600.0, "workers": 1}))
    data = model_data(problem)
    assert broken(data, schedule.operated, schedule.delay_s) == []
    assert schedule.bound is not None and schedule.bound <= best + OBJ_TOL
    lost = schedule.extras["windows_lost"]
    assert all(why == "not done by the deadline" for why in lost.values())
    assert set(lost) <= set(range(schedule.extras["windows"]))
    assert all(b is not None for b in schedule.extras["window_bounds"])  # a lost window's separable bound too
