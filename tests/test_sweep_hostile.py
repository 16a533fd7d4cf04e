"""Hostile sweep input (issue 22, items 2 and 7 for sweeps): a results folder read through one
validated schema, a full disk or file-size limit during any write, and numbers in sweep files.

The reference is one uninterrupted run of a 3-case sweep (the paper case at 250 m cells, greedy
and HiGHS, seed 0) on the separately started cluster of conftest.py; every damaged folder below
is a copy of it, and whatever the damage, the table a re-run ends with must equal the reference
row for row (timing aside): a part that breaks the schema is set aside (renamed
``NAME.parquet.set-aside``, never deleted) and its case recomputed, a conflicting duplicate row is
never merged. A broken manifest or ``parts`` path is refused with one ``error:`` line, exit 2, the
folder untouched. A full disk (a real 200 KB tmpfs, ENOSPC) or a file-size limit
(``RLIMIT_FSIZE`` in the child, SIGXFSZ ignored: EFBIG) ends with one ``error:`` line naming the
file and the space it needs, exit 2, every part finished before it kept; a resume once the space
is there gives the reference table. Real components throughout: Dask workers, greedy, HiGHS,
the Parquet writer, the kernel's file system.
"""

from __future__ import annotations

import json
import math
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from test_sweep import PAPER, ROOT, assert_one_line_error, cli, snapshot, without_timing

SWEEP = f'''base = "{PAPER.as_posix()}"
stage = "schedule"
solvers = ["greedy", "highs"]
seeds = [0]
time_limit_s = 10.0

[set]
"grid.cell" = [250.0, 250.0, 60.0]
"tracks.equivalent" = "midpoint"
"network.routes" = [["V1", "V5"], ["V5", "V4"]]
"schedule.first_departure_window_s" = 300.0

[grid]
"schedule.aircraft" = [2, 3, 4]
'''
CASES = 3


@pytest.fixture(scope="module")
def sweep_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("hostile_sweep") / "fast.toml"
    path.write_text(SWEEP)
    return path


@pytest.fixture(scope="module")
def reference(sweep_file, cluster, tmp_path_factory) -> Path:
    """An uninterrupted run of the sweep, into a folder on an ordinary disk."""
    import uamopt as ua

    out = tmp_path_factory.mktemp("hostile_sweep") / "reference"
    table = ua.sweep(sweep_file, out=out, scheduler=cluster)
    assert table.attrs["run"] == CASES and len(table) == 2 * CASES and (table["status"] != "error").all()
    return out


def reference_table(reference: Path) -> pd.DataFrame:
    return without_timing(pd.read_parquet(reference / "results.parquet"))


def copy_of(reference: Path, tmp_path: Path) -> Path:
    out = tmp_path / "out"
    shutil.copytree(reference, out)
    return out


def parts_of(out: Path) -> list[Path]:
    return sorted((out / "parts").glob("*.parquet"))


def warnings_of(proc) -> list[str]:
    return [line for line in proc.stderr.splitlines() if line.startswith("warning: ")]


def rerun(capsys, sweep_file, out, cluster):
    proc = cli(capsys, "sweep", sweep_file, "--out", out, "--scheduler", cluster)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    return proc


# --- the results folder's schema ---------------------------------------------------------------

def _seed_string(frame):
    frame["seed"] = frame["seed"].astype(str)
    return frame


def _seed_float(frame):
    frame["seed"] = frame["seed"].astype(float) + 0.5
    return frame


def _operated_negative(frame):
    frame["operated"] = -frame["operated"]
    return frame


@pytest.mark.parametrize("damage", ["seed-string", "seed-float", "operated-negative", "truncated"])
def test_a_part_that_breaks_the_schema_is_set_aside_and_its_case_recomputed(reference, sweep_file, cluster, tmp_path,
                                                                           capsys, damage):
    out = copy_of(reference, tmp_path)
    part = parts_of(out)[0]
    if damage == "truncated":
        part.write_bytes(part.read_bytes()[:100])
    else:
        change = {"seed-string": _seed_string, "seed-float": _seed_float, "operated-negative": _operated_negative}[damage]
        change(pd.read_parquet(part)).to_parquet(part, index=False)
    damaged = part.read_bytes()
    proc = rerun(capsys, sweep_file, out, cluster)
    assert f"1 of {CASES} cases run now, {CASES - 1} already done" in proc.stdout
    aside = part.with_name(part.name + ".set-aside")
    assert aside.read_bytes() == damaged  # renamed, never deleted
    [line] = warnings_of(proc)
    assert str(part) in line and aside.name in line and "recomputed" in line, line
    assert part.is_file() and part.read_bytes() != damaged  # the case's new part, under its own name
    pd.testing.assert_frame_equal(without_timing(pd.read_parquet(out / "results.parquet")), reference_table(reference))


@pytest.mark.parametrize("where", ["same-part", "another-part-of-the-case", "a-part-of-another-case"])
def test_a_conflicting_duplicate_row_is_never_merged(reference, sweep_file, cluster, tmp_path, capsys, where):
    """A second row for a finished (case, solver, seed) with another objective, read before the
    genuine one (file order, then row order), so that keeping "the first" would take it."""
    out = copy_of(reference, tmp_path)
    first, second = parts_of(out)[:2]
    genuine = pd.read_parquet(second if where == "a-part-of-another-case" else first)
    rogue = genuine[genuine["solver"] == "highs"].copy()
    rogue["objective"] -= 1.0
    if where == "same-part":
        target = first
        pd.concat([rogue, genuine], ignore_index=True).to_parquet(target, index=False)
    elif where == "another-part-of-the-case":
        target = first.with_name(first.name.split("-")[0] + "-00000000.parquet")  # sorts before the genuine part
        assert target.name < first.name
        rogue.to_parquet(target, index=False)
    else:
        target = first  # another case's part, read before the genuine one
        pd.concat([rogue, pd.read_parquet(first)], ignore_index=True).to_parquet(target, index=False)
    written = target.read_bytes()
    proc = rerun(capsys, sweep_file, out, cluster)
    pd.testing.assert_frame_equal(without_timing(pd.read_parquet(out / "results.parquet")), reference_table(reference))
    aside = target.with_name(target.name + ".set-aside")
    assert aside.read_bytes() == written
    assert any(str(target) in line and "recomputed" in line for line in warnings_of(proc)), proc.stderr
    if where == "another-part-of-the-case":  # which of the two rows is right is unknown: both parts go
        assert first.with_name(first.name + ".set-aside").is_file()
        assert len(warnings_of(proc)) == 2


def test_a_parts_path_that_is_a_file_is_refused_untouched(reference, sweep_file, tmp_path, capsys):
    out = copy_of(reference, tmp_path)
    shutil.rmtree(out / "parts")
    (out / "parts").write_text("not a folder")
    before = snapshot(out)
    assert_one_line_error(cli(capsys, "sweep", sweep_file, "--out", out), "parts is not a folder")
    assert snapshot(out) == before


@pytest.mark.parametrize("solvers", [["greedy", "highs"], "greedy"], ids=["list", "string"])
def test_a_manifest_whose_solvers_is_not_a_table_is_refused_untouched(reference, sweep_file, tmp_path, capsys, solvers):
    out = copy_of(reference, tmp_path)
    manifest = json.loads((out / "sweep.json").read_text())
    manifest["solvers"] = solvers
    (out / "sweep.json").write_text(json.dumps(manifest))
    before = snapshot(out)
    assert_one_line_error(cli(capsys, "sweep", sweep_file, "--out", out), "sweep.json")
    assert snapshot(out) == before


def test_a_manifest_nested_deeply_is_refused_untouched(reference, sweep_file, tmp_path, capsys):
    out = copy_of(reference, tmp_path)
    (out / "sweep.json").write_text('{"uamopt_sweep": 1, "solvers": ' + "[" * 10**5 + "]" * 10**5 + "}")
    before = snapshot(out)
    assert_one_line_error(cli(capsys, "sweep", sweep_file, "--out", out), "sweep.json")
    assert snapshot(out) == before


# --- a full disk, a file-size limit ------------------------------------------------------------

def _one_error_line(proc) -> str:
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr, proc.stderr
    errors = [line for line in proc.stderr.splitlines() if line.startswith("error: ")]
    assert len(errors) == 1, proc.stderr
    return errors[0]


def _no_temporaries(out: Path) -> None:
    assert not [p for p in out.rglob("*") if p.name.endswith(".tmp")]  # nothing half-written


def _resume_equals_reference(sweep_file, out, cluster, reference, kept: dict, run: int) -> None:
    proc = subprocess.run([sys.executable, "-m", "uamopt", "sweep", str(sweep_file), "--out", str(out), "--scheduler", cluster],
                          cwd=ROOT, capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr
    assert f"{run} of {CASES} cases run now, {CASES - run} already done" in proc.stdout
    assert all(snapshot(out / "parts")[name] == data for name, data in kept.items())  # kept, never rewritten
    pd.testing.assert_frame_equal(without_timing(pd.read_parquet(out / "results.parquet")), reference_table(reference))


@pytest.fixture
def tmpfs(tmp_path):
    """A real 200 KB tmpfs (ENOSPC when full), unmounted afterwards; skipped where mount fails."""
    disk = tmp_path / "disk"
    disk.mkdir()
    if shutil.which("mount") is None:
        pytest.skip("no mount command: cannot make a small tmpfs for the full-disk case")
    proc = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=200k", "tmpfs", str(disk)], capture_output=True, text=True,
                          check=False)
    if proc.returncode != 0:
        reason = f"cannot mount a 200 KB tmpfs (needs root): {proc.stderr.strip() or proc.returncode}"
        print(reason)
        pytest.skip(reason)
    try:
        yield disk
    finally:
        subprocess.run(["umount", "-l", str(disk)], check=False)


def test_a_full_disk_keeps_the_finished_cases_and_a_resume_completes_them(reference, sweep_file, cluster, tmpfs):
    page = os.sysconf("SC_PAGE_SIZE")
    part_pages = math.ceil(max(p.stat().st_size for p in parts_of(reference)) / page)
    filler = tmpfs / "filler"
    free_pages = os.statvfs(tmpfs).f_bavail
    keep_free = 1 + 2 * part_pages + 1  # the manifest, two parts and a page: not a third part
    filler.write_bytes(b"\0" * ((free_pages - keep_free) * page))
    assert os.statvfs(tmpfs).f_bavail == keep_free

    out = tmpfs / "out"
    proc = subprocess.run([sys.executable, "-m", "uamopt", "sweep", str(sweep_file), "--out", str(out), "--scheduler", cluster],
                          cwd=ROOT, capture_output=True, text=True, timeout=300, check=False)
    line = _one_error_line(proc)
    assert re.search(rf"{re.escape(str(out / 'parts'))}/[0-9a-f]{{12}}-[0-9a-f]{{8}}\.parquet", line), line
    assert "No space left on device" in line and re.search(r"needs about [\d.]+ [KM]B", line), line
    assert re.search(r"[\d.]+ [KM]?B free", line), line
    saved = parts_of(out)
    assert 1 <= len(saved) < CASES, proc.stderr
    for part in saved:  # whole parts, each readable
        assert len(pd.read_parquet(part)) == 2
    assert not (out / "results.parquet").exists()
    _no_temporaries(out)

    filler.unlink()  # space freed
    _resume_equals_reference(sweep_file, out, cluster, reference, snapshot(out / "parts"), CASES - len(saved))


def _limited(limit: int):
    def preexec():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG instead of killing
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return preexec


@pytest.mark.parametrize("fails", ["part", "results"])
def test_a_file_size_limit_keeps_the_finished_cases_and_a_resume_completes_them(reference, sweep_file, cluster, tmp_path,
                                                                               fails):
    largest_part = max(p.stat().st_size for p in parts_of(reference))
    results = (reference / "results.parquet").stat().st_size
    assert (reference / "sweep.json").stat().st_size < largest_part - 1000 and largest_part < results - 200
    # below every part, or above every part and below results.parquet
    limit = largest_part - 1000 if fails == "part" else (largest_part + results) // 2
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "uamopt", "sweep", str(sweep_file), "--out", str(out), "--scheduler", cluster],
                          cwd=ROOT, capture_output=True, text=True, timeout=300, preexec_fn=_limited(limit),
                          check=False)
    line = _one_error_line(proc)
    assert "File too large" in line and "ulimit -f" in line and re.search(r"needs [\d.]+ KB", line), line
    if fails == "part":
        assert re.search(rf"{re.escape(str(out / 'parts'))}/[0-9a-f]{{12}}-[0-9a-f]{{8}}\.parquet", line), line
        assert parts_of(out) == []
    else:
        assert str(out / "results.parquet") in line, line
        assert len(parts_of(out)) == CASES and not (out / "results.parquet").exists()
    _no_temporaries(out)
    _resume_equals_reference(sweep_file, out, cluster, reference, snapshot(out / "parts"), CASES - len(parts_of(out)))


def test_a_file_size_limit_the_local_workers_inherit_stops_the_sweep_and_saves_no_error_rows(reference, sweep_file,
                                                                                            tmp_path):
    """Under ``ulimit -f`` the local cluster's workers inherit the limit, and a case's own writes (the
    verifier's schedule folder) fail there. That is the machine's state, not the case's result: the
    sweep stops in one line, no part holds an error row (a resume would take it as done), and a resume
    without the limit equals an uninterrupted run. Before, every case was saved as an error row and
    the sweep exited 0 with a table of errors that a resume kept."""
    largest_part = max(p.stat().st_size for p in parts_of(reference))
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "uamopt", "sweep", str(sweep_file), "--out", str(out), "--workers", "1"],
                          cwd=ROOT, capture_output=True, text=True, timeout=600, preexec_fn=_limited(largest_part + 1000),
                          check=False)
    line = _one_error_line(proc)
    assert "File too large" in line, line
    for part in parts_of(out):
        assert (pd.read_parquet(part)["status"] != "error").all(), part
    proc = subprocess.run([sys.executable, "-m", "uamopt", "sweep", str(sweep_file), "--out", str(out), "--workers", "1"],
                          cwd=ROOT, capture_output=True, text=True, timeout=600, check=False)
    assert proc.returncode == 0, proc.stderr
    pd.testing.assert_frame_equal(without_timing(pd.read_parquet(out / "results.parquet")), reference_table(reference))


# --- numbers in sweep files ----------------------------------------------------------------------

def write_sweep(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "bad.toml"
    path.write_text(f'base = "{PAPER.as_posix()}"\n' + body)
    return path


@pytest.mark.parametrize(("body", "fragment"), [
    ('[grid]\n"schedule.aircraft" = [2, 1979-05-27]\n', '"schedule.aircraft"'),
    ('[set]\n"schedule.service_s" = 07:32:00\n[grid]\n"schedule.aircraft" = [2]\n', '"schedule.service_s"'),
    ('[grid]\n"aircraft.cruise_speed_mps" = [1979-05-27T07:32:00Z]\n', '"aircraft.cruise_speed_mps"'),
    ('[grid]\n"schedule.aircraft" = [2]\n[small.grid]\n"schedule.aircraft" = [1979-05-27T07:32:00]\n', '"schedule.aircraft"'),
], ids=["grid-date", "set-time", "grid-datetime", "small-local-datetime"])
def test_a_date_or_time_where_a_number_belongs(tmp_path, capsys, body, fragment):
    sweep = write_sweep(tmp_path, body)
    args = ["--small"] if "[small" in body else []
    proc = cli(capsys, "sweep", sweep, "--out", tmp_path / "out", *args)
    assert_one_line_error(proc, "date or time")
    assert fragment in proc.stderr
    assert not (tmp_path / "out").exists()


def test_a_seed_beyond_32_bits_is_refused(tmp_path, capsys):
    """HiGHS (and CP-SAT) seeds are int32, as a profile's seed is (uamopt/solvers/options.py)."""
    sweep = write_sweep(tmp_path, f'solvers = ["highs"]\nseeds = [0, {2**40}]\n[grid]\n"schedule.aircraft" = [2]\n')
    assert_one_line_error(cli(capsys, "sweep", sweep, "--out", tmp_path / "out"), "2147483647")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("small", ["small = 5", 'small = ["seeds"]', '[small]\nseeds = "all"', "[small]\nset = 3"])
def test_a_small_that_is_not_a_table_of_the_right_shape_is_refused_without_small(tmp_path, capsys, small):
    """Checked whether or not --small is given: a broken [small] is an error in the file."""
    grid = '[grid]\n"schedule.aircraft" = [2]\n'
    sweep = write_sweep(tmp_path, grid + small + "\n" if small.startswith("[") else small + "\n" + grid)
    assert_one_line_error(cli(capsys, "sweep", sweep, "--out", tmp_path / "out"), "small")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(("body", "fragment"), [
    ('set = 5\n[grid]\n"schedule.aircraft" = [2]\n', "[set] must be a table"),
    ("grid = 5\n", "[grid] must be a table"),
    ('[grid]\n"schedule.aircraft" = 2\n', "must be a list"),
    ('name = 5\n[grid]\n"schedule.aircraft" = [2]\n', "name must be a string"),
])
def test_a_table_or_name_of_the_wrong_type(tmp_path, capsys, body, fragment):
    assert_one_line_error(cli(capsys, "sweep", write_sweep(tmp_path, body), "--out", tmp_path / "out"), fragment)


def test_a_grid_of_a_hundred_million_cases_is_refused_up_front(tmp_path):
    """10⁸ cases (four keys of 100 values): refused from its size, before any case is built (under a
    1 GB address-space limit, which building the cases' table would exceed many times over)."""
    values = ", ".join(str(v) for v in range(1, 101))
    grid = "".join(f'"{key}" = [{values}]\n' for key in ("schedule.aircraft", "schedule.flights", "schedule.plan_seed",
                                                          "city.seed"))
    sweep = write_sweep(tmp_path, f'solvers = ["greedy", "highs"]\n[grid]\n{grid}')
    def one_gb():
        resource.setrlimit(resource.RLIMIT_AS, (2**30, 2**30))

    proc = subprocess.run([sys.executable, "-m", "uamopt", "sweep", str(sweep), "--out", str(tmp_path / "out")], cwd=ROOT,
                          capture_output=True, text=True, timeout=600, check=False, preexec_fn=one_gb)
    assert_one_line_error(proc, "100,000,000 cases")
    assert "200,000,000 rows" in proc.stderr and "max_cases" in proc.stderr and "10,000" in proc.stderr
    assert not (tmp_path / "out").exists()


def test_max_cases_is_the_limit(sweep_file, tmp_path, capsys):
    lower = tmp_path / "lower.toml"
    lower.write_text("max_cases = 2\n" + sweep_file.read_text())
    proc = cli(capsys, "sweep", lower, "--out", tmp_path / "out")
    assert_one_line_error(proc, f"{CASES} cases")
    assert "more than the limit of 2" in proc.stderr
    for bad in ("0", "true", '"many"', "2.5"):
        lower.write_text(f"max_cases = {bad}\n" + sweep_file.read_text())
        assert_one_line_error(cli(capsys, "sweep", lower, "--out", tmp_path / "out"), "max_cases must be a whole number")
    assert not (tmp_path / "out").exists()
