"""The families seam (uamopt/schedule/families): the paper's model as five families, the
one-line refusal of a solver without an encoder, and the ``extra=`` callbacks of docs/variants.md."""

from __future__ import annotations

import dataclasses

import numpy as np
import pyomo.environ as pyo
import pytest

import uamopt as ua
from uamopt.errors import UamoptError
from uamopt.schedule import violations
from uamopt.solvers import SolverProfile


def test_the_paper_model_is_five_families(paper_problem):
    assert [(f.name, f.shape) for f in paper_problem.families] == [
        ("delay_bounds", "bounds"), ("must_operate", "must_operate"), ("precedence", "precedence"),
        ("turnaround", "turnaround"), ("conflicts", "pairs")]
    t = paper_problem.turnaround
    chains = sum(len(c) * (len(c) - 1) // 2 for c in paper_problem.chains)
    assert len(t) == chains  # every ordered pair of one aircraft's flights


def test_turnaround_rows_against_the_flights(paper_problem):
    # need = D_e + T_e + ΔT_e − D_f, recomputed from the Flight objects (not the family's arrays)
    fl = paper_problem.flights.flights
    t = paper_problem.turnaround
    for e, f, need in list(zip(t.e.tolist(), t.f.tolist(), t.need_s.tolist(), strict=True))[:40]:
        assert fl[e].aircraft == fl[f].aircraft and fl[e].planned_departure_s < fl[f].planned_departure_s
        assert need == pytest.approx(fl[e].planned_departure_s + fl[e].length_m / fl[e].speed_mps
                                     + fl[e].turnaround_after_s - fl[f].planned_departure_s)


def test_extra_callbacks_act_in_highs_and_cpsat(paper_problem):
    flights = paper_problem.flights
    keep = set(sorted({f.aircraft for f in flights.flights})[:3])
    small = ua.build_problem(dataclasses.replace(flights, flights=tuple(f for f in flights.flights if f.aircraft in keep)),
                             objective="lexicographic")
    free = ua.solve(small, "highs", time_limit_s=30)
    # push flight 0 at least 100 s later than it flies in the free optimum: the callback's row must hold
    late = float(free.delay_s[0]) + 100.0
    assert late <= small.delay_upper_s[0]

    def highs_rule(m, problem):
        m.late_first = pyo.Constraint(expr=m.delay[0] >= late * m.operate[0])
        m.first_flies = pyo.Constraint(expr=m.operate[0] == 1)

    def cpsat_rule(model, problem, operate, delay):
        model.add(delay[0] >= round(late / 0.01))
        model.add(operate[0] == 1)

    for solver, rule in (("highs", highs_rule), ("cpsat", cpsat_rule)):
        got = ua.solve(small, solver, time_limit_s=30, extra=rule)
        assert got.operated[0] and got.delay_s[0] >= late - 1e-6, solver
        assert not violations(small, got.operated, got.delay_s)
        assert got.objective >= free.objective - 1e-9
    with pytest.raises(UamoptError, match="takes no extra= callback"):
        ua.solve(small, "greedy", extra=highs_rule)


def test_a_family_of_an_unknown_shape_is_refused_by_every_solver(paper_problem):
    @dataclasses.dataclass(frozen=True)
    class Holding:
        name = "holding"
        shape = "holding_pattern"
        description = "not encoded anywhere"

        def violations(self, problem, operated, delay_s, tol_s):
            return []

    problem = dataclasses.replace(paper_problem, extra_families=(Holding(),))
    for solver in ("greedy", "highs", "cpsat", "timeindexed", "rolling"):
        with pytest.raises(UamoptError, match=r"no encoder for the family 'holding'.*no solver supports"):
            ua.solve(problem, SolverProfile(solver, time_limit_s=5))


def test_violations_come_from_the_families(paper_problem):
    n = paper_problem.n_flights
    everything = np.ones(n, dtype=bool)
    broken = violations(paper_problem, everything, np.zeros(n))
    assert any("forbidden" in line and "(conflicts)" in line for line in broken)
    assert any("turnaround" in line for line in broken) or any("forbidden" in line for line in broken)
