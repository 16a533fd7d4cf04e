"""Shape ``pairs``: for each pair (p, q), δ = dep_q − dep_p avoids open intervals when both operate.

The paper's conflict rule (Eq. 24: the 3×3×3 zones of Fig. 13 turned into forbidden departure
gaps, uamopt.schedule.occupancy) has this shape, and so does any rule on the difference of two
departures: a runway separation (the aircraft-landing problem), a minimum spacing of departures
from one vertiport. Several pair families are merged into one pair view for the solvers
(:func:`merged`, read as ``problem.pairs``): per (p, q) the union of their forbidden intervals.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Self

import numpy as np


@dataclass(frozen=True, eq=False)
class PairIntervals:
    """Pair k = (p[k], q[k]), p < q, forbids δ in the open intervals (lo, hi) of rows ptr[k]:ptr[k+1]."""

    name: str
    p: np.ndarray  # (m,) int64
    q: np.ndarray  # (m,) int64
    ptr: np.ndarray  # (m + 1,) int64
    lo: np.ndarray  # (K,) s
    hi: np.ndarray  # (K,) s
    description: str = "pair conflicts (Eq. 24): dep_q − dep_p outside the forbidden open intervals"
    #: what summary.json records so that ``uamopt verify`` can check this family from the files
    #: (e.g. ``{"airland_file": path, "sha256": ...}``); None: derived from flights.json (the paper's conflicts)
    record_data: dict | None = None
    shape = "pairs"

    def record(self) -> dict:
        return {"name": self.name, "shape": self.shape, **(self.record_data or {})}

    @classmethod
    def of_table(cls, name: str, p, q, ptr, intervals, description: str | None = None,
                 record_data: dict | None = None) -> Self:
        iv = np.asarray(intervals, dtype=float).reshape(-1, 2)
        kw: dict[str, Any] = {"record_data": record_data} | ({} if description is None else {"description": description})
        return cls(name=name, p=np.asarray(p, dtype=np.int64), q=np.asarray(q, dtype=np.int64),
                   ptr=np.asarray(ptr, dtype=np.int64), lo=iv[:, 0].copy(), hi=iv[:, 1].copy(), **kw)

    @classmethod
    def of_rows(cls, name: str, rows: list[tuple[int, int, float, float]], description: str | None = None,
                record_data: dict | None = None) -> Self:
        """From rows (a, b, lo, hi): dep_b − dep_a ∉ (lo, hi), any order of a and b (flipped to a < b)."""
        fixed = sorted((a, b, lo, hi) if a < b else (b, a, -hi, -lo) for a, b, lo, hi in rows)
        return cls.of_table(name, *compress_rows(fixed), description=description, record_data=record_data)

    def __len__(self) -> int:
        return len(self.p)

    def violations(self, problem, operated, delay_s, tol_s) -> list[str]:
        c = np.asarray(operated, dtype=bool)
        dep = problem.planned_departure_s + np.where(c, delay_s, 0.0)
        row_pair = np.repeat(np.arange(len(self.p)), np.diff(self.ptr))
        p, q = self.p[row_pair], self.q[row_pair]
        delta = dep[q] - dep[p]
        bad = c[p] & c[q] & (self.lo + tol_s < delta) & (delta < self.hi - tol_s)
        ids = problem.flights.ids
        return [f"flights {ids[p[r]]} and {ids[q[r]]}: departure gap {delta[r]:.3f} s in forbidden "
                f"({self.lo[r]:.3f}, {self.hi[r]:.3f}) ({self.name})" for r in np.flatnonzero(bad)]


def compress_rows(rows: list[tuple[int, int, float, float]]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Sorted rows (p, q, lo, hi) → (p, q, ptr, intervals) with each pair's intervals merged where
    they overlap (open intervals that only touch stay apart: the shared end is allowed)."""
    p_out, q_out, ptr, iv = [], [], [0], []
    k = 0
    while k < len(rows):
        a, b = rows[k][:2]
        spans = []
        while k < len(rows) and rows[k][:2] == (a, b):
            lo, hi = rows[k][2:]
            if lo < hi:
                spans.append([lo, hi])
            k += 1
        spans.sort()
        merged: list[list[float]] = []
        for lo, hi in spans:
            if merged and lo < merged[-1][1]:
                merged[-1][1] = max(merged[-1][1], hi)
            else:
                merged.append([lo, hi])
        if merged:
            p_out.append(a)
            q_out.append(b)
            iv += merged
            ptr.append(len(iv))
    return (np.asarray(p_out, dtype=np.int64), np.asarray(q_out, dtype=np.int64), np.asarray(ptr, dtype=np.int64),
            np.asarray(iv, dtype=float).reshape(-1, 2))


def merged(families) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(p, q, ptr, intervals) of the union of several pair families (one family: its arrays as they are)."""
    families = list(families)
    if len(families) == 1:
        f = families[0]
        return f.p, f.q, f.ptr, np.stack([f.lo, f.hi], axis=1)
    rows = []
    for f in families:
        row_pair = np.repeat(np.arange(len(f.p)), np.diff(f.ptr))
        rows += list(zip(f.p[row_pair].tolist(), f.q[row_pair].tolist(), f.lo.tolist(), f.hi.tolist(), strict=True))
    return compress_rows(sorted(rows))
