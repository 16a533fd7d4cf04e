"""The ``export`` and ``replay`` subcommands (docs/interfaces.md), added to the main parser by :mod:`uamopt.cli`.

    uamopt export bluesky DIR [--dt S] [--bank DEG] [--trajectory designed|waypoints] [--zone RPZ,HPZ]
                              [--budget EH,EV]                                       # DIR/bluesky.scn
    uamopt export geojson DIR [--risk risk.npz | --scenario FILE [--set K=V ...]]  # DIR/*.geojson, trips.kepler.json
    uamopt replay DIR [--dt S] [--bank DEG] [--trajectory designed|waypoints] [--zone RPZ,HPZ] [--budget EH,EV]
                      [--window T0,T1]

``replay`` exits 0 when BlueSky finds no loss of separation and every flight stays within the
deviation budget, 1 otherwise (like ``uamopt verify``), 2 on bad input or a missing BlueSky.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

from uamopt.errors import UamoptError

MAX_DT_S = 10.0  # longest BlueSky clock step accepted, s (the default is 0.05 s)


def _pair(text: str | None, option: str, example: str) -> tuple[float, float] | None:
    if text is None:
        return None
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 2 or not all(math.isfinite(v) and v >= 0 for v in values):
        raise UamoptError(f"{option} {text!r} is not two numbers ≥ 0", option, f"write e.g. {option} {example}")
    return values  # type: ignore[return-value]


def _simulation_options(p) -> None:
    from uamopt.export.defaults import (
        DEFAULT_BANK_DEG,
        DEFAULT_BUDGET_H_M,
        DEFAULT_BUDGET_V_M,
        DEFAULT_DT_S,
        DEFAULT_TRAJECTORY,
        TRAJECTORIES,
    )

    p.add_argument("dir", help="a schedule folder written by uamopt schedule")
    p.add_argument("--dt", type=float, default=DEFAULT_DT_S, help=f"BlueSky clock step, s (default {DEFAULT_DT_S:g})")
    p.add_argument("--bank", type=float, default=DEFAULT_BANK_DEG, help=f"bank limit, degrees (default {DEFAULT_BANK_DEG:g})")
    p.add_argument("--zone", metavar="RPZ,HPZ", help="protected zone radius and half height, m (default: from the cells and r)")
    p.add_argument("--trajectory", choices=TRAJECTORIES, default=DEFAULT_TRAJECTORY,
                   help="designed: the flyable trajectory nearest to the plan (default); waypoints: the track's own at v_g")
    p.add_argument("--budget", metavar="EH,EV", help=f"deviation budget the zone allows for, m "
                                                    f"(default {DEFAULT_BUDGET_H_M:g},{DEFAULT_BUDGET_V_M:g})")


def _zone(args, folder_path: str):
    from uamopt.export.folder import read_schedule_folder
    from uamopt.export.zone import DEFAULT_BUDGET_H_M, DEFAULT_BUDGET_V_M, protected_zone

    if not 0 < args.dt <= MAX_DT_S or not 0 < args.bank < 90:  # a step longer than a flight samples nothing
        raise UamoptError(f"--dt {args.dt:g} or --bank {args.bank:g} out of range", "command line",
                          f"give 0 < --dt ≤ {MAX_DT_S:g} s and 0 < --bank < 90 degrees")
    budget = _pair(args.budget, "--budget", "10,2") or (DEFAULT_BUDGET_H_M, DEFAULT_BUDGET_V_M)
    flights = read_schedule_folder(folder_path).flights
    return budget, protected_zone(flights.cell, flights.conflict_radius, budget_h_m=budget[0], budget_v_m=budget[1],
                                  zone_m=_pair(args.zone, "--zone", "29.5,25.5"))


def cmd_export_bluesky(args) -> int:
    from uamopt.export.bluesky import export_bluesky
    from uamopt.outputs import output_lock

    with output_lock(args.dir, "DIR"):
        _, zone = _zone(args, args.dir)
        path = export_bluesky(args.dir, (zone.rpz_m, zone.hpz_m), dt_s=args.dt, bank_deg=args.bank,
                              trajectory=args.trajectory)
    print(f"BlueSky scenario (protected zone r_pz = {zone.rpz_m:g} m, h_pz = {zone.hpz_m:g} m) -> {path}")
    return 0


def cmd_export_geojson(args) -> int:
    from uamopt.export.geojson import export_geojson
    from uamopt.outputs import output_lock

    if args.risk and args.scenario:
        raise UamoptError("--risk and --scenario both given", "command line", "give one source of the unsafe airspace")
    with output_lock(args.dir, "DIR"):
        paths = export_geojson(args.dir, risk=args.risk, scenario=args.scenario, overrides=args.set)
    print("GeoJSON and kepler.gl trips (WGS 84): " + ", ".join(p.name for p in paths) + f" -> {Path(args.dir)}")
    return 0


def cmd_replay(args) -> int:
    from uamopt.outputs import output_lock
    from uamopt.sim.replay import replay

    with output_lock(args.dir, "DIR"):  # held while BlueSky reads the folder, until the results are in
        budget, zone = _zone(args, args.dir)
        window = _pair(args.window, "--window", "0,900")
        result = replay(args.dir, dt_s=args.dt, bank_deg=args.bank, budget_h_m=budget[0], budget_v_m=budget[1],
                        zone_m=(zone.rpz_m, zone.hpz_m), window_s=window, trajectory=args.trajectory)
    d = result.as_dict()["deviation"]
    print(f"BlueSky replay: {len(result.flights)} flights, {result.los_count} losses of separation "
          f"(r_pz = {zone.rpz_m:g} m, h_pz = {zone.hpz_m:g} m), {len(result.near_pairs)} near pairs; deviation from the "
          f"plan ≤ {d['max_horizontal_error_m']['max']:.1f} m horizontal, ≤ {d['max_vertical_error_m']['max']:.1f} m vertical, "
          f"arrival {d['arrival_deviation_s']['min']:+.2f} to {d['arrival_deviation_s']['max']:+.2f} s; "
          f"{result.seconds['total']:.0f} s -> {Path(args.dir) / 'replay.json'}")
    for event in result.los:
        print(f"loss of separation: flights {event['flights'][0]} and {event['flights'][1]} from {event['start_s']:.2f} s "
              f"to {event['end_s']:.2f} s")
    if result.over_budget:
        sys.stderr.write(f"warning: {len(result.over_budget)} flights deviate from the plan beyond the budget "
                         f"({', '.join(result.over_budget[:5])}): the zone does not cover them (replay.json)\n")
    return 1 if result.los or result.over_budget else 0


def add_export_commands(sub) -> None:
    """Add ``export bluesky``, ``export geojson`` and ``replay`` to the subparsers ``sub`` of ``uamopt``."""
    text = "export a schedule folder: bluesky (bluesky.scn) or geojson (tracks, vertiports, unsafe airspace, kepler.gl trips)"
    export = sub.add_parser("export", help=text, description=text)
    kinds = export.add_subparsers(dest="kind", required=True, parser_class=type(export))
    text = "write DIR/bluesky.scn: the operated flights as a BlueSky scenario"
    bluesky = kinds.add_parser("bluesky", help=text, description=text)
    _simulation_options(bluesky)
    bluesky.set_defaults(func=cmd_export_bluesky)
    text = ("write DIR/tracks.geojson, vertiports.geojson, unsafe.geojson (RFC 7946) and trips.kepler.json "
            "(kepler.gl's trip layer: the operated flights, positions [lon, lat, z, Unix time]) in WGS 84")
    geojson = kinds.add_parser("geojson", help=text, description=text)
    geojson.add_argument("dir", help="a schedule folder written by uamopt schedule")
    geojson.add_argument("--risk", help="risk.npz of the same scenario (default: recompute from the recorded scenario)")
    geojson.add_argument("--scenario", help="scenario TOML to recompute the risk field with (default: the recorded one)")
    geojson.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override a scenario key")
    geojson.set_defaults(func=cmd_export_geojson)
    text = "replay a schedule folder in the BlueSky simulator: replay.json, replay.png (needs uamopt[sim])"
    rp = sub.add_parser("replay", help=text, description=text)
    _simulation_options(rp)
    rp.add_argument("--window", metavar="T0,T1", help="replay only the flights departing in [T0, T1] s")
    rp.set_defaults(func=cmd_replay)
