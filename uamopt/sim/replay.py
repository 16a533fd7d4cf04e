"""``uamopt replay DIR``: an independent check of a schedule in the BlueSky simulator.

Our verifier shares the team's reading of occupancy; BlueSky (TU Delft) is a check nobody here
wrote. :func:`replay` writes the folder's scenario (:mod:`uamopt.export.bluesky`), runs it
headless in fast time in a fresh process (:mod:`uamopt.sim.worker`), and compares what BlueSky
flew with our plan:

- losses of separation found by BlueSky's own state-based detection, its protected zone derived
  from our conflict zone (:mod:`uamopt.export.zone`: a verified schedule gives none while every
  flight stays within the deviation budget);
- per pair that came near: the closest approach and the smallest horizontal distance;
- per flight: largest cross-track distance to the track, largest horizontal and vertical error
  against the planned position at the same time, and the arrival-time deviation; beside them the
  commanded trajectory's own largest distance to the plan (``designed_error_m``, the part no
  aircraft at this bank limit can avoid) and its speed range; with vertical phases also
  ``transition_error_m``, v²/(8a), what BlueSky's rotorcraft acceleration costs at the top of
  climb and of descent (:mod:`uamopt.export.bluesky`).

Results: ``DIR/replay.json`` and the figure ``DIR/replay.png`` (docs/export.md). BlueSky is an
optional dependency (``pip install 'uamopt[sim]'``).
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from uamopt.errors import UamoptError
from uamopt.export.bluesky import (
    DEFAULT_BANK_DEG,
    DEFAULT_DT_S,
    DEFAULT_TRAJECTORY,
    flight_trajectories,
    scenario_text,
    transition_error_m,
)
from uamopt.export.folder import ScheduleFolder, read_schedule_folder
from uamopt.export.zone import (
    DEFAULT_BUDGET_H_M,
    DEFAULT_BUDGET_V_M,
    ProtectedZone,
    protected_zone,
)
from uamopt.sim.analysis import flight_deviation, pair_separations

INSTALL_HINT = "install the simulator with: pip install 'uamopt[sim]' (PyPI bluesky-simulator)"


@dataclass(frozen=True)
class ReplayResult:
    """What BlueSky flew against our plan (see the module docstring); ``as_dict()`` is replay.json."""

    folder: Path
    zone: ProtectedZone
    los: list[dict]
    near_pairs: list[dict]
    flights: list[dict]
    settings: dict
    seconds: dict = field(default_factory=dict)

    @property
    def los_count(self) -> int:
        return len(self.los)

    @property
    def over_budget(self) -> list[str]:
        """Flights whose deviation exceeds the zone's budget: the zero-LoS guarantee does not cover them."""
        return [f["flight"] for f in self.flights
                if f["max_horizontal_error_m"] > self.zone.budget_h_m or f["max_vertical_error_m"] > self.zone.budget_v_m]

    def as_dict(self) -> dict:
        def stat(key):
            values = np.array([f[key] for f in self.flights]) if self.flights else np.zeros(1)
            return {"min": float(values.min()), "max": float(values.max()), "mean": float(values.mean())}

        return {
            "folder": str(self.folder), "settings": self.settings, "zone": self.zone.as_dict(),
            "flights_replayed": len(self.flights), "los_count": self.los_count, "los": self.los,
            "near_pair_count": len(self.near_pairs), "near_pairs": self.near_pairs,
            "within_budget": not self.over_budget, "over_budget": self.over_budget,
            "deviation": {"max_cross_track_m": stat("max_cross_track_m"),
                          "max_horizontal_error_m": stat("max_horizontal_error_m"),
                          "max_vertical_error_m": stat("max_vertical_error_m"),
                          "arrival_deviation_s": stat("arrival_deviation_s")},
            "flights": self.flights, "seconds": self.seconds,
        }


def bluesky_available() -> bool:
    try:
        return importlib.util.find_spec("bluesky") is not None
    except (ImportError, ValueError):
        return False


def _workdir() -> Path:
    """BlueSky's working folder (settings, navigation-data cache), kept between replays."""
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "uamopt" / "bluesky"
    try:
        base.mkdir(parents=True, exist_ok=True)
        return base
    except OSError:
        return Path(tempfile.mkdtemp(prefix="uamopt-bluesky-"))


def _run_worker(scn: Path, until_s: float) -> tuple[dict, dict]:
    with tempfile.TemporaryDirectory(prefix="uamopt-replay-") as tmp:
        raw = Path(tmp) / "raw.npz"
        cmd = [sys.executable, "-m", "uamopt.sim.worker", str(scn), str(raw), "--workdir", str(_workdir()),
               "--until", repr(until_s), "--parent", str(os.getpid())]  # the worker ends with us, even on SIGKILL
        done = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if done.returncode != 0 or not raw.is_file():
            last = (done.stderr.strip().splitlines() or ["no output"])[-1]
            raise UamoptError(f"BlueSky failed: {last}", str(scn), "check the BlueSky installation (uamopt[sim])")
        with np.load(raw) as data:
            meta = json.loads(str(data["meta"]))
            arrays = {k: data[k] for k in ("t", "ac", "lat", "lon", "alt")}
    return meta, arrays


def replay(path: str | Path, *, dt_s: float = DEFAULT_DT_S, bank_deg: float = DEFAULT_BANK_DEG,
           budget_h_m: float = DEFAULT_BUDGET_H_M, budget_v_m: float = DEFAULT_BUDGET_V_M,
           zone_m: tuple[float, float] | None = None, window_s: tuple[float, float] | None = None,
           trajectory: str = DEFAULT_TRAJECTORY, write: bool = True) -> ReplayResult:
    """Replay the schedule folder ``path`` in BlueSky and compare it with the plan.

    Parameters
    ----------
    path : str or Path
        A folder written by ``uamopt schedule`` (flights.json, schedule.csv, summary.json).
    dt_s : float
        BlueSky's clock step, s (its default, 0.05 s).
    bank_deg : float
        Bank limit of every aircraft, degrees (turn radius v²/(g tan φ)).
    budget_h_m, budget_v_m : float
        e_h, e_v: the deviation from the plan the protected zone allows for, m (:mod:`uamopt.export.zone`).
    zone_m : (r_pz, h_pz), optional
        An explicit protected zone, m, instead of the derived one.
    window_s : (t0, t1), optional
        Replay only the operated flights departing in [t0, t1], s (any subset of a verified
        schedule is verified).
    trajectory : {"designed", "waypoints"}
        What each aircraft is commanded (:func:`uamopt.export.bluesky.flight_trajectories`): the
        flyable trajectory nearest to the plan (default) or the track's own waypoints at v_g.
    write : bool
        Write ``bluesky.scn`` (the scenario replayed), ``replay.json`` and ``replay.png`` into the folder.

    Returns
    -------
    ReplayResult

    Raises
    ------
    UamoptError
        BlueSky is not installed, the zone is empty, BlueSky fails, or an aircraft type is unknown.
    InputFileError
        The folder or one of its files is missing or malformed.
    """
    started = time.perf_counter()
    if not bluesky_available():
        raise UamoptError("BlueSky is not installed", "uamopt replay", INSTALL_HINT)
    folder = read_schedule_folder(path)
    from uamopt.progress import Steps

    with Steps(3, "replay") as bar:  # plain lines off a terminal once it has run 5 s (the simulation takes ~1 min)
        return _replay(folder, bar, started, dt_s=dt_s, bank_deg=bank_deg, budget_h_m=budget_h_m,
                       budget_v_m=budget_v_m, zone_m=zone_m, window_s=window_s, trajectory=trajectory, write=write)


def _replay(folder: ScheduleFolder, bar, started: float, *, dt_s, bank_deg, budget_h_m, budget_v_m, zone_m, window_s,
            trajectory, write) -> ReplayResult:
    """:func:`replay` after the folder is read; ``bar`` counts its three steps."""
    bar.set_description("designing the trajectories")
    zone = protected_zone(folder.flights.cell, folder.flights.conflict_radius, budget_h_m=budget_h_m,
                          budget_v_m=budget_v_m, zone_m=zone_m)
    chosen = [o for o in folder.operated if window_s is None or window_s[0] <= o.departure_s <= window_s[1]]
    if not chosen:
        raise UamoptError("no operated flight to replay", str(folder.path), "widen the window or schedule flights")
    designs = flight_trajectories(chosen, bank_deg, trajectory)
    text = scenario_text(folder, (zone.rpz_m, zone.hpz_m), dt_s=dt_s, bank_deg=bank_deg, flights=chosen,
                         trajectory=trajectory, designs=designs)
    with tempfile.TemporaryDirectory(prefix="uamopt-scn-") as tmp:
        scn = Path(tmp) / "bluesky.scn"
        scn.write_text(text, encoding="utf-8")
        until = max(o.arrival_s for o in chosen) + 600.0
        bar.update(1)
        bar.set_description(f"BlueSky simulating {len(chosen)} flights to t = {until:.0f} s")
        meta, raw = _run_worker(scn, until)
    bar.update(1)
    bar.set_description("comparing with the plan")
    result = _compare(folder, chosen, zone, meta, raw)
    by_id = {o.flight.id: o.flight for o in chosen}
    for f in result[2]:
        design = designs[f["flight"]]
        f["designed_error_m"], f["commanded_speed_mps"] = design.max_error_m, list(design.speed_range_mps)
        vertical = by_id[f["flight"]].vertical_rate_mps is not None  # hover <-> cruise (export.bluesky)
        f["transition_error_m"] = transition_error_m(by_id[f["flight"]].speed_mps) if vertical else 0.0
    settings = {"bluesky": meta["bluesky"], "aircraft_type": "EC35", "bank_deg": bank_deg, "dt_s": meta["dt_s"],
                "trajectory": trajectory,
                "cd_method": meta["cd_method"], "bluesky_zone_m": meta["zone_m"], "window_s": window_s,
                "frame": folder.frame.as_dict(), "frame_recorded": folder.frame_recorded}
    seconds = {"simulated": meta["end_s"], "simulation": meta["wall_s"], "simulation_cpu": meta["cpu_s"],
               "bluesky_cpu": meta["process_cpu_s"], "total": time.perf_counter() - started}
    result = ReplayResult(folder.path, zone, result[0], result[1], result[2], settings, seconds)
    if write:
        from uamopt.outputs import staged_output
        from uamopt.sim.plot import plot_replay

        with staged_output(folder.path, "DIR") as stage:  # all three or none (uamopt.outputs)
            plot_replay(result, stage / "replay.png")
            (stage / "bluesky.scn").write_text(text, encoding="utf-8")
            (stage / "replay.json").write_text(json.dumps(result.as_dict(), indent=2) + "\n", encoding="utf-8")
    bar.update(1)
    return result


def _compare(folder: ScheduleFolder, chosen: list, zone: ProtectedZone, meta: dict, raw: dict):
    """LoS events, near pairs and per-flight deviations from the worker's recording."""
    from uamopt.export.bluesky import aircraft_ids

    ids = aircraft_ids([o.flight.id for o in folder.operated])
    flight_of = {acid: fid for fid, acid in ids.items()}
    wrong = sorted((a, t) for a, t in meta["actypes"].items() if t != "EC35")
    if wrong:
        raise UamoptError(f"BlueSky flew aircraft {wrong[0][0]} as {wrong[0][1]}, not EC35",
                          "uamopt replay", "use a bluesky-simulator whose OpenAP data has the EC35 rotorcraft")
    x, y = folder.frame.from_lonlat(raw["lon"], raw["lat"])
    xyz = np.column_stack([x, y, raw["alt"]])
    steps = np.rint(raw["t"] / meta["dt_s"]).astype(np.int64)
    by_flight = {o.flight.id: o for o in chosen}
    tracks, flights = {}, []
    for n, acid in enumerate(meta["acids"]):
        rows = np.flatnonzero(raw["ac"] == n)
        fid = flight_of[acid]
        tracks[fid] = (steps[rows], xyz[rows])
        flights.append(flight_deviation(by_flight[fid], raw["t"][rows], xyz[rows]))
    missing = sorted(set(by_flight) - set(tracks))
    if missing:
        raise UamoptError(f"BlueSky never created flight {missing[0]}", "uamopt replay", "check bluesky.scn")
    speed = max(o.flight.speed_mps for o in chosen)
    aircraft = {fid: o.flight.aircraft for fid, o in by_flight.items()}
    pairs = pair_separations(tracks, aircraft, zone, 2 * speed * meta["dt_s"])
    for p in pairs:
        for key in ("closest", "min_horizontal"):
            p[f"{key}_s"] = p.pop(f"{key}_step") * meta["dt_s"]
    by_pair = {tuple(p["flights"]): p for p in pairs}
    los = []
    for a, b, start, end in meta["los"]:
        fa, fb = sorted((flight_of[a], flight_of[b]))
        p = by_pair.get((fa, fb)) or by_pair.get((fb, fa)) or {}
        los.append({"flights": [fa, fb], "start_s": start, "end_s": end,
                    "closest_horizontal_m": p.get("closest_horizontal_m"), "closest_vertical_m": p.get("closest_vertical_m"),
                    "closest_s": p.get("closest_s")})
    los.sort(key=lambda e: (e["start_s"], e["flights"]))
    return los, pairs, sorted(flights, key=lambda f: (f["departure_s"], f["flight"]))
