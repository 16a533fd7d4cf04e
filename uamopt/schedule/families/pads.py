"""Family ``pads`` (shape ``cumulative``): at most n aircraft on a vertiport's pads (FATO) at once.

The vertiport variant (docs/variants.md). An operated flight f holds one pad of its origin during
its vertical take-off, [d_f, d_f + t_up), and one pad of its destination from the start of its
vertical landing to the end of its turnaround, [a_f − t_down, a_f + ΔT_f) (T_D after an outbound,
T_R after a return; Eq. 28). After the turnaround the aircraft leaves the pad for a stand, so a
later departure takes a pad again for its take-off only (the reading of docs/variants.md).
Intervals are half-open: a take-off may start the instant a turnaround ends. Without vertical
phases t_up = t_down = 0 and only the landing's turnaround holds a pad.

Every event is an offset and a duration from its flight's departure, so:

- a vertiport with **one** pad is a disjunctive resource: two events there must not overlap,
  δ = d_b − d_a ∉ (o_a − o_b − l_b, o_a + l_a − o_b), the ``pairs`` shape
  (:meth:`Pads.disjunctive`, merged into ``problem.pairs``), which every solver encodes;
- a vertiport with more pads is a cumulative resource (:meth:`Pads.residual`), encoded by the
  solvers whose module lists the shape ``cumulative`` (cpsat's AddCumulative, the brute force);
  the others refuse it in one line.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from uamopt.schedule.families.pairs import PairIntervals


@dataclass(frozen=True, eq=False)
class Pads:
    """Event k: flight ``flight[k]`` holds a pad of vertiport ``resources[resource[k]]`` during
    [d + offset_s[k], d + offset_s[k] + duration_s[k]); at most ``capacity[r]`` at once."""

    resources: tuple[str, ...]
    capacity: np.ndarray  # (R,) int
    flight: np.ndarray  # (E,) int64
    resource: np.ndarray  # (E,) int64
    offset_s: np.ndarray  # (E,) s from departure
    duration_s: np.ndarray  # (E,) s, > 0
    landing: np.ndarray  # (E,) bool: a landing with its turnaround (else a take-off)
    #: vertiports of the network without a pad limit (recorded as null: the verifier skips them)
    unlimited: tuple[str, ...] = ()
    name: str = "pads"
    description: str = "vertiport pads: at most n aircraft taking off, landing or turning around on a vertiport's pads"
    shape = "cumulative"

    @classmethod
    def of(cls, flightset, pads: dict[str, int | None]) -> Pads:
        """Pads ``{vertiport: capacity}``; a capacity None is unlimited (no event, recorded as null)."""
        unlimited = tuple(sorted(n for n, c in pads.items() if c is None))
        pads = {n: c for n, c in pads.items() if c is not None}
        names = tuple(sorted(pads))
        where = {n: i for i, n in enumerate(names)}
        rows = []
        for i, f in enumerate(flightset.flights):
            up, down, time = f.takeoff_s, f.landing_s, f.flight_time_s
            if f.origin in where and up > 0:
                rows.append((i, where[f.origin], 0.0, up, False))
            hold = down + float(flightset.turnaround_after_s[i])
            if f.destination in where and hold > 0:
                rows.append((i, where[f.destination], time - down, hold, True))
        cols = list(zip(*rows, strict=True)) if rows else [(), (), (), (), ()]
        return cls(resources=names, capacity=np.array([pads[n] for n in names], dtype=np.int64),
                   flight=np.array(cols[0], dtype=np.int64), resource=np.array(cols[1], dtype=np.int64),
                   offset_s=np.array(cols[2], dtype=float), duration_s=np.array(cols[3], dtype=float),
                   landing=np.array(cols[4], dtype=bool), unlimited=unlimited)

    def record(self) -> dict:
        """Every vertiport of the network: its capacity, null where unlimited."""
        pads: dict[str, int | None] = {n: int(c) for n, c in zip(self.resources, self.capacity, strict=True)}
        pads |= {n: None for n in self.unlimited}
        return {"name": self.name, "shape": self.shape, "pads": dict(sorted(pads.items()))}

    def _events_at(self, keep: np.ndarray) -> Pads:
        return replace(self, flight=self.flight[keep], resource=self.resource[keep], offset_s=self.offset_s[keep],
                       duration_s=self.duration_s[keep], landing=self.landing[keep])

    def meetings(self, events: np.ndarray, planned_s=None, upper_s=None) -> tuple[np.ndarray, np.ndarray]:
        """Pairs (a, b) of ``events`` (indices, a before b in window order) at one resource that can
        overlap: event k can only lie in [P + o_k, P + U + o_k + l_k) of its flight (P the planned
        departure, U the largest delay); two events whose windows do not overlap never meet.
        Without ``planned_s`` every pair at one resource."""
        blocks = []
        events = np.asarray(events, dtype=np.int64)
        for r in np.unique(self.resource[events]).tolist():
            ev = events[self.resource[events] == r]
            if planned_s is None:
                lo_w, hi_w = np.zeros(len(ev)), np.full(len(ev), np.inf)
            else:
                lo_w = np.asarray(planned_s, dtype=float)[self.flight[ev]] + self.offset_s[ev]
                hi_w = lo_w + np.asarray(upper_s, dtype=float)[self.flight[ev]] + self.duration_s[ev]
            order = np.argsort(lo_w, kind="stable")
            ev, lo_w, hi_w = ev[order], lo_w[order], hi_w[order]
            stop = np.searchsorted(lo_w, hi_w, side="left")  # partners of x: later windows opening before x's closes
            count = np.maximum(stop - np.arange(len(ev)) - 1, 0)
            a = np.repeat(np.arange(len(ev)), count)
            first = np.repeat(np.cumsum(count) - count, count)
            b = a + 1 + (np.arange(len(a)) - first)
            blocks.append((ev[a], ev[b]))
        if not blocks:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        return np.concatenate([x for x, _ in blocks]), np.concatenate([y for _, y in blocks])

    def disjunctive(self, planned_s=None, upper_s=None) -> PairIntervals:
        """The events at one-pad vertiports as pair intervals: no two may overlap. With the planned
        departures and largest delays, only the pairs that can meet (:meth:`meetings`; a pruning,
        not a relaxation)."""
        a, b = self.meetings(np.flatnonzero(self.capacity[self.resource] == 1), planned_s, upper_s)
        keep = self.flight[a] != self.flight[b]
        a, b = a[keep], b[keep]
        oa, la, ob, lb = self.offset_s[a], self.duration_s[a], self.offset_s[b], self.duration_s[b]
        rows = list(zip(self.flight[a].tolist(), self.flight[b].tolist(), (oa - ob - lb).tolist(), (oa + la - ob).tolist(),
                        strict=True))
        return PairIntervals.of_rows(self.name, rows, description="vertiport pads (one pad: no two holds overlap)")

    def restricted(self, pos: np.ndarray) -> Pads:
        """The family on a subset of the flights: ``pos[f]`` is flight f's index there, −1 where
        it is left out (a rolling-horizon window: offsets are from each flight's departure, so they
        carry over to a flight fixed at its decided departure)."""
        keep = np.asarray(pos)[self.flight] >= 0
        out = self._events_at(keep)
        return replace(out, flight=np.asarray(pos)[out.flight].astype(np.int64))

    def residual(self) -> Pads:
        """The events at vertiports with more than one pad (the cumulative part)."""
        return self._events_at(self.capacity[self.resource] > 1)

    def violations(self, problem, operated, delay_s, tol_s) -> list[str]:
        c = np.asarray(operated, dtype=bool)
        dep = problem.planned_departure_s + np.where(c, delay_s, 0.0)
        out = []
        ids = problem.flights.ids
        for r, name in enumerate(self.resources):
            ev = np.flatnonzero((self.resource == r) & c[self.flight])
            start = dep[self.flight[ev]] + self.offset_s[ev]
            end = start + self.duration_s[ev]
            for t in start.tolist():  # the load is largest at some start
                on = ev[(start <= t + tol_s) & (end > t + tol_s)]
                if len(on) > self.capacity[r]:
                    who = ", ".join(ids[int(self.flight[j])] for j in on)
                    out.append(f"vertiport {name}: {len(on)} aircraft on {int(self.capacity[r])} pad(s) at "
                               f"{t:.3f} s ({who}) ({self.name})")
                    break
        return out


def from_scenario(flightset, scenario) -> Pads | None:
    """The family when any vertiport has a pad limit (``network.pads`` or a vertiport's ``pads``)."""
    pads = scenario.network.pads_of()
    return None if pads is None else Pads.of(flightset, pads)
