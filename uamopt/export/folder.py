"""Reading a schedule folder (``flights.json``, ``schedule.csv``, ``summary.json``) for the exports.

The folder is what ``uamopt schedule`` writes (docs/interfaces.md). The exports need the operated
flights with their departure and arrival times, the tracks, and the georeference (``frame`` in
summary.json, see :mod:`uamopt.export.frame`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from uamopt.bounds import parse_error, shown
from uamopt.errors import InputFileError
from uamopt.export.frame import LocalFrame, synthetic_frame
from uamopt.schedule.flights import Flight, FlightSet
from uamopt.schedule.flights_file import load_flights
from uamopt.schedule.verify import read_schedule_csv


@dataclass(frozen=True)
class OperatedFlight:
    """One operated flight of a schedule: its plan and its scheduled times (s)."""

    flight: Flight
    departure_s: float
    arrival_s: float


@dataclass(frozen=True)
class ScheduleFolder:
    """A schedule folder's content, as the exports read it.

    ``frame_recorded`` is False for a folder written before summary.json carried ``frame``: its
    frame is then the synthetic anchor (``source = "default"``). ``scenario`` is the recorded
    ``{"name", "file", "set"}`` or None.
    """

    path: Path
    flights: FlightSet
    operated: tuple[OperatedFlight, ...]
    frame: LocalFrame
    frame_recorded: bool
    scenario: dict | None
    summary: dict


def _operated(path: Path, flights: FlightSet) -> tuple[OperatedFlight, ...]:
    """The operated flights of ``schedule.csv``, read by the verifier's own reader (every field
    checked the same way as ``uamopt verify`` does)."""
    by_id = {f.id: f for f in flights.flights}
    out = []
    for flight_id, rec in read_schedule_csv(path).items():
        where = f"{path}: line {rec['line']}"
        if rec["duplicate"]:
            raise InputFileError(f"flight {flight_id!r} appears more than once", where, "rewrite it with uamopt schedule")
        if not rec["operated"]:
            continue
        flight = by_id.get(flight_id)
        if flight is None:
            raise InputFileError(f"flight {flight_id!r} is not in flights.json", where, "rewrite the folder with uamopt schedule")
        out.append(OperatedFlight(flight, rec["departure"], rec["arrival"]))
    return tuple(sorted(out, key=lambda o: (o.departure_s, o.flight.id)))


def read_schedule_folder(path: str | Path) -> ScheduleFolder:
    """Read a schedule folder written by ``uamopt schedule``.

    Raises
    ------
    InputFileError
        The folder or one of its files is missing or malformed.
    """
    folder = Path(path)
    if not folder.is_dir():
        raise InputFileError(f"not a folder: {folder}", str(folder), "give the --out folder of uamopt schedule")
    flights = load_flights(folder / "flights.json")
    summary: dict = {}
    summary_path = folder / "summary.json"
    if summary_path.is_file():
        try:
            summary = json.loads(summary_path.read_text(encoding="utf-8-sig"))
        except (ValueError, RecursionError, OSError) as exc:  # JSONDecodeError, UnicodeDecodeError, > 4300 digits
            raise InputFileError(f"malformed JSON: {parse_error(exc) if isinstance(exc, ValueError) else exc}",
                                 str(summary_path), "rewrite it with uamopt schedule") from None
        if not isinstance(summary, dict):
            raise InputFileError("summary.json does not hold a JSON object", str(summary_path),
                                 "rewrite it with uamopt schedule")
    raw_frame = summary.get("frame")
    frame = LocalFrame.from_dict(raw_frame, str(summary_path)) if isinstance(raw_frame, dict) else synthetic_frame("default")
    scenario = summary.get("scenario") if isinstance(summary.get("scenario"), dict) else None
    return ScheduleFolder(folder, flights, _operated(folder / "schedule.csv", flights), frame,
                          isinstance(raw_frame, dict), scenario, summary)


def recorded_scenario(folder: ScheduleFolder, scenario_path: str | None = None, overrides: list[str] | None = None):
    """The scenario the folder was scheduled with: ``scenario_path`` if given, else the recorded file.

    Raises
    ------
    InputFileError
        No scenario given and none recorded (a folder from before the record existed).
    ScenarioError
        The scenario file is missing or malformed.
    """
    from uamopt.scenario import load_scenario

    if scenario_path is not None:
        return load_scenario(scenario_path, overrides or [])
    record = folder.scenario or {}
    where = str(folder.path / "summary.json")
    if not record.get("file") or not isinstance(record["file"], str):
        raise InputFileError("the folder records no scenario file", where,
                             "pass --scenario FILE (and its --set overrides), or --risk risk.npz")
    recorded = record.get("set", [])
    if not (isinstance(recorded, list) and all(isinstance(s, str) for s in recorded)):
        raise InputFileError(f"the recorded scenario's 'set' is not a list of KEY=VALUE strings, got {shown(recorded)}",
                             where, "rewrite the folder with uamopt schedule, or pass --scenario FILE (and its --set "
                             "overrides), or --risk risk.npz")
    return load_scenario(record["file"], recorded + list(overrides or []))


def write_texts(folder: Path, texts: dict[str, str]) -> list[Path]:
    """Write ``texts`` (file name -> text) into the existing folder ``folder``, all or nothing,
    under its lock (uamopt.outputs.staged_output); returns the paths written."""
    from uamopt.outputs import staged_output

    with staged_output(folder, "DIR") as stage:
        for name, text in texts.items():
            (stage / name).write_text(text, encoding="utf-8")
    return [folder / name for name in texts]
