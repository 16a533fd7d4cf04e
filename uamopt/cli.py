"""Command line: ``uamopt COMMAND SCENARIO [--set KEY=VALUE ...] [--out DIR]`` (docs/interfaces.md).

Bad input ends with one line ``error: <what> (<where>): <how to fix>`` on stderr and exit code 2;
results are staged and moved into ``--out`` only when complete.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path


from uamopt.errors import UamoptError

EXIT_BAD_INPUT = 2
_STARTED = time.perf_counter()  # the command's own clock (imports included)


class _Parser(argparse.ArgumentParser):
    """argparse with the project's one-line error and exit code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"error: {message} (command line): see `{self.prog} --help`\n")
        raise SystemExit(EXIT_BAD_INPUT)


def _progress(total: int, desc: str):
    """A progress bar on a terminal, silent otherwise."""
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, disable=not sys.stderr.isatty(), leave=False)


def _load(args):
    from uamopt.scenario import load_scenario

    return load_scenario(args.scenario, args.set)


def _risk_stage(scenario, stage: Path, bar) -> dict:
    """Compute the risk field and write risk.npz, risk.png, summary.json into ``stage``."""
    from uamopt.outputs import write_json
    from uamopt.plots import plot_risk
    from uamopt.stages import compute_risk, risk_summary

    bar.set_description("risk field")
    run = compute_risk(scenario)
    bar.update(1)
    run.field.save_npz(stage / "risk.npz")
    bar.set_description("risk map")
    plot_risk(
        run.field, stage / "risk.png", vertiports=scenario.network.vertiports,
        cruise_altitude_m=scenario.network.cruise_altitude_m, title=scenario.name,
    )
    bar.update(1)
    summary = risk_summary(run)
    write_json(stage / "summary.json", summary)
    return run, summary


def _endpoints(scenario, args):
    """--from/--to (X,Y,Z or a vertiport name), else the scenario's route (tracks.route)."""
    from uamopt.planning.endpoints import default_endpoints, parse_endpoint

    origin, destination = default_endpoints(scenario) if (args.origin is None or args.destination is None) else (None, None)
    if args.origin is not None:
        origin = parse_endpoint(scenario, args.origin, "--from")
    if args.destination is not None:
        destination = parse_endpoint(scenario, args.destination, "--to")
    return origin, destination


def _planning(scenario, bar):
    from uamopt.planning import planning_model
    from uamopt.stages import compute_risk

    bar.set_description("risk field")
    run = compute_risk(scenario)
    bar.update(1)
    bar.set_description("planning model")
    model = planning_model(scenario, run.field)
    bar.update(1)
    return run, model


def _plan_stage(scenario, model, origin, destination, stage: Path, bar) -> dict:
    """Plan the four stages and write tracks.json and tracks.png into ``stage``."""
    from uamopt.outputs import write_json
    from uamopt.planning import plan_track
    from uamopt.plot_tracks import plot_tracks

    bar.set_description("tracks")
    plan = plan_track(model, origin, destination)
    bar.update(1)
    doc = {**plan.as_dict(), "scenario": {"name": scenario.name, "file": scenario.source,
                                          "cell": list(model.field.grid.cell), "weights": list(scenario.tracks.weights)}}
    write_json(stage / "tracks.json", doc)
    plot_tracks(model, plan, stage / "tracks.png", title=scenario.name)
    bar.update(1)
    return doc


def _network_stage(scenario, model, stage: Path, bar):
    """Plan every route in both directions and write network.json and network.png."""
    from uamopt.outputs import write_json
    from uamopt.planning.network import plan_network
    from uamopt.plot_tracks import plot_network

    bar.set_description("network")
    network = plan_network(model, progress=bar)
    write_json(stage / "network.json", network.to_document())
    plot_network(model, network.waypoints(), stage / "network.png", vertiports=scenario.network.vertiports)
    return network


def cmd_plan(args) -> int:
    from uamopt.outputs import check_out_dir, staged_output

    scenario = _load(args)
    origin, destination = _endpoints(scenario, args)
    check_out_dir(args.out)
    with _progress(4, "plan") as bar, staged_output(args.out) as stage:
        _, model = _planning(scenario, bar)
        doc = _plan_stage(scenario, model, origin, destination, stage, bar)
    opt = doc["stages"]["optimal"]
    print(f"optimal track: {opt['length_m']:.0f} m, ¥{opt['transport_cost']:.2f}, risk {opt['risk_cost']:.1f} "
          f"-> {Path(args.out) / 'tracks.json'}")
    return 0


def cmd_network(args) -> int:
    from uamopt.outputs import check_out_dir, staged_output

    scenario = _load(args)
    check_out_dir(args.out)
    with _progress(2 + 2 * 10, "network") as bar, staged_output(args.out) as stage:
        _, model = _planning(scenario, bar)
        network = _network_stage(scenario, model, stage, bar)
    print(f"network: {len(network)} tracks -> {Path(args.out) / 'network.json'}")
    return 0


def cmd_risk(args) -> int:
    from uamopt.outputs import check_out_dir, staged_output

    scenario = _load(args)
    check_out_dir(args.out)
    with _progress(2, "risk") as bar, staged_output(args.out) as stage:
        _, summary = _risk_stage(scenario, stage, bar)
    print(
        f"risk field: {summary['cells']:,} cells, {100 * summary['unsafe_share']:.1f} % unsafe, "
        f"{summary['seconds']['risk']:.2f} s (whole command {time.perf_counter() - _STARTED:.2f} s) -> "
        f"{Path(args.out) / 'risk.npz'}"
    )
    return 0


def _plan_at(scenario, side: float, extent) -> tuple:
    """Risk field, planning model and the P_O → P_D plan at cubic cells of ``side`` metres."""
    from uamopt.planning import plan_track, planning_model
    from uamopt.planning.endpoints import default_endpoints
    from uamopt.stages import compute_risk

    started = time.perf_counter()
    fine = scenario.with_overrides([f"grid.cell=[{side},{side},{side}]", f"grid.extent={_toml_list(extent)}"])
    model = planning_model(fine, compute_risk(fine).field)
    plan = plan_track(model, *default_endpoints(fine))
    return fine, model, plan, time.perf_counter() - started


REPRODUCE_SOLVERS = ("greedy", "ga", "soa", "highs", "cpsat")


def _reproduce_schedules(scenario, model, network, stage: Path, bar, provenance: dict | None = None) -> list[str]:
    """Table 3 / Fig. 19: every solver profile on the paper-case plan over the planned network."""
    from uamopt.plot_schedule import plot_delay_comparison, plot_gantt
    from uamopt.report import is_paper_schedule, table3_section
    from uamopt.schedule import build_problem, write_schedule
    from uamopt.schedule.verify import verify_dir
    from uamopt.solvers import load_profile, solve

    flights = _initial_plan(scenario, network, scenario.schedule.plan_seed)
    sections = []
    for objective in (scenario.schedule.objective, "lexicographic" if scenario.schedule.objective == "weighted" else "weighted"):
        problem = build_problem(flights, scenario, objective=objective)
        schedules, verified = {}, {}
        for name in REPRODUCE_SOLVERS:
            bar.set_description(f"schedule ({objective}): {name}")
            schedule = solve(problem, load_profile(name))
            folder = stage / "schedules" / objective / name
            write_schedule(folder, problem, schedule, extra=provenance)
            schedules[name], verified[name] = schedule, not verify_dir(folder)
            bar.update(1)
        suffix = "" if objective == scenario.schedule.objective else f"_{objective}"
        best = min((s for s in schedules.values() if s.objective is not None), key=lambda s: s.objective)
        plot_gantt(problem, best, stage / f"gantt{suffix}.png")
        plot_delay_comparison(problem, schedules, stage / f"delays{suffix}.png")
        sections.append(table3_section(problem, schedules, verified, suffix=suffix,
                                       paper=is_paper_schedule(scenario, problem)))
    return sections


def cmd_reproduce(args) -> int:
    from uamopt.outputs import check_out_dir, staged_output, write_json
    from uamopt.planning import planning_model
    from uamopt.planning.endpoints import default_endpoints, is_paper_track
    from uamopt.plot_tracks import plot_tracks
    from uamopt.planning.pareto import plot_pareto, weight_sweep
    from uamopt.report import (network_section, pareto_section, risk_section, table2_section, table4_section,
                               write_report)

    scenario = _load(args)
    check_out_dir(args.out)
    t2 = scenario.tracks.table2_cell_m
    sides = [t2] + [c for c in scenario.tracks.table4_cells if c != t2]
    with _progress(4 + 20 + len(sides) + 2 * len(REPRODUCE_SOLVERS), "reproduce") as bar, staged_output(args.out) as stage:
        run, summary = _risk_stage(scenario, stage, bar)
        model = planning_model(scenario, run.field)
        network = _network_stage(scenario, model, stage, bar)
        plans = {}
        for side in sides:
            bar.set_description(f"track at {side:g} m cells")
            plans[side] = _plan_at(scenario, side, run.grid.extent)
            bar.update(1)
        fine, fine_model, plan, _ = plans[t2]
        origin, destination = default_endpoints(scenario)
        paper = is_paper_track(origin, destination)
        tracks = {**plan.as_dict(), "scenario": {"name": scenario.name, "file": scenario.source,
                                                 "cell": list(fine_model.field.grid.cell)}}
        write_json(stage / "tracks.json", tracks)
        plot_tracks(fine_model, plan, stage / "tracks.png", title=f"{scenario.name}, {t2:g} m cells")
        table4 = [(side, plans[side][2], plans[side][3]) for side in scenario.tracks.table4_cells]
        bar.set_description("buffer variant")
        other = "count" if scenario.tracks.buffer_measure != "count" else "structures"
        variant = scenario.with_overrides([f"tracks.buffer_measure={other}"])
        v_scenario, v_model, v_plan, _ = _plan_at(variant, t2, run.grid.extent)
        v_tracks = {**v_plan.as_dict()}
        bar.set_description("pareto front")
        fronts = {flag: weight_sweep(fine_model, origin, destination, 9, buffer=flag) for flag in (False, True)}
        plot_pareto(fronts[True], stage / "pareto.png", title=f"{scenario.name}: Eq. 10 + μ·R(t) trade-off")
        from uamopt.export.frame import schedule_provenance

        sched_sections = _reproduce_schedules(scenario, model, network, stage, bar, schedule_provenance(scenario, args.set))
        sections = [risk_section(scenario, summary), table2_section(fine, fine_model, tracks, paper=paper),
                    table2_section(v_scenario, v_model, v_tracks, figure=False, paper=paper,
                                   title=f"Table 2 analogue with the variant tracks.buffer_measure = \"{other}\""),
                    table4_section(scenario, table4, paper=paper),
                    pareto_section(fine, fine_model, fronts, (origin.label, destination.label)),
                    network_section(scenario, network.to_document())] + sched_sections
        write_report(stage / "report.md", scenario, sections)
    print(f"report: {Path(args.out) / 'report.md'}")
    return 0


def _initial_plan(scenario, network, seed: int):
    """The generated initial flight plan with the scenario's [schedule] keys."""
    from uamopt.schedule import generate_plan

    return generate_plan(scenario, network, seed)


def _scheduling_problem(scenario, args, bar):
    """The flight set (given, or generated on the planned or given network) and its model."""
    from uamopt.grid import build_grid
    from uamopt.planning import planning_model
    from uamopt.planning.network import load_network, plan_network
    from uamopt.schedule import build_problem, load_flights
    from uamopt.stages import compute_risk

    grid = build_grid(scenario)
    if args.network:
        network = load_network(args.network)
    elif args.flights:
        network = None  # self-contained flights need no network; named routes then fail clearly
    else:
        bar.set_description("network")
        model = planning_model(scenario, compute_risk(scenario).field)
        network = plan_network(model)
    bar.update(1)
    if args.flights:
        flights = load_flights(args.flights, scenario, grid, network)
    else:
        flights = _initial_plan(scenario, network, scenario.schedule.plan_seed if args.seed is None else args.seed)
    bar.set_description("conflicts")
    problem = build_problem(flights, scenario, objective=scenario.schedule.objective)
    bar.update(1)
    return problem


def cmd_flights(args) -> int:
    """The scenario's generated flight plan as a self-contained flights.json (the instance generator)."""
    from uamopt.outputs import check_out_dir, staged_output, write_json
    from uamopt.pipeline import build_problem, compute_risk, generate_flights, plan_network, planning_model
    from uamopt.schedule import save_flights

    scenario = _load(args)
    check_out_dir(args.out)
    with _progress(3, "flights") as bar, staged_output(args.out) as stage:
        bar.set_description("network")
        model = planning_model(scenario, compute_risk(scenario))
        network = plan_network(model)
        bar.update(1)
        flights = generate_flights(scenario, network, args.seed)
        bar.update(1)
        problem = build_problem(flights, scenario)
        save_flights(stage / "flights.json", flights)
        write_json(stage / "summary.json", {
            "scenario": scenario.name, "flights": len(flights), "aircraft": flights.n_aircraft,
            "vertiports": len(scenario.network.vertiports), "directed_routes": len(network),
            "tracks": scenario.network.tracks, "conflicting_pairs": len(problem.conflicts),
            "seed": scenario.schedule.plan_seed if args.seed is None else args.seed, "plan_notes": list(flights.notes)})
        bar.update(1)
    print(f"flights: {len(flights)} flights, {flights.n_aircraft} aircraft, {len(problem.conflicts)} conflicting pairs "
          f"-> {Path(args.out) / 'flights.json'}")
    return 0


def cmd_schedule(args) -> int:
    from uamopt.export.frame import schedule_provenance
    from uamopt.outputs import check_out_dir
    from uamopt.schedule import write_schedule
    from uamopt.schedule.verify import verify_dir
    from uamopt.solvers import load_profile, solve

    scenario = _load(args)
    profile = load_profile(args.solver)
    check_out_dir(args.out)
    provenance = schedule_provenance(scenario, args.set)  # frame and scenario for the exports
    with _progress(3, "schedule") as bar:
        problem = _scheduling_problem(scenario, args, bar)
        bar.set_description(profile.solver)
        schedule = solve(problem, profile)
        bar.update(1)
    write_schedule(args.out, problem, schedule, extra=provenance)
    problems = verify_dir(args.out)
    print(f"{schedule.solver}: {schedule.status}, objective {schedule.objective}, operated {schedule.operated_count}, "
          f"cancelled {schedule.cancelled}, total delay {schedule.total_delay_s:.1f} s, "
          f"{schedule.solve_seconds:.2f} s -> {Path(args.out) / 'schedule.csv'}")
    if problems:  # a solver bug, never bad input: say so loudly
        sys.stderr.write(f"error: the schedule failed verification ({len(problems)} violations, {args.out}): "
                         f"{problems[0]}\n")
        return 1
    return 0


def cmd_verify(args) -> int:
    from uamopt.schedule.verify import verify_dir

    problems = verify_dir(args.dir)
    for line in problems:
        print(line)
    if problems:
        print(f"{len(problems)} violations")
        return 1
    print(f"feasible and conflict-free: {args.dir}")
    return 0


def cmd_bench(args) -> int:
    import tempfile

    from uamopt.outputs import check_out_dir, staged_output
    from uamopt.scenario import load_scenario
    from uamopt.schedule import write_schedule
    from uamopt.schedule.verify import verify_dir
    from uamopt.solvers import load_profile, solve

    profiles = [load_profile(p) for p in args.solver]
    scenarios = [load_scenario(path, args.set) for path in args.scenario]
    check_out_dir(args.out)
    rows = []
    with _progress(len(scenarios) * (2 + len(profiles)), "bench") as bar:
        for scenario in scenarios:
            problem = _scheduling_problem(scenario, args, bar)
            for profile in profiles:
                bar.set_description(f"{scenario.name}: {profile.name}")
                schedule = solve(problem, profile)
                with tempfile.TemporaryDirectory() as tmp:
                    write_schedule(Path(tmp) / "s", problem, schedule)
                    verified = not verify_dir(Path(tmp) / "s")
                rows.append({"instance": scenario.name, "flights": problem.n_flights, "profile": profile.name,
                             "solver": profile.solver, "status": schedule.status, "objective": schedule.objective,
                             "bound": schedule.bound, "gap": schedule.gap, "operated": schedule.operated_count,
                             "cancelled": schedule.cancelled, "total_delay_s": schedule.total_delay_s,
                             "seconds": schedule.solve_seconds, "verified": "yes" if verified else "NO"})
                bar.update(1)
    keys = list(rows[0])
    with staged_output(args.out) as stage:
        with open(stage / "bench.csv", "w", encoding="utf-8") as fh:
            fh.write(",".join(keys) + "\n")
            for r in rows:
                fh.write(",".join("" if r[k] is None else str(r[k]) for k in keys) + "\n")
        fmt = lambda v: "-" if v is None else (f"{v:.6g}" if isinstance(v, float) else str(v))
        lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
        lines += ["| " + " | ".join(fmt(r[k]) for k in keys) + " |" for r in rows]
        (stage / "bench.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))
    return 0 if all(r["verified"] == "yes" for r in rows) else 1


def _toml_list(values) -> str:
    return "[" + ",".join(f"{float(v)!r}" for v in values) + "]"


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="uamopt", description="Urban Air Mobility risk fields, tracks and schedules.")
    parser.add_argument("--version", action="version", version="uamopt 0.1.0")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    def command(name: str, func, help_text: str, default_out: str):
        p = sub.add_parser(name, help=help_text, description=help_text)
        p.add_argument("scenario", help="scenario TOML file, e.g. models/paper_case.toml")
        p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="override a scenario key (dotted, TOML value), e.g. grid.cell=[10,10,10]")
        p.add_argument("--out", default=default_out, help=f"output folder (default: {default_out})")
        p.set_defaults(func=func)
        return p

    command("risk", cmd_risk, "compute the operational risk field: risk.npz, risk.png, summary.json", "out/risk")
    plan = command("plan", cmd_plan, "plan one track in four stages: tracks.json, tracks.png", "out/plan")
    plan.add_argument("--from", dest="origin", metavar="X,Y,Z|NAME",
                      help="origin, m, or a vertiport name (default: tracks.route / tracks.origin)")
    plan.add_argument("--to", dest="destination", metavar="X,Y,Z|NAME",
                      help="destination, m, or a vertiport name (default: tracks.route / tracks.destination)")
    command("network", cmd_network, "plan one track per route and direction: network.json, network.png", "out/network")
    flights = command("flights", cmd_flights, "generate the scenario's flight plan: flights.json (the instance "
                      "generator)", "out/flights")
    flights.add_argument("--seed", type=int, help="seed of the generated plan (default: schedule.plan_seed)")
    sched = command("schedule", cmd_schedule, "schedule the flights: flights.json, schedule.csv, summary.json", "out/schedule")
    for p in (sched,):
        p.add_argument("--solver", required=True, metavar="PROFILE", help="solver profile: solvers/NAME.toml or NAME")
    bench = sub.add_parser("bench", help="benchmark solver profiles on scenarios: bench.csv, bench.md",
                           description="benchmark solver profiles on scenarios: bench.csv, bench.md")
    bench.add_argument("scenario", nargs="+", help="scenario TOML files")
    bench.add_argument("--solver", nargs="+", required=True, metavar="PROFILE", help="solver profiles")
    bench.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override keys of every scenario")
    bench.add_argument("--out", default="out/bench", help="output folder (default: out/bench)")
    bench.set_defaults(func=cmd_bench)
    for p in (sched, bench):
        p.add_argument("--flights", help="flights.json to schedule instead of the generated plan")
        p.add_argument("--network", help="network.json whose routes the flights fly (default: planned now)")
        p.add_argument("--seed", type=int, help="seed of the generated plan (default: schedule.plan_seed)")
    verify = sub.add_parser("verify", help="check a schedule folder independently: exit 0 iff feasible and conflict-free",
                            description="check a schedule folder independently: exit 0 iff feasible and conflict-free")
    verify.add_argument("dir", help="folder with flights.json and schedule.csv")
    verify.set_defaults(func=cmd_verify)
    command("reproduce", cmd_reproduce, "run every stage that applies and write report.md with figures", "out/reproduce")
    from uamopt.export.cli import add_export_commands

    add_export_commands(sub)  # export bluesky | geojson, replay
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except UamoptError as exc:
        sys.stderr.write(f"error: {exc.line()}\n")
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        sys.stderr.write("error: interrupted (keyboard): nothing was written to --out\n")
        return 130


if __name__ == "__main__":
    sys.exit(main())
