"""The replay's figure (``replay.png``): deviations from the plan, and the closest approaches."""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure
from matplotlib.patches import Rectangle


def plot_replay(result, path: str | Path) -> Path:
    """Left: each flight's largest horizontal error and cross-track distance against its departure,
    with the budget e_h. Right: each near pair at its closest approach (horizontal, vertical), the
    LoS cylinder (r_pz × h_pz, red) and the cell model's guaranteed separation r·Δ (dashed)."""
    zone = result.zone
    fig = Figure(figsize=(12, 4.6), dpi=130)
    ax, bx = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    dep = [f["departure_s"] for f in result.flights]
    ax.scatter(dep, [f["max_horizontal_error_m"] for f in result.flights], s=14, label="max horizontal error vs plan")
    ax.scatter(dep, [f["max_cross_track_m"] for f in result.flights], s=14, marker="x", label="max cross-track distance")
    ax.axhline(zone.budget_h_m, color="crimson", linestyle="--", linewidth=1, label=f"budget e_h = {zone.budget_h_m:g} m")
    ax.set_xlabel("scheduled departure (s)")
    ax.set_ylabel("m")
    ax.set_ylim(bottom=0)
    ax.legend(fontsize=8, loc="best")
    ax.set_title(f"{len(result.flights)} flights in BlueSky ({result.settings['aircraft_type']}, "
                 f"bank {result.settings['bank_deg']:g}°, dt {result.settings['dt_s']:g} s)", fontsize=10)
    bx.add_patch(Rectangle((0, 0), zone.rpz_m, zone.hpz_m, color="crimson", alpha=0.15, label="LoS zone"))
    r = zone.conflict_radius
    bx.axvline(r * min(zone.cell[:2]), color="grey", linestyle="--", linewidth=1, label="r·Δ (verified: one of the two)")
    bx.axhline(r * zone.cell[2], color="grey", linestyle="--", linewidth=1)
    los = {tuple(e["flights"]) for e in result.los}
    for pair in result.near_pairs:
        hit = tuple(sorted(pair["flights"])) in los
        bx.scatter(pair["closest_horizontal_m"], pair["closest_vertical_m"], s=18,
                   color="crimson" if hit else "tab:blue", zorder=3)
    bx.set_xlim(0, max([zone.near_m[0]] + [p["closest_horizontal_m"] for p in result.near_pairs]) * 1.05)
    bx.set_ylim(0, max([zone.near_m[2]] + [p["closest_vertical_m"] for p in result.near_pairs]) * 1.05)
    bx.set_xlabel("horizontal distance at closest approach (m)")
    bx.set_ylabel("vertical distance (m)")
    bx.legend(fontsize=8, loc="upper right")
    bx.set_title(f"{result.los_count} losses of separation, {len(result.near_pairs)} near pairs", fontsize=10)
    fig.tight_layout()
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp)
    tmp.replace(path)  # never a half-written figure
    return path
