"""One status, one meaning (issue 40, point 5): ``termination`` (why a solver stopped) and
``proved_for`` (what a proof is about), with the status word derived from them.

Every claim a solver makes is checked against what an independent computation says: a proof of
optimality for continuous delays against the enumeration of tests/oracles.py (which shares no
code with the solvers), a proof on a restriction against the same (a restriction's optimum is
never below the continuous one), a heuristic's answer against "it proves nothing"."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from instances import crossing_problem
from oracles import broken, exact_optimum, model_data, score
from strategies import tiny_problems

import uamopt as ua
from uamopt.errors import UamoptError
from uamopt.schedule import write_schedule
from uamopt.schedule.model import STATUSES, TERMINATIONS, Schedule
from uamopt.schedule.verify import verify_dir
from uamopt.solvers import SolverProfile, bruteforce, solve

OBJ_TOL = 1e-6
EXACT = ["highs", "cpsat", "timeindexed", "exact", "discovery", "scip", "bruteforce"]  # profiles, and the oracle solver
HEURISTICS = ["greedy", "ga", "soa", "rolling"]


def test_the_table_of_pairs():
    """Each valid (termination, proved_for) gives one status word, each word comes from one pair,
    and a pair that claims a proof without saying of what (or the reverse) is refused."""
    n = 2
    words = {}
    refused = []
    for termination in TERMINATIONS:
        for proved_for in ("continuous", "restricted", "none"):
            try:
                s = Schedule("hand", termination, np.zeros(n, bool), np.zeros(n), None, proved_for=proved_for)
            except UamoptError as exc:
                refused.append(exc.line())
                continue
            words.setdefault(s.status, []).append((termination, proved_for))
    assert len(refused) == 3 * len(TERMINATIONS) - len(STATUSES) and all("proved_for" in line for line in refused)
    assert set(words) == set(STATUSES) and all(len(v) == 1 for v in words.values())
    assert words["optimal"] == [("optimal", "continuous")] and words["optimal_on_grid"] == [("optimal", "restricted")]
    assert words["infeasible"] == [("infeasible", "continuous")]  # a restriction's infeasibility is no answer
    assert words["feasible"] == [("stopped", "none")] and words["no_solution"] == [("no_solution", "none")]
    with pytest.raises(UamoptError):
        Schedule("hand", "error", np.zeros(n, bool), np.zeros(n), None)  # the old unused word is gone


@settings(max_examples=12, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(tiny_problems(max_flights=4))
def test_every_claim_holds_against_the_enumeration(case):
    """Per solver on tiny instances: (optimal, continuous) only at the enumerated optimum;
    (optimal, restricted) never below it; a heuristic never claims a proof; every schedule keeps
    the rows as the oracle reads them; the bound is never above the optimum."""
    _, problem = case
    data = model_data(problem)
    best, _, _ = exact_optimum(data)
    for name in EXACT + HEURISTICS:
        result = (bruteforce.solve(problem) if name == "bruteforce"
                  else ua.solve(problem, name, time_limit_s=20.0, threads=1))
        assert result.found and broken(data, result.operated, result.delay_s) == [], name
        value = score(data, result.operated, result.delay_s)
        if result.bound is not None:
            assert result.bound <= best + OBJ_TOL, name
        if name in HEURISTICS:
            assert result.proved_for == "none" and result.termination in ("stopped", "time_limit"), name
        if (result.termination, result.proved_for) == ("optimal", "continuous"):
            assert value == pytest.approx(best, abs=OBJ_TOL), name
        elif result.termination == "optimal":
            assert result.proved_for == "restricted" and value >= best - OBJ_TOL, name


@pytest.mark.parametrize("name", ["highs", "cpsat", "discovery", "scip"])
def test_the_exact_solvers_do_prove_one(name):
    """The claims above are not vacuous: on the crossing instance (tests/instances.py) each exact
    solver proves its schedule optimal for continuous delays, at the enumerated optimum."""
    problem = crossing_problem("lexicographic", (0.6, 0.4))
    best, _, _ = exact_optimum(model_data(problem))
    result = ua.solve(problem, name, time_limit_s=20.0, threads=1)
    assert (result.termination, result.proved_for, result.status) == ("optimal", "continuous", "optimal")
    assert score(model_data(problem), result.operated, result.delay_s) == pytest.approx(best, abs=OBJ_TOL)


@pytest.mark.parametrize(("name", "engine_says"), [("highs", "convergenceCriteriaSatisfied"), ("scip", "gaplimit")])
def test_a_gap_rule_is_not_a_proof(name, engine_says):
    """HiGHS or SCIP told to stop at a 1 % relative gap on the paper case (120 flights, weighted) stops
    with its bound short of its schedule: ``stopped`` (status ``feasible``), never ``optimal`` (before:
    optimal, for HiGHS). For scip it is also the test that its ``mip_rel_gap`` option acts (at 0 it
    proves this instance: −43.18929, 2026-12-08)."""
    import sys

    sys.path.insert(0, str(Path(__file__).parent / "benchmarks"))
    from bench_exact import ladder_problem

    result = solve(ladder_problem(120), SolverProfile(name, time_limit_s=120.0, threads=1,
                                                      options={"mip_rel_gap": 0.01}))
    assert result.extras["engine_termination"] == engine_says  # the engine's gap rule met
    # regression value, not vacuous: on this instance the 1 % rule stops with the gap open (measured
    # 2026-12-08: HiGHS −43.0886 against −43.3979, SCIP −43.0232 against −43.2112); a closed gap would say optimal
    assert result.objective - result.bound > 1e-6
    assert (result.termination, result.proved_for, result.status) == ("stopped", "none", "feasible")
    assert not result.status.startswith("optimal")


def test_summary_round_trip_and_the_verifier_checks_the_three_agree(tmp_path):
    problem = crossing_problem("weighted", (0.6, 0.4))
    schedule = ua.solve(problem, "highs", time_limit_s=20)
    out = tmp_path / "s"
    write_schedule(out, problem, schedule)
    summary = json.loads((out / "summary.json").read_text())
    assert (summary["status"], summary["termination"], summary["proved_for"]) == ("optimal", "optimal", "continuous")
    again = ua.load_schedule(out)
    assert (again.termination, again.proved_for, again.status) == ("optimal", "continuous", "optimal")
    assert verify_dir(out) == []
    # a hand-edited summary whose status claims more than its termination: the verifier says so
    summary["termination"], summary["proved_for"] = "time_limit", "none"
    (out / "summary.json").write_text(json.dumps(summary))
    lines = verify_dir(out)
    assert any("status optimal with termination 'time_limit'" in v for v in lines), lines
    # a folder written before the split (status only) is read with the pair its status stands for
    for key in ("termination", "proved_for"):
        del summary[key]
    summary["status"] = "feasible"
    (out / "summary.json").write_text(json.dumps(summary))
    old = ua.load_schedule(out)
    assert (old.termination, old.proved_for) == ("stopped", "none")
