"""Property: ``uamopt verify`` never passes a schedule folder whose conflicts an independent
sampler finds, however the folder was tampered with.

The sampler is written here from the definition of a conflict (paper Sec. 5.2.1,
docs/readings.md), not from uamopt's occupancy code: each operated flight flies its waypoints at
constant speed from its departure in schedule.csv; at fine time steps (0.25 s, offset by an
irrational fraction so that no step lands on a cell boundary crossing) two flights of different
aircraft conflict when their cells, floor(coordinate / Δ), are within ``conflict_radius`` of each
other on every axis. A conflict the sampler finds must make ``verify`` exit non-zero, and when
the folder is well formed (exit 1) the verifier must name that very pair.
"""

from __future__ import annotations

import csv
import itertools
import json
import math
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import PAPER_CASE
from hostile_files import PORTS
from hypothesis import HealthCheck, event, given, settings, strategies as st

from uamopt.cli import main

DT_S = 0.25  # sampling step, s
PHASE = (math.sqrt(5.0) - 1.0) / 2.0  # irrational offset of the samples within a step
CONFLICT_LINE = re.compile(r"conflict: flights (\S+) \(.*?\) in cell .*? and (\S+) \(.*?\) in cell")
# four aircraft, each out and back on a route through the middle of the paper case's city, at 290 m
# timed so that the outbound flights reach the crossing (1260, 2260) within about a second of each other
ROUTES = {"A": ("V1", "V4"), "B": ("V3", "V2"), "C": ("V1", "V3"), "D": ("V2", "V4")}
MIDDLE = {"C": (300.0, 2260.0, 2220.0, 2260.0), "D": (1260.0, 300.0, 1260.0, 4220.0)}  # x0, y0, x1, y1
FIRST_DEPARTURE_S = {"A": 0.0, "B": 0.0, "C": 50.0, "D": 10.0}


def plan() -> dict:
    flights = []
    for aircraft, (a, b) in ROUTES.items():
        x0, y0, x1, y1 = MIDDLE.get(aircraft, (*PORTS[a], *PORTS[b]))
        track = [[x0, y0, 290.0], [x1, y1, 290.0]]
        duration = math.dist(track[0], track[1]) / 25.0
        first = FIRST_DEPARTURE_S[aircraft]
        for leg, (waypoints, departure) in enumerate(((track, first), (track[::-1], first + duration + 300.0))):
            flights.append({"id": f"{aircraft}{leg + 1}", "aircraft": aircraft, "route": f"{aircraft}-{leg}",
                            "origin": "o", "destination": "d", "speed_mps": 25.0, "planned_departure_s": departure,
                            "max_delay_s": 600.0, "waypoints": waypoints})
    return {"cell": [50.0, 50.0, 30.0], "conflict_radius": 1, "flights": flights}


@pytest.fixture(scope="module")
def good(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("prop")
    (folder / "flights.json").write_text(json.dumps(plan()), encoding="utf-8")
    assert main(["schedule", str(PAPER_CASE), "--solver", "greedy", "--flights", str(folder / "flights.json"),
                 "--out", str(folder / "good")]) == 0
    return folder / "good"


def sampled_conflicts(folder: Path) -> set[frozenset[str]] | None:
    """Pairs of flight ids the sampler finds in conflict; None when the folder cannot be read."""
    try:
        spec = json.loads((folder / "flights.json").read_text(encoding="utf-8"))
        with open(folder / "schedule.csv", newline="", encoding="utf-8") as fh:
            rows = {row["flight"]: row for row in csv.DictReader(fh)}
        cell, radius = np.asarray(spec["cell"], dtype=float), int(spec["conflict_radius"])
        flown = []
        for f in spec["flights"]:
            row = rows.get(f["id"])
            if row is None or row["operated"].strip() != "1":
                continue
            w = np.asarray(f["waypoints"], dtype=float)
            along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(w, axis=0), axis=1))])
            departure, speed = float(row["departure_s"]), float(f["speed_mps"])
            flown.append((f["id"], f["aircraft"], w, along, departure, departure + along[-1] / speed, speed))
    except (OSError, ValueError, KeyError, TypeError):
        return None
    pairs = set()
    for a, b in itertools.combinations(flown, 2):
        start, end = max(a[4], b[4]), min(a[5], b[5])
        if a[1] == b[1] or end <= start:
            continue
        t = start + (np.arange(math.ceil((end - start) / DT_S) + 1) + PHASE) * DT_S
        t = t[t < end]
        cells = [np.floor(np.column_stack([np.interp((t - f[4]) * f[6], f[3], f[2][:, k]) for k in range(3)]) / cell)
                 for f in (a, b)]
        if np.any(np.max(np.abs(cells[0] - cells[1]), axis=1) <= radius):
            pairs.add(frozenset((a[0], b[0])))
    return pairs


def _rewrite(folder: Path, flights: dict, rows: list[dict], consistent: bool) -> None:
    (folder / "flights.json").write_text(json.dumps(flights), encoding="utf-8")
    by_id = {f["id"]: f for f in flights["flights"]}
    for row in rows:
        f = by_id.get(row["flight"])
        if consistent and f is not None and row["operated"] == "1" and row["departure_s"] != "x":
            length = sum(math.dist(p, q) for p, q in itertools.pairwise(f["waypoints"]))  # Eq. 31
            row["arrival_s"] = repr(float(row["departure_s"]) + length / f["speed_mps"])
    with open(folder / "schedule.csv", "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


flight_index = st.integers(0, 7)
# operate a flight with a delay: on time (the plan is timed to conflict), a few steps of ΔT_a, or any
flies = st.one_of(
    st.tuples(st.just("fly"), flight_index, st.sampled_from([0.0, 0.0, 10.0, 20.0, 30.0])),
    st.tuples(st.just("fly"), flight_index, st.integers(0, 60).map(lambda k: 10.0 * k)),
    st.tuples(st.just("fly"), flight_index, st.floats(0.0, 600.0)),
)
others = st.one_of(
    st.tuples(st.just("cancel"), flight_index, st.none()),
    st.tuples(st.just("move"), flight_index, st.tuples(st.integers(0, 1), st.integers(-3, 3), st.integers(-3, 3),
                                                      st.integers(-2, 2))),  # a waypoint moved by cells
    st.tuples(st.just("aircraft"), flight_index, flight_index),
    st.tuples(st.just("radius"), st.integers(0, 2), st.none()),
    st.tuples(st.just("cell"), st.sampled_from([0.5, 2.0, 3.0]), st.none()),
    st.tuples(st.just("speed"), flight_index, st.sampled_from([0.5, 2.0])),
    st.tuples(st.just("junk"), flight_index, st.sampled_from(["departure_s", "delay_s", "operated"])),
)


def tamper(good: Path, folder: Path, changes, consistent: bool, keep_summary: bool) -> None:
    shutil.copytree(good, folder)
    flights = json.loads((folder / "flights.json").read_text(encoding="utf-8"))
    with open(folder / "schedule.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    fs = flights["flights"]
    for kind, i, value in changes:
        if kind == "fly":
            rows[i].update(operated="1", delay_s=repr(value), departure_s=repr(float(rows[i]["planned_departure_s"]) + value))
        elif kind == "cancel":
            rows[i].update(operated="0", delay_s="0.0", departure_s="", arrival_s="")
        elif kind == "move":
            k, dx, dy, dz = value
            fs[i]["waypoints"][k] = [fs[i]["waypoints"][k][0] + 50 * dx, fs[i]["waypoints"][k][1] + 50 * dy,
                                     fs[i]["waypoints"][k][2] + 30 * dz]
        elif kind == "aircraft":
            fs[i]["aircraft"] = rows[i]["aircraft"] = fs[value]["aircraft"]
        elif kind == "radius":
            flights["conflict_radius"] = i
        elif kind == "cell":
            flights["cell"] = [c * i for c in flights["cell"]]
        elif kind == "speed":
            fs[i]["speed_mps"] *= value
        else:
            rows[i][value] = "x"
    _rewrite(folder, flights, rows, consistent)
    if not keep_summary:
        (folder / "summary.json").unlink()


def verify(folder: Path, capsys) -> tuple[int, str]:
    code = main(["verify", str(folder)])  # an exception here is a traceback: the test fails
    out, _ = capsys.readouterr()
    assert code in (0, 1, 2)
    return code, out


def test_the_sampler_agrees_on_the_good_folder_and_finds_the_plans_conflicts(good, tmp_path, capsys):
    """Not vacuous: no conflict in greedy's folder (exit 0); every flight flown on time brings the
    plan's conflicts back, which the sampler finds and the verifier names."""
    assert sampled_conflicts(good) == set() and verify(good, capsys)[0] == 0
    folder = tmp_path / "on_time"
    tamper(good, folder, [("fly", i, 0.0) for i in range(8)], consistent=True, keep_summary=False)
    found = sampled_conflicts(folder)
    code, out = verify(folder, capsys)
    named = {frozenset(m.groups()) for m in CONFLICT_LINE.finditer(out)}
    assert len(found) >= 2 and code == 1 and found <= named


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(changes=st.builds(lambda a, b: a + b, st.lists(flies, min_size=1, max_size=4), st.lists(others, max_size=2)),
       consistent=st.booleans() | st.just(True), keep_summary=st.booleans())
def test_verify_never_passes_a_folder_the_sampler_finds_in_conflict(good, tmp_path_factory, capsys, changes,
                                                                    consistent, keep_summary):
    folder = tmp_path_factory.mktemp("tampered") / "s"
    tamper(good, folder, changes, consistent, keep_summary)
    found = sampled_conflicts(folder)
    code, out = verify(folder, capsys)
    event(f"exit {code}, sampler {'unreadable' if found is None else 'conflict' if found else 'clear'}")
    if found:
        assert code != 0, f"verify passed a folder with conflicts {found}"
        if code == 1:
            named = {frozenset(m.groups()) for m in CONFLICT_LINE.finditer(out)}
            assert found <= named, f"sampled conflicts {found - named} not reported:\n{out}"
