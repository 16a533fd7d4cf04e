"""Benchmark: the track planner's optimal search and the whole four-stage plan.

Run on demand (not collected by pytest; several minutes, most of it the 8010 maze rows):

    .venv/bin/python tests/benchmarks/bench_planning.py [--movingai-rows N] [--nx-cell 20] [--cells 10 5]

(i)   Moving AI: every scenario row of both maps in tests/data/movingai, fast backend with the
      transport heuristic: rows matching the optimal length to 1e-3, and the total time.
(ii)  The paper case at 10 m cells, P_O → P_D: time of ``planning_model`` and of ``plan_track``
      (all four stages, default heuristic), numba warmed up first on a tiny problem. Target: plan < 5 s.
(iii) The peer in the same run: the initial-stage search with networkx's A* vs the fast backend
      on the same graph and heuristic. networkx needs minutes at 10 m cells, so this is the paper
      case at ``--nx-cell`` (20 m: 0.5 million cells, networkx ≈ 40 s). Target: ≥ 30×.
(iv)  The paper case at 5 m cells (32 million cells): plan time and peak resident memory.
      Targets: < 60 s, < 6 GB (the whole ``uamopt plan``'s 1.2 GB is row (vi)'s).
(v)   The planning model's clearance (Eq. 15) at each cell size: ``clearance_ok`` (edt's float32
      squared transform, exact cut) against its peer in the same process, scipy's float64
      ``distance_transform_edt`` on the same building mask (best of 3 each), as a ratio. Target:
      the whole planning model < 0.5 s at 10 m cells.

(vi)  The whole commands, as a user runs them: ``uamopt plan`` and ``uamopt risk`` on the paper
      case with ``--no-figures`` at each cell size, from process start (imports included): wall
      time, peak resident memory (``os.wait4``'s rusage of that one child) and the memory guard's
      estimate (``grid.memory_limit_gb``: uamopt/grid/grid.py, MEMORY_MODEL) beside it. The peer is
      the paper's own time for its optimal track (68.7 s at 10 m, 659.5 s at 5 m). Targets: plan
      at 10 m <= 3 s (>= 35x the paper), at 5 m <= 10 s and <= 1.2 GB; each estimate within 20 %.

(vii) The 3-D search on the Moving AI voxel benchmark (tests/data/warframe: ``Simple`` and ``Complex``,
      ``--voxel-rows`` rows of each, evenly spread; 0 skips it) beside tcod's compiled A* on the same
      queries (bench_voxel.py's runs; that script has the full table). Target: every row optimal,
      median per query <= tcod's.

(ii) and (iv) each run in a fresh subprocess, so each peak memory (``ru_maxrss``, which includes
the city and the risk field the planner needs, and the clearance peer's scipy transform) is that
cell size's alone.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from uamopt import load_city, load_scenario, risk_field, scenario_grid  # noqa: E402
from uamopt.planning import SearchProblem, grid_search, plan_track, planning_model  # noqa: E402
from uamopt.planning.graph import grid_graph  # noqa: E402
from uamopt.planning.movingai import movingai_problem, read_map, read_scenarios  # noqa: E402
from uamopt.planning.tracks import endpoint_cell  # noqa: E402

MOVINGAI = ROOT / "tests" / "data" / "movingai"
MAPS = ("arena.map", "maze512-32-9.map")
SCENARIO = ROOT / "models" / "paper_case.toml"
P_O, P_D = (300.0, 300.0, 120.0), (2220.0, 4220.0, 120.0)  # Table B.3
TARGET_PLAN_S = {10.0: 5.0, 5.0: 60.0}
TARGET_MODEL_S = {10.0: 0.5}
TARGET_RSS_GB = {5.0: 6.0}
TARGET_RATIO = 30.0
TARGET_COMMAND_S = {10.0: 3.0, 5.0: 10.0}  # the whole `uamopt plan`
TARGET_COMMAND_GB = {5.0: 1.2}
PAPER_OPTIMAL_S = {10.0: 68.7, 5.0: 659.5}  # the paper's time for its optimal track
ESTIMATE_TOLERANCE = 0.20


def warm_up() -> None:
    """Load (or compile) the numba search once, so timings measure the search alone."""
    free = np.ones((3, 3, 2), dtype=bool)
    zero = np.zeros(free.shape)
    problem = SearchProblem(free, zero, zero, (1.0, 1.0, 1.0), 1.0, 1.0, 1.0)
    for heuristic in ("transport", "zero"):
        grid_search(problem, (0, 0, 0), (2, 2, 1), heuristic=heuristic)


def paper_model(cell_m: float):
    """(model, start cell, goal cell, seconds for city + risk field, seconds for planning_model)."""
    scenario = load_scenario(SCENARIO, [f"grid.cell=[{cell_m},{cell_m},{cell_m}]"])
    t0 = time.perf_counter()
    grid = scenario_grid(scenario)
    field = risk_field(scenario, grid, load_city(scenario, grid))
    t_field = time.perf_counter() - t0
    t0 = time.perf_counter()
    model = planning_model(scenario, field)
    t_model = time.perf_counter() - t0
    return model, endpoint_cell(model, P_O, "origin"), endpoint_cell(model, P_D, "destination"), t_field, t_model


def movingai(rows_per_map: int) -> list[dict]:
    out = []
    for name in MAPS:
        problem = movingai_problem(read_map(MOVINGAI / name))
        rows = read_scenarios(MOVINGAI / f"{name}.scen")
        if rows_per_map:
            rows = rows[len(rows) - 1::-max(1, len(rows) // rows_per_map)][::-1]
        matched, worst, expansions = 0, 0.0, 0
        t0 = time.perf_counter()
        for row in rows:
            result = grid_search(problem, *row.cells(), backend="fast", heuristic="transport")
            error = abs(result.cost - row.optimal_length)
            matched += error <= 1e-3
            worst = max(worst, error)
            expansions += result.expansions
        out.append({"map": name, "rows": len(rows), "matched": matched, "worst_error": worst,
                    "seconds": time.perf_counter() - t0, "mean_expansions": expansions / len(rows)})
    return out


def networkx_peer(cell_m: float) -> dict:
    """Initial-stage search, transport heuristic, fast vs networkx on the same problem."""
    model, start, goal, _, _ = paper_model(cell_m)
    problem = model.search_problem("initial")
    # the transport heuristic on both sides: the peers compare backends on the same (large) search
    fast = min((grid_search(problem, start, goal, backend="fast", heuristic="transport") for _ in range(3)),
               key=lambda r: r.seconds)
    t0 = time.perf_counter()
    graph = grid_graph(problem.passable, problem.cell)
    t_graph = time.perf_counter() - t0
    edges = graph.number_of_edges()
    del graph
    reference = grid_search(problem, start, goal, backend="networkx", heuristic="transport")
    return {"cell_m": cell_m, "shape": list(problem.shape), "edges": edges, "fast_s": fast.seconds,
            "networkx_s": reference.seconds, "graph_build_s": t_graph, "fast_cost": fast.cost,
            "networkx_cost": reference.cost, "expansions": fast.expansions}


def clearance_peer(model) -> dict:
    """(v): the clearance as the model builds it, and scipy's float64 transform on the same mask."""
    from scipy import ndimage

    from uamopt.planning.problem import building_cells, clearance_layers, clearance_ok

    building, cell, s_min = building_cells(model.field), model.field.grid.cell, model.scenario.tracks.clearance_m
    below = clearance_layers(building, cell, s_min)

    def best(fn) -> tuple[float, np.ndarray]:
        times, out = [], None
        for _ in range(3):
            t0 = time.perf_counter()
            out = fn()
            times.append(time.perf_counter() - t0)
        return min(times), out

    t_ours, ours = best(lambda: clearance_ok(building, cell, s_min))
    t_scipy, theirs = best(lambda: ndimage.distance_transform_edt(~building[:, :, :below], sampling=cell) >= s_min - 1e-9)
    return {"clearance_s": t_ours, "clearance_scipy_s": t_scipy,
            "clearance_same": bool(np.array_equal(ours[:, :, :below], theirs) and ours[:, :, below:].all())}


def plan_child(cell_m: float) -> dict:
    """Body of the subprocess for (ii)/(iv): warm up, build the model, plan, report."""
    warm_up()
    model, _, _, t_field, t_model = paper_model(cell_m)
    peer = clearance_peer(model)
    t0 = time.perf_counter()
    plan = plan_track(model, P_O, P_D)
    t_plan = time.perf_counter() - t0
    return {"cell_m": cell_m, "shape": list(model.admissible.shape), "field_s": t_field, "model_s": t_model,
            "plan_s": t_plan, "stages_s": {k: v.seconds for k, v in plan.stages.items()},
            "expansions": {k: plan.stages[k].extra["expansions"] for k in ("shortest", "initial")},
            "maxrss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20, **peer}


def whole_command(command: str, cell_m: float) -> dict:
    """(vi): one ``uamopt COMMAND`` process at ``cell_m`` cells: seconds, peak RSS and the guard's estimate, GB."""
    import tempfile

    from uamopt.grid.grid import memory_estimate

    scenario = load_scenario(SCENARIO, [f"grid.cell=[{cell_m},{cell_m},{cell_m}]"])
    cells = int(np.prod(scenario_grid(scenario).shape))
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        proc = subprocess.Popen([sys.executable, "-m", "uamopt", command, str(SCENARIO), "--set",
                                 f"grid.cell=[{cell_m},{cell_m},{cell_m}]", "--no-figures", "--out", f"{tmp}/out"],
                                cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        _, status, usage = os.wait4(proc.pid, 0)
        seconds = time.perf_counter() - t0
        stderr = proc.stderr.read().decode() if proc.stderr else ""
    if status != 0:
        sys.exit(f"uamopt {command} at {cell_m:g} m failed: {stderr}")
    return {"seconds": seconds, "peak_gb": usage.ru_maxrss / 2**20,
            "estimate_gb": memory_estimate(cells, "plan" if command == "plan" else "risk") / 2**30}


def voxel_rows(n: int) -> list[tuple[str, str, str, str]]:
    """(vii): bench_voxel.py's runs on ``n`` rows of each Warframe map, as rows of this table."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import bench_voxel as bv

    from uamopt.planning.voxel import read_voxel_map, read_voxel_map_text, read_voxel_scenarios, voxel_problem

    try:
        import tcod.path  # noqa: F401
    except ImportError:
        return [("(vii) Warframe voxel maps", "tcod is not installed (pip install tcod==21.2.2): skipped", "", "")]
    tiny = voxel_problem(read_voxel_map_text("voxel 3 3 3\n1 1 1\n"))  # compile for the voxel problems' array types
    grid_search(tiny, (0, 0, 0), (2, 2, 2))
    rows = []
    for name in ("Simple", "Complex"):
        voxels = read_voxel_map(bv.WARFRAME / f"{name}.3dmap")
        queries = bv.evenly(read_voxel_scenarios(bv.WARFRAME / f"{name}.3dmap.3dscen"), n)
        ours = bv.run_uamopt(voxel_problem(voxels), queries, "relaxed")
        graph, keep = bv.tcod_graph(voxels.passable)
        theirs = bv.run_tcod(graph, queries)
        del graph, keep
        med, t_med = (1e3 * float(np.median(r["seconds"])) for r in (ours, theirs))
        result = (f"{ours['optimal']}/{len(queries)} rows optimal (tcod {theirs['optimal']}); median {med:.1f} ms "
                  f"vs tcod {t_med:.1f} ms: {med / t_med:.2f}x")
        ok = ours["optimal"] == len(queries) and med <= t_med
        rows.append((f"(vii) Warframe {name}", result, "all optimal, <= tcod", verdict(ok)))
    return rows


def run_child(cell_m: float) -> dict:
    out = subprocess.run([sys.executable, __file__, "--child", str(cell_m)], check=True, capture_output=True,
                         text=True, cwd=ROOT)
    return json.loads(out.stdout.strip().splitlines()[-1])


def verdict(ok: bool) -> str:
    return "ok" if ok else "MISSED"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--movingai-rows", type=int, default=0, help="rows per map, evenly spread; 0 = all")
    parser.add_argument("--nx-cell", type=float, default=20.0, help="cell side (m) of the networkx comparison")
    parser.add_argument("--cells", type=float, nargs="*", default=[10.0, 5.0], help="cell sides (m) to plan at")
    parser.add_argument("--voxel-rows", type=int, default=200, help="Warframe rows per map for (vii); 0 = skip")
    parser.add_argument("--child", type=float, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child is not None:
        print(json.dumps(plan_child(args.child)))
        return

    warm_up()
    table: list[tuple[str, str, str, str]] = []
    if not MOVINGAI.is_dir():
        sys.exit(f"Moving AI benchmarks not found at {MOVINGAI}")
    for m in movingai(args.movingai_rows):
        result = (f"{m['matched']}/{m['rows']} rows match, worst |err| {m['worst_error']:.1e}; {m['seconds']:.1f} s "
                  f"({1e3 * m['seconds'] / m['rows']:.1f} ms/row, {m['mean_expansions']:.0f} expansions/row)")
        table.append((f"(i) Moving AI {m['map']}", result, "all", verdict(m["matched"] == m["rows"])))
    for cell_m in args.cells:
        c = run_child(cell_m)
        target = TARGET_PLAN_S.get(cell_m)
        stages = ", ".join(f"{k} {v:.2f}" for k, v in c["stages_s"].items())
        label = "(ii)" if cell_m == 10 else "(iv)" if cell_m == 5 else "    "
        result = (f"city+risk {c['field_s']:.2f} s, planning_model {c['model_s']:.2f} s, plan_track {c['plan_s']:.2f} s "
                  f"[{stages}; initial expansions {c['expansions']['initial']}]")
        table.append((f"{label} paper case {cell_m:g} m {tuple(c['shape'])}", result,
                      f"< {target:g} s" if target else "", verdict(c["plan_s"] < target) if target else ""))
        model_target = TARGET_MODEL_S.get(cell_m)
        ratio = c["clearance_scipy_s"] / c["clearance_s"]
        table.append((f"(v)  clearance {cell_m:g} m", f"{c['clearance_s']:.3f} s vs scipy {c['clearance_scipy_s']:.3f} s: "
                      f"{ratio:.1f}x, masks {'equal' if c['clearance_same'] else 'DIFFER'}; planning_model {c['model_s']:.2f} s",
                      f"model < {model_target:g} s" if model_target else "",
                      verdict(c["model_s"] < model_target and c["clearance_same"]) if model_target else ""))
        rss_target = TARGET_RSS_GB.get(cell_m)
        table.append((f"     peak memory {cell_m:g} m", f"{c['maxrss_gb']:.2f} GB (whole process: city, risk, model, plan)",
                      f"< {rss_target:g} GB" if rss_target else "",
                      verdict(c["maxrss_gb"] < rss_target) if rss_target else ""))
    for cell_m in args.cells:
        for command in ("plan", "risk"):
            c = whole_command(command, cell_m)
            off = c["estimate_gb"] / c["peak_gb"] - 1
            result = (f"{c['seconds']:.2f} s, peak {c['peak_gb']:.2f} GB, guard's estimate {c['estimate_gb']:.2f} GB "
                      f"({100 * off:+.0f} %)")
            targets, ok = [f"estimate within {100 * ESTIMATE_TOLERANCE:.0f} %"], abs(off) <= ESTIMATE_TOLERANCE
            if command == "plan" and cell_m in TARGET_COMMAND_S:
                paper = PAPER_OPTIMAL_S[cell_m] / c["seconds"]
                result += f"; {paper:.0f}x the paper's {PAPER_OPTIMAL_S[cell_m]:g} s"
                targets.append(f"<= {TARGET_COMMAND_S[cell_m]:g} s")
                ok &= c["seconds"] <= TARGET_COMMAND_S[cell_m]
            if command == "plan" and cell_m in TARGET_COMMAND_GB:
                targets.append(f"<= {TARGET_COMMAND_GB[cell_m]:g} GB")
                ok &= c["peak_gb"] <= TARGET_COMMAND_GB[cell_m]
            table.append((f"(vi) uamopt {command} {cell_m:g} m", result, ", ".join(targets), verdict(ok)))
    if args.nx_cell:
        p = networkx_peer(args.nx_cell)
        ratio = p["networkx_s"] / p["fast_s"]
        agree = abs(p["networkx_cost"] - p["fast_cost"]) <= 1e-9 * abs(p["fast_cost"])
        result = (f"fast {p['fast_s']:.3f} s, networkx {p['networkx_s']:.1f} s (graph build {p['graph_build_s']:.1f} s, "
                  f"{p['edges']} edges): {ratio:.0f}x, {(p['networkx_s'] - p['graph_build_s']) / p['fast_s']:.0f}x "
                  f"search only; costs {'agree' if agree else 'DIFFER'} ({p['fast_cost']:.6f})")
        table.append((f"(iii) initial search {p['cell_m']:g} m {tuple(p['shape'])}", result,
                      f">= {TARGET_RATIO:g}x", verdict(ratio >= TARGET_RATIO and agree)))
    if args.voxel_rows:
        table += voxel_rows(args.voxel_rows)
    width = max(len(row[0]) for row in table)
    print(f"{'benchmark':<{width}}  result  [target, verdict]")
    for name, result, target, ok in table:
        print(f"{name:<{width}}  {result}" + (f"  [{target}, {ok}]" if target else ""))


if __name__ == "__main__":
    main()
