"""DSM GeoTIFF city source (uamopt.city.dsm) on a small synthetic raster written by the test.

The raster: EPSG:32633, 1 m pixels, 200 m (x, east) × 300 m (y, north), ground at 10 m, with
- a tower, top 50 m (40 m above ground), x ∈ [20, 60), y ∈ [220, 240): columns i = 1, 2 at j = 11;
- a low block, top 22 m (12 m above ground), x ∈ [140, 160), y ∈ [40, 80): column i = 7 at j = 2, 3;
- a 5 × 5 m nodata patch in the south-west corner that must not set the ground datum.
Both blocks are asymmetric and off-centre, so a transposed or flipped axis moves them.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import rasterio
from affine import Affine

from uamopt.city import load_city, source_extent
from uamopt.city.dsm import dsm_extent, load_dsm
from uamopt.errors import InputFileError, ScenarioError
from uamopt.grid import AirspaceGrid
from uamopt.pipeline import scenario_grid
from uamopt.scenario import load_scenario

LEFT, BOTTOM = 400_000.0, 6_600_000.0  # UTM 33N, metres
WIDTH, HEIGHT = 200, 300  # pixels = metres
NODATA = -9999.0


def _write_tif(path: Path, data: np.ndarray, crs: str = "EPSG:32633", nodata: float | None = NODATA) -> Path:
    """A north-up GeoTIFF whose array ``data`` is (rows southward, cols eastward), 1 m pixels."""
    transform = Affine(1.0, 0.0, LEFT, 0.0, -1.0, BOTTOM + data.shape[0])
    with rasterio.open(path, "w", driver="GTiff", height=data.shape[0], width=data.shape[1], count=1,
                       dtype="float32", crs=crs, transform=transform, nodata=nodata) as dst:
        dst.write(data.astype("float32"), 1)
    return path


def _block(dsm: np.ndarray, x: tuple[int, int], y: tuple[int, int], top_m: float) -> None:
    """Raise the local-frame rectangle x ∈ [x0, x1), y ∈ [y0, y1) (m east / north of the SW corner)."""
    rows = slice(HEIGHT - y[1], HEIGHT - y[0])  # row 0 is the north edge
    dsm[rows, x[0]:x[1]] = top_m


def _feature_collection(geometries: list[dict]) -> str:
    return json.dumps({"type": "FeatureCollection",
                       "features": [{"type": "Feature", "properties": {}, "geometry": g} for g in geometries]})


def _utm(points: list[tuple[float, float]]) -> list[list[float]]:
    return [[LEFT + x, BOTTOM + y] for x, y in points]


def write_dsm_city(tmp_path: Path) -> Path:
    """The test city of the module docstring in ``tmp_path`` (city.toml, dsm.tif, roads, no-fly)."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    dsm = np.full((HEIGHT, WIDTH), 10.0)
    _block(dsm, (20, 60), (220, 240), 50.0)
    _block(dsm, (140, 160), (40, 80), 22.0)
    dsm[HEIGHT - 5:, :5] = NODATA
    _write_tif(tmp_path / "dsm.tif", dsm)
    # roads: an east-west street along y = 150 m across the whole raster, a diagonal from (0, 0) to (100, 100)
    (tmp_path / "roads.geojson").write_text(_feature_collection([
        {"type": "LineString", "coordinates": _utm([(0, 150), (200, 150)])},
        {"type": "LineString", "coordinates": _utm([(0, 0), (100, 100)])},
    ]))
    # no-fly: x ∈ [101, 139], y ∈ [261, 299] → columns i = 5, 6, j = 13, 14
    (tmp_path / "no_fly.geojson").write_text(json.dumps({"type": "Feature", "properties": {}, "geometry": {
        "type": "Polygon", "coordinates": [_utm([(101, 261), (139, 261), (139, 299), (101, 299), (101, 261)])]}}))
    (tmp_path / "city.toml").write_text(
        'name = "dsm-test"\n[grid]\ncell = [20.0, 20.0, 10.0]\n'
        '[city]\nsource = "dsm"\ndsm = "dsm.tif"\nroads = "roads.geojson"\nno_fly = "no_fly.geojson"\n'
    )
    return tmp_path


@pytest.fixture
def dsm_dir(tmp_path: Path) -> Path:
    return write_dsm_city(tmp_path)


def dsm_city_with_every_layer(directory: Path) -> Path:
    """The test city with every optional [city] key of the dsm source set; returns its city.toml."""
    write_dsm_city(directory)
    _write_tif(directory / "shelter.tif", np.full((HEIGHT, WIDTH), 0.4), nodata=None)
    toml = directory / "city.toml"
    toml.write_text(toml.read_text() + 'shelter = "shelter.tif"\nground_m = 9.0\nbuilding_min_height_m = 3.0\n')
    return toml


def _layers(directory: Path, overrides: list[str] | None = None):
    scenario = load_scenario(directory / "city.toml", overrides)
    grid = scenario_grid(scenario)
    return grid, load_city(scenario, grid)


def test_extent_is_raster_size(dsm_dir):
    scenario = load_scenario(dsm_dir / "city.toml")
    assert dsm_extent(scenario) == source_extent(scenario) == (200.0, 300.0)
    assert scenario_grid(scenario).shape == (10, 15, 30)


def test_heights_and_orientation(dsm_dir):
    grid, layers = _layers(dsm_dir)
    assert layers.building_height.shape == (10, 15)
    expected = np.zeros((10, 15))
    expected[1:3, 11] = 40.0  # tower: x 20-60 m (i = 1, 2), y 220-240 m (j = 11)
    expected[7, 2:4] = 12.0  # block: x 140-160 m (i = 7), y 40-80 m (j = 2, 3)
    np.testing.assert_allclose(layers.building_height, expected)
    np.testing.assert_allclose(layers.surface_height, expected)  # flat ground at the datum
    assert layers.notes["ground_m"] == 10.0  # the nodata patch is ignored
    assert layers.source == "dsm" and "32633" in layers.crs and layers.origin == (LEFT, BOTTOM)
    # the tower's cell found from its east/north position
    assert grid.index_of((40.0, 230.0, 5.0))[:2] == (2, 11)


def test_shelter_rule(dsm_dir):
    _, layers = _layers(dsm_dir)
    tall = layers.building_height > 15.0
    assert tall.sum() == 2
    assert np.all(layers.shelter[tall] == 0.75) and np.all(layers.shelter[~tall] == 0.5)


def test_shelter_layer_overrides_rule(dsm_dir):
    shelter = np.full((HEIGHT, WIDTH), 0.2)
    shelter[:, 100:] = 0.6  # east half
    _write_tif(dsm_dir / "shelter.tif", shelter, nodata=None)
    _, layers = _layers(dsm_dir, ["city.shelter='shelter.tif'"])
    np.testing.assert_allclose(layers.shelter[:5], 0.2)
    np.testing.assert_allclose(layers.shelter[5:], 0.6)


def test_ground_datum_override(dsm_dir):
    _, layers = _layers(dsm_dir, ["city.ground_m=4.0"])
    assert layers.building_height[1, 11] == pytest.approx(46.0)
    assert layers.surface_height[0, 0] == pytest.approx(6.0)  # ground 6 m above the datum: a "building" of 6 m
    _, layers = _layers(dsm_dir, ["city.ground_m=4.0", "city.building_min_height_m=8.0"])
    assert layers.building_height[0, 0] == 0.0 and layers.surface_height[0, 0] == pytest.approx(6.0)


def test_road_length_per_column(dsm_dir):
    _, layers = _layers(dsm_dir)
    expected = np.zeros((10, 15))
    expected[:, 7] = 20.0  # y = 150 m lies in row j = 7: 20 m of road in each of the 10 columns
    expected[np.arange(5), np.arange(5)] = 20.0 * math.sqrt(2.0)  # the diagonal crosses cells (k, k) corner to corner
    np.testing.assert_allclose(layers.road_length, expected, atol=1e-9)
    assert layers.road_length.sum() == pytest.approx(200.0 + 100.0 * math.sqrt(2.0))


def test_no_fly_columns(dsm_dir):
    _, layers = _layers(dsm_dir)
    expected = np.zeros((10, 15), dtype=bool)
    expected[5:7, 13:15] = True
    np.testing.assert_array_equal(layers.no_fly, expected)
    assert not layers.open_space.any()
    np.testing.assert_allclose(layers.population_density, 2.5e-4)


def test_missing_geotiff(dsm_dir):
    scenario = load_scenario(dsm_dir / "city.toml", ["city.dsm='missing.tif'"])
    with pytest.raises(InputFileError, match=r"GeoTIFF not found.*\(city\.dsm\)"):
        dsm_extent(scenario)
    with pytest.raises(InputFileError, match=r"\(city\.dsm\)"):
        load_dsm(scenario, AirspaceGrid(cell=(20.0, 20.0, 10.0), shape=(10, 15, 30)))


def test_unreadable_inputs(dsm_dir):
    (dsm_dir / "junk.tif").write_bytes(b"not a tiff")
    with pytest.raises(InputFileError, match=r"cannot read GeoTIFF.*\(city\.dsm\)"):
        dsm_extent(load_scenario(dsm_dir / "city.toml", ["city.dsm='junk.tif'"]))
    (dsm_dir / "junk.geojson").write_text("{ not json")
    grid = AirspaceGrid(cell=(20.0, 20.0, 10.0), shape=(10, 15, 30))
    with pytest.raises(InputFileError, match=r"\(city\.roads\)"):
        load_dsm(load_scenario(dsm_dir / "city.toml", ["city.roads='junk.geojson'"]), grid)
    with pytest.raises(InputFileError, match=r"not found.*\(city\.no_fly\)"):
        load_dsm(load_scenario(dsm_dir / "city.toml", ["city.no_fly='none.geojson'"]), grid)


def test_geographic_crs_rejected(dsm_dir):
    _write_tif(dsm_dir / "geo.tif", np.full((10, 10), 5.0), crs="EPSG:4326")
    with pytest.raises(InputFileError, match="gdalwarp"):
        dsm_extent(load_scenario(dsm_dir / "city.toml", ["city.dsm='geo.tif'"]))


def test_no_dsm_given(dsm_dir):
    (dsm_dir / "bare.toml").write_text('[city]\nsource = "dsm"\n')
    with pytest.raises(ScenarioError, match=r"city\.dsm"):
        dsm_extent(load_scenario(dsm_dir / "bare.toml"))


def test_low_patch_is_an_obstacle_but_not_a_clearance_source(dsm_dir):
    """Eq. 15 measures s_min from building cells: a 6 m patch below building_min_height_m = 8 m is an
    obstacle the track cannot enter, but the cell 10 m above it stays admissible."""
    from uamopt.pipeline import compute_risk
    from uamopt.planning import planning_model

    band = ["aircraft.h_min=0.0", "grid.h_min_airspace=0.0", "city.ground_m=4.0"]

    def model(min_height: float):
        scenario = load_scenario(dsm_dir / "city.toml", [*band, f"city.building_min_height_m={min_height}"])
        return planning_model(scenario, compute_risk(scenario))

    low = model(8.0)  # the ground between the blocks stands 6 m above the datum: a low patch
    assert low.field.obstacle[4, 7, 0] and low.field.city.building_height[4, 7] == 0.0
    assert low.admissible[4, 7, 1] and not low.admissible[4, 7, 0]
    tall = model(2.0)  # the same 6 m surface counted as buildings: 10 m above is within s_min = 50 m
    assert tall.field.city.building_height[4, 7] == pytest.approx(6.0) and not tall.admissible[4, 7, 1]


# --- the shipped example: models/dsm_example.toml ------------------------------------------------

EXAMPLE = Path(__file__).resolve().parents[1] / "models" / "dsm_example.toml"


def test_the_example_dsm_is_a_small_plausible_city():
    """The shipped GeoTIFF is small, projected (UTM 33N) and 1.2 km × 1.0 km; at its 10 m cells it
    has towers up to about 180 m, roads, a no-fly zone, and four vertiports that can be flown from."""
    from uamopt.pipeline import compute_risk
    from uamopt.planning import planning_model

    data = EXAMPLE.parent / "data"
    assert (data / "dsm_example.tif").stat().st_size <= 200_000
    scenario = load_scenario(EXAMPLE)
    assert dsm_extent(scenario) == (1200.0, 1000.0) and scenario.grid.cell == (10.0, 10.0, 10.0)
    with rasterio.open(data / "dsm_example.tif") as src:
        assert src.crs.to_epsg() == 32633 and src.crs.is_projected
    field = compute_risk(scenario)
    city = field.city
    assert field.grid.shape == (120, 100, 30)
    assert 170.0 <= city.building_height.max() <= 180.0
    assert 0.3 < (city.building_height > 0).mean() < 0.7  # built-up blocks between streets and open ground
    assert city.notes["roads"] > 10 and (city.road_length > 0).mean() > 0.1 and city.notes["no_fly_zones"] == 1
    model = planning_model(scenario, field)
    for v in scenario.network.vertiports:
        cell = field.grid.index_of((v.x, v.y, scenario.network.cruise_altitude_m))
        assert model.admissible[cell] and not field.unsafe[cell], v.name  # off the roads, clear of buildings


def test_the_example_dsm_is_what_its_script_writes(tmp_path):
    """models/data/make_dsm_example.py documents the shipped files: it writes the same raster and
    GeoJSON."""
    import importlib.util

    script = EXAMPLE.parent / "data" / "make_dsm_example.py"
    spec = importlib.util.spec_from_file_location("make_dsm_example", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.main(tmp_path)
    for name in ("dsm_example_roads.geojson", "dsm_example_no_fly.geojson"):
        assert json.loads((tmp_path / name).read_text()) == json.loads((script.parent / name).read_text()), name
    with rasterio.open(tmp_path / "dsm_example.tif") as new, rasterio.open(script.parent / "dsm_example.tif") as old:
        assert new.crs == old.crs and new.transform == old.transform
        np.testing.assert_array_equal(new.read(1), old.read(1))


def test_every_command_runs_on_the_example(tmp_path):
    """`uamopt risk`, `plan`, `network` and `schedule` work on the shipped DSM scenario."""
    from uamopt.cli import main

    out = tmp_path / "out"
    assert main(["risk", str(EXAMPLE), "--out", str(out / "risk")]) == 0
    assert main(["plan", str(EXAMPLE), "--out", str(out / "plan")]) == 0
    assert main(["network", str(EXAMPLE), "--out", str(out / "network")]) == 0
    assert main(["schedule", str(EXAMPLE), "--solver", "greedy", "--network", str(out / "network" / "network.json"),
                 "--out", str(out / "schedule")]) == 0
    tracks = json.loads((out / "plan" / "tracks.json").read_text())
    stages = tracks["stages"]
    assert stages["optimal"]["risk_cost"] < stages["shortest"]["risk_cost"]
    assert len(json.loads((out / "network" / "network.json").read_text())["routes"]) == 12
    summary = json.loads((out / "schedule" / "summary.json").read_text())
    assert summary["flights"] > 0 and (out / "schedule" / "schedule.csv").is_file()
