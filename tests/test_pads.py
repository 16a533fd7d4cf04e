"""The vertiport variant (issue 18, item 2): vertical take-off and landing phases
(``network.vertical_phases``, ``aircraft.vertical_rate_mps``) and vertiport pads (``network.pads``,
family ``pads``, shape ``cumulative``; uamopt/schedule/families/pads.py).

Expected values come from the test's own arithmetic (flight times from the track's geometry, pad
holds counted by a sweep written here), never from the family's code."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import uamopt as ua
from uamopt.errors import UamoptError
from uamopt.scenario import load_scenario
from uamopt.schedule import build_problem, generate_plan
from uamopt.solvers import bruteforce

PAPER_CASE = Path(__file__).resolve().parents[1] / "models" / "paper_case.toml"
ON = ["network.vertical_phases=true"]


def plan(network, keys, aircraft=None):
    scenario = load_scenario(PAPER_CASE, keys)
    flights = generate_plan(scenario, network, seed=0, max_delay_scale=1.0)
    if aircraft is not None:
        keep = set(sorted({f.aircraft for f in flights.flights})[:aircraft])
        flights = dataclasses.replace(flights, flights=tuple(f for f in flights.flights if f.aircraft in keep))
    return scenario, flights


def max_pad_load(problem, schedule, pads: int) -> int:
    """The largest number of aircraft on one vertiport's pads at once, counted here: a take-off holds
    [dep, dep + climb), a landing [arr − descent, arr + ΔT); ΔT = T_D after an odd leg, T_R after even."""
    fs = problem.flights
    holds: dict[str, list[tuple[float, float]]] = {}
    legs: dict[str, int] = {}
    order = sorted(range(len(fs.flights)), key=lambda i: fs.flights[i].planned_departure_s)
    leg = {}
    for i in order:
        f = fs.flights[i]
        legs[f.aircraft] = legs.get(f.aircraft, 0) + 1
        leg[i] = legs[f.aircraft]
    for i, f in enumerate(fs.flights):
        if not schedule.operated[i]:
            continue
        wp = f.waypoints
        climb, descent = (wp[1][2] - wp[0][2]) / 2.5, (wp[-2][2] - wp[-1][2]) / 2.5
        cruise = sum(math.dist(a, b) for a, b in zip(wp[1:-2], wp[2:-1])) / f.speed_mps
        dep = f.planned_departure_s + schedule.delay_s[i]
        arr = dep + climb + cruise + descent
        gap = 240.0 if leg[i] % 2 == 1 else 360.0
        holds.setdefault(f.origin, []).append((dep, dep + climb))
        holds.setdefault(f.destination, []).append((arr - descent, arr + gap))
    worst = 0
    for spans in holds.values():
        for t, _ in spans:
            worst = max(worst, sum(1 for a, b in spans if a <= t + 1e-6 and b > t + 1e-6))
    return worst


@pytest.fixture(scope="module")
def network(paper_straight_plan):
    return paper_straight_plan[2]


def test_vertical_phases_add_the_climb_and_descent_at_the_rate(network):
    _, cruise = plan(network, [])
    _, phased = plan(network, ON)
    _, slow = plan(network, ON + ["aircraft.vertical_rate_mps=2.0"])
    for a, b, c in zip(cruise.flights[:4], phased.flights[:4], slow.flights[:4]):
        alt = a.waypoints[0][2]  # the cruise starts at the cruise altitude above the vertiport
        assert b.waypoints[0].tolist() == [a.waypoints[0][0], a.waypoints[0][1], 0.0]
        assert b.waypoints[-1].tolist() == [a.waypoints[-1][0], a.waypoints[-1][1], 0.0]
        hand = sum(math.dist(p, q) for p, q in zip(a.waypoints[:-1], a.waypoints[1:])) / 25.0
        assert b.flight_time_s == pytest.approx(hand + 2 * alt / 2.5, abs=1e-9)
        assert c.flight_time_s == pytest.approx(hand + 2 * alt / 2.0, abs=1e-9)  # the rate key acts


def test_default_scenario_has_no_pads_and_no_phases(network):
    scenario, flights = plan(network, [])
    problem = build_problem(flights, scenario)
    assert [f.name for f in problem.families if f.name == "pads"] == []
    assert all(f.vertical_rate_mps is None for f in flights.flights)


@pytest.fixture(scope="module")
def small(network):
    """Four aircraft of the paper-case plan with vertical phases: without pads, with one and with two."""
    scenario, flights = plan(network, ON, aircraft=4)
    with_pads = {n: build_problem(flights, load_scenario(PAPER_CASE, ON + [f"network.pads={n}"])) for n in (1, 2)}
    return build_problem(flights, scenario), with_pads


def test_one_pad_is_kept_by_every_solver_and_binds(small):
    free, pads = small
    unlimited = ua.solve(free, "highs", time_limit_s=60)
    assert max_pad_load(free, unlimited, 1) > 1  # without the family the optimum puts two aircraft on a pad
    results = {}
    for solver in ("highs", "cpsat", "timeindexed", "greedy", "soa"):
        s = ua.solve(pads[1], solver, time_limit_s=30)
        assert max_pad_load(pads[1], s, 1) <= 1, solver
        assert ua.verify(pads[1], s).ok, solver
        results[solver] = s
    assert results["highs"].status == "optimal"
    assert results["highs"].objective > unlimited.objective  # a real restriction
    assert results["highs"].objective <= results["greedy"].objective + 1e-9


def test_more_pads_need_the_cumulative_shape(small):
    _, pads = small
    with pytest.raises(UamoptError, match="no encoder for the family 'pads'.*cpsat"):
        ua.solve(pads[2], "highs", time_limit_s=10)
    one, two = (ua.solve(pads[n], "cpsat", time_limit_s=30) for n in (1, 2))
    assert max_pad_load(pads[2], two, 2) <= 2
    assert two.objective <= one.objective + 1e-9  # a second pad never hurts


def test_cumulative_agrees_with_the_brute_force(network):
    """Two pads on a tiny instance: the brute force (branching on every three holds) and CP-SAT's
    AddCumulative find the same optimum (CP-SAT's covers holds by whole 0.01 s units: at most
    that per flight worse)."""
    lex = ["network.routes=[[\"V1\",\"V5\"]]"]
    scenario, flights = plan(network, ON + lex + ["schedule.aircraft=3",
                                            "schedule.flights=3", "schedule.first_departure_window_s=0.0"])
    free = build_problem(flights, scenario, objective="lexicographic")
    two = build_problem(flights, load_scenario(PAPER_CASE, ON + lex + ["network.pads=2"]), objective="lexicographic")
    exact = bruteforce.solve(two)
    assert exact.status == "optimal"
    assert exact.objective > bruteforce.solve(free).objective + 1e-9  # two pads bind here
    cp = ua.solve(two, "cpsat", time_limit_s=30)
    assert max_pad_load(two, cp, 2) <= 2 and max_pad_load(two, exact, 2) <= 2
    assert exact.objective <= cp.objective + 1e-9
    assert cp.objective - exact.objective <= 0.01 * len(flights.flights) * two.objective.per_delay + 1e-9


def test_pads_of_a_vertiport_override_the_network(network):
    keys = ON + ["network.pads=1", 'network.vertiports=[{name="V1", x=300.0, y=300.0, pads=3}, '
                 '{name="V2", x=300.0, y=4220.0}, {name="V3", x=2220.0, y=300.0}, {name="V4", x=2220.0, y=4220.0}, '
                 '{name="V5", x=1260.0, y=2260.0}]']
    scenario = load_scenario(PAPER_CASE, keys)
    assert scenario.network.pads_of() == {"V1": 3, "V2": 1, "V3": 1, "V4": 1, "V5": 1}
    _, flights = plan(network, ON, aircraft=4)
    family = next(f for f in build_problem(flights, scenario).families if f.name == "pads")
    assert family.record()["pads"]["V1"] == 3
    assert family.residual().resources[int(family.residual().resource[0])] == "V1"  # only V1 is cumulative
    assert set(family.residual().resource.tolist()) == {family.resources.index("V1")}
