"""Operational risk field (Sec. 4.1.1, App. A): Eqs. 1–9 and A.1–A.9, vectorised over every cell.

Readings (docs/readings.md):

- Each cell is evaluated separately; h' = centre altitude − surface height under it. A cell any
  part of which lies below the surface (inside or under a building) is an obstacle; its
  continuous risk values are NaN ("not airspace") and it is unsafe in Eq. 9.
- A.3 is the speed after a fall from rest through h' with quadratic drag,
  v² = (g/k)(1 − e^{−2kh'}), k = R_I ρ_a S_e / (2(m_e + m_p)); the fall time is
  t = arccosh(e^{kh'}) / √(gk). S_e = πd²/4 is both the crash disc (Eq. 2) and the frontal area.
- R^V uses l_r = road length inside the column's footprint; R^V = λ ρ_V l_r · S_v ρ_V / w_r.
- R^U = λ ρ_U V_e with V_e = e_w e_h (v_r' t + e_l) (A.4–A.5) and v_r' the A.6 average of A.9,
  computed once by Gauss–Legendre quadrature (v_r does not depend on time, so the time average
  is the identity).
- λ and therefore R and R_0 are per flight hour; λ is not converted.

Known weaknesses, reported rather than hidden: R^V grows with the cell side (l_r is per cell),
and with Table B.3 values any column over a road exceeds R_0 while open ground never does.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np
from scipy.special import expit

from uamopt.city.layers import CityLayers
from uamopt.grid import AirspaceGrid, altitude_band
from uamopt.scenario import Scenario

# --- physical models (one function each, SI units) -----------------------------------------


def crash_area(diameter_m: float) -> float:
    """S_e = π d² / 4, m² (Eq. 2): crash disc, also the frontal area of A.2–A.3."""
    return math.pi * diameter_m**2 / 4.0


def drag_constant(mass_kg: float, drag_coefficient: float, air_density: float, area_m2: float) -> float:
    """k = R_I ρ_a S_e / (2 m), 1/m, so that dv/dt = g − k v² (A.2)."""
    return drag_coefficient * air_density * area_m2 / (2.0 * mass_kg)


def terminal_speed(k: float, g: float) -> float:
    """√(g/k), m/s: the limit of A.3 as h' → ∞."""
    return math.sqrt(g / k)


def impact_speed(height_m, k: float, g: float):
    """Impact speed after a drag-limited fall from rest through ``height_m`` (Eq. A.3), m/s.

    v = √((g/k)(1 − e^{−2kh'})), written with ``expm1`` so small heights keep full precision.
    """
    return np.sqrt(-(g / k) * np.expm1(-2.0 * k * np.asarray(height_m, dtype=float)))


def fall_time(height_m, k: float, g: float):
    """Time to fall ``height_m`` from rest with quadratic drag, s: t = arccosh(e^{kh'}) / √(gk).

    Evaluated as (kh' + ln(1 + √(1 − e^{−2kh'}))) / √(gk), which does not overflow.
    """
    x = k * np.asarray(height_m, dtype=float)
    return (x + np.log1p(np.sqrt(-np.expm1(-2.0 * x)))) / math.sqrt(g * k)


def impact_energy(mass_kg: float, speed_mps):
    """E_imp = ½ (m_e + m_p) v², J (Eq. A.1)."""
    return 0.5 * mass_kg * np.asarray(speed_mps, dtype=float) ** 2


def fatality_probability(energy_j, shelter, alpha_j: float, beta_j: float):
    """P^P = 1 / (1 + √(α/β) (β/E_imp)^{1/(4 c_s)}) (Eq. 3).

    Computed as expit(−[½ ln(α/β) + ln(β/E)/(4 c_s)]). The limit c_s → 0 is taken exactly:
    P = 1 when E > β, 0 when E < β, 1/(1 + √(α/β)) when E = β; no division by zero.
    """
    energy = np.asarray(energy_j, dtype=float)
    cs = np.asarray(shelter, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = np.where(cs > 0, 1.0 / (4.0 * np.where(cs > 0, cs, 1.0)), np.inf)
        term = np.log(beta_j / energy) * inv
    term = np.where(np.isnan(term), 0.0, term)
    return expit(-(0.5 * math.log(alpha_j / beta_j) + term))


def relative_speed(v_e, v_u: float, theta: float, gamma, epsilon):
    """v_r between the aircraft and a UAV (Eq. A.9), m/s."""
    return np.sqrt(
        v_e**2 + v_u**2
        + 2.0 * v_e * v_u * (math.cos(theta) * np.cos(gamma) * np.cos(epsilon) - math.sin(theta) * np.sin(gamma))
    )


@lru_cache(maxsize=64)
def mean_relative_speed(v_min: float, v_max: float, v_u: float, theta: float, points: int = 64) -> float:
    """v_r' (Eq. A.6): the mean of A.9 over v_e ∈ [v_min, v_max], γ ∈ (−π/2, π/2), ε ∈ (0, π), m/s.

    The normalisation 1/(π² t (v_max − v_min)) of A.6 is exactly this average (the integrand does
    not depend on t). Tensor Gauss–Legendre quadrature with ``points`` nodes per axis; the
    integrand is smooth because v_e > v_U keeps v_r > 0.
    """
    nodes, weights = np.polynomial.legendre.leggauss(points)

    def on(a: float, b: float):
        return 0.5 * (b - a) * nodes + 0.5 * (b + a), 0.5 * (b - a) * weights

    ve, wv = on(v_min, v_max)
    ga, wg = on(-math.pi / 2, math.pi / 2)
    ep, we = on(0.0, math.pi)
    vr = relative_speed(ve[:, None, None], v_u, theta, ga[None, :, None], ep[None, None, :])
    total = np.einsum("i,j,k,ijk->", wv, wg, we, vr)
    return float(total / (math.pi**2 * (v_max - v_min)))


def swept_volume(fall_time_s, mean_speed_mps: float, length_m: float, width_m: float, height_m: float):
    """V_e = e_w e_h (v_r' t + e_l), m³ (Eq. A.5)."""
    return width_m * height_m * (mean_speed_mps * np.asarray(fall_time_s, dtype=float) + length_m)


def vehicle_collision_probability(vehicle_area_m2: float, traffic_density_per_m: float, road_width_m: float) -> float:
    """P^V = S_v ρ_V / w_r (Eq. 5)."""
    return vehicle_area_m2 * traffic_density_per_m / road_width_m


# --- the field -------------------------------------------------------------------------------


@dataclass(frozen=True)
class RiskConstants:
    """Scalars of the risk model derived once from the scenario."""

    mass_kg: float  # m_e + m_p
    crash_area_m2: float  # S_e
    k_per_m: float  # drag constant of A.2
    terminal_speed_mps: float
    mean_relative_speed_mps: float  # v_r' (A.6)
    vehicle_collision_probability: float  # P^V (Eq. 5)

    @classmethod
    def from_scenario(cls, scenario: Scenario) -> RiskConstants:
        a, r = scenario.aircraft, scenario.risk
        mass = a.empty_mass_kg + a.payload_kg
        area = crash_area(a.length_m)
        k = drag_constant(mass, r.drag_coefficient, r.air_density, area)
        return cls(
            mass_kg=mass,
            crash_area_m2=area,
            k_per_m=k,
            terminal_speed_mps=terminal_speed(k, r.gravity_mps2),
            mean_relative_speed_mps=mean_relative_speed(
                a.speed_min_mps, a.speed_max_mps, r.uav_speed_mps, a.climb_angle_rad, r.quadrature_points
            ),
            vehicle_collision_probability=vehicle_collision_probability(
                r.vehicle_area_m2, r.traffic_density_per_m, r.road_width_m
            ),
        )


@dataclass(frozen=True)
class TermModel:
    """Eqs. 1–7 and A.1–A.5 reduced to the scalars and column layers they need: one layer's
    three risk terms on demand (:meth:`layer`). Column terms are computed once: N^P = ρ_P S_e
    (Eq. 2), 1/(4 c_s) (Eq. 3, inf where c_s = 0) and R^V = λ ρ_V l_r P^V (Eqs. 4–5), which does
    not depend on altitude."""

    surface_height: np.ndarray  # (nx, ny), m
    half_cell_z: float  # m
    lam_people: np.ndarray  # λ N^P per column (Eqs. 1-2)
    inv4cs: np.ndarray  # 1/(4 c_s) per column
    risk_v_column: np.ndarray  # R^V per column
    k_per_m: float
    half_log_ab: float  # ½ ln(α/β)
    log_beta_over_half_mg_k: float  # ln β − ln(½ m g / k)
    root_gk: float  # √(g k)
    uav_scale: float  # λ ρ_U e_w e_h
    mean_speed_mps: float  # v_r' (A.6)
    fuselage_length_m: float  # e_l
    weights: tuple[float, float, float]  # w1, w2, w3 of Eq. 8

    @classmethod
    def of(cls, scenario: Scenario, grid: AirspaceGrid, city: CityLayers, c: RiskConstants) -> TermModel:
        r, a = scenario.risk, scenario.aircraft
        g, lam = r.gravity_mps2, r.failure_rate_per_h
        with np.errstate(divide="ignore"):
            inv4cs = np.where(city.shelter > 0, 1.0 / (4.0 * np.where(city.shelter > 0, city.shelter, 1.0)), np.inf)
        return cls(
            surface_height=city.surface_height, half_cell_z=0.5 * grid.cell[2],
            lam_people=lam * (c.crash_area_m2 * city.population_density), inv4cs=inv4cs,
            risk_v_column=lam * r.traffic_density_per_m * city.road_length * c.vehicle_collision_probability,
            k_per_m=c.k_per_m, half_log_ab=0.5 * math.log(r.alpha_j / r.beta_j),
            log_beta_over_half_mg_k=math.log(r.beta_j) - math.log(0.5 * c.mass_kg * g / c.k_per_m),
            root_gk=math.sqrt(g * c.k_per_m), uav_scale=lam * r.uav_density_per_m3 * a.wingspan_m * a.height_m,
            mean_speed_mps=c.mean_relative_speed_mps, fuselage_length_m=a.fuselage_length_m,
            weights=tuple(float(w) for w in r.weights),  # type: ignore[arg-type]
        )

    def layer(self, z: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(R^P, R^V, R^U, obstacle) of the layer centred at altitude ``z``; NaN in obstacle cells."""
        # h' per cell (docs/readings.md); an obstacle is any cell reaching below the surface.
        blocked = (z - self.half_cell_z) < self.surface_height - 1e-9
        height = np.where(blocked, np.nan, z - self.surface_height)
        decay = np.exp(-2.0 * self.k_per_m * height)  # e^{-2kh'}, shared by A.3 and the fall time
        with np.errstate(divide="ignore", invalid="ignore"):
            # ln E_imp = ln(½ m g / k) + ln(1 - e^{-2kh'})  (A.1, A.3)
            log_ratio = (self.log_beta_over_half_mg_k - np.log1p(-decay)) * self.inv4cs
        log_ratio = np.where(np.isnan(log_ratio) & ~blocked, 0.0, log_ratio)  # c_s = 0 and E = β
        risk_p = self.lam_people * expit(-(self.half_log_ab + log_ratio))  # Eqs. 1 and 3
        risk_v = np.where(blocked, np.nan, self.risk_v_column)
        with np.errstate(invalid="ignore"):
            t_fall = (self.k_per_m * height + np.log1p(np.sqrt(1.0 - decay))) / self.root_gk
        risk_u = self.uav_scale * (self.mean_speed_mps * t_fall + self.fuselage_length_m)  # A.4-A.5
        return risk_p, risk_v, risk_u, blocked

    def combined(self, risk_p: np.ndarray, risk_v: np.ndarray, risk_u: np.ndarray) -> np.ndarray:
        """R of Eq. 8 from one layer's terms."""
        w1, w2, w3 = self.weights
        return w1 * risk_p + w2 * risk_v + w3 * risk_u


#: the continuous arrays of a field: Eq. 8 and its three terms
TERMS = ("risk", "risk_P", "risk_V", "risk_U")


@dataclass(frozen=True)
class RiskField:
    """The risk field on the grid. 3-D arrays have shape (nx, ny, nz).

    ``risk`` is Eq. 8 and ``risk_P``, ``risk_V``, ``risk_U`` its terms (per flight hour; NaN in
    obstacle cells); ``unsafe`` is Eq. 9 (risk > R_0, obstacle or no-fly); ``obstacle`` marks
    cells inside or below a building.

    These four continuous arrays are kept as computed (``risk_field(..., keep_risk=True)``, the
    default, and a loaded ``risk.npz``) or else computed on first use from ``term_model``, all four
    in one pass, and kept from then on: the planner's default binary field needs only ``unsafe``,
    and at 5 m cells the four float64 arrays are 1.04 GB of a plan's memory.
    """

    grid: AirspaceGrid
    city: CityLayers
    unsafe: np.ndarray
    obstacle: np.ndarray
    band: tuple[float, float]
    constants: RiskConstants
    threshold: float
    seconds: float = 0.0
    meta: dict = field(default_factory=dict)
    terms: dict[str, np.ndarray] | None = field(default=None, repr=False, compare=False)  # TERMS, or None
    term_model: TermModel | None = field(default=None, repr=False, compare=False)

    def _terms(self) -> dict[str, np.ndarray]:
        if self.terms is None:
            if self.term_model is None:
                raise ValueError("this risk field holds neither its risk arrays nor the model to compute them")
            computed = {name: np.empty(self.grid.shape) for name in TERMS}
            for k, z in enumerate(self.grid.z):
                risk_p, risk_v, risk_u, _ = self.term_model.layer(z)
                values = (self.term_model.combined(risk_p, risk_v, risk_u), risk_p, risk_v, risk_u)
                for name, layer in zip(TERMS, values, strict=True):
                    computed[name][:, :, k] = layer
            object.__setattr__(self, "terms", computed)  # a cache of what the field already defines
        return self.terms  # type: ignore[return-value]

    def release(self) -> None:
        """Forget the continuous arrays where they can be computed again (a field from
        :func:`risk_field`; a loaded one keeps them): the memory of a plan after a summary."""
        if self.term_model is not None:
            object.__setattr__(self, "terms", None)

    @property
    def risk(self) -> np.ndarray:
        """R of Eq. 8, per flight hour (NaN in obstacle cells)."""
        return self._terms()["risk"]

    @property
    def risk_P(self) -> np.ndarray:
        """R^P (Eqs. 1–3), the ground-impact term, per flight hour."""
        return self._terms()["risk_P"]

    @property
    def risk_V(self) -> np.ndarray:
        """R^V (Eqs. 4–5), the road-vehicle term, per flight hour."""
        return self._terms()["risk_V"]

    @property
    def risk_U(self) -> np.ndarray:
        """R^U (Eqs. 6–7, A.4–A.9), the mid-air term, per flight hour."""
        return self._terms()["risk_U"]

    @property
    def no_fly(self) -> np.ndarray:
        """No-fly cells (bool, (nx, ny, nz)): every layer above a no-fly column."""
        return np.broadcast_to(self.city.no_fly[:, :, None], self.grid.shape)

    @property
    def binary(self) -> np.ndarray:
        """Eq. 9 as 0/1 floats: the field the planner uses by default."""
        return self.unsafe.astype(float)

    def band_layers(self) -> np.ndarray:
        """Layer indices inside the altitude band of Eq. 14."""
        return self.grid.layers_in_band(*self.band)

    def unsafe_share(self, layers=None) -> float:
        """Share of the free cells (not inside or below a building, Eq. 9's obstacles) that are
        unsafe (Eq. 9: R > R_0 or no-fly), over ``layers``: None for the altitude band of
        Eq. 14 (``summary()["band_unsafe_share"]``, the report's and ``risk.png``'s figure), "all"
        for the whole grid, else a sequence of layer indices. 0 when those layers hold no free
        cell. Obstacle cells are left out of both counts: they are unsafe by definition and
        nobody could fly there anyway."""
        if layers is None:
            layers = self.band_layers()
        elif isinstance(layers, str) and layers == "all":
            layers = np.arange(self.grid.shape[2])
        layers = np.asarray(layers, dtype=int).reshape(-1)
        free = ~self.obstacle[:, :, layers]
        n = int(free.sum())
        return float(self.unsafe[:, :, layers][free].sum() / n) if n else 0.0

    def arrays(self) -> dict[str, np.ndarray]:
        """The arrays of ``risk.npz`` (docs/interfaces.md)."""
        g = self.grid
        return {
            "risk": self.risk, "risk_P": self.risk_P, "risk_V": self.risk_V, "risk_U": self.risk_U,
            "unsafe": self.unsafe, "obstacle": self.obstacle, "no_fly": self.city.no_fly,
            "x": g.x, "y": g.y, "z": g.z, "cell": np.asarray(g.cell),
            "surface_height": self.city.surface_height, "building_height": self.city.building_height,
            "shelter": self.city.shelter, "road_length": self.city.road_length,
            "population_density": self.city.population_density, "open_space": self.city.open_space,
        }

    def save_npz(self, path: str | Path) -> None:
        np.savez_compressed(path, **self.arrays())

    def summary(self, seconds: dict | None = None) -> dict:
        """Cell counts, unsafe shares (whole grid and altitude band), risk statistics and timings:
        the content of the risk command's ``summary.json``. ``seconds`` defaults to
        ``meta["seconds"]`` (city, risk, total) or this field's own computing time."""
        g = self.grid
        band = self.band_layers()
        free = ~self.obstacle
        in_band = np.zeros(g.shape[2], dtype=bool)
        in_band[band] = True
        band_free = free & in_band[None, None, :]
        w = self.meta.get("weights", (0.5, 0.3, 0.2))

        def share(mask, of):
            n = int(of.sum())
            return float(mask[of].sum() / n) if n else 0.0

        if self.term_model is not None:  # R^V is a column term: no 3-D temporary
            road_driven = (w[1] * self.term_model.risk_v_column > self.threshold)[:, :, None] & free
        else:
            with np.errstate(invalid="ignore"):
                road_driven = (w[1] * self.risk_V > self.threshold) & free
        risk_free = self.risk[free]  # a copy: the median below may reorder it
        c = self.constants
        return {
            "scenario": self.meta.get("scenario", ""),
            "inputs": dict(self.meta.get("inputs", {})),
            "source": self.city.source,
            "attribution": self.city.attribution,
            "crs": self.city.crs,
            "origin": list(self.city.origin),
            "grid": {"cell_m": list(g.cell), "shape": list(g.shape), "extent_m": list(g.extent)},
            "cells": g.n_cells,
            "obstacle_cells": int(self.obstacle.sum()),
            "no_fly_cells": int((self.no_fly & free).sum()),
            "unsafe_cells": int(self.unsafe.sum()),
            "unsafe_share": float(self.unsafe.mean()),
            "band_m": list(self.band),
            "band_layers": [int(k) for k in band],
            "band_free_cells": int(band_free.sum()),
            "band_unsafe_share": self.unsafe_share(),  # of the band's free cells, as risk.png
            "unsafe_share_by_layer": {f"{z:g}": share(self.unsafe[:, :, k], free[:, :, k]) for k, z in enumerate(g.z)},
            "road_columns_share": float((self.city.road_length > 0).mean()),
            "road_driven_unsafe_share": share(road_driven, free),
            "risk_per_flight_hour": {
                "threshold_R0": self.threshold,
                "min": float(risk_free.min()) if risk_free.size else None,
                "median": float(np.median(risk_free, overwrite_input=True)) if risk_free.size else None,
                "max": float(risk_free.max()) if risk_free.size else None,
            },
            "constants": {
                "mass_kg": c.mass_kg,
                "crash_area_m2": c.crash_area_m2,
                "drag_k_per_m": c.k_per_m,
                "terminal_speed_mps": c.terminal_speed_mps,
                "mean_relative_speed_mps": c.mean_relative_speed_mps,
                "vehicle_collision_probability": c.vehicle_collision_probability,
            },
            "city": self.city.notes,
            "seconds": dict(seconds or self.meta.get("seconds") or {"risk": self.seconds}),
        }


def risk_field(scenario: Scenario, grid: AirspaceGrid, city: CityLayers, *, keep_risk: bool = True) -> RiskField:
    """Compute Eqs. 1–9 for every cell of ``grid`` over ``city``.

    Parameters
    ----------
    scenario : Scenario
        Risk (Table B.3) and aircraft parameters.
    grid : AirspaceGrid
        The cells.
    city : CityLayers
        Column layers on ``grid``'s footprint.
    keep_risk : bool
        Keep R (Eq. 8), R^P, R^V and R^U as computed (four float64 arrays the size of the grid);
        with False only Eq. 9's ``unsafe`` and ``obstacle`` are kept, and the four are computed
        again on first use (the planner's default binary field never uses them).

    Returns
    -------
    RiskField

    Raises
    ------
    TypeError
        An argument of another type (``scenario`` not a Scenario, ...).
    GridError
        ``city`` holds the layers of another grid.

    Examples
    --------
    >>> from uamopt import Scenario, AirspaceGrid, risk_field
    >>> from uamopt.city.layers import CityLayers
    >>> import numpy as np
    >>> g = AirspaceGrid(cell=(50.0, 50.0, 30.0), shape=(2, 1, 10))
    >>> zeros = np.zeros((2, 1))
    >>> city = CityLayers(zeros, zeros, np.array([[0.0], [50.0]]), zeros + 2.5e-4, zeros + 0.5,
    ...                   zeros > 0, zeros > 0, source="doc")
    >>> f = risk_field(Scenario(), g, city)
    >>> bool(f.unsafe[0, 0, 4]), bool(f.unsafe[1, 0, 4])   # open ground vs above a 50 m road
    (False, True)
    """
    from uamopt.checks import expect
    from uamopt.errors import GridError

    expect(scenario, Scenario, "scenario", "risk_field")
    expect(grid, AirspaceGrid, "grid", "risk_field")
    expect(city, CityLayers, "city", "risk_field")
    expect(keep_risk, bool, "keep_risk", "risk_field")
    if tuple(city.surface_height.shape) != tuple(grid.shape[:2]):
        raise GridError(f"the city layers are of another grid: {city.surface_height.shape[0]} × "
                        f"{city.surface_height.shape[1]} columns, the grid has {grid.shape[0]} × {grid.shape[1]}",
                        "risk_field(scenario, grid, city)", "pass the layers ua.load_city(scenario, grid) returns for this grid")
    started = time.perf_counter()
    r, c = scenario.risk, RiskConstants.from_scenario(scenario)
    shape = grid.shape
    model = TermModel.of(scenario, grid, city, c)
    terms = {name: np.empty(shape) for name in TERMS} if keep_risk else None
    unsafe = np.empty(shape, dtype=bool)
    obstacle = np.empty(shape, dtype=bool)

    # One layer at a time: every operation is vectorised over the layer's columns, and the
    # temporaries stay the size of one layer (memory ~ outputs only, even at 5 m cells).
    for k, z in enumerate(grid.z):
        risk_p, risk_v, risk_u, blocked = model.layer(z)
        layer = model.combined(risk_p, risk_v, risk_u)  # Eq. 8
        if terms is not None:
            for name, values in zip(TERMS, (layer, risk_p, risk_v, risk_u), strict=True):
                terms[name][:, :, k] = values
        with np.errstate(invalid="ignore"):
            unsafe[:, :, k] = (layer > r.threshold) | blocked | city.no_fly  # Eq. 9
        obstacle[:, :, k] = blocked
    return RiskField(
        grid=grid, city=city, unsafe=unsafe, obstacle=obstacle, band=altitude_band(scenario), constants=c,
        threshold=r.threshold, seconds=time.perf_counter() - started,
        meta={"scenario": scenario.name, "weights": tuple(r.weights), "inputs": field_inputs(scenario)},
        terms=terms, term_model=model,
    )


#: the scenario sections a risk field is computed from (the grid, the city, the aircraft of A.1-A.5, Eq. 8's weights)
FIELD_SECTIONS = ("grid", "city", "aircraft", "risk")


def field_inputs(scenario: Scenario) -> dict[str, str]:
    """A digest of each scenario section the field depends on (:data:`FIELD_SECTIONS`), so that a
    field given with another scenario is recognised (``ua.planning_model``), saved or not."""
    import hashlib
    import json

    def digest(name: str) -> str:
        values = getattr(scenario, name).model_dump(mode="json")
        values.pop("memory_limit_gb", None)  # a limit on the run, not an input of the field
        return hashlib.sha256(json.dumps(values, sort_keys=True).encode()).hexdigest()[:16]

    return {name: digest(name) for name in FIELD_SECTIONS}
