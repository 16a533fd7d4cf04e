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

# MODEL_NOTES reference numbers (Table B.3, h' = 148.2 m), for m_p = 0 kg and 220 kg.
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
        "| quantity | ours, m_p = 0 | MODEL_NOTES | ours, m_p = 220 kg | MODEL_NOTES |",
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
