"""``uamopt verify DIR`` on crafted schedule folders (issue 22, reliability): every folder ends with
exit 0 (feasible), exit 1 (well-formed files, a broken rule: the violations on stdout) or exit 2
(bad input: exactly one line ``error: <what> (<where>): <how to fix>`` on stderr), never a
traceback, and verify writes nothing anywhere.

Every folder is written here by hand (flights.json, schedule.csv, summary.json), as in
tests/test_verify_vertiport.py. The base folder: one flight F1 of aircraft A1 from (100, 100, 120)
to (600, 100, 120) m at 25 m/s (500 m: 20 s), planned and flown at 100 s, arriving at 120 s.
"""

from __future__ import annotations

import copy
import csv
import json

import pytest

from uamopt.cli import main

HEADER = ["flight", "aircraft", "route", "operated", "planned_departure_s", "delay_s", "departure_s", "arrival_s"]
BIG = 10 ** 400  # a JSON integer of 401 digits: float() of it overflows
FLIGHT = {"id": "F1", "aircraft": "A1", "route": "V1-V2", "origin": "V1", "destination": "V2", "speed_mps": 25.0,
          "planned_departure_s": 100.0, "max_delay_s": 600.0, "waypoints": [[100.0, 100.0, 120.0], [600.0, 100.0, 120.0]]}
ROW = ["F1", "A1", "V1-V2", "1", "100.0", "0.0", "100.0", "120.0"]
DOC = {"cell": [50.0, 50.0, 30.0], "conflict_radius": 1, "service_start_s": 0.0, "service_end_s": 3600.0,
       "outbound_gap_s": 60.0, "return_gap_s": 90.0}
SUMMARY = {"solver": "hand", "status": "feasible", "objective": -1.0, "weights": [0.6, 0.4],
           "objective_kind": "lexicographic", "operated": 1, "cancelled": 0, "total_delay_s": 0.0,
           "avg_delay_s": 0.0, "aircraft": 1, "flights": 1}
EMPTY_SUMMARY = SUMMARY | {"objective": 0.0, "operated": 0, "aircraft": 0, "flights": 0}


def write_folder(folder, flights=(FLIGHT,), rows=(ROW,), summary=SUMMARY, doc=None, csv_text=None,
                 flights_text=None, summary_text=None):
    """A schedule folder; ``summary=None`` leaves summary.json out, ``*_text`` writes a file verbatim."""
    folder.mkdir(parents=True, exist_ok=True)
    body = (DOC if doc is None else doc) | {"flights": list(flights)}
    (folder / "flights.json").write_text(flights_text if flights_text is not None else json.dumps(body), encoding="utf-8")
    if csv_text is not None:
        (folder / "schedule.csv").write_text(csv_text, encoding="utf-8")
    else:
        with open(folder / "schedule.csv", "w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(HEADER)
            w.writerows(rows)
    if summary_text is not None:
        (folder / "summary.json").write_text(summary_text, encoding="utf-8")
    elif summary is not None:
        (folder / "summary.json").write_text(json.dumps(summary), encoding="utf-8")
    return folder


def snapshot(root) -> dict:
    """Every path under ``root`` (hidden ones too) with its bytes: nothing may appear or change."""
    return {str(p.relative_to(root)): (p.read_bytes() if p.is_file() else None) for p in sorted(root.rglob("*"))}


def verify(capsys, folder, *extra):
    try:
        code = main(["verify", str(folder), *extra])
    except SystemExit as exc:  # a command-line error: argparse exits (uamopt.cli._Parser, exit 2)
        code = exc.code
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def assert_bad_input(code, out, err, fragment):
    """exit 2 and exactly one line ``error: <what> (<where>): <how to fix>`` (tests/test_hostile.py)."""
    assert code == 2, (code, out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and err.endswith("\n") and err.count("\n") == 1, repr(err)
    assert " (" in lines[0] and "): " in lines[0], f"not 'what (where): how to fix': {lines[0]}"
    assert fragment in lines[0], (fragment, lines[0])


# --- 1. an empty schedule ------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["lexicographic", "weighted"])
def test_an_empty_schedule_its_summary_agrees_with_is_feasible(kind, tmp_path, capsys):
    """0 flights in flights.json, a header-only schedule.csv, and a summary that says 0 flights,
    0 aircraft, 0 operated: trivially feasible (it was a ZeroDivisionError: avg delay = 0 / G)."""
    folder = write_folder(tmp_path / "empty", flights=[], rows=[], summary=EMPTY_SUMMARY | {"objective_kind": kind})
    code, out, err = verify(capsys, folder)
    assert (code, err) == (0, "") and out == f"feasible and conflict-free: {folder}\n"


def test_an_empty_schedule_without_a_summary_is_feasible(tmp_path, capsys):
    folder = write_folder(tmp_path / "empty", flights=[], rows=[], summary=None)
    assert verify(capsys, folder)[0] == 0


def test_an_empty_speed_choice_schedule_is_feasible(tmp_path, capsys):
    """The speed-choice objective divides by G as well (verify_variants.py)."""
    family = {"name": "speed_choice", "factors": [1.0, 0.8], "cruise_speed_mps": {}, "change_cost_s": 10.0}
    summary = EMPTY_SUMMARY | {"objective_kind": "weighted", "families": [family]}
    folder = write_folder(tmp_path / "empty", flights=[], rows=[], summary=summary)
    assert verify(capsys, folder)[0] == 0


@pytest.mark.parametrize(("claim", "fragment"), [
    ({"operated": 4, "flights": 4, "aircraft": 2}, "summary.json: operated = 4, the schedule gives 0"),
    ({"flights": 4}, "summary.json: flights = 4, flights.json holds 0"),  # its counts alone claim flights
    ({"aircraft": 2}, "summary.json: aircraft = 2, flights.json holds 0"),
])
def test_an_empty_schedule_whose_summary_claims_flights_is_a_violation(claim, fragment, tmp_path, capsys):
    folder = write_folder(tmp_path / "empty", flights=[], rows=[], summary=EMPTY_SUMMARY | claim)
    code, out, err = verify(capsys, folder)
    assert code == 1 and err == "" and fragment in out, out


def test_a_summary_claiming_more_flights_than_the_files_hold_is_a_violation(tmp_path, capsys):
    folder = write_folder(tmp_path / "one", summary=SUMMARY | {"flights": 5})
    code, out, _ = verify(capsys, folder)
    assert code == 1 and "summary.json: flights = 5, flights.json holds 1" in out, out


def test_the_base_folder_is_feasible(tmp_path, capsys):
    """The folder the hostile cases below start from passes: every refusal is the crafted field's."""
    assert verify(capsys, write_folder(tmp_path / "base")) == (0, f"feasible and conflict-free: {tmp_path / 'base'}\n", "")


def test_a_zero_byte_schedule_csv_is_bad_input(tmp_path, capsys):
    """No header at all is not an empty schedule: the columns are missing."""
    folder = write_folder(tmp_path / "empty", flights=[], summary=EMPTY_SUMMARY, csv_text="")
    assert_bad_input(*verify(capsys, folder), "schedule.csv needs the columns")


# --- 2. refused input writes nothing ---------------------------------------------------------------

@pytest.mark.parametrize("weights", [[BIG, 0.4], "heavy"], ids=["weights-huge", "weights-word"])
def test_a_refused_folder_writes_nothing(weights, tmp_path, capsys):
    """verify has no --out (it only reads): ``--out`` is a command-line error, and neither that nor a
    refused folder leaves any file, hidden staging folder or lock file behind."""
    folder = write_folder(tmp_path / "bad", summary=SUMMARY | {"weights": weights})
    before = snapshot(tmp_path)
    assert_bad_input(*verify(capsys, folder), "weights must be two finite numbers")
    assert snapshot(tmp_path) == before
    assert_bad_input(*verify(capsys, folder, "--out", str(tmp_path / "report")), "unrecognized arguments: --out")
    assert snapshot(tmp_path) == before and not (tmp_path / "report").exists()


# --- 3. crafted fields -------------------------------------------------------------------------------

def _flight(**change):
    return [FLIGHT | change]


def _doc(**change):
    return DOC | change


SPEED = {"name": "speed_choice", "factors": [1.0, 0.8], "cruise_speed_mps": {"F1": 25.0}, "change_cost_s": 10.0}
NEWLINE_ID = [FLIGHT | {"id": "F\n1"}, FLIGHT | {"id": "F\n1", "aircraft": "A2"}]
# (id, write_folder arguments, exit code, fragment of the error line (2) or of stdout (1))
CASES = [
    # flights.json: a number too large for a float (OverflowError), NaN, a 5000-digit integer
    ("planned-huge", {"flights": _flight(planned_departure_s=BIG)}, 2, "planned_departure_s is not finite"),
    ("max-delay-huge", {"flights": _flight(max_delay_s=BIG)}, 2, "max_delay_s is not finite"),
    ("speed-huge", {"flights": _flight(speed_mps=BIG)}, 2, "speed_mps is not finite"),
    ("waypoint-huge", {"flights": _flight(waypoints=[[BIG, 100.0, 120.0], [600.0, 100.0, 120.0]])}, 2,
     "waypoints must be at least two finite"),
    ("rate-huge", {"flights": _flight(vertical_rate_mps=BIG)}, 2, "vertical_rate_mps must be a number"),
    ("cell-huge", {"doc": _doc(cell=[BIG, 50.0, 30.0])}, 2, "cell is not finite"),
    ("service-start-huge", {"doc": _doc(service_start_s=BIG)}, 2, "service_start_s is not finite"),
    ("service-end-huge", {"doc": _doc(service_end_s=BIG)}, 2, "service_end_s is not finite"),
    ("gap-huge", {"doc": _doc(outbound_gap_s=BIG)}, 2, "outbound_gap_s is not finite"),
    ("flights-5000-digits", {"flights_text": json.dumps(DOC | {"flights": [FLIGHT]}).replace(
        '"conflict_radius": 1', '"conflict_radius": ' + "9" * 5000)}, 2, "malformed JSON"),
    ("planned-nan", {"flights": _flight(planned_departure_s=float("nan"))}, 2, "planned_departure_s is not finite"),
    ("gap-negative", {"doc": _doc(return_gap_s=-30.0)}, 2, "must be ≥ 0"),
    ("id-newline-twice", {"flights": NEWLINE_ID, "rows": []}, 2, "appears twice"),
    # schedule.csv
    ("csv-short-row", {"rows": [ROW[:2]]}, 2, "line 2 has fewer fields than the header's 8 columns"),
    ("csv-departure-400-digits", {"rows": [[*ROW[:6], "9" * 400, "120.0"]]}, 2, "departure_s is not finite"),
    ("csv-departure-inf", {"rows": [[*ROW[:6], "inf", "120.0"]]}, 2, "departure_s is not finite"),
    ("csv-departure-early", {"rows": [[*ROW[:4], "100.0", "-150.0", "-50.0", "-30.0"]]}, 1, "before the service start"),
    # summary.json
    ("summary-5000-digits", {"summary_text": json.dumps(SUMMARY).replace('"operated": 1', '"operated": ' + "9" * 5000)},
     2, "malformed JSON"),
    ("summary-operated-huge", {"summary": SUMMARY | {"operated": BIG}}, 1, "summary.json: operated = 1000"),
    ("summary-objective-huge", {"summary": SUMMARY | {"objective": BIG}}, 1, "summary.json: objective = 1000"),
    ("summary-flights-huge", {"summary": SUMMARY | {"flights": BIG}}, 1, "summary.json: flights = 1000"),
    ("summary-weights-huge", {"summary": SUMMARY | {"weights": [BIG, 0.4]}}, 2, "weights must be two finite numbers"),
    ("summary-extent-huge", {"summary": SUMMARY | {"extent_m": [BIG, 1000.0, 300.0]}}, 2, "extent_m must be three"),
    ("speed-cruise-huge", {"summary": SUMMARY | {"families": [SPEED | {"cruise_speed_mps": {"F1": BIG}}]}}, 2,
     "speed_choice"),
    ("speed-cost-huge", {"summary": SUMMARY | {"families": [SPEED | {"change_cost_s": BIG}]}}, 2, "speed_choice"),
    ("speed-cost-inf", {"summary": SUMMARY | {"families": [SPEED | {"change_cost_s": float("inf")}]}}, 2, "speed_choice"),
    ("speed-objective-huge", {"summary": SUMMARY | {"objective": BIG, "families": [SPEED]}}, 1,
     "summary.json: objective = 1000"),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_a_crafted_folder_ends_in_one_line_or_a_violation(case, tmp_path, capsys):
    name, kwargs, expected, fragment = case
    folder = write_folder(tmp_path / name, **copy.deepcopy(kwargs))
    before = snapshot(tmp_path)
    code, out, err = verify(capsys, folder)
    if expected == 2:
        assert_bad_input(code, out, err, fragment)
    else:
        assert code == 1 and err == "" and fragment in out, (code, out, err)
        assert out.splitlines()[-1].endswith("violations")
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize(("text", "fragment"), [("1e400 10\n", "not an airland file"), ("nan 10\n", "not an airland file"),
                                            (None, "not a regular file")])
def test_a_crafted_airland_file_is_bad_input(text, fragment, tmp_path, capsys):
    """summary.json's separation family names an instance file: its aircraft count is inf or NaN
    (OverflowError, ValueError), or it is /dev/zero (read without end)."""
    path = tmp_path / "airland.txt"
    if text is not None:
        path.write_text(text, encoding="utf-8")
    target = str(path) if text is not None else "/dev/zero"
    summary = SUMMARY | {"objective_kind": "earliness_tardiness", "families": [{"name": "separation", "airland_file": target}]}
    folder = write_folder(tmp_path / "air", summary=summary)
    assert_bad_input(*verify(capsys, folder), fragment)


def test_a_control_character_in_an_id_stays_on_its_line(tmp_path, capsys):
    """A flight id with a newline (or NUL) in it: each violation is still one line of stdout."""
    flights = [FLIGHT | {"id": "F\n1"}]
    folder = write_folder(tmp_path / "nl", flights=flights, rows=[["F\x001", *ROW[1:]]], summary=None)
    code, out, _ = verify(capsys, folder)
    lines = out.splitlines()
    assert code == 1 and len(lines) == 3 and lines[-1] == "2 violations" and "\x00" not in out, lines
