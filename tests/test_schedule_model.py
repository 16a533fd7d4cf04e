"""Flight plans, flights.json and the scheduling model (uamopt/schedule/{flights,plan,model}.py)."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from uamopt.errors import InputFileError, UamoptError
from uamopt.schedule import (
    build_problem,
    evaluate,
    flights_per_aircraft,
    generate_plan,
    load_flights,
    make_schedule,
    save_flights,
    violations,
    write_schedule,
)
from uamopt.schedule.flights_file import flightset_to_dict


@pytest.fixture(scope="module")
def paper(paper_straight_plan):
    return paper_straight_plan


def test_eq23_gives_six_flights_per_aircraft():
    # ⌊3600 / (2·round(4365/25) + 240 + 360 + 0.3)⌋ × 2 = ⌊3600 / 950.3⌋ × 2 = 6
    assert flights_per_aircraft(3600.0, 4365.0, 25.0, 240.0, 360.0, 0.3) == 6
    assert flights_per_aircraft(3600.0, 1920.0, 25.0, 240.0, 360.0, 0.3) == 8


def test_straight_network_layers(paper):
    network = paper[2]
    assert len(network) == 20  # 10 routes, both directions
    np.testing.assert_allclose(network["V1-V4"], [[300, 300, 120], [2220, 4220, 120]])
    np.testing.assert_allclose(network["V4-V1"], [[2220, 4220, 150], [300, 300, 150]])  # one Δz higher
    lengths = {k: np.linalg.norm(v[1] - v[0]) for k, v in network.items()}
    # Table B.3's L_14, L_12, L_13, L_15 (its 2183 m is half of 4365 rounded up; the geometry gives 2182.5)
    np.testing.assert_allclose([lengths[k] for k in ("V1-V4", "V1-V2", "V1-V3", "V1-V5")], [4365, 3920, 1920, 2183], atol=0.6)


def test_paper_plan_120_flights(paper):
    scenario, _, network, fs = paper
    assert len(fs) == 120 and fs.n_aircraft == 20
    assert all(len(c) == 6 for c in fs.chains)
    routes = [fs.flights[int(c[0])].route for c in fs.chains]
    assert all(routes.count(r) == 2 for r in set(routes)) and len(set(routes)) == 10
    dep, arr, gap = fs.planned_departure_s, fs.planned_arrival_s, fs.turnaround_after_s
    for chain in fs.chains:
        legs = [fs.flights[int(i)] for i in chain]
        assert legs[0].origin == legs[1].destination and legs[0].destination == legs[1].origin
        assert [f.route for f in legs[::2]] == [legs[0].route] * 3
        np.testing.assert_allclose(gap[chain], [240, 360] * 3)
        np.testing.assert_array_equal(dep[chain[1:]], arr[chain[:-1]] + gap[chain[:-1]])  # Eq. 27, equality
        assert 0 <= dep[chain[0]] <= 600 and dep[chain[0]] == round(dep[chain[0]])
    for f in fs.flights:
        assert f.max_delay_s == np.floor(f.length_m / 25.0 + 0.5) + f.turnaround_after_s  # Eq. 29
    assert np.all(arr <= 3600.0)
    again = generate_plan(scenario, network, seed=0, max_delay_scale=1.0)
    assert np.array_equal(again.planned_departure_s, dep)
    assert not np.array_equal(generate_plan(scenario, network, seed=1, max_delay_scale=1.0).planned_departure_s, dep)


def test_plan_window_too_wide_is_narrowed(paper):
    """A window wider than an aircraft's slack shrinks to that slack, and the plan says so."""
    scenario, _, network, _ = paper
    fs = generate_plan(scenario, network, seed=0, first_departure_window_s=1500.0)
    assert np.all(fs.planned_arrival_s <= fs.service_end_s + 1e-9)
    assert fs.notes and "first_departure_window_s = 1500 s" in fs.notes[0]
    assert not generate_plan(scenario, network, seed=0).notes


def test_plan_that_cannot_fit_names_the_keys(paper):
    scenario, _, network, _ = paper
    with pytest.raises(UamoptError, match="more than the 3600 s service window"):
        generate_plan(scenario, network, seed=0, flights=400)


def test_flights_json_round_trip(paper, tmp_path):
    scenario, grid, network, fs = paper
    save_flights(tmp_path / "flights.json", fs)
    back = load_flights(tmp_path / "flights.json", scenario, grid)
    assert flightset_to_dict(back) == flightset_to_dict(fs)
    assert np.array_equal(back.turnaround_after_s, fs.turnaround_after_s)
    assert back.conflict_radius == 1 and back.cell == (50.0, 50.0, 30.0)
    # a flight without waypoints takes its route's track from the network; max_delay_s defaults to Eq. 29
    raw = flightset_to_dict(fs)
    for f in raw["flights"]:
        del f["waypoints"], f["max_delay_s"]
    raw["cell"], raw["conflict_radius"] = [25.0, 25.0, 30.0], 0  # the file overrides the scenario
    (tmp_path / "routes.json").write_text(json.dumps(raw))
    by_route = load_flights(tmp_path / "routes.json", scenario, grid, network=network)
    assert by_route.cell == (25.0, 25.0, 30.0) and by_route.conflict_radius == 0
    np.testing.assert_array_equal(by_route.max_delay_s, fs.max_delay_s)
    assert all(np.array_equal(a.waypoints, b.waypoints) for a, b in zip(by_route.flights, fs.flights, strict=True))


def _write(tmp_path, raw, name="bad.json"):
    path = tmp_path / name
    path.write_text(raw if isinstance(raw, str) else json.dumps(raw))
    return path


@pytest.mark.parametrize(("case", "match"), [
    ("malformed", "malformed JSON"),
    ("missing", "missing key 'speed_mps'"),
    ("route", "unknown route 'V9-V1'"),
    ("speed", r"speed_mps must be a number in \[0.1, 200\], got 0"),
    ("outside", "outside the grid"),
    ("overlap", "overlaps aircraft A01's flight F001"),
    ("window", "after the service end"),
    ("no_file", "not found"),
])
def test_validation_errors_are_one_line(paper, tmp_path, case, match):
    scenario, grid, network, fs = paper
    raw = flightset_to_dict(fs)
    first = raw["flights"][0]
    if case == "malformed":
        path = _write(tmp_path, json.dumps(raw)[:-5])
    else:
        if case == "missing":
            del first["speed_mps"]
        elif case == "route":
            del first["waypoints"]
            first["route"] = "V9-V1"
        elif case == "speed":
            first["speed_mps"] = 0
        elif case == "outside":
            first["waypoints"][1] = [300.0, 300.0, 9000.0]
        elif case == "overlap":
            raw["flights"][1]["planned_departure_s"] = first["planned_departure_s"] + 10.0
        elif case == "window":
            raw["service_end_s"] = 1000.0
        path = _write(tmp_path, raw) if case != "no_file" else tmp_path / "nowhere.json"
    with pytest.raises(InputFileError, match=match) as info:
        load_flights(path, scenario, grid, network=network)
    line = info.value.line()
    assert "\n" not in line and line.count(": ") >= 1 and str(path) in line
    expected = {"missing": "F001", "route": "F001", "speed": "F001", "outside": "F001", "overlap": "F002", "window": "F0"}
    if case in expected:
        assert f"flight {expected[case]}" in line


def test_problem_and_objective(paper):
    scenario, _, _, fs = paper
    problem = build_problem(fs, scenario)
    n = problem.n_flights
    assert problem.aircraft_count == 20 and problem.weights == (0.6, 0.4)
    assert problem.conflicts and all(c.p < c.q for c in problem.conflicts)
    assert all(fs.flights[c.p].aircraft != fs.flights[c.q].aircraft for c in problem.conflicts)
    view = problem.pairs
    assert len(view) == len(problem.conflicts) and view.ptr[-1] == len(view.lo)
    assert np.all(view.hi > view.lo)
    on, delay = np.ones(n, bool), np.zeros(n)
    assert evaluate(problem, on, delay) == pytest.approx(-0.4 * 120)
    delay[:3] = [100.0, 200.0, 101.0]
    assert evaluate(problem, on, delay) == pytest.approx(0.6 * 401.0 / 20 - 0.4 * 120)  # Eqs. 20-22
    # Table 3's initial plan: 109 operated, total delay 2401 s -> T_d = 120.05 s
    on[:11] = False
    sched = make_schedule(problem, "test", "stopped", on, np.where(on, 2401.0 / 109, 0.0))
    assert sched.operated_count == 109 and sched.cancelled_count == 11
    assert sched.avg_delay_s == pytest.approx(120.05) and sched.objective == pytest.approx(0.6 * 120.05 - 0.4 * 109)
    lex = build_problem(fs, scenario, objective="lexicographic")
    assert evaluate(lex, on, np.zeros(n)) == -109
    assert -109 < evaluate(lex, on, np.full(n, 50.0)) < evaluate(lex, on, np.full(n, 60.0)) < -108  # S decides first


def test_model_violations(paper):
    scenario, _, _, fs = paper
    problem = build_problem(fs, scenario)
    n = problem.n_flights
    assert violations(problem, np.zeros(n, bool), np.zeros(n)) == []
    chain = problem.chains[0]
    on = np.zeros(n, bool)
    on[chain[1]] = True  # a return without its outbound
    assert any("without its outbound" in v for v in violations(problem, on, np.zeros(n)))
    on[chain[0]] = True
    delay = np.zeros(n)
    delay[chain[0]] = 30.0  # the return departs too early after a late outbound
    assert any("turnaround" in v for v in violations(problem, on, delay))
    delay[chain[0]] = problem.delay_upper_s[chain[0]] + 1
    assert any("outside" in v for v in violations(problem, on, delay))
    c = problem.conflicts[0]
    on, delay = np.zeros(n, bool), np.zeros(n)
    on[[c.p, c.q]] = True
    mid = c.intervals[0].mean()  # δ = dep_q − dep_p in the middle of a forbidden interval
    delta0 = problem.planned_departure_s[c.q] - problem.planned_departure_s[c.p]
    delay[c.q if mid > delta0 else c.p] = abs(mid - delta0)
    assert problem.delay_upper_s[c.q if mid > delta0 else c.p] >= abs(mid - delta0)
    assert any("forbidden" in v for v in violations(problem, on, delay))


def test_write_schedule_files(paper, tmp_path):
    scenario, _, _, fs = paper
    problem = build_problem(fs, scenario)
    n = problem.n_flights
    on = np.zeros(n, bool)
    on[problem.chains[0]] = True
    delay = np.zeros(n)
    sched = make_schedule(problem, "none", "stopped", on, delay, bound=-3.0, solve_seconds=0.5, seed=4)
    write_schedule(tmp_path / "out", problem, sched)
    names = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert names == ["flights.json", "schedule.csv", "summary.json"]
    with open(tmp_path / "out" / "schedule.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["flight", "aircraft", "route", "operated", "planned_departure_s", "delay_s", "departure_s",
                             "arrival_s"]
    assert [r["operated"] for r in rows].count("1") == 6 and rows[-1]["departure_s"] == ""
    first = rows[int(problem.chains[0][0])]
    assert float(first["arrival_s"]) == pytest.approx(float(first["departure_s"]) + fs.flight_time_s[0])
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    for key in ("solver", "status", "objective", "bound", "gap", "operated", "cancelled", "total_delay_s",
                "avg_delay_s", "solve_seconds", "seed"):
        assert key in summary
    assert summary["operated"] == 6 and summary["cancelled"] == 114 and summary["seed"] == 4
    assert summary["objective"] == pytest.approx(-2.4) and summary["gap"] == pytest.approx(0.6 / 2.4)
