"""Shape ``bounds``: 0 ≤ d_f ≤ upper_s[f] for an operated flight.

The paper's delay bounds are two rules: the delay threshold Δd_f (Eq. 29) and the end of service
(Eq. 26: an operated flight arrives by T_f, so d_f ≤ T_f − A_f). A time window [E_f, L_f] on the
departure (the aircraft-landing problem's landing window) is the same shape with D_f = E_f and
upper L_f − E_f (``uamopt.schedule.airland``). The solvers read the tightest bound over every bounds family,
``problem.delay_upper_s``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class DelayBounds:
    """upper_s = min(threshold_s, service_s), each ≥ 0 (Eqs. 26, 29)."""

    threshold_s: np.ndarray  # (n,) Δd_f, s (Eq. 29)
    service_s: np.ndarray  # (n,) T_f − A_f, s (Eq. 26)
    name = "delay_bounds"
    shape = "bounds"
    description = "delay bounds: delay threshold Δd (Eq. 29) and arrival by the end of service (Eq. 26)"

    @classmethod
    def of(cls, flightset) -> DelayBounds:
        return cls(threshold_s=flightset.max_delay_s, service_s=flightset.service_end_s - flightset.planned_arrival_s)

    @property
    def upper_s(self) -> np.ndarray:
        return np.maximum(0.0, np.minimum(self.threshold_s, self.service_s))

    def upper_of(self, problem) -> np.ndarray:
        """(n,) this family's delay bound of each flight, s (every bounds family has it)."""
        return self.upper_s

    def violations(self, problem, operated, delay_s, tol_s) -> list[str]:
        c = np.asarray(operated, dtype=bool)
        d = np.where(c, delay_s, 0.0)
        upper, ids = self.upper_s, problem.flights.ids
        out = []
        for i in np.flatnonzero(c & ((d < -tol_s) | (d > upper + tol_s))):
            why = "past the end of service" if d[i] > self.service_s[i] + tol_s else "beyond the delay threshold"
            out.append(f"flight {ids[i]}: delay {d[i]:g} s outside [0, {upper[i]:g}] s ({why})")
        return out

