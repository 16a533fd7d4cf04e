"""Family ``departure_spacing`` (shape ``pairs``): successive departures from one vertiport at
least ``schedule.departure_spacing_s`` apart — the worked example of docs/variants.md.

Any two operated flights f, g that leave the same vertiport (``origin``) keep
|dep_g − dep_f| ≥ s, i.e. δ = dep_g − dep_f avoids the open interval (−s, s). That is the
``pairs`` shape, so every solver already has its encoder; this module only computes the arrays.
Off (no family) when s = 0, the default: the paper's model is unchanged.
"""

from __future__ import annotations

import numpy as np

from uamopt.schedule.families.pairs import PairIntervals


def departure_spacing(flightset, spacing_s: float) -> PairIntervals:
    """Every pair of flights with one origin, forbidding departure gaps in (−s, s)."""
    origin = np.array([f.origin for f in flightset.flights])
    rows = []
    for name in np.unique(origin):
        same = np.flatnonzero(origin == name).tolist()
        rows += [(a, b, -spacing_s, spacing_s) for i, a in enumerate(same) for b in same[i + 1:]]
    return PairIntervals.of_rows("departure_spacing", rows, record_data={"spacing_s": float(spacing_s)},
                                 description=f"departure spacing: flights from one vertiport leave ≥ {spacing_s:g} s apart")


def from_scenario(flightset, scenario) -> PairIntervals | None:
    """The family when ``schedule.departure_spacing_s`` > 0 (families.scenario_families)."""
    spacing = scenario.schedule.departure_spacing_s
    return departure_spacing(flightset, spacing) if spacing > 0 else None
