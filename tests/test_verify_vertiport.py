"""The independent verifier (uamopt/schedule/verify.py, verify_variants.py) on the vertiport
variant: ``vertical_rate_mps`` (vertical take-off and landing phases) and the ``pads`` family.

Every folder is written here by hand (flights.json, schedule.csv, summary.json) and every
expected time is worked out in the test, never with the model's code. The geometry: cells of
50 x 50 x 30 m, cruise at 25 m/s and z = 120 m, climb and descent at 4 m/s, so a 120 m climb
takes 30 s and each 30 m layer of the column 7.5 s.
"""

from __future__ import annotations

import csv
import json
import re

import pytest

from uamopt.cli import main
from uamopt.schedule.verify import cell_visits, verify_dir

SPEED = 25.0
RATE = 4.0
OUT_GAP, BACK_GAP = 60.0, 90.0  # outbound_gap_s (after an odd leg), return_gap_s (after an even leg)
PORTS = {"V1": (100.0, 100.0), "V2": (600.0, 100.0), "V3": (600.0, 800.0), "V4": (100.0, 600.0)}


def vertical_track(a: str, b: str, z: float = 120.0) -> list[list[float]]:
    (x0, y0), (x1, y1) = PORTS[a], PORTS[b]
    return [[x0, y0, 0.0], [x0, y0, z], [x1, y1, z], [x1, y1, 0.0]]


def flight(fid, aircraft, a, b, departure, rate=RATE, waypoints=None):
    f = {"id": fid, "aircraft": aircraft, "route": f"{a}-{b}", "origin": a, "destination": b, "speed_mps": SPEED,
         "planned_departure_s": departure, "max_delay_s": 600.0,
         "waypoints": waypoints if waypoints is not None else vertical_track(a, b)}
    if rate is not None:
        f["vertical_rate_mps"] = rate
    return f


def write_folder(folder, flights, arrivals, radius=1, families=None):
    """flights.json, schedule.csv (every flight operated at its planned departure, delay 0, at the
    given arrival) and summary.json (counts; ``families`` when given)."""
    folder.mkdir(parents=True, exist_ok=True)
    doc = {"cell": [50.0, 50.0, 30.0], "conflict_radius": radius, "service_start_s": 0.0, "service_end_s": 3600.0,
           "outbound_gap_s": OUT_GAP, "return_gap_s": BACK_GAP, "flights": flights}
    (folder / "flights.json").write_text(json.dumps(doc))
    with open(folder / "schedule.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["flight", "aircraft", "route", "operated", "planned_departure_s", "delay_s", "departure_s", "arrival_s"])
        for f in flights:
            dep = f["planned_departure_s"]
            w.writerow([f["id"], f["aircraft"], f["route"], 1, dep, 0.0, dep, arrivals[f["id"]]])
    n_aircraft = len({f["aircraft"] for f in flights})
    summary = {"solver": "hand", "status": "feasible", "operated": len(flights), "cancelled": 0,
               "total_delay_s": 0.0, "avg_delay_s": 0.0 / n_aircraft}
    if families is not None:
        summary["families"] = families
    (folder / "summary.json").write_text(json.dumps(summary))
    return folder


def pads(**capacity):
    return [{"name": "pads", "shape": "cumulative", "pads": capacity}]


# V1 -> V2: climb 120 / 4 = 30 s, cruise 500 / 25 = 20 s, descent 30 s: 80 s in all
# V2 -> V3: climb 30 s, cruise 700 / 25 = 28 s, descent 30 s: 88 s
# the old rule, track length / speed: (120 + 500 + 120) / 25 = 29.6 s for V1 -> V2
V1_V2_S, V2_V3_S, V1_V2_OLD_S = 80.0, 88.0, 29.6


def test_cell_visits_times_the_vertical_segments_at_their_own_speed():
    track = [tuple(p) for p in vertical_track("V1", "V2")]
    got = cell_visits(track, SPEED, (50.0, 50.0, 30.0), [RATE, SPEED, RATE])
    # up the column (2, 2, 0..3) at 7.5 s a layer, the cruise in the plane z = 120 (upper cell 4),
    # x from 100 to 600 m at 2 s per 50 m cell, then down the column (12, 2, 3..0)
    # (the descent starts on the plane z = 120 and moves down: lower cell 3)
    expect = [((2, 2, k), 7.5 * k, 7.5 * (k + 1)) for k in range(4)]
    expect += [((i, 2, 4), 30.0 + 2 * (i - 2), 32.0 + 2 * (i - 2)) for i in range(2, 12)]
    expect += [((12, 2, 3 - k), 50.0 + 7.5 * k, 57.5 + 7.5 * k) for k in range(4)]
    assert [c for c, _, _ in got] == [c for c, _, _ in expect]
    assert [t for _, a, b in got for t in (a, b)] == pytest.approx([t for _, a, b in expect for t in (a, b)], abs=1e-9)
    # the existing call (one speed) is unchanged: the whole 740 m at 25 m/s
    assert cell_visits(track, SPEED, (50.0, 50.0, 30.0))[-1][2] == pytest.approx(V1_V2_OLD_S)


def test_arrival_includes_climb_and_descent(tmp_path, capsys):
    flights = [flight("F1", "A1", "V1", "V2", 0.0), flight("F2", "A2", "V2", "V3", 500.0)]
    good = write_folder(tmp_path / "good", flights, {"F1": V1_V2_S, "F2": 500.0 + V2_V3_S})
    assert verify_dir(good) == []
    assert main(["verify", str(good)]) == 0
    old = write_folder(tmp_path / "old", flights, {"F1": V1_V2_OLD_S, "F2": 500.0 + V2_V3_S})
    found = verify_dir(old)
    assert len(found) == 1 and found[0].startswith("flight F1: arrival 29.6 s") and "80.000000" in found[0]
    capsys.readouterr()
    assert main(["verify", str(old)]) == 1


def test_without_a_vertical_rate_the_same_track_is_length_over_speed(tmp_path):
    flights = [flight("F1", "A1", "V1", "V2", 0.0, rate=None)]
    assert verify_dir(write_folder(tmp_path / "plain", flights, {"F1": V1_V2_OLD_S})) == []
    assert len(verify_dir(write_folder(tmp_path / "phased", flights, {"F1": V1_V2_S}))) == 1


def two_at_v2(tmp_path, name, f2_departure, **capacity):
    """F1 lands at V2 at 80 s and holds a pad there during [80 − 30, 80 + T_D) = [50, 140) (leg 1 of
    A1: outbound gap); F2 (A2) takes off from V2, holding a pad during [dep, dep + 30)."""
    flights = [flight("F1", "A1", "V1", "V2", 0.0), flight("F2", "A2", "V2", "V3", f2_departure)]
    return write_folder(tmp_path / name, flights, {"F1": V1_V2_S, "F2": f2_departure + V2_V3_S},
                        families=pads(**capacity))


def test_one_pad_landing_hold_overlapping_a_take_off_is_one_violation(tmp_path):
    found = verify_dir(two_at_v2(tmp_path, "overlap", 100.0, V1=1, V2=1, V3=1))
    assert len(found) == 1, found
    line = found[0]
    assert "vertiport V2" in line and "holds 2 pads" in line and "100.000 s" in line and "capacity 1" in line
    assert "F1" in line and "F2" in line


def test_take_off_exactly_at_the_hold_end_passes(tmp_path):
    assert verify_dir(two_at_v2(tmp_path, "touch", 140.0, V1=1, V2=1, V3=1)) == []
    assert verify_dir(two_at_v2(tmp_path, "within_tol", 140.0 - 0.5e-6, V1=1, V2=1, V3=1)) == []
    assert len(verify_dir(two_at_v2(tmp_path, "beyond_tol", 140.0 - 1e-3, V1=1, V2=1, V3=1))) == 1


def test_a_pad_taken_during_the_descent_is_a_violation(tmp_path):
    # F2 takes off at 60 s: F1 is still descending onto V2 (its hold began at 50 s); F1's descent
    # column (12, 2, ·) is F2's climb column, F1 there in [50, 80), F2 in [60, 90): a conflict too
    found = verify_dir(two_at_v2(tmp_path, "descent", 60.0, V1=1, V2=1, V3=1))
    assert sum(line.startswith("pads: vertiport V2 holds 2 pads at 60.000 s") for line in found) == 1
    assert any(line.startswith("conflict: flights F1") for line in found)


def test_two_pads_pass(tmp_path):
    assert verify_dir(two_at_v2(tmp_path, "two", 100.0, V1=1, V2=2, V3=1)) == []


def test_a_vertiport_missing_from_the_record_is_a_violation(tmp_path):
    found = verify_dir(two_at_v2(tmp_path, "missing", 200.0, V1=1, V2=1))
    assert len(found) == 1 and "vertiport V3 has no pad capacity in the pads record" in found[0]


def test_a_null_capacity_is_unlimited(tmp_path):
    # the overlap at V2 of test_one_pad_landing_hold_overlapping_a_take_off... is no violation where V2
    # has no limit (null), and V3 null is not "missing"
    assert verify_dir(two_at_v2(tmp_path, "null", 100.0, V1=1, V2=None, V3=None)) == []
    assert len(verify_dir(two_at_v2(tmp_path, "limited", 100.0, V1=1, V2=1, V3=None))) == 1


def test_without_vertical_phases_only_the_turnaround_is_held(tmp_path):
    # cruise-only tracks at z = 120 m: climb_s = descent_s = 0, F1 (leg 1 of A1) V1 -> V2 in
    # 500 / 25 = 20 s, holds V2 during [20, 20 + 60); F2 (leg 2 of A1) V2 -> V1 at 80 s, 20 s,
    # holds V1 during [100, 100 + 90) (return gap); F3 (A3) takes off from V1 with no climb: no hold
    flat = {k: [[x, y, 120.0] for x, y in (PORTS[a], PORTS[b])] for k, a, b in (("12", "V1", "V2"), ("21", "V2", "V1"))}
    f1 = flight("F1", "A1", "V1", "V2", 0.0, rate=None, waypoints=flat["12"])
    f2 = flight("F2", "A1", "V2", "V1", 80.0, rate=None, waypoints=flat["21"])
    f3 = flight("F3", "A3", "V1", "V4", 150.0, rate=None,
                waypoints=[[100.0, 100.0, 120.0], [100.0, 400.0, 120.0]])
    f4 = flight("F4", "A4", "V4", "V1", 0.0, rate=None,  # lands at V1 at 12 s, holds [12, 72): then V1 is free
                waypoints=[[100.0, 400.0, 120.0], [100.0, 100.0, 120.0]])
    arrivals = {"F1": 20.0, "F2": 100.0, "F3": 162.0, "F4": 12.0}
    assert verify_dir(write_folder(tmp_path / "flat", [f1, f2, f3, f4], arrivals, radius=0,
                                   families=pads(V1=1, V2=1, V4=1))) == []
    # F4 an hour later: it lands at V1 at 192 s, while F2's return-gap hold [100, 190) ... ends at
    # 190 s: free; at 182 s it is not (the outbound gap, 60 s, would have ended at 160 s)
    for start, breaches in ((180.0, 0), (170.0, 1)):
        f4b = dict(f4, planned_departure_s=start)
        found = verify_dir(write_folder(tmp_path / f"late{start:g}", [f1, f2, f3, f4b],
                                        dict(arrivals, F4=start + 12.0), radius=0, families=pads(V1=1, V2=1, V4=1)))
        assert len(found) == breaches, found
        assert all(line.startswith(f"pads: vertiport V1 holds 2 pads at {start + 12.0:.3f} s") for line in found)


def test_two_flights_climbing_in_one_column_conflict(tmp_path):
    # both from V1; F2 (another aircraft) 5 s later: F1 in layer k of the column during
    # [7.5 k, 7.5 (k + 1)), F2 during [5 + 7.5 k, 12.5 + 7.5 k): overlaps of 7.5 − 5 = 2.5 s.
    # (At the cruise speed the climbs would take 4.8 s and never meet.)
    flights = [flight("F1", "A1", "V1", "V2", 0.0), flight("F2", "A2", "V1", "V4", 5.0)]
    # V1 -> V4: climb 30 s, cruise 500 / 25 = 20 s, descent 30 s
    folder = write_folder(tmp_path / "column", flights, {"F1": V1_V2_S, "F2": 5.0 + 80.0}, radius=0)
    found = verify_dir(folder)
    assert len(found) == 1 and found[0].startswith("conflict: flights F1 (A1)") and "F2 (A2)" in found[0]
    a, b = map(float, re.search(r"from ([\d.]+) s to ([\d.]+) s", found[0]).groups())
    assert b - a == pytest.approx(2.5, abs=1e-6)
    apart = write_folder(tmp_path / "apart", [flights[0], dict(flights[1], planned_departure_s=40.0)],
                         {"F1": V1_V2_S, "F2": 40.0 + 80.0}, radius=0)
    assert verify_dir(apart) == []  # F1 is cruising (z layer 4) by 30 s, F2 climbs from 40 s


def _exit_2(tmp_path, capsys, name, flights, families=None, fragment=""):
    arrivals = {f["id"]: f["planned_departure_s"] + V1_V2_S for f in flights}
    folder = write_folder(tmp_path / name, flights, arrivals, families=families)
    capsys.readouterr()
    assert main(["verify", str(folder)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and fragment in err, err
    assert "Traceback" not in err


@pytest.mark.parametrize("rate", [0, -4.0, 50.5, "4", True, float("nan"), [4.0]])
def test_a_malformed_vertical_rate_is_exit_2(tmp_path, capsys, rate):
    _exit_2(tmp_path, capsys, "rate", [flight("F1", "A1", "V1", "V2", 0.0, rate=rate)],
            fragment="vertical_rate_mps must be a number in (0, 50]")


def test_the_largest_vertical_rate_is_accepted(tmp_path):
    # at 50 m/s: climb and descent 120 / 50 = 2.4 s each, cruise 20 s
    folder = write_folder(tmp_path / "fast", [flight("F1", "A1", "V1", "V2", 0.0, rate=50)], {"F1": 24.8})
    assert verify_dir(folder) == []


@pytest.mark.parametrize("waypoints", [
    [[100.0, 100.0, 0.0], [101.0, 100.0, 120.0], [600.0, 100.0, 120.0], [600.0, 100.0, 0.0]],  # slanted climb
    [[100.0, 100.0, 120.0], [100.0, 100.0, 60.0], [600.0, 100.0, 120.0], [600.0, 100.0, 0.0]],  # first one descends
    [[100.0, 100.0, 0.0], [100.0, 100.0, 120.0], [600.0, 100.0, 120.0], [600.0, 100.0, 130.0]],  # last one climbs
    [[100.0, 100.0, 0.0], [100.0, 100.0, 120.0], [600.0, 100.0, 120.0], [600.0, 100.0, 120.0]],  # last one level
    [[100.0, 100.0, 0.0], [100.0, 100.0, 120.0], [100.0, 100.0, 0.0]],  # three waypoints
])
def test_a_track_without_vertical_ends_is_exit_2(tmp_path, capsys, waypoints):
    _exit_2(tmp_path, capsys, "slanted", [flight("F1", "A1", "V1", "V2", 0.0, waypoints=waypoints)],
            fragment="flight F1: vertical_rate_mps needs a vertical first and last segment")


@pytest.mark.parametrize("record", [
    [{"name": "pads", "shape": "cumulative", "pads": [1, 1]}],
    [{"name": "pads", "shape": "cumulative"}],
    pads(V1=0, V2=1),
    pads(V1=1.5, V2=1),
    pads(V1=True, V2=1),
    pads(V1="2", V2=1),
])
def test_a_malformed_pads_record_is_exit_2(tmp_path, capsys, record):
    _exit_2(tmp_path, capsys, "badpads", [flight("F1", "A1", "V1", "V2", 0.0)], families=record,
            fragment="pads: 'pads' must be an object")
