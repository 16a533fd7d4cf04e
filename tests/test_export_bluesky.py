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
from georef import hand_lonlat
from pyproj import Transformer

from uamopt.cli import main
from uamopt.errors import UamoptError
from uamopt.export.frame import scenario_frame
from uamopt.scenario import load_scenario
from uamopt.sim.zone import protected_zone

DT = 0.05
FT, KT = 0.3048, 1852.0 / 3600.0


@pytest.fixture(scope="module")
def scn(paper_export):
    return paper_export("bluesky")


def test_scenario_flies_each_operated_flight_from_its_departure(scn):
    readscn = pytest.importorskip("bluesky.stack.simstack").readscn
    from bluesky.tools.aero import cas2tas

    lines = readscn(str(scn / "bluesky.scn"))
    assert lines[0] == (0.0, "CASMACHTHR 0")  # before any speed is read
    assert (0.0, f"DT {DT:g}") in lines and (0.0, "CDMETHOD STATEBASED") in lines
    zoner = next(float(c.split()[1]) for _, c in lines if c.startswith("ZONER"))
    assert zoner * 1852.0 == pytest.approx(29.5, abs=1e-3)
    cre = {c.split()[1]: (t, c.split()) for t, c in lines if c.startswith("CRE ")}
    with open(scn / "schedule.csv", newline="", encoding="utf-8") as fh:
        rows = [r for r in csv.DictReader(fh) if r["operated"] == "1"]
    flights = {f["id"]: f for f in json.loads((scn / "flights.json").read_text(encoding="utf-8"))["flights"]}
    assert sorted(cre) == sorted(r["flight"] for r in rows)
    for r in rows:
        t, (_, acid, actype, lat, lon, _, alt_ft, cas_kt) = cre[r["flight"]]
        departure = float(r["departure_s"])
        t_k = t + DT / 2  # the clock step at which BlueSky runs the command
        assert actype == "EC35" and 0.0 <= t_k - departure < DT + 1e-6
        wp = np.array(flights[r["flight"]]["waypoints"])
        start = wp[0] + 25.0 * (t_k - departure) * (wp[1] - wp[0]) / np.linalg.norm(wp[1] - wp[0])
        assert (float(lon), float(lat)) == pytest.approx([float(v) for v in hand_lonlat(*start[:2])], abs=5e-6)
        assert float(alt_ft) * FT == pytest.approx(wp[0, 2], abs=0.01)
        assert 24.9 < cas2tas(float(cas_kt) * KT, wp[0, 2]) < 25.1  # v_g, corrected by ≤ 0.3 % per leg
        assert any(c == f"{acid} AT {acid}_END DO DEL {acid}" for _, c in lines)
    adds = sum(1 for _, c in lines if c.startswith("ADDWPT "))
    assert adds == sum(len(flights[r["flight"]]["waypoints"]) - 1 for r in rows)


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
    """r_pz = r·min(Δx, Δy) − 2e_h − 0.5 m, h_pz = r·Δz − 2e_v − 0.5 m (uamopt/sim/zone.py)."""
    zone = protected_zone((20.0, 10.0, 8.0), 2, budget_h_m=1.0, budget_v_m=0.5)
    assert (zone.rpz_m, zone.hpz_m) == (17.5, 14.5)
    assert zone.near_m == (62.0, 32.0, 25.0)  # (r + 1)Δ + 2e
    with pytest.raises(UamoptError, match=r"protected zone is empty .* give --zone"):
        protected_zone((50.0, 50.0, 30.0), 0)  # same-cell conflicts guarantee no distance
    assert protected_zone((50.0, 50.0, 30.0), 0, zone_m=(20.0, 10.0)).rpz_m == 20.0


def test_docstring_examples_run():
    import doctest

    from uamopt.export import frame
    from uamopt.sim import zone

    for module in (frame, zone):
        assert doctest.testmod(module).failed == 0
