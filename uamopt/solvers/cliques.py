"""Clique inequalities of the time-indexed model, from the flights' cell occupancy (issue 19).

Why
---
The time-indexed model's conflict rows are pairwise (timeindexed.py: x_{p,a} + Σ_{b ∈ a+Z} x_{q,b}
≤ 1). Where several flights want one piece of airspace at about one time, the LP relaxation sets
each of them to ½ in two slots and every pair row holds: on a 1,000-flight paper-case plan the LP
bound of the 10 s grid lay 51 % below the best schedule on that grid (−338.5 against −223.5; with
the rows −263.3, docs/exact_scheduling.md). The aircraft-landing
literature closes this with clique inequalities on time-indexed models (the facets of right-hand
side 1 are the maximal cliques of the column conflict graph); here the cliques come from the
geometry, so no clique search on a graph of 10⁵ columns is needed.

Which columns form a clique
---------------------------
Conflict rule (occupancy.py): two operated flights of different aircraft conflict when they
occupy cells whose indices differ by at most r in every axis during overlapping times of positive
length. Every two cells of a *block* of (r + 1)³ cells are within r of each other, so two flights
that are both inside one block at one instant t (each for a positive time around t) conflict.
Two flights of one aircraft cannot both fly at t either: the turnaround rule puts the later one's
departure after the earlier one's arrival. Hence, for a block B and an instant t, the columns
(f, k) whose flight is inside B throughout [t − τ, t + τ] form a clique (τ = ``TIME_TOL_S``, the
verifier's tolerance: the two overlaps are then 2τ long, beyond what it forgives):

    Σ_{(f, k) in B at t} x_{f,k} ≤ 1.

*grid* model: column (f, k) has delay k s, so f is in B during [D_f + k s + a, D_f + k s + b] for
each of its visits [a, b] of B (consecutive visits of cells of B merged). *relaxed* model: column
(f, k) stands for any delay in [k s, (k + 1) s); it joins the clique only if f is inside B at t
for *every* such delay, i.e. t ∈ [D_f + (k + 1) s + a, D_f + k s + b] — so every continuous
schedule still maps to a point of the strengthened relaxation, whose bound stays valid for
continuous delays. (With cells crossed in less than s, the relaxed model has few such columns.)

The maximal cliques of the intervals of one block are found by one sweep (ends before starts at
one instant): a start followed by an end closes a maximal clique. Identical cliques of different
blocks are kept once; cliques of a single flight (implied by its assignment row) are dropped.

Dominated rows: a pair row whose columns all lie in one clique row is implied by it and is
removed (:func:`dominated`): on a 1,000-flight paper-case plan 70,791 of its 121,397 pair rows
(10 s grid); on models/benchmark_1000.toml 35,863 of 60,224, for 53,267 clique rows.

When
----
Only for a problem whose conflict table was computed from its own flights' tracks
(``ConflictTable.from_tracks``, set by :func:`~uamopt.schedule.occupancy.conflict_table`) and
whose flights are the plan's own (``core_families`` None: not speed copies). Any other problem
(a hand-made table, a rolling window's sub-problem, the aircraft-landing benchmark) gets none.
"""

from __future__ import annotations

import numpy as np

from uamopt.schedule.flights import TIME_TOL_S
from uamopt.schedule.model import SchedulingProblem

MERGE_S = 1e-9  # consecutive visits of one block closer than this are one stay, s
#: beyond these sizes no rows are derived (the model is solved without them): about 1.5 GB of
#: index arrays; measured 7.5 M column stays and 7.8 M memberships on models/benchmark_1000.toml at 10 s
MAX_STAYS = 60_000_000
MAX_MEMBERS = 60_000_000
_HASH_SEED = 20261206  # the row de-duplication's hash keys (fixed: same model, same rows, any run)


def applicable(problem: SchedulingProblem) -> bool:
    """Whether :func:`occupancy_cliques` may derive rows for ``problem`` (module docstring, *When*)."""
    return bool(getattr(problem.conflicts, "from_tracks", False)) and problem.core_families is None \
        and problem.n_flights > 1


def _block_stays(occupancy, radius: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(block origin cells (m, 3), entry, exit) of one track: each cell visit lies in the (r + 1)³
    blocks whose origin is the cell minus an offset in {0..r}³; consecutive visits of one block merged."""
    side = radius + 1
    offsets = np.array([(i, j, k) for i in range(side) for j in range(side) for k in range(side)], dtype=np.int64)
    blocks = (occupancy.cells[None, :, :] - offsets[:, None, :]).reshape(-1, 3)
    a = np.tile(occupancy.t_in, len(offsets))
    b = np.tile(occupancy.t_out, len(offsets))
    return blocks, a, b


def occupancy_cliques(problem: SchedulingProblem, start: np.ndarray, step_s: float, kind: str
                      ) -> tuple[np.ndarray, np.ndarray]:
    """The clique rows (module docstring) of the time-indexed model with columns ``start[f] + k``,
    k ≤ ``start[f+1] − start[f] − 1``, as CSR ``(ptr, cols)``; empty when not :func:`applicable`."""
    from uamopt.schedule.occupancy import flight_occupancies

    none = (np.zeros(1, np.int64), np.zeros(0, np.int64))
    if not applicable(problem):
        return none
    fs = problem.flights
    occupancies, key = flight_occupancies(fs)
    stays = [_block_stays(o, fs.conflict_radius) for o in occupancies]
    cells = np.concatenate([s[0] for s in stays])
    low = cells.min(axis=0)
    dims = cells.max(axis=0) - low + 1
    tracks = []
    for blocks, a, b in stays:
        code = ((blocks[:, 0] - low[0]) * dims[1] + (blocks[:, 1] - low[1])) * dims[2] + (blocks[:, 2] - low[2])
        order = np.lexsort((a, code))
        code, a, b = code[order], a[order], b[order]
        new = np.ones(len(code), dtype=bool)
        new[1:] = (code[1:] != code[:-1]) | (a[1:] > b[:-1] + MERGE_S)
        heads = np.flatnonzero(new)
        tracks.append((code[heads], a[heads], np.maximum.reduceat(b, heads)))
    tracks = _shared_or_longest(tracks)
    dep = problem.planned_departure_s
    k_count = np.diff(start)
    company = _in_company(tracks, key, dep, (k_count - 1) * step_s)
    parts: list[tuple[np.ndarray, ...]] = []
    for f in range(problem.n_flights):
        code, a, b = tracks[key[f]]
        code, a, b = code[company[f]], a[company[f]], b[company[f]]
        k = np.arange(k_count[f])[:, None]
        lo = dep[f] + (k + (1 if kind == "relaxed" else 0)) * step_s + a[None, :] + TIME_TOL_S
        hi = dep[f] + k * step_s + b[None, :] - TIME_TOL_S
        ok = hi > lo
        if ok.any():
            parts.append((np.broadcast_to(code, lo.shape)[ok], lo[ok], hi[ok],
                          np.broadcast_to(start[f] + k, lo.shape)[ok]))
    if not parts or sum(len(x[0]) for x in parts) > MAX_STAYS:
        return none
    block, lo, hi, col = (np.concatenate(x) for x in zip(*parts, strict=True))
    # the sweep, per block: ends (−1) before starts (+1) at one instant; a start then an end closes a clique
    m = len(block)
    # one exact integer key per (block, time): block · (T + 1) + the time's rank among all T distinct
    # times (a float key would round two instants of a block together); a stable sort of
    # [ends, starts] puts the ends first at one key
    times, rank = np.unique(np.concatenate([hi, lo]), return_inverse=True)
    keys = np.concatenate([block, block]) * np.int64(len(times) + 1) + rank.astype(np.int64)
    order = np.argsort(keys, kind="stable")
    is_start = order >= m
    sorted_keys = keys[order]
    at = np.flatnonzero(is_start[:-1] & ~is_start[1:])
    same_block = sorted_keys[at] // (len(times) + 1) == sorted_keys[at + 1] // (len(times) + 1)
    point_key = sorted_keys[at[same_block]]  # sorted
    # member (interval i, point j) iff one block and lo_i ≤ t_j < hi_i
    first = np.searchsorted(point_key, keys[m:], side="left")
    last = np.searchsorted(point_key, keys[:m], side="left")
    count = last - first
    if int(count.sum()) > MAX_MEMBERS:
        return none
    member_point = np.repeat(first, count) + np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    member_col = np.repeat(col, count)
    return _distinct_rows(member_point, member_col, len(point_key), start)


def _in_company(tracks: list, key: np.ndarray, dep: np.ndarray, reach_s: np.ndarray) -> list[np.ndarray]:
    """Per flight, a mask over its track's stays: True where another flight's stay of the block can
    be there at an overlapping time (its span over every delay, [D + a, D + reach + b], meets the
    other's). A clique of one flight is implied by its assignment row, so the other stays are
    left out before they are multiplied by the delay indices. Conservative: 1 ms of slack."""
    sizes = np.array([len(tracks[k][0]) for k in key])
    flight = np.repeat(np.arange(len(key)), sizes)
    block = np.concatenate([tracks[k][0] for k in key])
    lo = np.concatenate([tracks[k][1] for k in key]) + dep[flight]
    hi = np.concatenate([tracks[k][2] for k in key]) + (dep + reach_s)[flight]
    order = np.lexsort((lo, block))
    b_s, lo_s, hi_s = block[order], lo[order], hi[order]
    first = np.ones(len(b_s), dtype=bool)
    first[1:] = b_s[1:] != b_s[:-1]
    # the latest end among the earlier spans of the block: a running maximum restarted per block
    lifted = hi_s + np.cumsum(first) * (float(hi.max() - lo.min()) + 1.0)
    before = np.maximum.accumulate(lifted) - np.cumsum(first) * (float(hi.max() - lo.min()) + 1.0)
    before = np.concatenate([[-np.inf], before[:-1]])
    before[first] = -np.inf
    after = np.concatenate([lo_s[1:], [np.inf]])
    last = np.concatenate([first[1:], [True]])
    after[last] = np.inf
    meets = (before > lo_s - 1e-3) | (after < hi_s + 1e-3)
    keep = np.empty(len(order), dtype=bool)
    keep[order] = meets
    return np.split(keep, np.cumsum(sizes)[:-1])


def _shared_or_longest(tracks: list) -> list:
    """Each track's stays in blocks that another track visits too, and of its other stays the
    longest one. A block only one track visits gives the same cliques as any other such block up
    to a shift in time, a longer stay a superset of them (every column inside [a, b] at t is inside
    [a', b'] at t + a' − a when b' − a' ≥ b − a): the longest stay's cliques imply the rest."""
    code = np.concatenate([t[0] for t in tracks])
    owner = np.repeat(np.arange(len(tracks)), [len(t[0]) for t in tracks])
    pairs = np.unique(code * len(tracks) + owner)
    blocks, visitors = np.unique(pairs // len(tracks), return_counts=True)
    out = []
    for c, a, b in tracks:
        shared = visitors[np.searchsorted(blocks, c)] > 1
        keep = shared.copy()
        if (~shared).any():
            alone = np.flatnonzero(~shared)
            keep[alone[np.argmax((b - a)[alone])]] = True
        out.append((c[keep], a[keep], b[keep]))
    return out


def _distinct_rows(point: np.ndarray, col: np.ndarray, n_points: int, start: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cliques (point → columns) as CSR rows: each set once, only sets of two flights or more."""
    order = np.lexsort((col, point))
    point, col = point[order], col[order]
    keep = np.ones(len(point), dtype=bool)
    keep[1:] = (point[1:] != point[:-1]) | (col[1:] != col[:-1])
    point, col = point[keep], col[keep]
    flight = np.searchsorted(start, col, side="right") - 1
    new_flight = np.ones(len(point), dtype=bool)
    new_flight[1:] = (point[1:] != point[:-1]) | (flight[1:] != flight[:-1])
    several = np.bincount(point[new_flight], minlength=n_points) >= 2
    # one set once: two independent 64-bit sums of random keys per set, and its size
    rng = np.random.default_rng(_HASH_SEED)
    keys = rng.integers(1, 2**62, size=(2, int(start[-1])), dtype=np.int64).astype(np.uint64)
    size = np.bincount(point, minlength=n_points)
    end = np.cumsum(size)
    sums = np.zeros((n_points, 3), dtype=np.uint64)
    with np.errstate(over="ignore"):  # sums modulo 2⁶⁴
        for j in range(2):
            running = np.zeros(len(col) + 1, dtype=np.uint64)
            np.cumsum(keys[j, col], dtype=np.uint64, out=running[1:])
            sums[:, j] = running[end] - running[end - size]
    sums[:, 2] = size.astype(np.uint64)
    chosen = np.zeros(n_points, dtype=bool)
    _, first = np.unique(sums[several], axis=0, return_index=True)
    chosen[np.flatnonzero(several)[first]] = True
    rows = (np.cumsum(chosen) - 1)[point[chosen[point]]]
    cols = col[chosen[point]]
    ptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=int(chosen.sum())))]).astype(np.int64)
    return ptr, cols.astype(np.int64)


def dominated(row_ptr: np.ndarray, row_col: np.ndarray, clique_ptr: np.ndarray, clique_col: np.ndarray,
              n_cols: int) -> np.ndarray:
    """(rows,) bool: the "≤ 1" rows whose columns all lie in one clique row (implied by it)."""
    n_rows, n_cliques = len(row_ptr) - 1, len(clique_ptr) - 1
    if n_rows == 0 or n_cliques == 0:
        return np.zeros(n_rows, dtype=bool)
    row_of = np.repeat(np.arange(n_rows), np.diff(row_ptr))
    clique_of = np.repeat(np.arange(n_cliques), np.diff(clique_ptr))
    order = np.argsort(clique_col, kind="stable")
    by_col = clique_of[order]
    col_ptr = np.concatenate([[0], np.cumsum(np.bincount(clique_col, minlength=n_cols))])
    count = col_ptr[row_col + 1] - col_ptr[row_col]
    if int(count.sum()) > MAX_MEMBERS:  # the join would not fit: keep every row (valid, only larger)
        return np.zeros(n_rows, dtype=bool)
    at = np.repeat(col_ptr[row_col], count) + np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    pair = np.repeat(row_of, count).astype(np.int64) * n_cliques + by_col[at]
    pair, shared = np.unique(pair, return_counts=True)
    row = pair // n_cliques
    out = np.zeros(n_rows, dtype=bool)
    out[row[shared == np.diff(row_ptr)[row]]] = True
    return out


def drop_dominated(pair_ptr: np.ndarray, col: np.ndarray, clique_ptr: np.ndarray, clique_col: np.ndarray,
                   n_cols: int) -> tuple[np.ndarray, np.ndarray, int]:
    """The pair rows (CSR ``pair_ptr``, ``col``) less those a clique row implies (:func:`dominated`):
    (pair_ptr, col, how many were dropped)."""
    drop = dominated(pair_ptr, col, clique_ptr, clique_col, n_cols)
    sizes = np.diff(pair_ptr)[~drop]
    col = col[~np.repeat(drop, np.diff(pair_ptr))]
    return np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64), col, int(drop.sum())
