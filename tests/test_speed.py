"""Speed control (issue 18, item 3; uamopt/schedule/families/speed.py): each flight flies its track
at one of ``schedule.speed_options`` × its cruise speed. Checked against the brute force on a tiny
crossing (hand-reasoned below), through the independent verifier, and on the paper case."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import uamopt as ua
from uamopt.cli import main
from uamopt.errors import UamoptError
from uamopt.schedule import Flight, FlightSet, build_problem
from uamopt.schedule.families.speed import speed_problem
from uamopt.solvers import SolverProfile, bruteforce

# A flies east along y = 275 m (1 km, 25 m/s), C north across it at x = 275 m; both leave at t = 0
# and may not wait (Δd = 0). At the cruise speed they meet in one conflict zone (C reaches the
# crossing at 8 s, A at 10 s), so only one can fly. With A at half speed (it reaches x = 275 m at
# 20 s, after C has left the zone) both fly.
EAST = np.array([[25.0, 275.0, 45.0], [1025.0, 275.0, 45.0]])
NORTH = np.array([[275.0, 75.0, 45.0], [275.0, 475.0, 45.0]])


def crossing() -> FlightSet:
    flights = (Flight("A1", "A", "A", "a", "b", 25.0, 0.0, 0.0, EAST), Flight("C1", "C", "C", "a", "b", 25.0, 0.0, 0.0, NORTH))
    return FlightSet(cell=(50.0, 50.0, 30.0), conflict_radius=1, flights=flights)


def test_a_slower_speed_lets_both_fly_and_every_exact_solver_agrees():
    base = build_problem(crossing(), objective="lexicographic")
    assert bruteforce.solve(base).operated_count == 1
    problem = speed_problem(crossing(), [0.5, 1.0], objective="lexicographic")
    oracle = bruteforce.solve(problem)
    assert oracle.operated_count == 2
    for solver in ("highs", "cpsat", "timeindexed"):
        got = ua.solve(problem, SolverProfile(solver, time_limit_s=20))
        assert got.operated_count == 2 and got.objective == pytest.approx(oracle.objective, abs=1e-9), solver
        assert ua.verify(problem, got).ok
    # greedy tries the cruise speed first: A1 is placed at 25 m/s, and C1 meets it at either speed
    # (at half speed C1 is at y = 225 m when A1 is at x = 325 m: neighbouring cells), so one flies
    greedy = ua.solve(problem, "greedy")
    assert greedy.operated.tolist() == [True, False, False, False] and ua.verify(problem, greedy).ok


def test_the_speed_change_cost_acts():
    free = speed_problem(crossing(), [0.5, 1.0], objective="weighted", weights=(0.6, 0.4))
    costly = speed_problem(crossing(), [0.5, 1.0], objective="weighted", weights=(0.6, 0.4), change_cost_s=2.0)
    # G = 2: a second of delay costs 0.3, a flight is worth 0.4; a change charged as 2 s (0.6) is not worth it
    assert bruteforce.solve(free).objective == pytest.approx(-0.8)
    assert bruteforce.solve(costly).objective == pytest.approx(-0.4)
    for solver in ("highs", "cpsat"):
        got = ua.solve(costly, SolverProfile(solver, time_limit_s=20))
        assert got.objective == pytest.approx(-0.4, abs=1e-9) and got.operated_count == 1
        assert ua.verify(costly, got).ok
    # the same through the scenario keys
    from uamopt.scenario import load_scenario

    for keys, value in ((["schedule.speed_options=[0.5, 1.0]"], -0.8),
                        (["schedule.speed_options=[0.5, 1.0]", "schedule.speed_change_cost_s=2.0"], -0.4)):
        scenario = load_scenario("models/paper_case.toml", keys)
        problem = build_problem(crossing(), scenario, objective="weighted")
        assert bruteforce.solve(problem).objective == pytest.approx(value)


def test_the_written_schedule_carries_the_chosen_speed_and_the_verifier_checks_it(tmp_path):
    problem = speed_problem(crossing(), [0.5, 1.0], objective="lexicographic")
    schedule = ua.solve(problem, "highs", time_limit_s=20)
    folder = tmp_path / "speed"
    ua.schedule.write_schedule(folder, problem, schedule)
    flights = json.loads((folder / "flights.json").read_text())
    rows = list(csv.DictReader(open(folder / "schedule.csv", newline="")))
    assert [r["flight"] for r in rows] == ["A1", "C1"]  # one row per flight, not per speed
    speeds = {f["id"]: f["speed_mps"] for f in flights["flights"]}
    assert sorted(speeds.values()) == [12.5, 25.0]
    assert main(["verify", str(folder)]) == 0
    slow = min(speeds, key=speeds.get)
    for f in flights["flights"]:  # 0.6 × cruise is not an option; the arrival is made consistent with it
        if f["id"] == slow:
            f["speed_mps"] = 15.0
    (folder / "flights.json").write_text(json.dumps(flights))
    for r in rows:
        if r["flight"] == slow:
            length = float(np.linalg.norm(EAST[1] - EAST[0])) if slow == "A1" else float(np.linalg.norm(NORTH[1] - NORTH[0]))
            r["arrival_s"] = repr(float(r["departure_s"]) + length / 15.0)
    with open(folder / "schedule.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    assert main(["verify", str(folder)]) == 1


def test_speed_options_are_checked_and_refused_where_they_cannot_act(paper_problem):
    from uamopt.scenario import load_scenario

    with pytest.raises(UamoptError, match=r"invalid value 1\.2 for 'schedule\.speed_options'.*less than or equal to 1"):
        load_scenario("models/paper_case.toml", ["schedule.speed_options=[1.2]"])
    with pytest.raises(UamoptError, match=r"invalid value \[\] for 'schedule\.speed_options'.*at least 1 item"):
        load_scenario("models/paper_case.toml", ["schedule.speed_options=[]"])
    problem = speed_problem(crossing(), [0.5, 1.0])
    with pytest.raises(UamoptError, match=r"speed_turnaround|speed_precedence|speed_choice"):
        ua.solve(problem, "rolling")


@pytest.mark.slow
def test_on_the_paper_case_speed_options_are_never_worse(paper_straight_plan):
    """Regression values (recorded, lexicographic, 300 s): with [1.0] HiGHS proves 120 flights and
    4490.5 s of delay; the [0.8, 0.9, 1.0] model starts from the cruise-speed model's schedule."""
    from uamopt.scenario import load_scenario

    scenario, _, _, flights = paper_straight_plan
    plain = build_problem(flights, scenario, objective="lexicographic")
    cruise = ua.solve(plain, "highs", time_limit_s=300)
    assert cruise.status == "optimal"
    spaced = load_scenario("models/paper_case.toml", ["schedule.speed_options=[0.8, 0.9, 1.0]"])
    problem = build_problem(flights, spaced, objective="lexicographic")
    assert problem.n_flights == 3 * plain.n_flights
    fast = ua.solve(problem, "highs", time_limit_s=300)
    assert ua.verify(problem, fast).ok
    assert (-fast.operated_count, fast.total_delay_s) <= (-cruise.operated_count, cruise.total_delay_s + 1e-6)


def test_the_schedule_command_counts_flights_not_speed_copies(tmp_path, capsys):
    """``uamopt schedule`` with two speed options prints the counts of schedule.csv (one row per
    flight), not of the model's copies (two per flight): 12 flights, operated + cancelled = 12."""
    import csv

    folder = tmp_path / "two_speeds"
    root = Path(__file__).resolve().parents[1]
    assert main(["schedule", str(root / "models" / "paper_case.toml"), "--solver", "greedy", "--out", str(folder),
                 "--set", 'network.tracks="straight"', "--set", "schedule.aircraft=4", "--set", "schedule.flights=12",
                 "--set", "schedule.speed_options=[0.8, 1.0]"]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    with open(folder / "schedule.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    flown = sum(r["operated"] == "1" for r in rows)
    assert len(rows) == 12
    assert f"operated {flown}, cancelled {12 - flown}," in line, line
