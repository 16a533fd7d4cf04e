"""A flight's own turnaround (``Flight.turnaround_after_s``) survives flights.json and is what
``uamopt verify`` checks (issue 40, point 1). Before, the file neither wrote nor read it and the
verifier re-derived ΔT from leg parity: a 30 s turnaround gave a model-feasible schedule the
verifier rejected, and a 600 s one a schedule that broke the model and passed.

The hand-checked instance: aircraft X flies A→B (20 s, 500 m at 25 m/s) at t = 0 and back at
t = 50 s, far from every other aircraft; its first leg's default turnaround would be T_D = 240 s.
"""

from __future__ import annotations

import numpy as np
import pytest

import uamopt as ua
from uamopt.schedule import Flight, FlightSet, build_problem
from uamopt.schedule.flights_file import load_flights, save_flights
from uamopt.schedule.model import make_schedule, write_schedule
from uamopt.schedule.verify import verify_dir

OUT = np.array([[25.0, 275.0, 45.0], [525.0, 275.0, 45.0]])
BACK = OUT[::-1].copy()


def plan(turnaround_s: float | None, back_at_s: float = 50.0) -> FlightSet:
    def leg(fid, track, dep, gap):
        return Flight(id=fid, aircraft="X", route=fid, origin="a", destination="b", speed_mps=25.0,
                      planned_departure_s=dep, max_delay_s=600.0, waypoints=track, turnaround_after_s=gap)

    return FlightSet(cell=(50.0, 50.0, 30.0), conflict_radius=1, service_end_s=3600.0,
                     flights=(leg("X1", OUT, 0.0, turnaround_s), leg("X2", BACK, back_at_s, None)))


def written(tmp_path, flights: FlightSet, delays: tuple[float, float]):
    problem = build_problem(flights, objective="weighted")
    schedule = make_schedule(problem, "hand", "stopped", np.ones(2, bool), np.array(delays))
    write_schedule(tmp_path / "s", problem, schedule)
    return problem, schedule, verify_dir(tmp_path / "s")


def test_the_file_keeps_a_flights_own_turnaround(tmp_path):
    flights = plan(30.0)
    save_flights(tmp_path / "flights.json", flights)
    again = load_flights(tmp_path / "flights.json")
    assert again.turnaround_after_s.tolist() == [30.0, 360.0]  # the second: T_R, the default after an even leg


def test_a_short_own_turnaround_verifies(tmp_path):
    """X2 departs at 50 s, 30 s after X1 lands (20 s): allowed with a 30 s turnaround."""
    problem, schedule, problems = written(tmp_path, plan(30.0), (0.0, 0.0))
    assert ua.verify(problem, schedule).ok and problems == []


def test_a_long_own_turnaround_is_enforced(tmp_path):
    """With 600 s after X1 the same departures break the rule: the model and the verifier both say so."""
    problem, schedule, problems = written(tmp_path, plan(600.0), (0.0, 0.0))
    assert not ua.verify(problem, schedule).ok
    assert len(problems) == 1 and "less than 600 s after X1" in problems[0]


def test_the_default_turnaround_still_applies_without_one(tmp_path):
    """No own value: T_D = 240 s after the first leg, so a departure at 50 s is refused."""
    _, _, problems = written(tmp_path, plan(None), (0.0, 0.0))
    assert len(problems) == 1 and "less than 240 s after X1" in problems[0]


@pytest.mark.parametrize("value", [-5.0, "soon"])
def test_a_bad_turnaround_in_the_file_is_one_line(tmp_path, value):
    import json

    save_flights(tmp_path / "flights.json", plan(30.0))
    raw = json.loads((tmp_path / "flights.json").read_text())
    raw["flights"][0]["turnaround_after_s"] = value
    (tmp_path / "flights.json").write_text(json.dumps(raw))
    with pytest.raises(ua.UamoptError, match="turnaround_after_s"):
        load_flights(tmp_path / "flights.json")
