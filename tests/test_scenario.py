"""Scenario loading: Table B.3 defaults, overrides, and one-line errors for bad input."""

from __future__ import annotations

import math
import re

import pytest

from uamopt.errors import ScenarioError
from uamopt.scenario import Scenario, load_scenario, parse_override


def test_defaults_are_table_b3():
    s = Scenario()
    assert s.risk.failure_rate_per_h == 6.04e-5
    assert s.city.population_density == 2.5e-4
    assert s.aircraft.length_m == 6.0 and s.aircraft.empty_mass_kg == 400.0 and s.aircraft.payload_max_kg == 220.0
    assert (s.risk.alpha_j, s.risk.beta_j, s.risk.drag_coefficient, s.risk.air_density) == (1e6, 232.0, 0.3, 1.225)
    assert (s.risk.vehicle_area_m2, s.risk.traffic_density_per_m, s.risk.road_width_m) == (9.68, 0.07, 3.5)
    assert s.risk.uav_density_per_m3 == 3.48e-8 and s.risk.uav_speed_mps == 6.0
    assert s.aircraft.speed_max_mps == pytest.approx(130 / 3.6) and s.aircraft.climb_angle_rad == pytest.approx(math.pi / 6)
    assert s.risk.weights == (0.5, 0.3, 0.2) and s.risk.threshold == 1e-7
    assert (s.aircraft.h_min, s.grid.h_min_airspace, s.aircraft.h_max, s.grid.h_max_airspace) == (90, 30, 3000, 300)
    assert s.tracks.weights == (0.5, 0.5) and s.tracks.clearance_m == 50 and s.tracks.buffer_penalty == 100
    assert (s.schedule.outbound_gap_s, s.schedule.return_gap_s, s.schedule.interference) == (240, 360, 0.3)
    assert s.schedule.weights == (0.6, 0.4)
    ports = {v.name: (v.x, v.y) for v in s.network.vertiports}
    assert ports == {"V1": (300, 300), "V2": (300, 4220), "V3": (2220, 300), "V4": (2220, 4220), "V5": (1260, 2260)}
    # L_14 = 4365 m is |V4 - V1| (docs/readings.md)
    assert math.dist(ports["V1"], ports["V4"]) == pytest.approx(4365, abs=0.5)


def test_paper_case_file(root):
    s = load_scenario(root / "models" / "paper_case.toml")
    assert s.name == "paper_case" and s.grid.cell == (50, 50, 30) and s.city.source == "synthetic"
    assert len(s.network.vertiports) == 5


@pytest.mark.parametrize(("item", "path", "value"), [
    ("grid.cell=[10,10,10]", ["grid", "cell"], [10, 10, 10]),
    ("city.source=osm", ["city", "source"], "osm"),
    ("city.source='dsm'", ["city", "source"], "dsm"),
    ("risk.threshold=2e-7", ["risk", "threshold"], 2e-7),
    ("city.seed=3", ["city", "seed"], 3),
])
def test_parse_override(item, path, value):
    assert parse_override(item) == (path, value)


def test_overrides_apply_and_validate(root):
    s = load_scenario(root / "models" / "paper_case.toml", ["grid.cell=[10,10,10]", "tracks.weights=[0.0,1.0]"])
    assert s.grid.cell == (10, 10, 10) and s.tracks.weights == (0.0, 1.0)
    s2 = Scenario().with_overrides(["city.seed=11"])
    assert s2.city.seed == 11


def _write(tmp_path, text):
    p = tmp_path / "s.toml"
    p.write_text(text)
    return p


@pytest.mark.parametrize(("text", "overrides", "fragment"), [
    ("[grid\ncell = 1", [], "malformed TOML"),
    ("[grid]\ncel = [1, 1, 1]", [], "unknown key 'grid.cel'"),
    ("[grid]\ncell = [-10, 10, 10]", [], "grid.cell"),
    ("[grid]\ncell = [10, 10]", [], "grid.cell"),
    ("[risk]\nweights = 'a'", [], "risk.weights"),
    ("[city]\nsource = 'lidar'", [], "city.source"),
    ("", ["grid.cell=[0,10,10]"], "--set grid.cell"),
    ("", ["grid.size=3"], "unknown key 'grid.size'"),
    ("", ["nonsense"], "has no '='"),
    ("[network]\nroutes = [['V1', 'V9']]", [], "network.routes"),
])
def test_bad_scenarios_give_one_line(tmp_path, text, overrides, fragment):
    with pytest.raises(ScenarioError, match=re.escape(fragment)) as info:
        load_scenario(_write(tmp_path, text), overrides)
    line = info.value.line()
    assert fragment in line and "\n" not in line
    assert "(" in line and "):" in line  # what (where): how to fix


def test_missing_file(tmp_path):
    with pytest.raises(ScenarioError, match="not found"):
        load_scenario(tmp_path / "nope.toml")


def test_unknown_key_lists_valid_keys(tmp_path):
    with pytest.raises(ScenarioError, match=r"unknown key 'risk\.lambda'") as info:
        load_scenario(_write(tmp_path, "[risk]\nlambda = 1"))
    assert "failure_rate_per_h" in info.value.fix
