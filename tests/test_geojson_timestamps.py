"""``uamopt export geojson``: the time of every vertex of an operated flight (trip layers, issue 20):
``timestamps`` in tracks.geojson (RFC 7946 positions, three elements) and the 4th coordinate of
trips.kepler.json (kepler.gl's trip layer, operated flights only).

Expected times are computed here from flights.json (waypoints, speed_mps, vertical_rate_mps) and
schedule.csv (departure_s, arrival_s) with plain float arithmetic, not with uamopt's functions.
"""

from __future__ import annotations

import csv
import itertools
import json
import math
import re
from datetime import UTC, datetime

import numpy as np
import pytest

from uamopt.cli import main

gpd = pytest.importorskip("geopandas")

ANCHOR_UTC = "2026-01-01T00:00:00Z"
ANCHOR_UNIX = datetime(2026, 1, 1, tzinfo=UTC).timestamp()
OLD_PROPERTIES = {"id", "aircraft", "route", "origin", "destination", "operated", "departure_s", "arrival_s",
                  "speed_mps", "length_m"}  # what tracks.geojson wrote before the times
TOL_S = 1e-6
UNIX_TOL_S = 5e-4 + 1e-6  # trips.kepler.json's 4th coordinate is rounded to the millisecond (kepler.gl reads ≤ 3 decimals)
KEPLER_UNIX_SECONDS = re.compile(r"\d{9,10}(\.\d{1,3})?")  # type-analyzer's 'x' time format, used by kepler.gl


def _schedule(root, tmp_path_factory, name: str, *overrides: str):
    folder = tmp_path_factory.mktemp(name) / "s"
    args = ["schedule", str(root / "models" / "paper_case.toml"), "--solver", "greedy", "--out", str(folder),
            "--set", "schedule.aircraft=4", "--set", "schedule.flights=12"]
    for o in overrides:
        args += ["--set", o]
    assert main(args) == 0
    return folder


def _rows(folder) -> dict[str, dict]:
    with open(folder / "schedule.csv", newline="", encoding="utf-8") as fh:
        return {r["flight"]: r for r in csv.DictReader(fh)}


def _export(folder):
    """(tracks.geojson, trips.kepler.json, flights by id, schedule.csv rows by flight, tracks.geojson in GeoPandas)."""
    assert main(["export", "geojson", str(folder)]) == 0
    doc, trips = (json.loads((folder / name).read_text(encoding="utf-8")) for name in ("tracks.geojson", "trips.kepler.json"))
    flights = {f["id"]: f for f in json.loads((folder / "flights.json").read_text(encoding="utf-8"))["flights"]}
    return doc, trips, flights, _rows(folder), gpd.read_file(folder / "tracks.geojson", engine="pyogrio").set_index("id")


def _segment_seconds(flight: dict) -> list[float]:
    """Time of each segment: length / speed_mps; with vertical_rate_mps the first and last at that rate."""
    wp = flight["waypoints"]
    lengths = [math.sqrt(sum((b - a) ** 2 for a, b in zip(p, q, strict=True))) for p, q in itertools.pairwise(wp)]
    rates = [flight["speed_mps"]] * len(lengths)
    if "vertical_rate_mps" in flight:
        rates[0] = rates[-1] = flight["vertical_rate_mps"]
    return [d / v for d, v in zip(lengths, rates, strict=True)]


def _expected_times(flight: dict, departure_s: float) -> list[float]:
    out, t = [departure_s], departure_s
    for dt in _segment_seconds(flight):
        t += dt
        out.append(t)
    return out


@pytest.fixture(scope="module")
def planned(root, tmp_path_factory):
    """The paper case, 4 aircraft, 12 flights on A*-planned tracks (tens of waypoints each), with
    aircraft A01's last flight cancelled by hand in schedule.csv before the export (the greedy
    schedule operates all twelve; no flight depends on an aircraft's last one)."""
    folder = _schedule(root, tmp_path_factory, "planned")
    rows = _rows(folder)
    last = [r for r in rows.values() if r["aircraft"] == "A01"][-1]
    last.update(operated="0", departure_s="", arrival_s="")
    with open(folder / "schedule.csv", "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(last))
        writer.writeheader()
        writer.writerows(rows.values())
    return (*_export(folder), last["flight"])


@pytest.fixture(scope="module")
def vertical(root, tmp_path_factory):
    folder = _schedule(root, tmp_path_factory, "vertical", 'network.tracks="straight"', "network.vertical_phases=true")
    return _export(folder)


def _check_operated(doc, trips, flights, rows, frame) -> int:
    """Every operated flight's vertex times, in tracks.geojson and trips.kepler.json; returns how
    many flights were checked."""
    for collection in (doc, trips):
        assert collection["uamopt"]["time_origin_utc"] == ANCHOR_UTC
        assert collection["uamopt"]["time_origin_unix_s"] == ANCHOR_UNIX
    assert all(len(c) == 3 for f in doc["features"] for c in f["geometry"]["coordinates"])  # RFC 7946, every flight
    operated = [r["flight"] for r in rows.values() if r["operated"] == "1"]
    trip = {f["properties"]["id"]: f for f in trips["features"]}
    assert trips["type"] == "FeatureCollection" and len(trips["features"]) == len(trip)
    assert sorted(trip) == sorted(operated)  # the operated flights only: kepler.gl wants 4 elements everywhere
    checked = 0
    for feature in doc["features"]:
        p = feature["properties"]
        row = rows[p["id"]]
        if row["operated"] != "1":
            continue
        coords = feature["geometry"]["coordinates"]
        kepler = trip[p["id"]]
        assert kepler["type"] == "Feature" and kepler["geometry"]["type"] == "LineString"
        assert kepler["properties"] == p  # the same properties, timestamps included
        trip_coords = kepler["geometry"]["coordinates"]
        flight = flights[p["id"]]
        expected = _expected_times(flight, float(row["departure_s"]))
        stamps = p["timestamps"]
        assert p["operated"] is True and p["time_origin_utc"] == ANCHOR_UTC
        assert len(stamps) == len(coords) == len(flight["waypoints"])
        np.testing.assert_allclose(stamps, expected, rtol=0, atol=TOL_S)
        assert stamps[0] == pytest.approx(float(row["departure_s"]), abs=TOL_S) == p["departure_s"]
        assert stamps[-1] == pytest.approx(float(row["arrival_s"]), abs=TOL_S)
        assert all(b >= a for a, b in itertools.pairwise(stamps))
        assert all(len(c) == 3 for c in coords) and all(len(c) == 4 for c in trip_coords)
        assert [c[:3] for c in trip_coords] == coords  # the same positions, exactly
        unix = [c[3] for c in trip_coords]
        np.testing.assert_allclose(np.array(unix) - ANCHOR_UNIX, stamps, rtol=0, atol=UNIX_TOL_S)
        assert all(b >= a for a, b in itertools.pairwise(unix))
        assert all(KEPLER_UNIX_SECONDS.fullmatch(json.dumps(t)) for t in unix)  # as written in the file
        # GeoPandas: the same flight with z, the times as a list property
        geometry = frame.geometry[p["id"]]
        assert geometry.has_z and len(geometry.coords) == len(coords)
        np.testing.assert_allclose(np.array(geometry.coords), np.array(coords), rtol=0, atol=1e-9)
        np.testing.assert_allclose(np.asarray(frame.loc[p["id"], "timestamps"], float), stamps, rtol=0, atol=0)
        checked += 1
    return checked


def test_operated_flights_carry_their_vertex_times(planned):
    doc, trips, flights, rows, frame, _ = planned
    assert _check_operated(doc, trips, flights, rows, frame) == 11
    assert max(len(f["waypoints"]) for f in flights.values()) > 10  # the cumulative sums are over many segments


def test_cancelled_flight_is_written_as_before(planned):
    doc, trips, _, _, frame, cancelled = planned
    feature = next(f for f in doc["features"] if f["properties"]["id"] == cancelled)
    p = feature["properties"]
    assert set(p) == OLD_PROPERTIES and p["operated"] is False and p["departure_s"] is None is p["arrival_s"]
    assert all(len(c) == 3 for c in feature["geometry"]["coordinates"])
    assert frame.loc[cancelled, "timestamps"] is None and not bool(frame.loc[cancelled, "operated"])
    assert cancelled not in {f["properties"]["id"] for f in trips["features"]}  # no times: not a trip


def test_vertical_phases_at_their_rate(vertical):
    doc, trips, flights, rows, frame = vertical
    assert _check_operated(doc, trips, flights, rows, frame) == 12
    for feature in doc["features"]:
        p = feature["properties"]
        flight = flights[p["id"]]
        wp, rate = np.array(flight["waypoints"]), flight["vertical_rate_mps"]
        assert len(wp) == 4 and wp[0, 2] == wp[-1, 2] == 0.0  # ground, top of climb, top of descent, ground
        stamps = p["timestamps"]
        climb, descent = wp[1, 2] - wp[0, 2], wp[-2, 2] - wp[-1, 2]  # vertical segments: their length is the height
        assert stamps[1] - stamps[0] == pytest.approx(climb / rate, abs=TOL_S)
        assert stamps[-1] - stamps[-2] == pytest.approx(descent / rate, abs=TOL_S)
        cruise = math.dist(wp[1], wp[2])
        assert stamps[2] - stamps[1] == pytest.approx(cruise / flight["speed_mps"], abs=TOL_S)
        assert stamps[-1] == pytest.approx(float(rows[p["id"]]["arrival_s"]), abs=TOL_S)
