"""The paper's preliminary strategy (Sec. 5.2.1, Figs. 11-13) and the decoder the GA variants share.

Preliminary strategy
--------------------
Flights are taken in the conflict-resolution order f' = order of planned departure D (ties: flight index); flights
that must operate (``problem.must_operate``, none in the paper's model) come first. Flight f is checked against every
flight placed before it (Fig. 11): its departure starts at the earliest admissible time, max(D_f, arrival + ΔT of its
aircraft's previous *operated* flight) (Eqs. 27-28), and while it conflicts with an already placed operated flight —
dep_f lies in one of that pair's forbidden open intervals (``problem.pairs``, uamopt.schedule.core; the 3×3×3 zone of
Fig. 13) — it is delayed past the interval's end (Fig. 12). Delays are whole multiples of ΔT_a (``step_s``, Table B.3:
10 s), so a delay is rounded *up* to the step; with ``exact_gaps`` the flight goes exactly to the gap's end instead.
When the delay needed exceeds the flight's threshold, min(Δd_f, T_f − A_f) (Eqs. 26, 29), the flight is cancelled; a
cancelled outbound cancels its return (docs/readings.md: the aircraft never left). The result is feasible by
construction,
except that a must-operate flight that cannot be placed is cancelled too (status ``infeasible``).

Decoder (shared with :mod:`uamopt.solvers.genetic`)
---------------------------------------------------
:class:`Decoder` runs the same strategy for a whole population at once (numpy over individuals,
a Python loop over the n flights). Each individual is an integer chromosome (Fig. 14), one gene per
flight: gene k ≥ 0 asks for a delay of at least k·ΔT_a, gene −1 (:data:`CANCEL`) cancels the
flight. The all-zero chromosome decodes to the preliminary strategy's schedule.

Options (``[options]`` of a profile): ``step_s`` (ΔT_a, s, default 10.0) and ``exact_gaps``
(default false: the paper's ΔT_a steps). Usage::

    schedule = uamopt.solvers.solve(problem, SolverProfile("greedy", options={"step_s": 10.0}))
"""

from __future__ import annotations

import time
import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from uamopt.schedule.model import Schedule, SchedulingProblem, Termination, make_schedule

if TYPE_CHECKING:
    from uamopt.solvers import SolverProfile

CANCEL = -1  # gene value meaning "cancel this flight" (Fig. 14 extended with a cancel allele)
DEFAULT_STEP_S = 10.0  # ΔT_a, s (Table B.3)
EPS_S = 1e-7  # times closer than this are equal (well inside the verifier's 1e-6 s), s


@dataclass(frozen=True, eq=False)
class Decoder:
    """The conflict-resolution order and, per flight, the forbidden windows against earlier flights.

    For the flight at position i of ``order``, rows ``ptr[i]:ptr[i+1]`` say: its delay d must avoid
    the open interval (dep_e + ``lo``, dep_e + ``hi``) for each placed, operated ``partner`` e,
    with lo and hi already relative to its planned departure (intervals of δ = dep_q − dep_p
    turned into intervals of d).
    """

    order: np.ndarray  # flight indices in conflict-resolution order f'
    ptr: np.ndarray  # (n + 1,) rows of each position
    partner: np.ndarray  # (K,) earlier flight of each row
    lo: np.ndarray  # (K,) s, relative to the flight's planned departure
    hi: np.ndarray  # (K,) s
    t_ptr: np.ndarray  # (n + 1,) turnaround rows of each position (families/turnaround.py)
    t_from: np.ndarray  # (R,) the earlier-placed flight e of each row
    t_gap: np.ndarray  # (R,) dep_f ≥ dep_e + t_gap when both operate, s
    #: the ``cumulative`` shape (families/pads.py, more than one pad): per flight index its holds
    #: (resource, offset from departure, duration), and each resource's capacity
    holds: tuple = ()
    capacity: tuple = ()

    @classmethod
    def from_problem(cls, problem: SchedulingProblem, order: np.ndarray | None = None) -> Decoder:
        """The decoder's one view of the families: the ``pairs`` shape as forbidden windows against
        placed flights, ``turnaround`` as earliest departures after placed flights, ``precedence``,
        ``bounds`` and ``must_operate`` read in :meth:`decode`."""
        n = problem.n_flights
        if order is None:  # by planned departure plus the objective's preferred delay (0 but for earliness/tardiness)
            order = np.lexsort((np.arange(n), problem.planned_departure_s + problem.objective.preferred_delay_s,
                                ~problem.must_operate))
        order = np.asarray(order, dtype=np.int64)
        pos = np.empty(n, dtype=np.int64)
        pos[order] = np.arange(n)
        view = problem.pairs
        p, q = view.p[view.row_pair], view.q[view.row_pair]
        lo, hi = view.lo, view.hi
        dep0 = problem.planned_departure_s
        q_later = pos[q] > pos[p]
        # q placed after p: dep_q ∈ (dep_p + lo, dep_p + hi); p after q: dep_p ∈ (dep_q − hi, dep_q − lo)
        later = np.where(q_later, q, p)
        partner = np.where(q_later, p, q)
        rel_lo = np.where(q_later, lo, -hi) - dep0[later]
        rel_hi = np.where(q_later, hi, -lo) - dep0[later]
        rows = np.argsort(pos[later], kind="stable")
        counts = np.bincount(pos[later], minlength=n)
        t = problem.turnaround
        forward = pos[t.e] < pos[t.f]  # a row binds the later-placed flight (chains follow the order)
        t_rows = np.flatnonzero(forward)[np.argsort(pos[t.f[forward]], kind="stable")]
        t_counts = np.bincount(pos[t.f[t_rows]], minlength=n)
        holds: list[list[tuple[int, float, float]]] = [[] for _ in range(n)]
        capacity: list[int] = []
        for family in problem.of_shape("cumulative"):  # one-pad resources are pairs already (problem.pairs)
            rest = family.residual()
            base = len(capacity)
            capacity += [int(c) for c in rest.capacity]
            for f_, r, o_, l_ in zip(rest.flight.tolist(), rest.resource.tolist(), rest.offset_s.tolist(),
                                     rest.duration_s.tolist(), strict=True):
                holds[f_].append((base + r, o_, l_))
        return cls(order=order, ptr=np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
                   partner=partner[rows], lo=rel_lo[rows], hi=rel_hi[rows],
                   t_ptr=np.concatenate([[0], np.cumsum(t_counts)]).astype(np.int64), t_from=t.e[t_rows],
                   t_gap=t.gap_s(problem)[t_rows], holds=tuple(tuple(h) for h in holds) if capacity else (),
                   capacity=tuple(capacity))

    def decode(self, problem: SchedulingProblem, genes: np.ndarray, step_s: float = DEFAULT_STEP_S,
               exact_gaps: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Feasible schedules of a population of chromosomes (the preliminary strategy, Sec. 5.2.1).

        Parameters
        ----------
        genes : int array (P, n) or (n,)
            Per flight (in flight-index order) the wished delay in units of ``step_s``, or
            :data:`CANCEL`.
        step_s : float
            ΔT_a, s: delays are multiples of it (unless ``exact_gaps``).
        exact_gaps : bool
            Push a conflicting flight exactly to the end of the forbidden gap, not to the next step.

        Returns
        -------
        operated : bool array (P, n)
        delay_s : float array (P, n), s; 0 where cancelled. Each row passes ``violations``.
        """
        genes = np.atleast_2d(np.asarray(genes, dtype=np.int64))
        size, n = genes.shape
        dep0, upper = problem.planned_departure_s, problem.delay_upper_s
        must = problem.must_operate
        needs: dict[int, list] = {}  # precedence groups of each flight (one in the paper: the outbound)
        for family in problem.of_shape("precedence"):
            for f_, group in family.groups():
                needs.setdefault(f_, []).append(group)
        operated = np.zeros((size, n), dtype=bool)
        dep = np.zeros((size, n))
        delay = np.zeros((size, n))

        def snap(d: np.ndarray) -> np.ndarray:  # round a delay up to the ΔT_a grid
            return d if exact_gaps else np.ceil(d / step_s - EPS_S / step_s) * step_s

        # cumulative resources: the placed holds of each individual, (P, m) starts and ends (inf: none)
        placed_s = [np.zeros((size, 0)) for _ in self.capacity]
        placed_e = [np.zeros((size, 0)) for _ in self.capacity]

        def pad_push(f: int, d: np.ndarray, live: np.ndarray) -> np.ndarray:
            """The least delay ≥ d (per individual, -inf where none is needed) at which no hold of f
            would push a resource over its capacity at the instant t* of the first overflow:
            the earliest end among the holds active at t* (no start before it can fit)."""
            need = np.full(size, -np.inf)
            for r, o_, l_ in self.holds[f]:
                hs, he = placed_s[r], placed_e[r]
                if hs.shape[1] < self.capacity[r]:
                    continue
                s0 = dep0[f] + d + o_
                e0 = s0 + l_
                # the load is largest at the hold's start or at a placed start inside the hold
                t = np.concatenate([s0[:, None], np.where((hs > s0[:, None]) & (hs < e0[:, None] - EPS_S), hs, np.inf)],
                                   axis=1)  # (P, m + 1)
                on = (hs[:, None, :] < t[:, :, None] + EPS_S) & (t[:, :, None] < he[:, None, :] - EPS_S)  # (P, T, m)
                over = (on.sum(axis=2) >= self.capacity[r]) & np.isfinite(t)
                hit = over.any(axis=1) & live
                if not hit.any():
                    continue
                t_first = np.where(over, t, np.inf).min(axis=1)  # the earliest instant over capacity
                at = (hs[:, None, :] < t_first[:, None, None] + EPS_S) & (t_first[:, None, None] < he[:, None, :] - EPS_S)
                end = np.where(at[:, 0, :], he, np.inf).min(axis=1)
                need = np.where(hit, np.maximum(need, end - dep0[f] - o_), need)
            return need

        for i, f in enumerate(self.order):
            cap = upper[f] + EPS_S
            want = genes[:, f]
            on = (want != CANCEL) | must[f]
            for group in needs.get(int(f), ()):
                on &= operated[:, group].any(axis=1)  # a cancelled outbound cancels its return
            ta, tb = self.t_ptr[i], self.t_ptr[i + 1]
            ready = np.full(size, -np.inf)  # earliest departure after the placed operated flights of its aircraft (Eq. 27)
            if tb > ta:
                e = self.t_from[ta:tb]
                ready = np.where(operated[:, e], dep[:, e] + self.t_gap[ta:tb], -np.inf).max(axis=1)
            d = snap(np.maximum(np.maximum(want, 0) * step_s, ready - dep0[f]))
            a, b = self.ptr[i], self.ptr[i + 1]
            padded = bool(self.holds) and bool(self.holds[f])
            if b > a or padded:
                others = self.partner[a:b]
                live = operated[:, others]  # only operated partners constrain
                lo = dep[:, others] + self.lo[a:b]
                hi = dep[:, others] + self.hi[a:b]
                passes = b - a + 1 + (sum(m.shape[1] for m in placed_e) + 1 if padded else 0)
                for _ in range(passes):  # each pass leaves at least one interval (or one hold's end) behind for good
                    trying = on & (d <= cap)
                    inside = live & (lo + EPS_S < d[:, None]) & (d[:, None] < hi - EPS_S)
                    inside &= trying[:, None]
                    push = np.where(inside, hi, -np.inf).max(axis=1) if b > a else np.full(size, -np.inf)
                    if padded:
                        push = np.maximum(push, pad_push(int(f), d, trying))
                    hit = push > d
                    if not hit.any():
                        break
                    d = np.where(hit, snap(np.maximum(push, d)), d)
            on &= d <= cap
            operated[:, f] = on
            delay[:, f] = np.where(on, np.minimum(d, upper[f]), 0.0)
            dep[:, f] = dep0[f] + delay[:, f]
            if padded:
                for r, o_, l_ in self.holds[f]:
                    start_ = np.where(on, dep[:, f] + o_, np.inf)
                    placed_s[r] = np.column_stack([placed_s[r], start_])
                    placed_e[r] = np.column_stack([placed_e[r], np.where(on, start_ + l_, np.inf)])
        return operated, delay


#: the decoder's view (from_problem)
SHAPES = frozenset({"bounds", "must_operate", "precedence", "turnaround", "pairs", "cumulative"})
OBJECTIVES = frozenset({"weighted", "lexicographic", "earliness_tardiness"})

_DECODERS: weakref.WeakKeyDictionary[SchedulingProblem, Decoder] = weakref.WeakKeyDictionary()


def decoder_for(problem: SchedulingProblem) -> Decoder:
    """The problem's :class:`Decoder` in planned-departure order, built once per problem."""
    decoder = _DECODERS.get(problem)
    if decoder is None:
        decoder = _DECODERS[problem] = Decoder.from_problem(problem)
    return decoder


def greedy_decisions(problem: SchedulingProblem, step_s: float | None = None, exact_gaps: bool = False
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Operated flags and delays (s) of the preliminary strategy (Sec. 5.2.1); ``step_s``
    defaults to the problem's ΔT_a."""
    step_s = problem.time_step_s if step_s is None else step_s
    operated, delay = decoder_for(problem).decode(problem, base_genes(problem, step_s), step_s, exact_gaps)
    return operated[0], delay[0]


def base_genes(problem: SchedulingProblem, step_s: float) -> np.ndarray:
    """The preliminary strategy's chromosome: each flight wishes its preferred delay on the grid
    (all zeros but for the earliness/tardiness objective, whose flights wish their targets)."""
    pref = np.broadcast_to(np.asarray(problem.objective.preferred_delay_s, dtype=float), (problem.n_flights,))
    return np.floor(pref / step_s + EPS_S / step_s).astype(np.int64)


def solve(problem: SchedulingProblem, profile: SolverProfile) -> Schedule:
    """The preliminary strategy as a solver: termination ``stopped`` (status "feasible";
    ``no_solution`` when a must-operate flight cannot be placed: a heuristic proves nothing), no bound."""
    step_s, exact = profile.option("step_s", problem.time_step_s), profile.option("exact_gaps")
    start = time.perf_counter()
    operated, delay = greedy_decisions(problem, step_s, exact)
    # a must-operate flight not placed: no schedule, and no proof that none exists (a heuristic)
    termination: Termination = "no_solution" if np.any(problem.must_operate & ~operated) else "stopped"
    return make_schedule(problem, "greedy", termination, operated, delay, solve_seconds=time.perf_counter() - start,
                         seed=profile.seed, extras={"step_s": step_s, "exact_gaps": exact})
