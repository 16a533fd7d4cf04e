"""Hostile input (docs/interfaces.md): a table of command lines, each of which must end with its
exit code (2 for bad input, 1 where a schedule folder is well formed but infeasible), one line
``error: <what> (<where>): <how to fix>`` on stderr (for exit 2), no traceback, ``--out`` left as
it was, and no input file or folder touched.

The cases run in this process (``uamopt.cli.main``); an exception that escapes ``main`` is a
traceback the user would see, and fails its case. A few run as real subprocesses to show that no
traceback reaches the terminal. The inputs are written once by tests/hostile_files.py.
"""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import PAPER_CASE, ROOT
from hostile_files import TINY, write_all

from uamopt.cli import main

T = " ".join(TINY)
P = f"{PAPER_CASE} {T}"  # the paper case on 250 x 250 x 60 m cells
SCHED = f"schedule {P} --solver greedy"

# (id, command line, exit code, fragment of the error line (exit 2) or of stdout (exit 1))
# {d}: the folder of hostile files, {out}: a non-empty --out folder that must stay as it was
CASES = [
    # --- scenario files ---------------------------------------------------------------------
    ("scenario-missing", "risk {d}/nowhere.toml --out {out}", 2, "scenario file not found"),
    ("scenario-folder", "risk {d}/a_folder.toml --out {out}", 2, "scenario file not found"),
    ("scenario-malformed", "risk {d}/malformed.toml --out {out}", 2, "malformed TOML"),
    ("scenario-latin1", "risk {d}/latin1.toml --out {out}", 2, "not UTF-8"),
    ("scenario-deep", "risk {d}/deep.toml --out {out}", 2, "nested too deeply"),
    ("scenario-unreadable", "risk /proc/self/mem --out {out}", 2, "cannot read the scenario"),
    ("scenario-unknown-key", "risk {d}/unknown_key.toml --out {out}", 2, "unknown key 'whatever'"),
    ("scenario-unknown-grid-key", "risk {d}/unknown_grid_key.toml --out {out}", 2, "unknown key 'grid.cells'"),
    ("scenario-section-number", "risk {d}/grid_number.toml --out {out}", 2, "'grid'"),
    ("scenario-seed-true", "risk {d}/seed_true.toml --out {out}", 2, "city.seed"),
    ("scenario-seed-string", "risk {d}/seed_string.toml --out {out}", 2, "city.seed"),
    ("scenario-no-vertiports", "network {d}/no_ports.toml " + T + " --out {out}", 2, "the network has no route"),
    ("scenario-osm-no-pbf", "risk {d}/osm_nopbf.toml --out {out}", 2, "no OpenStreetMap file"),
    ("scenario-osm-missing", "risk {d}/osm_missing.toml --out {out}", 2, "OpenStreetMap file not found"),
    ("scenario-dsm-no-file", "risk {d}/dsm_nofile.toml --out {out}", 2, "no DSM GeoTIFF"),
    # --- --set --------------------------------------------------------------------------------
    ("set-cell-zero", "risk {paper} --set grid.cell=[0,50,30] --out {out}", 2, "greater than 0"),
    ("set-cell-negative", "risk {paper} --set grid.cell=[-50,50,30] --out {out}", 2, "greater than 0"),
    ("set-cell-nan", "risk {paper} --set grid.cell=[nan,50,30] --out {out}", 2, "grid.cell"),
    ("set-cell-inf", "risk {paper} --set grid.cell=[inf,50,30] --out {out}", 2, "finite number"),
    ("set-cell-word", "risk {paper} --set grid.cell=abc --out {out}", 2, "grid.cell"),
    ("set-cell-two", "risk {paper} --set grid.cell=[50,50] --out {out}", 2, "grid.cell"),
    ("set-cell-bool", "risk {paper} --set grid.cell=[true,50,30] --out {out}", 2, "must be a number"),
    ("set-extent-huge", "risk {paper} --set grid.extent=[1e6,1e6,360] --out {out}", 2, "more than the limit"),
    ("set-memory-zero", "risk {paper} --set grid.memory_limit_gb=0 --out {out}", 2, "grid.memory_limit_gb"),
    ("set-city-seed-negative", "risk {paper} --set city.seed=-1 --out {out}", 2, "city.seed"),
    ("set-city-seed-float", "risk {paper} --set city.seed=1.5 --out {out}", 2, "city.seed"),
    ("set-plan-seed-negative", "flights {P} --set schedule.plan_seed=-1 --out {out}", 2, "schedule.plan_seed"),
    ("set-aircraft-zero", "flights {P} --set schedule.aircraft=0 --out {out}", 2, "schedule.aircraft"),
    ("set-aircraft-bool", "flights {P} --set schedule.aircraft=true --out {out}", 2, "schedule.aircraft"),
    ("set-flights-zero", "flights {P} --set schedule.flights=0 --out {out}", 2, "schedule.flights"),
    ("set-radius-11", "flights {P} --set schedule.conflict_radius=11 --out {out}", 2, "conflict_radius"),
    ("set-radius-string", "flights {P} --set \"schedule.conflict_radius='1'\" --out {out}", 2, "conflict_radius"),
    ("set-ports-empty", "network {P} --set network.vertiports=[] --out {out}", 2, "the network has no route"),
    ("set-ports-one", "flights {P} --set \"network.vertiports=[{{name='A',x=300.0,y=300.0}}]\" --out {out}", 2,
     "the network has no route"),
    ("set-ports-same-spot", ("network {P} --set \"network.vertiports=[{{name='A',x=300.0,y=300.0}},"
                             "{{name='B',x=300.0,y=300.0}}]\" --out {out}"), 2, "both at (300, 300)"),
    ("set-ports-same-cell", ("network {P} --set \"network.vertiports=[{{name='A',x=300.0,y=300.0}},"
                             "{{name='B',x=310.0,y=300.0}}]\" --out {out}"), 2, "same cell"),
    ("set-port-nan", "risk {paper} --set \"network.vertiports=[{{name='A',x=nan,y=1.0}}]\" --out {out}", 2, "finite"),
    ("set-port-no-name", "risk {paper} --set \"network.vertiports=[{{name='',x=1.0,y=1.0}}]\" --out {out}", 2,
     "at least 1 character"),
    ("set-routes-empty", SCHED + " --set network.routes=[] --out {out}", 2, "network.routes is empty"),
    ("set-route-loop", "risk {paper} --set \"network.routes=[['V1','V1']]\" --out {out}", 2, "two different vertiports"),
    ("set-random-ports-one", "risk {paper} --set network.random_vertiports=1 --out {out}", 2, "random_vertiports"),
    ("set-random-ports-many", "risk {paper} --set network.random_vertiports=500 --out {out}", 2, "random_vertiports"),
    ("set-origin-inf", "plan {P} --set tracks.origin=[inf,0,0] --out {out}", 2, "finite"),
    ("set-weights-negative", "risk {paper} --set tracks.weights=[-1,0] --out {out}", 2, "tracks.weights"),
    ("set-speed-max-below-min", "risk {paper} --set aircraft.speed_max_mps=5 --out {out}", 2, "speed_min_mps"),
    ("set-climb-angle", "risk {paper} --set aircraft.climb_angle_rad=2 --out {out}", 2, "climb_angle_rad"),
    ("set-cruise-speed", SCHED + " --set aircraft.cruise_speed_mps=1000 --out {out}", 2, "cruise_speed_mps"),
    ("set-service-long", SCHED + " --set schedule.service_s=1e9 --out {out}", 2, "schedule.service_s"),
    ("set-quadrature-bool", "risk {paper} --set risk.quadrature_points=true --out {out}", 2, "quadrature_points"),
    ("set-delay-scale-bool", "flights {P} --set schedule.max_delay_scale=true --out {out}", 2, "must be a number"),
    ("set-delay-scale-two", "flights {P} --set schedule.max_delay_scale=2 --out {out}", 2, "max_delay_scale"),
    ("set-ground-string", "risk {paper} --set \"city.ground_m='10'\" --out {out}", 2, "must be a number"),
    ("set-bbox-nan", "risk {paper} --set city.bbox=[nan,0,1,1] --out {out}", 2, "finite"),
    ("set-unknown-key", "risk {paper} --set grid.foo=1 --out {out}", 2, "unknown key 'grid.foo'"),
    ("set-no-equals", "risk {paper} --set grid.cell --out {out}", 2, "has no '='"),
    ("set-empty-key", "risk {paper} --set =5 --out {out}", 2, "empty key"),
    ("set-below-value", "risk {paper} --set grid.cell.x=5 --out {out}", 2, "not a section"),
    ("set-deep-value", "risk {paper} --set a=" + "[" * 5000 + "]" * 5000 + " --out {out}", 2, "nested too deeply"),
    ("set-route-self", "plan {P} --set \"tracks.route=['V1','V1']\" --out {out}", 2, "to itself"),
    ("set-route-unknown", "plan {P} --set \"tracks.route=['V1','V9']\" --out {out}", 2, "unknown vertiport 'V9'"),
    # --- command-line options -----------------------------------------------------------------
    ("plan-same-point", "plan {P} --from 300,300,120 --to 300,300,120 --out {out}", 2, "same cell"),
    ("plan-same-port", "plan {P} --from V1 --to V1 --out {out}", 2, "same cell"),
    ("plan-unknown-port", "plan {P} --from Nowhere --out {out}", 2, "unknown vertiport 'Nowhere'"),
    ("plan-two-numbers", "plan {P} --from 1,2 --out {out}", 2, "not a point"),
    ("plan-nan-point", "plan {P} --from nan,0,120 --out {out}", 2, "not a point"),
    ("plan-far-point", "plan {P} --from 1e9,0,120 --out {out}", 2, "outside the grid"),
    ("plan-low-point", "plan {P} --from 300,300,5 --out {out}", 2, "outside the band"),
    ("flights-seed-negative", "flights {P} --seed -1 --out {out}", 2, "--seed"),
    ("schedule-seed-word", SCHED + " --seed abc --out {out}", 2, "--seed"),
    ("bench-seeds-negative", "bench {P} --solver greedy --seeds 0 -1 --out {out}", 2, "--seeds"),
    ("out-is-a-file", "risk {paper} --out {d}/flights.json", 2, "output path is a file"),
    ("unknown-command", "fly {paper}", 2, "invalid choice"),
    ("export-dt-huge", "export bluesky {d}/good --dt 1e9", 2, "--dt"),
    ("export-bank", "export bluesky {d}/good --bank 95", 2, "--bank"),
    ("verify-missing", "verify {d}/nowhere", 2, "not a folder"),
    ("export-summary-list", "export bluesky {d}/sched_summary_list", 2, "JSON object"),
    ("export-summary-deep", "export geojson {d}/sched_summary_deep", 2, "malformed JSON"),
    ("export-no-schedule", "export bluesky {d}/sched_no_schedule", 2, "missing schedule.csv"),
    # export reads schedule.csv with the verifier's reader: what verify refuses, export refuses
    ("export-operated-maybe", "export bluesky {d}/sched_operated_maybe", 2, "operated must be 1 or 0"),
    ("export-columns", "export geojson {d}/sched_columns", 2, "needs the columns"),
    ("export-risk-bomb", "export geojson {d}/good --risk {d}/risk_bomb/risk.npz", 2, "declares 931.3 GiB of arrays"),
    # --- solver profiles ------------------------------------------------------------------------
    *[(f"profile-{name.replace('_', '-')}", f"{SCHED.replace('greedy', '{d}/profile_' + name + '.toml')} --out {{out}}",
       2, fragment) for name, fragment in (
        ("unknown_key", "unknown key 'foo'"), ("no_solver", "missing key 'solver'"), ("bad_solver", "unknown solver"),
        ("negative_limit", "time_limit_s"), ("nan_limit", "time_limit_s"), ("no_threads", "threads"),
        ("malformed", "malformed TOML"), ("seed_word", "seed must be an integer"),
        ("options_number", "[options] must be a table"), ("seed_negative", "seed must be an integer"),
        ("seed_bool", "seed must be an integer"), ("latin1", "UTF-8"), ("deep", "cannot read the profile"))],
    ("profile-missing", SCHED.replace("greedy", "nowhere") + " --out {out}", 2, "solver profile not found"),
    # --- network files (--network) ------------------------------------------------------------
    *[(f"network-{name.replace('_', '-')}", SCHED + f" --network {{d}}/net_{name}.json --out {{out}}", 2, fragment)
      for name, fragment in (
        ("one_point", "at least two finite"), ("zero_length", "zero length"), ("nan", "at least two finite"),
        ("words", "got 'north'"), ("far", "outside the grid"), ("below", "outside the grid"),
        ("ground", "on or below the ground"), ("tower", "passes through a building"), ("no_routes", "non-empty"),
        ("routes_list", "non-empty"), ("bad_cell", "'cell' must be three positive"), ("tiny_cell", "more than the limit"),
        ("missing_route", "unknown route 'V1-V2'"), ("list", "non-empty"), ("truncated", "malformed network file"),
        ("deep", "malformed network file"), ("latin1", "malformed network file"), ("nowhere", "not found"))],
    # --- flights files (--flights) ------------------------------------------------------------
    *[(f"flights-{name.replace('_', '-')}", SCHED + f" --flights {{d}}/flights_{name}.json --out {{out}}", 2, fragment)
      for name, fragment in (
        ("no_list", "missing key 'flights'"), ("empty", "no flights"), ("not_object", "not a JSON object"),
        ("no_speed", "missing key 'speed_mps'"), ("speed_zero", "speed_mps must be a number in [0.1, 200], got 0"),
        ("speed_word", "got 'fast'"),
        ("speed_fast", "in [0.1, 200], got 1000.0"), ("departure_late", "in [-1e+07, 1e+07]"), ("service_long", "service_end_s"),
        ("departure_nan", "planned_departure_s must be a number"), ("negative_delay", "max_delay_s must be a number in [0,"),
        ("one_point", "at least two"),
        ("tower", "passes through a building"), ("ground", "on or below the ground"), ("off_grid", "outside the grid"),
        ("tiny_cell", "more than the limit"), ("radius_11", "conflict_radius"), ("radius_true", "conflict_radius"),
        ("duplicate_id", "duplicate flight id"), ("overlap", "overlaps aircraft A"), ("before_start", "before the service"),
        ("after_end", "after the service end"), ("unknown_route", "unknown route"), ("truncated", "malformed JSON"),
        ("deep", "nested too deeply"), ("nowhere", "not found"))],
    ("flights-unreadable", SCHED + " --flights /proc/self/mem --out {out}", 2, "cannot read the flights file"),
    ("network-unreadable", SCHED + " --network /proc/self/mem --out {out}", 2, "cannot read the network file"),
    ("flights-with-bad-network", SCHED + " --flights {d}/flights.json --network {d}/net_tower.json --out {out}", 2,
     "passes through a building"),
    # --- schedule folders (verify) --------------------------------------------------------------
    *[(f"verify-{name.replace('_', '-')}", f"verify {{d}}/sched_{name}", code, fragment) for name, code, fragment in (
        ("no_flights", 2, "missing flights.json"), ("no_schedule", 2, "missing schedule.csv"),
        ("columns", 2, "needs the columns"), ("operated_maybe", 2, "operated must be 1 or 0"),
        ("tiny_cell", 2, "conflict search would visit"), ("duplicate_id", 2, "appears twice"),
        ("radius_words", 2, "conflict_radius must be an integer"), ("summary_list", 2, "JSON object"),
        ("summary_deep", 2, "malformed JSON"), ("weights_word", 2, "weights must be two"),
        ("weights_one", 2, "weights must be two"), ("extent_word", 2, "extent_m must be"),
        ("objective_inf", 1, "summary.json: objective = inf"), ("off_grid", 1, "outside the grid"),
        ("sunk", 2, "outside the local frame"))],
    # --- rasters and GeoJSON layers (dsm source) --------------------------------------------------
    *[(f"dsm-{name.replace('_', '-')}", f"risk {{d}}/dsm_{name}.toml{extra} --out {{out}}", 2, fragment)
      for name, extra, fragment in (
        ("inf", "", "infinite elevations"), ("neginf", "", "infinite elevations"), ("nodata", "", "no valid data"),
        ("lonlat", "", "not in a projected CRS"), ("nocrs", "", "no coordinate reference system"),
        ("garbage", "", "cannot read GeoTIFF"), ("missing", "", "GeoTIFF not found"),
        ("huge", " --set grid.cell=[200,200,30] --set grid.memory_limit_gb=2", "3,600,000,000 pixels"),
        ("nofly_far", "", "lies on the grid"),
        ("nofly_badcrs", "", "unknown CRS"), ("nofly_elsewhere", "", "lies on the grid"),
        ("nofly_bad", "", "cannot read GeoJSON"), ("roads_elsewhere", "", "lies on the grid"),
        ("shelter_missing", "", "GeoTIFF not found"))],
    # --- numbers out of range (issue 22, item 6): one boundary check (uamopt/bounds.py, the scenario's key table) ---
    *[(f"number-flights-{name.replace('_', '-')}", SCHED + f" --flights {{d}}/flights_{name}.json --out {{out}}", 2, fragment)
      for name, fragment in (
        ("departure_big", "planned_departure_s must be a number in [-1e+07, 1e+07], got 1000"),
        ("departure_huge", "an integer of more than 4300 digits"), ("speed_big", "speed_mps must be a number in [0.1, 200]"),
        ("delay_big", "max_delay_s must be a number in [0, 1e+07]"), ("cell_big", "'cell' must be three positive sizes"),
        ("waypoint_big", "point 1 holds 1000"), ("id_newline", "flight F1\\nerror: forged"))],
    *[(f"number-network-{name.replace('_', '-')}", SCHED + f" --network {{d}}/net_{name}.json --out {{out}}", 2, fragment)
      for name, fragment in (
        ("cell_big", "'cell' must be three positive sizes"), ("waypoint_big", "point 1 holds 1000"),
        ("length_big", "length_m must be a number"), ("layer_inf", "layer_k must be an integer"))],
    ("number-export-departure-big", "export bluesky {d}/sched_departure_big", 2, "planned_departure_s must be a number"),
    ("number-export-summary-huge", "export geojson {d}/sched_summary_huge", 2, "an integer of more than 4300 digits"),
    ("number-export-origin-big", "export geojson {d}/sched_origin_big", 2, "the frame's origin must be a number"),
    *[(f"number-profile-{name.replace('_', '-')}", f"{SCHED.replace('greedy', '{d}/profile_' + name + '.toml')} --out {{out}}",
       2, fragment) for name, fragment in (
        ("limit_big", "time_limit_s must be a number in (0, 1e+07]"), ("limit_huge", "an integer of more than 4300 digits"),
        ("highs_gap_nan", "HiGHS refuses mip_rel_gap = nan"), ("highs_gap_inf", "HiGHS refuses mip_rel_gap = inf"),
        ("ga_population_inf", "option population must be int, got inf"),
        ("ga_population_nan", "option population must be int, got nan"),
        ("ga_population_1e8", "option population must be an integer in [2, 10000]"),
        ("ga_t0_big", "option t0 must be a number"), ("soa_points_big", "option multi_points must be an integer"),
        ("greedy_step_big", "option step_s must be a number in [0.001, 1e+07]"),
        ("timeindexed_step_tiny", "option step_s must be a number in [0.001, 1e+07], got 1e-300"),
        ("timeindexed_gap_big", "option mip_rel_gap must be a number"),
        ("cpsat_unit_tiny", "option time_unit_s must be a number in [1e-06, 1e+07], got 1e-300"))],
    ("number-scenario-seed-big", "risk {d}/seed_big.toml " + T + " --out {out}", 2, "less than or equal to 9223372036854775807"),
    ("number-scenario-seed-huge", "risk {d}/seed_huge.toml --out {out}", 2, "an integer of more than 4300 digits"),
    ("number-set-aircraft-1e30", "flights {P} --set schedule.aircraft=" + str(10**30) + " --out {out}", 2,
     "'schedule.aircraft': Input should be less than or equal to 1000000000"),
    ("number-set-plan-seed-1e30", "flights {P} --set schedule.plan_seed=" + str(10**30) + " --out {out}", 2,
     "schedule.plan_seed"),
    ("number-set-city-seed-big", "risk {P} --set city.seed=" + str(10**400) + " --out {out}", 2, "city.seed"),
    ("number-set-value-huge", "risk {P} --set city.seed=" + "9" * 5000 + " --out {out}", 2,
     "an integer of more than 4300 digits"),
    ("number-set-extent-1e300", "risk {paper} --set grid.extent=[1e300,1e300,360] --set grid.cell=[1e-300,1e-300,1] --out {out}",
     2, "'grid.extent': Input should be less than or equal to 1000000"),
    ("number-set-cell-1e-300", "risk {paper} --set grid.extent=[1e5,1e5,360] --set grid.cell=[1e-300,1e-300,1] --out {out}",
     2, "more than the limit"),
    ("number-set-memory-1e300", "risk {paper} --set grid.memory_limit_gb=1e300 --out {out}", 2, "grid.memory_limit_gb"),
    ("number-set-clearance-1e300", "network {P} --set tracks.clearance_m=1e300 --out {out}", 2, "tracks.clearance_m"),
    ("number-set-c-h-1e300", "network {P} --set aircraft.c_h=1e300 --out {out}", 2, "aircraft.c_h"),
    ("number-set-window-1e300", "flights {P} --set schedule.first_departure_window_s=1e300 --out {out}", 2,
     "first_departure_window_s"),
    ("number-set-time-step-1e-300", "flights {P} --set schedule.time_step_s=1e-300 --out {out}", 2, "schedule.time_step_s"),
    ("number-flights-seed-1e30", "flights {P} --seed " + str(10**30) + " --out {out}", 2, "--seed"),
    ("number-dsm-nofly-big", "risk {d}/dsm_nofly_big.toml --out {out}", 2, "cannot read GeoJSON"),
    ("number-dsm-nofly-nan", "risk {d}/dsm_nofly_nan.toml --out {out}", 2, "not a finite number"),
    ("number-bench-seed-count", "bench {P} --solver greedy --seeds 1000000000000 --out {out}", 2, "--seeds 1000000000000"),
    # --- output paths ---
    ("out-symlink-loop", "risk {P} --out {d}/out_loop", 2, "Too many levels of symbolic links"),
    ("out-name-newline", "risk {paper} --out '{d}/out_file\nerror: forged'", 2, "output path is a file"),
]

#: run as real subprocesses: the terminal sees one line and no traceback
SUBPROCESS = ["scenario-deep", "flights-seed-negative", "network-nan", "verify-weights-word", "dsm-inf", "plan-same-point",
              "number-flights-departure-big", "out-name-newline"]


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> Path:
    return write_all(tmp_path_factory.mktemp("hostile"))


def _snapshot(folder: Path) -> dict:
    return {str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in sorted(folder.rglob("*")) if p.is_file()}


def _argv(line: str, files: Path, out: Path) -> list[str]:
    text = line.replace("{paper}", str(PAPER_CASE)).replace("{P}", P).replace("{d}", str(files))
    return shlex.split(text.replace("{out}", str(out)).replace("{{", "{").replace("}}", "}"))


def _out(tmp_path: Path) -> Path:
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("written before the command", encoding="utf-8")
    return out


PROGRESS_LINE = re.compile(r"^[a-z]+: \d+/\d+ \w+, \d+ s( - stopped)?$")


def _assert_outcome(case, code, stdout: str, stderr: str, out: Path, before: dict, after: dict) -> None:
    name, _, expected, fragment = case
    assert "Traceback" not in stderr + stdout, f"{name}: traceback\n{stderr}"
    assert code == expected, f"{name}: exit {code}, expected {expected}\n{stderr}"
    if expected == 2:
        # the progress lines a slow step prints after 5 s (uamopt.progress: "schedule: 0/3 steps, 5 s") are
        # not part of the error; on a loaded machine a check can start after them
        lines = [line for line in stderr.strip().splitlines() if not PROGRESS_LINE.match(line)]
        assert len(lines) == 1 and lines[0].startswith("error: "), f"{name}: {stderr!r}"
        assert " (" in lines[0] and "): " in lines[0], f"{name}: not 'what (where): how to fix': {lines[0]}"
        assert fragment in lines[0], f"{name}: {fragment!r} not in {lines[0]!r}"
    else:
        assert fragment in stdout, f"{name}: {fragment!r} not in\n{stdout}"
    assert [p.name for p in out.iterdir()] == ["keep.txt"], f"{name}: --out torn: {sorted(out.iterdir())}"
    assert (out / "keep.txt").read_text(encoding="utf-8") == "written before the command"
    assert after == before, f"{name}: an input file changed"


def test_the_table_is_large_and_unique():
    names = [c[0] for c in CASES]
    assert len(names) == len(set(names)) and len(names) >= 80, len(names)
    assert set(SUBPROCESS) <= set(names)


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_hostile_case(case, files, tmp_path, capsys):
    out = _out(tmp_path)
    argv = _argv(case[1], files, out)
    before = _snapshot(files)
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse: one line and exit 2
        code = exc.code
    stdout, stderr = capsys.readouterr()
    _assert_outcome(case, code, stdout, stderr, out, before, _snapshot(files))


@pytest.mark.parametrize("name", SUBPROCESS)
def test_no_traceback_reaches_the_terminal(name, files, tmp_path):
    case = next(c for c in CASES if c[0] == name)
    out = _out(tmp_path)
    before = _snapshot(files)
    run = subprocess.run([sys.executable, "-m", "uamopt", *_argv(case[1], files, out)], cwd=ROOT,
                         capture_output=True, text=True, timeout=120, check=False)
    _assert_outcome(case, run.returncode, run.stdout, run.stderr, out, before, _snapshot(files))


def test_a_risk_folder_declaring_a_huge_array_is_refused_before_decompression(files):
    """``load_risk`` reads risk.npz through the same size check as ``export geojson --risk``."""
    import uamopt as ua
    from uamopt.errors import InputFileError

    with pytest.raises(InputFileError, match=r"risk\.npz declares 931\.3 GiB of arrays, more than"):
        ua.load_risk(files / "risk_bomb")
