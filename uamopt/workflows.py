"""What each command does, as library functions: run the stages (``uamopt.pipeline``) and write a
complete output folder (staged, moved into place only when complete; docs/interfaces.md).

Each ``*_folder`` function returns the in-memory result, so a notebook can write the same folder a
command writes. ``figures=False`` skips the PNGs (``--no-figures``).
"""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

from uamopt.scenario import Scenario


def progress(total: int, desc: str):
    """A progress bar on a terminal; elsewhere plain lines once the work has run 5 s
    (:class:`uamopt.progress.Steps`)."""
    from uamopt.progress import Steps

    return Steps(total, desc)


def write_risk(field, scenario: Scenario, folder: Path, figures: bool = True) -> dict:
    """risk.npz, summary.json (and risk.png) of a computed field into ``folder``; the summary."""
    from uamopt.io import save_risk

    save_risk(field, folder)
    if figures:
        from uamopt import plotting

        plotting.save(plotting.risk(field, vertiports=scenario.network.vertiports,
                                    cruise_altitude_m=scenario.network.cruise_altitude_m, title=scenario.name),
                      folder / "risk.png")
    return field.summary()


def write_network(network, model, scenario: Scenario, folder: Path, figures: bool = True) -> None:
    """network.json (and network.png) into ``folder``."""
    from uamopt.io import save_network

    save_network(network, folder)
    if figures:
        from uamopt import plotting

        plotting.save(plotting.network(model, network.waypoints(), vertiports=scenario.network.vertiports),
                      folder / "network.png")


def risk_folder(scenario: Scenario, out: str | Path, figures: bool = True):
    """``uamopt risk``: the risk field and its folder."""
    from uamopt.outputs import check_out_dir, staged_output
    from uamopt.pipeline import compute_risk

    check_out_dir(out)
    with progress(2, "risk") as bar, staged_output(out) as stage:
        field = compute_risk(scenario)
        bar.update(1)
        write_risk(field, scenario, stage, figures)
        bar.update(1)
    return field


def plan_folder(scenario: Scenario, out: str | Path, origin=None, destination=None, figures: bool = True):
    """``uamopt plan``: the four stages between two end points (default: the scenario's route)."""
    from uamopt.io import save_tracks
    from uamopt.outputs import check_out_dir, staged_output
    from uamopt.pipeline import compute_risk, plan_track, planning_model

    check_out_dir(out)
    with progress(3, "plan") as bar, staged_output(out) as stage:
        model = planning_model(scenario, compute_risk(scenario, keep_risk=False))
        bar.update(1)
        plan = plan_track(model, origin, destination)
        bar.update(1)
        save_tracks(plan, stage, scenario)
        if figures:
            from uamopt import plotting

            plotting.save(plotting.tracks(plan, model, title=scenario.name), stage / "tracks.png")
        bar.update(1)
    return plan


def network_folder(scenario: Scenario, out: str | Path, figures: bool = True):
    """``uamopt network``: one planned track per route and direction."""
    from uamopt.outputs import check_out_dir, staged_output
    from uamopt.pipeline import compute_risk, plan_network, planning_model

    check_out_dir(out)
    with progress(2 + 2 * len(scenario.network.route_list()), "network") as bar, staged_output(out) as stage:
        model = planning_model(scenario, compute_risk(scenario, keep_risk=False))
        bar.update(2)
        network = plan_network(model, progress=bar)
        write_network(network, model, scenario, stage, figures)
    return network


def flights_folder(scenario: Scenario, out: str | Path, seed: int | None = None, model: str | None = None):
    """``uamopt flights``: the generated plan as a self-contained flights.json (instance generator);
    with ``model`` ("mps" or "lp") also the exact MILP as ``model.mps`` / ``model.lp`` and its
    variable mapping (uamopt/solvers/model_files.py), for any MILP solver."""
    from uamopt.outputs import check_out_dir, staged_output, write_json
    from uamopt.pipeline import build_problem, scenario_flights
    from uamopt.schedule import save_flights

    check_out_dir(out)
    with progress(2, "flights") as bar, staged_output(out) as stage:
        flights = scenario_flights(scenario, seed=seed)
        bar.update(1)
        problem = build_problem(flights, scenario)
        save_flights(stage / "flights.json", flights)
        if model is not None:
            from uamopt.solvers.model_files import write_model

            write_model(problem, stage / f"model.{model}")
        write_json(stage / "summary.json", {
            "scenario": scenario.name, "flights": len(flights), "aircraft": flights.n_aircraft,
            "vertiports": len(scenario.network.vertiports), "directed_routes": 2 * len(scenario.network.route_list()),
            "tracks": scenario.network.tracks, "conflicting_pairs": len(problem.conflicts),
            "seed": scenario.schedule.plan_seed if seed is None else seed, "plan_notes": list(flights.notes)})
        bar.update(1)
    return problem


def schedule_folder(scenario: Scenario, out: str | Path, profile, flights_file=None, network_file=None,
                    seed: int | None = None, overrides: list[str] | None = None):
    """``uamopt schedule``: solve and write flights.json, schedule.csv, summary.json; returns
    (problem, schedule, violations found by the independent verifier in the written folder).

    The verifier reads the staged files before they are published into ``out``: a folder it
    refuses as malformed (a track a reader accepted and it does not, a bug) is one error line with
    nothing written; violations (a solver's bug) are published with the files, as evidence."""
    from uamopt.export.frame import schedule_provenance
    from uamopt.outputs import output_lock
    from uamopt.pipeline import build_problem, scenario_flights, scenario_grid, solve
    from uamopt.schedule import write_schedule
    from uamopt.schedule.verify import verify_dir
    from uamopt.solvers import load_profile

    profile = load_profile(profile) if isinstance(profile, (str, Path)) else profile
    with output_lock(out), progress(3, "schedule") as bar:  # locked until verified: no other run's files
        flights = scenario_flights(scenario, flights_file, network_file, seed)
        bar.update(1)
        problem = build_problem(flights, scenario)
        bar.update(1)
        bar.set_description(f"solving ({profile.name or profile.solver})")
        with solve_progress(bar, profile):
            schedule = solve(problem, profile)
        bar.set_description("verifying and writing")
        bar.update(1)
        extent = {"extent_m": list(scenario_grid(scenario).extent)}  # the airspace the verifier holds tracks to
        violations = write_schedule(out, problem, schedule, extra=schedule_provenance(scenario, list(overrides or [])) | extent,
                                    check=lambda stage: _verified(stage, out, verify_dir))
        return problem, schedule, violations


def solve_line(seconds: float, objective: float | None, bound: float | None) -> str:
    """``incumbent X, bound Y, gap G %`` (the parts known so far) at ``seconds`` of a solve."""
    parts = [f"{seconds:.0f} s"]
    if objective is not None:
        parts.append(f"incumbent {objective:.6g}")
    if bound is not None:
        parts.append(f"bound {bound:.6g}")
    if objective is not None and bound is not None and abs(objective) > 1e-9:
        parts.append(f"gap {100.0 * abs(objective - bound) / abs(objective):.2f} %")
    return ", ".join(parts)


@contextmanager
def solve_progress(bar, profile):
    """While an exact solve runs, the progress line names its best schedule, bound and gap so far
    (each improvement the watchdog hears; a line at least every 10 s when piped)."""
    from uamopt.solvers.watchdog import listening

    name = profile.name or profile.solver
    with listening(lambda t, o, b: bar.set_description(f"solving ({name}): {solve_line(t, o, b)}")):
        yield


def _verified(stage: Path, out: str | Path, verify_dir) -> list[str]:
    """``verify_dir`` on the staged folder; a refusal names the files as they will be in ``out``."""
    from uamopt.errors import UamoptError

    try:
        return verify_dir(stage)
    except UamoptError as exc:
        exc.what, exc.where = (text.replace(str(stage), str(out)) for text in (exc.what, exc.where))
        exc.args = (exc.line(),)
        raise

