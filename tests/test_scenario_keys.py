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

from uamopt.cli import main
from uamopt.scenario import schema as scenario_module


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
    _summary, rows = schedule(tmp_path, network_file, "schedule.time_step_s=7")
    delays = [float(r["delay_s"]) for r in rows if r["operated"] == "1"]
    assert any(d > 0 for d in delays)
    assert all(abs(d / 7 - round(d / 7)) < 1e-6 for d in delays)  # greedy's delays on the ΔT_a = 7 s grid
    assert any(abs(d / 10 - round(d / 10)) > 1e-6 for d in delays)  # ... and not on the default 10 s grid
    assert all(abs(t / 7 - round(t / 7)) < 1e-6 for t in first_departures(rows).values())


def test_flights_held_while_speed_varies(tmp_path, network_file):
    """The paper's Fig. 23 keeps 120 flights at every speed; Eq. 23 alone would plan more at 35 m/s,
    and the first-departure window is narrowed (not an error) where a chain has less slack."""
    free, _ = schedule(tmp_path / "free", network_file, "aircraft.cruise_speed_mps=35")
    held, _ = schedule(tmp_path / "held", network_file, "aircraft.cruise_speed_mps=35", "schedule.flights=120")
    assert free["flights"] > 120 and held["flights"] == 120
    tight, _ = schedule(tmp_path / "tight", network_file, "schedule.first_departure_window_s=2000")
    assert any("first_departure_window_s = 2000 s" in n for n in tight["plan_notes"])
    assert "plan_notes" not in held


SMALL_LADDER = ["grid.extent=[5000.0,5000.0,360.0]", "network.random_vertiports=4", "network.tracks='straight'",
                "schedule.aircraft=8", "schedule.flights=40"]


def flights_command(out: Path, *overrides: str) -> dict:
    args = ["flights", str(ROOT / "models" / "benchmark_300.toml"), "--out", str(out)]
    for item in (*SMALL_LADDER, *overrides):
        args += ["--set", item]
    assert main(args) == 0
    return json.loads((out / "flights.json").read_text())


def test_instance_generator_random_vertiports_straight_tracks(tmp_path):
    doc = flights_command(tmp_path / "a")
    flights = doc["flights"]
    assert len(flights) == 40 and len({f["aircraft"] for f in flights}) == 8
    ends = {}
    for f in flights:
        w = np.asarray(f["waypoints"])
        assert w.shape == (2, 3) and w[0, 2] == w[1, 2]  # straight and level
        ends[f["origin"]] = w[0, :2]
        assert w[0, 2] == (120.0 if f["origin"] < f["destination"] else 180.0)  # b->a r + 1 = 2 layers up
    pts = np.array(list(ends.values()))
    assert len(pts) >= 2 and np.all((pts >= 300) & (pts <= 4700))
    assert min(np.linalg.norm(a - b) for i, a in enumerate(pts) for b in pts[i + 1:]) >= 500
    assert flights_command(tmp_path / "b")["flights"] == flights  # same seed, same instance
    other = flights_command(tmp_path / "c", "network.vertiport_seed=1")["flights"]
    assert [f["waypoints"] for f in other] != [f["waypoints"] for f in flights]
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert summary["flights"] == 40 and summary["tracks"] == "straight" and summary["vertiports"] == 4


def test_random_vertiports_need_an_extent(tmp_path, capsys):
    assert main(["flights", str(ROOT / "models" / "helsinki.toml"), "--set", "network.random_vertiports=3",
                 "--out", str(tmp_path / "x")]) == 2
    assert "needs grid.extent" in capsys.readouterr().err and not (tmp_path / "x").exists()


# --- dead keys ----------------------------------------------------------------------------------

#: Keys read only by `uamopt reproduce` and its report (checked statically below: reproduce is too
#: slow to run here), with the file that reads them.
READ_BY_REPRODUCE = {("TracksConfig", "table2_cell_m"): ("reproduce.py", "tracks.table2_cell_m"),
                     ("TracksConfig", "table4_cells"): ("reproduce.py", "tracks.table4_cells"),
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
    # the vertiport variant: vertical phases at the aircraft's climb rate, pads
    assert main(["schedule", str(PAPER_CASE), "--solver", "greedy", "--out", str(tmp_path / "vertiport"),
                 "--set", 'network.tracks="straight"', "--set", "network.vertical_phases=true",
                 "--set", "network.pads=1", "--set", "schedule.aircraft=4", "--set", "schedule.flights=16"]) == 0
    # the instance generator: random vertiports, straight tracks
    flights_command(tmp_path / "ladder")
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


def test_the_memory_guard_counts_what_each_command_keeps(tmp_path, capsys):
    """On the paper case's 54,000 cells ``uamopt risk`` needs 120 MiB + 50 B a cell = 0.12 GB and
    ``uamopt plan`` (numba's and cvxpy's libraries, the planning model, a search) 255 MiB + 23 B a
    cell = 0.25 GB (printed 0.3): under a 0.2 GB limit the first runs and the second is refused
    before any work."""
    limit = ["--set", "grid.memory_limit_gb=0.2", "--no-figures"]
    assert main(["risk", str(PAPER_CASE), *limit, "--out", str(tmp_path / "risk")]) == 0
    capsys.readouterr()
    assert main(["plan", str(PAPER_CASE), *limit, "--out", str(tmp_path / "plan")]) == 2
    assert capsys.readouterr().err == ("error: a grid of 54,000 cells needs about 0.3 GB, more than the limit of 0.2 GB "
                                       "(grid.cell / grid.extent): use larger cells or a smaller extent, or raise "
                                       "grid.memory_limit_gb\n")
    assert not (tmp_path / "plan").exists()


@pytest.mark.parametrize(("override", "fragment"), [
    ("grid.cell=[true,true,true]", "must be a number"),
    ("city.seed=true", "valid integer"),
    ('city.seed="7"', "valid integer"),
    ("city.seed=-1", "greater than or equal to 0"),
    ("schedule.plan_seed=-3", "greater than or equal to 0"),
    ("grid.extent=[1e6,1e6,360]", "more than the limit"),  # 4.8e9 cells: 224 GB
    ("grid.memory_limit_gb=0.005", "more than the limit of 0.0 GB"),
])
def test_strict_types_and_memory_guard(tmp_path, capsys, override, fragment):
    """Bad values are one `error:` line and exit 2 before anything is allocated or written."""
    assert main(["risk", str(PAPER_CASE), "--set", override, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and fragment in err
    assert not (tmp_path / "out").exists()
