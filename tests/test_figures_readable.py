"""First contact: the figures read well. Each check is on the matplotlib objects a figure is
made of (titles, labels, limits, lines, legends after a draw), on hand-made inputs whose
expected values are written here, not computed by the plotting code.

- Fig. 21 (`plotting.pareto`): a far point does not squeeze the others (the axis is cut), the
  title says "trade-off" at most once, both series of the report are drawn with a legend;
- `plot_sweep(table, x=, hue=, y=)` on any sweep table; the fulfilment axis of Fig. 22 runs
  from 0 to 100 %;
- `network.png`: one colour per route, its way back dashed, route names, every track's profile,
  legends inside the page;
- the delay and Gantt titles name the objective; three maps side by side are (a), (b), (c);
- one unsafe share of the band for the report and risk.png; bench.md numbers for reading.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from instances import crossing_problem
from matplotlib import colors
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from uamopt import plotting
from uamopt.errors import UamoptError
from uamopt.experiments.store import columns, typed_frame
from uamopt.planning.pareto import ParetoPoint
from uamopt.plotting.sweeps import plot_sweep

# Fig. 21 at 10 m cells (regression values of the paper case): (ω4, ω5, C_R, C_T)
WITH_BUFFER = [(6.2e-09, 1.0, 318.8, 29.33), (0.0053, 0.9947, 304.7, 29.37), (0.0068, 0.9932, 286.4, 29.48),
               (0.022, 0.978, 278.1, 29.55), (0.029, 0.971, 272.3, 29.69), (0.045, 0.955, 262.3, 30.02),
               (0.066, 0.934, 258.1, 30.24), (0.57, 0.43, 249.9, 30.90), (1.0, 0.00016, 247.4, 123.62)]
WITHOUT_BUFFER = [(6.2e-09, 1.0, 288.5, 29.33), (0.011, 0.989, 280.6, 29.40), (0.013, 0.987, 268.5, 29.55),
                  (0.039, 0.961, 266.4, 29.59), (0.67, 0.33, 249.9, 30.90), (1.0, 0.00016, 247.4, 112.35),
                  (0.3, 0.7, 290.0, 29.80)]  # the last one is dominated
REPORT_TITLE = "paper_case: Eq. 10 + μ·R(t) trade-off"  # what uamopt reproduce passes


def _points(rows):
    return [ParetoPoint(w4, w5, risk, cost, np.zeros((2, 3))) for w4, w5, risk, cost in rows]


def _drawn(fig: Figure) -> Figure:
    FigureCanvasAgg(fig).draw()
    return fig


def _all_axes(fig: Figure) -> list:
    found, todo = [], list(fig.axes)
    while todo:
        ax = todo.pop()
        found.append(ax)
        todo += ax.child_axes
    return found


def _assert_legends_inside(fig: Figure) -> int:
    """Every legend's drawn box lies inside the figure; returns how many legends there are."""
    renderer = _drawn(fig).canvas.get_renderer()
    page = fig.bbox
    legends = [ax.get_legend() for ax in _all_axes(fig) if ax.get_legend() is not None] + list(fig.legends)
    for legend in legends:
        box = legend.get_window_extent(renderer)
        assert page.x0 - 0.5 <= box.x0 and box.x1 <= page.x1 + 0.5, (box, page)
        assert page.y0 - 0.5 <= box.y0 and box.y1 <= page.y1 + 0.5, (box, page)
    return len(legends)


# --- Fig. 21 ---------------------------------------------------------------------------------------


def test_pareto_cuts_the_cost_axis_for_the_far_point():
    fig = plotting.pareto(_points(WITH_BUFFER), title=REPORT_TITLE)
    (ax,) = fig.axes
    x0, x1 = ax.get_xlim()
    assert x0 <= 29.33 and 30.90 <= x1 < 40.0  # the eight tracks at ¥29–31 own the axis ...
    assert (30.90 - 29.33) / (x1 - x0) > 0.5  # ... and spread over most of it
    (beyond,) = ax.child_axes  # ... the ¥123.62 track is in the panel beyond the cut
    b0, b1 = beyond.get_xlim()
    assert b0 < 123.62 < b1 and b0 > 40.0
    assert beyond.get_ylim() == ax.get_ylim()  # on the same risk scale
    (front,) = [line for line in ax.lines if "Pareto front" in line.get_label()]
    assert front.get_xdata().tolist() == [c for *_, c in WITH_BUFFER]  # every track on the front, by cost
    assert "cut" in ax.get_xlabel()
    assert ax.get_title().lower().count("trade-off") <= 1 and ax.get_title().startswith(REPORT_TITLE)
    assert "Fig. 21" in ax.get_title()


def test_pareto_without_a_far_point_keeps_one_axis():
    fig = plotting.pareto(_points(WITH_BUFFER[:-1]))
    (ax,) = fig.axes
    assert not ax.child_axes and ax.get_xlim()[0] <= 29.33 and 30.90 <= ax.get_xlim()[1] < 31.2


def test_pareto_draws_both_series_of_the_report_with_a_legend():
    series = {"Eq. 10 (μ = 0)": _points(WITHOUT_BUFFER), "Eq. 10 + μ·R(t)": _points(WITH_BUFFER)}
    fig = plotting.pareto(series, title="paper_case")
    (ax,) = fig.axes
    fronts = [line for line in ax.lines if "Pareto front" in line.get_label()]
    assert len(fronts) == 2
    without = sorted(c for *_, c in WITHOUT_BUFFER[:-1])  # the dominated (29.80, 290.0) left out
    assert fronts[0].get_xdata().tolist() == without and fronts[1].get_xdata().tolist() == [c for *_, c in WITH_BUFFER]
    assert colors.to_hex(fronts[0].get_color()) != colors.to_hex(fronts[1].get_color())
    (dominated,) = ax.collections
    assert dominated.get_offsets().tolist() == [[29.80, 290.0]]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any(t.startswith("Eq. 10 (μ = 0)") for t in texts) and any(t.startswith("Eq. 10 + μ·R(t)") for t in texts)
    (beyond,) = ax.child_axes
    assert beyond.get_xlim()[0] < 112.35 and 123.62 < beyond.get_xlim()[1]  # both ω4 = 1 tracks
    assert _assert_legends_inside(fig) == 1
    assert plotting.pareto(series, ax=Figure()).axes  # into a given Figure as well


# --- sweeps ----------------------------------------------------------------------------------------

SPEEDS, FLEETS, SEEDS = (20.0, 25.0, 30.0), (4, 8), (0, 1, 2)


def _schedule_table():
    """A two-key schedule sweep as results.parquet holds it: avg delay = G·v/10 + 3·seed, SOA 2 s less."""
    rows = []
    for g in FLEETS:
        for v in SPEEDS:
            for solver in ("greedy", "soa"):
                for seed in SEEDS:
                    rows.append({"case": f"{g}-{v}", "schedule.aircraft": g, "aircraft.cruise_speed_mps": v,
                                 "solver": solver, "seed": seed, "status": "optimal", "flights": 6 * g,
                                 "operated": 6 * g - seed, "cancelled": seed,
                                 "avg_delay_s": g * v / 10 + 3 * seed - (2.0 if solver == "soa" else 0.0)})
    cols = {"case": "str", "schedule.aircraft": "Int64", "aircraft.cruise_speed_mps": "float64", **columns("schedule")}
    return typed_frame(rows, cols)


def test_plot_sweep_any_two_keys_one_line_per_hue_median_and_band():
    table = _schedule_table()
    fig = plot_sweep(table, x="aircraft.cruise_speed_mps", hue="schedule.aircraft")
    assert len(fig.axes) == 2  # the solver varies too: a panel each, not averaged away
    for ax, solver, less in zip(fig.axes, ("greedy", "soa"), (0.0, 2.0), strict=True):
        assert f"solver = {solver}" in ax.get_title()
        assert [line.get_label() for line in ax.lines] == ["4", "8"]
        for line, g in zip(ax.lines, FLEETS, strict=True):
            assert line.get_xdata().tolist() == list(SPEEDS)
            assert line.get_ydata().tolist() == pytest.approx([g * v / 10 + 3.0 - less for v in SPEEDS])  # seed 1
        bands = ax.collections
        assert len(bands) == 2
        for band, g in zip(bands, FLEETS, strict=True):
            y = band.get_paths()[0].vertices[:, 1]
            assert (y.min(), y.max()) == pytest.approx((g * 20 / 10 - less, g * 30 / 10 + 6.0 - less))
        assert [t.get_text() for t in ax.get_legend().get_texts()] == ["4", "8"]
        assert "schedule.aircraft" in ax.get_legend().get_title().get_text()
        assert [float(t) for t in ax.get_xticks()] == list(SPEEDS)
        assert "cruise speed" in ax.get_xlabel() and "average delay" in ax.get_ylabel()
        assert ax.get_ylim()[0] == 0.0
    default = plot_sweep(table)  # x: the first key, hue: the second, y: the schedule stage's delay
    assert [t.get_text() for t in default.axes[0].get_legend().get_texts()] == ["20", "25", "30"]
    assert [float(t) for t in default.axes[0].get_xticks()] == [4.0, 8.0]


def test_plot_sweep_fulfilment_and_bad_names():
    table = _schedule_table()
    fig = plot_sweep(table, x="schedule.aircraft", hue="solver", y="fulfilment")
    assert len(fig.axes) == 3  # one panel per speed
    for ax in fig.axes:
        assert ax.get_ylim() == (0.0, 100.0) and "%" in ax.get_ylabel()
        greedy = ax.lines[0]
        assert greedy.get_ydata().tolist() == pytest.approx([100 * (6 * g - 1) / (6 * g) for g in FLEETS])
    with pytest.raises(UamoptError, match="no metric 'nonsense'"):
        plot_sweep(table, y="nonsense")
    with pytest.raises(UamoptError, match=r"no column 'schedule\.nothing'"):
        plot_sweep(table, hue="schedule.nothing")


def _plan_table(n: int):
    """A one-key plan sweep over list-valued cells ("[c.0, c.0, 30.0]"): risk 10·c."""
    rows = [{"case": str(c), "grid.cell": f"[{c}.0, {c}.0, 30.0]", "status": "ok", "risk_cost": 10.0 * c}
            for c in range(5, 5 * (n + 1), 5)]
    return typed_frame(rows, {"case": "str", "grid.cell": "str", **columns("plan")})


def test_plot_sweep_categorical_labels_read():
    fig = plot_sweep(_plan_table(8))
    (ax,) = fig.axes
    labels = [t.get_text() for t in ax.get_xticklabels()]
    assert labels == [f"[{c}, {c}, 30]" for c in range(5, 45, 5)]  # no ".0", grid order
    assert all(t.get_rotation() > 0 for t in ax.get_xticklabels())  # too long to sit side by side
    (line,) = ax.lines
    assert line.get_ydata().tolist() == [10.0 * c for c in range(5, 45, 5)]
    assert "C_R" in ax.get_ylabel()  # the plan stage's default metric
    many = plot_sweep(_plan_table(30)).axes[0]
    shown = [t.get_text() for t in many.get_xticklabels() if t.get_text()]
    assert 2 <= len(shown) <= 12 and shown[0] == "[5, 5, 30]"


def test_fig22_fulfilment_axis_runs_from_0_to_100():
    rows = [{"case": str(f), "schedule.flights": f, "solver": s, "seed": seed, "status": "optimal", "flights": f,
             "operated": round(f * (0.84 if s == "greedy" else 0.97)) - seed, "cancelled": 0, "avg_delay_s": 10.0}
            for f in (40, 80, 120) for s in ("greedy", "highs") for seed in (0, 1)]
    table = typed_frame(rows, {"case": "str", "schedule.flights": "Int64", **columns("schedule")})
    fig = plot_sweep(table, "flights")
    delay, fulfilment = fig.axes
    assert fulfilment.get_ylim() == (0.0, 100.0)
    assert delay.get_ylim()[0] == 0.0
    assert [line.get_label() for line in fulfilment.lines] == ["greedy", "highs"]


# --- the route network -----------------------------------------------------------------------------

LONG = ["Kamppi", "Rautatientori", "Senaatintori", "Esplanadi", "Kaisaniemi"]  # Helsinki's, on the paper's ports


def _straight_network(model, names=None):
    """Every pair of the scenario's vertiports: a straight track at 120 m, the way back at 180 m."""
    ports = model.scenario.network.vertiports
    names = names or [p.name for p in ports]
    routes = {}
    for i in range(len(ports)):
        for j in range(i + 1, len(ports)):
            a, b = ports[i], ports[j]
            line = np.linspace([a.x, a.y, 120.0], [b.x, b.y, 120.0], 6)
            routes[f"{names[i]}-{names[j]}"] = line
            routes[f"{names[j]}-{names[i]}"] = line[::-1] + np.array([0.0, 0.0, 60.0])
    return routes


def test_network_one_colour_per_route_way_back_dashed_and_named(paper_model):
    routes = _straight_network(paper_model)
    fig = Figure(figsize=(14, 8))
    ax_map, ax_profile = fig.subplots(1, 2)
    plotting.network(paper_model, routes, [ax_map, ax_profile])
    drawn = {line.get_label(): line for line in ax_map.lines}
    assert set(drawn) == set(routes)
    route_colours = set()
    for name in list(routes)[::2]:
        a, b = name.split("-")
        out, back = drawn[name], drawn[f"{b}-{a}"]
        assert colors.to_hex(out.get_color()) == colors.to_hex(back.get_color())  # one colour per route
        assert (out.get_linestyle(), back.get_linestyle()) == ("-", "--")
        route_colours.add(colors.to_hex(out.get_color()))
    assert len(route_colours) == len(routes) // 2 == 10
    names = {f"V{i}–V{j}" for i in range(1, 6) for j in range(i + 1, 6)}
    labels = [t for t in ax_map.texts if t.get_text() in names]
    assert sorted(t.get_text() for t in labels) == sorted(names)  # every route named on the map, once
    for text in labels:
        x, y = text.xy  # beside its track, inside the map
        assert 0 <= x <= 2500 and 0 <= y <= 4500


def test_network_profile_shows_every_track(paper_model):
    routes = _straight_network(paper_model)
    fig = Figure(figsize=(14, 8))
    ax_map, ax_profile = fig.subplots(1, 2)
    plotting.network(paper_model, routes, [ax_map, ax_profile])
    rows = ax_profile.child_axes
    assert len(rows) == 10  # one row per route
    profiles = {line.get_label(): line for row in rows for line in row.lines if line.get_label() in routes}
    assert set(profiles) == set(routes)  # all 20 tracks, none hidden behind another
    for name, line in profiles.items():
        np.testing.assert_array_equal(line.get_ydata(), routes[name][:, 2])
        assert line.get_xdata()[-1] == pytest.approx(np.hypot(*(routes[name][-1, :2] - routes[name][0, :2])))
    assert len({row.get_xlim() for row in rows}) == 1 and len({row.get_ylim() for row in rows}) == 1  # one scale
    for row in rows:  # each row names its route
        assert any(name in row.get_title(loc="left") for name in routes)


def test_network_page_with_long_route_names_keeps_its_legends_inside(paper_model):
    routes = _straight_network(paper_model, LONG)
    fig = plotting.network(paper_model, routes, title="helsinki-like names")
    assert _assert_legends_inside(fig) >= 1
    ax_map, ax_profile = fig.axes
    assert {t.get_text() for t in ax_map.texts} >= {str(n) for n in range(1, 11)}  # numbered on the map ...
    assert {row.get_title(loc="left").split(":")[0] for row in ax_profile.child_axes} == {str(n) for n in range(1, 11)}
    assert any("Kamppi-Rautatientori" in row.get_title(loc="left") for row in ax_profile.child_axes)  # ... named here


# --- titles and panel letters ----------------------------------------------------------------------


def test_delay_and_gantt_titles_name_the_objective():
    from uamopt.solvers import solve

    titles = {}
    for kind, words in (("weighted", "Eq. 20 weighted"), ("lexicographic", "lexicographic: most flights, then least delay")):
        problem = crossing_problem(kind, (0.1, 0.9))
        schedules = {"greedy": solve(problem, "greedy"), "soa": solve(problem, "soa")}
        delays = plotting.delays(problem, schedules).axes[0].get_title()
        gantt = plotting.gantt(problem, schedules["soa"]).axes[0].get_title()
        assert words in delays and words in gantt
        assert delays.startswith("delay per flight") and gantt.startswith("soa: ")
        titles[kind] = (delays, gantt)
    assert titles["weighted"][0] != titles["lexicographic"][0] and titles["weighted"][1] != titles["lexicographic"][1]
    problem = crossing_problem("weighted", (0.1, 0.9))
    own = plotting.gantt(problem, solve(problem, "greedy"), title="helsinki: HiGHS").axes[0].get_title()
    assert own.startswith("helsinki: HiGHS") and "Eq. 20 weighted" in own


def test_three_maps_side_by_side_are_a_b_c(paper_run):
    fig = Figure(figsize=(15, 6.5))
    for ax, h in zip(fig.subplots(1, 3), (100.0, 160.0, 220.0), strict=True):  # notebook 01's Fig. 20
        plotting.risk(paper_run.field, ax=ax, cruise_altitude_m=h)
    assert [ax.get_title(loc="left")[:4] for ax in fig.axes] == ["(a) ", "(b) ", "(c) "]
    single = Figure()
    plotting.risk(paper_run.field, ax=single.add_subplot())
    assert single.axes[0].get_title(loc="left").startswith("(a) ")


# --- one unsafe share --------------------------------------------------------------------------------


def test_report_and_risk_page_give_the_same_unsafe_share_of_the_band(paper_run):
    from uamopt.report import risk_section

    field = paper_run.field
    band = field.band_layers()
    free = ~field.obstacle[:, :, band]
    expected = field.unsafe[:, :, band][free].sum() / free.sum()  # unsafe among the band's free cells
    every_cell = field.unsafe[:, :, band].mean()  # what risk.png showed before: buildings counted
    assert f"{expected:.1%}" != f"{every_cell:.1%}"  # the two readings differ on the paper case
    assert field.unsafe_share() == pytest.approx(expected, rel=1e-12)
    summary = field.summary()
    assert summary["band_unsafe_share"] == pytest.approx(expected, rel=1e-12)
    page = plotting.risk(field)
    assert f"{expected:.1%} of the band's free cells" in page.get_suptitle()
    assert f"{every_cell:.1%}" not in page.get_suptitle()
    assert f"free cells in the band {field.band[0]:g}–{field.band[1]:g} m (Eq. 14) | {100 * expected:.1f} %" in \
        risk_section(paper_run.scenario, summary)
    assert field.unsafe_share("all") == pytest.approx(field.unsafe[~field.obstacle].mean(), rel=1e-12)


# --- bench.md ------------------------------------------------------------------------------------------


def test_bench_markdown_numbers_for_reading():
    from uamopt.experiments.bench_report import bench_markdown

    base = {"instance": "paper_case", "flights": 120, "aircraft": 20, "conflicting_pairs": 300, "threads": 1,
            "time_limit_s": 20.0, "objective_kind": "lexicographic", "verified": True, "operated": 120,
            "cancelled": 0, "total_delay_s": 1711.0, "avg_delay_s": 85.55, "error": None}
    table = pd.DataFrame([
        {**base, "solver": "highs", "profile": "highs", "seed": 0, "status": "optimal", "model": "continuous",
         "objective": -119.98, "bound": -119.98, "gap": 1.33954e-15, "wall_seconds": 0.00869462,
         "solve_seconds": 0.00512345, "build_seconds": 0.00357117},
        {**base, "solver": "cpsat", "profile": "cpsat", "seed": 0, "status": "time_limit", "model": "continuous",
         "objective": -119.5, "bound": -119.98, "gap": 0.0040167, "wall_seconds": 20.123456,
         "solve_seconds": 19.987654, "build_seconds": 0.135802},
    ])
    text = bench_markdown(table)
    assert "e-15" not in text and "0.00869462" not in text
    section = text.split("## By solver profile")[1].split("\n## ")[0]
    highs = next(line for line in section.splitlines() if line.startswith("| paper_case | highs"))
    cells = [c.strip() for c in highs.strip("|").split("|")]
    assert cells[9:] == ["0.00 %", "0.00869", "0.00869", "0.00512", "0.00357"]  # gap, wall med/max, solve, build
    cpsat = next(line for line in section.splitlines() if line.startswith("| paper_case | cpsat"))
    assert [c.strip() for c in cpsat.strip("|").split("|")][9:] == ["0.40 %", "20.1", "20.1", "20.0", "0.136"]
    runs = text.split("## Runs")[1]
    assert "| 0.00 % |" in runs and "| 0.40 % |" in runs and "| 0.00869 |" in runs and "| 1711 |" in runs


def test_sweep_delay_figures_name_the_objective():
    """Figs. 22-23 and the generic sweep figure say which objective the schedules were solved under."""
    import pandas as pd

    from uamopt.plotting.sweeps import plot_sweep

    rows = [{"case": f"c{i}", "schedule.flights": f, "solver": s, "seed": 0, "status": "optimal", "verified": True,
             "objective_kind": "lexicographic", "avg_delay_s": d, "operated": f, "flights": f}
            for i, (f, s, d) in enumerate([(40, "greedy", 5.0), (80, "greedy", 9.0), (40, "highs", 2.0), (80, "highs", 4.0)])]
    table = pd.DataFrame(rows)
    for fig in (plot_sweep(table, "flights"), plot_sweep(table, x="schedule.flights", hue="solver")):
        assert "lexicographic objective" in fig.axes[0].get_title()
    weighted = table.assign(objective_kind="weighted")
    assert "Eq. 20 weighted" in plot_sweep(weighted, "flights").axes[0].get_title()


def test_weights_study_spreads_a_far_point_on_a_log_axis():
    """The weights sweep (Fig. 21 from models/variants/weights.toml): ¥29-31 and one ¥124 point."""
    import pandas as pd

    from uamopt.plotting.sweeps import plot_sweep

    weights = ["[0.0, 1.0]", "[0.25, 0.75]", "[0.5, 0.5]", "[1.0, 0.0]"]
    table = pd.DataFrame({"case": list("abcd"), "tracks.weights": weights, "status": "ok",
                          "risk_cost": [300.0, 260.0, 250.0, 240.0], "transport_cost": [29.0, 30.0, 31.0, 124.0]})
    ax = plot_sweep(table, "weights").axes[0]
    assert ax.get_xscale() == "log" and "log scale" in ax.get_xlabel()
    assert ax.get_title().lower().count("trade-off") <= 1
    near = table.assign(transport_cost=[29.0, 30.0, 31.0, 32.0])
    assert plot_sweep(near, "weights").axes[0].get_xscale() == "linear"  # spread points: a plain axis
