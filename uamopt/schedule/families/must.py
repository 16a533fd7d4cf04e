"""Shape ``must_operate``: c_f = 1 where ``mask[f]``.

The paper has no such flight (all False). The rolling-horizon solver fixes earlier windows'
operated flights with it, the aircraft-landing problem operates every aircraft, and a user can pin
flights the same way (``dataclasses.replace(problem, must_operate=mask)``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class MustOperate:
    mask: np.ndarray  # (n,) bool
    name = "must_operate"
    shape = "must_operate"
    description = "must operate: pinned flights may not be cancelled"

    def violations(self, problem, operated, delay_s, tol_s) -> list[str]:
        ids = problem.flights.ids
        return [f"flight {ids[i]}: must operate but is cancelled"
                for i in np.flatnonzero(self.mask & ~np.asarray(operated, bool))]
