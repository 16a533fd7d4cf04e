"""The planning model's costly arrays (clearance, Eq. 11 risk, Eq. 35 shell counts) are built once
per risk field and reused by a second model of the same field (uamopt.planning.problem.field_arrays),
and a sweep's cases share the last case's field (uamopt.experiments.case.case_field), so a sweep over
the weights or μ builds them once per worker. Reused arrays must be those a fresh field gives: each
key they depend on is changed in turn, and the model must then equal one built from a new field."""

from __future__ import annotations

import numpy as np
import pytest

import uamopt as ua
from uamopt.experiments import case as cases

PAPER = "paper_case"
COARSE = ["grid.cell=[100,100,60]"]  # 25 x 45 x 6 cells: fast, and the band still holds layers


def arrays(model) -> tuple:
    return model.admissible, model.risk, model.shell_count


def test_a_second_model_of_the_field_takes_its_arrays():
    base = ua.load_scenario(PAPER, COARSE)
    field = ua.compute_risk(base)
    first = ua.planning_model(base, field)
    other = ua.load_scenario(PAPER, [*COARSE, "tracks.weights=[0.2,0.8]", "tracks.buffer_penalty=40"])
    second = ua.planning_model(other, field)
    assert all(a is b for a, b in zip(arrays(first), arrays(second), strict=True))
    # what does depend on the new keys does change: the weights and μ of the search
    problem = second.search_problem("initial")
    assert problem.penalty_scale == 40.0 and problem.w_risk == 0.2
    assert problem.c_h == pytest.approx(0.8 * second.c_h)


@pytest.mark.parametrize("override", ["tracks.clearance_m=100", "tracks.buffer_measure=count",
                                      "tracks.risk_model=continuous"])
def test_a_key_the_arrays_depend_on_builds_them_again(override):
    base = ua.load_scenario(PAPER, COARSE)
    field = ua.compute_risk(base)
    first = ua.planning_model(base, field)
    changed = ua.load_scenario(PAPER, [*COARSE, override])
    reused = ua.planning_model(changed, field)  # the field now holds the first model's arrays
    fresh = ua.planning_model(changed, ua.compute_risk(changed))
    for got, want in zip(arrays(reused), arrays(fresh), strict=True):
        assert got.dtype == want.dtype and np.array_equal(got, want)
    # the key matters: with the first model's arrays the test above would fail
    assert any(not np.array_equal(a, b) for a, b in zip(arrays(first), arrays(fresh), strict=True))
    # and the first model's arrays come back when its keys do
    again = ua.planning_model(base, field)
    assert all(np.array_equal(a, b) for a, b in zip(arrays(again), arrays(first), strict=True))


def test_a_sweeps_cases_share_the_last_field(monkeypatch):
    """Two plan cases that differ in the weights compute one field; a case with another city seed
    computes its own; the rows are those of cases that share nothing."""
    import uamopt.pipeline as pipeline

    computed = []
    compute = pipeline.compute_risk

    def counting(scenario, **kwargs):
        computed.append(scenario.city.seed)
        return compute(scenario, **kwargs)

    def rows(overrides):
        return [{k: v for k, v in row.items() if "seconds" not in k}
                for row in cases.run_case(ua.load_scenario(PAPER, [*COARSE, *overrides]), "plan")]

    monkeypatch.setattr(pipeline, "compute_risk", counting)
    monkeypatch.setattr(cases, "_LAST_FIELD", [])
    shared = [rows([]), rows(["tracks.weights=[0.2,0.8]"]), rows(["city.seed=8"])]
    seed = ua.load_scenario(PAPER).city.seed
    assert seed != 8 and computed == [seed, 8]  # the paper city once for two cases, then the new city
    alone = []
    for overrides in ([], ["tracks.weights=[0.2,0.8]"], ["city.seed=8"]):
        monkeypatch.setattr(cases, "_LAST_FIELD", [])
        alone.append(rows(overrides))
    assert shared == alone
    assert all(r[0]["status"] == "ok" for r in shared) and shared[0] != shared[1]
