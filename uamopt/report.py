"""``report.md``: what ``uamopt reproduce`` ran, beside the paper's figures where it has them."""

from __future__ import annotations

from uamopt.risk import (
    crash_area,
    drag_constant,
    fall_time,
    fatality_probability,
    impact_energy,
    impact_speed,
    terminal_speed,
)
from uamopt.scenario import Scenario

# The reference numbers of docs/readings.md (Table B.3, h' = 148.2 m), for m_p = 0 kg and 220 kg.
REFERENCE = {
    "terminal speed (m/s)": (27.468, 34.198),
    "v from h' = 148.2 m (A.3, m/s)": (27.174496, 32.740228),
    "fall time from 148.2 m (s)": (7.323078, 6.677222),
    "E_imp (J)": (147690.7, 332296.0),
    "P^P, c_s = 0.5": (0.277616, 0.365664),
    "P^P, c_s = 0.75": (0.115849, 0.146535),
}


def reference_rows(scenario: Scenario, height_m: float = 148.2) -> list[tuple[str, float, float, float, float]]:
    """(quantity, ours m_p=0, reference, ours m_p=220, reference) for the App. A reference numbers."""
    a, r = scenario.aircraft, scenario.risk
    ours = []
    for payload in (0.0, a.payload_max_kg):
        m = a.empty_mass_kg + payload
        k = drag_constant(m, r.drag_coefficient, r.air_density, crash_area(a.length_m))
        v = float(impact_speed(height_m, k, r.gravity_mps2))
        e = float(impact_energy(m, v))
        ours.append([
            terminal_speed(k, r.gravity_mps2), v, float(fall_time(height_m, k, r.gravity_mps2)), e,
            float(fatality_probability(e, 0.5, r.alpha_j, r.beta_j)),
            float(fatality_probability(e, 0.75, r.alpha_j, r.beta_j)),
        ])
    return [(name, ours[0][i], ref[0], ours[1][i], ref[1]) for i, (name, ref) in enumerate(REFERENCE.items())]


def _fmt(x: float) -> str:
    return f"{x:.6g}" if abs(x) < 1e5 else f"{x:.7g}"


def risk_section(scenario: Scenario, summary: dict) -> str:
    """The risk field part of the report."""
    g = summary["grid"]
    rk = summary["risk_per_flight_hour"]
    lines = [
        "## Operational risk field (Sec. 4.1, App. A)",
        "",
        f"Source: **{summary['source']}**" + (f" — {summary['attribution']}" if summary["attribution"] else ""),
        "",
        "| quantity | value |",
        "|---|---|",
        f"| cells (Δx, Δy, Δz = {', '.join(f'{c:g}' for c in g['cell_m'])} m) | {summary['cells']:,} ({' × '.join(map(str, g['shape']))}) |",
        f"| obstacle cells (inside or below buildings) | {summary['obstacle_cells']:,} |",
        f"| no-fly cells | {summary['no_fly_cells']:,} |",
        f"| unsafe cells (Eq. 9), whole grid | {summary['unsafe_cells']:,} ({100 * summary['unsafe_share']:.1f} %) |",
        f"| unsafe share of free cells in the band {summary['band_m'][0]:g}–{summary['band_m'][1]:g} m (Eq. 14) | {100 * summary['band_unsafe_share']:.1f} % |",
        f"| columns with road (l_r > 0) | {100 * summary['road_columns_share']:.1f} % |",
        f"| free cells unsafe through R^V alone | {100 * summary['road_driven_unsafe_share']:.1f} % |",
        f"| R per flight hour over free cells: min / median / max | {rk['min']:.3e} / {rk['median']:.3e} / {rk['max']:.3e} (R_0 = {rk['threshold_R0']:g}) |",
        f"| v_r' (A.6) | {summary['constants']['mean_relative_speed_mps']:.4f} m/s |",
        f"| computed in | {summary['seconds']['risk']:.3f} s (city layers {summary['seconds']['city']:.3f} s) |",
        "",
        "![risk map](risk.png)",
        "",
        "With Table B.3 values the vehicle term dominates: every free cell above a road exceeds R_0, and",
        "no cell above open ground does, at any altitude. The paper's Fig. 20 (risk falling with",
        "altitude) does not follow from its formulas; this report shows what the model gives.",
        "",
        "### Appendix A reference numbers (h' = 148.2 m, Table B.3)",
        "",
        "| quantity | ours, m_p = 0 | reference | ours, m_p = 220 kg | reference |",
        "|---|---|---|---|---|",
    ]
    for name, a, ra, b, rb in reference_rows(scenario):
        lines.append(f"| {name} | {_fmt(a)} | {_fmt(ra)} | {_fmt(b)} | {_fmt(rb)} |")
    return "\n".join(lines) + "\n"


def write_report(path, scenario: Scenario, sections: list[str]) -> None:
    """Assemble ``report.md`` from the stage sections that ran."""
    head = [
        f"# uamopt report: {scenario.name}",
        "",
        scenario.description or "",
        "",
        f"Scenario file: `{scenario.source}`. Paper: *Multi-Aircraft Scheduling Optimization in Urban Environments*.",
        "",
    ]
    path.write_text("\n".join(head) + "\n".join(sections), encoding="utf-8")


# Table 2 of the paper (P_O -> P_D): shortest, initial, equivalent, optimal.
PAPER_TABLE2 = {
    "operational risk": (196, 174, 174, 181),
    "transport cost (¥)": (27.1527, 32.7379, 32.0715, 30.8265),
    "waypoints": (386, 456, 453, 432),
    "computational time (s)": (68.71, 90.58, 101.96, 108.97),
}
PAPER_TABLE4 = {10.0: (196, 27.1527, 386, 68.71), 5.0: (163.33, 25.7975, 636, 659.52)}


def _change(value: float, base: float) -> str:
    return f" ({100 * (value - base) / base:+.1f} %)" if base else ""


def straight_segment_cost(scenario: Scenario, length_m: float = 4365.0) -> float:
    """Eq. 12 for a straight level segment: c_h · L · c_e · τ(m_p) (docs/readings.md: ¥27.15)."""
    from uamopt.planning.problem import transport_rates

    return transport_rates(scenario)[0] * length_m


def table2_section(scenario: Scenario, model, tracks: dict, title: str = "Track planning: Table 2 analogue (Sec. 6.2, Fig. 18)",
                   figure: bool = True) -> str:
    """Table 2 analogue beside the paper's figures, with the cumulative computing time."""
    st = tracks["stages"]
    names = ("shortest", "initial", "equivalent", "optimal")
    cumulative = 0.0
    times = []
    for n in names:
        cumulative += st[n]["seconds"]
        times.append(cumulative)
    rows = [
        ("operational risk C_R (Eq. 11)", [st[n]["risk_cost"] for n in names], PAPER_TABLE2["operational risk"], ".1f"),
        ("safety-buffer exposure Σ μ·R(t) (Eq. 34)", [st[n]["buffer_cost"] for n in names], None, ".0f"),
        ("transport cost C_T (¥, Eq. 12)", [st[n]["transport_cost"] for n in names], PAPER_TABLE2["transport cost (¥)"], ".4f"),
        ("waypoints", [st[n]["n_waypoints"] for n in names], PAPER_TABLE2["waypoints"], "d"),
        ("length (m)", [st[n]["length_m"] for n in names], None, ".0f"),
        ("computational time, cumulative (s)", times, PAPER_TABLE2["computational time (s)"], ".3f"),
    ]
    g = model.field.grid
    o, d = tracks["origin"], tracks["destination"]
    lines = [
        f"## {title}",
        "",
        f"P_O = ({', '.join(f'{v:g}' for v in o)}) → P_D = ({', '.join(f'{v:g}' for v in d)}) m, cells "
        f"{' × '.join(f'{c:g}' for c in g.cell)} m, ω4 = {scenario.tracks.weights[0]:g}, ω5 = {scenario.tracks.weights[1]:g}, "
        f"μ = {scenario.tracks.buffer_penalty:g}, buffer n_s = {model.n_s}. Ours first, the paper's in brackets "
        "(its instance, not ours: compare the shape). Changes are relative to the shortest track.",
        "",
        "| index | shortest | initial | equivalent | optimal |",
        "|---|---|---|---|---|",
    ]
    for label, ours, paper, fmt in rows:
        cells = []
        for i, v in enumerate(ours):
            text = format(int(v) if fmt == "d" else v, fmt) + (_change(v, ours[0]) if i else "")
            if paper is not None:
                text += f" [{paper[i]:g}]"
            cells.append(text)
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    mid = tracks.get("equivalent_midpoint_rule")
    eq = st["equivalent"]
    lines += [
        "",
        f"Equivalent track, exact shortest polyline through the corridor (SOCP): {eq['length_m']:.1f} m, "
        f"¥{eq['transport_cost']:.4f}; the paper's midpoint rule: {mid['length_m']:.1f} m, ¥{mid['transport_cost']:.4f}."
        if mid else "",
        "",
        f"Check of Eq. 12–13 (docs/readings.md): a straight level 4365 m segment with m_p = {scenario.aircraft.payload_kg:g} kg "
        f"costs ¥{straight_segment_cost(scenario):.4f} (paper's shortest track: ¥27.1527).",
        "",
    ] + (["![tracks](tracks.png)", ""] if figure else [])
    return "\n".join(lines) + "\n"


def table4_section(scenario: Scenario, results: list) -> str:
    """Table 4 analogue: the optimal track at finer cells (cell side, plan, seconds)."""
    if not results:
        return ""
    lines = [
        "## Track planning at finer cells: Table 4 analogue (Sec. 6.3.2)",
        "",
        "Optimal track P_O → P_D; computational time includes the risk field and planning model. "
        "The paper's figures in brackets (its Table 4 reports the shortest-track column of Table 2).",
        "",
        "| cells | operational risk C_R | transport cost (¥) | waypoints | length (m) | time (s) |",
        "|---|---|---|---|---|---|",
    ]
    for side, plan, seconds in results:
        o = plan.stages["optimal"]
        p = PAPER_TABLE4.get(float(side))
        ref = (lambda i: f" [{p[i]:g}]") if p else (lambda i: "")
        lines.append(f"| {side:g} m | {o.risk_cost:.1f}{ref(0)} | {o.transport_cost:.4f}{ref(1)} | {o.n_waypoints}{ref(2)} | "
                     f"{o.length_m:.0f} | {seconds:.2f}{ref(3)} |")
    return "\n".join(lines) + "\n\n"


def network_section(scenario: Scenario, doc: dict) -> str:
    """The route network: one optimal track per route and direction."""
    lines = [
        "## Route network (Sec. 6.2)",
        "",
        f"{len(doc['routes'])} tracks (layering: {doc['layering']}; directions on separate cruise layers).",
        "",
        "| route | layer k | length (m) | transport cost (¥) | risk C_R |",
        "|---|---|---|---|---|",
    ]
    for name, r in doc["routes"].items():
        lines.append(f"| {name} | {r['layer_k'] if r['layer_k'] is not None else '-'} | {r['length_m']:.0f} | "
                     f"{r['transport_cost']:.2f} | {r['risk_cost']:.1f} |")
    return "\n".join(lines + ["", "![network](network.png)", ""]) + "\n"


def pareto_section(scenario: Scenario, model, fronts: dict) -> str:
    """Fig. 21 analogue: the (C_R, C_T) trade-off over ω4/ω5, without and with the buffer term."""
    from uamopt.planning.pareto import non_dominated

    g = model.field.grid
    lines = [
        "## Risk–cost trade-off: Fig. 21 analogue (Sec. 6.3.2)",
        "",
        f"P_O → P_D at {' × '.join(f'{c:g}' for c in g.cell)} m cells, weights ω4/ω5 swept (ω4 + ω5 = 1). "
        "Non-dominated points of Eq. 10 alone (μ = 0), and with the safety-buffer term μ·R(t) of Eq. 34 "
        f"(μ = {scenario.tracks.buffer_penalty:g}), which dominates the objective and collapses the front.",
        "",
        "| objective | ω4 | ω5 | C_R (Eq. 11) | C_T (¥, Eq. 12) |",
        "|---|---|---|---|---|",
    ]
    for flag, label in ((False, "Eq. 10"), (True, "Eq. 10 + μ·R(t)")):
        for p in non_dominated(fronts[flag]):
            lines.append(f"| {label} | {p.w4:.4g} | {p.w5:.4g} | {p.risk_cost:.1f} | {p.transport_cost:.4f} |")
    return "\n".join(lines + ["", "![pareto](pareto.png)", ""]) + "\n"


# Table 3 of the paper (operated, cancelled, total delay s)
PAPER_TABLE3 = {"greedy": (109, 11, 2401), "soa": (117, 3, 1911), "ga": (114, 6, 2161)}


def table3_section(problem, schedules: dict, verified: dict, suffix: str = "") -> str:
    """Table 3 analogue: every solver on the same flights, with each one's distance to the proven
    optimum (which the paper could not give)."""
    exact = [s for s in schedules.values() if s.status == "optimal" and s.bound is not None]
    best = min((s.objective for s in exact), default=None)
    lines = [
        f"## Multi-aircraft scheduling: Table 3 analogue, {problem.objective_kind} objective (Sec. 6.2, Fig. 19)",
        "",
        f"{problem.n_flights} flights, G = {problem.aircraft_count} aircraft, {len(problem.conflicts)} conflicting "
        f"pairs, objective Eq. 20 with (ω6, ω7) = {tuple(problem.weights)} ({problem.objective_kind}). "
        "The paper's figures in brackets (operated / cancelled / total delay; its instance, not ours). "
        "'to optimum' is the objective's distance to the proven optimum.",
        "",
        "| solver | status | operated | cancelled | total delay (s) | avg delay T_d (s) | objective | bound | "
        "to optimum | time (s) | verified |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, s in schedules.items():
        p = PAPER_TABLE3.get(name)
        ref = (lambda i: f" [{p[i]:g}]") if p else (lambda i: "")
        dist = "-" if best is None or s.objective is None else f"{s.objective - best:+.4f}"
        bound = "-" if s.bound is None else f"{s.bound:.4f}"
        lines.append(f"| {name} | {s.status} | {s.operated_count}{ref(0)} | {s.cancelled}{ref(1)} | "
                     f"{s.total_delay_s:.1f}{ref(2)} | {s.avg_delay_s:.2f} | {s.objective:.4f} | {bound} | {dist} | "
                     f"{s.solve_seconds:.2f} | {'yes' if verified.get(name) else 'NO'} |")
    if problem.objective_kind == "weighted":
        lines += ["", "Eq. 20 with T_d = total delay / G makes one operated flight worth ω7·G/ω6 "
                  f"= {problem.weights[1] * problem.aircraft_count / problem.weights[0]:.1f} s of total delay, so the "
                  "optimum cancels flights rather than delay them; the lexicographic objective (most flights, then "
                  "least delay) gives the paper's shape."]
    lines += ["", f"![gantt](gantt{suffix}.png)", "", f"![delays](delays{suffix}.png)", ""]
    return "\n".join(lines) + "\n"
