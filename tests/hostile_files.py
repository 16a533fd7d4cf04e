"""The hostile inputs of tests/test_hostile.py, written into one folder: scenarios, network and
flights files, schedule folders, solver profiles, rasters and GeoJSON layers.

Everything is derived from three good files made by hand (no track planning, so the folder is
ready in about a second): ``net.json``, straight routes between the paper case's vertiports at
290 m and 330 m, above its tallest tower (239 m); ``flights.json``, four self-contained flights of
two aircraft at 250 × 250 × 60 m cells; and ``good/``, their greedy schedule.
"""

from __future__ import annotations

import copy
import json
import shutil
from pathlib import Path

import numpy as np
from conftest import PAPER_CASE

from uamopt.cli import main

TINY = ("--set", "grid.cell=[250,250,60]")  # 10 x 18 x 6 cells: every command is fast
PORTS = {"V1": (300.0, 300.0), "V2": (300.0, 4220.0), "V3": (2220.0, 300.0), "V4": (2220.0, 4220.0), "V5": (1260.0, 2260.0)}
TOWER = (1075.0, 1625.0)  # the synthetic city's tallest column (239 m) at 50 m cells
UTM = (400_000.0, 6_600_000.0)  # (left, bottom) of the test rasters, EPSG:32633, m


def _json(path: Path, doc) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(doc), encoding="utf-8")


def good_network() -> dict:
    names = list(PORTS)
    routes = {}
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            for o, d, z in ((a, b, 290.0), (b, a, 330.0)):
                routes[f"{o}-{d}"] = {"origin": o, "destination": d, "waypoints": [[*PORTS[o], z], [*PORTS[d], z]]}
    return {"cell": [250.0, 250.0, 60.0], "routes": routes}


def good_flights() -> dict:
    def flight(fid, aircraft, route, departure, z):
        o, d = route.split("-")
        return {"id": fid, "aircraft": aircraft, "route": route, "origin": o, "destination": d, "speed_mps": 25.0,
                "planned_departure_s": departure, "max_delay_s": 120.0,
                "waypoints": [[*PORTS[o], z], [*PORTS[d], z]]}

    return {"cell": [250.0, 250.0, 60.0], "conflict_radius": 1, "flights": [
        flight("F1", "A", "V1-V4", 0.0, 290.0), flight("F2", "A", "V4-V1", 600.0, 330.0),
        flight("F3", "B", "V3-V2", 0.0, 290.0), flight("F4", "B", "V2-V3", 600.0, 330.0)]}


def _tamper(doc: dict, edit) -> dict:
    doc = copy.deepcopy(doc)
    edit(doc)
    return doc


def _raster(path: Path, data: np.ndarray, crs: str = "EPSG:32633", nodata=-9999.0, **options) -> None:
    import rasterio
    from affine import Affine

    transform = Affine(1.0, 0.0, UTM[0], 0.0, -1.0, UTM[1] + data.shape[0])
    with rasterio.open(path, "w", driver="GTiff", height=data.shape[0], width=data.shape[1], count=1,
                       dtype=data.dtype, crs=crs, transform=transform, nodata=nodata, **options) as dst:
        dst.write(data, 1)


def _polygon(points, crs: str | None = None) -> dict:
    doc = {"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {},
                                                      "geometry": {"type": "Polygon", "coordinates": [points]}}]}
    if crs:
        doc["crs"] = {"type": "name", "properties": {"name": crs}}
    return doc


def write_rasters(d: Path) -> None:
    """DSM cities of 200 x 300 m (1 m pixels, ground 10 m, one 40 m block) and their scenarios."""
    import rasterio

    base = np.full((300, 200), 10.0, dtype="float32")
    base[60:80, 20:60] = 50.0
    variants = {"ok": base}
    for name, value in (("inf", np.inf), ("neginf", -np.inf)):
        variants[name] = base.copy()
        variants[name][100:110, 100:110] = value
    variants["nodata"] = np.full((300, 200), -9999.0, dtype="float32")
    for name, data in variants.items():
        _raster(d / f"{name}.tif", data)
    _raster(d / "lonlat.tif", base, crs="EPSG:4326")
    _raster(d / "nocrs.tif", base, crs=None)
    (d / "garbage.tif").write_text("not a GeoTIFF")
    # 60,000 x 60,000 pixels declared, one 512 x 512 tile written: about 110 KB on disk
    with rasterio.open(d / "huge.tif", "w", driver="GTiff", height=60000, width=60000, count=1, dtype="float32",
                       crs="EPSG:32633", transform=rasterio.Affine(1, 0, UTM[0], 0, -1, UTM[1] + 60000), nodata=-9999.0,
                       tiled=True, blockxsize=512, blockysize=512, sparse_ok=True, compress="deflate") as dst:
        dst.write(np.full((512, 512), 10.0, dtype="float32"), 1, window=rasterio.windows.Window(0, 60000 - 512, 512, 512))
    square = [(101, 261), (139, 261), (139, 299), (101, 299), (101, 261)]
    _json(d / "nofly_far.geojson", _polygon([[15.0, 59.5], [15.001, 59.5], [15.001, 59.501], [15.0, 59.501], [15.0, 59.5]]))
    _json(d / "nofly_badcrs.geojson", _polygon([[UTM[0] + x, UTM[1] + y] for x, y in square], "EPSG:99999999"))
    _json(d / "nofly_elsewhere.geojson", _polygon([[UTM[0] + 1e5 + x, UTM[1] + y] for x, y in square]))
    (d / "nofly_bad.geojson").write_text('{"type": "FeatureCollection", "features": [', encoding="utf-8")
    roads = {"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {}, "geometry": {
        "type": "LineString", "coordinates": [[UTM[0] + 5e4, UTM[1]], [UTM[0] + 5e4 + 100, UTM[1] + 100]]}}]}
    _json(d / "roads_elsewhere.geojson", roads)
    for name, extra in {"ok": "", "inf": "", "neginf": "", "nodata": "", "lonlat": "", "nocrs": "", "garbage": "",
                        "missing": "", "huge": "", "nofly_far": 'no_fly = "nofly_far.geojson"\n',
                        "nofly_badcrs": 'no_fly = "nofly_badcrs.geojson"\n',
                        "nofly_elsewhere": 'no_fly = "nofly_elsewhere.geojson"\n',
                        "nofly_bad": 'no_fly = "nofly_bad.geojson"\n', "roads_elsewhere": 'roads = "roads_elsewhere.geojson"\n',
                        "shelter_missing": 'shelter = "nowhere.tif"\n'}.items():
        raster = {"nofly_far": "ok", "nofly_badcrs": "ok", "nofly_elsewhere": "ok", "nofly_bad": "ok",
                  "roads_elsewhere": "ok", "shelter_missing": "ok"}.get(name, name)
        (d / f"dsm_{name}.toml").write_text(f'name = "{name}"\n[grid]\ncell = [20.0, 20.0, 10.0]\n'
                                            f'[city]\nsource = "dsm"\ndsm = "{raster}.tif"\n{extra}', encoding="utf-8")


def write_scenarios(d: Path) -> None:
    paper = PAPER_CASE.read_text(encoding="utf-8")
    (d / "malformed.toml").write_text("[grid\ncell = [50, 50, 30]\n", encoding="utf-8")
    (d / "latin1.toml").write_bytes(b'name = "caf\xe9"\n')
    (d / "deep.toml").write_text("a = " + "[" * 100_000 + "]" * 100_000 + "\n", encoding="utf-8")
    (d / "unknown_key.toml").write_text("whatever = 1\n" + paper, encoding="utf-8")
    (d / "unknown_grid_key.toml").write_text(paper.replace("[grid]", "[grid]\ncells = [1, 2, 3]"), encoding="utf-8")
    (d / "grid_number.toml").write_text('name = "x"\ngrid = 5\n', encoding="utf-8")
    (d / "seed_true.toml").write_text(paper.replace("seed = 7", "seed = true"), encoding="utf-8")
    (d / "seed_string.toml").write_text(paper.replace("seed = 7", 'seed = "7"'), encoding="utf-8")
    (d / "no_ports.toml").write_text(paper.split("[network]")[0] + "[network]\nvertiports = []\n", encoding="utf-8")
    (d / "osm_nopbf.toml").write_text('[city]\nsource = "osm"\n', encoding="utf-8")
    (d / "osm_missing.toml").write_text('[city]\nsource = "osm"\npbf = "nowhere.pbf"\n', encoding="utf-8")
    (d / "dsm_nofile.toml").write_text('[city]\nsource = "dsm"\n', encoding="utf-8")
    (d / "a_folder.toml").mkdir()


def write_profiles(d: Path) -> None:
    profiles = {"unknown_key": 'solver = "greedy"\nfoo = 1\n', "no_solver": "time_limit_s = 5\n",
                "bad_solver": 'solver = "magic"\n', "negative_limit": 'solver = "greedy"\ntime_limit_s = -1\n',
                "nan_limit": 'solver = "greedy"\ntime_limit_s = nan\n', "no_threads": 'solver = "greedy"\nthreads = 0\n',
                "malformed": "solver = [\n", "seed_word": 'solver = "greedy"\nseed = "x"\n',
                "options_number": 'solver = "greedy"\noptions = 5\n'}
    profiles |= {"seed_negative": 'solver = "greedy"\nseed = -1\n', "seed_bool": 'solver = "greedy"\nseed = true\n',
                 "deep": "a = " + "[" * 100_000 + "]" * 100_000 + "\n"}
    for name, text in profiles.items():
        (d / f"profile_{name}.toml").write_text(text, encoding="utf-8")
    (d / "profile_latin1.toml").write_bytes(b'solver = "gr\xe9edy"\n')


def write_networks(d: Path) -> None:
    net = good_network()
    _json(d / "net.json", net)

    def route(name, value):
        return lambda doc: doc["routes"][name].__setitem__("waypoints", value)

    edits = {
        "one_point": route("V1-V2", [[300, 300, 290]]),
        "zero_length": route("V1-V2", [[300, 300, 290], [300, 300, 290]]),
        "nan": route("V1-V2", [[300, 300, 290], [float("nan"), 4220, 290]]),
        "words": route("V1-V2", "north"),
        "far": route("V1-V2", [[300, 300, 290], [100300, 4220, 290]]),
        "below": route("V1-V2", [[300, 300, -10], [300, 4220, -10]]),
        "ground": route("V1-V2", [[300, 300, 0], [300, 4220, 0]]),
        "tower": route("V1-V2", [[TOWER[0] - 200, TOWER[1], 120], [TOWER[0] + 200, TOWER[1], 120]]),
        "no_routes": lambda doc: doc.__setitem__("routes", {}),
        "routes_list": lambda doc: doc.__setitem__("routes", []),
        "bad_cell": lambda doc: doc.__setitem__("cell", [-1, 50, 30]),
        "tiny_cell": lambda doc: doc.__setitem__("cell", [0.01, 0.01, 0.01]),
        "missing_route": lambda doc: doc["routes"].pop("V1-V2"),
    }
    for name, edit in edits.items():
        _json(d / f"net_{name}.json", _tamper(net, edit))
    (d / "net_list.json").write_text("[1, 2]", encoding="utf-8")
    (d / "net_truncated.json").write_text(json.dumps(net)[:200], encoding="utf-8")
    (d / "net_deep.json").write_text("[" * 100_000 + "]" * 100_000, encoding="utf-8")
    (d / "net_latin1.json").write_bytes(b'{"routes": "caf\xe9"}')


def write_flights(d: Path) -> None:
    good = good_flights()
    _json(d / "flights.json", good)

    def first(key, value):
        return lambda doc: doc["flights"][0].__setitem__(key, value)

    edits = {
        "no_list": lambda doc: doc.pop("flights"),
        "empty": lambda doc: doc.__setitem__("flights", []),
        "not_object": lambda doc: doc["flights"].__setitem__(0, 7),
        "no_speed": lambda doc: doc["flights"][0].pop("speed_mps"),
        "speed_zero": first("speed_mps", 0),
        "speed_word": first("speed_mps", "fast"),
        "speed_fast": first("speed_mps", 1000.0),
        "departure_late": first("planned_departure_s", 2e7),
        "service_long": lambda doc: doc.__setitem__("service_end_s", 1e9),
        "departure_nan": first("planned_departure_s", float("nan")),
        "negative_delay": first("max_delay_s", -5),
        "one_point": first("waypoints", [[300, 300, 290]]),
        "tower": first("waypoints", [[TOWER[0] - 200, TOWER[1], 120], [TOWER[0] + 200, TOWER[1], 120]]),
        "ground": first("waypoints", [[300, 300, 0], [2220, 4220, 0]]),
        "off_grid": first("waypoints", [[300, 300, 290], [1e6, 4220, 290]]),
        "tiny_cell": lambda doc: doc.__setitem__("cell", [0.01, 0.01, 0.01]),
        "radius_11": lambda doc: doc.__setitem__("conflict_radius", 11),
        "radius_true": lambda doc: doc.__setitem__("conflict_radius", True),
        "duplicate_id": lambda doc: doc["flights"][1].__setitem__("id", "F1"),
        "overlap": lambda doc: doc["flights"][1].__setitem__("planned_departure_s", 100.0),
        "before_start": first("planned_departure_s", -50.0),
        "after_end": first("planned_departure_s", 3500.0),
        "unknown_route": lambda doc: doc["flights"][0].pop("waypoints"),
    }
    for name, edit in edits.items():
        _json(d / f"flights_{name}.json", _tamper(good, edit))
    (d / "flights_truncated.json").write_text(json.dumps(good)[:100], encoding="utf-8")
    (d / "flights_deep.json").write_text("[" * 100_000 + "]" * 100_000, encoding="utf-8")


def write_folders(d: Path) -> None:
    """``good/`` (greedy on flights.json) and tampered copies of it for ``uamopt verify``."""
    good = d / "good"
    assert main(["schedule", str(PAPER_CASE), *TINY, "--solver", "greedy", "--flights", str(d / "flights.json"),
                 "--out", str(good)]) == 0

    def folder(name: str, edit_flights=None, edit_summary=None, files: dict | None = None) -> None:
        target = d / f"sched_{name}"
        shutil.copytree(good, target)
        for file, edit in (("flights.json", edit_flights), ("summary.json", edit_summary)):
            if edit is not None:
                _json(target / file, _tamper(json.loads((target / file).read_text()), edit))
        for file, text in (files or {}).items():
            (target / file).write_text(text, encoding="utf-8") if text is not None else (target / file).unlink()

    folder("no_flights", files={"flights.json": None})
    folder("no_schedule", files={"schedule.csv": None})
    folder("columns", files={"schedule.csv": "flight,operated\nF1,1\n"})
    folder("operated_maybe", files={"schedule.csv": (good / "schedule.csv").read_text().replace(",1,", ",maybe,", 1)})
    folder("tiny_cell", lambda doc: doc.__setitem__("cell", [0.001, 0.001, 0.001]))
    folder("duplicate_id", lambda doc: doc["flights"][1].__setitem__("id", "F1"))
    folder("radius_words", lambda doc: doc.__setitem__("conflict_radius", "one"))
    folder("summary_list", files={"summary.json": "[1, 2, 3]"})
    folder("summary_deep", files={"summary.json": "[" * 100_000 + "]" * 100_000})
    folder("weights_word", edit_summary=lambda doc: doc.__setitem__("weights", "ab"))
    folder("weights_one", edit_summary=lambda doc: doc.__setitem__("weights", [1]))
    folder("extent_word", edit_summary=lambda doc: doc.__setitem__("extent_m", [1, "a", 3]))
    folder("objective_inf", edit_summary=lambda doc: doc.__setitem__("objective", float("inf")))
    folder("off_grid", lambda doc: doc["flights"][0].__setitem__("waypoints", [[300, 300, 290], [2220, 9e5, 290]]))
    folder("sunk", lambda doc: doc["flights"][0].__setitem__("waypoints", [[300, 300, -5], [2220, 4220, -5]]))
    write_npz_bomb(d / "risk_bomb" / "risk.npz")
    (d / "risk_bomb" / "summary.json").write_text("{}", encoding="utf-8")


def write_npz_bomb(path: Path) -> None:
    """A 700-byte risk.npz whose ``unsafe`` member declares a 10⁵ × 10⁵ × 100 array (931 GiB)."""
    import io
    import zipfile

    from numpy.lib import format as npy

    path.parent.mkdir(parents=True, exist_ok=True)
    header = io.BytesIO()
    npy.write_array_header_1_0(header, {"descr": "|b1", "fortran_order": False, "shape": (100_000, 100_000, 100)})
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("unsafe.npy", header.getvalue() + bytes(1000))
        for name in ("obstacle", "z", "cell"):
            small = io.BytesIO()
            np.save(small, np.zeros(3))
            archive.writestr(f"{name}.npy", small.getvalue())


BIG = 10**400  # a JSON or TOML integer of 401 digits: float() of it overflows
HUGE = "9" * 5000  # more digits than Python's int-string limit (4300): a ValueError while parsing


def _huge(text: str, value: str) -> str:
    """``text`` with the first occurrence of ``value`` replaced by a 5000-digit integer."""
    assert value in text, value
    return text.replace(value, HUGE, 1)


def write_numbers(d: Path) -> None:
    """Numbers out of every range (issue 22, item 6): 400-digit and 5000-digit integers, NaN, inf,
    1e300 and 1e-300 in flights and network files, schedule folders, solver profiles and scenarios;
    a symlink loop and a name holding a newline as --out."""
    good = good_flights()

    def first(key, value):
        return lambda doc: doc["flights"][0].__setitem__(key, value)

    for name, edit in {"departure_big": first("planned_departure_s", BIG), "speed_big": first("speed_mps", BIG),
                       "delay_big": first("max_delay_s", BIG), "cell_big": lambda doc: doc.__setitem__("cell", [BIG, 250, 60]),
                       "waypoint_big": first("waypoints", [[300, 300, BIG], [2220, 4220, 290]]),
                       "id_newline": lambda doc: doc["flights"][0].update(id="F1\nerror: forged", speed_mps=0)}.items():
        _json(d / f"flights_{name}.json", _tamper(good, edit))
    (d / "flights_departure_huge.json").write_text(_huge(json.dumps(good), "0.0"), encoding="utf-8")
    net = good_network()
    for name, edit in {"cell_big": lambda doc: doc.__setitem__("cell", [BIG, 250, 60]),
                       "waypoint_big": lambda doc: doc["routes"]["V1-V2"].__setitem__("waypoints",
                                                                                    [[300, 300, BIG], [300, 4220, 290]]),
                       "length_big": lambda doc: doc["routes"]["V1-V2"].__setitem__("length_m", BIG),
                       "layer_inf": lambda doc: doc["routes"]["V1-V2"].__setitem__("layer_k", float("inf"))}.items():
        _json(d / f"net_{name}.json", _tamper(net, edit))
    # schedule folders read by export
    for name, file, edit in (("departure_big", "flights.json",
                              lambda doc: doc["flights"][0].__setitem__("planned_departure_s", BIG)),
                             ("origin_big", "summary.json", lambda doc: doc["frame"].__setitem__("origin", [BIG, 0]))):
        target = d / f"sched_{name}"
        shutil.copytree(d / "good", target)
        _json(target / file, _tamper(json.loads((target / file).read_text()), edit))
    target = d / "sched_summary_huge"
    shutil.copytree(d / "good", target)
    (target / "summary.json").write_text(_huge((target / "summary.json").read_text(), "0.0"), encoding="utf-8")
    # solver profiles
    profiles = {"limit_big": f'solver = "greedy"\ntime_limit_s = {BIG}\n',
                "limit_huge": f'solver = "greedy"\ntime_limit_s = {HUGE}\n',
                "highs_gap_nan": 'solver = "highs"\ntime_limit_s = 2\n[options]\nmip_rel_gap = nan\n',
                "highs_gap_inf": 'solver = "highs"\ntime_limit_s = 2\n[options]\nmip_rel_gap = inf\n',
                "ga_population_inf": 'solver = "ga"\n[options]\npopulation = inf\n',
                "ga_population_nan": 'solver = "ga"\n[options]\npopulation = nan\n',
                "ga_population_1e8": 'solver = "ga"\n[options]\npopulation = 100000000\n',
                "ga_t0_big": f'solver = "ga"\n[options]\nt0 = {BIG}\n',
                "soa_points_big": f'solver = "soa"\n[options]\nmulti_points = {BIG}\n',
                "greedy_step_big": f'solver = "greedy"\n[options]\nstep_s = {BIG}\n',
                "timeindexed_step_tiny": 'solver = "timeindexed"\n[options]\nstep_s = 1e-300\n',
                "timeindexed_gap_big": f'solver = "timeindexed"\n[options]\nmip_rel_gap = {BIG}\n',
                "cpsat_unit_tiny": 'solver = "cpsat"\n[options]\ntime_unit_s = 1e-300\n'}
    for name, text in profiles.items():
        (d / f"profile_{name}.toml").write_text(text, encoding="utf-8")
    # scenarios
    paper = PAPER_CASE.read_text(encoding="utf-8")
    (d / "seed_big.toml").write_text(paper.replace("seed = 7", f"seed = {BIG}"), encoding="utf-8")
    (d / "seed_huge.toml").write_text(paper.replace("seed = 7", f"seed = {HUGE}"), encoding="utf-8")
    # GeoJSON layers of the DSM city (write_rasters): a 400-digit and a NaN coordinate
    square = [[UTM[0] + x, UTM[1] + y] for x, y in [(101, 261), (139, 261), (139, 299), (101, 299), (101, 261)]]
    for name, value in (("big", BIG), ("nan", float("nan"))):
        _json(d / f"nofly_{name}.geojson", _polygon([square[0], [value, square[1][1]], *square[2:]]))
        (d / f"dsm_nofly_{name}.toml").write_text(f'name = "nofly_{name}"\n[grid]\ncell = [20.0, 20.0, 10.0]\n[city]\n'
                                                  f'source = "dsm"\ndsm = "ok.tif"\nno_fly = "nofly_{name}.geojson"\n',
                                                  encoding="utf-8")
    # output paths: a symlink loop, a file whose name holds a newline
    (d / "out_loop").symlink_to(d / "out_loop")
    (d / "out_file\nerror: forged").write_text("a file, not a folder", encoding="utf-8")


def write_all(d: Path) -> Path:
    d.mkdir(parents=True, exist_ok=True)
    for write in (write_scenarios, write_profiles, write_networks, write_flights, write_rasters, write_folders,
                  write_numbers):
        write(d)
    return d
