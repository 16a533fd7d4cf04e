"""Solver benchmarks: ``uamopt bench`` and :func:`benchmark` (a loop, not a special case: every
solver takes the same :class:`~uamopt.schedule.SchedulingProblem` and returns a Schedule).

One row per instance × profile × seed (``COLUMNS``): the instance's name and size (flights,
aircraft G, conflicting pairs), the profile, its solver, seed, threads and the time limit it was
given, the objective kind (Eq. 20 ``weighted`` or ``lexicographic``), the solver's status,
objective, bound and relative gap (NaN where undefined: no incumbent, no bound, or an objective
of 0), operated S (Eq. 22), cancelled, total and average delay (Eq. 21), and three times:
``wall_seconds`` around the whole call, ``solve_seconds`` as the solver reports it (HiGHS's and
CP-SAT's own clocks, which the time limit bounds) and ``build_seconds`` = wall − solve (model
building, data transfer). Before the timed runs each solver runs once, untimed, on a few flights
(:func:`warm_up`), so no row carries a process's one-time costs (imports, helper processes).
``verified`` is the independent verifier's verdict on the written schedule
(uamopt/schedule/verify.py), for every row. Last, where the instance came from: ``plan_seed`` (the
seed of its generated flight plan; empty for an airland file or a ``--flights`` plan),
``scenario`` (the file) and ``set`` (the overrides, a JSON list), so that a row can be run again
and recorded in a results file (``--against FILE --update``, uamopt/experiments/results.py).
``trace`` (a JSON list) is the run's progress: ``[seconds, best objective, best bound]`` each time
either improved (null until the first), ending at the answer (uamopt.solvers.watchdog.trace_of;
a heuristic's is its answer alone): bench.md's *over time* section and ``convergence.png``.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from pathlib import Path

from uamopt.checks import expect
from uamopt.errors import UamoptError
from uamopt.experiments.case import error_line, schedule_row, scheduling_problem
from uamopt.progress import Progress

COLUMNS = ["instance", "flights", "aircraft", "conflicting_pairs", "solver", "profile", "seed", "threads", "time_limit_s",
           "objective_kind", "status", "termination", "proved_for", "model", "objective", "bound", "gap", "operated",
           "cancelled", "total_delay_s",
           "avg_delay_s", "wall_seconds", "solve_seconds", "build_seconds", "verified", "error", "plan_seed", "scenario",
           "set", "trace"]


def instance_name(scenario, overrides=()) -> str:
    """The scenario's name and the overrides that made the instance: ``paper_case[schedule.aircraft=10]``."""
    return f"{scenario.name}[{','.join(overrides)}]" if overrides else scenario.name


def scenario_problem(scenario, seed: int = 0):
    """The scenario's scheduling instance: its route network planned (Sec. 6.2) and its generated
    flight plan (plan seed ``schedule.plan_seed + seed``)."""
    from uamopt.pipeline import compute_risk, plan_network, planning_model

    return scheduling_problem(scenario, plan_network(planning_model(scenario, compute_risk(scenario, keep_risk=False))), seed)


def _instances(problem_or_scenarios, sources: dict | None = None) -> dict:
    """name -> SchedulingProblem from a problem, a scenario (object or file), or a list / dict of them;
    ``sources`` (when given) gets name -> the instance's plan seed, scenario file and overrides."""
    from uamopt.scenario import Scenario, load_scenario
    from uamopt.schedule import SchedulingProblem

    items = problem_or_scenarios
    if isinstance(items, dict):
        named = list(items.items())
    else:
        items = list(items) if isinstance(items, (list, tuple)) else [items]
        named = [(None, item) for item in items]
    out: dict = {}
    for i, (name, item) in enumerate(named):
        source = {}
        if isinstance(item, (str, Path)):
            source["scenario"] = str(item)
            item = load_scenario(item)
        if isinstance(item, Scenario):
            source |= {"plan_seed": item.schedule.plan_seed, "set": []}
            name, item = name or instance_name(item), scenario_problem(item)
        if not isinstance(item, SchedulingProblem):
            raise TypeError("benchmark(): problem_or_scenarios must be a SchedulingProblem, Scenario or path "
                            f"(or a list or dict of them), got {type(item).__name__}")
        name = name or f"instance{i + 1}"
        if name in out:
            name = f"{name}#{i + 1}"
        out[name] = item
        if sources is not None:
            sources[name] = source
    return out


def _checked_seeds(seeds) -> list[int] | None:
    """``benchmark``'s ``seeds``: None, or a sequence of distinct solver seeds 0 to SEED_MAX (32-bit,
    as a profile's ``seed``); else ``TypeError`` (not a list of integers) or ``UamoptError`` (out of
    range, none, repeated: ``--seeds`` too), naming ``seeds``, before anything runs."""
    import numpy as np

    from uamopt.solvers.options import SEED_MAX

    if seeds is None:
        return None
    rule = f"benchmark(): seeds must be None or a list of solver seeds, integers from 0 to {SEED_MAX} (e.g. [0, 1, 2])"
    if not isinstance(seeds, (list, tuple, range, np.ndarray)):
        raise TypeError(f"{rule}, got {type(seeds).__name__}")
    for seed in seeds:
        if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)):
            raise TypeError(f"{rule}, got a {type(seed).__name__} ({str(seed)[:40]!r})")
    bad = next((seed for seed in seeds if not 0 <= seed <= SEED_MAX), None)
    if bad is not None or len(seeds) == 0 or len(set(map(int, seeds))) != len(seeds):
        got = f"the seed {str(bad)[:40]}" if bad is not None else f"{list(seeds)!r}"[:200]
        raise UamoptError(f"the solver seeds must be distinct integers from 0 to {SEED_MAX}, at least one, got {got}",
                          "benchmark(seeds=...) / --seeds", "give e.g. [0, 1, 2] (HiGHS and CP-SAT take 32-bit seeds)")
    return [int(seed) for seed in seeds]


def _profiles(solvers, time_limit_s):
    import os

    from uamopt.solvers import SolverProfile, load_profile, solver_module

    items = [solvers] if isinstance(solvers, (str, os.PathLike, SolverProfile)) else solvers
    if not isinstance(items, (list, tuple)) or not all(isinstance(s, (str, os.PathLike, SolverProfile)) for s in items):
        bad = items if not isinstance(items, (list, tuple)) else next(s for s in items
                                                                      if not isinstance(s, (str, os.PathLike, SolverProfile)))
        raise TypeError("benchmark(): solvers must be a list of profiles (names such as 'greedy', paths or SolverProfile), "
                        f"got {type(bad).__name__}")
    profiles = [s if isinstance(s, SolverProfile) else load_profile(s) for s in items]
    for profile in profiles:  # a solver of an extra not installed: its one line, not a table of error rows
        solver_module(profile.solver)
    if not profiles:
        raise UamoptError("no solver profile given", "benchmark(solvers=...) / --solver",
                          "give at least one profile, e.g. ['greedy', 'highs']")
    if time_limit_s is not None:
        if not (isinstance(time_limit_s, (int, float)) and math.isfinite(time_limit_s) and time_limit_s > 0):
            raise UamoptError(f"the time limit must be a positive number of seconds, got {time_limit_s!r}", "--time-limit",
                              "give seconds, e.g. 20")
        profiles = [dataclasses.replace(p, time_limit_s=float(time_limit_s)) for p in profiles]
    return profiles


def warm_up(problems, profiles) -> None:
    """Run each solver once, untimed, on the first aircraft's flights of an instance: the one-time
    costs of a process (imports, HiGHS or OR-Tools helper processes) then stay out of the rows."""
    from uamopt.pipeline import build_problem, solve

    problem = next(iter(problems))
    first = problem.flights.flights[0].aircraft
    tiny = dataclasses.replace(problem.flights, flights=tuple(f for f in problem.flights.flights if f.aircraft == first))
    if problem.objective_terms is not None or problem.extra_families:  # not a flight plan's model: warm up on it
        tiny_problem = problem
    else:
        tiny_problem = build_problem(tiny, objective=problem.objective_kind, weights=problem.weights)
    for profile in {p.solver: p for p in profiles}.values():
        try:
            solve(tiny_problem, profile, time_limit_s=min(5.0, profile.time_limit_s))
        except Exception:  # noqa: BLE001 - a broken solver shows in its own rows
            pass


def solve_row(name: str, problem, profile, seed: int) -> dict:
    """One benchmark row: solve, time, verify; a solver failure is an ``error`` row."""
    from uamopt.pipeline import solve

    row = {"instance": name, "flights": problem.n_flights, "aircraft": problem.aircraft_count,
           "conflicting_pairs": len(problem.pairs), "solver": profile.solver, "profile": profile.name or profile.solver,
           "seed": seed, "threads": profile.threads, "time_limit_s": profile.time_limit_s,
           "objective_kind": problem.objective_kind}
    t0 = time.perf_counter()
    try:
        schedule = solve(problem, profile, seed=seed)
        wall = time.perf_counter() - t0
        row.update(schedule_row(problem, schedule, wall))
        row.update(wall_seconds=wall, solve_seconds=schedule.solve_seconds,
                   build_seconds=max(0.0, wall - schedule.solve_seconds),
                   trace=json.dumps(schedule.extras.get("trace", [])))
    except Exception as exc:  # noqa: BLE001 - one failing solver must not end a benchmark
        row.update(status="error", error=error_line(exc), wall_seconds=time.perf_counter() - t0)
    row.pop("seconds", None)
    return row


def benchmark(problem_or_scenarios, solvers, seeds=None, time_limit_s: float | None = None, *, progress: bool = True,
              sources: dict | None = None):
    """Run every solver profile with every seed on every instance; one row per run (``COLUMNS``).

    Parameters
    ----------
    problem_or_scenarios : SchedulingProblem, Scenario, path, or a list or dict (name -> item) of them
        A scenario is turned into its instance (network planned, flights generated).
    solvers : sequence of str, Path or SolverProfile
        Profiles (``"highs"``, ``"solvers/soa.toml"``).
    seeds : sequence of int, optional
        Solver seeds, distinct, 0 to 2³¹ − 1 (each profile's own seed when omitted).
    time_limit_s : float, optional
        Applied to every profile instead of its own ``time_limit_s``.
    progress : bool
        A bar on a terminal, else a line per finished solve on stderr.
    sources : dict, optional
        Instance name -> ``{"plan_seed": int or None, "scenario": path, "set": [overrides]}``: the
        ``plan_seed``, ``scenario`` and ``set`` columns (a scenario given as such fills its own).

    Returns
    -------
    pandas.DataFrame

    Examples
    --------
    ::

        table = benchmark("models/paper_case.toml", ["greedy", "soa", "highs"], seeds=[0, 1, 2], time_limit_s=30)
        table.groupby("profile")["objective"].median()
    """
    import pandas as pd

    seeds = _checked_seeds(seeds)
    expect(progress, bool, "progress", "benchmark")
    if sources is not None and not (isinstance(sources, dict) and all(isinstance(v, dict) for v in sources.values())):
        bad = sources if not isinstance(sources, dict) else next(v for v in sources.values() if not isinstance(v, dict))
        raise TypeError("benchmark(): sources must be None or a dict of instance name -> {'plan_seed': ..., 'scenario': "
                        f"..., 'set': [...]}}, got {type(bad).__name__}{'' if bad is sources else ' as a value'}")
    profiles = _profiles(solvers, time_limit_s)
    found: dict = {}
    instances = _instances(problem_or_scenarios, found)
    found |= sources or {}
    runs = [(name, p, s) for name in instances for p in profiles for s in (seeds if seeds is not None else [p.seed])]
    warm_up(instances.values(), profiles)
    rows = []
    bar = Progress(len(runs), "bench", "solves", every=True, stream=None) if progress else None
    for name, profile, seed in runs:
        row = solve_row(name, instances[name], profile, int(seed))
        source = found.get(name, {})
        row.update(plan_seed=source.get("plan_seed"), scenario=source.get("scenario"),
                   set=json.dumps(list(source["set"])) if "set" in source else None)
        rows.append(row)
        if bar is not None:
            objective = row.get("objective")
            shown = f"{objective:.6g}" if isinstance(objective, float) and math.isfinite(objective) else "-"
            bar.update(1, f"{name} {row['profile']} seed {seed}: {row['status']} {shown} in {row['wall_seconds']:.1f} s")
    if bar is not None:
        bar.close()
    table = pd.DataFrame.from_records(rows, columns=COLUMNS)
    for column in ("objective", "bound", "gap", "total_delay_s", "avg_delay_s", "wall_seconds", "solve_seconds", "build_seconds"):
        table[column] = table[column].astype("float64")
    table["plan_seed"] = table["plan_seed"].astype("Int64")
    return table


def _against(args):
    """``--against FILE`` read and checked before anything runs (None without it); with
    ``--update`` a FILE that does not exist yet is an empty one, created at the end."""
    import os

    from uamopt.experiments.results import Results, read_results

    against, update = getattr(args, "against", None), getattr(args, "update", False)
    if update and not against:
        raise UamoptError("--update needs --against FILE", "--update",
                          "name the results file to update: --against benchmarks/results.json --update")
    if not against:
        return None
    if args.flights or args.network:
        raise UamoptError("--against compares instances the results file can name (scenario, --set, plan seed); a "
                          "--flights or --network instance is not one", "--against",
                          "bench the scenario's generated plan (--seed picks it), or leave out --against")
    path = Path(against)
    folder = path.parent
    if update and not (folder.is_dir() and os.access(folder, os.W_OK | os.X_OK)):  # the file is replaced from there
        raise UamoptError(f"cannot write the results file {path}: its folder does not exist or is not writable",
                          "--update", "create the folder first, or give another path")
    return read_results(path) if path.exists() or not update else Results()


def _record(args, table_path: Path) -> None:
    """``--update``: the bench.csv just written merged into the results file; one line each."""
    import sys

    from uamopt.errors import printable
    from uamopt.experiments.results import update_results

    changes, skipped = update_results(args.against, table_path)
    for line in changes:
        print(printable(f"results: {args.against}: {line}"))
    if not changes:
        print(printable(f"results: {args.against} unchanged (no verified run improves it)"))
    for line in skipped:
        sys.stderr.write(f"warning: {printable(f'not recorded in {args.against}: {line}')}\n")


def cmd_bench(args) -> int:
    """``uamopt bench``: the instances of the scenarios (or --flights), every profile × seed;
    ``--against FILE`` compares each run with the best known values, ``--update`` records them."""
    import sys

    from uamopt.errors import printable
    from uamopt.experiments.bench_report import write_bench
    from uamopt.experiments.results import compare
    from uamopt.outputs import output_lock
    from uamopt.scenario import load_scenario

    results = _against(args)  # before anything runs or is written
    seeds = None
    if args.seeds:
        seeds = list(range(args.seeds[0])) if len(args.seeds) == 1 else list(args.seeds)
        if not seeds or len(set(seeds)) != len(seeds):
            raise UamoptError(f"--seeds {' '.join(map(str, args.seeds))} gives no distinct seeds", "--seeds",
                              "give a count (--seeds 3 runs seeds 0, 1, 2) or two or more seeds (--seeds 0 1 2)")
        _checked_seeds(seeds)  # 32-bit solver seeds, before any instance is built
    profiles = _profiles(args.solver, args.time_limit)
    if getattr(args, "scheduler", None) is not None:  # the windows profiles' tasks on a running Dask cluster
        from uamopt.cluster import reach_scheduler

        if not any(p.solver == "windows" for p in profiles):
            raise UamoptError(f"--scheduler is for the windows solver, not {', '.join(p.solver for p in profiles)}",
                              "--scheduler", "add a windows profile (--solver windows), or drop --scheduler")
        # a malformed address, or one where no scheduler answers now, is bad input (one line, exit 2,
        # nothing written: as `schedule` and `sweep`); a cluster that goes away between runs is that
        # run's error row
        reach_scheduler(args.scheduler)
        profiles = [dataclasses.replace(p, options={**p.options, "scheduler": args.scheduler})
                    if p.solver == "windows" else p for p in profiles]
    airland = [path for path in args.scenario if is_airland(path)]  # OR-Library landing files: instances as they are
    if airland and (args.set or args.flights or args.network):
        raise UamoptError("--set, --flights and --network do not apply to an airland file", airland[0],
                          "bench airland files on their own, or scenarios with those options")
    scenarios = {path: load_scenario(path, args.set) for path in args.scenario if path not in airland}
    with output_lock(args.out):  # held from the first instance to the written report (and results file)
        instances, sources = {}, {}
        for path in args.scenario:
            if path in airland:
                from uamopt.schedule.airland import read_airland

                name, problem = Path(path).stem, read_airland(path)
                source = {"plan_seed": None, "scenario": path, "set": []}
            else:
                scenario = scenarios[path]
                name, problem = instance_name(scenario, args.set), _cli_problem(scenario, args)
                plan_seed = None if args.flights else scenario.schedule.plan_seed if args.seed is None else args.seed
                source = {"plan_seed": plan_seed, "scenario": path, "set": list(args.set)}
            name = name if name not in instances else f"{name}#{len(instances) + 1}"
            instances[name], sources[name] = problem, source
        table = benchmark(instances, profiles, seeds=seeds, sources=sources)
        comparison = compare(table, results, str(args.against)) if results is not None else None
        text = write_bench(args.out, comparison.table if comparison is not None else table, comparison)
        print(text)
        for line in comparison.warnings() if comparison is not None else []:
            sys.stderr.write(f"warning: {printable(line)}\n")
        if results is not None and args.update:
            _record(args, Path(args.out) / "bench.csv")
    return 0 if bool(table["verified"].fillna(False).all()) else 1


def is_airland(path) -> bool:
    """An OR-Library aircraft-landing file (``airland*.txt``, or any ``.txt``): not a scenario."""
    return Path(str(path)).suffix.lower() == ".txt"


def _cli_problem(scenario, args):
    """--flights (self-contained or on --network routes), else the generated plan (--seed)."""
    from uamopt.pipeline import checked_network, scenario_flights
    from uamopt.schedule import build_problem

    seed = 0 if args.seed is None else args.seed - scenario.schedule.plan_seed
    if not args.flights:
        if args.network:
            return scheduling_problem(scenario, checked_network(scenario, args.network), seed)
        return scenario_problem(scenario, seed)
    flights = scenario_flights(scenario, args.flights, args.network)
    return build_problem(flights, scenario, objective=scenario.schedule.objective)
