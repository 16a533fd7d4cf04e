"""Every scenario key acts: the revived [schedule] keys, and a walk over the whole scenario model
that fails when a key is never read (a dead key).

The commands run in-process (``uamopt.cli.main``) on the paper case at its 50 m cells, flying a
network planned once for the module.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

from conftest import PAPER_CASE, ROOT
from uamopt import scenario as scenario_module
from uamopt.cli import main


@pytest.fixture(scope="module")
def network_file(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("net") / "network"
    assert main(["network", str(PAPER_CASE), "--out", str(out)]) == 0
    return out / "network.json"


def schedule(tmp_path: Path, network_file: Path, *overrides: str, solver: str = "greedy") -> tuple[dict, list[dict]]:
    out = tmp_path / "s"
    args = ["schedule", str(PAPER_CASE), "--solver", solver, "--network", str(network_file), "--out", str(out)]
    for item in overrides:
        args += ["--set", item]
    assert main(args) == 0
    summary = json.loads((out / "summary.json").read_text())
    with open(out / "schedule.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    return summary, rows


def first_departures(rows: list[dict]) -> dict[str, float]:
    first: dict[str, float] = {}
    for r in rows:
        first[r["aircraft"]] = min(first.get(r["aircraft"], math.inf), float(r["planned_departure_s"]))
    return first


def test_flights_key_sets_the_total(tmp_path, network_file):
    summary, rows = schedule(tmp_path, network_file, "schedule.flights=125")
    assert summary["flights"] == len(rows) == 125
    per_aircraft = sorted(sum(r["aircraft"] == a for r in rows) for a in {r["aircraft"] for r in rows})
    assert per_aircraft == [6] * 15 + [7] * 5  # ⌊125/20⌋ = 6 each, the remainder on five aircraft


def test_service_key_changes_eq23(tmp_path, network_file):
    """T_f − T_s = 2400 s: Eq. 23 with the network's longest route gives F per aircraft."""
    routes = json.loads(network_file.read_text())["routes"]
    longest = max(float(np.sum(np.linalg.norm(np.diff(np.asarray(r["waypoints"]), axis=0), axis=1)))
                  for r in routes.values())
    cycle = 2 * math.floor(longest / 25.0 + 0.5) + 240 + 360 + 0.3
    expected = math.floor(2400 / cycle) * 2 * 20
    summary, rows = schedule(tmp_path, network_file, "schedule.service_s=2400")
    assert summary["flights"] == expected != 120
    assert max(float(r["arrival_s"]) for r in rows if r["operated"] == "1") <= 2400 + 1e-6


def test_time_step_key_is_the_delay_and_departure_grid(tmp_path, network_file):
    summary, rows = schedule(tmp_path, network_file, "schedule.time_step_s=7")
    delays = [float(r["delay_s"]) for r in rows if r["operated"] == "1"]
    assert any(d > 0 for d in delays)
    assert all(abs(d / 7 - round(d / 7)) < 1e-6 for d in delays)  # greedy's delays on the ΔT_a = 7 s grid
    assert any(abs(d / 10 - round(d / 10)) > 1e-6 for d in delays)  # ... and not on the default 10 s grid
    assert all(abs(t / 7 - round(t / 7)) < 1e-6 for t in first_departures(rows).values())


def test_flights_held_while_speed_varies(tmp_path, network_file):
    """The paper's Fig. 23 keeps 120 flights at every speed; Eq. 23 alone would plan more at 35 m/s,
    and the first-departure window is narrowed (not an error) where a chain has less slack."""
    free, _ = schedule(tmp_path / "free", network_file, "aircraft.cruise_speed_mps=35")
    held, rows = schedule(tmp_path / "held", network_file, "aircraft.cruise_speed_mps=35", "schedule.flights=120")
    assert free["flights"] > 120 and held["flights"] == 120
    tight, _ = schedule(tmp_path / "tight", network_file, "schedule.first_departure_window_s=2000")
    assert any("first_departure_window_s = 2000 s" in n for n in tight["plan_notes"])
    assert "plan_notes" not in held


# --- dead keys ----------------------------------------------------------------------------------

#: Keys read only by `uamopt reproduce` and its report (checked statically below: reproduce is too
#: slow to run here), with the file that reads them.
READ_BY_REPRODUCE = {("TracksConfig", "table2_cell_m"): ("cli.py", "tracks.table2_cell_m"),
                     ("TracksConfig", "table4_cells"): ("cli.py", "tracks.table4_cells"),
                     ("Scenario", "description"): ("report.py", "scenario.description")}


def _walk(model_cls, out: set):
    for name, info in model_cls.model_fields.items():
        out.add((model_cls.__name__, name))
        ann = info.annotation
        for sub in (ann, *getattr(ann, "__args__", ())):
            sub = getattr(sub, "__args__", (sub,))[0] if getattr(sub, "__origin__", None) is tuple else sub
            if isinstance(sub, type) and issubclass(sub, scenario_module._Section) and sub is not model_cls:
                _walk(sub, out)
    return out


def test_every_scenario_key_is_read(tmp_path, network_file, monkeypatch):
    """Record every attribute read of every scenario section while the commands run; a field never
    read is a key that validates and then does nothing."""
    every = _walk(scenario_module.Scenario, set())
    read: set = set()
    plain = scenario_module._Section.__getattribute__

    def tracking(self, name):
        cls = type(self)
        if name in cls.model_fields:
            read.add((cls.__name__, name))
        return plain(self, name)

    monkeypatch.setattr(scenario_module._Section, "__getattribute__", tracking)
    # synthetic city: risk, tracks, network, plan, schedule
    assert main(["plan", str(PAPER_CASE), "--out", str(tmp_path / "plan")]) == 0
    assert main(["schedule", str(PAPER_CASE), "--solver", "greedy", "--out", str(tmp_path / "sched")]) == 0
    # OpenStreetMap city (bundled Helsinki extract), coarse cells
    assert main(["risk", str(ROOT / "models" / "helsinki.toml"), "--set", "grid.cell=[50,50,30]",
                 "--set", "city.bbox=[24.935,60.164,24.952,60.175]", "--out", str(tmp_path / "osm")]) == 0
    # DSM city with roads, no-fly zones, a shelter raster and a ground datum
    from test_city_dsm import dsm_city_with_every_layer

    assert main(["risk", str(dsm_city_with_every_layer(tmp_path / "dsm")), "--out", str(tmp_path / "dsm_out")]) == 0
    monkeypatch.undo()
    for (_, key), (module, text) in READ_BY_REPRODUCE.items():
        assert text in (ROOT / "uamopt" / module).read_text(), key
    dead = sorted(every - read - set(READ_BY_REPRODUCE))
    assert not dead, f"scenario keys never read: {dead}"
