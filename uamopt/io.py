"""Loaders: every folder a command writes reads back into the objects that wrote it.

``load_risk`` (risk.npz + summary.json → RiskField), ``load_tracks`` (tracks.json → TrackPlan),
``load_network`` (network.json → RouteNetwork), ``load_flights`` (flights.json → FlightSet) and
``load_schedule`` (schedule.csv + summary.json → Schedule). Each takes the folder or the file.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from uamopt.checks import expect_path
from uamopt.errors import InputFileError, UamoptError

if TYPE_CHECKING:
    from uamopt.planning.network import RouteNetwork
    from uamopt.planning.tracks import TrackPlan
    from uamopt.risk import RiskField
    from uamopt.schedule.flights import FlightSet
    from uamopt.schedule.model import Schedule


def _file(path: str | Path, name: str) -> Path:
    path = Path(path)
    path = path / name if path.is_dir() else path
    if not path.is_file():
        raise InputFileError(f"{name} not found: {path}", str(path), f"give a folder written by uamopt, or its {name}")
    return path


def read_npz(path: Path, fix: str, names=None, limit_gb: float | None = None) -> dict[str, np.ndarray]:
    """The arrays ``names`` (default: all) of the .npz file ``path``, refused (``InputFileError``,
    ``fix`` in the message) before anything is decompressed when the sizes their .npy headers
    declare add up to more than ``limit_gb`` (default: 80 % of this machine's memory, as
    ``grid.memory_limit_gb``): a few megabytes of compressed zeros can declare tens of gigabytes.
    A missing name is left out (the caller names what it lacks)."""
    import zipfile

    from numpy.lib import format as npy

    from uamopt.grid.grid import memory_limit_bytes

    where = str(path)
    try:
        declared = 0
        with zipfile.ZipFile(path) as archive:
            for info in archive.infolist():
                if names is not None and info.filename.removesuffix(".npy") not in names:
                    continue
                with archive.open(info) as member:
                    version = npy.read_magic(member)
                    if version not in ((1, 0), (2, 0)):
                        raise ValueError(f"member {info.filename} has .npy format version {version}")
                    read_header = npy.read_array_header_1_0 if version == (1, 0) else npy.read_array_header_2_0
                    shape, _, dtype = read_header(member)
                declared += int(np.prod(shape, dtype=np.float64) * dtype.itemsize)
        limit = memory_limit_bytes(limit_gb)
        if declared > limit:
            raise InputFileError(f"{path.name} declares {declared / 2**30:,.1f} GiB of arrays, more than the "
                                 f"{limit / 2**30:,.1f} GiB allowed", where, fix)
        with np.load(path) as data:
            return {name: data[name] for name in data.files if names is None or name in names}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise InputFileError(f"cannot read {path.name}: {exc}", where, fix) from None


def _json(path: Path) -> dict:
    try:
        doc = json.loads(path.read_text(encoding="utf-8-sig"))
    except (ValueError, UnicodeDecodeError, RecursionError) as exc:
        raise InputFileError(f"malformed JSON: {exc}", str(path), "regenerate the folder with uamopt") from None
    except OSError as exc:
        raise InputFileError(f"cannot read {path.name}: {exc.strerror or exc}", str(path),
                             "check that the file is readable") from None
    if not isinstance(doc, dict):
        raise InputFileError("the file does not hold a JSON object", str(path), "regenerate the folder with uamopt")
    return doc


def load_risk(path: str | Path) -> RiskField:
    """The :class:`~uamopt.risk.RiskField` of a risk folder (``risk.npz`` and ``summary.json``)."""
    expect_path(path, "path", "load_risk")

    from uamopt.city.layers import CityLayers
    from uamopt.grid import AirspaceGrid
    from uamopt.risk import RiskConstants, RiskField

    npz = _file(path, "risk.npz")
    summary = _json(_file(npz.parent, "summary.json"))
    a = read_npz(npz, "regenerate it with `uamopt risk`")
    _check_risk_numbers(a, summary, npz.parent)
    try:
        grid = AirspaceGrid(cell=tuple(float(c) for c in a["cell"]), shape=a["risk"].shape)  # type: ignore[arg-type]
        city = CityLayers(
            surface_height=a["surface_height"], building_height=a["building_height"], road_length=a["road_length"],
            population_density=a["population_density"], shelter=a["shelter"], no_fly=a["no_fly"],
            open_space=a.get("open_space", np.zeros_like(a["no_fly"])), source=summary.get("source", ""),
            attribution=summary.get("attribution", ""), crs=summary.get("crs", ""),
            origin=tuple(summary.get("origin", (0.0, 0.0))), notes=summary.get("city", {}))
        rk = summary["risk_per_flight_hour"]
        c = summary["constants"]
        constants = RiskConstants(c["mass_kg"], c["crash_area_m2"], c["drag_k_per_m"], c["terminal_speed_mps"],
                                  c["mean_relative_speed_mps"], c["vehicle_collision_probability"])
        return RiskField(grid=grid, city=city, terms={name: a[name] for name in ("risk", "risk_P", "risk_V", "risk_U")},
                         unsafe=a["unsafe"], obstacle=a["obstacle"],
                         band=tuple(summary["band_m"]), constants=constants, threshold=float(rk["threshold_R0"]),  # type: ignore[arg-type]
                         seconds=float(summary.get("seconds", {}).get("risk", 0.0)),
                         meta={"scenario": summary.get("scenario", ""), "seconds": summary.get("seconds", {}),
                               "inputs": summary.get("inputs") if isinstance(summary.get("inputs"), dict) else {}})
    except (KeyError, ValueError, TypeError) as exc:
        raise InputFileError(f"incomplete risk folder: {exc}", str(npz.parent), "regenerate it with `uamopt risk`") from None


def load_tracks(path: str | Path) -> TrackPlan:
    """The :class:`~uamopt.planning.tracks.TrackPlan` of a plan folder (``tracks.json``)."""
    expect_path(path, "path", "load_tracks")

    from uamopt.planning.tracks import TrackPlan

    file = _file(path, "tracks.json")
    try:
        return TrackPlan.from_dict(_json(file))
    except (KeyError, ValueError, TypeError) as exc:
        raise InputFileError(f"malformed tracks file: {exc}", str(file), "regenerate it with `uamopt plan`") from None


def load_network(path: str | Path) -> RouteNetwork:
    """The :class:`~uamopt.planning.network.RouteNetwork` of a network folder (``network.json``)."""
    expect_path(path, "path", "load_network")

    from uamopt.planning.network import load_network as load

    return load(path)  # a folder or the file; "network file not found" names what is missing


def load_flights(path: str | Path, scenario=None, grid=None, network=None) -> FlightSet:
    """The :class:`~uamopt.schedule.flights.FlightSet` of ``flights.json`` (validated): ``scenario``
    (a Scenario) fills in what the file does not give, ``grid`` (an AirspaceGrid) holds every waypoint
    inside it, ``network`` (a RouteNetwork or route name -> waypoints) gives the tracks of flights
    without waypoints (:func:`uamopt.schedule.flights_file.load_flights`)."""
    from collections.abc import Mapping

    from uamopt.checks import expect
    from uamopt.grid import AirspaceGrid
    from uamopt.scenario import Scenario
    from uamopt.schedule.flights_file import load_flights as load

    expect_path(path, "path", "load_flights")
    if scenario is not None:
        expect(scenario, Scenario, "scenario", "load_flights")
    if grid is not None:
        expect(grid, AirspaceGrid, "grid", "load_flights")
    if callable(getattr(network, "waypoints", None)):  # a RouteNetwork
        network = network.waypoints()
    if network is not None and not isinstance(network, Mapping):
        raise TypeError("load_flights(): network must be a RouteNetwork or a mapping route name -> (n, 3) waypoints, "
                        f"got {type(network).__name__}")
    return load(_file(path, "flights.json"), scenario, grid, network)


#: the arrays of risk.npz that are one value per cell, and the ones that are one value per column
_RISK_3D = ("risk", "risk_P", "risk_V", "risk_U", "unsafe", "obstacle")
_RISK_2D = ("surface_height", "building_height", "road_length", "population_density", "shelter", "no_fly")


def _check_risk_numbers(a: dict, summary: dict, folder: Path) -> None:
    """The numbers of a risk folder within what they can mean: the cell, the arrays' shapes (one
    grid), the risk terms finite or NaN (an obstacle) and ≥ 0, the threshold, band and constants."""
    from uamopt.bounds import MAX_COORD_M, Range, check_cell, check_number

    where, fix = str(folder), "regenerate it with `uamopt risk`"
    missing = [name for name in ("cell", *_RISK_3D, *_RISK_2D) if name not in a]
    if missing:
        raise InputFileError(f"risk.npz lacks the arrays {', '.join(missing)}", where, fix)
    check_cell(np.asarray(a["cell"]).tolist(), where, fix)
    shape = a["risk"].shape
    if len(shape) != 3 or 0 in shape:
        raise InputFileError(f"risk.npz's risk is not a 3-D grid (shape {shape})", where, fix)
    for name in _RISK_3D + _RISK_2D:
        want = shape if name in _RISK_3D else shape[:2]
        if a[name].shape != want:
            raise InputFileError(f"risk.npz's {name} has shape {a[name].shape}, not the grid's {want}", where, fix)
        values = a[name]
        if values.dtype.kind == "f":
            if np.isinf(values).any() or (name not in ("risk", "risk_P", "risk_V", "risk_U") and np.isnan(values).any()):
                raise InputFileError(f"risk.npz's {name} holds inf or NaN", where, fix)
            if name != "surface_height" and (values < 0).any():
                raise InputFileError(f"risk.npz's {name} holds negative values", where, fix)
        elif values.dtype.kind not in "biu":
            raise InputFileError(f"risk.npz's {name} is not numeric ({values.dtype})", where, fix)
    rk = summary.get("risk_per_flight_hour")
    band = summary.get("band_m")
    constants = summary.get("constants")
    if not (isinstance(rk, dict) and isinstance(band, list) and len(band) == 2 and isinstance(constants, dict)):
        raise InputFileError("summary.json lacks risk_per_flight_hour, band_m or constants", where, fix)
    check_number(rk.get("threshold_R0"), "summary.json's risk_per_flight_hour.threshold_R0", where, fix,
                 Range(0, 1e6, lo_open=True))
    low, high = (check_number(b, "summary.json's band_m", where, fix, Range(-MAX_COORD_M, MAX_COORD_M)) for b in band)
    if low > high:
        raise InputFileError(f"summary.json's band_m is empty ([{low:g}, {high:g}] m)", where, fix)
    for key in ("mass_kg", "crash_area_m2", "drag_k_per_m", "terminal_speed_mps", "mean_relative_speed_mps",
                "vehicle_collision_probability"):
        check_number(constants.get(key), f"summary.json's constants.{key}", where, fix, Range(0, 1e12))


def load_schedule(path: str | Path) -> Schedule:
    """The :class:`~uamopt.schedule.model.Schedule` of a schedule folder (``schedule.csv`` and
    ``summary.json``), rows in schedule.csv order."""
    expect_path(path, "path", "load_schedule")

    from uamopt.schedule.model import Schedule, status_of, termination_of

    file = _file(path, "schedule.csv")
    summary = _json(_file(file.parent, "summary.json"))
    try:
        with open(file, newline="", encoding="utf-8-sig") as fh:
            rows = list(csv.DictReader(fh))
        operated = np.array([r["operated"].strip() == "1" for r in rows], dtype=bool)
        delay = np.array([float(r["delay_s"]) for r in rows], dtype=float)
        _check_schedule_numbers(delay, summary, file.parent)
        # a summary written before the statuses were split has only "status"; the pair it stands for
        try:
            termination, proved_for = ((summary["termination"], summary["proved_for"]) if "termination" in summary
                                       else termination_of(summary["status"]))
            consistent = status_of(termination, proved_for) == summary["status"]
        except UamoptError as exc:
            raise InputFileError(exc.what, str(file.parent), "regenerate it with `uamopt schedule`") from None
        if not consistent:
            raise InputFileError(f"status {summary['status']!r} does not match termination {termination!r} and "
                                 f"proved_for {proved_for!r}", str(file.parent), "regenerate it with `uamopt schedule`")
        return Schedule(
            solver=str(summary["solver"]), termination=termination, proved_for=proved_for, operated=operated,
            delay_s=delay,
            objective=summary.get("objective"), bound=summary.get("bound"), gap=summary.get("gap"),
            solve_seconds=float(summary.get("solve_seconds", 0.0)), seed=summary.get("seed"),
            aircraft_count=int(summary.get("aircraft", 1)), extras=dict(summary.get("extras", {})),
            flight_ids=tuple(r["flight"] for r in rows))
    except (KeyError, ValueError, TypeError, AttributeError) as exc:
        raise InputFileError(f"malformed schedule folder: {exc}", str(file.parent),
                             "regenerate it with `uamopt schedule`") from None


def _check_schedule_numbers(delay: np.ndarray, summary: dict, folder: Path) -> None:
    """A schedule folder's numbers within what they can mean (the verifier's ranges)."""
    from uamopt.bounds import DURATION_S, Range, check_number

    where, fix = str(folder), "regenerate it with `uamopt schedule`"
    bad = ~((delay >= DURATION_S.lo) & (delay <= DURATION_S.hi))  # NaN too
    if bad.any():
        raise InputFileError(f"schedule.csv's delay_s must be {DURATION_S.text()}, got {delay[bad][0]!r} "
                             f"(row {int(np.flatnonzero(bad)[0]) + 1})", where, fix)
    for key in ("objective", "bound", "gap"):
        if summary.get(key) is not None:
            check_number(summary[key], f"summary.json's {key}", where, fix, Range(-1e15, 1e15))
    check_number(summary.get("solve_seconds", 0.0), "summary.json's solve_seconds", where, fix, DURATION_S)
    check_number(summary.get("aircraft", 1), "summary.json's aircraft", where, fix, Range(0, 10**9, integer=True))
    if summary.get("seed") is not None:
        check_number(summary["seed"], "summary.json's seed", where, fix, Range(0, 2**63 - 1, integer=True))


# --- writers: what the commands write, so every folder loads back with the loaders above -------


def save_risk(field: RiskField, folder: str | Path) -> None:
    """``risk.npz`` and ``summary.json`` of a risk folder."""
    from uamopt.outputs import write_json

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    field.save_npz(folder / "risk.npz")
    write_json(folder / "summary.json", field.summary())


def save_tracks(plan: TrackPlan, folder: str | Path, scenario=None) -> None:
    """``tracks.json`` of a plan folder (docs/interfaces.md: stages with waypoints and metrics)."""
    from uamopt.outputs import write_json

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    doc = plan.as_dict()
    if scenario is not None:
        doc["scenario"] = {"name": scenario.name, "file": scenario.source, "cell": list(scenario.grid.cell),
                           "weights": list(scenario.tracks.weights)}
    write_json(folder / "tracks.json", doc)


def save_network(network: RouteNetwork, folder: str | Path) -> None:
    """``network.json`` of a network folder."""
    from uamopt.outputs import write_json

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    write_json(folder / "network.json", network.to_document())
