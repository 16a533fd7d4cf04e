"""The plotting API: every plot function draws into the axes it is given and returns their
Figure, makes a new Figure when ``ax`` is None, and writes nothing; ``save`` writes the file.

The paper case at its default 50 × 50 × 30 m cells. Expected values are computed here from the
inputs (the risk field's layer, the plan's waypoints, the schedule's decisions), not read back
from the plotting code.
"""

from __future__ import annotations

import dataclasses
import struct

import numpy as np
import pytest
from matplotlib import colors
from matplotlib.figure import Figure

from uamopt import plotting
from uamopt.planning.pareto import ParetoPoint

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
FIG18_COLOURS = {"shortest": "#d62728", "initial": "#ff7f0e", "equivalent": "#f2c200", "optimal": "#138a2e"}
CRUISE_LAYER = 4  # 120 m cruise altitude over 30 m layers: z = 120-150 m
SECTION_ROW = 45  # y = 2250 m, the middle of 4500 m, over 50 m rows


@pytest.fixture(scope="module")
def paper(paper_run):
    """(scenario, field, model, plan V1 → V4) at 50 m cells."""
    from uamopt.planning import plan_track, planning_model

    model = planning_model(paper_run.scenario, paper_run.field)
    return paper_run.scenario, paper_run.field, model, plan_track(model, "V1", "V4")


@pytest.fixture(scope="module")
def schedules(paper_straight_plan):
    """The paper-case problem on the straight network and two solvers' schedules of it."""
    from uamopt.schedule import build_problem
    from uamopt.solvers import load_profile, solve

    scenario, _, _, flights = paper_straight_plan
    problem = build_problem(flights, scenario, objective="lexicographic")
    return problem, {name: solve(problem, load_profile(name)) for name in ("greedy", "soa")}


def _one_axes(figsize=(6.0, 5.0)):
    fig = Figure(figsize=figsize)
    return fig, fig.add_subplot()


def _png_size(path) -> tuple[int, int]:
    """(width, height) in pixels from the PNG's IHDR chunk."""
    head = path.read_bytes()[:24]
    assert head[:8] == PNG_SIGNATURE and head[12:16] == b"IHDR"
    return struct.unpack(">II", head[16:24])


def _expected_log10(values: np.ndarray) -> np.ma.MaskedArray:
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.ma.masked_invalid(np.log10(values))


def _assert_same_image(drawn, expected: np.ma.MaskedArray) -> None:
    drawn = np.ma.masked_invalid(np.ma.filled(drawn.astype(float), np.nan))
    np.testing.assert_array_equal(np.ma.getmaskarray(drawn), np.ma.getmaskarray(expected))
    np.testing.assert_allclose(drawn.compressed(), expected.compressed(), rtol=1e-12)


# --- risk ----------------------------------------------------------------------------------------


def test_risk_draws_the_cruise_layer_into_given_axes(paper):
    scenario, field, _, _ = paper
    fig, ax = _one_axes()
    assert plotting.risk(field, ax, vertiports=scenario.network.vertiports) is fig
    (image,) = ax.images
    _assert_same_image(image.get_array(), _expected_log10(field.risk[:, :, CRUISE_LAYER]).T)
    assert {t.get_text() for t in ax.texts} >= {"V1", "V2", "V3", "V4", "V5", field.city.attribution}
    assert ax.get_title(loc="left").startswith(f"(a) risk R (Eq. 8) on layer k={CRUISE_LAYER}")


def test_risk_page_and_five_axes(paper):
    scenario, field, _, _ = paper
    page = plotting.risk(field, vertiports=scenario.network.vertiports, title="paper_case")
    assert isinstance(page, Figure) and len(page.axes) == 5
    assert page.get_suptitle().startswith("paper_case — city: synthetic")
    fig = Figure(figsize=(14, 8))
    axes = fig.subplots(1, 5)
    assert plotting.risk(field, axes) is fig
    (section,) = axes[2].images  # (c): without vertiports, the grid's middle row (y = 2250 m)
    assert f"(row j={SECTION_ROW})" in axes[2].get_title(loc="left")
    _assert_same_image(section.get_array(), _expected_log10(field.risk[:, SECTION_ROW, :]).T)
    assert [line.get_label() for line in axes[3].lines] == ["R (Eq. 8)", "R^P people", "R^V vehicles", "R^U UAVs",
                                                            "R₀"]


def test_risk_into_a_subfigure(paper):
    _, field, _, _ = paper
    fig = Figure(figsize=(20, 8))
    left, _ = fig.subfigures(1, 2, width_ratios=[14, 6])
    assert plotting.risk(field, left) is fig
    assert len(left.axes) == 5 and field.city.attribution in {t.get_text() for t in left.texts}
    assert left.get_suptitle().startswith("city: synthetic; cells 50 × 50 × 30 m (50 × 90 × 12)")


def test_wrong_axes_are_refused(paper):
    _, field, _, _ = paper
    fig = Figure()
    with pytest.raises(ValueError, match="5 Axes, got 2"):
        plotting.risk(field, fig.subplots(1, 2))
    with pytest.raises(TypeError, match="sequence of 5 Axes"):
        plotting.risk(field, ["not an axes"] * 5)
    with pytest.raises(ValueError, match="4 Axes, got 1"):
        plotting.risk_components(field, fig.add_subplot())


def test_risk_components_one_panel_per_term(paper):
    _, field, _, _ = paper
    fig = Figure(figsize=(12, 4))
    axes = fig.subplots(1, 4)
    assert plotting.risk_components(field, axes) is fig
    for ax, name in zip(axes, ("risk_P", "risk_V", "risk_U", "risk"), strict=True):
        (mean,) = [line for line in ax.lines if line.get_label() == "mean"]
        values = getattr(field, name)
        free = np.isfinite(values).sum(axis=(0, 1))
        expected = np.where(values >= 0, values, 0.0).sum(axis=(0, 1)) / np.maximum(free, 1)  # mean over free cells
        shown = np.isfinite(mean.get_xdata())
        np.testing.assert_allclose(mean.get_xdata()[shown], expected[shown], rtol=1e-12)
    assert isinstance(plotting.risk_components(field), Figure)


# --- tracks, network, pareto ----------------------------------------------------------------------


def test_tracks_draws_one_line_per_stage(paper):
    from uamopt.planning.tracks import STAGES

    _, _, model, plan = paper
    fig, ax = _one_axes()
    assert plotting.tracks(plan, model, ax) is fig
    assert len(ax.lines) == len(STAGES) == 4
    for line, name in zip(ax.lines, STAGES, strict=True):
        np.testing.assert_array_equal(line.get_xydata(), plan.stages[name].waypoints[:, :2])
        assert colors.to_hex(line.get_color()) == FIG18_COLOURS[name]
    (image,) = ax.images
    _assert_same_image(image.get_array(), _expected_log10(model.field.risk[:, :, CRUISE_LAYER]).T)


def test_tracks_page_and_three_axes(paper):
    _, _, model, plan = paper
    page = plotting.tracks(plan, model, title="paper_case")
    assert isinstance(page, Figure) and len(page.axes) == 3
    fig = Figure(figsize=(14, 8))
    axes = fig.subplots(3, 1)
    assert plotting.tracks(plan, model, axes) is fig
    profile = [line for line in axes[2].lines if colors.to_hex(line.get_color()) in FIG18_COLOURS.values()]
    assert len(profile) == 4  # one altitude profile per stage
    for line, name in zip(profile, FIG18_COLOURS, strict=True):
        np.testing.assert_array_equal(line.get_ydata(), plan.stages[name].waypoints[:, 2])


def test_network_draws_every_track(paper):
    _, _, model, plan = paper
    out = plan.stages["optimal"].waypoints
    routes = {"V1-V4": out, "V4-V1": out[::-1] + np.array([0.0, 0.0, 30.0]), "V1-X": out[: len(out) // 2]}
    fig, ax = _one_axes()
    assert plotting.network(model, routes, ax) is fig
    assert len(ax.lines) == 3
    fig = Figure(figsize=(14, 8))
    ax_map, ax_profile = fig.subplots(1, 2)
    plotting.network(model, {"routes": {k: {"waypoints": v.tolist()} for k, v in routes.items()}},
                     [ax_map, ax_profile])  # a network.json document
    assert len(ax_map.lines) == 3
    # (b): a row per route (V1-V4 with its way back, V1-X), each track's altitude profile in its row
    assert [[line.get_label() for line in row.lines] for row in ax_profile.child_axes] == [["V1-V4", "V4-V1"], ["V1-X"]]
    assert isinstance(plotting.network(model, routes), Figure)
    with pytest.raises(ValueError, match="at least one route"):
        plotting.network(model, {})


def test_pareto_front_and_dominated_points():
    def point(risk, transport):
        return ParetoPoint(0.5, 0.5, risk, transport, np.zeros((2, 3)))

    fig, ax = _one_axes()
    assert plotting.pareto([point(10, 5), point(8, 6), point(9, 7), point(3, 9)], ax) is fig
    (front,) = ax.lines
    assert front.get_xdata().tolist() == [5, 6, 9] and front.get_ydata().tolist() == [10, 8, 3]
    (dominated,) = ax.collections
    assert dominated.get_offsets().tolist() == [[7, 9]]
    assert isinstance(plotting.pareto([point(1, 1)]), Figure)
    with pytest.raises(ValueError, match="at least one ParetoPoint"):
        plotting.pareto([])


# --- schedules ------------------------------------------------------------------------------------


def test_gantt_draws_one_bar_per_operated_flight(schedules):
    from uamopt.schedule import Schedule

    problem, _ = schedules
    operated = np.ones(problem.n_flights, dtype=bool)
    operated[[2, 5, 9]] = False
    delay_s = np.zeros(problem.n_flights)
    delay_s[[0, 4]] = [30.0, 60.0]
    schedule = Schedule("by hand", "stopped", operated, delay_s, objective=None)
    fig, ax = _one_axes((14, 8))
    assert plotting.gantt(problem, schedule, ax) is fig
    shown, cancelled = ax.containers
    assert len(shown.patches) == problem.n_flights - 3 and len(cancelled.patches) == 3
    np.testing.assert_allclose(sorted(p.get_x() for p in shown.patches),
                               np.sort((problem.planned_departure_s + delay_s)[operated]))
    np.testing.assert_allclose(sorted(p.get_x() for p in cancelled.patches),
                               np.sort(problem.planned_departure_s[[2, 5, 9]]))
    (delay_lines,) = ax.collections
    assert [tuple(seg[:, 0]) for seg in delay_lines.get_segments()] == [
        (problem.planned_departure_s[0], problem.planned_departure_s[0] + 30.0),
        (problem.planned_departure_s[4], problem.planned_departure_s[4] + 60.0)]
    assert ax.get_title() == ("by hand: 117 operated, 3 cancelled, total delay 90 s — objective lexicographic: most "
                              "flights, then least delay")
    assert isinstance(plotting.gantt(problem, schedule), Figure)


def test_delays_side_by_side(schedules):
    problem, by_solver = schedules
    fig, ax = _one_axes((14, 5))
    assert plotting.delays(problem, by_solver, ax) is fig
    touched = np.zeros(problem.n_flights, dtype=bool)
    for s in by_solver.values():
        touched |= (s.delay_s > 0) | ~s.operated
    assert touched.sum() > 0
    assert len(ax.get_xticklabels()) == touched.sum()
    for n, s in enumerate(by_solver.values()):
        operated, cancelled = ax.containers[2 * n], ax.containers[2 * n + 1]
        assert len(operated.patches) + len(cancelled.patches) == touched.sum()
        np.testing.assert_allclose([p.get_height() for p in operated.patches], s.delay_s[touched & s.operated])
    assert isinstance(plotting.delays(problem, by_solver), Figure)


# --- files and imports ----------------------------------------------------------------------------


def test_save_writes_a_png_with_the_credit(paper, tmp_path):
    from matplotlib import image

    scenario, field, _, _ = paper
    page = plotting.risk(field, vertiports=scenario.network.vertiports)
    path = plotting.save(page, tmp_path / "risk.png")
    assert path == tmp_path / "risk.png"
    assert _png_size(path) == (round(14 * plotting.DPI), round(8 * plotting.DPI))
    assert path.stat().st_size > 50_000
    png = image.imread(path)
    assert png[-12:, -png.shape[1] // 4:, :3].min() < 0.5  # the credit, dark, in the bottom-right corner
    # the same page without attribution: that corner stays white
    bare = dataclasses.replace(field, city=dataclasses.replace(field.city, attribution=""))
    png = image.imread(plotting.save(plotting.risk(bare), tmp_path / "bare.png"))
    assert png[-12:, -png.shape[1] // 4:, :3].min() == 1.0


def test_save_follows_the_suffix(tmp_path):
    fig, ax = _one_axes((2, 1))
    ax.plot([0, 1], [1, 0])
    assert plotting.save(ax, tmp_path / "a.png").read_bytes()[:8] == PNG_SIGNATURE
    assert plotting.save(fig, tmp_path / "a.pdf").read_bytes()[:5] == b"%PDF-"
    assert _png_size(plotting.save(fig, tmp_path / "b.png", dpi=50)) == (100, 50)


def test_a_returned_figure_displays_as_png_in_ipython():
    from IPython.core.interactiveshell import InteractiveShell

    from uamopt.plotting.output import show_figures_in

    shell = InteractiveShell.instance()
    formatter = shell.display_formatter.formatters["image/png"]
    formatter.type_printers.pop(Figure, None)  # as in a kernel that has not imported pyplot
    assert shell.display_formatter.format(Figure())[0].keys() == {"text/plain"}
    assert show_figures_in(shell) and not show_figures_in(shell)  # registered once
    fig, ax = _one_axes((2, 1))
    ax.plot([0, 1], [1, 0])
    data, _ = shell.display_formatter.format(fig)
    assert data["image/png"][:8] == PNG_SIGNATURE
