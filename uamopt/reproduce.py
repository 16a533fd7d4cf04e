"""``uamopt reproduce``: every stage that applies to a scenario, and ``report.md`` beside the paper.

Risk field (Sec. 4.1), route network (Sec. 6.2), Table 2 at ``tracks.table2_cell_m`` under the
scenario's reading and the other reading of Eq. 35, Table 4 at ``tracks.table4_cells``, Fig. 21 at
the Table 2 cells, and Table 3 / Fig. 19: every solver on the generated plan under both objectives,
each schedule written and checked by the independent verifier. The paper's figures appear only
where the scenario is the paper's case (docs/readings.md).
"""

from __future__ import annotations

import time
from pathlib import Path

from uamopt.optional import require
from uamopt.scenario import Scenario

REPRODUCE_SOLVERS = ("greedy", "ga", "soa", "highs", "cpsat")


def plan_at(scenario: Scenario, side: float, extent) -> tuple:
    """(scenario, planning model, plan of the scenario's route, seconds) at cubic cells of ``side`` m."""
    from uamopt.pipeline import compute_risk, plan_track, planning_model

    started = time.perf_counter()
    extent_text = "[" + ",".join(f"{float(v)!r}" for v in extent) + "]"
    fine = scenario.with_overrides([f"grid.cell=[{side},{side},{side}]", f"grid.extent={extent_text}"])
    model = planning_model(fine, compute_risk(fine, keep_risk=False))
    return fine, model, plan_track(model), time.perf_counter() - started


def schedule_sections(scenario: Scenario, network, stage: Path, bar, provenance: dict | None = None,
                      figures: bool = True) -> list[str]:
    """Table 3 / Fig. 19: every solver profile on the generated plan, both objectives."""
    from uamopt.pipeline import build_problem, generate_flights, solve
    from uamopt.report import is_paper_schedule, table3_section
    from uamopt.schedule import write_schedule
    from uamopt.schedule.verify import verify_dir

    flights = generate_flights(scenario, network)
    first = scenario.schedule.objective
    sections = []
    for objective in (first, "lexicographic" if first == "weighted" else "weighted"):
        problem = build_problem(flights, scenario, objective=objective)
        schedules, verified = {}, {}
        for name in REPRODUCE_SOLVERS:
            bar.set_description(f"schedule ({objective}): {name}")
            schedule = solve(problem, name)
            folder = stage / "schedules" / objective / name
            write_schedule(folder, problem, schedule, extra=provenance)
            schedules[name], verified[name] = schedule, not verify_dir(folder)
            if figures:  # every solver's own Gantt beside its files (the report shows the best one's)
                from uamopt import plotting

                plotting.save(plotting.gantt(problem, schedule), folder / "gantt.png")
            bar.update(1)
        suffix = "" if objective == first else f"_{objective}"
        if figures:
            from uamopt import plotting

            best = min((s for s in schedules.values() if s.objective is not None), key=lambda s: s.objective)
            plotting.save(plotting.gantt(problem, best), stage / f"gantt{suffix}.png")
            plotting.save(plotting.delays(problem, schedules), stage / f"delays{suffix}.png")
            if objective == first and (stage / "risk.npz").is_file():  # the 3-D playback of the best schedule
                name = next(n for n, s in schedules.items() if s is best)
                plotting.explore(stage / "schedules" / objective / name, risk=stage / "risk.npz").save(stage / "view.html")
        sections.append(table3_section(problem, schedules, verified, suffix=suffix,
                                       paper=is_paper_schedule(scenario, problem)))
    return sections


def reproduce(scenario: Scenario, out: str | Path, overrides: list[str] | None = None, figures: bool = True) -> Path:
    """Run every stage and write ``out``/report.md with its figures and folders; returns the report."""
    from uamopt.export.frame import schedule_provenance
    from uamopt.io import save_tracks
    from uamopt.outputs import check_out_dir, staged_output
    from uamopt.pipeline import compute_risk, plan_network, planning_model
    from uamopt.planning.endpoints import default_endpoints, is_paper_track
    from uamopt.planning.pareto import weight_sweep
    from uamopt.report import network_section, pareto_section, risk_section, table2_section, table4_section, write_report
    from uamopt.workflows import progress, write_network, write_risk

    check_out_dir(out)
    require("pyomo", "ortools", extra="exact", what="uamopt reproduce (Table 3 runs highs and cpsat)")
    if figures:
        require("plotly", extra="view", what="uamopt reproduce's 3-D view (--no-figures leaves it out)")
    t2 = scenario.tracks.table2_cell_m
    sides = [t2] + [c for c in scenario.tracks.table4_cells if c != t2]
    steps = 4 + 2 * len(scenario.network.route_list()) + len(sides) + 2 * len(REPRODUCE_SOLVERS)
    with progress(steps, "reproduce") as bar, staged_output(out) as stage:
        bar.set_description("risk field")
        field = compute_risk(scenario)
        summary = write_risk(field, scenario, stage, figures)
        bar.update(2)
        model = planning_model(scenario, field)
        network = plan_network(model, progress=bar)
        write_network(network, model, scenario, stage, figures)
        plans = {}
        for side in sides:
            bar.set_description(f"track at {side:g} m cells")
            plans[side] = plan_at(scenario, side, field.grid.extent)
            bar.update(1)
        fine, fine_model, plan, _ = plans[t2]
        origin, destination = default_endpoints(scenario)
        paper = is_paper_track(origin, destination)
        save_tracks(plan, stage, fine)
        tracks = plan.as_dict()
        table4 = [(side, plans[side][2], plans[side][3]) for side in scenario.tracks.table4_cells]
        bar.set_description("buffer variant")
        other = "count" if scenario.tracks.buffer_measure != "count" else "structures"
        v_scenario, v_model, v_plan, _ = plan_at(scenario.with_overrides([f"tracks.buffer_measure={other}"]), t2,
                                                 field.grid.extent)
        bar.update(1)
        bar.set_description("pareto front")
        fronts = {flag: weight_sweep(fine_model, origin, destination, 9, buffer=flag) for flag in (False, True)}
        bar.update(1)
        if figures:
            from uamopt import plotting

            plotting.save(plotting.tracks(plan, fine_model, title=f"{scenario.name}, {t2:g} m cells"),
                          stage / "tracks.png")
            plotting.save(plotting.pareto({"Eq. 10 (μ = 0)": fronts[False], "Eq. 10 + μ·R(t)": fronts[True]},
                                          title=scenario.name), stage / "pareto.png")
        provenance = schedule_provenance(scenario, list(overrides or []))
        sections = [risk_section(scenario, summary), table2_section(fine, fine_model, tracks, paper=paper),
                    table2_section(v_scenario, v_model, v_plan.as_dict(), figure=False, paper=paper,
                                   title=f"Table 2 analogue with the variant tracks.buffer_measure = \"{other}\""),
                    table4_section(scenario, table4, paper=paper),
                    pareto_section(fine, fine_model, fronts, (origin.label, destination.label)),
                    network_section(scenario, network.to_document())]
        sections += schedule_sections(scenario, network, stage, bar, provenance, figures)
        write_report(stage / "report.md", scenario, sections)
    return Path(out) / "report.md"
