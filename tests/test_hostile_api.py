"""Hostile arguments to the Python API and the boundary numbers around it (docs/interfaces.md, the
house rule): a wrong-typed argument is a ``TypeError``/``ValueError`` naming the function's argument
and what it must be, or a one-line :class:`~uamopt.errors.UamoptError`; never a raw error from deep
inside ("argument of type 'NoneType' is not iterable", "operands could not be broadcast", an
AttributeError, "need at least one array to concatenate", pydantic's many-line ValidationError,
"invalid literal for int()"). Through the command line: one ``error:`` line, exit 2, nothing
written. Each test names what today's code did instead ("Was: ...").
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import PAPER_CASE
from test_cli import assert_one_line_error, cli

import uamopt as ua

PAPER = str(PAPER_CASE)
BIG = "1" + "0" * 400  # a TOML/JSON integer of 401 digits: float() of it overflows


@pytest.fixture(scope="module")
def scenario():
    return ua.load_scenario(PAPER_CASE)


@pytest.fixture(scope="module")
def network(scenario):
    from uamopt.grid import AirspaceGrid
    from uamopt.schedule import straight_network

    return dict(straight_network(scenario, AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent)))


@pytest.fixture(scope="module")
def flights(scenario, network):
    return ua.generate_flights(scenario, network, seed=0)


@pytest.fixture(scope="module")
def problem(network):
    small = ua.load_scenario(PAPER_CASE, ["schedule.flights=12", "schedule.aircraft=4"])
    return ua.build_problem(ua.generate_flights(small, network, seed=0), small)


@pytest.fixture(scope="module")
def coarse():
    """The paper case at 100 m cells: its scenario, risk field and planning model (a few seconds)."""
    scenario = ua.load_scenario(PAPER_CASE, ["grid.cell=[100,100,60]"])
    field = ua.compute_risk(scenario)
    return scenario, field, ua.planning_model(scenario, field)


@pytest.fixture(scope="module")
def flights_file(tmp_path_factory) -> Path:
    """A flights.json written by ``uamopt flights`` (12 flights of 4 aircraft on the planned network)."""
    from uamopt.cli import main

    out = tmp_path_factory.mktemp("hostile_api") / "flights"
    assert main(["flights", PAPER, "--set", "schedule.flights=12", "--set", "schedule.aircraft=4", "--out", str(out)]) == 0
    return out / "flights.json"


def one_line(exc: ua.UamoptError) -> None:
    assert "\n" not in exc.line() and exc.where and exc.fix, exc.line()


# --- 1. the arguments the issue names --------------------------------------------------------------

@pytest.mark.parametrize("overrides", [[None], [3], ("grid.cell=[10,10,10]", None), "grid.cell=[10,10,10]", 3,
                                       {"grid.cell": "[10,10,10]"}],
                         ids=["list-of-None", "list-of-int", "tuple-with-None", "bare-string", "int", "dict"])
def test_load_scenario_overrides_of_the_wrong_type(overrides):
    """Was: TypeError "argument of type 'NoneType' is not iterable" ([None]), "'int' object is not
    iterable", or a bare string read one character at a time ("override 'g' has no '='")."""
    with pytest.raises(TypeError, match=r'load_scenario\(\): overrides must be a list or tuple of "KEY=VALUE" strings'):
        ua.load_scenario(PAPER_CASE, overrides)


def test_with_overrides_of_the_wrong_type(scenario):
    with pytest.raises(TypeError, match=r"Scenario.with_overrides\(\): overrides must be"):
        scenario.with_overrides([None])


def test_load_scenario_overrides_none_and_a_tuple_still_work(scenario):
    assert ua.load_scenario(PAPER_CASE, None) == scenario
    assert ua.load_scenario(PAPER_CASE, ("schedule.flights=12",)).schedule.flights == 12


@pytest.mark.parametrize("point", [(100.0, 100.0), (1.0, 2.0, 3.0, 4.0), (), ("a", "b", "c"), 3, object(),
                                   np.zeros((1, 3))],
                         ids=["2-D", "4-D", "empty", "strings", "int", "object", "2-D-array"])
@pytest.mark.parametrize("argument", ["origin", "destination"])
def test_plan_track_point_that_is_not_three_numbers(coarse, point, argument):
    """Was: ValueError "operands could not be broadcast together with shapes (2,) (3,)"."""
    _, _, model = coarse
    ends = {"origin": "V1", "destination": "V4", argument: point}
    with pytest.raises(TypeError, match=rf"plan_track\(\): {argument} must be a vertiport name or a point of 3 numbers"):
        ua.plan_track(model, ends["origin"], ends["destination"])


@pytest.mark.parametrize("bad", [None, "V1-V2", [], 3], ids=["None", "str", "list", "int"])
def test_generate_flights_network_of_the_wrong_type(scenario, bad):
    """Was: AttributeError "'NoneType' object has no attribute 'items'"."""
    with pytest.raises(TypeError, match=r"generate_flights\(\): network must be a RouteNetwork .* or a mapping"):
        ua.generate_flights(scenario, network=bad)


def test_generate_flights_network_of_waypoints_that_are_not_numbers(scenario, network):
    """Was: ValueError "could not convert string to float: 'x'"."""
    with pytest.raises(TypeError, match=r"generate_flights\(\): network must be .* for route 'V1-V2'"):
        ua.generate_flights(scenario, {name: "x" for name in network})


def test_build_problem_of_an_empty_flight_set(scenario, flights):
    """Was: ValueError "need at least one array to concatenate"."""
    with pytest.raises(ua.UamoptError, match="the flight set is empty") as info:
        ua.build_problem(dataclasses.replace(flights, flights=()), scenario)
    assert "build_problem(flights)" in info.value.where
    one_line(info.value)


@pytest.mark.parametrize(("values", "key"), [
    ({"grid": {"cell": "x"}}, "grid.cell"),
    ({"schedule": {"aircraft": -1}}, "schedule.aircraft"),
    ({"aircraft": {"cruise_speed_mps": 10 ** 400}}, "aircraft.cruise_speed_mps"),
    ({"name": 3}, "name"),
    ({"tracks": {"weights": (0.0, 0.0)}}, "tracks.weights"),
    ({"flights": 12}, "flights"),  # an unknown key (it is schedule.flights)
], ids=["cell-word", "negative-count", "400-digits", "name-int", "zero-weights", "unknown-key"])
def test_scenario_constructed_with_a_bad_value(values, key):
    """Was: pydantic's ValidationError, several lines ("1 validation error for Scenario\\n grid.cell ...")."""
    with pytest.raises(ua.ScenarioError) as info:
        ua.Scenario(**values)
    assert f"'{key}'" in info.value.what and info.value.where == "Scenario(...)", info.value.line()
    one_line(info.value)


def test_scenario_constructed_gives_load_scenarios_line():
    """The same formatter as load_scenario: the key, its meaning and its range."""
    with pytest.raises(ua.ScenarioError) as direct:
        ua.Scenario(schedule={"aircraft": -1})
    with pytest.raises(ua.ScenarioError) as loaded:
        ua.load_scenario(PAPER_CASE, ["schedule.aircraft=-1"])
    assert (direct.value.what, direct.value.fix) == (loaded.value.what, loaded.value.fix)
    assert "it takes an integer in [1, 1000000000]" in direct.value.fix


def test_scenario_constructed_with_good_values_still_works():
    assert ua.Scenario(grid={"cell": (25, 25, 30)}).grid.cell == (25.0, 25.0, 30.0)


@pytest.mark.parametrize("seeds", ["0,1", "012", 3, [1.5], [True]], ids=["string", "digits", "int", "float", "bool"])
def test_benchmark_seeds_of_the_wrong_type(problem, seeds):
    """Was: ValueError "invalid literal for int() with base 10: ','"; [1.5] ran seed 1."""
    with pytest.raises(TypeError, match=r"benchmark\(\): seeds must be None or a list of solver seeds"):
        ua.benchmark(problem, ["greedy"], seeds=seeds, progress=False)


@pytest.mark.parametrize("seeds", [[-1], [2 ** 31], [], [0, 0]], ids=["negative", "beyond-32-bits", "empty", "twice"])
def test_benchmark_seeds_out_of_range(problem, seeds):
    """Was: an error row per run (a seed beyond 32 bits or negative), an empty table ([])."""
    with pytest.raises(ua.UamoptError, match="the solver seeds must be distinct integers from 0 to 2147483647") as info:
        ua.benchmark(problem, ["greedy"], seeds=seeds, progress=False)
    assert "seeds" in info.value.where
    one_line(info.value)


def test_bench_seeds_beyond_32_bits_on_the_command_line(tmp_path, capsys):
    """Was: one error row per run and exit 0 (the CLI takes seeds up to 2^63 - 1, the solvers 32 bits)."""
    out = tmp_path / "bench"
    code, _, err = cli(capsys, "bench", PAPER, "--solver", "greedy", "--seeds", "0", "3000000000", "--set",
                       "schedule.flights=12", "--out", str(out))
    assert_one_line_error(code, err, "the seed 3000000000")
    assert not out.exists()


@pytest.mark.parametrize(("argument", "bad", "expected"), [
    ("scenario", "x", "a Scenario"), ("scenario", 3, "a Scenario"),
    ("grid", "x", "an AirspaceGrid"), ("network", "x", "a RouteNetwork or a mapping"),
])
def test_load_flights_arguments_of_the_wrong_type(flights_file, argument, bad, expected):
    """Was: AttributeError "'str' object has no attribute 'schedule'"."""
    with pytest.raises(TypeError, match=rf"load_flights\(\): {argument} must be {expected}"):
        ua.load_flights(flights_file, **{argument: bad})


# --- 1b. more public functions of uamopt.__init__'s _LAZY table -------------------------------------

@pytest.mark.parametrize("use", [None, "x", ["plan"]], ids=["None", "word", "list"])
def test_scenario_grid_and_build_grid_use(scenario, use):
    """Was: KeyError None / KeyError 'x' / TypeError "unhashable type: 'list'"."""
    with pytest.raises(ValueError, match=r"scenario_grid\(\): use must be 'risk' or 'plan'"):
        ua.scenario_grid(scenario, use=use)
    with pytest.raises(ValueError, match=r"build_grid\(\): use must be one of 'risk', 'plan'"):
        ua.build_grid((1000, 1000, 300), (50, 50, 30), use=use)


@pytest.mark.parametrize("limit", ["x", [], math.nan, 0, 1e300], ids=["word", "list", "nan", "zero", "huge"])
def test_build_grid_memory_limit(limit):
    """Was: ValueError "invalid literal for int() with base 10: 'xxxx…'" (a string times 2**30),
    TypeError "int() argument must be ... not 'list'", ValueError "cannot convert float NaN to integer"."""
    with pytest.raises(ua.GridError, match="memory_limit_gb must be a number in") as info:
        ua.build_grid((1000, 1000, 300), (50, 50, 30), memory_limit_gb=limit)
    one_line(info.value)


def test_load_city_arguments_of_the_wrong_type(coarse):
    """Was: AttributeError "'NoneType' object has no attribute 'city'" / "... 'shape'"."""
    scenario, field, _ = coarse
    with pytest.raises(TypeError, match=r"load_city\(\): scenario must be a Scenario, got NoneType"):
        ua.load_city(None, field.grid)
    with pytest.raises(TypeError, match=r"load_city\(\): grid must be an AirspaceGrid, got tuple"):
        ua.load_city(scenario, (1000.0, 1000.0, 300.0))


def test_risk_field_arguments_of_the_wrong_type(coarse):
    """Was: AttributeError "'NoneType' object has no attribute 'shape'" (or 'shelter', 'risk')."""
    scenario, field, _ = coarse
    for args, parameter in (((None, field.grid, field.city), "scenario"), ((scenario, None, field.city), "grid"),
                            ((scenario, field.grid, "city"), "city")):
        with pytest.raises(TypeError, match=rf"risk_field\(\): {parameter} must be"):
            ua.risk_field(*args)
    with pytest.raises(TypeError, match=r"risk_field\(\): keep_risk must be a bool"):
        ua.risk_field(scenario, field.grid, field.city, keep_risk="no")


def test_risk_field_city_of_another_grid(coarse):
    """Was: a numpy broadcast error naming no argument."""
    scenario, field, _ = coarse
    other = ua.build_grid((1000.0, 1000.0, 300.0), (100.0, 100.0, 60.0))
    with pytest.raises(ua.GridError, match="the city layers are of another grid") as info:
        ua.risk_field(scenario, other, field.city)
    one_line(info.value)


def test_weight_sweep_arguments_of_the_wrong_type(coarse):
    """Was: AttributeError "'NoneType' object has no attribute 'scenario'", TypeError "'NoneType'
    object is not iterable" (weights), ValueError "operands could not be broadcast" (a 2-D origin)."""
    _, _, model = coarse
    with pytest.raises(TypeError, match=r"weight_sweep\(\): model must be a PlanningModel, got NoneType"):
        ua.weight_sweep(None, "V1", "V4")
    with pytest.raises(TypeError, match=r"weight_sweep\(\): weights must be an int ≥ 2 or a sequence"):
        ua.weight_sweep(model, "V1", "V4", weights=None)
    with pytest.raises(TypeError, match=r"weight_sweep\(\): origin must be a vertiport name or a point of 3 numbers"):
        ua.weight_sweep(model, (300.0, 300.0), "V4")
    with pytest.raises(TypeError, match=r"weight_sweep\(\): buffer must be a bool"):
        ua.weight_sweep(model, "V1", "V4", buffer="no")


@pytest.mark.parametrize("bad", ["bar", 3, []], ids=["str", "int", "list"])
def test_plan_network_progress_of_the_wrong_type(coarse, bad):
    """Was: AttributeError "'str' object has no attribute 'update'" after the first track was planned."""
    _, _, model = coarse
    with pytest.raises(TypeError, match=r"plan_network\(\): progress must be None or an object with update"):
        ua.plan_network(model, progress=bad)


def test_solve_overrides_of_the_wrong_type(problem):
    """Was: TypeError "'NoneType' object is not a mapping" (options), "SolverProfile.__init__() got
    an unexpected keyword argument" (a misspelt override), "'str' object is not callable" (extra)."""
    with pytest.raises(TypeError, match=r"solver_profile\(\): options must be a dict"):
        ua.solve(problem, "greedy", options=None)
    with pytest.raises(TypeError, match=r"solver_profile\(\): unknown override 'time_limt_s'; a profile takes .*time_limit_s"):
        ua.solve(problem, "greedy", time_limt_s=3)
    with pytest.raises(TypeError, match=r"solve\(\): extra must be None or a callable"):
        ua.solve(problem, "greedy", extra="x")


@pytest.mark.parametrize(("kwargs", "fragment"), [
    ({"solvers": None}, r"solvers must be a list of profiles"), ({"solvers": [3]}, r"solvers must be a list of profiles"),
    ({"progress": "no"}, r"progress must be a bool"), ({"sources": "x"}, r"sources must be None or a dict"),
    ({"sources": {"instance1": 3}}, r"sources must be None or a dict"),
], ids=["solvers-None", "solvers-int", "progress-str", "sources-str", "sources-value"])
def test_benchmark_other_arguments_of_the_wrong_type(problem, kwargs, fragment):
    """Was: TypeError "'NoneType' object is not iterable", a profile named 3, a truthy "no", ValueError
    "dictionary update sequence element #0 has length 1", AttributeError "'int' object has no attribute 'get'"."""
    args = {"solvers": ["greedy"], "progress": False} | kwargs
    with pytest.raises(TypeError, match=rf"benchmark\(\): {fragment}"):
        ua.benchmark(problem, args.pop("solvers"), **args)


def test_plot_sweep_names_of_the_wrong_type():
    """Was: TypeError "unhashable type: 'list'" (kind); x=[] silently the default column."""
    import pandas as pd

    table = pd.DataFrame({"schedule.aircraft": [1, 2], "status": ["feasible"] * 2, "avg_delay_s": [1.0, 2.0]})
    for name in ("kind", "x", "hue", "y"):
        with pytest.raises(TypeError, match=rf"plot_sweep\(\): {name} must be a str, got list"):
            ua.plot_sweep(table, **{name: []})


@pytest.mark.parametrize("name", ["load_sweep", "sweep"])
def test_sweep_small_of_the_wrong_type(name, tmp_path):
    """Was: a truthy "no" applied the [small] table (checked first, before the file is read)."""
    with pytest.raises(TypeError, match=rf"{name}\(\): small must be a bool, got str"):
        getattr(ua, name)(tmp_path / "sweep.toml", small="no")


# --- 2. a 400-digit number in a sweep file ---------------------------------------------------------

def sweep_file(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "bad.toml"
    path.write_text(f'base = "{PAPER_CASE.as_posix()}"\n{body}[grid]\n"schedule.aircraft" = [2]\n')
    return path


@pytest.mark.parametrize(("body", "fragment"), [
    (f"time_limit_s = {BIG}\n", "time_limit_s must be a number in (0, 1e+07], got 1000000000"),
    (f"time_limit_s = -{BIG}\n", "time_limit_s must be a number in (0, 1e+07]"),
    ("time_limit_s = 1e400\n", "time_limit_s must be a number in (0, 1e+07], got inf"),
    (f"max_cases = {BIG}\n", "max_cases must be a whole number ≥ 1 (at most 2^63 − 1)"),
], ids=["400-digits", "minus-400-digits", "inf", "max-cases-400-digits"])
def test_a_sweep_file_with_a_number_beyond_the_float_range(tmp_path, capsys, body, fragment):
    """Was: OverflowError "int too large to convert to float" and a traceback (time_limit_s); a
    400-digit max_cases was taken as no limit."""
    code, _, err = cli(capsys, "sweep", str(sweep_file(tmp_path, body)), "--out", str(tmp_path / "out"))
    assert_one_line_error(code, err, fragment)
    assert not (tmp_path / "out").exists()


def test_a_sweep_files_small_time_limit_beyond_the_float_range(tmp_path, capsys):
    path = sweep_file(tmp_path, "")
    path.write_text(path.read_text() + f"[small]\ntime_limit_s = {BIG}\n")
    code, _, err = cli(capsys, "sweep", str(path), "--out", str(tmp_path / "out"))
    assert_one_line_error(code, err, "small.time_limit_s must be a number in (0, 1e+07]")
    assert not (tmp_path / "out").exists()


# --- 3. weights whose products overflow in a schedule folder ---------------------------------------

@pytest.fixture(scope="module")
def schedule_folders(flights_file, tmp_path_factory):
    """Real schedule folders of ``flights_file`` (greedy), one per objective kind."""
    from uamopt.cli import main

    folders = {}
    for kind in ("lexicographic", "weighted"):
        out = tmp_path_factory.mktemp("hostile_api") / kind
        assert main(["schedule", PAPER, "--flights", str(flights_file), "--solver", "greedy", "--set",
                     f"schedule.objective={kind}", "--out", str(out)]) == 0
        folders[kind] = out
    return folders


def tampered(folder: Path, tmp_path: Path, weights) -> Path:
    import shutil

    copy = tmp_path / folder.name
    shutil.copytree(folder, copy)
    summary = json.loads((copy / "summary.json").read_text())
    summary["weights"] = weights
    (copy / "summary.json").write_text(json.dumps(summary))
    return copy


@pytest.mark.parametrize("kind", ["lexicographic", "weighted"])
@pytest.mark.parametrize("weights", [[1e308, 1e308], [1e308, 0.4], [0.6, 1e7]], ids=["both", "delay", "flights"])
def test_verify_refuses_weights_whose_objective_cannot_be_recomputed(schedule_folders, tmp_path, capsys, kind, weights):
    """Was: exit 0 "feasible and conflict-free" (lexicographic, weights unused), or a violation
    "objective = -4.8, the schedule gives -inf" that did not name the weights (weighted)."""
    folder = tampered(schedule_folders[kind], tmp_path, weights)
    code, _, err = cli(capsys, "verify", str(folder))
    assert_one_line_error(code, err, "weights must be two finite numbers (ω6, ω7) in [0, 1e+06]")
    assert "1e+308" in err or "10000000.0" in err


def test_verify_reports_a_non_finite_objective_naming_the_weights(schedule_folders, tmp_path, capsys, monkeypatch):
    """The second guard: were the weights' range ever wider, ω6·delay − ω7·S = inf − inf is a
    violation naming the weights, never a pass."""
    import uamopt.schedule.verify_summary as verify_summary

    monkeypatch.setattr(verify_summary, "MAX_WEIGHT", math.inf)
    folder = tampered(schedule_folders["weighted"], tmp_path, [1e308, 1e308])
    code, out, _ = cli(capsys, "verify", str(folder))
    assert code == 1 and "summary.json: the objective cannot be recomputed (weights = [1e+308, 1e+308]" in out, out


def test_the_untampered_folders_verify(schedule_folders, capsys):
    for folder in schedule_folders.values():
        assert cli(capsys, "verify", str(folder))[0] == 0


# --- 4. a waypoint 5e-7 m beyond the grid's faces --------------------------------------------------

def moved(flights_file: Path, tmp_path: Path, axis: int, value: float) -> tuple[Path, str]:
    """A copy of ``flights_file`` whose last flight (the last of its aircraft, with slack before
    the service end) has its sixth waypoint moved to ``value`` on ``axis``; (the file, the flight's id)."""
    doc = json.loads(flights_file.read_text())
    last = doc["flights"][-1]
    last["waypoints"][5][axis] = value
    path = tmp_path / "flights.json"
    path.write_text(json.dumps(doc))
    return path, last["id"]


def schedule(capsys, flights: Path, out: Path):
    return cli(capsys, "schedule", PAPER, "--flights", str(flights), "--solver", "greedy", "--out", str(out))


@pytest.mark.parametrize("axis", [0, 1], ids=["x", "y"])
def test_a_waypoint_just_below_the_grids_origin_is_refused_and_nothing_is_written(flights_file, tmp_path, capsys, axis):
    """Was: exit 2 from the verifier ("waypoints outside the local frame") *after* --out was written:
    the reader allowed 1e-6 m below 0, the verifier none. The rule is now one function
    (uamopt.bounds.outside_grid): no slack below 0, the local frame's exact origin."""
    flights, fid = moved(flights_file, tmp_path, axis, -5e-7)
    out = tmp_path / "out"
    code, _, err = schedule(capsys, flights, out)
    assert_one_line_error(code, err, "is outside the grid")
    assert f"flight {fid}" in err and "-5e-07" in err
    assert not out.exists()


@pytest.mark.parametrize(("axis", "value"), [(0, 5e-7), (1, 5e-7), (0, 2500.0 + 5e-7), (2, 360.0 + 5e-7)],
                         ids=["x-inside-origin", "y-inside-origin", "x-beyond-top-face", "z-beyond-top-face"])
def test_a_waypoint_within_the_tolerance_is_scheduled_and_verified(flights_file, tmp_path, capsys, axis, value):
    """5e-7 m inside the origin's faces, or within the 1e-6 m slack of the top faces (round-off of an
    extent of whole cells): accepted by the reader and by the verifier alike."""
    flights, _ = moved(flights_file, tmp_path, axis, value)
    out = tmp_path / "out"
    code, _, err = schedule(capsys, flights, out)
    assert code == 0, err
    assert cli(capsys, "verify", str(out))[0] == 0


def test_the_verifier_runs_before_anything_is_published(flights_file, tmp_path, capsys, monkeypatch):
    """Every check runs before --out is written: a folder the verifier refuses (here a reader made
    to accept a waypoint below the origin) is one line, exit 2, and no --out, its line naming the
    files as in --out (not the staging folder)."""
    import uamopt.schedule.airspace as airspace
    import uamopt.schedule.flights_file as flights_module

    def accept(points, extent):
        return np.zeros(len(np.asarray(points).reshape(-1, 3)), dtype=bool)

    monkeypatch.setattr(airspace, "outside_grid", accept, raising=False)
    monkeypatch.setattr(flights_module, "outside_grid", accept, raising=False)
    flights, _ = moved(flights_file, tmp_path, 0, -5e-7)
    out = tmp_path / "out"
    code, _, err = schedule(capsys, flights, out)
    assert_one_line_error(code, err, "outside the local frame")
    assert str(out / "flights.json") in err and ".uamopt-stage-" not in err
    assert not out.exists()


def test_readers_and_verifier_share_one_rule():
    """One constant, one function: the flights reader, the airspace check and the verifier's extent
    check all call uamopt.bounds.outside_grid."""
    import uamopt.bounds as bounds
    import uamopt.schedule.airspace as airspace
    import uamopt.schedule.flights_file as flights_module
    import uamopt.schedule.verify_summary as verify_summary

    assert airspace.outside_grid is flights_module.outside_grid is verify_summary.outside_grid is bounds.outside_grid
    assert airspace.TOL_M == bounds.GRID_TOL_M == 1e-6
    extent = (10.0, 10.0, 10.0)
    assert bounds.outside_grid([[-5e-7, 1, 1], [1, -5e-7, 1], [10 + 2e-6, 1, 1]], extent).tolist() == [True, True, True]
    assert bounds.outside_grid([[0, 0, 0], [5e-7, 1, 1], [10 + 5e-7, 10, 10]], extent).tolist() == [False, False, False]


def test_a_plan_too_large_is_refused_before_the_network_is_planned(tmp_path, capsys):
    """grid.memory_limit_gb so small that planning the network would be refused by the grid's own
    guard: the plan's guard (schedule.memory_limit_gb defaults to it) speaks first, so the plan's
    size is checked before any risk field or network is computed."""
    from uamopt.cli import main

    out = tmp_path / "f"
    code = main(["flights", "models/paper_case.toml", "--set", "grid.memory_limit_gb=0.0001", "--set",
                 "schedule.flights=1000", "--set", "schedule.aircraft=100", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "a plan of 1,000 flights of 100 aircraft needs about" in err[0], err
    assert not out.exists()
