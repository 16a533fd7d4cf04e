"""``uamopt sweep``: resumable Dask sweeps (docs/sweeps.md).

The reference is one uninterrupted run of tests/data/sweeps/tiny.toml (4 cases × greedy, HiGHS)
on a separately started ``dask scheduler`` + two ``dask worker`` processes (conftest.py); a run on
the default local cluster that is killed after two cases and then resumed must give the same
table row for row (timing aside). Solvers: real greedy and real HiGHS; workers: real processes.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "data" / "sweeps" / "tiny.toml"
PAPER = ROOT / "models" / "paper_case.toml"
COLUMNS = ["case", "schedule.aircraft", "aircraft.cruise_speed_mps", "solver", "seed", "status", "termination",
           "proved_for", "model", "objective_kind", "objective", "bound", "gap", "operated", "cancelled", "total_delay_s",
           "avg_delay_s", "verified", "seconds", "risk_cost", "transport_cost", "length_m", "n_waypoints"]


def uamopt(*args, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "uamopt", *map(str, args)], cwd=ROOT, capture_output=True, text=True,
                          timeout=timeout)


def cli(capsys, *args) -> subprocess.CompletedProcess:
    """The command line in this process (for the errors raised before anything runs)."""
    from uamopt.cli import main

    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return subprocess.CompletedProcess(args, code, out, err)


def without_timing(table: pd.DataFrame) -> pd.DataFrame:
    return table.drop(columns=["seconds"])


def assert_one_line_error(proc, fragment: str) -> None:
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and fragment in lines[0], proc.stderr


def snapshot(folder: Path) -> dict:
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def reference(cluster, tmp_path_factory) -> Path:
    """An uninterrupted run of the tiny sweep file, unchanged, on the separately started cluster."""
    assert cluster.startswith("tcp://127.0.0.1:")
    out = tmp_path_factory.mktemp("sweep") / "reference"
    proc = uamopt("sweep", TINY, "--out", out, "--scheduler", cluster)
    assert proc.returncode == 0, proc.stderr
    assert "8 rows (0 with errors), 4 of 4 cases run now" in proc.stdout
    # not on a terminal: a start line and a final line instead of a bar
    assert "sweep tiny: 0/4 cases" in proc.stderr and "sweep tiny: 4/4 cases" in proc.stderr
    return out


def test_results_table(reference):
    table = pd.read_parquet(reference / "results.parquet")
    assert list(table.columns[:len(COLUMNS)]) == COLUMNS
    assert {"error", "uamopt_version", "flights", "aircraft", "conflicting_pairs"} <= set(table.columns)
    assert len(table) == 8 and table["case"].nunique() == 4
    # grid order (the product of the lists as written), then solver order
    assert table["schedule.aircraft"].tolist() == [3, 3, 3, 3, 4, 4, 4, 4]
    assert table["aircraft.cruise_speed_mps"].tolist() == [20.0, 20.0, 30.0, 30.0] * 2
    assert table["solver"].tolist() == ["greedy", "highs"] * 4
    assert table["verified"].all() and table["error"].isna().all()
    # G aircraft × F flights; Eq. 23 by hand for routes of ~2.2-2.4 km at 20 or 30 m/s:
    # cycle = 2·L/v + T_D + T_R + χ = 747-840 s, so ⌊3600 / cycle⌋ × 2 = 8 flights each
    assert (table["flights"] == 8 * table["schedule.aircraft"]).all()
    assert (table["operated"] + table["cancelled"] == table["flights"]).all()
    assert table["avg_delay_s"].tolist() == pytest.approx((table["total_delay_s"] / table["aircraft"]).tolist())
    highs, greedy = table[table["solver"] == "highs"], table[table["solver"] == "greedy"]
    assert (highs["status"] == "optimal").all() and (highs["gap"] < 1e-6).all()
    assert (highs["termination"] == "optimal").all() and (highs["proved_for"] == "continuous").all()
    assert (greedy["termination"] == "stopped").all() and (greedy["proved_for"] == "none").all()
    # the lexicographic objective is at least −F (every flight flown, none delayed): on these cases the
    # optimum reaches it (regression: greedy does too, −24 and −32), so HiGHS is checked against a value it
    # does not compute, not against greedy, its own warm start
    assert (table["objective_kind"] == "lexicographic").all()
    least = -highs["flights"].to_numpy()
    assert highs["objective"].to_numpy() == pytest.approx(least, abs=1e-9) and highs["bound"].to_numpy() == pytest.approx(least)
    assert (highs["operated"] == highs["flights"]).all()
    assert greedy["bound"].isna().all() and greedy["gap"].isna().all()  # undefined, not a sentinel
    # the case id is a function of the overrides only: the same for the same case of another run
    assert len(set(table["case"])) == 4 and all(len(c) == 12 for c in table["case"])


def test_interrupted_sweep_resumes_to_the_same_table(reference, tmp_path):
    out = tmp_path / "resumed"
    log = open(tmp_path / "first.log", "w")
    first = subprocess.Popen([sys.executable, "-m", "uamopt", "sweep", str(TINY), "--out", str(out), "--workers", "1"],
                             cwd=ROOT, stdout=log, stderr=log, start_new_session=True)
    deadline = time.monotonic() + 240
    try:
        while len(list((out / "parts").glob("*.parquet"))) < 2 and first.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
    finally:
        os.killpg(first.pid, signal.SIGKILL)  # the sweep and its cluster, as a crash would
        first.wait()
        log.close()
    saved = snapshot(out / "parts")
    parts = [p for p in saved if not p.name.startswith(".")]
    assert 2 <= len(parts) < 4, (tmp_path / "first.log").read_text()
    assert not (out / "results.parquet").exists()
    second = uamopt("sweep", TINY, "--out", out, "--workers", 2)
    assert second.returncode == 0, second.stderr
    assert f"{4 - len(parts)} of 4 cases run now, {len(parts)} already done" in second.stdout
    after = snapshot(out / "parts")
    assert all(after[name] == data for name, data in saved.items())  # saved parts never rewritten
    resumed = pd.read_parquet(out / "results.parquet")
    pd.testing.assert_frame_equal(without_timing(resumed), without_timing(pd.read_parquet(reference / "results.parquet")))


def test_library_call_on_a_finished_folder_runs_nothing(reference, tmp_path):
    import uamopt as ua

    out = tmp_path / "copy"
    shutil.copytree(reference, out)
    table = ua.sweep(TINY, out=out)
    assert table.attrs["run"] == 0 and table.attrs["cases"] == 4
    pd.testing.assert_frame_equal(table, pd.read_parquet(reference / "results.parquet"))


def test_extending_the_grid_runs_only_the_new_cases(reference, cluster, tmp_path):
    import uamopt as ua

    out = tmp_path / "extended"
    shutil.copytree(reference, out)
    saved = snapshot(out / "parts")
    wider = tmp_path / "wider.toml"
    wider.write_text(TINY.read_text().replace("[20.0, 30.0]", "[20.0, 30.0, 25.0]").replace(
        'base = "../../../models/paper_case.toml"', f'base = "{PAPER.as_posix()}"'))
    table = ua.sweep(wider, out=out, scheduler=cluster)
    assert table.attrs["run"] == 2 and len(table) == 12
    assert table["aircraft.cruise_speed_mps"].tolist() == [20.0, 20.0, 30.0, 30.0, 25.0, 25.0] * 2
    assert all(snapshot(out / "parts")[name] == data for name, data in saved.items())
    old = pd.read_parquet(reference / "results.parquet")
    kept = table[table["case"].isin(old["case"])].reset_index(drop=True)
    pd.testing.assert_frame_equal(without_timing(kept), without_timing(old))


def test_a_failing_case_is_a_row_not_a_crash(cluster, tmp_path):
    """290 m cruise: the return direction's layer lies above the band (h'_max = 300 m)."""
    import uamopt as ua

    sweep_file = tmp_path / "altitude.toml"
    sweep_file.write_text(f'base = "{PAPER.as_posix()}"\nstage = "network"\n[set]\n"tracks.equivalent" = "midpoint"\n'
                          '[grid]\n"network.cruise_altitude_m" = [120.0, 290.0]\n')
    table = ua.sweep(sweep_file, out=tmp_path / "out", scheduler=cluster)
    assert table["network.cruise_altitude_m"].tolist() == [120.0, 290.0]
    assert table["status"].tolist() == ["ok", "error"]
    assert "no cell layer in the altitude band" in table["error"].iloc[1] and pd.isna(table["error"].iloc[0])
    assert table["length_m"].iloc[0] > 20 * 1000 and pd.isna(table["length_m"].iloc[1])
    assert "solver" in table.columns and table["solver"].isna().all() and table["seed"].isna().all()
    # the error row is saved like any other: nothing is recomputed on a re-run
    assert ua.sweep(sweep_file, out=tmp_path / "out").attrs["run"] == 0


@pytest.mark.parametrize(("body", "fragment"), [
    ('[grid]\n"schedule.flightz" = [1, 2]\n', "unknown key 'schedule.flightz'"),
    ('[set]\n"grid.celll" = [10, 10, 10]\n[grid]\n"schedule.aircraft" = [2]\n', "unknown key 'grid.celll'"),
    ('[grid]\n"schedule.aircraft" = []\n', "empty grid"),
    ("", "empty grid"),
    ('[grid]\n"schedule.aircraft" = [2, 0]\n', "case schedule.aircraft = 0"),
    ('solvers = ["nope"]\n[grid]\n"schedule.aircraft" = [2]\n', "solver profile not found"),
    ('stage = "plan"\nseeds = [0]\n[grid]\n"schedule.aircraft" = [2]\n', "'seeds' applies to stage"),
    ('frobnicate = 1\n[grid]\n"schedule.aircraft" = [2]\n', "unknown key 'frobnicate'"),
])
def test_bad_sweep_file(tmp_path, capsys, body, fragment):
    sweep_file = tmp_path / "bad.toml"
    sweep_file.write_text(f'base = "{PAPER.as_posix()}"\n' + body)
    out = tmp_path / "out"
    assert_one_line_error(cli(capsys, "sweep", sweep_file, "--out", out), fragment)
    assert not out.exists()


def test_bad_options(tmp_path, capsys):
    out = tmp_path / "out"
    assert_one_line_error(cli(capsys, "sweep", TINY, "--out", out, "--workers", 0), "--workers must be a whole number")
    assert_one_line_error(cli(capsys, "sweep", TINY, "--out", out, "--workers", 2, "--scheduler", "tcp://127.0.0.1:9"),
                          "--workers applies to the local cluster")
    assert_one_line_error(cli(capsys, "sweep", tmp_path / "missing.toml", "--out", out), "sweep file not found")
    assert not out.exists()


def test_unreachable_scheduler_fails_fast_and_touches_nothing(reference, tmp_path, capsys):
    out = tmp_path / "partial"
    shutil.copytree(reference, out)
    missing = next((out / "parts").glob("*.parquet"))
    missing.unlink()  # one case left to run, so the sweep needs the cluster
    before = snapshot(out)
    proc = cli(capsys, "sweep", TINY, "--out", out, "--scheduler", "tcp://127.0.0.1:9")
    assert_one_line_error(proc, "cannot reach the Dask scheduler at tcp://127.0.0.1:9")
    assert snapshot(out) == before


def test_corrupt_or_foreign_results_folder_is_refused_untouched(reference, tmp_path, capsys):
    corrupt = tmp_path / "corrupt"
    shutil.copytree(reference, corrupt)
    (corrupt / "sweep.json").write_text("{not json")  # (a broken part is set aside instead: test_sweep_hostile.py)
    before = snapshot(corrupt)
    assert_one_line_error(cli(capsys, "sweep", TINY, "--out", corrupt), "sweep.json is unreadable")
    assert snapshot(corrupt) == before

    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    assert_one_line_error(cli(capsys, "sweep", TINY, "--out", foreign), "not a sweep results folder")
    assert (foreign / "notes.txt").read_text() == "mine" and len(list(foreign.iterdir())) == 1

    other = tmp_path / "other"
    shutil.copytree(reference, other)
    before = snapshot(other)
    assert_one_line_error(cli(capsys, "sweep", TINY, "--out", other, "--small"), "holds another sweep (--small differs)")
    assert snapshot(other) == before
