"""Write notebooks/00_quickstart.ipynb: the paper case end to end with `import uamopt` only."""
from nbgen import code, md, write_notebook

cells = [
    md("""# 00 · Quick start: the paper case end to end (`import uamopt` only)

Risk field → one track in four stages (Table 2) → the route network → the flight plan (Eq. 23) →
three solvers → the independent verifier → a benchmark table. Every stage is one call; results
are typed objects with `to_frame()`. Executed by `tests/test_notebooks.py`: each `assert` is a
check (the values it compares come from the paper's Table B.3 and from the verifier, not from the
code under test)."""),
    code("""from pathlib import Path
import uamopt as ua

root = Path.cwd()
if not (root / "models").is_dir() and (root.parent / "models").is_dir():  # opened from notebooks/
    root = root.parent
scenario = ua.load_scenario(root / "models" / "paper_case.toml")
field = ua.compute_risk(scenario)
summary = field.summary()
assert summary["grid"]["shape"] == [50, 90, 12]  # 2500 × 4500 × 360 m in 50 × 50 × 30 m cells (Sec. 6.2)
print(f"{summary['cells']:,} cells, {summary['unsafe_share']:.1%} unsafe")"""),
    md("""## Table 2: one track in four stages, V1 → V4 (P_O → P_D of Table B.3)

At the scenario's own 50 × 50 × 30 m cells, so that this notebook runs in seconds. The paper's
Table 2 is at 10 m cells (C_R 196 for its shortest track), and C_R is not comparable across cell
sizes: the road term R^V of a cell grows with the road length inside it (Eq. 7, l_r per cell), so
the 50 m risks here are several times the 10 m ones. Notebook 02 runs Table 2 at 10 m, as
`uamopt reproduce` does (`ua.load_scenario(..., ["grid.cell=[10,10,10]"])`)."""),
    code("""model = ua.planning_model(scenario, field)
plan = ua.plan_track(model, "V1", "V4")
table2 = plan.to_frame()
assert (table2["length_m"] >= 4365.0 - 1e-6).all()  # never shorter than |V4 − V1| = 4365 m (Table B.3 L_14)
table2"""),
    code("""fig = ua.plotting.tracks(plan, model, title="V1 → V4 at 50 m cells")
fig  # the last expression of a cell is what Jupyter shows"""),
    md("## The route network and the flight plan (Sec. 6.2, Eq. 23)"),
    code("""network = ua.plan_network(model)
flights = ua.generate_flights(scenario, network)
frame = flights.to_frame()
assert len(network) == 20 and len(frame) == 120 and frame["aircraft"].nunique() == 20  # 10 routes; F = 6 by Eq. 23
frame.head()"""),
    md("## Three solvers, each schedule checked by the independent verifier"),
    code("""problem = ua.build_problem(flights, scenario)
schedules = {name: ua.solve(problem, name, time_limit_s=30) for name in ("greedy", "soa", "highs")}
for name, schedule in schedules.items():
    assert ua.verify(problem, schedule).ok, name
    print(f"{name:7s} {schedule.status:9s} objective {schedule.objective:9.4f} operated {schedule.operated_count}")
print(f"objective: {problem.objective_kind} (most flights, then least delay; docs/readings.md)")
assert schedules["highs"].status == "optimal"
assert schedules["highs"].objective <= min(s.objective for s in schedules.values()) + 1e-6"""),
    md("""## See it fly: the 3-D playback

The city, the unsafe airspace per layer (toggle in the legend), the tracks, and the highs schedule
played back at its times (slider, play, colour by route or delay; hover an aircraft). It is one
offline HTML file: `view.save("view.html")`, or `uamopt view DIR` from the shell."""),
    code("""view = ua.plotting.explore(problem, schedules["highs"], field=field)
assert len(view.figure.frames) > 100 and view.figure.layout.meta["uamopt"]["rejected"] == []  # the verifier rejects no pair
view"""),
    md("## A benchmark table (seeds × solvers, one time limit)"),
    code("""table = ua.benchmark(problem, ["greedy", "soa"], seeds=[0, 1], time_limit_s=10, progress=False)
assert len(table) == 4 and table["verified"].all()
table[["profile", "seed", "status", "objective", "operated", "solve_seconds"]]"""),
]

write_notebook(cells, "00_quickstart.ipynb")
