"""The risk field cell by cell: risk.npz recomputed independently from its own layers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import tplquad

from uamopt.scenario import Scenario


def _reference_vr(a, v_u: float) -> float:
    def f(eps, gam, ve):
        return math.sqrt(ve * ve + v_u * v_u + 2 * ve * v_u * (
            math.cos(a.climb_angle_rad) * math.cos(gam) * math.cos(eps) - math.sin(a.climb_angle_rad) * math.sin(gam)))

    total, _ = tplquad(f, a.speed_min_mps, a.speed_max_mps, -math.pi / 2, math.pi / 2, 0, math.pi, epsrel=1e-10)
    return total / (math.pi**2 * (a.speed_max_mps - a.speed_min_mps))


def recompute_cell(s: Scenario, vr: float, h: float, cs: float, rho_p: float, l_r: float) -> tuple[float, float, float, float]:
    """Eqs. 1-8 for one free cell with the math module only, in the paper's own forms."""
    a, r = s.aircraft, s.risk
    m = a.empty_mass_kg + a.payload_kg
    s_e = math.pi * a.length_m**2 / 4
    v = math.sqrt(2 * m * r.gravity_mps2 / (r.drag_coefficient * r.air_density * s_e)
                  * (1 - math.exp(-h * r.drag_coefficient * r.air_density * s_e / m)))  # A.3 as printed
    e_imp = 0.5 * m * v * v  # A.1
    p_p = 1 / (1 + math.sqrt(r.alpha_j / r.beta_j) * (r.beta_j / e_imp) ** (1 / (4 * cs)))  # Eq. 3
    r_p = r.failure_rate_per_h * rho_p * s_e * p_p  # Eqs. 1-2
    n_v = r.traffic_density_per_m * l_r
    r_v = r.failure_rate_per_h * n_v * r.vehicle_area_m2 * r.traffic_density_per_m / r.road_width_m  # Eqs. 4-5
    vt = math.sqrt(2 * m * r.gravity_mps2 / (r.drag_coefficient * r.air_density * s_e))
    t = vt / r.gravity_mps2 * math.acosh(math.exp(r.gravity_mps2 * h / vt**2))
    r_u = r.failure_rate_per_h * r.uav_density_per_m3 * a.wingspan_m * a.height_m * (vr * t + a.fuselage_length_m)
    w1, w2, w3 = r.weights
    return w1 * r_p + w2 * r_v + w3 * r_u, r_p, r_v, r_u


@pytest.fixture(scope="module", params=["kept", "computed on first use"])
def npz(request, paper_run, tmp_path_factory):
    """The paper case's risk.npz: from a field that kept its three terms as computed, and from one
    that did not (``keep_risk=False``, a planning run's field), whose terms ``save_npz`` computes."""
    field = paper_run.field
    if request.param != "kept":
        import uamopt as ua

        field = ua.compute_risk(paper_run.scenario, keep_risk=False)
        assert field.terms is None  # nothing of the terms' size is held before they are asked for
    path = tmp_path_factory.mktemp("risk") / "risk.npz"
    field.save_npz(path)
    with np.load(path) as data:
        return {k: data[k] for k in data.files}


def test_npz_has_the_interface_arrays(npz, paper_run):
    shape = paper_run.grid.shape
    for name in ("risk", "risk_P", "risk_V", "risk_U", "unsafe", "obstacle"):
        assert npz[name].shape == shape, name
    for name in ("surface_height", "shelter", "road_length"):
        assert npz[name].shape == shape[:2], name
    assert npz["x"].shape == (shape[0],) and npz["z"].shape == (shape[2],)
    assert tuple(npz["cell"]) == (50.0, 50.0, 30.0)
    assert npz["unsafe"].dtype == bool and npz["obstacle"].dtype == bool


def test_every_sampled_cell_matches_the_formulas(npz, paper_run):
    s = paper_run.scenario
    vr = _reference_vr(s.aircraft, s.risk.uav_speed_mps)
    dz = float(npz["cell"][2])
    free = np.argwhere(~npz["obstacle"])
    rng = np.random.default_rng(0)
    sample = free[rng.choice(len(free), size=400, replace=False)]
    # make sure roads and both shelter classes are represented
    assert (npz["road_length"][sample[:, 0], sample[:, 1]] > 0).any()
    assert (npz["shelter"][sample[:, 0], sample[:, 1]] == 0.75).any()
    for i, j, k in sample:
        h = float(npz["z"][k] - npz["surface_height"][i, j])
        assert h >= dz / 2 - 1e-9
        ref = recompute_cell(s, vr, h, float(npz["shelter"][i, j]), float(npz["population_density"][i, j]),
                             float(npz["road_length"][i, j]))
        got = (npz["risk"][i, j, k], npz["risk_P"][i, j, k], npz["risk_V"][i, j, k], npz["risk_U"][i, j, k])
        assert got == pytest.approx(ref, rel=1e-9, abs=1e-300)


def test_obstacles_and_binary_field(npz):
    z_bottom = npz["z"] - float(npz["cell"][2]) / 2
    expected_obstacle = z_bottom[None, None, :] < npz["surface_height"][:, :, None] - 1e-9
    assert np.array_equal(npz["obstacle"], expected_obstacle)
    assert np.all(np.isnan(npz["risk"][npz["obstacle"]]))
    assert not np.any(np.isnan(npz["risk"][~npz["obstacle"]]))
    with np.errstate(invalid="ignore"):
        expected_unsafe = (npz["risk"] > 1e-7) | npz["obstacle"] | npz["no_fly"][:, :, None]
    assert np.array_equal(npz["unsafe"], expected_unsafe)


def test_roads_dominate_with_table_b3_values(npz):
    """Any free cell above a road exceeds R_0; no free cell above open ground does (docs/readings.md)."""
    free = ~npz["obstacle"]
    road = np.broadcast_to(npz["road_length"][:, :, None] > 0.41, free.shape)
    no_road = np.broadcast_to(npz["road_length"][:, :, None] == 0, free.shape)
    assert np.all(npz["risk"][free & road] > 1e-7)
    assert np.all(npz["risk"][free & no_road] < 1e-7)


def test_shelter_rule(npz):
    tall = npz["building_height"] > 15.0
    assert np.all(npz["shelter"][tall] == 0.75)
    assert np.all(npz["shelter"][~tall] == 0.5)


def test_people_risk_rises_with_height_to_terminal(npz):
    """R^P grows with h' (impact energy grows to terminal speed); R^V is constant up a column."""
    free = ~npz["obstacle"]
    i, j = np.argwhere(free[:, :, 0] & (npz["road_length"] > 0))[0]
    column_p = npz["risk_P"][i, j, :]
    column_v = npz["risk_V"][i, j, :]
    assert np.all(np.diff(column_p) > 0)
    assert np.allclose(column_v, column_v[0], rtol=0, atol=0)
