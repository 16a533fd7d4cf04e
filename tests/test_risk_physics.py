"""The risk model's physics against the reference numbers of docs/readings.md and known limits."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp, tplquad

from uamopt.city.layers import CityLayers
from uamopt.grid import AirspaceGrid
from uamopt.risk import (
    crash_area,
    drag_constant,
    fall_time,
    fatality_probability,
    impact_energy,
    impact_speed,
    mean_relative_speed,
    risk_field,
    swept_volume,
    terminal_speed,
    vehicle_collision_probability,
)
from uamopt.scenario import Scenario

B3 = Scenario()
G = 9.8
S_E = crash_area(6.0)
LAM = 6.04e-5


def approx_printed(value: str, rel: float = 1e-6):
    """Compare to a printed reference to 1e-6 relative, or to half a unit of its last digit when
    the reference carries fewer digits than that."""
    ref = float(value)
    mantissa = value.lower().split("e")[0]
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    exponent = int(value.lower().split("e")[1]) if "e" in value.lower() else 0
    half_ulp = 0.5 * 10.0 ** (exponent - decimals)
    return pytest.approx(ref, rel=rel, abs=half_ulp)


def k_for(payload_kg: float) -> float:
    return drag_constant(400.0 + payload_kg, 0.3, 1.225, S_E)


# (terminal, v(148.2), t(148.2), E, P cs=0.5, P cs=0.75, R^P cs=0.5) from docs/readings.md (Reference numbers)
REFERENCE = {
    0.0: ("27.468", "27.174496", "7.323078", "147690.7", "0.277616", "0.115849", "1.185261e-07"),
    220.0: ("34.198", "32.740228", "6.677222", "332296.0", "0.365664", "0.146535", "1.561174e-07"),
}


def test_crash_area_matches_notes():
    assert S_E == approx_printed("28.274334")


@pytest.mark.parametrize("payload", [0.0, 220.0])
def test_reference_numbers(payload):
    ref = REFERENCE[payload]
    k = k_for(payload)
    m = 400.0 + payload
    v = float(impact_speed(148.2, k, G))
    energy = float(impact_energy(m, v))
    p5 = float(fatality_probability(energy, 0.5, 1e6, 232.0))
    p75 = float(fatality_probability(energy, 0.75, 1e6, 232.0))
    assert terminal_speed(k, G) == approx_printed(ref[0])
    assert v == approx_printed(ref[1])
    assert float(fall_time(148.2, k, G)) == approx_printed(ref[2])
    assert energy == approx_printed(ref[3])
    assert p5 == approx_printed(ref[4])
    assert p75 == approx_printed(ref[5])
    n_people = 2.5e-4 * S_E
    assert n_people == approx_printed("7.068583e-03")
    assert LAM * n_people * p5 == approx_printed(ref[6])


def test_vehicle_terms():
    """P^V (Eq. 5) and R^V = λ N^V P^V (Eq. 4) of a column with l_r = 50 m of road, through the
    field computation: N^V = ρ_V l_r = 3.5 makes R^V = 4.092704e-05 at every altitude (reference)."""
    assert vehicle_collision_probability(9.68, 0.07, 3.5) == approx_printed("0.1936")
    grid = AirspaceGrid(cell=(50.0, 50.0, 30.0), shape=(2, 1, 10))
    zeros = np.zeros((2, 1))
    city = CityLayers(zeros, zeros, np.array([[0.0], [50.0]]), zeros + 2.5e-4, zeros + 0.5, zeros > 0, zeros > 0,
                      source="test")
    field = risk_field(B3, grid, city)
    assert np.all(field.risk_V[0] == 0.0)
    for value in field.risk_V[1, 0]:
        assert value == approx_printed("4.092704e-05")


@pytest.mark.parametrize("payload", [0.0, 220.0])
def test_impact_speed_and_fall_time_solve_the_drag_ode(payload):
    """A.3 and the fall time agree with a numerical solution of dv/dt = g − k v²."""
    k = k_for(payload)
    sol = solve_ivp(lambda t, y: [y[1], G - k * y[1] ** 2], (0, 60), [0.0, 0.0],
                    events=lambda t, y: y[0] - 148.2, rtol=1e-12, atol=1e-12)
    t_hit = sol.t_events[0][0]
    v_hit = sol.y_events[0][0][1]
    assert float(fall_time(148.2, k, G)) == pytest.approx(t_hit, rel=1e-8)
    assert float(impact_speed(148.2, k, G)) == pytest.approx(v_hit, rel=1e-8)


def test_large_height_gives_terminal_speed():
    k = k_for(220.0)
    assert float(impact_speed(1e5, k, G)) == pytest.approx(terminal_speed(k, G), rel=1e-12)
    # the fall time from very high grows like h / v_terminal without overflowing
    t = float(fall_time(1e6, k, G))
    assert np.isfinite(t) and t == pytest.approx(1e6 / terminal_speed(k, G), rel=1e-3)


def test_small_height_is_free_fall():
    k = k_for(0.0)
    h = 1e-3
    assert float(impact_speed(h, k, G)) == pytest.approx(math.sqrt(2 * G * h), rel=1e-5)
    assert float(fall_time(h, k, G)) == pytest.approx(math.sqrt(2 * h / G), rel=1e-5)


def test_fatality_probability_at_alpha_is_one_half():
    assert float(fatality_probability(1e6, 0.5, 1e6, 232.0)) == pytest.approx(0.5, abs=1e-15)


def test_fatality_probability_shelter_to_zero():
    """c_s → 0: P → 1 above β, 0 below β, and c_s = 0 itself is handled without dividing by 0."""
    above = fatality_probability(1000.0, np.array([1e-3, 1e-6, 0.0]), 1e6, 232.0)
    below = fatality_probability(100.0, np.array([1e-3, 0.0]), 1e6, 232.0)
    at = fatality_probability(232.0, 0.0, 1e6, 232.0)
    assert np.all(np.isfinite(above)) and above[-1] == 1.0 and above[0] > 0.999
    assert below[-1] == 0.0 and below[0] < 1e-6
    assert float(at) == pytest.approx(1.0 / (1.0 + math.sqrt(1e6 / 232.0)))


def test_fatality_probability_increases_with_energy_and_falls_with_shelter():
    e = np.geomspace(300, 1e7, 50)
    p = fatality_probability(e, 0.5, 1e6, 232.0)
    assert np.all(np.diff(p) > 0)
    assert np.all(fatality_probability(e, 0.75, 1e6, 232.0) < p)


def test_mean_relative_speed_matches_notes_and_adaptive_quadrature():
    a = B3.aircraft
    value = mean_relative_speed(a.speed_min_mps, a.speed_max_mps, 6.0, math.pi / 6)
    assert value == pytest.approx(23.664, abs=5e-4)
    ref, _ = tplquad(
        lambda eps, gam, ve: math.sqrt(ve**2 + 36 + 12 * ve * (math.cos(math.pi / 6) * math.cos(gam) * math.cos(eps)
                                                               - math.sin(math.pi / 6) * math.sin(gam))),
        a.speed_min_mps, a.speed_max_mps, -math.pi / 2, math.pi / 2, 0.0, math.pi, epsabs=1e-10, epsrel=1e-10,
    )
    assert value == pytest.approx(ref / (math.pi**2 * (a.speed_max_mps - a.speed_min_mps)), rel=1e-9)


def test_average_of_a_constant_is_that_constant():
    """With v_U = 0 the integrand is v_e, whose A.6 average is the mid-speed."""
    assert mean_relative_speed(10.0, 30.0, 0.0, 0.3) == pytest.approx(20.0, rel=1e-12)


def test_swept_volume():
    """V_e = e_w e_h (v_r' t + e_l) (Eq. A.5): the volume a box e_l × e_w × e_h sweeps moving v_r' t
    along its length. Every dimension differs, so a swapped argument shows; the reference is the
    convex hull of the box at its start and its end (scipy), no formula of the code."""
    from scipy.spatial import ConvexHull

    length, width, height = 6.0, 2.0, 0.5
    # by hand: 2 m × 0.5 m × (3 m/s · 4 s + 6 m) = 18 m³
    assert float(swept_volume(4.0, 3.0, length, width, height)) == pytest.approx(18.0, rel=1e-12)
    times = np.array([0.0, 0.5, 2.0, 7.323078])
    box = np.array(list(itertools.product((0.0, length), (0.0, width), (0.0, height))))
    for t, volume in zip(times, swept_volume(times, 23.664, length, width, height), strict=True):
        moved = box + np.array([23.664 * t, 0.0, 0.0])
        assert volume == pytest.approx(ConvexHull(np.vstack([box, moved])).volume, rel=1e-9)
    # Table B.3's aircraft (e_l = e_w = 5.63 m, e_h = 1.855 m) at rest: the box itself, 58.7977 m³
    assert float(swept_volume(0.0, 23.664, 5.63, 5.63, 1.855)) == pytest.approx(58.7977, abs=1e-4)


def test_road_threshold_and_open_ground_bound():
    """A road makes a cell unsafe once l_r > 0.407 m; without road R stays below R_0 even at
    terminal speed (ω1 R^P ≤ 8.02e-8 at m_p = 220 kg)."""
    p_v = vehicle_collision_probability(9.68, 0.07, 3.5)
    per_metre = 0.3 * LAM * 0.07 * p_v
    l_star = 1e-7 / per_metre
    assert 0.4065 < l_star < 0.4075
    k = k_for(220.0)
    e_max = float(impact_energy(620.0, terminal_speed(k, G)))
    p_max = float(fatality_probability(e_max, 0.5, 1e6, 232.0))
    people = 0.5 * LAM * 2.5e-4 * S_E * p_max
    assert people == pytest.approx(8.02e-8, rel=5e-4)  # the bound docs/readings.md quotes, to its 3 digits
    t_300 = float(fall_time(300.0, k, G))
    uav = 0.2 * LAM * 3.48e-8 * 5.63 * 1.855 * (23.664 * t_300 + 5.63)
    assert people + uav < 1e-7
