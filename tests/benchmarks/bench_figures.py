"""Benchmark: draw and save every figure of the paper case, each in a fresh process (as a command
pays it), then again in the same process (as a notebook pays it).

    .venv/bin/python tests/benchmarks/bench_figures.py [--cell 50] [--repeat 3] [--figures risk tracks]
                                                       [--cells imshow|pcolormesh] [--dpi 110]

Per figure: the import of matplotlib, then of :mod:`uamopt.plotting`, then building the Figure
and saving the PNG, first call (cold: fonts, glyph and text caches empty) and best of
``--repeat`` further calls (warm); wall and CPU seconds of this process, and the PNG's size.
The inputs (risk field, plan, network, Pareto sweep, schedules) are computed before timing.
``--cells pcolormesh`` draws the cell arrays as meshes instead of images, for comparison.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FIGURES = ("risk", "tracks", "network", "pareto", "gantt", "delays")


def inputs(name: str, cell: float) -> dict:
    """What figure ``name`` draws, for the paper case at cubic-ish cells of ``cell`` m."""
    import numpy as np

    from uamopt.pipeline import compute_risk
    from uamopt.planning import plan_track, planning_model
    from uamopt.planning.network import plan_network
    from uamopt.planning.pareto import weight_sweep
    from uamopt.scenario import load_scenario

    scenario = load_scenario(ROOT / "models" / "paper_case.toml", [f"grid.cell=[{cell},{cell},30.0]"])
    field = compute_risk(scenario)
    out = {"scenario": scenario, "field": field}
    if name in ("risk",):
        return out
    out["model"] = model = planning_model(scenario, field)
    out["plan"] = plan_track(model, "V1", "V4")
    if name == "pareto":
        out["points"] = weight_sweep(model, "V1", "V4", 9)
    if name in ("network", "gantt", "delays"):
        out["network"] = doc = plan_network(model).to_document()
    if name in ("gantt", "delays"):
        from uamopt.schedule import build_problem, generate_plan
        from uamopt.solvers import load_profile, solve

        routes = {k: np.asarray(v["waypoints"]) for k, v in doc["routes"].items()}
        out["problem"] = problem = build_problem(generate_plan(scenario, routes, scenario.schedule.plan_seed), scenario)
        out["schedules"] = {s: solve(problem, load_profile(s)) for s in ("greedy", "ga")}
    return out


def draw(plotting, name: str, data: dict):
    """The Figure of ``name``, as the CLI draws it."""
    sc = data["scenario"]
    if name == "risk":
        return plotting.risk(data["field"], vertiports=sc.network.vertiports,
                             cruise_altitude_m=sc.network.cruise_altitude_m, title=sc.name)
    if name == "tracks":
        return plotting.tracks(data["plan"], data["model"], title=sc.name)
    if name == "network":
        return plotting.network(data["model"], data["network"]["routes"], vertiports=sc.network.vertiports)
    if name == "pareto":
        return plotting.pareto(data["points"], plan=data["plan"], title=sc.name)
    if name == "gantt":
        return plotting.gantt(data["problem"], data["schedules"]["ga"])
    return plotting.delays(data["problem"], data["schedules"])


def use_meshes() -> None:
    """Draw cell arrays with pcolormesh (one quadrilateral per cell) instead of imshow."""
    from uamopt.plotting import network, risk, style

    def cell_mesh(ax, values, xe, ye, **kwargs):
        return ax.pcolormesh(xe, ye, values.T, shading="flat", **kwargs)

    for module in (style, risk, network):
        module.cell_image = cell_mesh


def child(args) -> None:
    wall, cpu = time.perf_counter(), time.process_time()
    import matplotlib.figure  # noqa: F401  (what every figure needs first)

    timings = {"matplotlib": (time.perf_counter() - wall, time.process_time() - cpu)}
    data = inputs(args.child, args.cell)
    wall, cpu = time.perf_counter(), time.process_time()
    from uamopt import plotting

    if args.cells == "pcolormesh":
        use_meshes()
    timings["import"] = (time.perf_counter() - wall, time.process_time() - cpu)
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        png = Path(tmp) / f"{args.child}.png"
        for _ in range(1 + args.repeat):
            w0, c0 = time.perf_counter(), time.process_time()
            fig = draw(plotting, args.child, data)
            w1, c1 = time.perf_counter(), time.process_time()
            plotting.save(fig, png, dpi=args.dpi)
            runs.append((w1 - w0, c1 - c0, time.perf_counter() - w1, time.process_time() - c1))
        size_kb = png.stat().st_size / 1e3
    timings["cold"] = runs[0]
    timings["warm"] = tuple(min(r[i] for r in runs[1:]) for i in range(4)) if len(runs) > 1 else runs[0]
    print(json.dumps({"figure": args.child, "size_kb": size_kb, **timings}))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cell", type=float, default=50.0, help="horizontal cell side, m (layers stay 30 m)")
    parser.add_argument("--repeat", type=int, default=3, help="warm calls after the first")
    parser.add_argument("--figures", nargs="+", default=list(FIGURES), choices=FIGURES)
    parser.add_argument("--cells", choices=("imshow", "pcolormesh"), default="imshow")
    parser.add_argument("--dpi", type=float, default=None, help="PNG resolution (default: plotting.DPI)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.dpi is None:
        from uamopt.plotting.style import DPI

        args.dpi = DPI
    if args.child:
        child(args)
        return
    print(f"paper case, {args.cell:g} m cells, {args.cells}, {args.dpi:g} dpi; seconds wall / CPU")
    print("| figure | import matplotlib | import plotting | cold build | cold save | warm build | warm save | PNG kB |")
    print("|---|---|---|---|---|---|---|---|")
    for name in args.figures:
        command = [sys.executable, __file__, "--child", name, "--cell", str(args.cell), "--repeat", str(args.repeat),
                   "--cells", args.cells, "--dpi", str(args.dpi)]
        row = json.loads(subprocess.run(command, capture_output=True, text=True, check=True).stdout.splitlines()[-1])
        cold, warm = row["cold"], row["warm"]

        def pair(wall, cpu):
            return f"{wall:.2f} / {cpu:.2f}"

        print(f"| {name} | {pair(*row['matplotlib'])} | {pair(*row['import'])} | {pair(cold[0], cold[1])} | "
              f"{pair(cold[2], cold[3])} | "
              f"{pair(warm[0], warm[1])} | {pair(warm[2], warm[3])} | {row['size_kb']:.0f} |", flush=True)


if __name__ == "__main__":
    main()
