"""``uamopt export bluesky`` and the georeference of schedule folders (no simulation here).

The .scn is parsed with BlueSky's own scenario reader; positions are checked against a first-order
WGS 84 formula at the documented anchor, airspeeds against BlueSky's own ISA conversion.
"""

from __future__ import annotations

import csv
import json
import shutil

import numpy as np
import pytest
import rasterio
from affine import Affine
from georef import hand_local
from pyproj import Transformer

from uamopt.cli import main
from uamopt.errors import UamoptError
from uamopt.export.frame import scenario_frame
from uamopt.export.zone import protected_zone
from uamopt.scenario import load_scenario

DT = 0.05
FT, KT = 0.3048, 1852.0 / 3600.0


@pytest.fixture(scope="module")
def scn(paper_export):
    return paper_export("bluesky")


def _flights(folder):
    with open(folder / "schedule.csv", newline="", encoding="utf-8") as fh:
        rows = [r for r in csv.DictReader(fh) if r["operated"] == "1"]
    flights = {f["id"]: f for f in json.loads((folder / "flights.json").read_text(encoding="utf-8"))["flights"]}
    return rows, flights


def _commanded(lines, acid):
    """An aircraft's commands read back: creation time, type, and its 4-D polyline in the local frame
    (georef, not uamopt), each leg timed by BlueSky's own CAS → TAS and distance on its sphere."""
    from bluesky.tools.aero import (  # BlueSky moves aircraft over a sphere of this radius
        Rearth,
        cas2tas,
    )

    t, cre = next((t, c.split()) for t, c in lines if c.startswith(f"CRE {acid} "))
    points = [(float(cre[3]), float(cre[4]), float(cre[6]), float(cre[7]))]  # lat, lon, alt_ft, cas_kt
    ends = {c.split()[1]: (float(c.split()[2]), float(c.split()[3])) for _, c in lines if c.startswith("DEFWPT ")}
    for _, c in lines:
        w = c.split()
        if c.startswith(f"ADDWPT {acid} "):
            lat, lon = ends[w[2]] if w[2] in ends else (float(w[2]), float(w[3]))
            points.append((lat, lon, float(w[-2]), float(w[-1])))
    lat, lon, alt_ft, cas_kt = (np.array(v) for v in zip(*points, strict=True))
    x, y = hand_local(lon, lat)
    z = alt_ft * FT
    tas = np.array([cas2tas(c * KT, 0.5 * (z[i] + z[i + 1])) for i, c in enumerate(cas_kt[:-1])])  # "from" speeds
    p, dl = np.radians(lat), np.radians(np.diff(lon))
    legs = 2 * Rearth * np.arcsin(np.sqrt(np.sin(np.diff(p) / 2) ** 2 + np.cos(p[:-1]) * np.cos(p[1:]) * np.sin(dl / 2) ** 2))
    times = t + DT / 2 + np.concatenate([[0.0], np.cumsum(legs / tas)])  # created at the step t_k = t + DT/2
    return cre[2], times, np.column_stack([x, y, z])


def _plan_at(waypoints, speed, departure, t):
    cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1))])
    return np.column_stack([np.interp(speed * (t - departure), cum, waypoints[:, k]) for k in range(3)])


def test_scenario_flies_each_operated_flight_on_a_flyable_trajectory_near_its_plan(scn):
    """Each aircraft is created at the first clock step after its departure, on its plan, and is
    commanded a polyline whose position at every instant is within 8.5 m of the plan's (the
    designed trajectory, ≤ 8.20 m on the paper case's tracks — a regression value of this version's
    tracks, 7.81 m before the corridor points kept inside their cells — plus ≤ 0.3 m of the
    first-order georeference; the replay's budget e_h = 10 m is the requirement behind it), whose velocity changes
    by at most g·tan 45° per second, and which reaches the destination at the planned arrival."""
    readscn = pytest.importorskip("bluesky.stack.simstack").readscn
    lines = readscn(str(scn / "bluesky.scn"))
    assert lines[0] == (0.0, "CASMACHTHR 0")  # before any speed is read
    assert (0.0, f"DT {DT:g}") in lines and (0.0, "CDMETHOD STATEBASED") in lines
    zoner = next(float(c.split()[1]) for _, c in lines if c.startswith("ZONER"))
    assert zoner * 1852.0 == pytest.approx(29.5, abs=1e-3)
    rows, flights = _flights(scn)
    assert sorted(c.split()[1] for _, c in lines if c.startswith("CRE ")) == sorted(r["flight"] for r in rows)
    for r in rows:
        acid, departure, arrival = r["flight"], float(r["departure_s"]), float(r["arrival_s"])
        wp = np.array(flights[acid]["waypoints"])
        actype, times, points = _commanded(lines, acid)
        assert actype == "EC35" and 0.0 <= times[0] - departure < DT + 1e-6
        assert np.linalg.norm(points[0] - _plan_at(wp, 25.0, departure, times[:1])[0]) < 0.5
        assert np.linalg.norm(points[-1] - wp[-1]) < 0.5 and times[-1] == pytest.approx(arrival, abs=0.01)
        t = np.linspace(times[0], times[-1], 20001)
        flown = np.column_stack([np.interp(t, times, points[:, k]) for k in range(3)])
        error = flown - _plan_at(wp, 25.0, departure, t)
        assert np.hypot(error[:, 0], error[:, 1]).max() < 8.5 and np.abs(error[:, 2]).max() < 0.01
        velocity = np.diff(points, axis=0) / np.diff(times)[:, None]
        dt = np.diff(times)
        assert (np.linalg.norm(np.diff(velocity, axis=0), axis=1) / (0.5 * (dt[:-1] + dt[1:]))).max(initial=0.0) < 9.81
        assert any(c == f"{acid} AT {acid}_END DO DEL {acid}" for _, c in lines)


def test_scenario_can_fly_the_tracks_own_waypoints(scn, tmp_path):
    """``--trajectory waypoints``: one ADDWPT per waypoint after the first, every leg at v_g (its
    time on BlueSky's sphere, within 0.3 %)."""
    readscn = pytest.importorskip("bluesky.stack.simstack").readscn
    folder = tmp_path / "waypoints"
    shutil.copytree(scn, folder)
    assert main(["export", "bluesky", str(folder), "--trajectory", "waypoints"]) == 0
    lines = readscn(str(folder / "bluesky.scn"))
    rows, flights = _flights(folder)
    assert sum(1 for _, c in lines if c.startswith("ADDWPT ")) == sum(len(flights[r["flight"]]["waypoints"]) - 1 for r in rows)
    for r in rows[:10]:
        _, times, points = _commanded(lines, r["flight"])
        speed = np.linalg.norm(np.diff(points, axis=0), axis=1) / np.diff(times)
        assert np.all(np.abs(speed - 25.0) < 0.075)


def test_folder_records_its_frame_and_scenario(paper_schedule_dir, root):
    summary = json.loads((paper_schedule_dir / "summary.json").read_text(encoding="utf-8"))
    assert summary["frame"]["source"] == "synthetic"
    assert summary["frame"]["origin_lonlat"] == pytest.approx([118.77, 32.02], abs=1e-9)
    assert summary["scenario"] == {"name": "paper_case", "file": str(root / "models" / "paper_case.toml"), "set": []}


def test_folder_without_a_frame_uses_the_synthetic_anchor(scn, tmp_path):
    folder = tmp_path / "old"
    shutil.copytree(scn, folder)
    (folder / "summary.json").unlink()
    assert main(["export", "bluesky", str(folder)]) == 0
    text = (folder / "bluesky.scn").read_text(encoding="utf-8")
    assert "none recorded, synthetic anchor assumed" in text
    assert text.split("\n", 4)[4] == (scn / "bluesky.scn").read_text(encoding="utf-8").split("\n", 4)[4]


def test_osm_frame_is_the_extracts_south_west_corner(root):
    frame = scenario_frame(load_scenario(root / "models" / "helsinki.toml"))
    # models/helsinki.toml: "the extract's south-west corner (lon 24.935178, lat 60.164155)"
    assert [float(v) for v in frame.to_lonlat(0.0, 0.0)] == pytest.approx([24.935178, 60.164155], abs=1e-6)
    x, y = frame.from_lonlat(24.935178, 60.164155)
    assert abs(float(x)) < 0.1 and abs(float(y)) < 0.1


def test_dsm_frame_is_the_rasters_crs_and_corner(tmp_path, root):
    left, bottom = 400_000.0, 6_600_000.0  # UTM 33N
    with rasterio.open(tmp_path / "dsm.tif", "w", driver="GTiff", height=50, width=40, count=1, dtype="float32",
                       crs="EPSG:32633", transform=Affine(1.0, 0.0, left, 0.0, -1.0, bottom + 50)) as dst:
        dst.write(np.full((50, 40), 10.0, dtype="float32"), 1)
    scenario = load_scenario(root / "models" / "paper_case.toml", ["city.source=dsm", f"city.dsm='{tmp_path / 'dsm.tif'}'"])
    frame = scenario_frame(scenario)
    assert frame.source == "dsm" and frame.origin == (left, bottom)
    utm = Transformer.from_crs("EPSG:32633", "EPSG:4326", always_xy=True)
    for x, y in ((0.0, 0.0), (40.0, 50.0)):
        assert [float(v) for v in frame.to_lonlat(x, y)] == pytest.approx(utm.transform(left + x, bottom + y), abs=1e-9)


def test_export_bad_input(tmp_path, capsys):
    assert main(["export", "bluesky", str(tmp_path / "nowhere")]) == 2
    (tmp_path / "flights.json").write_text("{", encoding="utf-8")
    assert main(["export", "bluesky", str(tmp_path)]) == 2
    assert main(["export", "geojson", str(tmp_path), "--risk", "a.npz", "--scenario", "b.toml"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and all(line.startswith("error: ") for line in err)
    assert not (tmp_path / "bluesky.scn").exists()


def test_protected_zone_from_the_cells():
    """r_pz = r·min(Δx, Δy) − 2e_h − 0.5 m, h_pz = r·Δz − 2e_v − 0.5 m (uamopt/export/zone.py)."""
    zone = protected_zone((20.0, 10.0, 8.0), 2, budget_h_m=1.0, budget_v_m=0.5)
    assert (zone.rpz_m, zone.hpz_m) == (17.5, 14.5)
    assert zone.near_m == (62.0, 32.0, 25.0)  # (r + 1)Δ + 2e
    with pytest.raises(UamoptError, match=r"protected zone is empty .* give --zone"):
        protected_zone((50.0, 50.0, 30.0), 0)  # same-cell conflicts guarantee no distance
    assert protected_zone((50.0, 50.0, 30.0), 0, zone_m=(20.0, 10.0)).rpz_m == 20.0


def test_docstring_examples_run():
    import doctest

    from uamopt.export import frame, zone

    for module in (frame, zone):
        assert doctest.testmod(module).failed == 0
