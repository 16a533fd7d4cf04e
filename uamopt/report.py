"""``report.md``: what ``uamopt reproduce`` ran, beside the paper's figures where it has them."""

from __future__ import annotations

from uamopt.paper import TABLE2, TABLE3, table4_row
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
        f"| cells (Δx, Δy, Δz = {', '.join(f'{c:g}' for c in g['cell_m'])} m) | {summary['cells']:,} "
        f"({' × '.join(map(str, g['shape']))}) |",
        f"| obstacle cells (inside or below buildings) | {summary['obstacle_cells']:,} |",
        f"| no-fly cells | {summary['no_fly_cells']:,} |",
        f"| unsafe cells (Eq. 9), whole grid | {summary['unsafe_cells']:,} ({100 * summary['unsafe_share']:.1f} %) |",
        f"| unsafe share of free cells in the band {summary['band_m'][0]:g}–{summary['band_m'][1]:g} m (Eq. 14) | "
        f"{100 * summary['band_unsafe_share']:.1f} % |",
        f"| columns with road (l_r > 0) | {100 * summary['road_columns_share']:.1f} % |",
        f"| free cells unsafe through R^V alone | {100 * summary['road_driven_unsafe_share']:.1f} % |",
        f"| R per flight hour over free cells: min / median / max | {rk['min']:.3e} / {rk['median']:.3e} / {rk['max']:.3e} "
        f"(R_0 = {rk['threshold_R0']:g}) |",
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


def _change(value: float, base: float) -> str:
    return f" ({100 * (value - base) / base:+.1f} %)" if base else ""


def straight_segment_cost(scenario: Scenario, length_m: float = 4365.0) -> float:
    """Eq. 12 for a straight level segment: c_h · L · c_e · τ(m_p) (docs/readings.md: ¥27.15)."""
    from uamopt.planning.problem import transport_rates

    return transport_rates(scenario)[0] * length_m


def track_shape(tracks: dict, cruise_altitude_m: float, layer_m: float, risk_tolerance: float = 0.02) -> dict:
    """The paper's Table 2 shape, per stage: does the track stay within one cell layer of the cruise
    altitude, how its C_T and C_R compare with the shortest track's (%), is it no riskier than the
    shortest track (C_R), and (later stages) within (1 + ``risk_tolerance``) of the initial track's C_R
    (or of the corridor's least risk from the exact end points plus that slack, when it is more)."""
    st = tracks["stages"]
    base = st["shortest"]
    initial = st.get("initial", base)["risk_cost"]
    least = st.get("equivalent", {}).get("least_risk")  # the corridor could not meet the bound (docs/readings.md)
    bound = max((1 + risk_tolerance) * initial, (least or 0.0) + risk_tolerance * initial)
    shape = {}
    for name, stage in st.items():
        z = [p[2] for p in stage["waypoints"]]
        deviation = max(abs(v - cruise_altitude_m) for v in z)
        shape[name] = {
            "max_altitude_deviation_m": deviation, "in_layer": deviation <= layer_m + 1e-6,
            "d_cost_pct": 100 * (stage["transport_cost"] / base["transport_cost"] - 1),
            "d_risk_pct": 100 * (stage["risk_cost"] / base["risk_cost"] - 1) if base["risk_cost"] else float("nan"),
            "no_riskier": stage["risk_cost"] <= base["risk_cost"] * (1 + 1e-9) + 1e-12,
            "within_initial": stage["risk_cost"] <= bound * (1 + 1e-6) + 1e-12,
        }
    return shape


def risk_hint(scenario: Scenario, shape: dict) -> str:
    """The variant (key and value) to try when a stage is riskier than the shortest track, or ""."""
    t = scenario.tracks
    if all(shape[n]["no_riskier"] for n in ("initial", "equivalent", "optimal")):
        return ""
    if not shape["initial"]["no_riskier"]:  # the search itself traded risk away
        if t.risk_model == "continuous":
            return ('the initial track is riskier: with tracks.risk_model = "continuous" C_R is tiny beside C_T; try '
                    'tracks.risk_model = "binary" or raise ω4 in tracks.weights')
        if t.buffer_measure != "structures":
            return (f'the initial track is riskier: the buffer term of tracks.buffer_measure = "{t.buffer_measure}" '
                    'outweighs risk; try tracks.buffer_measure = "structures" (the default)')
        return ("the initial track is riskier: the safety-buffer term outweighs risk here; try a lower "
                f"tracks.buffer_penalty (now {t.buffer_penalty:g}) or a larger ω4 in tracks.weights")
    if t.equivalent == "midpoint":
        return ('a later stage is riskier: the midpoint rule is not bounded by the initial track\'s risk; try '
                'tracks.equivalent = "exact" (the default)')
    return (f"a later stage is riskier: tracks.risk_tolerance = {t.risk_tolerance:g} lets it carry more than the "
            'initial track; try tracks.risk_tolerance = 0, or tracks.equivalent = "exact_cost"')


def table2_section(scenario: Scenario, model, tracks: dict, title: str = "Track planning: Table 2 analogue (Sec. 6.2, Fig. 18)",
                   figure: bool = True, paper: bool = True) -> str:
    """Table 2 analogue, with the paper's figures in brackets when ``paper`` (same P_O → P_D), and
    the shape checks: each stage in its layer, Δcost and Δrisk against the shortest track."""
    st = tracks["stages"]
    names = ("shortest", "initial", "equivalent", "optimal")
    ref = TABLE2 if paper else {}
    rows = [
        ("operational risk C_R (Eq. 11)", [st[n]["risk_cost"] for n in names], ref.get("operational risk"), ".1f", True),
        ("safety-buffer exposure Σ μ·R(t) (Eq. 34)", [st[n]["buffer_cost"] for n in names], None, ".0f", False),
        ("transport cost C_T (¥, Eq. 12)", [st[n]["transport_cost"] for n in names], ref.get("transport cost (¥)"), ".4f", True),
        ("waypoints", [st[n]["n_waypoints"] for n in names], ref.get("waypoints"), "d", False),
        ("length (m)", [st[n]["length_m"] for n in names], None, ".0f", True),
        ("computational time of the stage (s)", [st[n]["seconds"] for n in names], None, ".3f", False),
    ]
    g = model.field.grid
    o, d = tracks["origin"], tracks["destination"]
    cruise = scenario.network.cruise_altitude_m
    t = scenario.tracks
    shape = track_shape(tracks, cruise, g.cell[2], t.risk_tolerance)
    lines = [
        f"## {title}",
        "",
        f"P_O = ({', '.join(f'{v:g}' for v in o)}) → P_D = ({', '.join(f'{v:g}' for v in d)}) m, cells "
        f"{' × '.join(f'{c:g}' for c in g.cell)} m, ω4 = {t.weights[0]:g}, ω5 = {t.weights[1]:g}, "
        f"μ = {t.buffer_penalty:g}, buffer n_s = {model.n_s}, R(t) = {t.buffer_measure}, charged on the "
        f"{t.buffer_charge}. Changes in parentheses are relative to the shortest track"
        + (", the paper's figures in brackets (its instance, not ours: compare the shape)." if paper else
           "; the paper has no figures for this track."),
        "",
        "| index | shortest | initial | equivalent | optimal |",
        "|---|---|---|---|---|",
    ]
    for label, ours, paper_row, fmt, relative in rows:
        cells = []
        for i, v in enumerate(ours):
            text = format(int(v) if fmt == "d" else v, fmt) + (_change(v, ours[0]) if i and relative else "")
            if paper_row is not None:
                text += f" [{paper_row[i]:g}]"
            cells.append(text)
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    stays = ", ".join(f"{n} {'yes' if shape[n]['in_layer'] else 'NO'} ({shape[n]['max_altitude_deviation_m']:.0f} m)"
                      for n in names)
    ini = shape["initial"]
    later = ("initial", "equivalent", "optimal")
    safer = ", ".join(f"{n} {'yes' if shape[n]['no_riskier'] else 'NO'} ({shape[n]['d_risk_pct']:+.1f} %)" for n in later)
    kept = ", ".join(f"{n} {'yes' if shape[n]['within_initial'] else 'NO'}" for n in later[1:])
    hint = risk_hint(scenario, shape)
    least = st["equivalent"].get("least_risk")
    lines += [
        "",
        f"Shape checks: within one layer ({g.cell[2]:g} m) of the cruise altitude {cruise:g} m, largest deviation in "
        f"parentheses: {stays}. Initial track against the shortest: C_T {ini['d_cost_pct']:+.1f} %, "
        f"C_R {ini['d_risk_pct']:+.1f} %" + (" (paper: +20.6 %, −11.2 %)." if paper else "."),
        f"No riskier than the shortest track (C_R): {safer}." + (f" Hint: {hint}." if hint else ""),
        f"Later stages within {100 * t.risk_tolerance:g} % of the initial track's C_R (tracks.risk_tolerance): {kept}"
        + (f" (the exact end points lie in risky cells: the bound is the least risk the corridor allows from them, "
           f"{least:.1f}, plus the same slack; docs/readings.md)." if least is not None else "."),
        "The shortest track minimises C_T alone and breaks ties between equally cheap tracks by least risk. "
        "Waypoints: the shortest and initial tracks list their cell centres; the equivalent track's waypoints "
        "are its corners; the optimal track adds the points of its corner curves. Times are each stage's own"
        + (f"; compiling the search took {tracks['warmup_seconds']:.2f} s before the first stage and is in none."
           if tracks.get("warmup_seconds") else "."),
    ]
    mid = tracks.get("equivalent_midpoint_rule")
    eq = st["equivalent"]
    if mid:
        rule = {"exact Eq. 10 (SOCP)": "exact Eq. 10 optimum in the corridor (SOCP)",
                "midpoint": "the paper's midpoint rule"}.get(eq.get("rule"),
                                                             "exact shortest polyline through the corridor (SOCP)")
        lines += ["", f"Equivalent track, {rule}: {eq['length_m']:.1f} m, "
                  f"¥{eq['transport_cost']:.4f}; the paper's midpoint rule: {mid['length_m']:.1f} m, "
                  f"¥{mid['transport_cost']:.4f}."]
    if paper:
        lines += ["", f"Check of Eq. 12–13: a straight level 4365 m segment with m_p = {scenario.aircraft.payload_kg:g} kg "
                  f"costs ¥{straight_segment_cost(scenario):.4f} (paper's shortest track: ¥27.1527)."]
    lines += [""] + (["![tracks](tracks.png)", ""] if figure else [])
    return "\n".join(lines) + "\n"


def table4_section(scenario: Scenario, results: list, paper: bool = True) -> str:
    """Table 4 analogue: the optimal track at finer cells (cell side, plan, seconds); the paper's
    figures in brackets when ``paper`` (same P_O → P_D)."""
    if not results:
        return ""
    lines = [
        "## Track planning at finer cells: Table 4 analogue (Sec. 6.3.2)",
        "",
        "Optimal track P_O → P_D; computational time includes the risk field and planning model. "
        + ("The paper's figures in brackets (its Table 4 reports the shortest-track column of Table 2)."
           if paper else "The paper has no figures for this track."),
        "",
        "| cells | operational risk C_R | transport cost (¥) | waypoints | length (m) | time: risk field, planning model "
        "and four stages (s) |",
        "|---|---|---|---|---|---|",
    ]
    for side, plan, seconds in results:
        o = plan.stages["optimal"]
        p = table4_row(side) if paper else None
        ref = (lambda i, p=p: f" [{p[i]:g}]") if p else (lambda i: "")
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
    return "\n".join([*lines, "", "![network](network.png)", ""]) + "\n"


def pareto_section(scenario: Scenario, model, fronts: dict, endpoints: tuple[str, str] = ("P_O", "P_D")) -> str:
    """Fig. 21 analogue: the (C_R, C_T) trade-off over ω4/ω5, without and with the buffer term, and
    the number of non-dominated points of each (the paper's Fig. 21 shows a front, not a point)."""
    from uamopt.planning.pareto import non_dominated

    g = model.field.grid
    fronts_nd = {flag: non_dominated(fronts[flag]) for flag in (False, True)}
    lines = [
        "## Risk–cost trade-off: Fig. 21 analogue (Sec. 6.3.2)",
        "",
        f"{endpoints[0]} → {endpoints[1]} at {' × '.join(f'{c:g}' for c in g.cell)} m cells, weights ω4/ω5 swept "
        "(ω4 + ω5 = 1). Non-dominated points of Eq. 10 alone (μ = 0), and with the safety-buffer term μ·R(t) of "
        f"Eq. 34 (μ = {scenario.tracks.buffer_penalty:g}, R(t) = {scenario.tracks.buffer_measure}).",
        "",
        f"Shape check: {len(fronts_nd[True])} non-dominated points with the buffer term "
        f"({len(fronts[True])} searches), {len(fronts_nd[False])} without.",
        "",
        "| objective | ω4 | ω5 | C_R (Eq. 11) | C_T (¥, Eq. 12) |",
        "|---|---|---|---|---|",
    ]
    for flag, label in ((False, "Eq. 10"), (True, "Eq. 10 + μ·R(t)")):
        for p in fronts_nd[flag]:
            lines.append(f"| {label} | {p.w4:.4g} | {p.w5:.4g} | {p.risk_cost:.1f} | {p.transport_cost:.4f} |")
    return "\n".join([*lines, "", "![pareto](pareto.png)", ""]) + "\n"


def is_paper_schedule(scenario: Scenario, problem) -> bool:
    """True when the flights are the paper's case (Table B.3 vertiports, 20 eVTOLs, 120 flights)."""
    from uamopt.scenario import NetworkConfig

    paper_ports = [(v.name, v.x, v.y) for v in NetworkConfig().vertiports]
    ports = [(v.name, v.x, v.y) for v in scenario.network.vertiports]
    return ports == paper_ports and problem.n_flights == 120 and problem.aircraft_count == 20


def objective_label(problem) -> str:
    """The objective in words, as every scheduling table and figure names it."""
    if problem.objective_kind == "lexicographic":
        return ("objective lexicographic: most flights operated, then least total delay (the default; Eq. 20 "
                "literal is schedule.objective = \"weighted\")")
    return f"objective Eq. 20 weighted, (ω6, ω7) = {tuple(problem.weights)}, delays in seconds"


def table3_section(problem, schedules: dict, verified: dict, suffix: str = "", paper: bool = True) -> str:
    """Table 3 analogue: every solver on the same flights, with each one's distance to the proven
    optimum (which the paper could not give); the paper's figures in brackets when ``paper``."""
    exact = [s for s in schedules.values() if s.status == "optimal" and s.bound is not None]
    best = min((s.objective for s in exact), default=None)
    lines = [
        f"## Multi-aircraft scheduling: Table 3 analogue, {problem.objective_kind} objective (Sec. 6.2, Fig. 19)",
        "",
        f"{problem.n_flights} flights, G = {problem.aircraft_count} aircraft, {len(problem.conflicts)} conflicting "
        f"pairs, {objective_label(problem)}. "
        + ("The paper's figures in brackets (operated / cancelled / total delay; its instance, not ours). "
           if paper else "The paper has no figures for this instance. ") +
        "'to optimum' is the objective's distance to the proven optimum.",
        "",
        "| solver | status | operated | cancelled | total delay (s) | avg delay T_d (s) | objective | bound | "
        "to optimum | time (s) | verified |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, s in schedules.items():
        p = TABLE3.get(name) if paper else None
        ref = (lambda i, p=p: f" [{p[i]:g}]") if p else (lambda i: "")
        dist = "-" if best is None or s.objective is None else f"{s.objective - best:+.4f}"
        bound = "-" if s.bound is None else f"{s.bound:.4f}"
        lines.append(f"| {name} | {s.status} | {s.operated_count}{ref(0)} | {s.cancelled_count}{ref(1)} | "
                     f"{s.total_delay_s:.1f}{ref(2)} | {s.avg_delay_s:.2f} | {s.objective:.4f} | {bound} | {dist} | "
                     f"{s.solve_seconds:.2f} | {'yes' if verified.get(name) else 'NO'} |")
    if problem.objective_kind == "weighted":
        lines += ["", "Eq. 20 with T_d = total delay / G makes one operated flight worth ω7·G/ω6 "
                  f"= {problem.weights[1] * problem.aircraft_count / problem.weights[0]:.1f} s of total delay, so the "
                  "optimum cancels flights rather than delay them; the lexicographic objective (most flights, then "
                  "least delay) gives the paper's shape."]
    lines += ["", f"![gantt](gantt{suffix}.png)", "", f"![delays](delays{suffix}.png)", ""]
    return "\n".join(lines) + "\n"
