"""End-to-end: the commands as a user runs them, and the one-line errors of INTERFACES.md."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
PAPER = str(ROOT / "models" / "paper_case.toml")


def run(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "uamopt", *args], cwd=cwd, capture_output=True, text=True, timeout=300)


def assert_one_line_error(proc: subprocess.CompletedProcess, fragment: str) -> None:
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("error: ") and fragment in lines[0], lines[0]
    assert "Traceback" not in proc.stderr


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


def test_reproduce_writes_the_report(tmp_path):
    out = tmp_path / "paper"
    proc = run("reproduce", PAPER, "--out", str(out), "--set", "tracks.table2_cell_m=25", "--set", "tracks.table4_cells=[]")
    assert proc.returncode == 0, proc.stderr
    assert "report.md" in proc.stdout
    report = (out / "report.md").read_text()
    assert "Operational risk field" in report and "![risk map](risk.png)" in report
    assert "27.4684" in report  # terminal speed at m_p = 0 beside the reference 27.468
    assert "Table 2 analogue" in report and "Route network" in report
    expected = {"risk.npz", "risk.png", "summary.json", "report.md", "tracks.json", "tracks.png", "network.json", "network.png"}
    assert expected <= {p.name for p in out.iterdir()}


def test_plan_command(tmp_path):
    out = tmp_path / "plan"
    proc = run("plan", PAPER, "--from", "300,300,120", "--to", "2220,4220,120", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((out / "tracks.json").read_text())
    assert list(doc["stages"]) == ["shortest", "initial", "equivalent", "optimal"]
    for stage in doc["stages"].values():
        pts = np.asarray(stage["waypoints"])
        assert stage["n_waypoints"] == len(pts)
        assert stage["length_m"] == pytest.approx(float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum()))
    assert doc["stages"]["optimal"]["waypoints"][0] == [300.0, 300.0, 120.0]
    assert (out / "tracks.png").stat().st_size > 10_000


def test_network_command(tmp_path):
    out = tmp_path / "net"
    proc = run("network", PAPER, "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    doc = json.loads((out / "network.json").read_text())
    assert len(doc["routes"]) == 20 and doc["routes"]["V1-V4"]["origin"] == "V1"


@pytest.mark.parametrize("args, fragment", [
    (["--from", "300,300,50"], "outside the band"),
    (["--from", "300,300"], "not a point"),
    (["--from", "9000,300,120"], "outside the grid"),
    (["--set", "aircraft.range_m=2000"], "range"),
])
def test_plan_bad_input(tmp_path, args, fragment):
    out = tmp_path / "o"
    assert_one_line_error(run("plan", PAPER, "--out", str(out), *args), fragment)
    assert not out.exists()


def test_plan_origin_in_building_and_unreachable_destination(tmp_path):
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
    assert_one_line_error(run("plan", str(scenario), "--from", "30,30,120", "--to", "120,120,135", "--out", str(out)),
                          "inside a building")
    assert_one_line_error(run("plan", str(scenario), "--from", "30,30,120", "--to", "200,200,120", "--out", str(out)),
                          "no admissible track")
    assert not out.exists()


def test_helsinki_from_openstreetmap(tmp_path):
    out = tmp_path / "hel"
    proc = run("risk", str(ROOT / "models" / "helsinki.toml"), "--out", str(out), "--set", "grid.cell=[40,40,30]")
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["source"] == "osm" and "OpenStreetMap" in summary["attribution"]
    assert summary["obstacle_cells"] > 0 and summary["unsafe_share"] > 0


def test_same_seed_same_field(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    for out in (a, b):
        assert run("risk", PAPER, "--out", str(out), "--set", "grid.cell=[100,100,60]").returncode == 0
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


@pytest.mark.parametrize("text, extra, fragment", [
    ("[grid\ncell = [1,1,1]", [], "malformed TOML"),
    ("[grid]\ncelll = [10, 10, 10]", [], "unknown key 'grid.celll'"),
    ("[grid]\ncell = [-10, 10, 10]", [], "grid.cell"),
    ("[grid]\ncell = [50, 50, 30]\nextent = [10, 4500, 300]", [], "no cells"),
    ("[city]\nsource = 'osm'\npbf = 'missing.osm.pbf'", [], "OpenStreetMap file not found"),
    ("[city]\nsource = 'dsm'\ndsm = 'missing.tif'", [], "missing.tif"),
    ("", ["grid.cell=[10,10,-1]"], "--set grid.cell"),
])
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, bad_toml, text, extra, fragment):
    out = tmp_path / "out"
    args = ["risk", bad_toml(text), "--out", str(out)]
    for item in extra:
        args += ["--set", item]
    proc = run(*args)
    assert_one_line_error(proc, fragment)
    assert not out.exists()


def test_missing_scenario_and_bad_arguments(tmp_path):
    assert_one_line_error(run("risk", str(tmp_path / "none.toml"), "--out", str(tmp_path / "o")), "not found")
    assert_one_line_error(run("risk"), "command line")
    assert_one_line_error(run("frobnicate", PAPER), "command line")


def test_out_is_a_file(tmp_path):
    target = tmp_path / "file.txt"
    target.write_text("keep me")
    assert_one_line_error(run("risk", PAPER, "--out", str(target)), "output path is a file")
    assert target.read_text() == "keep me"


def test_schedule_verify_and_bench(tmp_path):
    out = tmp_path / "sched"
    proc = run("schedule", PAPER, "--solver", "highs", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "optimal" and summary["operated"] + summary["cancelled"] == 120
    assert summary["avg_delay_s"] == pytest.approx(summary["total_delay_s"] / 20)
    lines = (out / "schedule.csv").read_text().splitlines()
    assert lines[0] == "flight,aircraft,route,operated,planned_departure_s,delay_s,departure_s,arrival_s"
    assert len(lines) == 121
    assert run("verify", str(out)).returncode == 0
    # plant a conflict: run two flights on one route at the same time -> the verifier exits 1
    rows = [l.split(",") for l in lines[1:]]
    first = next(r for r in rows if r[3] == "1")
    twin = next(r for r in rows if r[2] == first[2] and r[0] != first[0] and r[1] != first[1])
    twin[3], twin[5], twin[6] = "1", "0.0", first[6]
    twin[4] = str(float(first[6]))
    twin[7] = str(float(first[7]))
    (out / "schedule.csv").write_text("\n".join([lines[0]] + [",".join(r) for r in rows]) + "\n")
    bad = run("verify", str(out))
    assert bad.returncode == 1 and bad.stdout.strip()
    # `uamopt bench`: tests/test_benchmark.py


def test_schedule_bad_input(tmp_path):
    flights = tmp_path / "flights.json"
    flights.write_text(json.dumps({"cell": [50, 50, 30], "conflict_radius": 1, "flights": [
        {"id": "f1", "aircraft": "A", "route": "V9-V1", "origin": "V9", "destination": "V1", "speed_mps": 25,
         "planned_departure_s": 0, "max_delay_s": 100}]}))
    out = tmp_path / "o"
    assert_one_line_error(run("schedule", PAPER, "--solver", "greedy", "--flights", str(flights), "--out", str(out)),
                          "unknown route")
    assert_one_line_error(run("schedule", PAPER, "--solver", "nosuch", "--out", str(out)), "solver profile not found")
    assert not out.exists()
