"""Shapes ``turnaround`` and ``precedence``: how one aircraft's flights tie together (Eqs. 27-28).

Turnaround, the one place it is derived: an operated flight departs at least ΔT after the arrival
of the previous *operated* flight of its aircraft. Written for every ordered pair e before f of one
aircraft (c_e = c_f = 1 ⇒ dep_f ≥ dep_e + T_e + ΔT_e), i.e. on delays

    d_f − d_e ≥ need_ef = D_e + T_e + ΔT_e − D_f,

the pairs with an operated flight in between are implied, so the all-pairs form is exact for any
set of cancellations. Rows whose need can never bind (need ≤ −U_e: d_f − d_e ≥ −U_e always holds)
are kept; encoders may drop them.

Precedence: a return needs its outbound operated (the aircraft never left; docs/readings.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class Turnaround:
    """Rows r: d_f[r] − d_e[r] ≥ need_s[r] when flights e[r] and f[r] both operate."""

    e: np.ndarray  # (R,) int64, the earlier flight of the aircraft
    f: np.ndarray  # (R,) int64, a later flight of the same aircraft
    need_s: np.ndarray  # (R,) s
    name: str = "turnaround"
    description: str = "turnaround (Eqs. 27-28): a flight departs ΔT after its aircraft's previous operated arrival"
    shape = "turnaround"

    @classmethod
    def of(cls, flightset) -> Turnaround:
        dep, time, gap = flightset.planned_departure_s, flightset.flight_time_s, flightset.turnaround_after_s
        e_rows, f_rows = [], []
        for chain in flightset.chains:
            for i in range(len(chain) - 1):
                e_rows.append(np.full(len(chain) - 1 - i, chain[i]))
                f_rows.append(chain[i + 1:])
        e = np.concatenate(e_rows).astype(np.int64) if e_rows else np.zeros(0, np.int64)
        f = np.concatenate(f_rows).astype(np.int64) if f_rows else np.zeros(0, np.int64)
        return cls(e=e, f=f, need_s=dep[e] + time[e] + gap[e] - dep[f])

    def __len__(self) -> int:
        return len(self.e)

    def gap_s(self, problem) -> np.ndarray:
        """(R,) the least departure difference dep_f − dep_e of each row (= T_e + ΔT_e)."""
        return self.need_s + problem.planned_departure_s[self.f] - problem.planned_departure_s[self.e]

    def violations(self, problem, operated, delay_s, tol_s) -> list[str]:
        c = np.asarray(operated, dtype=bool)
        d = np.where(c, delay_s, 0.0)
        bad = c[self.e] & c[self.f] & (d[self.f] - d[self.e] < self.need_s - tol_s)
        ids, dep = problem.flights.ids, problem.planned_departure_s + d
        return [f"flight {ids[self.f[r]]}: departs {dep[self.f[r]]:.3f} s, before {ids[self.e[r]]}'s arrival + turnaround "
                f"{dep[self.e[r]] + self.gap_s(problem)[r]:.3f} s" for r in np.flatnonzero(bad)]


@dataclass(frozen=True, eq=False)
class Precedence:
    """Row r: flight ``flight[r]`` may operate only if one of ``idx[ptr[r]:ptr[r+1]]`` does (the
    paper: a return needs its outbound, groups of one; with speed options, any copy of it)."""

    flight: np.ndarray  # (m,) int64
    ptr: np.ndarray  # (m + 1,) int64
    idx: np.ndarray  # (K,) int64
    name: str = "precedence"
    description: str = "precedence: a return operates only if its outbound does"
    shape = "precedence"

    @classmethod
    def of(cls, flightset) -> Precedence:
        return cls.of_requires(flightset.requires)

    @classmethod
    def of_requires(cls, requires: np.ndarray, **kw) -> Precedence:
        """Groups of one from an (n,) array of required flights (−1: none)."""
        flight = np.flatnonzero(np.asarray(requires) >= 0).astype(np.int64)
        return cls(flight=flight, ptr=np.arange(len(flight) + 1, dtype=np.int64),
                   idx=np.asarray(requires, dtype=np.int64)[flight], **kw)

    def groups(self):
        """(f, required group) per row."""
        return [(int(f), self.idx[self.ptr[r]:self.ptr[r + 1]]) for r, f in enumerate(self.flight.tolist())]

    def single(self, n: int) -> np.ndarray | None:
        """(n,) the one flight each flight requires (−1: none) when every group has one member, else None."""
        if np.any(np.diff(self.ptr) != 1):
            return None
        out = np.full(n, -1, dtype=np.int64)
        out[self.flight] = self.idx
        return out

    def violations(self, problem, operated, delay_s, tol_s) -> list[str]:
        c = np.asarray(operated, dtype=bool)
        ids = problem.flights.ids
        return [f"flight {ids[f]}: operated without {' or '.join(ids[g] for g in group)} ({self.name})"
                if len(group) > 1 else f"flight {ids[f]}: return operated without its outbound {ids[group[0]]}"
                for f, group in self.groups() if c[f] and not c[group].any()]
