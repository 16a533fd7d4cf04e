"""Numbers in saved folders read back through the Python API (issue 22, item 6): ``ua.load_risk`` and
``ua.load_schedule`` hold every number to what it can mean, as the CLI's readers and the verifier do,
so a crafted or damaged folder is one ``InputFileError`` line, never a field or schedule that
carries inf, NaN or a 400-digit integer into the next stage. On 31937a6 every case below loaded
silently except the shape mismatch, which ended in a raw numpy ``IndexError`` later, in planning."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from conftest import PAPER_CASE

import uamopt as ua
from uamopt.io import save_risk


@pytest.fixture(scope="module")
def risk_folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("risk")
    save_risk(ua.compute_risk(ua.load_scenario(PAPER_CASE, ["grid.cell=[100,100,60]"])), folder)
    return folder


def _copy_risk(src, dst, array=None, edit=None, summary=None):
    dst.mkdir()
    a = dict(np.load(src / "risk.npz"))
    if array is not None:
        a[array] = edit(a[array])
    np.savez(dst / "risk.npz", **a)
    doc = json.loads((src / "summary.json").read_text(encoding="utf-8"))
    if summary is not None:
        summary(doc)
    (dst / "summary.json").write_text(json.dumps(doc), encoding="utf-8")
    return dst


def _with(a, index, value):
    a = a.astype(float).copy()
    a[index] = value
    return a


RISK_CASES = [
    ("risk-inf", "risk", lambda a: _with(a, (0, 0, 0), math.inf), None, "risk holds inf"),
    ("population-nan", "population_density", lambda a: _with(a, (1, 1), math.nan), None, "population_density holds inf or NaN"),
    ("road-negative", "road_length", lambda a: _with(a, (2, 2), -5.0), None, "road_length holds negative"),
    ("unsafe-short", "unsafe", lambda a: a[:-1], None, "unsafe has shape"),
    ("no-fly-3d", "no_fly", lambda a: np.stack([a, a], axis=-1), None, "no_fly has shape"),
    ("cell-zero", "cell", lambda a: np.array([0.0, 100.0, 60.0]), None, "cell"),
    ("threshold-huge", None, None, lambda d: d["risk_per_flight_hour"].update(threshold_R0=10**400), "threshold_R0"),
    ("threshold-zero", None, None, lambda d: d["risk_per_flight_hour"].update(threshold_R0=0), "threshold_R0"),
    ("band-inverted", None, None, lambda d: d.update(band_m=[300.0, 60.0]), "band_m is empty"),
    ("band-words", None, None, lambda d: d.update(band_m=["low", "high"]), "band_m"),
    ("mass-nan", None, None, lambda d: d["constants"].update(mass_kg="NaN"), "constants.mass_kg"),
    ("constants-missing", None, None, lambda d: d.pop("constants"), "lacks"),
]


@pytest.mark.parametrize(("name", "array", "edit", "summary", "fragment"), RISK_CASES, ids=[c[0] for c in RISK_CASES])
def test_a_damaged_risk_folder_is_one_line(risk_folder, tmp_path, name, array, edit, summary, fragment):
    folder = _copy_risk(risk_folder, tmp_path / name, array, edit, summary)
    with pytest.raises(ua.InputFileError) as info:
        ua.load_risk(folder)
    line = info.value.line()
    assert fragment in line and "\n" not in line and str(folder) in line, line


def test_the_undamaged_copy_loads(risk_folder, tmp_path):
    """The copy itself is not what the loader refuses (the cases above each change one thing)."""
    field = ua.load_risk(_copy_risk(risk_folder, tmp_path / "same"))
    assert field.grid.cell == (100.0, 100.0, 60.0) and np.isfinite(field.risk[~field.obstacle]).all()


@pytest.fixture(scope="module")
def schedule_folder(tmp_path_factory):
    from uamopt.grid import AirspaceGrid
    from uamopt.schedule import straight_network
    from uamopt.schedule.model import write_schedule

    scenario = ua.load_scenario(PAPER_CASE, ["schedule.flights=20"])
    network = dict(straight_network(scenario, AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent)))
    problem = ua.build_problem(ua.generate_flights(scenario, network, seed=0), scenario)
    folder = tmp_path_factory.mktemp("schedule")
    write_schedule(folder, problem, ua.solve(problem, "greedy"))
    return folder


def _copy_schedule(src, dst, row=None, summary=None):
    import csv

    dst.mkdir()
    with open(src / "schedule.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    if row is not None:
        row(rows[3])
    with open(dst / "schedule.csv", "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    doc = json.loads((src / "summary.json").read_text(encoding="utf-8"))
    if summary is not None:
        summary(doc)
    (dst / "summary.json").write_text(json.dumps(doc), encoding="utf-8")
    (dst / "flights.json").write_bytes((src / "flights.json").read_bytes())
    return dst


SCHEDULE_CASES = [
    ("delay-nan", lambda r: r.update(delay_s="nan"), None, "delay_s"),
    ("delay-inf", lambda r: r.update(delay_s="inf"), None, "delay_s"),
    ("delay-negative", lambda r: r.update(delay_s="-30"), None, "delay_s"),
    ("delay-400-digits", lambda r: r.update(delay_s="1" + "0" * 400), None, "delay_s"),
    ("objective-400-digits", None, lambda d: d.update(objective=10**400), "objective"),
    ("bound-word", None, lambda d: d.update(bound="low"), "bound"),
    ("seconds-negative", None, lambda d: d.update(solve_seconds=-1.0), "solve_seconds"),
    ("aircraft-fraction", None, lambda d: d.update(aircraft=2.5), "aircraft"),
    ("seed-negative", None, lambda d: d.update(seed=-3), "seed"),
]


@pytest.mark.parametrize(("name", "row", "summary", "fragment"), SCHEDULE_CASES, ids=[c[0] for c in SCHEDULE_CASES])
def test_a_damaged_schedule_folder_is_one_line(schedule_folder, tmp_path, name, row, summary, fragment):
    folder = _copy_schedule(schedule_folder, tmp_path / name, row, summary)
    with pytest.raises(ua.InputFileError) as info:
        ua.load_schedule(folder)
    line = info.value.line()
    assert fragment in line and "\n" not in line, line


def test_the_undamaged_schedule_copy_loads(schedule_folder, tmp_path):
    """What loads is what the files say, read here with the csv and json modules."""
    import csv

    folder = _copy_schedule(schedule_folder, tmp_path / "same")
    s = ua.load_schedule(folder)
    with open(folder / "schedule.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
    assert s.solver == summary["solver"] == "greedy" and len(rows) == 20
    assert s.operated.tolist() == [r["operated"] == "1" for r in rows]
    assert s.delay_s.tolist() == pytest.approx([float(r["delay_s"]) for r in rows], abs=1e-9)
    assert s.objective == pytest.approx(summary["objective"], rel=1e-12)


def test_a_sweep_file_with_a_5000_digit_integer_is_one_line(tmp_path, capsys):
    """Was: Python's int-string limit ValueError ('Exceeds the limit (4300 digits)') as a traceback."""
    from uamopt.cli import main

    sweep = tmp_path / "s.toml"
    sweep.write_text(f'base = "{PAPER_CASE.as_posix()}"\nname = "x"\nsolvers = ["greedy"]\nseeds = [{"9" * 5000}]\n',
                     encoding="utf-8")
    out = tmp_path / "out"
    assert main(["sweep", str(sweep), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and "4300 digits" in err[0] and len(err[0]) < 400, err
    assert not out.exists()
