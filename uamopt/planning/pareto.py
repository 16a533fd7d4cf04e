"""Trade-off between operational risk and transport cost (Sec. 6.3.2, Fig. 21).

Each point is the initial track (A* on Eq. 10 plus the safety buffer μ·R(t) of Eq. 35) for one
weight pair (ω4, ω5): ω4 weighs the risk cost C_R (Eq. 11), ω5 the transport cost C_T (Eq. 12).
The front keeps the points no other point beats on both costs.

A weighted sum with a zero weight is ill-posed: with ω5 = 0 every move through safe cells is
free and A* may return any detour. A zero weight is therefore replaced by a tie-break ε scaled
to the costs (ε · largest R per metre against ε · c_h per metre), which makes (1, 0) and (0, 1)
the lexicographic optima: least risk, then least transport, and the reverse.

With ``weights=n`` the sweep starts from those two extremes and then spends the remaining solves
where the front is still unknown (dichotomic search): for two neighbouring points a and b it
solves with the weights normal to the segment ab, ω4 ∝ C_T(b) − C_T(a), ω5 ∝ C_R(a) − C_R(b), and
keeps splitting wherever a new point appears. Without the buffer (``buffer=False``) this finds
the supported points of the exact bi-objective front; with it, each point is still the optimum
of its own weighted search, and the points that the buffer term makes dominated are reported
as such by :func:`non_dominated` and greyed by :func:`uamopt.plotting.pareto`.
"""

from __future__ import annotations

import dataclasses
import heapq
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from uamopt.checks import expect
from uamopt.planning.endpoints import as_endpoint
from uamopt.planning.problem import PlanningModel
from uamopt.planning.search import grid_search
from uamopt.planning.tracks import endpoint_cell, track_metrics

TIE_BREAK = 1e-6  # ε: a zero weight becomes ε times the other objective's per-metre scale
SAME_COST = 1e-9  # relative tolerance under which two points have the same costs


@dataclass(frozen=True)
class ParetoPoint:
    """One weighted search: its weights, Eq. 11 and Eq. 12 costs and the cell-centre track."""

    w4: float  # ω4, risk weight actually used (a zero replaced by the tie-break)
    w5: float  # ω5, transport weight actually used
    risk_cost: float  # C_R, Eq. 11
    transport_cost: float  # C_T, Eq. 12, ¥
    waypoints: np.ndarray  # (n, 3), m: centres of the cells of the optimal path


def tie_break_weights(model: PlanningModel) -> tuple[float, float]:
    """(ε_4, ε_5): the weights that stand in for ω4 = 0 and ω5 = 0.

    ε_5 · c_h per metre is 10⁻⁶ of the largest risk per metre, and ε_4 the reverse, so the
    stand-in only breaks ties between tracks of equal cost in the other objective.
    """
    risky = model.risk[model.admissible]
    rho = float(risky.max()) if risky.size and risky.max() > 0 else 1.0  # R per metre (Eq. 11)
    kappa = float(model.c_h)  # ¥ per horizontal metre (Eq. 12)
    return TIE_BREAK * kappa / rho, TIE_BREAK * rho / kappa


def _checked_pair(pair, eps: tuple[float, float]) -> tuple[float, float]:
    try:
        w4, w5 = (float(v) for v in pair)
    except (TypeError, ValueError):
        raise ValueError(f"weights must be pairs (ω4, ω5) of numbers, got {pair!r}") from None
    if not (np.isfinite(w4) and np.isfinite(w5)) or w4 < 0 or w5 < 0 or w4 + w5 == 0:
        raise ValueError(f"weights (ω4, ω5) must be finite, ≥ 0 and not both 0, got {pair!r}")
    return (w4 if w4 > 0 else eps[0]), (w5 if w5 > 0 else eps[1])


def weighted_model(model: PlanningModel, w4: float, w5: float, *, buffer: bool = True) -> PlanningModel:
    """The model with tracks.weights = (ω4, ω5) (and μ = 0 when ``buffer`` is False); the
    scenario is copied through :meth:`Scenario.with_overrides`, never mutated."""
    overrides = [f"tracks.weights=[{float(w4)!r},{float(w5)!r}]"]
    if not buffer:
        overrides.append("tracks.buffer_penalty=0.0")
    return dataclasses.replace(model, scenario=model.scenario.with_overrides(overrides))


def _solve(model: PlanningModel, start, goal, w4: float, w5: float, buffer: bool) -> ParetoPoint:
    weighted = weighted_model(model, w4, w5, buffer=buffer)
    result = grid_search(weighted.search_problem("initial"), start, goal, backend=model.scenario.tracks.search,
                         heuristic=model.scenario.tracks.heuristic)
    waypoints = (result.path + 0.5) * np.asarray(model.field.grid.cell)  # as the initial stage's
    costs = track_metrics(weighted, waypoints)
    return ParetoPoint(w4, w5, costs["risk_cost"], costs["transport_cost"], waypoints)


def _same(a: ParetoPoint, b: ParetoPoint) -> bool:
    scale = max(abs(a.risk_cost), abs(b.risk_cost), 1e-300), max(abs(a.transport_cost), abs(b.transport_cost), 1e-300)
    return (abs(a.risk_cost - b.risk_cost) <= SAME_COST * scale[0]
            and abs(a.transport_cost - b.transport_cost) <= SAME_COST * scale[1])


def weight_sweep(model: PlanningModel, origin, destination, weights: int | Sequence = 9, *,
                 buffer: bool = True) -> list[ParetoPoint]:
    """Every weighted search of the sweep, in the order solved (dominated points included).

    Parameters
    ----------
    model : PlanningModel
    origin, destination : (x, y, z), m
        As for :func:`uamopt.planning.plan_track`; the search runs between their cells.
    weights : int or sequence of (ω4, ω5)
        An int n ≥ 2: the two extremes and n − 2 dichotomic solves (module docstring); fewer
        when the front is complete earlier. A sequence: exactly these pairs, zeros replaced by
        the tie-break of :func:`tie_break_weights`.
    buffer : bool
        Keep the scenario's safety-buffer penalty μ (Eq. 35) in every search; False sets μ = 0,
        so each search minimises ω4 C_R + ω5 C_T alone.

    Raises
    ------
    TypeError
        ``model`` is not a PlanningModel, ``origin`` or ``destination`` not a vertiport name or
        (x, y, z), ``weights`` neither an int nor a sequence, ``buffer`` not a bool.
    ValueError
        ``weights`` is an int below 2, or a pair is negative, not finite or (0, 0).
    UamoptError, NoTrackError
        As :func:`plan_track`, for the end points.
    """
    expect(model, PlanningModel, "model", "weight_sweep")
    if isinstance(weights, bool) or not isinstance(weights, (int, np.integer, list, tuple, np.ndarray)):
        raise TypeError(f"weight_sweep(): weights must be an int ≥ 2 or a sequence of (ω4, ω5) pairs, "
                        f"got {type(weights).__name__}")
    expect(buffer, bool, "buffer", "weight_sweep")
    o = as_endpoint(model.scenario, origin, "origin", "weight_sweep")
    d = as_endpoint(model.scenario, destination, "destination", "weight_sweep")
    start = endpoint_cell(model, np.asarray(o.point, dtype=float), "origin", o.where)
    goal = endpoint_cell(model, np.asarray(d.point, dtype=float), "destination", d.where)
    eps = tie_break_weights(model)
    if not isinstance(weights, (int, np.integer)):
        pairs = [_checked_pair(p, eps) for p in weights]
        if not pairs:
            raise ValueError("weights must hold at least one pair (ω4, ω5)")
        return [_solve(model, start, goal, w4, w5, buffer) for w4, w5 in pairs]
    if weights < 2:
        raise ValueError(f"weights must be an int ≥ 2 or a sequence of (ω4, ω5) pairs, got {weights}")
    cheap = _solve(model, start, goal, eps[0], 1.0, buffer)  # least C_T, then least C_R
    safe = _solve(model, start, goal, 1.0, eps[1], buffer)  # least C_R, then least C_T
    points = [cheap, safe]
    # segments (a, b) with C_T(a) < C_T(b) and C_R(a) > C_R(b), widest first (normalised span)
    span_r = max(cheap.risk_cost - safe.risk_cost, 1e-300)
    span_t = max(safe.transport_cost - cheap.transport_cost, 1e-300)
    queue: list = []

    def push(a: ParetoPoint, b: ParetoPoint) -> None:
        d_t, d_r = b.transport_cost - a.transport_cost, a.risk_cost - b.risk_cost
        if d_t > SAME_COST * max(abs(b.transport_cost), 1.0) and d_r > SAME_COST * max(abs(a.risk_cost), 1e-300):
            heapq.heappush(queue, (-np.hypot(d_t / span_t, d_r / span_r), len(points), a, b))

    push(cheap, safe)
    while queue and len(points) < weights:
        _, _, a, b = heapq.heappop(queue)
        d_t, d_r = b.transport_cost - a.transport_cost, a.risk_cost - b.risk_cost
        w4, w5 = d_t / (d_t + d_r), d_r / (d_t + d_r)  # normal to ab: a and b cost the same
        c = _solve(model, start, goal, w4, w5, buffer)
        if _same(c, a) or _same(c, b) or any(_same(c, p) for p in points):
            continue
        points.append(c)
        if a.transport_cost < c.transport_cost < b.transport_cost and b.risk_cost < c.risk_cost < a.risk_cost:
            push(a, c)
            push(c, b)
    return points


def non_dominated(points: Sequence[ParetoPoint]) -> list[ParetoPoint]:
    """The points no other point beats on both C_R and C_T (both minimised), one per distinct
    cost pair, sorted by transport cost (then risk cost)."""
    def below(a: float, b: float) -> bool:  # a < b beyond rounding
        return a < b - SAME_COST * max(abs(a), abs(b), 1e-300)

    ordered = sorted(points, key=lambda p: (p.transport_cost, p.risk_cost))
    front: list[ParetoPoint] = []
    for p in ordered:  # by rising C_T, a point is on the front iff its C_R is below every earlier one
        if not front or below(p.risk_cost, front[-1].risk_cost):
            if front and not below(front[-1].transport_cost, p.transport_cost):
                front[-1] = p  # the same C_T up to rounding and less risk: the earlier one is dominated
            else:
                front.append(p)
    return front


def pareto_front(model: PlanningModel, origin, destination, weights: int | Sequence = 9, *,
                 buffer: bool = True) -> list[ParetoPoint]:
    """The Pareto front of Fig. 21: non-dominated (C_R, C_T) of the weighted initial tracks.

    Parameters and exceptions as :func:`weight_sweep`. Returns the front sorted by rising
    transport cost, hence falling risk cost; never empty.

    Examples
    --------
    Table B.3's synthetic city on 100 m cells, V1 → V4 at 120 m (regression values). The middle
    three points lie on one straight stretch of the front, where one weight has several optimal
    tracks; which of them the search returns depends on its heuristic's tie-breaking:

    >>> from uamopt.planning import planning_model
    >>> from uamopt.scenario import Scenario
    >>> from uamopt.pipeline import compute_risk
    >>> scenario = Scenario().with_overrides(["grid.cell=[100,100,60]"])
    >>> model = planning_model(scenario, compute_risk(scenario))
    >>> front = pareto_front(model, (300, 300, 120), (2220, 4220, 120), 5, buffer=False)
    >>> [(round(p.risk_cost), round(p.transport_cost, 2)) for p in front]
    [(3068, 29.15), (2985, 29.52), (2944, 29.88), (2861, 30.61), (2744, 97.11)]
    >>> with_buffer = pareto_front(model, (300, 300, 120), (2220, 4220, 120), 5)  # plus μ·R(t), Eq. 34
    >>> [(round(p.risk_cost), round(p.transport_cost, 2)) for p in with_buffer]
    [(3206, 99.08), (3002, 99.81), (2961, 100.18)]
    """
    return non_dominated(weight_sweep(model, origin, destination, weights, buffer=buffer))
