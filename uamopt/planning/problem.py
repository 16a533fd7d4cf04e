"""The single-aircraft track planning model (Sec. 4.2, 5.1): admissible cells, costs, buffer.

Readings (docs/readings.md, paper Sec. 5.1):

- Admissible cells: passable (not an obstacle, not a no-fly zone; Eq. 9/15), centre altitude in
  the band of Eq. 14, and centre at least s_min from the centre of every *building* cell (Eq. 15).
  A building cell is an obstacle cell in a column whose surface stands more than
  ``city.building_min_height_m`` above the ground (``building_height > 0``); a lower bump (trees,
  cars in a DSM) is an obstacle the track cannot enter but not a clearance source.
  A continuous track is admissible when every point of it lies in admissible cells.
- Safety buffer (Eqs. 34–35): a box of n_s cells per axis around the cell entered,
  n_s = ⌈s_min/Δ⌉·2 + 1 (50 m cells → 3, 30 m layers → 5); R(t) counts the obstacle and no-fly
  cells on the box's outer shell (``tracks.buffer_measure = "structures"``, default): the buffer is
  "a safety margin between the aircraft and obstructions" (Sec. 5.1), while risk is already
  charged by Eq. 11. Counting every unsafe (road) cell instead makes one shell cell weigh about
  twenty risky steps at 10 m cells, and the planner climbs 120 → 265 m for +553 % transport cost,
  far from the paper's shape; that reading stays as the variant ``"count"``, with ``"share"``
  (the unsafe share of the shell). Cells outside the grid count as occupied. The move pays
  μ·R(t) on entering the cell (``tracks.buffer_charge = "path"``), or μ·R(t) only orders the
  search's open list (φ′ of Eq. 34, variant ``"priority"``). Computed for all cells at once with
  a 3-D summed-area table.
- Transport cost (Eqs. 12–13): c_h·horizontal + c_v·|vertical| times c_e·τ(m_p),
  τ = 1 + (m_p/m_p,max)·τ_max.
- Risk cost (Eq. 11) uses the binary field of Eq. 9 by default (``tracks.risk_model``), the
  continuous Eq. 8 field as a variant.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from uamopt.errors import UamoptError
from uamopt.planning.search import SearchProblem
from uamopt.risk import RiskField
from uamopt.scenario import Scenario


def load_factor(scenario: Scenario) -> float:
    """τ(m_p) = 1 + (m_p / m_p,max) τ_max (Eq. 13)."""
    a = scenario.aircraft
    return 1.0 + a.payload_kg / a.payload_max_kg * a.tau_max


def transport_rates(scenario: Scenario) -> tuple[float, float]:
    """(c_h c_e τ, c_v c_e τ): ¥ per horizontal and per vertical metre (Eq. 12), before ω5."""
    a = scenario.aircraft
    tau = load_factor(scenario)
    return a.c_h * a.c_e * tau, a.c_v * a.c_e * tau


def buffer_cells(cell: tuple[float, float, float], clearance_m: float) -> tuple[int, int, int]:
    """n_s per axis: ⌈s_min / Δ⌉ · 2 + 1 (Sec. 5.1)."""
    return tuple(math.ceil(clearance_m / d - 1e-9) * 2 + 1 for d in cell)  # type: ignore[return-value]


def box_counts(mask: np.ndarray, half: tuple[int, int, int], outside: bool = False) -> np.ndarray:
    """Number of True cells in the box of half-widths ``half`` centred on every cell (int32);
    cells beyond the grid count as ``outside``. Separable running sums, one axis at a time:
    O(cells), no loop over cells."""
    counts = np.pad(mask.astype(np.int32), [(h, h) for h in half], constant_values=int(outside))
    for axis, h in enumerate(half):
        np.cumsum(counts, axis=axis, dtype=np.int32, out=counts)  # in place: one grid-sized array
        width, n = 2 * h + 1, counts.shape[axis]

        def along(start: int, stop: int, axis: int = axis) -> tuple:
            return (slice(None),) * axis + (slice(start, stop),)

        box = counts[along(width - 1, n)].copy()  # running[i + w − 1] − running[i − 1], running[−1] = 0
        box[along(1, None)] -= counts[along(0, n - width)]
        counts = box
    return counts


def buffer_shell_count(occupied: np.ndarray, n_s: tuple[int, int, int]) -> np.ndarray:
    """R(t) of Eq. 35 for every cell: ``occupied`` cells on the outer shell of its n_s box.

    Cells beyond the grid count as occupied: airspace outside the modelled city is not known to be
    safe, and counting it free would make the domain's edge the most attractive place to fly.

    >>> solid = np.zeros((5, 5, 5), dtype=bool); solid[0, 2, 2] = True
    >>> int(buffer_shell_count(solid, (3, 3, 3))[1, 2, 2]), int(buffer_shell_count(solid, (3, 3, 3))[2, 2, 2])
    (1, 0)
    """
    outer = tuple((n - 1) // 2 for n in n_s)
    inner = tuple(h - 1 for h in outer)
    full = box_counts(occupied, outer, outside=True)
    if min(inner) < 0:
        return full
    return full - box_counts(occupied, inner, outside=True)  # type: ignore[arg-type]


def clearance_threshold_sq(cell: tuple[float, float, float], clearance_m: float) -> float | None:
    """A squared distance θ such that, between cell centres, d ≥ s_min − 10⁻⁹ exactly when d² > θ:
    the midpoint between the largest squared centre distance below the limit and the least one
    at or above it, over every integer offset within reach. None when two such values lie too
    close for float32 to tell apart (then :func:`clearance_ok` uses the float64 transform).

    >>> clearance_threshold_sq((10.0, 10.0, 10.0), 50.0)  # 2400 (e.g. 40, 20, 20) below, 2500 at
    2450.0
    """
    limit = (clearance_m - 1e-9) ** 2
    axes = [(np.arange(math.ceil(clearance_m / d) + 2) * d) ** 2 for d in cell]
    values = np.unique((axes[0][:, None, None] + axes[1][None, :, None] + axes[2][None, None, :]).ravel())
    below, above = values[values < limit], values[values >= limit]
    lo = float(below[-1]) if len(below) else 0.0
    hi = float(above[0])
    if hi - lo <= 1e-5 * hi:  # float32 squared distances carry ~1e-7 relative error: keep well apart
        return None
    return 0.5 * (lo + hi)


def clearance_layers(building: np.ndarray, cell: tuple[float, float, float], clearance_m: float) -> int:
    """How many layers from the ground the clearance's distance transform needs: a layer s_min or
    more above the highest building cell is clear (``building`` holds at least one cell)."""
    top = int(np.flatnonzero(building.any(axis=(0, 1)))[-1])
    return min(building.shape[2], top + math.ceil(clearance_m / cell[2] - 1e-9))


def clearance_ok(building: np.ndarray, cell: tuple[float, float, float], clearance_m: float) -> np.ndarray:
    """Cells whose centre is at least s_min from the centre of every building cell (Eq. 15).

    The squared distance transform is ``edt``'s (float32, a quarter of scipy's memory, about 2×
    faster at 10 m cells), compared with :func:`clearance_threshold_sq`'s exact cut, so the mask is
    the one scipy's float64 transform gives (tests/test_planning_model.py checks the two agree)."""
    if clearance_m <= 0 or not building.any():
        return np.ones(building.shape, dtype=bool)
    if building.all():
        return np.zeros(building.shape, dtype=bool)
    # the distance transform (the planning model's largest cost at fine cells) runs on the layers
    # below the first clear one only
    below = clearance_layers(building, cell, clearance_m)
    ok = np.ones(building.shape, dtype=bool)
    free = np.ascontiguousarray(~building[:, :, :below])
    threshold = clearance_threshold_sq(cell, clearance_m)
    if threshold is None:
        from scipy import ndimage

        ok[:, :, :below] = ndimage.distance_transform_edt(free, sampling=cell) >= clearance_m - 1e-9
        return ok
    import edt

    threads = max(1, min(4, os.cpu_count() or 1))  # the same distances whatever the count (separable passes)
    ok[:, :, :below] = edt.edtsq(free, anisotropy=tuple(float(c) for c in cell), black_border=False,
                                 parallel=threads) > threshold
    return ok


#: Risk weight of the shortest-track search, ¥ per metre of R = 1: a tie-break only. A whole
#: track's risk (< 10⁵ R·m) then weighs < 10⁻⁴ ¥, while two grid paths differing in their moves
#: differ in transport cost by at least ~(√2 − 1)·Δ·c_h ≈ 10⁻² ¥.
SHORTEST_TIE_BREAK = 1e-9


@dataclass(frozen=True)
class PlanningModel:
    """Everything the planner's stages need, derived once from the scenario and the risk field."""

    scenario: Scenario
    field: RiskField
    admissible: np.ndarray  # bool (nx, ny, nz)
    risk: np.ndarray  # R used in Eq. 11, 0 in inadmissible cells: uint8 0/1 (binary) or float64 (continuous)
    # R(t) of Eq. 35 per cell of the band (tracks.buffer_measure), 0 outside it: uint16/uint32 counts or float64 shares
    shell_count: np.ndarray
    n_s: tuple[int, int, int]
    c_h: float  # c_h c_e τ, ¥/m
    c_v: float  # c_v c_e τ, ¥/m

    def search_problem(self, stage: str) -> SearchProblem:
        """``shortest``: transport cost (standard A*), risk only breaking ties between equally cheap
        tracks (weight ``SHORTEST_TIE_BREAK`` ¥ per risky metre, far below any difference in
        transport cost between two grid paths); ``initial``: Eqs. 10–13 plus μ·R(t)."""
        # μ·R(t) as the shell counts and μ (penalty_scale): no grid-sized array is made per stage
        w_risk, w_transport = self.scenario.tracks.weights
        if stage == "shortest":
            return SearchProblem(self.admissible, self.risk, self.shell_count, self.field.grid.cell, SHORTEST_TIE_BREAK,
                                 self.c_h, self.c_v, penalty_scale=0.0)
        if stage != "initial":
            raise ValueError(f"stage must be 'shortest' or 'initial', got {stage!r}")
        mu = float(self.scenario.tracks.buffer_penalty)
        if self.scenario.tracks.buffer_charge == "priority":
            return SearchProblem(self.admissible, self.risk, self.shell_count, self.field.grid.cell, w_risk,
                                 w_transport * self.c_h, w_transport * self.c_v, priority=self.shell_count,
                                 penalty_scale=0.0, priority_scale=mu)
        return SearchProblem(self.admissible, self.risk, self.shell_count, self.field.grid.cell, w_risk,
                             w_transport * self.c_h, w_transport * self.c_v, penalty_scale=mu)


def check_aircraft_limits(scenario: Scenario) -> None:
    """Eqs. 18–19: take-off mass and wind within the aircraft's limits."""
    a, t = scenario.aircraft, scenario.tracks
    if a.empty_mass_kg + a.payload_max_kg > a.mass_max_kg:
        raise UamoptError(
            f"take-off mass m_e + m_p,max = {a.empty_mass_kg + a.payload_max_kg:g} kg exceeds m_max = {a.mass_max_kg:g} kg",
            "aircraft (Eq. 18)", "lower aircraft.payload_max_kg or raise aircraft.mass_max_kg")
    if a.payload_kg > a.payload_max_kg:
        raise UamoptError(f"payload m_p = {a.payload_kg:g} kg exceeds m_p,max = {a.payload_max_kg:g} kg",
                          "aircraft.payload_kg (Eq. 13)", "lower the payload")
    if t.wind_speed_mps > a.wind_max_mps:
        raise UamoptError(f"wind {t.wind_speed_mps:g} m/s exceeds the aircraft's limit v_we = {a.wind_max_mps:g} m/s",
                          "tracks.wind_speed_mps (Eq. 19)", "plan for a calmer wind or another aircraft")


def building_cells(field: RiskField) -> np.ndarray:
    """Obstacle cells of columns with a building (surface above ``city.building_min_height_m``):
    the cells s_min is measured from (Eq. 15)."""
    return field.obstacle & (field.city.building_height > 0)[:, :, None]


#: what the arrays of :func:`field_arrays` depend on besides the field: the scenario keys they read
ARRAY_KEYS = ("tracks.clearance_m", "tracks.risk_model", "tracks.buffer_measure")


def field_arrays(scenario: Scenario, field: RiskField) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(admissible, risk, shell_count) of the planning model: Eqs. 14–15, Eq. 11's risk and Eq. 35's
    R(t), the costly part of the model (the clearance's distance transform, the shell's running sums).

    They depend on the field and the keys of :data:`ARRAY_KEYS` only, not on the weights, μ or the
    transport rates, so they are kept on the field (the last set built from it) and a second model
    of the same field (a weight sweep, another track's scenario) takes them as they are: every model
    of the field shares them, so nothing may change them in place (the route network's confined
    models make new ones).
    """
    t = scenario.tracks
    key = (float(t.clearance_m), t.risk_model, t.buffer_measure)
    kept = vars(field).get("_planning_arrays")  # a cache beside the frozen dataclass's fields
    if kept is not None and kept[0] == key:
        return kept[1]
    grid = field.grid
    s_min = t.clearance_m
    in_band = np.zeros(grid.shape[2], dtype=bool)
    in_band[field.band_layers()] = True
    admissible = ~(field.obstacle | field.no_fly) & in_band[None, None, :]
    admissible &= clearance_ok(building_cells(field), grid.cell, s_min)
    if t.risk_model == "binary":  # 0/1 as uint8: an eighth of float64's memory, the same costs
        risk = (field.unsafe & admissible).view(np.uint8)
    else:
        risk = np.where(admissible, np.nan_to_num(field.risk, nan=0.0), 0.0)
    n_s = buffer_cells(grid.cell, s_min)
    occupied = (field.obstacle | field.no_fly) if t.buffer_measure == "structures" else field.unsafe
    inner = [max(n - 2, 0) for n in n_s]
    shell_cells = int(np.prod(n_s) - np.prod(inner))  # the most a count can be
    shell = np.zeros(grid.shape, dtype=np.uint16 if shell_cells < 2**16 else np.uint32)
    layers = field.band_layers()
    if len(layers):  # only band cells are ever entered: count there, from the layers within reach
        lo, hi, reach = int(np.min(layers)), int(np.max(layers)) + 1, (n_s[2] - 1) // 2
        z0, z1 = max(0, lo - reach), min(grid.shape[2], hi + reach)
        shell[:, :, lo:hi] = buffer_shell_count(occupied[:, :, z0:z1], n_s)[:, :, lo - z0:hi - z0]
    if t.buffer_measure == "share":
        # Variant: the unsafe share of the shell. With the count, the shell holds 26 cells at 50 m
        # but 602 at 10 m, so μ·R(t) grows 23-fold with resolution and outweighs Eq. 10 entirely.
        shell = shell / float(shell_cells)
    arrays = (admissible, risk, shell)
    vars(field)["_planning_arrays"] = (key, arrays)
    return arrays


def planning_model(scenario: Scenario, field: RiskField) -> PlanningModel:
    """Admissible cells, Eq. 11 risk, the buffer's shell counts and transport rates (the arrays
    from :func:`field_arrays`, built once per field and :data:`ARRAY_KEYS`)."""
    check_aircraft_limits(scenario)
    admissible, risk, shell = field_arrays(scenario, field)
    c_h, c_v = transport_rates(scenario)
    return PlanningModel(scenario, field, admissible, risk, shell, buffer_cells(field.grid.cell, scenario.tracks.clearance_m),
                         c_h, c_v)
