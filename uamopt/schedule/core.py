"""The scheduling core every solver reads: the objective, the pair view and "must operate".

Each piece is defined here once, as named arrays on the :class:`~uamopt.schedule.model.SchedulingProblem`
(``problem.objective``, ``problem.pairs``, ``problem.must_operate``); greedy, ga, soa, highs, cpsat,
rolling, timeindexed and bruteforce take them from there and derive nothing of their own.

Objective (Eqs. 20-22)
    W = ``per_delay`` · Σ_f c_f d_f − ``per_flight`` · Σ_f c_f, minimised.
    ``weighted``: per_delay = ω6 / G, per_flight = ω7 (Eq. 20 with T_d = Σ c d / G of Eq. 21 and
    S = Σ c of Eq. 22). ``lexicographic``: most operated flights first, then least total delay, as
    per_delay = 1 / (Σ_f U_f + 1), per_flight = 1 (the delay term lies in [0, 1), so S decides first).

Pair view (Eq. 24 as data)
    Conflicting pair k = (p_k, q_k) forbids δ = dep_q − dep_p in the open intervals (lo, hi) of
    rows ``ptr[k]:ptr[k+1]`` (the forbidden-interval view). With D the planned departures and U
    the delay bounds, δ = shift_k + z with shift_k = D_q − D_p and z = d_q − d_p ∈ [−U_p, U_q], so
    δ reaches [reach_lo_k, reach_hi_k] = [shift_k − U_p, shift_k + U_q]. The admissible-gap view:
    the closed gaps of reachable δ between the forbidden intervals, ``gap_lo``/``gap_hi`` in rows
    ``gap_ptr[k]:gap_ptr[k+1]``; a pair with no gap cannot operate both flights.

Must operate
    ``must_operate[f]`` (bool): flight f may not be cancelled (c_f = 1). The paper has no such
    flight (all False); the rolling-horizon solver fixes earlier windows' operated flights with it,
    and a user can pin flights the same way (``dataclasses.replace(problem, must_operate=mask)``).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property

import numpy as np


@dataclass(frozen=True, eq=False)
class Objective:
    """W = per_delay · Σ c d − per_flight · Σ c (module docstring), plus the per-flight
    earliness/tardiness terms of kind ``earliness_tardiness``; ``kind`` is weighted | lexicographic
    | earliness_tardiness.

    Examples
    --------
    The paper's weights (ω6, ω7) = (0.6, 0.4) and G = 20: 109 flights with 2401 s of delay (Table 3)

    >>> w = Objective.weighted(0.6, 0.4, 20)
    >>> round(w.value(109, 2401.0), 4)
    28.43
    """

    kind: str
    per_delay: float
    per_flight: float
    #: (per_delay, per_flight) as exact fractions when the weights are decimals (CP-SAT's integer
    #: objective); None for the lexicographic kind, whose scale CP-SAT sets itself
    exact: tuple[Fraction, Fraction] | None = None
    #: earliness_tardiness: per flight the target delay a_f and the costs per second early (e_f)
    #: and late (l_f): an operated flight costs e_f·(a_f − d_f)⁺ + l_f·(d_f − a_f)⁺ on top
    target_s: np.ndarray | None = None
    early_per_s: np.ndarray | None = None
    late_per_s: np.ndarray | None = None
    #: per flight a cost of operating it, in seconds of delay (charged per_delay each; a speed
    #: change, families/speed.py); None: none
    operate_cost_s: np.ndarray | None = None

    @classmethod
    def weighted(cls, w6: float, w7: float, aircraft: int) -> Objective:
        """Eq. 20: ω6 · T_d − ω7 · S with T_d = Σ c d / G (Eq. 21)."""
        f6, f7 = Fraction(repr(float(w6))), Fraction(repr(float(w7)))
        return cls("weighted", float(w6) / aircraft, float(w7), (f6 / aircraft, f7))

    @classmethod
    def lexicographic(cls, delay_upper_s: np.ndarray) -> Objective:
        """Most flights first, then least delay: per flight 1, per second 1 / (Σ U + 1)."""
        return cls("lexicographic", 1.0 / (float(np.sum(delay_upper_s)) + 1.0), 1.0)

    @classmethod
    def earliness_tardiness(cls, target_s, early_per_s, late_per_s, per_flight: float = 0.0) -> Objective:
        """Σ_f c_f (e_f (a_f − d_f)⁺ + l_f (d_f − a_f)⁺) − per_flight Σ c (the aircraft-landing
        problem's cost with a_f = T_f − E_f; Beasley et al. 2000)."""
        arrays = [np.asarray(a, dtype=float).copy() for a in (target_s, early_per_s, late_per_s)]
        for a in arrays:
            a.setflags(write=False)
        return cls("earliness_tardiness", 0.0, float(per_flight), (Fraction(0), Fraction(repr(float(per_flight)))),
                   *arrays)

    @property
    def per_flight_terms(self) -> bool:
        """Whether the delay cost differs per flight (earliness/tardiness): not a function of Σ d."""
        return self.target_s is not None

    @property
    def terms(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(a_f, e_f, l_f): the target delays and the costs per second early and late (earliness/tardiness only)."""
        a, e, late = self.target_s, self.early_per_s, self.late_per_s
        assert a is not None and e is not None and late is not None, "only earliness_tardiness has per-flight terms"
        return a, e, late

    @property
    def linear(self) -> bool:
        """W = per_delay · Σ c d − per_flight · Σ c exactly (no per-flight terms, no operating costs)."""
        return self.target_s is None and self.operate_cost_s is None

    def with_operate_cost(self, cost_s: np.ndarray) -> Objective:
        """The same objective plus per-flight operating costs in seconds of delay."""
        import dataclasses

        cost = np.asarray(cost_s, dtype=float).copy()
        cost.setflags(write=False)
        return dataclasses.replace(self, operate_cost_s=cost)

    def value(self, operated: int, total_delay_s: float) -> float:
        """W of a decision with ``operated`` flights and ``total_delay_s`` = Σ c d (linear kinds)."""
        assert self.linear, "per-flight terms or operating costs need the decisions: use cost()"
        return self.per_delay * total_delay_s - self.per_flight * operated

    def delay_cost(self, delay_s: np.ndarray, flights: np.ndarray | slice = slice(None)) -> np.ndarray:
        """The delay part of an operated flight's cost at ``delay_s`` (flights ``flights``)."""
        d = np.asarray(delay_s, dtype=float)
        out = self.per_delay * d
        if self.operate_cost_s is not None:
            out = out + self.per_delay * self.operate_cost_s[flights]
        if self.per_flight_terms:
            target, early, late = self.terms
            a = target[flights]
            out = out + early[flights] * np.maximum(0.0, a - d) + late[flights] * np.maximum(0.0, d - a)
        return out

    def cost(self, operated: np.ndarray, delay_s: np.ndarray) -> float:
        """W of one decision (n,) — any kind."""
        c = np.asarray(operated, dtype=bool)
        if self.linear:
            return self.value(int(c.sum()), float(np.sum(np.where(c, np.asarray(delay_s, dtype=float), 0.0))))
        return float(self.values(c[None, :], np.asarray(delay_s, dtype=float)[None, :])[0])

    def values(self, operated: np.ndarray, delay_s: np.ndarray) -> np.ndarray:
        """W of each row of (k, n) decisions (vectorised over a population)."""
        c = np.asarray(operated, dtype=bool)
        d = np.where(c, np.asarray(delay_s, dtype=float), 0.0)
        if self.linear:  # Σ d first, then the weight: the linear kinds' values to the last bit
            return self.per_delay * np.sum(d, axis=-1) - self.per_flight * c.sum(axis=-1)
        per = np.where(c, self.delay_cost(d), 0.0)
        return np.sum(per, axis=-1) - self.per_flight * c.sum(axis=-1)

    @property
    def preferred_delay_s(self) -> np.ndarray | float:
        """The delay an operated flight would choose alone: its target (earliness/tardiness), else 0."""
        return self.terms[0] if self.per_flight_terms else 0.0

    def scaled_delay(self, unit_s: float) -> Fraction:
        """The exact weight of one delay unit of ``unit_s`` seconds (weighted kind only)."""
        assert self.exact is not None, "the lexicographic objective has no decimal weights"
        return self.exact[0] * Fraction(repr(float(unit_s)))


@dataclass(frozen=True, eq=False)
class PairView:
    """The conflicting pairs as named arrays (module docstring); built by :func:`pair_view`."""

    p: np.ndarray  # (m,) int64, the earlier-indexed flight of each pair
    q: np.ndarray  # (m,) int64
    ptr: np.ndarray  # (m + 1,) rows of pair k: ptr[k]:ptr[k+1]
    lo: np.ndarray  # (K,) forbidden open intervals (lo, hi) of δ = dep_q − dep_p, s
    hi: np.ndarray
    shift: np.ndarray  # (m,) D_q − D_p, s
    reach_lo: np.ndarray  # (m,) shift − U_p: the least reachable δ, s
    reach_hi: np.ndarray  # (m,) shift + U_q

    def __len__(self) -> int:
        return len(self.p)

    @cached_property
    def row_pair(self) -> np.ndarray:
        """(K,) the pair of each forbidden-interval row."""
        return np.repeat(np.arange(len(self.p)), np.diff(self.ptr))

    @cached_property
    def gaps(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The admissible-gap view: (gap_ptr (m + 1,), gap_lo, gap_hi): the closed gaps of
        reachable δ between the forbidden intervals of each pair, in increasing order."""
        ptr_out, lo_out, hi_out = [0], [], []
        for k in range(len(self.p)):
            start, end = float(self.reach_lo[k]), float(self.reach_hi[k])
            rows = slice(self.ptr[k], self.ptr[k + 1])
            for lo, hi in zip(self.lo[rows].tolist(), self.hi[rows].tolist(), strict=True):
                if min(lo, end) >= start:
                    lo_out.append(start)
                    hi_out.append(min(lo, end))
                start = max(start, hi)
            if start <= end:
                lo_out.append(start)
                hi_out.append(end)
            ptr_out.append(len(lo_out))
        return np.asarray(ptr_out, dtype=np.int64), np.asarray(lo_out, dtype=float), np.asarray(hi_out, dtype=float)

    def gaps_of(self, k: int) -> list[tuple[float, float]]:
        """The admissible closed gaps [(g, h), ...] of pair k."""
        ptr, lo, hi = self.gaps
        return list(zip(lo[ptr[k]:ptr[k + 1]].tolist(), hi[ptr[k]:ptr[k + 1]].tolist(), strict=True))


def pair_view(p: np.ndarray, q: np.ndarray, ptr: np.ndarray, intervals: np.ndarray, planned_departure_s: np.ndarray,
              delay_upper_s: np.ndarray) -> PairView:
    """The pair view of a conflict table (``ConflictTable`` arrays) on a flight set's D and U."""
    p, q = np.asarray(p, dtype=np.int64), np.asarray(q, dtype=np.int64)
    shift = planned_departure_s[q] - planned_departure_s[p]
    intervals = np.asarray(intervals, dtype=float).reshape(-1, 2)
    return PairView(p=p, q=q, ptr=np.asarray(ptr, dtype=np.int64), lo=intervals[:, 0], hi=intervals[:, 1], shift=shift,
                    reach_lo=shift - delay_upper_s[p], reach_hi=shift + delay_upper_s[q])
