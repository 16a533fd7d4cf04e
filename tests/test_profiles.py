"""Solver profiles (solvers/*.toml) and ``load_profile``: every shipped profile loads as written and
solves a tiny instance whose optimum is known; a bad profile is a one-line error."""

from __future__ import annotations

import tomllib

import pytest
from checks import OBJ_TOL, assert_verified
from conftest import ROOT
from instances import crossing_problem

from uamopt.errors import UamoptError
from uamopt.solvers import SOLVERS, SolverProfile, bruteforce, load_profile, solve

PROFILES = sorted((ROOT / "solvers").glob("*.toml"))
EXACT = {"highs", "cpsat"}  # proven optimal on this instance (its times are whole seconds: CP-SAT exact too)


def test_every_registered_solver_has_a_profile():
    assert {p.stem for p in PROFILES} == set(SOLVERS) | {"exact"}  # exact.toml: the time-indexed solver at scale
    assert load_profile("exact").solver in SOLVERS


@pytest.mark.parametrize("path", PROFILES, ids=[p.stem for p in PROFILES])
def test_shipped_profile_loads_as_written_and_solves(path):
    raw = tomllib.loads(path.read_text(encoding="utf-8"))
    by_name, by_path = load_profile(path.stem), load_profile(path)
    assert by_name == by_path
    assert (by_name.name, by_name.solver) == (path.stem, raw["solver"])
    assert by_name.time_limit_s == raw.get("time_limit_s", 60.0) and by_name.seed == raw.get("seed", 0)
    assert by_name.threads == raw.get("threads", 2) and by_name.options == raw.get("options", {})
    # the crossing instance (tests/instances.py): greedy cancels two flights, the optimum delays one 6 s
    problem = crossing_problem("weighted", (0.1, 0.9))
    optimum = bruteforce.solve(problem).objective
    schedule = solve(problem, path.stem)
    assert schedule.solver == by_name.solver
    assert_verified(problem, schedule)
    assert schedule.objective >= optimum - OBJ_TOL
    if by_name.solver in EXACT:
        assert schedule.status == "optimal" and schedule.objective == pytest.approx(optimum, abs=OBJ_TOL)
    elif by_name.solver in ("ga", "soa"):
        assert schedule.operated.all()  # the 10 s grid's best: A1 delayed 10 s
    elif by_name.solver == "greedy":
        assert schedule.operated_count == 1


@pytest.mark.parametrize("text, match", [
    ("solver = 'highs'\ntime_limit_s = [1", "malformed TOML"),
    ("solver = 'highs'\ntimelimit = 5", "unknown key 'timelimit'"),
    ("time_limit_s = 5", "missing key 'solver'"),
    ("solver = 'gurobi'", "unknown solver 'gurobi'"),
    ("solver = 'highs'\ntime_limit_s = 0", "time_limit_s must be positive, got 0.0"),
    ("solver = 'highs'\nthreads = 0", "threads must be at least 1, got 0"),
    ("solver = 'highs'\ntime_limit_s = 'soon'", "invalid value in solver profile"),
])
def test_bad_profile_is_a_one_line_error(tmp_path, text, match):
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(UamoptError, match=match) as info:
        load_profile(path)
    line = info.value.line()
    assert "\n" not in line and " (" in line and "): " in line  # what (where): how to fix


def test_missing_profile_lists_the_shipped_ones(tmp_path):
    with pytest.raises(UamoptError, match="solver profile not found: nosuch") as info:
        load_profile("nosuch")
    assert all(p.stem in info.value.fix for p in PROFILES)
    with pytest.raises(UamoptError, match="solver profile not found"):
        load_profile(tmp_path / "absent.toml")


def test_profile_object_validates_its_fields():
    with pytest.raises(UamoptError, match="unknown solver 'simplex'"):
        SolverProfile("simplex")
