"""The independent verifier (uamopt/schedule/verify.py) against the model, and planted violations."""

from __future__ import annotations

import csv
import json
import re

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from uamopt.errors import InputFileError
from uamopt.schedule import (
    Flight,
    FlightSet,
    build_problem,
    make_schedule,
    violations,
    write_schedule,
)
from uamopt.schedule.verify import verify_dir


@pytest.fixture(scope="module")
def paper_problem(paper_straight_plan):
    scenario, _, _, flights = paper_straight_plan
    return build_problem(flights, scenario)


def first_fit(problem, order=None):
    """A tiny greedy for the tests: each flight at its earliest admissible departure, or cancelled."""
    n = problem.n_flights
    on, delay = np.zeros(n, bool), np.zeros(n)
    dep0, upper = problem.planned_departure_s, problem.delay_upper_s
    partners = [[] for _ in range(n)]
    for c in problem.conflicts:  # dep_q − dep_p ∉ (lo, hi): as intervals of one's departure given the other's
        partners[c.q].append((c.p, c.intervals, +1))
        partners[c.p].append((c.q, c.intervals, -1))
    last_arrival = {}
    for f in (np.argsort(dep0, kind="stable") if order is None else order):
        req = problem.requires[f]
        if req >= 0 and not on[req]:
            continue
        g = problem.flights.aircraft_index[f]
        t = dep0[f]
        if g in last_arrival:
            t = max(t, last_arrival[g])
        moved = True
        while moved and t - dep0[f] <= upper[f]:
            moved = False
            for other, iv, sign in partners[f]:
                if on[other]:
                    lo, hi = (dep0[other] + delay[other] + iv.T) if sign > 0 else (dep0[other] + delay[other] - iv.T[::-1])
                    inside = (lo < t) & (t < hi)
                    if inside.any():
                        t, moved = float(hi[inside].max()), True
        if t - dep0[f] <= upper[f]:
            on[f], delay[f] = True, t - dep0[f]
            last_arrival[g] = t + problem.flight_time_s[f] + problem.turnaround_after_s[f]
    return on, delay


def _write(tmp_path, problem, on, delay, name="out"):
    out = tmp_path / name
    write_schedule(out, problem, make_schedule(problem, "first-fit", "stopped", on, delay))
    return out


def _edit_csv(folder, edit):
    path = folder / "schedule.csv"
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    edit({r["flight"]: r for r in rows})
    with open(path, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


def test_all_cancelled_passes(paper_problem, tmp_path):
    n = paper_problem.n_flights
    assert verify_dir(_write(tmp_path, paper_problem, np.zeros(n, bool), np.zeros(n))) == []


def test_greedy_schedule_passes_model_and_verifier(paper_problem, tmp_path):
    on, delay = first_fit(paper_problem)
    assert 60 < on.sum() < 120  # the paper case has conflicts to resolve
    assert violations(paper_problem, on, delay) == []
    assert verify_dir(_write(tmp_path, paper_problem, on, delay)) == []


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_random_orders_model_feasible_is_verifier_feasible(paper_problem, tmp_path_factory, seed):
    order = np.random.default_rng(seed).permutation(paper_problem.n_flights)
    on, delay = first_fit(paper_problem, order)
    assert violations(paper_problem, on, delay) == []
    assert verify_dir(_write(tmp_path_factory.mktemp("v"), paper_problem, on, delay)) == []


def test_verifier_finds_what_the_model_forbids(paper_problem, tmp_path):
    """Operate everything as planned: each model conflict is a verifier conflict, and vice versa."""
    n = paper_problem.n_flights
    on, delay = np.ones(n, bool), np.zeros(n)
    dep, tol = paper_problem.planned_departure_s, 1e-6  # the verifier's tolerance: touching intervals are no conflict
    model = {(c.p, c.q) for c in paper_problem.conflicts
             if np.any((c.intervals[:, 0] + tol < dep[c.q] - dep[c.p]) & (dep[c.q] - dep[c.p] < c.intervals[:, 1] - tol))}
    ids = [f.id for f in paper_problem.flights.flights]
    pattern = re.compile(r"conflict: flights (\S+) \(.*\) in cell .* and (\S+) \(")
    found = {tuple(sorted(ids.index(x) for x in pattern.match(v).groups()))
             for v in verify_dir(_write(tmp_path, paper_problem, on, delay)) if v.startswith("conflict")}
    assert model and found == model


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_model_and_verifier_agree_on_conflicts_under_random_delays(paper_problem, tmp_path_factory, seed):
    """Everything operated with random admissible delays: the same pairs conflict for both."""
    n = paper_problem.n_flights
    delay = np.random.default_rng(seed).uniform(0.0, 1.0, n) * paper_problem.delay_upper_s
    ids = [f.id for f in paper_problem.flights.flights]
    model = {tuple(sorted((ids.index(m.group(1)), ids.index(m.group(2)))))
             for m in (re.match(r"flights (\S+) and (\S+): departure gap", v)
                       for v in violations(paper_problem, np.ones(n, bool), delay))
             if m}
    pattern = re.compile(r"conflict: flights (\S+) \(.*\) in cell .* and (\S+) \(")
    found = {tuple(sorted(ids.index(x) for x in pattern.match(v).groups()))
             for v in verify_dir(_write(tmp_path_factory.mktemp("r"), paper_problem, np.ones(n, bool), delay))
             if v.startswith("conflict")}
    assert model and found == model


def _two_flights(dep_b, tracks=None, aircraft=("A1", "A2")):
    tracks = tracks or [[[25, 25, 125], [475, 25, 125]]] * 2
    flights = tuple(
        Flight(f"F{i + 1}", aircraft[i], "r", "a", "b", 25.0, dep, 100.0, np.array(t, dtype=float))
        for i, (dep, t) in enumerate(zip((0.0, dep_b), tracks, strict=True))
    )
    fs = FlightSet(cell=(50.0, 50.0, 30.0), conflict_radius=1, flights=flights, service_end_s=3600.0)
    return build_problem(fs)


def test_planted_conflict_same_route_same_time(tmp_path):
    problem = _two_flights(0.0)
    found = verify_dir(_write(tmp_path, problem, np.ones(2, bool), np.zeros(2)))
    assert len(found) == 1 and "conflict" in found[0] and "F1" in found[0] and "F2" in found[0]
    assert "in cell (1, 0, 4)" in found[0]
    # the model's forbidden gap on one straight track: two cells of 2 s each in the 3x3x3 zone → (−4, 4)
    assert len(problem.conflicts) == 1
    np.testing.assert_allclose(problem.conflicts[0].intervals, [[-4.0, 4.0]])
    # 4 s apart exactly: touching, no conflict; 3.9 s: conflict
    assert verify_dir(_write(tmp_path, problem, np.ones(2, bool), np.array([0.0, 4.0]), "touch")) == []
    assert len(verify_dir(_write(tmp_path, problem, np.ones(2, bool), np.array([0.0, 3.9]), "close"))) == 1


def test_hand_made_conflict_free_crossing(tmp_path):
    # two tracks crossing at (250, 250): 10 s apart is clear, together is a conflict
    tracks = [[[25, 250, 125], [475, 250, 125]], [[250, 25, 125], [250, 475, 125]]]
    problem = _two_flights(10.0, tracks)
    assert verify_dir(_write(tmp_path, problem, np.ones(2, bool), np.zeros(2))) == []
    assert violations(problem, np.ones(2, bool), np.zeros(2)) == []
    crash = verify_dir(_write(tmp_path, problem, np.ones(2, bool), np.array([10.0, 0.0]), "crash"))
    assert len(crash) == 1 and "conflict" in crash[0]


def test_planted_rule_violations(paper_problem, tmp_path):
    on, delay = first_fit(paper_problem)
    out = _write(tmp_path, paper_problem, on, delay)
    fl = paper_problem.flights.flights
    chain = next(c for c in paper_problem.chains if on[c].all())
    outbound, ret = fl[chain[0]].id, fl[chain[1]].id

    def cancel_outbound(rows):
        rows[outbound].update(operated="0", departure_s="", arrival_s="")
    _edit_csv(out, cancel_outbound)
    found = verify_dir(out)
    assert any(f"{ret}: return operated without its outbound {outbound}" in v for v in found)
    assert any(v.startswith("summary.json: operated") for v in found)

    out = _write(tmp_path, paper_problem, on, delay, "turn")

    def early_return(rows):
        r = rows[ret]
        new_dep = float(r["departure_s"]) - 100.0
        r.update(departure_s=repr(new_dep), delay_s=repr(new_dep - float(r["planned_departure_s"])),
                 arrival_s=repr(float(r["arrival_s"]) - 100.0))
    _edit_csv(out, early_return)
    assert any(f"flight {ret}: departs" in v and "Eqs. 27-28" in v for v in verify_dir(out))

    out = _write(tmp_path, paper_problem, on, delay, "late")
    last = fl[chain[-1]]

    def too_late(rows):
        r = rows[last.id]
        d = last.max_delay_s + 5.0
        dep = last.planned_departure_s + d
        r.update(delay_s=repr(d), departure_s=repr(dep), arrival_s=repr(dep + last.flight_time_s))
    _edit_csv(out, too_late)
    found = verify_dir(out)
    assert any(f"flight {last.id}: delay" in v and "Eq. 29" in v for v in found)

    out = _write(tmp_path, paper_problem, on, delay, "arrival")
    _edit_csv(out, lambda rows: rows[outbound].update(arrival_s=repr(float(rows[outbound]["arrival_s"]) - 1.0)))
    assert any(f"flight {outbound}: arrival" in v for v in verify_dir(out))


def test_summary_objective_checked(paper_problem, tmp_path):
    on, delay = first_fit(paper_problem)
    out = _write(tmp_path, paper_problem, on, delay)
    summary = json.loads((out / "summary.json").read_text())
    summary["objective"] -= 1.0
    (out / "summary.json").write_text(json.dumps(summary))
    assert [v.split(" =")[0] for v in verify_dir(out)] == ["summary.json: objective"]


def test_bad_folders_raise(tmp_path):
    with pytest.raises(InputFileError, match="not a folder"):
        verify_dir(tmp_path / "missing")
    with pytest.raises(InputFileError, match=r"missing flights\.json"):
        verify_dir(tmp_path)
