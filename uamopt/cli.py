"""Command line: ``uamopt COMMAND SCENARIO [--set KEY=VALUE ...] [--out DIR]`` (docs/interfaces.md).

A thin layer: it parses arguments, calls the library (``uamopt.workflows``, ``uamopt.reproduce``)
and prints one line. Bad input ends with one line ``error: <what> (<where>): <how to fix>`` on
stderr and exit code 2; results are staged and moved into ``--out`` only when complete.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path

from uamopt.errors import UamoptError, printable

EXIT_BAD_INPUT = 2
_STARTED = time.perf_counter()  # the command's own clock (imports included)


class _Parser(argparse.ArgumentParser):
    """argparse with the project's one-line error and exit code 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"error: {printable(message)} (command line): see `{self.prog} --help`\n")
        raise SystemExit(EXIT_BAD_INPUT)


def _seed(text: str) -> int:
    """A seed on the command line: a whole number in [0, 2⁶³ − 1] (numpy's generators refuse
    negative seeds; the range of ``schedule.plan_seed``)."""
    from uamopt.bounds import INT64_MAX, shown

    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= INT64_MAX:
        raise argparse.ArgumentTypeError(f"{shown(text)} is not a whole number in [0, 2^63 - 1]")
    return value


def _load(args):
    from uamopt.scenario import load_scenario

    return load_scenario(args.scenario, args.set)


def cmd_risk(args) -> int:
    from uamopt.workflows import risk_folder

    field = risk_folder(_load(args), args.out, figures=not args.no_figures)
    s = field.summary()
    print(f"risk field: {s['cells']:,} cells, {100 * s['unsafe_share']:.1f} % unsafe, {s['seconds']['risk']:.2f} s "
          f"(whole command {time.perf_counter() - _STARTED:.2f} s) -> {Path(args.out) / 'risk.npz'}")
    return 0


def cmd_plan(args) -> int:
    from uamopt.planning.endpoints import default_endpoints, parse_endpoint
    from uamopt.workflows import plan_folder

    scenario = _load(args)
    origin, destination = default_endpoints(scenario) if None in (args.origin, args.destination) else (None, None)
    origin = parse_endpoint(scenario, args.origin, "--from") if args.origin is not None else origin
    destination = parse_endpoint(scenario, args.destination, "--to") if args.destination is not None else destination
    opt = plan_folder(scenario, args.out, origin, destination, figures=not args.no_figures).stages["optimal"]
    print(f"optimal track: {opt.length_m:.0f} m, ¥{opt.transport_cost:.2f}, risk {opt.risk_cost:.1f} "
          f"-> {Path(args.out) / 'tracks.json'}")
    return 0


def cmd_network(args) -> int:
    from uamopt.workflows import network_folder

    network = network_folder(_load(args), args.out, figures=not args.no_figures)
    print(f"network: {len(network)} tracks -> {Path(args.out) / 'network.json'}")
    return 0


def cmd_flights(args) -> int:
    from uamopt.workflows import flights_folder

    problem = flights_folder(_load(args), args.out, args.seed, model=args.model)
    print(f"flights: {problem.n_flights} flights, {problem.aircraft_count} aircraft, {len(problem.conflicts)} "
          f"conflicting pairs -> {Path(args.out) / 'flights.json'}"
          + (f" and {Path(args.out) / f'model.{args.model}'}" if args.model else ""))
    return 0


def cmd_schedule(args) -> int:
    from uamopt.solvers import load_profile, solver_module
    from uamopt.workflows import schedule_folder

    scenario = _load(args)
    profile = load_profile(args.solver)
    _warm_watchdog(profile.solver)
    if args.scheduler is not None:  # the windows solver's tasks on a running Dask cluster
        import dataclasses

        from uamopt.cluster import reach_scheduler
        from uamopt.errors import UamoptError

        if profile.solver != "windows":
            raise UamoptError(f"--scheduler is for the windows solver, not {profile.solver}", "--scheduler",
                              "use --solver windows, or drop --scheduler")
        reach_scheduler(args.scheduler)  # a malformed address, or nobody there: one line before the network is planned
        profile = dataclasses.replace(profile, options={**profile.options, "scheduler": args.scheduler})
    solver_module(profile.solver)  # a solver of an extra not installed: its one line before any work
    problem, s, problems = schedule_folder(scenario, args.out, profile, args.flights, args.network, args.seed, args.set)
    from uamopt.schedule.families.speed import collapse, speed_choice_of

    if speed_choice_of(problem) is not None:  # one row per flight, as schedule.csv (not one per speed copy)
        problem, s = collapse(problem, s)
    bound = (f", bound {s.bound:.6g} (gap {100.0 * s.gap:.2f} %)" if s.bound is not None and s.gap is not None
             and math.isfinite(s.gap) else "")
    print(f"{s.solver}: {s.status}, {problem.objective_kind} objective {s.objective}{bound}, operated {s.operated_count}, "
          f"cancelled {s.cancelled_count}, "
          f"total delay {s.total_delay_s:.1f} s, {s.solve_seconds:.2f} s -> {Path(args.out) / 'schedule.csv'}")
    if problems:  # a solver bug, never bad input: say so loudly
        sys.stderr.write(f"error: the schedule failed verification ({len(problems)} violations, {args.out}): "
                         f"{problems[0]}\n")
        return 1
    return 0


def cmd_view(args) -> int:
    import time

    from uamopt.export.folder import read_schedule_folder
    from uamopt.plotting.explore import explore

    started = time.perf_counter()
    if not (Path(args.dir) / "schedule.csv").is_file() and Path(args.dir).is_dir():
        pass  # a risk, plan, network or reproduce folder: explore checks it
    else:
        read_schedule_folder(args.dir)  # bad input first, in one line, before the risk field is computed
    out = Path(args.out) if args.out else Path(args.dir) / "view.html"
    if out.is_dir():
        raise UamoptError(f"--out is a folder: {out}", "--out", "give the HTML file to write, e.g. view.html")
    if not out.parent.is_dir():
        raise UamoptError(f"the folder of --out does not exist: {out.parent}", "--out", "create it or write elsewhere")
    view = explore(args.dir, risk=args.risk, scenario=args.scenario, overrides=args.set, step_s=args.step,
                   city=not args.no_city)
    path = view.save(out)
    frames = len(view.figure.frames)
    playback = f"{frames} frames, " if frames else "no playback, "
    rejected = view.spec["layout"].get("meta", {}).get("uamopt", {}).get("rejected") or []
    said = f"the verifier rejects {len(rejected)} flights (drawn red; uamopt verify lists why), " if rejected else ""
    print(printable(f"view: {playback}{said}{path.stat().st_size / 1e6:.1f} MB, {time.perf_counter() - started:.1f} s "
                    f"-> {path}"))
    return 0


def cmd_verify(args) -> int:
    """Read-only: verify writes nothing, so input it refuses leaves nothing behind."""
    from uamopt.schedule.verify import verify_dir

    try:
        problems = verify_dir(args.dir)
    except UamoptError as exc:  # the folder is untrusted: its error line must stay one line
        sys.stderr.write(f"error: {printable(exc.line())}\n")
        return EXIT_BAD_INPUT
    for line in problems:
        print(printable(line))
    print(f"{len(problems)} violations" if problems else f"feasible and conflict-free: {printable(str(args.dir))}")
    return 1 if problems else 0


#: ``bench --seeds N``: at most this many seeds as a count (each is a solve of every instance)
MAX_SEED_COUNT = 10_000


def _warm_watchdog(*solvers: str) -> None:
    """Start the forkserver of the watched solves while the command builds its problem
    (uamopt/solvers/watchdog.py): the first solve then does not spend its limit on imports."""
    from uamopt.solvers import SOLVERS
    from uamopt.solvers.watchdog import WATCHED, warm

    if any(s in WATCHED or s not in SOLVERS for s in solvers):  # a profile's path: it may name one
        warm()


def cmd_bench(args) -> int:
    from uamopt.experiments.benchmark import cmd_bench as bench

    _warm_watchdog(*(args.solver or ["highs"]))
    if args.seeds and len(args.seeds) == 1 and args.seeds[0] > MAX_SEED_COUNT:
        raise UamoptError(f"--seeds {args.seeds[0]} asks for more than {MAX_SEED_COUNT:,} runs per profile", "--seeds",
                          "give a count up to that (--seeds 3 runs seeds 0, 1, 2) or list the seeds (--seeds 0 7)")

    return bench(args)


def cmd_reproduce(args) -> int:
    from uamopt.reproduce import reproduce

    print(f"report: {reproduce(_load(args), args.out, args.set, figures=not args.no_figures)}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="uamopt", description="Urban Air Mobility risk fields, tracks and schedules.")
    from uamopt import __version__

    parser.add_argument("--version", action="version", version=f"uamopt {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    def command(name: str, func, help_text: str, default_out: str, figures: bool = True):
        p = sub.add_parser(name, help=help_text, description=help_text)
        p.add_argument("scenario", help="scenario TOML file, e.g. models/paper_case.toml, or a shipped scenario's name "
                       "(paper_case)")
        p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="override a scenario key (dotted, TOML value), e.g. grid.cell=[10,10,10]")
        p.add_argument("--out", default=default_out, help=f"output folder (default: {default_out})")
        if figures:
            p.add_argument("--no-figures", action="store_true", help="write the data files only, no PNG")
        p.set_defaults(func=func)
        return p

    def flight_sources(p, seed_only: bool = False):
        p.add_argument("--seed", type=_seed, help="seed of the generated plan (default: schedule.plan_seed)")
        if not seed_only:
            p.add_argument("--flights", help="flights.json to schedule instead of the generated plan")
            p.add_argument("--network", help="network.json whose routes the flights fly (default: planned now)")

    command("risk", cmd_risk, "compute the operational risk field: risk.npz, risk.png, summary.json", "out/risk")
    plan = command("plan", cmd_plan, "plan one track in four stages: tracks.json, tracks.png", "out/plan")
    plan.add_argument("--from", dest="origin", metavar="X,Y,Z|NAME",
                      help="origin, m, or a vertiport name (default: tracks.route / tracks.origin)")
    plan.add_argument("--to", dest="destination", metavar="X,Y,Z|NAME",
                      help="destination, m, or a vertiport name (default: tracks.route / tracks.destination)")
    command("network", cmd_network, "plan one track per route and direction: network.json, network.png", "out/network")
    flights = command("flights", cmd_flights, "generate the scenario's flight plan: flights.json (the instance "
                      "generator)", "out/flights", figures=False)
    flight_sources(flights, seed_only=True)
    flights.add_argument("--model", choices=("mps", "lp"),
                         help="also write the exact MILP as model.mps or model.lp, with model.*.columns.json mapping "
                              "its variables to the flights (for any MILP solver; docs/interfaces.md)")
    sched = command("schedule", cmd_schedule, "schedule the flights: flights.json, schedule.csv, summary.json",
                    "out/schedule", figures=False)
    sched.add_argument("--solver", required=True, metavar="PROFILE", help="solver profile: solvers/NAME.toml or NAME")
    sched.add_argument("--scheduler", metavar="ADDRESS",
                       help="the windows solver: a running Dask scheduler, e.g. tcp://127.0.0.1:8786 (default: a local cluster)")
    flight_sources(sched)
    bench = sub.add_parser("bench", help="benchmark solver profiles × seeds on scenarios: bench.csv, bench.md",
                           description="benchmark solver profiles × seeds on scenarios: bench.csv, bench.md")
    bench.add_argument("scenario", nargs="+", help="scenario TOML files, or OR-Library airland .txt files")
    bench.add_argument("--solver", nargs="+", action="extend", required=True, metavar="PROFILE", help="solver profiles")
    bench.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override keys of every scenario")
    bench.add_argument("--out", default="out/bench", help="output folder (default: out/bench)")
    bench.add_argument("--seeds", nargs="+", type=_seed, metavar="SEED",
                       help="solver seeds: a count (--seeds 3 = 0 1 2) or a list (--seeds 0 1 2); default each profile's")
    bench.add_argument("--time-limit", type=float, metavar="SECONDS", help="time limit of every solver (default: each profile's)")
    bench.add_argument("--against", metavar="FILE", help="results file of best known values (benchmarks/results.json): "
                       "each run's distance to them in bench.csv and bench.md (docs/benchmarks.md)")
    bench.add_argument("--update", action="store_true", help="with --against: record this run's better verified "
                       "objectives and bounds in FILE (rewritten atomically; created if missing)")
    bench.add_argument("--scheduler", metavar="ADDRESS",
                       help="the windows profiles: a running Dask scheduler, e.g. tcp://127.0.0.1:8786 "
                       "(default: a local cluster)")
    bench.set_defaults(func=cmd_bench)
    flight_sources(bench)
    verify = sub.add_parser("verify", help="check a schedule folder independently: exit 0 iff feasible and conflict-free",
                            description="check a schedule folder independently: exit 0 iff feasible and conflict-free")
    verify.add_argument("dir", help="folder with flights.json and schedule.csv")
    verify.set_defaults(func=cmd_verify)
    view = sub.add_parser("view", help="write an offline interactive 3-D view of a schedule folder (one HTML file)",
                          description="write an offline interactive 3-D view of a schedule folder: the city, the "
                          "unsafe airspace per layer, the tracks and the flights played back (one HTML file, no network)")
    view.add_argument("dir", help="a folder written by uamopt schedule (with playback), risk, plan, network or reproduce")
    view.add_argument("--out", help="the HTML file (default: DIR/view.html)")
    view.add_argument("--risk", help="risk.npz of the same scenario (default: recompute from the recorded one)")
    view.add_argument("--scenario", help="scenario TOML when the folder records none")
    view.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override a scenario key")
    view.add_argument("--step", type=float, metavar="SECONDS", help="playback clock step (default 10 s)")
    view.add_argument("--no-city", action="store_true", help="leave out the buildings and the unsafe airspace")
    view.set_defaults(func=cmd_view)
    command("reproduce", cmd_reproduce, "run every stage that applies and write report.md with figures", "out/reproduce")
    from uamopt.cli_export import add_export_commands
    from uamopt.experiments.commands import add_sweep_command

    add_sweep_command(sub)
    add_export_commands(sub)  # export bluesky | geojson, replay
    return parser


def _interrupted(args, interrupt: KeyboardInterrupt) -> int:
    """One line for Ctrl-C or SIGTERM, true about what is in the output folder."""
    from uamopt.interrupts import describe, handled
    from uamopt.outputs import published

    folder = getattr(args, "out", None) or getattr(args, "dir", None)
    line = describe(interrupt) + ": nothing was written"  # args None: before the command line was read
    if folder:
        line = (f"{describe(interrupt)}: the results in {folder} were complete before the interrupt" if published(folder)
                else f"{line} to {folder}")
    sys.stderr.write(printable(line) + "\n")
    return handled(interrupt)


def _warning_line(message, category, filename, lineno, file=None, line=None) -> None:
    """uamopt's own warnings (e.g. TrackWeightsWarning) as one ``warning: ...`` line on stderr;
    every other library's warning as Python prints it."""
    if getattr(category, "__module__", "").startswith("uamopt"):
        text = " ".join(str(message).split())  # one line whatever the message holds
        (file or sys.stderr).write(f"warning: {text}\n")
    else:
        _PYTHON_SHOWWARNING(message, category, filename, lineno, file, line)


_PYTHON_SHOWWARNING = warnings.showwarning


def _out_of_memory(args, exc: MemoryError) -> str:
    """The one line of a run that ran out of memory; the staging folder is gone, ``--out`` untouched."""
    detail = " ".join(str(exc).split()) or "an allocation failed"
    return UamoptError(f"out of memory: {detail}", f"uamopt {args.command}",
                       "use larger cells (grid.cell), a smaller grid.extent or fewer flights; grid.memory_limit_gb and "
                       "schedule.memory_limit_gb (default: 80 % of the memory, within ulimit -v) refuse such runs up "
                       "front; nothing was written").line()


def main(argv: list[str] | None = None) -> int:
    """Run one command; returns its exit code (0, 1 for ``verify``'s violations, 2 bad input, 130/143 interrupted)."""
    if argv is None:  # the process's own command line (the console script)
        import atexit
        import signal

        # registered before any library's exit hook, so it runs after them all: what is left of
        # the shutdown is the interpreter's own teardown, where Python drops its handlers and a
        # signal would kill the finished command (exit -2 / -15, no line)
        atexit.register(lambda: [signal.signal(s, signal.SIG_IGN) for s in (signal.SIGINT, signal.SIGTERM)])
    code = None
    try:
        code = _main(argv)
        if argv is None:  # the command is over
            _exit_on_signal(code)
            _end_process(code)
    except KeyboardInterrupt:  # the signal came after the command ended, before the handlers above took over
        if code is None or argv is not None:
            raise
        _finish(code)
    return code


def _exit_on_signal(code: int) -> None:
    """A Ctrl-C or SIGTERM while the interpreter shuts down (waiting for library threads, their exit
    hooks: 0.5 s and more on a loaded machine) finds the command finished: exit with its code at
    once, instead of a traceback or a finished run killed by the signal with no line."""
    import signal

    def finished(signum, frame) -> None:
        _finish(code)

    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, finished)


def _end_process(code: int) -> None:
    """End the finished command's process as the interpreter would, minus its teardown.

    What a normal exit does first is kept: wait for the threads that are not daemons, then run the
    exit hooks (atexit: logging's flush, Dask's and multiprocessing's clean-ups, weakref
    finalizers such as TemporaryDirectory's). Then the process ends with the command's code. The
    teardown that would follow (modules and thread states freed) is skipped: on CPython 3.11 a
    daemon or native thread of a library that re-enters Python during it aborts the process with
    "Fatal Python error: PyEval_RestoreThread ... Python runtime state: finalizing" and exit -6
    (CPython gh-87135; seen once in 40 SIGTERM trials of ``uamopt risk``, after the command had
    printed its line). Every file uamopt writes is closed before its command returns.
    """
    import atexit
    import threading

    current = threading.current_thread()
    for thread in threading.enumerate():
        if thread is not current and not thread.daemon:
            thread.join()
    atexit._run_exitfuncs()
    _finish(code)


def _finish(code: int) -> None:
    """End the process now with the finished command's exit code (its output flushed)."""
    import os

    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except Exception:  # noqa: BLE001 - a closed or broken stream: nothing more to say
            pass
    os._exit(code)


def _shipped_files(args) -> None:
    """A scenario or sweep file that is no file where the command runs but names a shipped one
    (``paper_case``, ``models/paper_case.toml`` outside a checkout, ``variants/speed``) is the
    shipped one (:func:`uamopt.shipped.scenario_path`)."""
    from uamopt.shipped import scenario_path

    for key in ("scenario", "sweep"):
        value = getattr(args, key, None)
        if isinstance(value, str):
            setattr(args, key, str(scenario_path(value)))
        elif isinstance(value, list):
            setattr(args, key, [str(scenario_path(v)) if isinstance(v, str) else v for v in value])


def _main(argv: list[str] | None) -> int:
    try:  # a Ctrl-C while the handlers are installed or the command line is read: one line too
        from uamopt.interrupts import install_handlers, interrupt_of

        install_handlers()  # SIGTERM cleans up like Ctrl-C (uamopt.interrupts)
        warnings.showwarning = _warning_line
        args = build_parser().parse_args(argv)
    except KeyboardInterrupt as exc:
        return _interrupted(None, exc)
    try:
        _shipped_files(args)  # inside: a signal while it imports (importlib.resources, typing) is one line too
        return args.func(args)
    except UamoptError as exc:
        sys.stderr.write(f"error: {exc.line()}\n")
        return EXIT_BAD_INPUT
    except ModuleNotFoundError as exc:  # an optional package imported where no uamopt.optional.need names its extra
        from uamopt.optional import missing_extra

        missing = missing_extra(exc)
        if missing is None:
            raise
        sys.stderr.write(f"error: {missing.line()}\n")
        return EXIT_BAD_INPUT
    except MemoryError as exc:  # past the memory guards (an address-space limit, ulimit -v): one line, not a traceback
        sys.stderr.write(f"error: {_out_of_memory(args, exc)}\n")
        return EXIT_BAD_INPUT
    except Exception as exc:
        interrupt = interrupt_of(exc)  # a library that wrapped the KeyboardInterrupt in its own error
        if interrupt is None:
            raise
        return _interrupted(args, interrupt)
    except KeyboardInterrupt as exc:
        return _interrupted(args, exc)
