"""Independent recomputations for the tests: nothing here imports uamopt.

A test that checks a solver's objective with the library's own ``evaluate`` (or reads back the
``objective`` that ``make_schedule`` computed with it) cannot fail when Eq. 20 is coded wrong.
These functions recompute what the tests compare against, in a few lines, from the paper:

- Eq. 20: W = ω6·T_d − ω7·S;  Eq. 21: T_d = Σ_f c_f d_f / G;  Eq. 22: S = Σ_f c_f.
- The lexicographic variant (docs/readings.md): most operated flights first, then least total
  delay, as the scalar −S + Σ c d / (Σ_f U_f + 1) with U_f = min(Δd_f, T_f − planned arrival_f).
"""

from __future__ import annotations

import csv
import itertools
import json
import math
from pathlib import Path


def objective(operated, delay_s, weights, aircraft: int, kind: str = "weighted", upper_s=None) -> float:
    """Eqs. 20-22 (or the lexicographic scalar) of a decision, from plain lists of numbers."""
    flown = [bool(c) for c in operated]
    total = sum(float(d) for c, d in zip(flown, delay_s, strict=True) if c)
    served = sum(flown)
    if kind == "lexicographic":
        return -served + total / (sum(float(u) for u in upper_s) + 1.0)
    w6, w7 = weights
    return w6 * total / aircraft - w7 * served


def _length(waypoints) -> float:
    return sum(math.dist(a, b) for a, b in itertools.pairwise(waypoints))


def objective_from_folder(folder: str | Path, weights, kind: str = "weighted") -> float:
    """The objective of a schedule folder, read from ``schedule.csv`` and ``flights.json`` only.

    G is the number of distinct aircraft in schedule.csv (Eq. 21); the delay bound of a flight is
    min(max_delay_s, service_end_s − planned departure − length / speed) (Eqs. 26, 29, 31).
    """
    folder = Path(folder)
    with open(folder / "schedule.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    spec = json.loads((folder / "flights.json").read_text(encoding="utf-8"))
    end = float(spec.get("service_end_s", 3600.0))
    flights = {f["id"]: f for f in spec["flights"]}
    upper = []
    for r in rows:
        f = flights[r["flight"]]
        arrival = float(f["planned_departure_s"]) + _length(f["waypoints"]) / float(f["speed_mps"])
        upper.append(max(0.0, min(float(f["max_delay_s"]), end - arrival)))
    return objective([r["operated"] == "1" for r in rows], [float(r["delay_s"]) for r in rows], weights,
                     len({r["aircraft"] for r in rows}), kind, upper)


# --- the paper's scheduling model (Sec. 4.3), rebuilt from the flights -----------------------------
#: the families ``model_data`` rebuilds (the paper's five); a problem with any other refuses
PAPER_SHAPES = frozenset({"bounds", "must_operate", "precedence", "turnaround", "pairs"})


def model_data(problem) -> dict:
    """The paper's model of a scheduling problem as plain numbers, rebuilt from its flights.

    Read off ``problem`` by attribute only (nothing of uamopt is imported or called): each flight's
    aircraft, planned departure D_f, track, speed, Δd_f and ΔT_f, the service end T_f, the pair
    intervals of ``problem.conflicts`` (the 4-D occupancy is not recomputed here), ω, G, the kind.
    Rebuilt here: the flight times (length / v_g), U_f = max(0, min(Δd_f, T_f − D_f − T_n)) (Eqs. 26,
    29), each aircraft's chain in planned-departure order, the turnaround of every ordered pair e
    before f of a chain, d_f − d_e ≥ D_e + T_e + ΔT_e − D_f (Eqs. 27-28), and the precedence: an
    even leg (a return) needs the flight before it (its outbound).
    """
    shapes = {family.shape for family in problem.families}
    if not shapes <= PAPER_SHAPES:
        raise ValueError(f"model_data rebuilds the paper's families only, not {sorted(shapes - PAPER_SHAPES)}")
    fs = problem.flights
    flights = fs.flights
    if any(getattr(f, "vertical_rate_mps", None) is not None for f in flights):
        raise ValueError("model_data takes flights without vertical phases (T = length / v_g)")
    planned = [float(f.planned_departure_s) for f in flights]
    duration = [_length([tuple(map(float, w)) for w in f.waypoints]) / float(f.speed_mps) for f in flights]
    end = float(fs.service_end_s)
    upper = [max(0.0, min(float(f.max_delay_s), end - planned[i] - duration[i])) for i, f in enumerate(flights)]
    chains: dict[str, list[int]] = {}
    for i, f in enumerate(flights):
        chains.setdefault(f.aircraft, []).append(i)
    requires = [-1] * len(flights)
    turnaround = []
    for chain in chains.values():
        chain.sort(key=lambda i: (planned[i], i))
        for pos, f in enumerate(chain):
            if pos % 2 == 1:  # leg pos + 1 is even: a return
                requires[f] = chain[pos - 1]
        for a, e in enumerate(chain):
            gap = float(flights[e].turnaround_after_s)
            turnaround += [(e, f, planned[e] + duration[e] + gap - planned[f]) for f in chain[a + 1:]]
    c = problem.conflicts
    ptr = [int(x) for x in c.ptr]
    conflicts = [(int(c.p[k]), int(c.q[k]), sorted((float(lo), float(hi)) for lo, hi in c.intervals[ptr[k]:ptr[k + 1]]))
                 for k in range(len(ptr) - 1)]
    return {"planned_s": planned, "upper_s": upper, "requires": requires, "turnaround": turnaround,
            "conflicts": conflicts, "must": [bool(m) for m in problem.must_operate],
            "weights": tuple(float(w) for w in problem.weights), "aircraft": int(problem.aircraft_count),
            "kind": str(problem.objective_kind)}


def score(data: dict, operated, delay_s) -> float:
    """:func:`objective` of a decision on the problem of ``model_data``."""
    return objective(operated, delay_s, data["weights"], data["aircraft"], data["kind"], data["upper_s"])


def broken(data: dict, operated, delay_s, tol_s: float = 1e-6) -> list[str]:
    """The constraints of the paper's model that a decision breaks (empty: feasible), each as a
    line: the delay bounds, must-operate, precedence, turnaround, and the pair intervals (δ =
    dep_q − dep_p may not lie in an open interval (lo, hi); its ends are allowed), ``tol_s`` of
    slack on every time comparison."""
    c = [bool(x) for x in operated]
    d = [float(x) if on else 0.0 for x, on in zip(delay_s, c, strict=True)]
    out = [f"flight {f}: delay {d[f]} outside [0, {u}]" for f, u in enumerate(data["upper_s"])
           if c[f] and not -tol_s <= d[f] <= u + tol_s]
    out += [f"flight {f}: must operate" for f, must in enumerate(data["must"]) if must and not c[f]]
    out += [f"flight {f}: operated without {r}" for f, r in enumerate(data["requires"]) if r >= 0 and c[f] and not c[r]]
    out += [f"flights {e}, {f}: turnaround {d[f] - d[e]} < {need}" for e, f, need in data["turnaround"]
            if c[e] and c[f] and d[f] - d[e] < need - tol_s]
    dep = [p + x for p, x in zip(data["planned_s"], d, strict=True)]
    for p, q, intervals in data["conflicts"]:
        if c[p] and c[q]:
            delta = dep[q] - dep[p]
            out += [f"flights {p}, {q}: δ = {delta} in ({lo}, {hi})" for lo, hi in intervals if lo + tol_s < delta < hi - tol_s]
    return out


def _least_delays(n: int, upper, edges) -> list[float] | None:
    """The least d ≥ 0 with d_j ≥ d_i + w for every edge (i, j, w), by longest paths from d = 0
    (Bellman-Ford); None when there is none within d ≤ U (a positive cycle, or a bound broken)."""
    d = [0.0] * n
    for _ in range(n + 1):
        changed = False
        for i, j, w in edges:
            if d[i] + w > d[j] + 1e-12:
                d[j] = d[i] + w
                changed = True
        if not changed:
            return d if all(x <= u + 1e-9 for x, u in zip(d, upper, strict=True)) else None
    return None


def _branch(data: dict, operated: list[bool], upper: list[float], branches: list, depth: int, edges: list,
            best: list) -> None:
    """Depth ``depth`` of :func:`exact_optimum`'s search over the gap choices of ``operated``:
    ``best`` ([objective, operated, delays]) is replaced by any better completion."""
    d = _least_delays(len(upper), upper, edges)
    if d is None:
        return
    value = score(data, operated, d)
    if value >= best[0] - 1e-12:
        return
    if depth == len(branches):
        best[:] = [value, list(operated), d]
        return
    for rows in branches[depth]:
        _branch(data, operated, upper, branches, depth + 1, edges + rows, best)


def exact_optimum(data: dict) -> tuple[float, list[bool], list[float]]:
    """The optimum of the paper's model (continuous delays) by enumeration, for a handful of flights.

    Every operate vector keeping the precedence and must-operate; for one, the objective grows with
    Σ d, and once each operated pair picks a closed gap of δ between (or beyond) its forbidden
    intervals every constraint is a difference constraint d_j ≥ d_i + w, whose least solution
    (longest paths) minimises every d_f at once. The gap choices are enumerated depth first; a
    partial choice's least solution bounds its completions from below, so a branch that is already
    no better than the best found is cut. Returns (objective, operated, delays)."""
    n, planned, upper = len(data["planned_s"]), data["planned_s"], data["upper_s"]
    best: list = [math.inf, [False] * n, [0.0] * n]
    for bits in itertools.product((True, False), repeat=n):
        c = list(bits)
        if any(m and not on for m, on in zip(data["must"], c, strict=True)):
            continue
        if any(r >= 0 and c[f] and not c[r] for f, r in enumerate(data["requires"])):
            continue
        if score(data, c, [0.0] * n) >= best[0] - 1e-12:
            continue  # no delays at all: no better than the best
        base = [(e, f, need) for e, f, need in data["turnaround"] if c[e] and c[f]]
        branches = []
        for p, q, intervals in data["conflicts"]:
            if not (c[p] and c[q]):
                continue
            shift = planned[q] - planned[p]  # δ = shift + d_q − d_p
            options = []
            for j in range(len(intervals) + 1):  # gap j: hi_{j−1} ≤ δ ≤ lo_j
                rows = []
                if j > 0:  # δ ≥ hi: d_q ≥ d_p + hi − shift
                    rows.append((p, q, intervals[j - 1][1] - shift))
                if j < len(intervals):  # δ ≤ lo: d_p ≥ d_q + shift − lo
                    rows.append((q, p, shift - intervals[j][0]))
                options.append(rows)
            branches.append(options)
        branches.sort(key=len)
        _branch(data, c, [u if on else 0.0 for u, on in zip(upper, c, strict=True)], branches, 0, base, best)
    return best[0], best[1], best[2]


def grid_optimum(data: dict, step_s: float) -> float:
    """The best objective over every decision whose delays are whole multiples of ``step_s`` (the
    time-indexed grid model's problem), each decision checked by :func:`broken`."""
    choices = [[None] + [k * step_s for k in range(math.floor(u / step_s + 1e-9) + 1)] for u in data["upper_s"]]
    best = math.inf
    for combo in itertools.product(*choices):
        operated = [x is not None for x in combo]
        delay = [0.0 if x is None else x for x in combo]
        value = score(data, operated, delay)
        if value < best - 1e-12 and not broken(data, operated, delay):
            best = value
    return best


# --- shortest paths on the cell grid ------------------------------------------------------------
def grid_shortest_length(passable, cell, source, target) -> float:
    """The least length, m, of a path of cell centres from ``source`` to ``target`` (index triples)
    through the cells where ``passable[i][j][k]`` is true: moves to any of the 26 neighbours whose
    bounding box of cells is all passable (no corner cutting), each as long as its offset scaled by
    ``cell`` (Dijkstra with a binary heap; inf when the target cannot be reached)."""
    import heapq

    nx_, ny_, nz_ = len(passable), len(passable[0]), len(passable[0][0])
    free = {(i, j, k) for i in range(nx_) for j in range(ny_) for k in range(nz_) if passable[i][j][k]}
    moves = []
    for offset in itertools.product((-1, 0, 1), repeat=3):
        if any(offset):
            corners = [c for c in itertools.product(*[(0, o) if o else (0,) for o in offset]) if any(c)]
            moves.append((offset, corners, math.sqrt(sum((o * s) ** 2 for o, s in zip(offset, cell, strict=True)))))
    source, target = tuple(source), tuple(target)
    if source not in free or target not in free:
        return math.inf
    dist = {source: 0.0}
    heap = [(0.0, source)]
    while heap:
        d, node = heapq.heappop(heap)
        if node == target:
            return d
        if d > dist[node]:
            continue
        i, j, k = node
        for (a, b, c), corners, step in moves:
            nxt = (i + a, j + b, k + c)
            if nxt not in free or not all((i + u, j + v, k + w) in free for u, v, w in corners):
                continue
            if d + step < dist.get(nxt, math.inf):
                dist[nxt] = d + step
                heapq.heappush(heap, (d + step, nxt))
    return math.inf


def pair_broken(data: dict, f: int, g: int, d_f: float, d_g: float, tol_s: float = 1e-6) -> bool:
    """Operating only f and g (delays d_f, d_g) breaks a conflict interval or a turnaround."""
    n = len(data["planned_s"])
    operated, delay = [False] * n, [0.0] * n
    operated[f] = operated[g] = True
    delay[f], delay[g] = d_f, d_g
    lines = broken(dict(data, requires=[-1] * n, must=[False] * n, upper_s=[1e9] * n), operated, delay, tol_s)
    return any("turnaround" in line or "δ" in line for line in lines)
