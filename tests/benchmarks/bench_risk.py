"""Benchmark: the risk field of the paper case at 10 m × 10 m × 10 m cells (about 4 million).

Target (issue 2): under 3 s on a 2-core machine with peak memory under 2 GB. Run on demand:

    .venv/bin/python tests/benchmarks/bench_risk.py [--cell 10] [--repeat 3]

Prints wall times (city layers, risk field: first run and best of ``repeat``), the peak resident
memory of this process and the traced peak of the risk computation alone, and a peer in the same
run: the straightforward per-cell evaluation in Python (math module) timed on a sample of cells
and scaled to the grid, quoted as a ratio.
"""

from __future__ import annotations

import argparse
import math
import resource
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from uamopt.city import load_city  # noqa: E402
from uamopt.pipeline import scenario_grid  # noqa: E402
from uamopt.risk import RiskConstants, risk_field  # noqa: E402
from uamopt.scenario import load_scenario  # noqa: E402


def per_cell_python(scenario, c: RiskConstants, h: float, cs: float, rho_p: float, l_r: float) -> float:
    """The peer: Eqs. 1-8 for one cell with scalar math, as a direct transcription would."""
    a, r = scenario.aircraft, scenario.risk
    v = math.sqrt(r.gravity_mps2 / c.k_per_m * (1 - math.exp(-2 * c.k_per_m * h)))
    e = 0.5 * c.mass_kg * v * v
    p = 1 / (1 + math.sqrt(r.alpha_j / r.beta_j) * (r.beta_j / e) ** (1 / (4 * cs)))
    t = math.acosh(math.exp(c.k_per_m * h)) / math.sqrt(r.gravity_mps2 * c.k_per_m)
    rp = r.failure_rate_per_h * rho_p * c.crash_area_m2 * p
    rv = r.failure_rate_per_h * r.traffic_density_per_m * l_r * c.vehicle_collision_probability
    ru = (r.failure_rate_per_h * r.uav_density_per_m3 * a.wingspan_m * a.height_m
          * (c.mean_relative_speed_mps * t + a.fuselage_length_m))
    w1, w2, w3 = r.weights
    return w1 * rp + w2 * rv + w3 * ru


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cell", type=float, default=10.0, help="cell side, m (all three axes)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--scenario", default=str(ROOT / "models" / "paper_case.toml"))
    args = parser.parse_args()

    c = args.cell
    scenario = load_scenario(args.scenario, [f"grid.cell=[{c},{c},{c}]"])
    t0 = time.perf_counter()
    grid = scenario_grid(scenario)
    city = load_city(scenario, grid)
    t_city = time.perf_counter() - t0

    tracemalloc.start()
    t0 = time.perf_counter()
    field = risk_field(scenario, grid, city)
    t_first = time.perf_counter() - t0
    traced_peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    del field
    times = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        field = risk_field(scenario, grid, city)
        times.append(time.perf_counter() - t0)
        del field
    rss_peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0

    # Peer: per-cell Python on a sample of free cells, scaled to every cell of the grid.
    field = risk_field(scenario, grid, city)
    free = np.argwhere(~field.obstacle)
    rng = np.random.default_rng(0)
    sample = free[rng.choice(len(free), size=min(20000, len(free)), replace=False)]
    consts = field.constants
    t0 = time.perf_counter()
    for i, j, k in sample:
        per_cell_python(scenario, consts, float(grid.z[k] - city.surface_height[i, j]), float(city.shelter[i, j]),
                        float(city.population_density[i, j]), float(city.road_length[i, j]))
    t_peer = (time.perf_counter() - t0) / len(sample) * grid.n_cells

    best = min(times)
    print(f"grid {grid.shape} = {grid.n_cells:,} cells at {c:g} m")
    print(f"city layers: {t_city:.3f} s")
    print(f"risk field: first {t_first:.3f} s, best of {args.repeat} {best:.3f} s (target < 3 s)")
    print(f"peak memory: process RSS {rss_peak_mb:.0f} MB, traced in risk_field {traced_peak / 2**20:.0f} MB (target < 2048 MB)")
    print(f"peer (per-cell Python, scaled from {len(sample):,} cells): {t_peer:.1f} s -> vectorised is "
          f"{t_peer / best:.0f}x faster")


if __name__ == "__main__":
    main()
