"""The worked example of docs/variants.md: ``schedule.departure_spacing_s``, a family of the
``pairs`` shape (uamopt/schedule/families/spacing.py) that every solver encodes without a change.

Checked with the test's own arithmetic (departures grouped by the flights' origin names) and by
the independent verifier (which groups by the first waypoint)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

import uamopt as ua
from uamopt.cli import main
from uamopt.errors import UamoptError
from uamopt.schedule import Flight, FlightSet, build_problem
from uamopt.solvers import SolverProfile, bruteforce

PAPER_CASE = Path(__file__).resolve().parents[1] / "models" / "paper_case.toml"
SPACING_S = 90.0


def closest_same_origin_gap(problem, schedule) -> float:
    dep = problem.planned_departure_s + schedule.delay_s
    origin = [f.origin for f in problem.flights.flights]
    gaps = [abs(dep[a] - dep[b]) for a in range(len(dep)) for b in range(a + 1, len(dep))
            if origin[a] == origin[b] and schedule.operated[a] and schedule.operated[b]]
    return min(gaps) if gaps else np.inf


@pytest.fixture(scope="module")
def pair(paper_straight_plan):
    """(problem without spacing, problem with it) on the first four aircraft of the paper-case plan."""
    from uamopt.scenario import load_scenario

    scenario, _, _, flights = paper_straight_plan
    keep = set(sorted({f.aircraft for f in flights.flights})[:4])
    subset = dataclasses.replace(flights, flights=tuple(f for f in flights.flights if f.aircraft in keep))
    spaced = load_scenario(PAPER_CASE, [f"schedule.departure_spacing_s={SPACING_S}"])
    return build_problem(subset, scenario), build_problem(subset, spaced)


def test_the_key_adds_the_family_and_changes_the_optimum(pair):
    plain, spaced = pair
    assert [f.name for f in spaced.extra_families] == ["departure_spacing"] and not plain.extra_families
    free = ua.solve(plain, "highs", time_limit_s=60)
    assert closest_same_origin_gap(plain, free) < SPACING_S  # without the family the optimum breaks the rule
    held = ua.solve(spaced, "highs", time_limit_s=60)
    assert held.status == "optimal" and closest_same_origin_gap(spaced, held) >= SPACING_S - 1e-6
    assert held.objective > free.objective  # a real restriction: the optimum got worse
    assert ua.verify(spaced, held).ok and not ua.verify(spaced, free).ok


@pytest.mark.parametrize("solver", ["cpsat", "timeindexed", "greedy", "soa"])
def test_every_solver_keeps_the_spacing(pair, solver):
    _, spaced = pair
    schedule = ua.solve(spaced, solver, time_limit_s=20)
    assert closest_same_origin_gap(spaced, schedule) >= SPACING_S - 1e-6
    assert ua.verify(spaced, schedule).ok


def test_bruteforce_agrees_on_a_tiny_instance():
    track = lambda y: np.array([[10.0, y, 30.0], [400.0, y, 30.0]])  # noqa: E731 - parallel tracks far apart: no conflicts
    flights = tuple(Flight(id=f"F{i}", aircraft=f"A{i}", route="V1-V2", origin="V1", destination="V2", speed_mps=25.0,
                           planned_departure_s=10.0 * i, max_delay_s=120.0, waypoints=track(50.0 + 200.0 * i))
                    for i in range(4))
    fs = FlightSet(cell=(50.0, 50.0, 30.0), conflict_radius=1, flights=flights)
    from uamopt.schedule.families.spacing import departure_spacing

    base = build_problem(fs, objective="lexicographic")
    problem = dataclasses.replace(base, extra_families=(departure_spacing(fs, 45.0),))
    assert len(base.pairs) == 0 and len(problem.pairs) == 6
    oracle = bruteforce.solve(problem)
    for solver in ("highs", "cpsat"):
        got = ua.solve(problem, SolverProfile(solver, time_limit_s=20))
        assert got.objective == pytest.approx(oracle.objective, abs=1e-7)
    # all four fly 45 s apart: delays 0, 35, 70, 105 s (hand-checked), total 210 s
    assert oracle.operated.all() and oracle.total_delay_s == pytest.approx(210.0)


def test_the_verifier_checks_the_recorded_spacing(pair, tmp_path):
    plain, _spaced = pair
    free = ua.solve(plain, "highs", time_limit_s=60)
    folder = tmp_path / "s"
    ua.schedule.write_schedule(folder, plain, free)
    assert main(["verify", str(folder)]) == 0
    summary = json.loads((folder / "summary.json").read_text())
    summary["families"] = [{"name": "departure_spacing", "shape": "pairs", "spacing_s": SPACING_S}]
    (folder / "summary.json").write_text(json.dumps(summary))
    assert main(["verify", str(folder)]) == 1
    summary["families"] = [{"name": "departure_spacing", "spacing_s": "ninety"}]
    (folder / "summary.json").write_text(json.dumps(summary))
    assert main(["verify", str(folder)]) == 2


def test_rolling_refuses_the_family(pair):
    _, spaced = pair
    with pytest.raises(UamoptError, match=r"family 'departure_spacing'.*highs"):
        ua.solve(spaced, "rolling")
