"""The paper's shape under the default readings (issue: faithful defaults).

Checks against the paper's own Table 2 / Fig. 21 shape, computed here from the tracks' waypoints
and the scenario's Table B.3 constants (not from the planner's own metrics where avoidable):

- at 10 m and 20 m cells the initial, equivalent and optimal tracks stay within one cell layer of
  the cruise altitude (the paper's +¥5.59 over the shortest allows ~10 m of vertical movement in
  all: c_v / c_h ≈ 90.6);
- the initial track costs +0 % to +30 % more than the shortest (paper: +20.6 %) and carries less
  risk (paper: −11.2 %);
- at 10 m the ω4/ω5 sweep gives at least 4 non-dominated (C_R, C_T) points (Fig. 21 is a front).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import PAPER_CASE

from uamopt.pipeline import compute_risk
from uamopt.planning import plan_track, planning_model
from uamopt.planning.endpoints import PAPER_DESTINATION, PAPER_ORIGIN, default_endpoints
from uamopt.planning.pareto import weight_sweep
from uamopt.scenario import load_scenario


def _model(side: float, extra: list[str] | None = None):
    scenario = load_scenario(PAPER_CASE, [f"grid.cell=[{side},{side},{side}]", "grid.extent=[2500.0,4500.0,360.0]",
                                          *(extra or [])])
    return planning_model(scenario, compute_risk(scenario))


def transport_cost(scenario, waypoints) -> float:
    """Eq. 12-13 from Table B.3 constants: (c_h·horizontal + c_v·|vertical|)·c_e·τ(m_p), ¥."""
    a = scenario.aircraft
    tau = 1.0 + a.payload_kg / a.payload_max_kg * a.tau_max
    step = np.diff(np.asarray(waypoints, dtype=float), axis=0)
    return (a.c_h * np.hypot(step[:, 0], step[:, 1]).sum() + a.c_v * np.abs(step[:, 2]).sum()) * a.c_e * tau


@pytest.fixture(scope="module")
def model_10m():
    return _model(10.0)


@pytest.fixture(scope="module")
def model_20m():
    return _model(20.0)


@pytest.mark.parametrize("which", ["model_10m", "model_20m"])
def test_table2_shape(request, which):
    model = request.getfixturevalue(which)
    scenario = model.scenario
    plan = plan_track(model, PAPER_ORIGIN, PAPER_DESTINATION)
    dz = model.field.grid.cell[2]
    for name in ("initial", "equivalent", "optimal"):
        z = plan.stages[name].waypoints[:, 2]
        assert np.max(np.abs(z - scenario.network.cruise_altitude_m)) <= dz + 1e-6, name
    shortest, initial = plan.stages["shortest"], plan.stages["initial"]
    cost_s, cost_i = (transport_cost(scenario, s.waypoints) for s in (shortest, initial))
    assert cost_i == pytest.approx(initial.transport_cost, rel=1e-9)  # the planner's Eq. 12 is Eq. 12
    assert 0.0 <= cost_i / cost_s - 1.0 <= 0.30
    assert initial.risk_cost < shortest.risk_cost


def test_fig21_front_at_10m(model_10m):
    points = weight_sweep(model_10m, PAPER_ORIGIN, PAPER_DESTINATION, 9, buffer=True)
    pairs = {(round(p.risk_cost, 6), round(p.transport_cost, 9)) for p in points}
    front = [a for a in pairs if not any(b != a and b[0] <= a[0] and b[1] <= a[1] for b in pairs)]
    assert len(front) >= 4


def test_default_route_is_paper_track():
    """V1 and the vertiport farthest from it are Table B.3's P_O and P_D."""
    origin, destination = default_endpoints(load_scenario(PAPER_CASE))
    assert (origin.name, destination.name) == ("V1", "V4")
    assert origin.point == (300.0, 300.0, 120.0) and destination.point == (2220.0, 4220.0, 120.0)


def test_buffer_readings_act(model_20m):
    """Every value of tracks.buffer_measure and tracks.buffer_charge changes the initial track's search."""
    count = _model(20.0, ["tracks.buffer_measure=count"])
    share = _model(20.0, ["tracks.buffer_measure=share"])
    structures = model_20m.shell_count
    # structures: obstacle and no-fly cells only; count: unsafe (risky, obstacle, no-fly) cells
    assert np.all(count.shell_count >= structures) and np.any(count.shell_count > structures)
    assert float(share.shell_count.max()) <= 1.0 < float(count.shell_count.max())
    priority = _model(20.0, ["tracks.buffer_charge=priority"])
    problem = priority.search_problem("initial")
    assert not np.any(problem.entry_penalty()) and np.array_equal(problem.open_priority(), 100.0 * structures)


@pytest.mark.parametrize("backend", ["fast", "python"])
def test_priority_orders_the_search_but_is_not_paid(backend):
    """3 × 3 × 1 cells of 1 m, start (0, 1), goal (2, 1); 100 on the middle cell (1, 1)."""
    from uamopt.planning.search import SearchProblem, grid_search

    free, zero = np.ones((3, 3, 1), dtype=bool), np.zeros((3, 3, 1))
    hundred = zero.copy()
    hundred[1, 1, 0] = 100.0
    args = ((1.0, 1.0, 1.0), 0.0, 1.0, 1.0)
    plain = grid_search(SearchProblem(free, zero, zero, *args), (0, 1, 0), (2, 1, 0), backend=backend)
    paid = grid_search(SearchProblem(free, zero, hundred, *args), (0, 1, 0), (2, 1, 0), backend=backend)
    guided = grid_search(SearchProblem(free, zero, zero, *args, priority=hundred), (0, 1, 0), (2, 1, 0), backend=backend)
    assert plain.cost == pytest.approx(2.0) and len(plain.path) == 3  # straight through the middle
    assert paid.cost == pytest.approx(2 * np.sqrt(2.0)) and (1, 1, 0) not in map(tuple, paid.path)
    assert guided.cost == pytest.approx(2 * np.sqrt(2.0)) and (1, 1, 0) not in map(tuple, guided.path)
    walled = free.copy()
    walled[1, [0, 2], 0] = False  # the middle cell is now the only way
    assert grid_search(SearchProblem(walled, zero, hundred, *args), (0, 1, 0), (2, 1, 0), backend=backend).cost == \
        pytest.approx(102.0)
    assert grid_search(SearchProblem(walled, zero, zero, *args, priority=hundred), (0, 1, 0), (2, 1, 0),
                       backend=backend).cost == pytest.approx(2.0)  # guided, not paid


def test_priority_is_refused_by_networkx():
    from uamopt.planning.search import grid_search
    from uamopt.planning.tracks import endpoint_cell

    model = _model(50.0, ["tracks.buffer_charge=priority"])
    start, goal = endpoint_cell(model, PAPER_ORIGIN, "origin"), endpoint_cell(model, PAPER_DESTINATION, "destination")
    with pytest.raises(ValueError, match="no open-list priority"):
        grid_search(model.search_problem("initial"), start, goal, backend="networkx")


def test_helsinki_route_defaults_to_its_own_vertiports():
    """The real city's single-track comparison runs between its own vertiports (first and farthest)."""
    from conftest import ROOT

    origin, destination = default_endpoints(load_scenario(ROOT / "models" / "helsinki.toml"))
    assert (origin.name, destination.name) == ("Kamppi", "Senaatintori")
    assert origin.point == (80.0, 585.0, 120.0) and destination.point == (950.0, 595.0, 120.0)
    chosen = load_scenario(ROOT / "models" / "helsinki.toml", ["tracks.route=['Esplanadi','Kaisaniemi']"])
    assert [e.name for e in default_endpoints(chosen)] == ["Esplanadi", "Kaisaniemi"]


@pytest.mark.slow
def test_helsinki_reproduce_end_to_end(tmp_path):
    """`uamopt reproduce models/helsinki.toml` with no --set: every schedule verified, and no paper
    figure beside the Helsinki instance (measured: about 5 minutes on 2 shared cores)."""
    import json

    from conftest import ROOT

    from uamopt.cli import main
    from uamopt.schedule.verify import verify_dir

    out = tmp_path / "helsinki"
    assert main(["reproduce", str(ROOT / "models" / "helsinki.toml"), "--out", str(out)]) == 0
    folders = sorted(p.parent for p in out.glob("schedules/*/*/summary.json"))
    assert len(folders) == 10
    for folder in folders:
        assert verify_dir(folder) == [], folder
        assert json.loads((folder / "summary.json").read_text())["flights"] == 200
    report = (out / "report.md").read_text()
    assert "the paper has no figures for this track" in report and "[196]" not in report and "[109]" not in report


def test_explicit_end_points_override_the_route():
    scenario = load_scenario(PAPER_CASE, ["tracks.origin=[300.0,300.0,150.0]", "tracks.route=['V2','V3']"])
    origin, destination = default_endpoints(scenario)
    assert origin.point == (300.0, 300.0, 150.0) and origin.where == "tracks.origin"
    assert destination.name == "V3" and destination.point == (2220.0, 300.0, 120.0)
