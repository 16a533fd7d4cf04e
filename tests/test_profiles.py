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


@pytest.mark.parametrize(("text", "match"), [
    ("solver = 'highs'\ntime_limit_s = [1", "malformed TOML"),
    ("solver = 'highs'\ntimelimit = 5", "unknown key 'timelimit'"),
    ("time_limit_s = 5", "missing key 'solver'"),
    ("solver = 'gurobi'", "unknown solver 'gurobi'"),
    ("solver = 'highs'\ntime_limit_s = 0", r"time_limit_s must be a number in \(0, 1e\+07\], got 0"),
    ("solver = 'highs'\nthreads = 0", r"threads must be an integer in \[1, \d+\], got 0"),
    ("solver = 'highs'\ntime_limit_s = 'soon'", r"time_limit_s must be a number in \(0, 1e\+07\], got 'soon'"),
    ("solver = 'highs'\ntime_limit_s = nan", r"time_limit_s must be a number in \(0, 1e\+07\], got nan"),
    ("solver = 'highs'\ntime_limit_s = true", r"time_limit_s must be a number in \(0, 1e\+07\], got True"),
    ("solver = 'cpsat'\nseed = -1", r"seed must be an integer in \[0, 2147483647\], got -1"),
    ("solver = 'cpsat'\nseed = 1e20", r"seed must be an integer in \[0, 2147483647\], got 1e\+20"),
    ("solver = 'cpsat'\nseed = 100000000000000000000", "seed must be an integer"),
    ("solver = 'highs'\nseed = '7'", "seed must be an integer in"),
    ("solver = 'highs'\nseed = true", "seed must be an integer in"),
    ("solver = 'cpsat'\nthreads = 100000", r"threads must be an integer in \[1, \d+\], got 100000"),
    ("solver = 'highs'\n[options]\nmip_rel_gap = -1", "HiGHS refuses mip_rel_gap = -1"),
    ("solver = 'highs'\n[options]\nmip_rel_gap = 'abc'", "HiGHS refuses mip_rel_gap = 'abc'"),
    ("solver = 'highs'\n[options]\nmip_rel_gap = true", "HiGHS refuses mip_rel_gap = True"),
    ("solver = 'highs'\n[options]\nmip_gap_rel = 0.1", "HiGHS has no option mip_gap_rel"),
    ("solver = 'cpsat'\n[options]\nnum_wrokers = 2", "CP-SAT has no parameter num_wrokers"),
    ("solver = 'cpsat'\n[options]\nlinearization_level = 'high'", "CP-SAT refuses linearization_level = 'high'"),
    ("solver = 'cpsat'\n[options]\nnum_workers = 4", "option num_workers is set by the profile's threads"),
    ("solver = 'highs'\n[options]\ntime_limit = 4", "option time_limit is set by the profile's time_limit_s"),
    ("solver = 'cpsat'\n[options]\ntime_unit_s = 0", r"option time_unit_s must be a number in \[1e-06, 1e\+07\], got 0"),
    ("solver = 'greedy'\n[options]\nexact_gaps = 1", "option exact_gaps must be true or false, got 1"),
    ("solver = 'greedy'\n[options]\nmip_rel_gap = 0", "unknown option 'mip_rel_gap' for solver greedy"),
    ("solver = 'rolling'\n[options]\ninner = 'gurobi'", "option inner = 'gurobi' is not one of"),
    ("solver = 'timeindexed'\n[options]\nstep_s = -10", r"option step_s must be a number in \[0.001, 1e\+07\], got -10"),
    ("solver = 'soa'\n[options]\ngenerations = 2.5", "option generations must be int"),
    ("solver = 'highs'\noptions = 3", "options. must be a table"),
])
def test_bad_profile_is_a_one_line_error(tmp_path, text, match):
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(UamoptError, match=match) as info:
        load_profile(path)
    line = info.value.line()
    assert "\n" not in line and " (" in line and "): " in line  # what (where): how to fix


def test_non_utf8_profile_is_a_one_line_error(tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes("description = 'Zürich'\nsolver = 'greedy'\n".encode("latin-1"))
    with pytest.raises(UamoptError, match="the profile is not UTF-8 text"):
        load_profile(path)


def test_valid_pass_through_option_is_accepted():
    """An option HiGHS accepts is not refused and the run still proves the hand-checked optimum
    (tests/instances.py: cancel A1, fly B1 and C1, W = −0.8)."""
    problem = crossing_problem("weighted", (0.6, 0.4))
    proved = solve(problem, SolverProfile("highs", time_limit_s=10, options={"presolve": "off"}))
    assert proved.status == "optimal" and proved.objective == pytest.approx(-0.8)


def test_missing_profile_lists_the_shipped_ones(tmp_path):
    with pytest.raises(UamoptError, match="solver profile not found: nosuch") as info:
        load_profile("nosuch")
    assert all(p.stem in info.value.fix for p in PROFILES)
    with pytest.raises(UamoptError, match="solver profile not found"):
        load_profile(tmp_path / "absent.toml")


def test_profile_object_validates_its_fields():
    with pytest.raises(UamoptError, match="unknown solver 'simplex'"):
        SolverProfile("simplex")
