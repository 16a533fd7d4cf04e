"""The verifier trusts nothing it verifies: tampered schedule folders are one `error:` line and
exit 2 (malformed) or a violation and exit 1, never a pass."""

from __future__ import annotations

import itertools
import json
import shutil

import pytest
from conftest import PAPER_CASE

from uamopt.cli import main


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    out = tmp_path_factory.mktemp("good") / "s"
    assert main(["schedule", str(PAPER_CASE), "--solver", "greedy", "--set", "tracks.layering='none'",
                 "--out", str(out)]) == 0
    return out


def tampered(good, tmp_path, edit):
    folder = tmp_path / "t"
    shutil.copytree(good, folder)
    doc = json.loads((folder / "flights.json").read_text())
    edit(doc)
    (folder / "flights.json").write_text(json.dumps(doc))
    return folder


def _set(key, value):
    return lambda d: d.__setitem__(key, value)


def _first(key, value):
    return lambda d: d["flights"][0].__setitem__(key, value)


@pytest.mark.parametrize(("edit", "fragment"), [
    (_set("conflict_radius", -1), "conflict_radius must be an integer"),
    (_set("conflict_radius", "abc"), "conflict_radius must be an integer"),
    (_set("conflict_radius", True), "conflict_radius must be an integer"),
    (_set("conflict_radius", 1.5), "conflict_radius must be an integer"),
    (_set("cell", [-50, 50, 30]), "cell must be three positive"),
    (_set("cell", [0, 50, 30]), "cell must be three positive"),
    (_set("flights", {"a": 1}), "flights a list"),
    (_first("speed_mps", 1e-300), "physical range"),
    (_first("waypoints", [[0, 0, "nan"], [10, 10, 120]]), "finite"),
    (_first("waypoints", [[300, 300, -100], [2220, 4220, -100]]), "outside the local frame"),
    (_first("waypoints", [[300, 300, 120], [2e9, 4220, 120]]), "outside the local frame"),
    (_first("planned_departure_s", 1e300), "beyond"),
])
def test_malformed_flights_are_exit_2(good, tmp_path, capsys, edit, fragment):
    folder = tampered(good, tmp_path, edit)
    assert main(["verify", str(folder)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and fragment in err


def test_summary_list_and_non_utf8_csv(good, tmp_path, capsys):
    folder = tmp_path / "s"
    shutil.copytree(good, folder)
    (folder / "summary.json").write_text("[1, 2, 3]")
    assert main(["verify", str(folder)]) == 2 and "JSON object" in capsys.readouterr().err
    shutil.copy(good / "summary.json", folder / "summary.json")
    (folder / "schedule.csv").write_bytes((good / "schedule.csv").read_bytes().replace(b"F001", b"F\xff01"))
    assert main(["verify", str(folder)]) == 2 and "not UTF-8" in capsys.readouterr().err


def test_spreadsheet_bom_is_accepted(good, tmp_path, capsys):
    folder = tmp_path / "s"
    shutil.copytree(good, folder)
    (folder / "schedule.csv").write_bytes(b"\xef\xbb\xbf" + (good / "schedule.csv").read_bytes())
    assert main(["verify", str(folder)]) == 0


def test_conflicting_folder_is_exit_1(good, tmp_path, capsys):
    """Every flight operated at its planned time: the plan's own conflicts come back, exit 1."""
    import csv

    folder = tmp_path / "s"
    shutil.copytree(good, folder)
    doc = json.loads((folder / "flights.json").read_text())
    rows = list(csv.DictReader(open(folder / "schedule.csv", newline="")))
    by_id = {f["id"]: f for f in doc["flights"]}
    for r in rows:  # all operated, no delay: the plan's own conflicts come back
        f = by_id[r["flight"]]
        length = sum(sum((a - b) ** 2 for a, b in zip(p, q, strict=True)) ** 0.5 for p, q in itertools.pairwise(f["waypoints"]))
        r.update(operated="1", delay_s="0.0", departure_s=repr(f["planned_departure_s"]),
                 arrival_s=repr(f["planned_departure_s"] + length / f["speed_mps"]))
    with open(folder / "schedule.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    (folder / "summary.json").unlink()
    assert main(["verify", str(folder)]) == 1
    assert "conflict: flights" in capsys.readouterr().out


# --- crafted folders that used to pass (issue 22): each exited 0 ---------------------------------
def _shifted(good, tmp_path, offset_s: float, name: str = "shifted"):
    """A copy of ``good`` with every time (planned, departure, arrival, service window) moved by
    ``offset_s``: the same schedule, honestly, at another magnitude of time."""
    import csv

    folder = tmp_path / name
    shutil.copytree(good, folder)
    doc = json.loads((folder / "flights.json").read_text())
    doc["service_start_s"] = doc.get("service_start_s", 0.0) + offset_s
    doc["service_end_s"] = doc.get("service_end_s", 3600.0) + offset_s
    for f in doc["flights"]:
        f["planned_departure_s"] += offset_s
    (folder / "flights.json").write_text(json.dumps(doc))
    with open(folder / "schedule.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        for key in ("planned_departure_s", "departure_s", "arrival_s"):
            if r[key] != "":
                r[key] = repr(float(r[key]) + offset_s)
    _rewrite(folder, rows)
    return folder, rows


def _rewrite(folder, rows):
    import csv

    with open(folder / "schedule.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


def test_a_negative_turnaround_gap_is_refused(good, tmp_path, capsys):
    """outbound_gap_s < 0 let an aircraft depart before its previous flight arrived."""
    folder = tampered(good, tmp_path, _set("outbound_gap_s", -3000.0))
    assert main(["verify", str(folder)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and "must be ≥ 0" in err


def test_departures_before_the_service_start_are_violations(good, tmp_path, capsys):
    folder = tampered(good, tmp_path, _set("service_start_s", 300.0))  # flights planned from 0 s
    assert main(["verify", str(folder)]) == 1
    assert "before the service start" in capsys.readouterr().out


def test_a_negative_planned_departure_is_a_violation(good, tmp_path, capsys):
    folder, _ = _shifted(good, tmp_path, -50.0)  # every flight 50 s earlier, the window kept at 0 s
    doc = json.loads((folder / "flights.json").read_text())
    doc["service_start_s"], doc["service_end_s"] = 0.0, 3600.0
    (folder / "flights.json").write_text(json.dumps(doc))
    assert main(["verify", str(folder)]) == 1
    out = capsys.readouterr().out
    assert "s before the service start 0 s (Eq. 23)" in out and "planned departure -" in out


@pytest.mark.parametrize("what", ["departure", "arrival"])
def test_absolute_time_tolerance_at_any_magnitude(good, tmp_path, capsys, what):
    """Near 9·10⁶ s a relative 1e-6 tolerance is 9 s: a departure 8 s early, or an arrival 8 s
    off length / speed, passed."""
    folder, rows = _shifted(good, tmp_path, 9e6)
    assert main(["verify", str(folder)]) == 0, capsys.readouterr().out  # honestly shifted: still feasible
    capsys.readouterr()
    row = next(r for r in rows if r["operated"] == "1")
    if what == "departure":  # 8 s early, the arrival kept consistent with it
        row["departure_s"] = repr(float(row["departure_s"]) - 8.0)
        row["arrival_s"] = repr(float(row["arrival_s"]) - 8.0)
    else:
        row["arrival_s"] = repr(float(row["arrival_s"]) + 8.0)
    _rewrite(folder, rows)
    assert main(["verify", str(folder)]) == 1
    out = capsys.readouterr().out
    assert f"flight {row['flight']}: {what}" in out


def _one_cell(folder, n):
    """``n`` flights of ``n`` aircraft on one 500 m track at once: every pair conflicts, C(n, 2) pairs."""
    import csv as csv_module

    folder.mkdir()
    flights = [{"id": f"F{i}", "aircraft": f"A{i}", "route": "R", "origin": "O", "destination": "D", "speed_mps": 25.0,
                "planned_departure_s": 100.0, "max_delay_s": 600.0,
                "waypoints": [[100.0, 100.0, 120.0], [600.0, 100.0, 120.0]]} for i in range(n)]
    doc = {"cell": [50.0, 50.0, 30.0], "conflict_radius": 1, "service_start_s": 0.0, "service_end_s": 3600.0,
           "outbound_gap_s": 60.0, "return_gap_s": 90.0, "flights": flights}
    (folder / "flights.json").write_text(json.dumps(doc))
    with open(folder / "schedule.csv", "w", newline="") as fh:
        w = csv_module.writer(fh)
        w.writerow(["flight", "aircraft", "route", "operated", "planned_departure_s", "delay_s", "departure_s", "arrival_s"])
        w.writerows([f"F{i}", f"A{i}", "R", "1", "100.0", "0.0", "100.0", "120.0"] for i in range(n))
    return folder


def test_every_conflicting_pair_is_listed_below_the_cap(tmp_path, capsys):
    assert main(["verify", str(_one_cell(tmp_path / "f", 60))]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert sum(line.startswith("conflict: flights") for line in lines) == 60 * 59 // 2  # C(60, 2), by hand
    assert not any("search stopped" in line for line in lines)


def test_a_schedule_of_millions_of_conflicting_pairs_stops_at_the_cap(tmp_path, capsys):
    """2,000 flights through one cell at once are 1,999,000 conflicting pairs: before, the verifier
    listed them all (8,000 flights: 32 million, past 3 GB and 120 s); now it stops at the cap and
    says so, exit 1."""
    from uamopt.schedule.verify import MAX_CONFLICTS

    assert main(["verify", str(_one_cell(tmp_path / "f", 2000))]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert sum(line.startswith("conflict: flights") for line in lines) == MAX_CONFLICTS
    assert any("the search stopped at 10,000 conflicting pairs" in line for line in lines)


def test_a_folder_too_large_to_verify_is_refused_before_it_is_read(good, tmp_path, capsys):
    """flights.json as large as this machine's memory (a sparse file: no disk is used, and nothing of
    it is read): the verifier's estimate (4 bytes a byte of input) exceeds its limit (80 % of the
    memory), so one line with both figures and exit code 2, before any parse."""
    import os

    folder = tmp_path / "huge"
    shutil.copytree(good, folder)
    memory = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    with open(folder / "flights.json", "r+b") as fh:
        fh.truncate(memory)
    assert main(["verify", str(folder)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "needs about" in err[0] and "more than the limit of" in err[0] and " GB" in err[0]
