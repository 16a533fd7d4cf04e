"""Exact cell occupancy of tracks and the forbidden departure gaps of flight pairs (Sec. 4.3, 5.2.1).

Occupancy
---------
A flight flies its piecewise-linear track at constant speed v_g from its departure, with no
holding (docs/readings.md). Its position is linear in time between consecutive *breakpoints*: the
waypoint times and the instants where the track crosses any x, y or z grid plane. Between two
breakpoints it stays in one cell, found from the position at the middle of the interval. The
breakpoints are computed for all segments and planes at once (numpy, no loop over cells).

Conventions
~~~~~~~~~~~
- Cells are indexed by floor(x/Δx), floor(y/Δy), floor(z/Δz) with no clipping, so a track that
  runs *inside* a grid plane for a positive time (the paper case flies at z = 120 m = 4Δz) is in
  the cell above that plane, as ``AirspaceGrid.indices_of`` puts points on a face in the upper
  cell. A single instant on a plane has no duration and does not matter (see conflicts below).
- Breakpoints closer than ``MERGE_TOL_S`` are merged, so a track through an edge or a corner
  of the grid (exactly, or up to float round-off) passes from cell to cell without a spurious
  visit of zero length to a neighbour. Visits shorter than that are physically meaningless.
- Times are relative to departure; the visits tile [0, flight time] exactly.

Conflicts and forbidden gaps
----------------------------
Two operated flights p, q of different aircraft conflict when they occupy cells whose indices
differ by at most r in every axis (r = 1: the 3×3×3 zone of Sec. 5.2.1; r = 0: Eq. 24's same
cell) during overlapping times of *positive length*. Cell c is occupied by p during
[a_p, b_p] + dep_p and a cell within r of c by q during [a_q, b_q] + dep_q; these overlap for a
positive time iff  a_p + dep_p < b_q + dep_q  and  a_q + dep_q < b_p + dep_p, that is iff

    δ = dep_q − dep_p ∈ (a_p − b_q,  b_p − a_q)        (an open interval).

So each pair's constraint is: δ avoids the union of these open intervals over all near pairs of
visits; touching (q entering as p leaves) is not a conflict. This reads Eq. 24's strict
T_in > T_out as "no overlap of positive length", the only reading that does not depend on how
an instant on a cell face is assigned; the verifier uses the same rule with a tolerance of
``TIME_TOL_S``. Intervals whose gap is below ``TIME_TOL_S`` are merged (conservative).

Speed-up: flights with the same track and speed share one occupancy; for each ordered pair of
such *tracks* the intervals are computed once with a sort-merge join on dilated cell codes; then
the flight pairs whose departure windows can meet are matched to their track pair's intervals.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import overload

import numpy as np

from uamopt.schedule.flights import TIME_TOL_S, FlightSet, waypoint_times_s

MERGE_TOL_S = 1e-9  # breakpoints closer than this are one instant, s
OFFSET_LIMIT = 1e8  # largest float offset used to separate groups in one vectorised pass, s
ROWS_PER_PASS = 500_000  # visit rows joined at once by the per-flight join (bounds its memory)


@dataclass(frozen=True, eq=False)
class Occupancy:
    """Cell visits of one track, in time order: ``cells`` (m, 3) int64 (i, j, k) and the entry
    and exit times ``t_in``, ``t_out`` (m,) relative to departure, s."""

    cells: np.ndarray
    t_in: np.ndarray
    t_out: np.ndarray

    def __len__(self) -> int:
        return len(self.t_in)


@dataclass(frozen=True, eq=False)
class PairConflict:
    """Flights ``p`` < ``q`` (indices into the flight set) conflict iff dep_q − dep_p lies in one
    of ``intervals`` (m, 2): sorted, disjoint, open intervals (lo, hi), s. Only intervals that
    meet the pair's feasible range of δ are kept."""

    p: int
    q: int
    intervals: np.ndarray


def track_occupancy(waypoints: np.ndarray, speed_mps: float, cell: tuple[float, float, float],
                    vertical_rate_mps: float | None = None) -> Occupancy:
    """Entry and exit time of every cell a track passes through, flown at ``speed_mps`` from t = 0
    (with ``vertical_rate_mps``: its first and last segments at that rate, ``waypoint_times_s``).

    Parameters
    ----------
    waypoints : ndarray (n, 3)
        Track, m. Repeated consecutive points are ignored.
    speed_mps : float
        v_g, m/s.
    cell : (Δx, Δy, Δz)
        Cell size, m.

    Examples
    --------
    >>> occ = track_occupancy(np.array([[5.0, 5, 5], [25.0, 5, 5]]), 10.0, (10.0, 10.0, 10.0))
    >>> occ.cells.tolist(), occ.t_in.tolist(), occ.t_out.tolist()
    ([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [0.0, 0.5, 1.5], [0.5, 1.5, 2.0])
    """
    pts = np.asarray(waypoints, dtype=float)
    keep = np.ones(len(pts), dtype=bool)
    keep[1:] = np.any(np.diff(pts, axis=0) != 0, axis=1)
    t_all = waypoint_times_s(pts, speed_mps, vertical_rate_mps)  # Eq. 31
    pts, t_vertex = pts[keep], t_all[keep]
    size = np.asarray(cell, dtype=float)
    p0, p1 = pts[:-1], pts[1:]
    t0, dt = t_vertex[:-1], np.diff(t_vertex)
    times = [t_vertex]
    for axis in range(3):
        # planes m·Δ strictly between the two ends of each segment
        lo_c = np.minimum(p0[:, axis], p1[:, axis]) / size[axis]
        hi_c = np.maximum(p0[:, axis], p1[:, axis]) / size[axis]
        first = np.floor(lo_c).astype(np.int64) + 1
        count = np.maximum(np.ceil(hi_c).astype(np.int64) - first, 0)
        if count.sum() == 0:
            continue
        seg = np.repeat(np.arange(len(count)), count)
        m = first[seg] + np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        frac = (m * size[axis] - p0[seg, axis]) / (p1[seg, axis] - p0[seg, axis])
        times.append(t0[seg] + frac * dt[seg])
    t = np.sort(np.concatenate(times))
    t = t[np.concatenate([[True], np.diff(t) > MERGE_TOL_S])]
    t = t if len(t) > 1 else np.array([0.0, t_vertex[-1]])  # a track shorter than MERGE_TOL_S
    t[-1] = t_vertex[-1]
    mid = 0.5 * (t[:-1] + t[1:])
    pos = np.stack([np.interp(mid, t_vertex, pts[:, a]) for a in range(3)], axis=1)
    cells = np.floor(pos / size).astype(np.int64)
    new = np.concatenate([[True], np.any(cells[1:] != cells[:-1], axis=1)])
    start = np.flatnonzero(new)
    t_out = np.append(t[start[1:]], t[-1])
    return Occupancy(cells=cells[start], t_in=t[start], t_out=t_out)


def flight_occupancies(flightset: FlightSet) -> tuple[list[Occupancy], np.ndarray]:
    """Occupancy of every flight, shared by flights with the same track and speed.

    Returns ``(occupancies, key)``: one :class:`Occupancy` per distinct (track, speed), and for
    each flight the index of its occupancy.
    """
    index: dict[tuple[bytes, float, float | None], int] = {}  # (waypoints, speed, vertical rate)
    occupancies: list[Occupancy] = []
    key = np.empty(len(flightset), dtype=np.int64)
    for i, f in enumerate(flightset.flights):
        k = (np.ascontiguousarray(f.waypoints, dtype=float).tobytes(), float(f.speed_mps), f.vertical_rate_mps)
        if k not in index:
            index[k] = len(occupancies)
            occupancies.append(track_occupancy(f.waypoints, f.speed_mps, flightset.cell, f.vertical_rate_mps))
        key[i] = index[k]
    return occupancies, key


def _chunks(group_start: np.ndarray, span: float):
    """Ranges [g0, g1) of consecutive groups whose float offsets (g − g0)·span stay ≤ 1e8, so the
    offset values keep a precision of ~1.5e-8 s, far below ``TIME_TOL_S``."""
    per_chunk = max(1, int(OFFSET_LIMIT // span))
    n = len(group_start) - 1
    return [(g0, min(g0 + per_chunk, n)) for g0 in range(0, n, per_chunk)]


def _group_merge(group: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Union of open intervals per group: returns (group, lo, hi) sorted, disjoint per group.

    Intervals closer than ``TIME_TOL_S`` are merged (conservative: a gap that thin is forbidden).
    """
    order = np.lexsort((lo, group))
    group, lo, hi = group[order], lo[order], hi[order]
    rank = np.concatenate([[0], np.cumsum(group[1:] != group[:-1])])
    bounds = np.searchsorted(rank, np.arange(rank[-1] + 2))  # rows of group rank g: bounds[g]:bounds[g+1]
    base = float(np.min(lo))
    span = float(np.max(hi) - base) + 1.0
    start = np.ones(len(lo), dtype=bool)
    for g0, g1 in _chunks(bounds, span):
        # running max of hi within each group: each group offset above the previous one
        rows = slice(bounds[g0], bounds[g1])
        off = (rank[rows] - g0) * span
        run = np.maximum.accumulate((hi[rows] - base) + off) - off + base
        start[rows][1:] = (rank[rows][1:] != rank[rows][:-1]) | (lo[rows][1:] >= run[:-1] + TIME_TOL_S)
    idx = np.flatnonzero(start)
    return group[idx], lo[idx], np.maximum.reduceat(hi, idx)


def _cell_codes(cells: np.ndarray, radius: int) -> tuple[np.ndarray, np.ndarray]:
    """Integer codes of cells with room for ±r offsets, and the (2r+1)³ neighbour offsets."""
    shift = cells.min(axis=0) - radius
    dims = cells.max(axis=0) - shift + radius + 1
    c = cells - shift
    r = np.arange(-radius, radius + 1)
    offsets = ((r[:, None, None] * dims[1] + r[None, :, None]) * dims[2] + r[None, None, :]).ravel()
    return (c[:, 0] * dims[1] + c[:, 1]) * dims[2] + c[:, 2], offsets


@overload
def _near_pairs(code: np.ndarray, offsets: np.ndarray, max_pairs: None = None) -> tuple[np.ndarray, np.ndarray]: ...
@overload
def _near_pairs(code: np.ndarray, offsets: np.ndarray, max_pairs: int | None) -> tuple[np.ndarray, np.ndarray] | None: ...
def _near_pairs(code: np.ndarray, offsets: np.ndarray, max_pairs: int | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """All (i, j) with code[j] + o == code[i] for an offset o: a sort-merge join of the rows with
    their dilated copies, one vectorised pass per offset. ``None`` if there would be more than
    ``max_pairs`` (counted before anything is built)."""
    order = np.argsort(code, kind="stable")
    sorted_code = code[order]

    def matches(off):  # the needles sorted_code + off are sorted: a fast, cache-friendly search
        first = np.searchsorted(sorted_code, sorted_code + off, side="left")
        return first, np.searchsorted(sorted_code, sorted_code + off, side="right") - first

    if max_pairs is not None and sum(int(matches(off)[1].sum()) for off in offsets) > max_pairs:
        return None  # counted without building anything
    base, probe = [], []
    for off in offsets:
        first, count = matches(off)
        hit = np.flatnonzero(count)
        reps = count[hit]
        probe.append(np.repeat(order[hit], reps))
        base.append(order[np.repeat(first[hit] - (np.cumsum(reps) - reps), reps) + np.arange(reps.sum())])
    return np.concatenate(base), np.concatenate(probe)


def track_pair_gaps(
    occupancies: list[Occupancy], radius: int, max_pairs: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """Forbidden δ = dep_q − dep_p for every ordered pair of tracks (A for p, B for q).

    Returns ``(pair_code, ptr, lo, hi)``: ``pair_code`` = A·K + B (sorted, only pairs with a
    conflict), the intervals of pair ``pair_code[g]`` are ``lo[ptr[g]:ptr[g+1]]``, ``hi[...]``.
    Visits are joined on cell codes: each visit is dilated to its (2r+1)³ neighbours and matched
    against all visits by binary search on the sorted codes. ``None`` when the join would exceed
    ``max_pairs`` pairs of visits (many distinct tracks through the same cells).
    """
    n_keys = len(occupancies)
    t_in = np.concatenate([o.t_in for o in occupancies])
    t_out = np.concatenate([o.t_out for o in occupancies])
    owner = np.repeat(np.arange(n_keys), [len(o) for o in occupancies])
    code, offsets = _cell_codes(np.concatenate([o.cells for o in occupancies]), radius)
    joined = _near_pairs(code, offsets, max_pairs)
    if joined is None:
        return None
    base, dil = joined  # visit of p (track A); visit of q (track B) within r of p's cell
    if len(base) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(1, dtype=np.int64), np.zeros(0), np.zeros(0)
    g, lo, hi = _group_merge(owner[base] * n_keys + owner[dil], t_in[base] - t_out[dil], t_out[base] - t_in[dil])
    pair_code, starts = np.unique(g, return_index=True)
    return pair_code, np.append(starts, len(g)).astype(np.int64), lo, hi


def flight_pair_gaps(
    flightset: FlightSet, occupancies: list[Occupancy], key: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Forbidden δ per flight pair p < q directly, for flight sets with many distinct tracks.

    Each visit of flight f can happen during [D_f + t_in, D_f + Δd_f + t_out]; visits are hashed
    by (cell, time bucket) and only visits in neighbouring cells whose windows overlap are joined
    (a pair sharing several buckets is kept in its first common bucket only).
    Returns ``(pair_code = p·n + q, ptr, lo, hi)`` like :func:`track_pair_gaps`.
    """
    n = len(flightset)
    size = np.array([len(o) for o in occupancies])
    vstart = np.concatenate([[0], np.cumsum(size)])
    t_in = np.concatenate([o.t_in for o in occupancies])
    t_out = np.concatenate([o.t_out for o in occupancies])
    code, offsets = _cell_codes(np.concatenate([o.cells for o in occupancies]), flightset.conflict_radius)
    count = size[key]  # visits per flight
    flight = np.repeat(np.arange(n), count)
    visit = np.repeat(vstart[key] - np.cumsum(count) + count, count) + np.arange(count.sum())
    dep, upper = flightset.planned_departure_s, flightset.delay_upper_s
    w_lo = dep[flight] + t_in[visit] - TIME_TOL_S
    w_hi = dep[flight] + upper[flight] + t_out[visit] + TIME_TOL_S
    width = max(float(np.median(w_hi - w_lo)), 1.0)
    b0 = np.floor((w_lo - w_lo.min()) / width).astype(np.int64)
    b1 = np.floor((w_hi - w_lo.min()) / width).astype(np.int64)
    reps = b1 - b0 + 1
    row = np.repeat(np.arange(len(flight)), reps)
    bucket = np.repeat(b0 - np.cumsum(reps) + reps, reps) + np.arange(reps.sum())
    n_buckets = int(b1.max()) + 1
    # rows join only within one bucket: process ranges of buckets of ≤ ROWS_PER_PASS rows each
    by_bucket = np.argsort(bucket, kind="stable")
    row, bucket = row[by_bucket], bucket[by_bucket]
    cuts = np.searchsorted(bucket, np.arange(n_buckets + 1))
    found: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    lo_cut = 0
    while lo_cut < n_buckets:
        hi_cut = max(lo_cut + 1, int(np.searchsorted(cuts, cuts[lo_cut] + ROWS_PER_PASS, side="right")) - 1)
        hi_cut = min(hi_cut, n_buckets)
        part = slice(cuts[lo_cut], cuts[hi_cut])
        rows, bk = row[part], bucket[part]
        base, probe = _near_pairs(code[visit[rows]] * n_buckets + bk, offsets * n_buckets)
        rb, rp = rows[base], rows[probe]
        keep = flight[rb] < flight[rp]  # one orientation, no flight with itself: the most selective test first
        base, rb, rp = base[keep], rb[keep], rp[keep]
        keep = (bk[base] == np.maximum(b0[rb], b0[rp])) & (w_lo[rb] < w_hi[rp]) & (w_lo[rp] < w_hi[rb])
        rb, rp = rb[keep], rp[keep]
        fp, fq = flight[rb], flight[rp]
        keep = flightset.aircraft_index[fp] != flightset.aircraft_index[fq]
        rb, rp, fp, fq = rb[keep], rp[keep], fp[keep], fq[keep]
        if len(rb):  # merge now: flights on near-identical tracks give hundreds of visit pairs each
            vb, vp = visit[rb], visit[rp]
            found.append(_group_merge(fp * n + fq, t_in[vb] - t_out[vp], t_out[vb] - t_in[vp]))
        lo_cut = hi_cut
    if not found:
        return np.zeros(0, dtype=np.int64), np.zeros(1, dtype=np.int64), np.zeros(0), np.zeros(0)
    g, lo, hi = _group_merge(*(np.concatenate(parts) for parts in zip(*found, strict=True)))
    pair_code, starts = np.unique(g, return_index=True)
    return pair_code, np.append(starts, len(g)).astype(np.int64), lo, hi


def _window_counts(flightset: FlightSet) -> tuple[np.ndarray, np.ndarray]:
    """Flights in order of planned departure, and for each how many later ones depart before its
    possible flying window [D, D + Δd_upper + flight time] ends (widened by ``TIME_TOL_S``)."""
    start = flightset.planned_departure_s
    end = start + flightset.delay_upper_s + flightset.flight_time_s + 2 * TIME_TOL_S
    order = np.argsort(start, kind="stable")
    stop = np.searchsorted(start[order], end[order], side="left")
    return order, np.maximum(stop - np.arange(len(order)) - 1, 0)


def candidate_count(flightset: FlightSet) -> int:
    """The number of flight pairs whose flying windows overlap (those of one aircraft included): an
    upper bound of :func:`candidate_pairs`'s, counted without making a pair (the memory guard,
    ``uamopt.schedule.plan.check_plan_memory``)."""
    return int(_window_counts(flightset)[1].sum())


def candidate_pairs(flightset: FlightSet) -> tuple[np.ndarray, np.ndarray]:
    """Flight pairs (p < q, different aircraft) whose possible flying windows
    [D, D + Δd_upper + flight time] overlap (widened by ``TIME_TOL_S``, as in :func:`conflict_table`);
    only those can ever conflict."""
    order, count = _window_counts(flightset)
    a = np.repeat(np.arange(len(order)), count)
    b = np.repeat(np.cumsum(count) - count, count)
    b = np.arange(count.sum()) - b + a + 1
    p, q = order[a], order[b]
    p, q = np.minimum(p, q), np.maximum(p, q)
    ac = flightset.aircraft_index
    keep = ac[p] != ac[q]  # one aircraft's own flights are kept apart by the turnaround rule
    return p[keep], q[keep]


MAX_TRACK_PAIRS = 10_000_000  # visit pairs of the track-level join before switching to flight level (~0.5 GB)


def conflict_table(flightset: FlightSet, *, max_track_pairs: int = MAX_TRACK_PAIRS) -> ConflictTable:
    """Every flight pair that can conflict, with its forbidden open intervals of δ = dep_q − dep_p,
    as arrays (the vectorised core of :func:`forbidden_gaps`).

    A pair is kept when one of its intervals meets the feasible range of δ,
    [D_q − D_p − Δd_p, D_q − D_p + Δd_q] with Δd the delay bound tightened by T_f
    (``FlightSet.delay_upper_s``); only those intervals are stored, widened to any interval within
    ``TIME_TOL_S`` of the range (conservative). Pairs of flights of the same aircraft are left out:
    the turnaround rule already keeps them apart in time.

    Flights sharing a track share its intervals (:func:`track_pair_gaps`); when the tracks are so
    many and so intertwined that this join would exceed ``max_track_pairs`` visit pairs, the
    intervals are computed per flight pair instead (:func:`flight_pair_gaps`). Both give the same.
    """
    occupancies, key = flight_occupancies(flightset)
    gaps = track_pair_gaps(occupancies, flightset.conflict_radius, max_track_pairs)
    if gaps is not None:
        pair_code, ptr, lo, hi = gaps
        p, q = candidate_pairs(flightset)
        if len(p) == 0 or len(pair_code) == 0:
            return ConflictTable.empty()
        code = key[p] * len(occupancies) + key[q]
        pos = np.minimum(np.searchsorted(pair_code, code), len(pair_code) - 1)
        found = pair_code[pos] == code
        p, q, grp = p[found], q[found], pos[found]
    else:
        pair_code, ptr, lo, hi = flight_pair_gaps(flightset, occupancies, key)
        if len(pair_code) == 0:
            return ConflictTable.empty()
        p, q = np.divmod(pair_code, len(flightset))
        grp = np.arange(len(pair_code))
    return dataclasses.replace(_prune_to_ranges(flightset, p, q, grp, pair_code, ptr, lo, hi), from_tracks=True)


def _prune_to_ranges(flightset, p, q, grp, pair_code, ptr, lo, hi) -> ConflictTable:
    """Keep, for each flight pair (p, q) with interval group ``grp``, the intervals meeting its range of δ."""
    dep, upper = flightset.planned_departure_s, flightset.delay_upper_s
    range_lo = dep[q] - dep[p] - upper[p] - TIME_TOL_S
    range_hi = dep[q] - dep[p] + upper[q] + TIME_TOL_S
    # One sorted key per interval: (group − g0)·span + value, per chunk of groups. Groups occupy
    # disjoint stretches, so one searchsorted finds, within each pair's group, the first interval
    # with hi > range_lo and the first with lo ≥ range_hi (intervals are sorted and disjoint).
    base, top = float(lo.min()), float(hi.max())
    span = top - base + 4.0
    lo_key, hi_key = lo - base, hi - base
    order = np.argsort(grp, kind="stable")
    q_lo = np.clip(range_lo, base - 1.0, top + 1.0) - base
    q_hi = np.clip(range_hi, base - 1.0, top + 1.0) - base
    first = np.empty(len(grp), dtype=np.int64)
    last = np.empty(len(grp), dtype=np.int64)
    group_of = np.repeat(np.arange(len(pair_code)), np.diff(ptr))
    for g0, g1 in _chunks(ptr, span):
        span_rows = slice(ptr[g0], ptr[g1])
        off = (group_of[span_rows] - g0) * span
        a, b = np.searchsorted(grp[order], [g0, g1])
        qs = order[a:b]
        q_off = (grp[qs] - g0) * span
        first[qs] = ptr[g0] + np.searchsorted(off + hi_key[span_rows], q_off + q_lo[qs], side="right")
        last[qs] = ptr[g0] + np.searchsorted(off + lo_key[span_rows], q_off + q_hi[qs], side="left")
    meet = last > first
    p, q, first, last = p[meet], q[meet], first[meet], last[meet]
    order = np.lexsort((q, p))
    p, q, first, last = p[order], q[order], first[order], last[order]
    count = last - first
    rows = np.repeat(first - np.cumsum(count) + count, count) + np.arange(count.sum())
    return ConflictTable(p=p, q=q, ptr=np.concatenate([[0], np.cumsum(count)]).astype(np.int64),
                         intervals=np.stack([lo[rows], hi[rows]], axis=1))


@dataclass(frozen=True, eq=False)
class ConflictTable:
    """All pair conflicts in compressed form; a sequence of :class:`PairConflict` on access.

    Pair k: flights ``p[k]`` < ``q[k]`` must keep dep_q − dep_p out of the open intervals
    ``intervals[ptr[k]:ptr[k+1]]`` (sorted, disjoint), s. Sorted by (p, q).
    """

    p: np.ndarray
    q: np.ndarray
    ptr: np.ndarray
    intervals: np.ndarray
    #: computed by :func:`conflict_table` from the flight set's own tracks (every conflict of the
    #: occupancy rule is in it): the time-indexed model may then derive clique rows from the
    #: geometry (uamopt/solvers/cliques.py); False for any other table
    from_tracks: bool = False

    @classmethod
    def empty(cls) -> ConflictTable:
        none = np.zeros(0, dtype=np.int64)
        return cls(p=none, q=none, ptr=np.zeros(1, dtype=np.int64), intervals=np.zeros((0, 2)))

    def __len__(self) -> int:
        return len(self.p)

    def __getitem__(self, k: int) -> PairConflict:
        if not -len(self) <= k < len(self):
            raise IndexError(k)
        k = k % len(self)
        return PairConflict(int(self.p[k]), int(self.q[k]), self.intervals[self.ptr[k]:self.ptr[k + 1]])

    def __iter__(self):
        return (self[k] for k in range(len(self)))


def forbidden_gaps(flightset: FlightSet) -> list[PairConflict]:
    """Every flight pair that can conflict, with its forbidden open intervals of δ = dep_q − dep_p.

    See :func:`conflict_table` (the same data as arrays, much faster for 10⁵+ pairs).
    """
    return list(conflict_table(flightset))
