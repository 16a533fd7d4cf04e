"""BlueSky's protected zone derived from our cell-based conflict zone, and why it is sound.

Our model (Sec. 5.2.1, docs/readings.md): two operated flights conflict when, at overlapping times,
they occupy cells whose indices differ by at most r in every axis. BlueSky's zone is metric: a
loss of separation (LoS) is horizontal distance < r_pz and |Δalt| < h_pz.

**Verified ⇒ no LoS.** If the verifier accepts a schedule, then at every instant any two airborne
flights of different aircraft lie in cells that differ by ≥ r + 1 in some axis a, so their planned
coordinates differ by ≥ r·Δ_a in that axis (two cells apart by r + 1 leave r whole cells between
the points). Hence planned horizontal distance ≥ r·min(Δx, Δy) or planned |Δz| ≥ r·Δz. If each
flown position stays within e_h horizontally and e_v vertically of the planned position at the same
time, the flown horizontal distance ≥ r·min(Δx, Δy) − 2e_h or the flown |Δz| ≥ r·Δz − 2e_v. With

    r_pz = r·min(Δx, Δy) − 2·e_h − m,    h_pz = r·Δz − 2·e_v − m

(m = a small margin for BlueSky's spherical distances and float rounding) no pair can be in LoS.
The replay measures e_h and e_v of every flight and reports any flight beyond the budget; the
implication holds whenever none is. Paper case, 50 × 50 × 30 m cells, r = 1, budget 10 m / 2 m:
r_pz = 29.5 m, h_pz = 25.5 m.

**Rejected ⇒ near pair, not necessarily LoS.** A conflict of the verifier only says the two
planned positions are within the box |Δx| < (r+1)Δx, |Δy| < (r+1)Δy, |Δz| < (r+1)Δz (100 × 100 ×
60 m half sizes at 50/30 m cells), which is larger than the LoS cylinder. So the replay also
flags *near pairs*: flown positions inside that box widened by 2e and by the relative motion of
one sample step. Every verifier conflict lasting longer than one step is a near pair; it is a
LoS only when the two flights really come within r_pz and h_pz. They legitimately differ when a
pair is in adjacent cells but metrically apart, e.g. crossing one layer (30 m) apart: a conflict
for the cell model, a vertical separation of 30 m ≥ h_pz for BlueSky.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from uamopt.errors import UamoptError
from uamopt.export.defaults import DEFAULT_BUDGET_H_M, DEFAULT_BUDGET_V_M

MARGIN_M = 0.5  # m: spherical vs projected distance at 30 m (≤ 0.3 %), float rounding at the boundary


@dataclass(frozen=True)
class ProtectedZone:
    """BlueSky's LoS zone (r_pz, h_pz) and the near-pair box, all in metres."""

    rpz_m: float  # horizontal radius of the LoS cylinder
    hpz_m: float  # half height of the LoS cylinder
    near_m: tuple[float, float, float]  # half sizes of the near-pair box along x, y, z (before the step allowance)
    budget_h_m: float  # e_h
    budget_v_m: float  # e_v
    margin_m: float
    cell: tuple[float, float, float]
    conflict_radius: int

    def as_dict(self) -> dict:
        return asdict(self)


def protected_zone(cell, conflict_radius: int, *, budget_h_m: float = DEFAULT_BUDGET_H_M,
                   budget_v_m: float = DEFAULT_BUDGET_V_M, margin_m: float = MARGIN_M,
                   zone_m: tuple[float, float] | None = None) -> ProtectedZone:
    """The zone for cells ``cell`` = (Δx, Δy, Δz) and conflict radius r (see the module docstring).

    ``zone_m`` = (r_pz, h_pz) overrides the derived LoS zone (the near box stays derived).

    Raises
    ------
    UamoptError
        A derived zone that is empty (r = 0, or a budget too large for the cells): the cell model
        then guarantees no metric separation and the replay needs an explicit ``zone_m``.

    Examples
    --------
    >>> z = protected_zone((50.0, 50.0, 30.0), 1)
    >>> z.rpz_m, z.hpz_m, z.near_m
    (29.5, 25.5, (120.0, 120.0, 64.0))
    """
    dx, dy, dz = (float(c) for c in cell)
    r = int(conflict_radius)
    if budget_h_m < 0 or budget_v_m < 0:
        raise UamoptError(f"negative deviation budget ({budget_h_m}, {budget_v_m})", "replay", "give budgets ≥ 0 m")
    near = ((r + 1) * dx + 2 * budget_h_m, (r + 1) * dy + 2 * budget_h_m, (r + 1) * dz + 2 * budget_v_m)
    if zone_m is not None:
        rpz, hpz = (float(v) for v in zone_m)
    else:
        rpz = r * min(dx, dy) - 2 * budget_h_m - margin_m
        hpz = r * dz - 2 * budget_v_m - margin_m
    if rpz <= 0 or hpz <= 0:
        raise UamoptError(
            f"the protected zone is empty (r_pz = {rpz:g} m, h_pz = {hpz:g} m) for cells {cell} and r = {r}",
            "replay", "the cell model guarantees no metric separation here: give --zone RPZ,HPZ in metres")
    return ProtectedZone(rpz, hpz, near, budget_h_m, budget_v_m, margin_m, (dx, dy, dz), r)
