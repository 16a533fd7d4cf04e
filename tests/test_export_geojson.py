"""``uamopt export geojson``: RFC 7946 files read back with GeoPandas and checked by hand.

Reference coordinates come from the documented anchor of the synthetic city and the WGS 84 radii
of curvature (tests/georef.py), not from uamopt's projection.
"""

from __future__ import annotations

import csv
import json
import shutil

import numpy as np
import pytest
import shapely
import shapely.geometry
from georef import hand_lonlat as _hand_lonlat

from uamopt.cli import main

gpd = pytest.importorskip("geopandas")

@pytest.fixture(scope="module")
def exported(paper_export):
    return paper_export("geojson")


def test_files_read_back_inside_the_city(exported):
    lon, lat = _hand_lonlat([0.0, 2500.0, 0.0, 2500.0], [0.0, 0.0, 4500.0, 4500.0])  # the paper case's corners
    west, east, south, north = lon.min(), lon.max(), lat.min(), lat.max()
    tol = 1e-5  # degrees, ~1 m
    flights = json.loads((exported / "flights.json").read_text(encoding="utf-8"))["flights"]
    for name in ("tracks", "vertiports", "unsafe"):
        frame = gpd.read_file(exported / f"{name}.geojson")
        assert frame.crs.to_epsg() in (4326, 4979)  # RFC 7946: WGS 84, lon/lat (+ ellipsoidal height with z)
        assert frame.is_valid.all() and len(frame) > 0
        x0, y0, x1, y1 = frame.total_bounds
        assert west - tol <= x0 < x1 <= east + tol and south - tol <= y0 < y1 <= north + tol
    tracks = gpd.read_file(exported / "tracks.geojson")
    assert sorted(tracks["id"]) == sorted(f["id"] for f in flights)
    with open(exported / "schedule.csv", newline="", encoding="utf-8") as fh:
        operated = {r["flight"]: r["operated"] == "1" for r in csv.DictReader(fh)}
    assert tracks.has_z.all() and dict(zip(tracks["id"], tracks["operated"].astype(bool), strict=True)) == operated
    first = flights[0]
    coords = np.array(tracks.set_index("id").geometry[first["id"]].coords)
    wp = np.array(first["waypoints"])
    lon, lat = _hand_lonlat(wp[:, 0], wp[:, 1])
    np.testing.assert_allclose(coords[:, 0], lon, atol=5e-6)
    np.testing.assert_allclose(coords[:, 1], lat, atol=5e-6)
    np.testing.assert_allclose(coords[:, 2], wp[:, 2], atol=0.01)


def _positions(coordinates):
    """Every position of a GeoJSON geometry's (nested) ``coordinates``: the innermost lists."""
    if coordinates and all(isinstance(c, int | float) for c in coordinates):
        yield coordinates
    else:
        for c in coordinates:
            yield from _positions(c)


def _geometries(geometry: dict):
    """A geometry and, for a GeometryCollection, its members."""
    yield geometry
    for member in geometry.get("geometries", []):
        yield from _geometries(member)


def test_every_geojson_file_reads_in_shapely_and_geopandas(exported):
    """Every *.geojson the export writes (found by name, so a new one is covered): RFC 7946
    positions of two or three elements, every feature's geometry read by Shapely and valid, the
    file read by GeoPandas (pyogrio) with one row per feature and the same coordinates."""
    paths = sorted(exported.glob("*.geojson"))
    assert {"tracks.geojson", "vertiports.geojson", "unsafe.geojson"} <= {p.name for p in paths}
    for path in paths:
        doc = json.loads(path.read_text(encoding="utf-8"))
        assert doc["type"] == "FeatureCollection" and len(doc["features"]) > 0, path.name
        shapes = []
        for feature in doc["features"]:
            positions = [q for g in _geometries(feature["geometry"]) for q in _positions(g.get("coordinates", []))]
            assert positions and all(len(q) in (2, 3) for q in positions), (path.name, feature["properties"])
            geometry = shapely.geometry.shape(feature["geometry"])  # raises on 4-element positions
            assert geometry.is_valid and not geometry.is_empty, (path.name, feature["properties"])
            assert shapely.get_num_coordinates(geometry) == len(positions)
            shapes.append(geometry)
        frame = gpd.read_file(path, engine="pyogrio")
        assert len(frame) == len(shapes) and frame.is_valid.all(), path.name
        for mine, theirs in zip(shapes, frame.geometry, strict=True):
            np.testing.assert_allclose(shapely.get_coordinates(theirs, include_z=mine.has_z),
                                       shapely.get_coordinates(mine, include_z=mine.has_z), rtol=0, atol=1e-9)


def test_vertiports_where_table_b3_puts_them(exported):
    ports = gpd.read_file(exported / "vertiports.geojson").set_index("name")
    table_b3 = {"V1": (300, 300), "V2": (300, 4220), "V3": (2220, 300), "V4": (2220, 4220), "V5": (1260, 2260)}
    assert sorted(ports.index) == sorted(table_b3)
    for name, (x, y) in table_b3.items():
        lon, lat = _hand_lonlat(x, y)
        assert ports.geometry[name].x == pytest.approx(lon, abs=5e-6)
        assert ports.geometry[name].y == pytest.approx(lat, abs=5e-6)


def test_unsafe_layers_are_the_risk_fields_unsafe_cells(exported, paper_run):
    """Per layer: the polygons' area is the unsafe cells' area; a sample of unsafe cell centres lies
    inside, a sample of safe ones outside; exterior rings counter-clockwise (RFC 7946)."""
    field = paper_run.field
    layers = gpd.read_file(exported / "unsafe.geojson").set_index("layer")
    frame_crs = json.loads((exported / "summary.json").read_text(encoding="utf-8"))["frame"]["crs"]
    area = layers.to_crs(frame_crs).area
    rng = np.random.default_rng(0)
    assert sorted(layers.index) == [k for k in range(field.grid.shape[2]) if field.unsafe[:, :, k].any()]
    for k, row in layers.iterrows():
        unsafe = field.unsafe[:, :, k]
        assert row["unsafe_cells"] == int(unsafe.sum())
        assert area[k] == pytest.approx(unsafe.sum() * 50.0 * 50.0, rel=1e-4)
        assert row["z_bottom_m"] == 30.0 * k and row["z_top_m"] == 30.0 * (k + 1)
        for flag in (True, False):
            cells = np.argwhere(unsafe == flag)
            for i, j in cells[rng.choice(len(cells), size=min(20, len(cells)), replace=False)]:
                lon, lat = _hand_lonlat((i + 0.5) * 50.0, (j + 0.5) * 50.0)
                assert row.geometry.contains(shapely.Point(lon, lat)) == flag
        for poly in shapely.get_parts(row.geometry):
            assert poly.exterior.is_ccw and not any(r.is_ccw for r in poly.interiors)
    assert layers.loc[4, "in_band"] and not layers.loc[0, "in_band"]  # 120-150 m inside [90, 300] m, 0-30 m not


def test_risk_npz_instead_of_recomputing(exported, paper_run, tmp_path):
    folder = tmp_path / "highs"
    shutil.copytree(exported, folder)
    (folder / "unsafe.geojson").unlink()
    paper_run.field.save_npz(tmp_path / "risk.npz")
    assert main(["export", "geojson", str(folder), "--risk", str(tmp_path / "risk.npz")]) == 0
    mine, recomputed = (gpd.read_file(d / "unsafe.geojson") for d in (folder, exported))
    assert list(mine["layer"]) == list(recomputed["layer"])
    assert all(a.equals(b) for a, b in zip(mine.geometry, recomputed.geometry, strict=True))
    assert mine["in_band"].isna().all()  # risk.npz does not record the band


def test_folder_without_a_recorded_scenario(exported, root, tmp_path, capsys):
    folder = tmp_path / "old"
    shutil.copytree(exported, folder)
    summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
    for key in ("frame", "scenario"):
        summary.pop(key)
    (folder / "summary.json").write_text(json.dumps(summary), encoding="utf-8")
    before = (folder / "unsafe.geojson").read_bytes()
    assert main(["export", "geojson", str(folder)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "records no scenario file" in err[0] and "--scenario" in err[0]
    assert (folder / "unsafe.geojson").read_bytes() == before  # nothing rewritten
    assert main(["export", "geojson", str(folder), "--scenario", str(root / "models" / "paper_case.toml")]) == 0
    doc = json.loads((folder / "tracks.geojson").read_text(encoding="utf-8"))
    assert doc["uamopt"]["frame_recorded"] is False and doc["uamopt"]["frame"]["source"] == "default"
