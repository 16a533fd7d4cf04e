"""The machine and the files around a run (issue 10, class 7): a read-only install (no writable
numba cache), a huge scenario name, a spreadsheet's BOM in schedule.csv, and errors that name the
scenario key an end point came from, not an option the user never passed."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import uamopt as ua
from uamopt.cli import main
from uamopt.errors import ScenarioError
from uamopt.scenario import load_scenario
from uamopt.schedule.verify import verify_dir

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "models" / "paper_case.toml"
TINY = ["--set", "grid.cell=[250,250,60]"]


def unwritable_cache(tmp_path: Path, kind: str) -> dict:
    """numba settings of a read-only install: only NUMBA_CACHE_DIR is tried (the package's own
    __pycache__ and the home folder are read-only there), and it cannot be written."""
    if kind == "read-only folder":
        if os.geteuid() == 0:
            pytest.skip("root writes into a read-only folder; the other kind covers root")
        folder = tmp_path / "cache"
        folder.mkdir()
        folder.chmod(0o555)
    else:  # a path through a regular file: no user, root included, can create it
        (tmp_path / "file").write_text("")
        folder = tmp_path / "file" / "cache"
    return {"NUMBA_CACHE_DIR": str(folder), "NUMBA_CACHE_LOCATOR_CLASSES": "UserProvidedCacheLocator"}


@pytest.mark.parametrize("kind", ["read-only folder", "path through a file"])
def test_the_search_loads_without_a_writable_numba_cache(tmp_path, kind):
    """numba refuses cache=True with a RuntimeError at import when no cache folder is writable;
    the search then compiles without a cache."""
    env = os.environ | unwritable_cache(tmp_path, kind)
    done = subprocess.run([sys.executable, "-c", "import uamopt.planning.search"], check=False, env=env, cwd=tmp_path,
                          capture_output=True, text=True)
    assert done.returncode == 0 and done.stderr == "", done.stderr


@pytest.mark.slow
def test_plan_without_a_writable_numba_cache(tmp_path):
    env = os.environ | unwritable_cache(tmp_path, "path through a file")
    out = tmp_path / "plan"
    done = subprocess.run([sys.executable, "-m", "uamopt", "plan", str(PAPER), *TINY, "--no-figures", "--out", str(out)],
                          check=False, env=env, cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert ua.load_tracks(out).stages["optimal"].length_m > 0


def test_a_huge_scenario_name_is_refused_in_one_short_line(tmp_path, capsys):
    """A 5 MB name (a figure title) took minutes to draw; it is refused at the boundary, and the
    error line does not repeat it."""
    huge = "x" * 5_000_000
    with pytest.raises(ScenarioError, match=r"for 'name': String should have at most 200 characters"):
        load_scenario(PAPER, [f'name="{huge}"'])
    scenario = tmp_path / "huge.toml"
    scenario.write_text(PAPER.read_text().replace('name = "paper_case"', f'name = "{huge}"'))
    assert main(["risk", str(scenario), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: invalid value 'xxx") and "(5,000,002 characters)" in err and len(err) < 400
    assert not (tmp_path / "out").exists()
    assert load_scenario(PAPER, [f'name="{"y" * 200}"']).name == "y" * 200


def test_a_byte_order_mark_is_accepted(paper_schedule_dir, paper_export, tmp_path):
    """Excel saves "CSV UTF-8" with a byte-order mark and CRLF line ends; some editors put the
    mark in JSON too."""
    folder = tmp_path / "excel"
    shutil.copytree(paper_schedule_dir, folder)
    text = (paper_schedule_dir / "schedule.csv").read_text(encoding="utf-8")
    (folder / "schedule.csv").write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode("utf-8"))
    for name in ("summary.json", "flights.json"):
        (folder / name).write_bytes(b"\xef\xbb\xbf" + (paper_schedule_dir / name).read_bytes())
    assert verify_dir(folder) == []
    original, edited = ua.load_schedule(paper_schedule_dir), ua.load_schedule(folder)
    assert edited.flight_ids == original.flight_ids and np.array_equal(edited.operated, original.operated)
    assert main(["export", "bluesky", str(folder)]) == 0
    edited_scn, original_scn = ((f / "bluesky.scn").read_text().split("\n", 1) for f in (folder, paper_export("bluesky")))
    assert edited_scn[0] == original_scn[0].replace("highs", "excel")  # the header names the folder
    assert edited_scn[1] == original_scn[1]


@pytest.mark.parametrize(("overrides", "where"), [
    (["tracks.origin=[9000.0,300.0,120.0]"], "tracks.origin"),
    (["tracks.destination=[2220.0,4220.0,20.0]"], "tracks.destination"),
    (["tracks.route=['V1','V9']"], "tracks.route"),
])
def test_an_end_point_error_names_the_scenario_key(overrides, where, tmp_path, capsys):
    """No --from or --to given: the error names the key the end point came from."""
    args = ["plan", str(PAPER), *TINY, "--no-figures", "--out", str(tmp_path / "plan")]
    for item in overrides:
        args += ["--set", item]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert f"({where})" in err and "--from" not in err and "--to" not in err, err
    assert len(err.splitlines()) == 1 and not (tmp_path / "plan").exists()
