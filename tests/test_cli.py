"""The commands as a user runs them, and the one-line errors of docs/interfaces.md.

Most tests call ``uamopt.cli.main([...])`` in this process (capsys holds stdout and stderr; an
argparse error raises SystemExit(2)); a few run the installed entry points in a subprocess to prove
that ``python -m uamopt`` and the ``uamopt`` script reach the same code with the same exit codes.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import PAPER_CASE, ROOT

from uamopt.cli import main

PAPER = str(PAPER_CASE)
UAMOPT_SCRIPT = Path(sys.executable).with_name("uamopt")


def run(*args: str) -> subprocess.CompletedProcess:
    """``python -m uamopt ARGS`` in a fresh interpreter."""
    return subprocess.run([sys.executable, "-m", "uamopt", *args], cwd=ROOT, capture_output=True, text=True, timeout=300)


def cli(capsys, *args: str) -> tuple[int, str, str]:
    """``uamopt ARGS`` in this process: (exit code, stdout, stderr)."""
    try:
        code = main(list(args))
    except SystemExit as exc:  # argparse: --help, --version, bad arguments
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def assert_one_line_error(code: int, stderr: str, fragment: str) -> None:
    assert code == 2, stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    assert lines[0].startswith("error: ") and fragment in lines[0], lines[0]
    assert " (" in lines[0] and "): " in lines[0]  # what (where): how to fix
    assert "Traceback" not in stderr


# --- end to end through the installed entry points ---------------------------------------------


def test_risk_command_writes_the_interface_files(tmp_path):
    out = tmp_path / "risk"
    proc = run("risk", PAPER, "--out", str(out), "--set", "grid.cell=[100,100,60]")
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in out.iterdir()) == ["risk.npz", "risk.png", "summary.json"]
    summary = json.loads((out / "summary.json").read_text())
    with np.load(out / "risk.npz") as data:
        assert data["risk"].shape == (25, 45, 6) == tuple(summary["grid"]["shape"])
        assert int(data["unsafe"].sum()) == summary["unsafe_cells"]
        assert int(data["obstacle"].sum()) == summary["obstacle_cells"]
    assert summary["cells"] == 25 * 45 * 6 and 0 < summary["unsafe_share"] < 1
    assert summary["constants"]["mean_relative_speed_mps"] == pytest.approx(23.664, abs=5e-4)
    assert summary["seconds"]["risk"] > 0
    assert (out / "risk.png").stat().st_size > 10_000


def test_entry_points_exit_codes_and_one_line_errors(tmp_path):
    script = subprocess.run([str(UAMOPT_SCRIPT), "--help"], capture_output=True, text=True, timeout=120)
    assert script.returncode == 0 and "reproduce" in script.stdout
    bad = subprocess.run([str(UAMOPT_SCRIPT), "risk", str(tmp_path / "none.toml"), "--out", str(tmp_path / "o")],
                         capture_output=True, text=True, timeout=120)
    assert_one_line_error(bad.returncode, bad.stderr, "not found")
    module = run("frobnicate", PAPER)
    assert_one_line_error(module.returncode, module.stderr, "command line")
    assert not (tmp_path / "o").exists()


# --- the commands, in process -----------------------------------------------------------------


def test_plan_command(tmp_path, capsys):
    out = tmp_path / "plan"
    code, stdout, err = cli(capsys, "plan", PAPER, "--from", "300,300,120", "--to", "2220,4220,120", "--out", str(out))
    assert code == 0, err
    doc = json.loads((out / "tracks.json").read_text())
    assert list(doc["stages"]) == ["shortest", "initial", "equivalent", "optimal"]
    for stage in doc["stages"].values():
        pts = np.asarray(stage["waypoints"])
        assert stage["n_waypoints"] == len(pts)
        assert stage["length_m"] == pytest.approx(float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum()))
    assert doc["stages"]["optimal"]["waypoints"][0] == [300.0, 300.0, 120.0]
    assert f"{doc['stages']['optimal']['length_m']:.0f} m" in stdout
    assert (out / "tracks.png").stat().st_size > 10_000


def test_network_command(tmp_path, capsys):
    out = tmp_path / "net"
    code, stdout, err = cli(capsys, "network", PAPER, "--out", str(out))
    assert code == 0, err
    doc = json.loads((out / "network.json").read_text())
    assert len(doc["routes"]) == 20 and doc["routes"]["V1-V4"]["origin"] == "V1"
    assert "network: 20 tracks" in stdout


@pytest.mark.parametrize(("args", "fragment"), [
    (["--from", "300,300,50"], "outside the band"),
    (["--from", "300,300"], "not a point"),
    (["--from", "9000,300,120"], "outside the grid"),
    (["--set", "aircraft.range_m=2000"], "range"),
])
def test_plan_bad_input(tmp_path, capsys, args, fragment):
    out = tmp_path / "o"
    assert_one_line_error(*cli(capsys, "plan", PAPER, "--out", str(out), *args)[::2], fragment)
    assert not out.exists()


def test_plan_origin_in_building_and_unreachable_destination(tmp_path, capsys):
    """A DSM city with a closed ring of 320 m towers: inside a tower, and inside the ring."""
    import rasterio
    from rasterio.transform import from_origin

    dsm = np.zeros((400, 400), dtype="float32")  # 1 m pixels, rows run south
    dsm[100:300, 100:300] = 320.0  # above the whole band
    dsm[140:260, 140:260] = 0.0  # the courtyard inside the ring
    path = tmp_path / "ring.tif"
    with rasterio.open(path, "w", driver="GTiff", height=400, width=400, count=1, dtype="float32",
                       crs="EPSG:32633", transform=from_origin(500000, 6000400, 1, 1)) as dst:
        dst.write(dsm, 1)
    scenario = tmp_path / "ring.toml"
    scenario.write_text(f"[grid]\ncell = [20.0, 20.0, 30.0]\n[city]\nsource = 'dsm'\ndsm = '{path}'\n"
                        "[tracks]\nclearance_m = 0.0\n")
    out = tmp_path / "o"
    assert_one_line_error(*cli(capsys, "plan", str(scenario), "--from", "30,30,120", "--to", "120,120,135",
                               "--out", str(out))[::2], "inside a building")
    assert_one_line_error(*cli(capsys, "plan", str(scenario), "--from", "30,30,120", "--to", "200,200,120",
                               "--out", str(out))[::2], "no admissible track")
    assert not out.exists()


def test_helsinki_from_openstreetmap(tmp_path, capsys):
    out = tmp_path / "hel"
    code, _, err = cli(capsys, "risk", str(ROOT / "models" / "helsinki.toml"), "--out", str(out),
                       "--set", "grid.cell=[40,40,30]")
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["source"] == "osm" and "OpenStreetMap" in summary["attribution"]
    assert summary["obstacle_cells"] > 0 and summary["unsafe_share"] > 0


def test_same_seed_same_field(tmp_path, capsys):
    a, b = tmp_path / "a", tmp_path / "b"
    for out in (a, b):
        assert cli(capsys, "risk", PAPER, "--out", str(out), "--set", "grid.cell=[100,100,60]")[0] == 0
    with np.load(a / "risk.npz") as x, np.load(b / "risk.npz") as y:
        for name in x.files:
            assert np.array_equal(x[name], y[name], equal_nan=True), name


@pytest.fixture
def bad_toml(tmp_path):
    def write(text: str) -> str:
        path = tmp_path / "bad.toml"
        path.write_text(text)
        return str(path)
    return write


@pytest.mark.parametrize(("text", "extra", "fragment"), [
    ("[grid\ncell = [1,1,1]", [], "malformed TOML"),
    ("[grid]\ncelll = [10, 10, 10]", [], "unknown key 'grid.celll'"),
    ("[grid]\ncell = [-10, 10, 10]", [], "grid.cell"),
    ("[grid]\ncell = [50, 50, 30]\nextent = [10, 4500, 300]", [], "no cells"),
    ("[city]\nsource = 'osm'\npbf = 'missing.osm.pbf'", [], "OpenStreetMap file not found"),
    ("[city]\nsource = 'dsm'\ndsm = 'missing.tif'", [], "missing.tif"),
    ("", ["grid.cell=[10,10,-1]"], "--set grid.cell"),
])
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, capsys, bad_toml, text, extra, fragment):
    out = tmp_path / "out"
    args = ["risk", bad_toml(text), "--out", str(out)]
    for item in extra:
        args += ["--set", item]
    assert_one_line_error(*cli(capsys, *args)[::2], fragment)
    assert not out.exists()


def test_missing_scenario_and_bad_arguments(tmp_path, capsys):
    assert_one_line_error(*cli(capsys, "risk", str(tmp_path / "none.toml"), "--out", str(tmp_path / "o"))[::2],
                          "not found")
    assert_one_line_error(*cli(capsys, "risk")[::2], "command line")
    assert_one_line_error(*cli(capsys, "frobnicate", PAPER)[::2], "command line")
    assert_one_line_error(*cli(capsys, "schedule", PAPER, "--solver", "highs", "--seed", "x")[::2], "command line")


def test_out_is_a_file(tmp_path, capsys):
    target = tmp_path / "file.txt"
    target.write_text("keep me")
    assert_one_line_error(*cli(capsys, "risk", PAPER, "--out", str(target))[::2], "output path is a file")
    assert target.read_text() == "keep me"


def test_a_degenerate_weighting_is_one_warning_line(tmp_path):
    """tracks.risk_model = "continuous" makes ω4·C_R about 10⁻³ of ω5·C_T at the default weights:
    the command says so in one `warning:` line naming the keys, and still writes its result."""
    out = tmp_path / "plan"
    done = run("plan", PAPER, "--set", 'tracks.risk_model="continuous"', "--no-figures", "--out", str(out))
    assert done.returncode == 0, done.stderr
    # progress lines ("plan: 1/3 steps, 5 s") appear when a step is slow (a loaded machine): not warnings
    lines = [line for line in done.stderr.strip().splitlines() if not re.match(r"plan: \d+/\d+ steps", line)]
    assert len(lines) == 1 and lines[0].startswith("warning: ") and "tracks.weights" in lines[0], done.stderr
    assert (out / "tracks.json").is_file()
    quiet = run("plan", PAPER, "--no-figures", "--out", str(tmp_path / "default"))
    assert quiet.returncode == 0 and "warning" not in quiet.stderr, quiet.stderr  # the binary default: no warning
