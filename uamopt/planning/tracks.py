"""The four stages of Fig. 18 / Table 2: shortest, initial, equivalent and optimal track.

- **shortest**: standard A* on transport cost alone (Eq. 12), under the same constraints.
- **initial**: A* on Eqs. 10–13 plus the safety-buffer penalty μ·R(t) (Eqs. 34–35).
- **equivalent**: the initial track's cells form a corridor; the track may pass anywhere inside
  it. The shortest polyline through the corridor — one point on the shared face (edge, corner)
  of each pair of consecutive cells — is a second-order cone program, solved exactly with cvxpy
  (``tracks.equivalent = "exact"``). The paper's rule, the midpoint of consecutive cell centres,
  is a feasible point of that program, so the exact track is never longer (unless the rule
  breaks the risk bound); both are reported. The program may not carry more than
  (1 + ``tracks.risk_tolerance``) × the initial track's risk (Eq. 11), a convex constraint added
  where the shortest polyline would break it, and its points keep inside their cells as Eq. 11
  counts them (:func:`corridor_program`, docs/readings.md).
- **optimal**: the equivalent track smoothed with local cubic curves at its turns (the paper's
  cubic interpolation around the entry and exit nodes of each integrated cell): each corner is
  rounded by a cubic Bézier fillet inside the corner's triangle, shrunk where it would leave the
  corridor or enter a risky or inadmissible cell, or add risk beyond the same bound. Fillets cut
  corners, so the optimal track is never longer than the equivalent one.

Each stage's metrics are recomputed from its own waypoints: the risk cost is Eq. 11 taken as
the exact line integral of R along the polyline (for centre-to-centre moves this is Eq. 11
itself: half of each move lies in each cell), the transport cost is Eq. 12.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import cvxpy as cp
import numpy as np

from uamopt.errors import GridError, NoTrackError, UamoptError
from uamopt.grid.geometry import polyline_in_mask, polyline_pieces, split_segments
from uamopt.planning.endpoints import as_endpoint
from uamopt.planning.problem import PlanningModel
from uamopt.planning.search import grid_search, warm_up

STAGES = ("shortest", "initial", "equivalent", "optimal")

#: ω4·C_R and ω5·C_T of the shortest track further apart than this factor (2.5 orders of magnitude):
#: Eq. 10 is in effect one of its terms alone, and :func:`plan_track` warns (:class:`TrackWeightsWarning`).
#: The binary field never gets there at Table B.3 weights: a risky metre weighs at most 1/c_h ≈ 161
#: metres of transport, the ratio of a track that is risky all along; the continuous field's R per
#: flight hour puts C_R some 5000 times below C_T.
SCALE_WARNING_RATIO = 10**2.5


class TrackWeightsWarning(UserWarning):
    """The two terms of Eq. 10 are on scales so far apart that the weights ω4, ω5 do not trade them."""


def weight_scale_message(model: PlanningModel, shortest: TrackStage) -> str | None:
    """Why Eq. 10 degenerates on this model, or None: ω4·C_R and ω5·C_T of the shortest track
    (the reference of Table 2) more than :data:`SCALE_WARNING_RATIO` apart. A shortest track
    without risk (C_R = 0) has nothing to trade and gives no message."""
    t = model.scenario.tracks
    w4, w5 = t.weights
    risk, transport = w4 * shortest.risk_cost, w5 * shortest.transport_cost
    if shortest.risk_cost <= 0 or risk <= 0 or transport <= 0:
        return None
    ratio = max(risk, transport) / min(risk, transport)
    if ratio <= SCALE_WARNING_RATIO:
        return None
    # the weights that would put the two terms on one scale: ω4/ω5 = C_T/C_R, with ω4 + ω5 = 1
    even = shortest.transport_cost / (shortest.risk_cost + shortest.transport_cost)
    small, large = ("risk", "transport") if risk < transport else ("transport", "risk")
    model_note = (f" (tracks.risk_model = \"{t.risk_model}\": R per flight hour)" if t.risk_model == "continuous"
                  else "")
    return (f"on the shortest track ω4·C_R = {risk:.3g}{model_note} and ω5·C_T = ¥{transport:.3g} differ by a factor "
            f"of {ratio:.3g}: Eq. 10 is in effect {large} alone and the weights do not trade {small} against it "
            f"(tracks.weights = [{w4:g}, {w5:g}]); give tracks.weights the ratio ω4/ω5 ≈ "
            f"{shortest.transport_cost / shortest.risk_cost:.3g} to weigh the two alike (e.g. [{even:.6g}, "
            f"{1 - even:.3g}])" + (", or set tracks.risk_model = \"binary\"" if t.risk_model == "continuous" else ""))


@dataclass(frozen=True)
class TrackStage:
    """One stage's track and its metrics (docs/interfaces.md ``tracks.json``)."""

    name: str
    waypoints: np.ndarray  # (n, 3), m
    risk_cost: float  # Eq. 11
    transport_cost: float  # Eq. 12, ¥
    objective: float  # Eq. 10
    buffer_cost: float  # Σ μ·R(t) over the cells entered (Eq. 34)
    length_m: float
    seconds: float  # this stage's own computing time
    extra: dict = field(default_factory=dict)

    @property
    def n_waypoints(self) -> int:
        return len(self.waypoints)

    def as_dict(self) -> dict:
        return {
            "waypoints": self.waypoints.tolist(), "risk_cost": self.risk_cost,
            "transport_cost": self.transport_cost, "objective": self.objective, "buffer_cost": self.buffer_cost,
            "n_waypoints": self.n_waypoints, "length_m": self.length_m, "seconds": self.seconds, **self.extra,
        }


def track_metrics(model: PlanningModel, waypoints: np.ndarray) -> dict:
    """Eq. 11 (line integral of R), Eq. 12 and Eq. 10 for a polyline, and its length (Eq. 17)."""
    pts = np.asarray(waypoints, dtype=float)
    step = np.diff(pts, axis=0)
    length = float(np.linalg.norm(step, axis=1).sum())
    cells, s0, s1 = polyline_pieces(pts, model.field.grid.cell)
    cells = np.clip(cells, 0, np.asarray(model.risk.shape) - 1)
    risk_cost = float(np.sum(model.risk[tuple(cells.T)] * (s1 - s0)))
    transport = float(model.c_h * np.hypot(step[:, 0], step[:, 1]).sum() + model.c_v * np.abs(step[:, 2]).sum())
    # Safety buffer exposure (Eq. 34): μ·R(t) for every cell entered after the first.
    entered = cells[np.concatenate([[False], np.any(np.diff(cells, axis=0) != 0, axis=1)])]
    buffer = float(model.scenario.tracks.buffer_penalty * model.shell_count[tuple(entered.T)].sum())
    w4, w5 = model.scenario.tracks.weights
    return {"risk_cost": risk_cost, "transport_cost": transport, "objective": w4 * risk_cost + w5 * transport,
            "buffer_cost": buffer, "length_m": length}


def _stage(model: PlanningModel, name: str, waypoints: np.ndarray, seconds: float, **extra) -> TrackStage:
    return TrackStage(name=name, waypoints=np.asarray(waypoints, dtype=float), seconds=seconds, extra=extra,
                      **track_metrics(model, waypoints))


def endpoint_cell(model: PlanningModel, point, label: str, where: str | None = None) -> tuple[int, int, int]:
    """The cell of an origin/destination, with a clear error when it cannot be flown from.
    ``where`` names how the user gave the point (``--from Kamppi``, ``tracks.route``)."""
    grid, field_ = model.field.grid, model.field
    if where is None:
        where = f"{label} ({', '.join(f'{v:g}' for v in point)})"
    try:
        cell = grid.index_of(tuple(point))
    except GridError:
        shown = "(" + ", ".join(f"{float(v):g}" for v in point) + ")"
        raise UamoptError(f"{label} {shown} is outside the grid", where,
                          f"give x, y, z inside {tuple(round(e, 1) for e in grid.extent)} m") from None
    low, high = field_.band
    if not low <= point[2] <= high:
        raise UamoptError(f"{label} altitude {point[2]:g} m is outside the band {low:g}-{high:g} m (Eq. 14)", where,
                          "choose an altitude inside the band")
    if field_.obstacle[cell]:
        if field_.city.building_height[cell[:2]] > 0:
            raise UamoptError(f"{label} is inside a building (cell {cell})", where, "move it above the roofs or into the street")
        raise UamoptError(f"{label} is inside a low obstacle (cell {cell}: surface up to "
                          f"{field_.city.surface_height[cell[:2]]:.1f} m, below city.building_min_height_m, e.g. trees)",
                          where, "move it above the obstacle")
    if field_.no_fly[cell]:
        raise UamoptError(f"{label} is inside a no-fly zone (cell {cell})", where, "move it out of the zone")
    if not model.admissible[cell]:
        raise UamoptError(f"{label} is closer than s_min = {model.scenario.tracks.clearance_m:g} m to a building (cell {cell})",
                          where, "move it away from the building or lower tracks.clearance_m")
    return cell


def _grid_waypoints(model: PlanningModel, path: np.ndarray) -> np.ndarray:
    """The paper's waypoints of a cell path: the centres of its cells, origin cell to goal cell
    (Sec. 4.2: p_n = (i_n, j_n, k_n)). The exact origin and destination, which lie inside the end
    cells, are where the equivalent and optimal tracks start and end."""
    return (path + 0.5) * np.asarray(model.field.grid.cell)


def corridor_boxes(path: np.ndarray, cell) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners of the shared face/edge/corner of consecutive corridor cells."""
    size = np.asarray(cell, dtype=float)
    lo = np.maximum(path[:-1], path[1:]) * size
    hi = (np.minimum(path[:-1], path[1:]) + 1) * size
    return lo, hi


def simplify(points: np.ndarray, tol: float = 1e-7) -> np.ndarray:
    """Drop repeated points and interior points collinear with their neighbours."""
    pts = np.asarray(points, dtype=float)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(pts, axis=0), axis=1) > tol])
    pts = pts[keep]
    changed = True
    while changed and len(pts) > 2:
        a, b, c = pts[:-2], pts[1:-1], pts[2:]
        ab, bc = b - a, c - b
        cross = np.linalg.norm(np.cross(ab, bc), axis=1)
        straight = (cross <= tol * np.linalg.norm(ab, axis=1) * np.linalg.norm(bc, axis=1) + tol) & (
            np.einsum("ij,ij->i", ab, bc) > 0)
        # drop every other collinear point per pass so neighbours are re-checked
        drop = np.zeros(len(pts), dtype=bool)
        idx = np.flatnonzero(straight) + 1
        drop[idx[::2]] = True
        changed = bool(drop.any())
        pts = pts[~drop]
    return pts


def midpoint_track(path: np.ndarray, cell, origin, destination) -> np.ndarray:
    """The paper's equivalent track: the midpoints of consecutive cell centres (Sec. 5.1)."""
    lo, hi = corridor_boxes(path, cell)
    return simplify(np.vstack([origin, 0.5 * (lo + hi), destination]))


#: Share of the cell side that the points of the corridor program keep below the upper faces of
#: their cell (docs/readings.md, *The four stages*). The program charges each segment the risk of
#: the corridor cell it crosses, but a point on a grid plane belongs to the cell above it (⌊x/Δ⌋,
#: as everywhere in the code), so a segment lying on the *upper* face of its cell would be charged
#: the risk of the cell beyond, outside the corridor.
FACE_MARGIN = 1e-4


def corridor_program(path: np.ndarray, cell, origin, destination, *, model: PlanningModel | None = None,
                     objective: str = "length", risk_budget: float | None = None,
                     reference: float | None = None) -> tuple[np.ndarray, dict]:
    """The equivalent track's program over the corridor of ``path`` cells, and what it did.

    The track crosses the corridor's cells in order: one point q_i on the shared face (edge,
    corner) of cells i−1 and i, and in a cell the path enters and leaves through its upper face
    on one axis (a "dip", the grid path stepping down and back up around a cell it avoided) one
    more point inside the cell, so that no segment need run along that face. Every point keeps
    :data:`FACE_MARGIN` of the cell side below its cell's upper faces where it is free to, so each
    segment lies in its corridor cell as Eq. 11's line integral counts it (⌊x/Δ⌋).

    The objective is the length Σ‖Δp‖ (``"length"``) or Eq. 10, Σ ω4 R ‖Δp‖ + ω5 (c_h ‖Δxy‖ +
    c_v |Δz|) (``"cost"``), R the risk of the segment's corridor cell (``model.risk``). With
    ``risk_budget`` (and ``model``) the track's Eq. 11 risk Σ R ‖Δp‖ may not exceed it; when no
    polyline of the corridor meets it (an end point lies in a risky cell, and the exact end point
    is farther from the corridor's exit than the cell centre the grid path starts from), the
    budget becomes the corridor's least risk plus the slack the budget gave above ``reference``
    (the initial track's risk; default: the budget itself, no slack). Both are second-order cone
    programs (cvxpy, Clarabel): every term is a norm with a weight ≥ 0.

    Returns the simplified polyline and, with a budget, ``{"risk_budget", "risk_bound_active"}``
    (plus ``"least_risk"`` when the budget could not be met).
    """
    path = np.asarray(path)
    info: dict = {}
    if len(path) < 2:
        return np.vstack([origin, destination]), info
    size = np.asarray(cell, dtype=float)
    step_in = np.diff(path, axis=0)  # move i -> i + 1
    dip = np.zeros(len(path), dtype=bool)
    dip[1:-1] = np.any((step_in[:-1] == -1) & (step_in[1:] == 1), axis=1)
    # the free points in track order, each with its box, and the cell of each segment
    face_lo, face_hi = corridor_boxes(path, cell)
    face_hi = face_hi - np.where(face_hi - face_lo > 0, FACE_MARGIN * size, 0.0)
    lows, highs, seg_cell = [], [], []
    for i in range(len(path)):
        if dip[i]:
            lows.append(path[i] * size)
            highs.append((path[i] + 1 - FACE_MARGIN) * size)
            seg_cell.append(i)
        if i < len(path) - 1:
            lows.append(face_lo[i])
            highs.append(face_hi[i])
        seg_cell.append(i)
    lo, hi = np.asarray(lows), np.asarray(highs)
    q = cp.Variable(lo.shape)
    pts = cp.vstack([np.asarray(origin, dtype=float)[None, :], q, np.asarray(destination, dtype=float)[None, :]])
    step = pts[1:] - pts[:-1]
    seg = cp.norm(step, 2, axis=1)
    box = [q >= lo, q <= hi]
    risk = model.risk[tuple(path[seg_cell].T)] if model is not None else None
    if objective == "length":
        goal = cp.sum(seg)
    elif objective == "cost":
        w4, w5 = model.scenario.tracks.weights
        goal = (w4 * risk @ seg + w5 * model.c_h * cp.sum(cp.norm(step[:, :2], 2, axis=1))
                + w5 * model.c_v * cp.sum(cp.abs(step[:, 2])))
    else:
        raise ValueError(f"objective must be 'length' or 'cost', got {objective!r}")
    ends = np.asarray(origin, dtype=float)[None, :], np.asarray(destination, dtype=float)[None, :]

    def carried() -> float:  # the risk of the solution, as the program charges it
        return float(risk @ np.linalg.norm(np.diff(np.vstack([ends[0], np.clip(q.value, lo, hi), ends[1]]), axis=0),
                                           axis=1))

    _solve(cp.Problem(cp.Minimize(goal), box), q, "equivalent-track")
    if risk_budget is not None and risk is not None and risk.any():
        budget = float(risk_budget)
        info = {"risk_budget": budget, "risk_bound_active": carried() > budget}
        if info["risk_bound_active"]:
            scale = float(risk.max())  # the bound in units of the riskiest cell: well scaled for any risk model
            reference = budget if reference is None else float(reference)
            bounded = cp.Problem(cp.Minimize(goal), [*box, risk / scale @ seg <= budget / scale])
            if _solve(bounded, q, "equivalent-track", infeasible_ok=True) is None:
                # no polyline of the corridor meets the budget: the same slack above the corridor's least risk
                least = scale * _solve(cp.Problem(cp.Minimize(risk / scale @ seg), box), q, "least-risk")
                budget = least + max(budget - reference, 1e-6 * least)
                info.update(risk_budget=budget, least_risk=least)
                _solve(cp.Problem(cp.Minimize(goal), [*box, risk / scale @ seg <= budget / scale]), q, "equivalent-track")
    track = simplify(np.vstack([ends[0], np.clip(q.value, lo, hi), ends[1]]), tol=1e-6)
    return track, info


def _solve(problem, q, what: str, infeasible_ok: bool = False) -> float | None:
    """Solve ``problem`` for ``q``; its optimal value, or None when infeasible and ``infeasible_ok``.

    An inaccurate solution is taken as it is, without cvxpy's warning: the track is clipped to
    its boxes and every stage's metrics are recomputed from its waypoints."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Solution may be inaccurate", category=UserWarning)
        # tight tolerances: straight runs come out straight, so collinear face points can be dropped
        problem.solve(solver=cp.CLARABEL, tol_gap_abs=1e-12, tol_gap_rel=1e-12, tol_feas=1e-12, tol_ktratio=1e-10)
    if infeasible_ok and problem.status in (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE):
        return None
    if q.value is None or problem.value is None:
        raise NoTrackError(f"the {what} program did not solve", "tracks.equivalent",
                           f"solver status {problem.status}; use tracks.equivalent = 'midpoint'")
    return float(problem.value)


def exact_equivalent_track(path: np.ndarray, cell, origin, destination, *, model: PlanningModel | None = None,
                           risk_budget: float | None = None) -> np.ndarray:
    """Shortest polyline from origin to destination through the corridor of ``path`` cells.

    One point q_i on the closed intersection of cells i−1 and i (and one inside each "dip" cell;
    :func:`corridor_program`); minimise the length — a second-order cone program (cvxpy, Clarabel).
    Each segment then lies in one corridor cell.

    With ``model`` given (variant ``tracks.equivalent = "exact_cost"``) the program minimises
    Eq. 10 instead: Σ ω4 R_i ‖Δp_i‖ + ω5 (c_h ‖Δxy_i‖ + c_v |Δz_i|), segment i in cell i with
    risk R_i. Still convex; its optimum is never worse than the midpoint rule's on Eq. 10. With
    ``risk_budget`` (and ``model``) the track's Eq. 11 risk is bounded (:func:`corridor_program`).
    """
    return corridor_program(path, cell, origin, destination, model=model, risk_budget=risk_budget,
                            objective="length" if model is None else "cost")[0]


def smoothing_mask(model: PlanningModel, corridor: np.ndarray) -> np.ndarray:
    """Where the smoothed track may fly: the corridor, and admissible cells that are safe (Eq. 9
    R = 0) and, when the safety buffer is on (μ > 0), outside every buffer shell (R(t) = 0 of
    Eq. 35). Cutting a corner through a risky cell or a buffer cell the corridor avoided would
    undo the planner's work, so that counts as a violation to repair."""
    mask = model.admissible & ~model.field.unsafe
    if model.scenario.tracks.buffer_penalty > 0:
        mask &= model.shell_count == 0
    mask[tuple(np.asarray(corridor).T)] = True
    return mask


def corner_fillets(points: np.ndarray, tangent: np.ndarray, samples: int = 8) -> np.ndarray:
    """Round every interior corner of a polyline with a cubic Bézier fillet.

    At vertex V with legs towards its neighbours, the fillet runs from A = V − t·u_in to
    B = V + t·u_out with control points A + ⅔(V − A) and B + ⅔(V − B) (the cubic form of the
    quadratic Bézier through A, V, B), sampled at ``samples`` points (the paper's "eight
    coordinate points" around each turn, Sec. 5.1). The fillet lies in the triangle A V B, so it
    is shorter than the corner it replaces, in length and in each of Eq. 12's horizontal and
    vertical parts. ``tangent`` holds t per interior vertex (0 keeps the corner).
    """
    pts = np.asarray(points, dtype=float)
    out = [pts[:1]]
    s = np.linspace(0.0, 1.0, samples)[:, None]
    for i in range(1, len(pts) - 1):
        v, t = pts[i], float(tangent[i - 1])
        if t <= 0:
            out.append(v[None, :])
            continue
        u_in = (v - pts[i - 1]) / np.linalg.norm(v - pts[i - 1])
        u_out = (pts[i + 1] - v) / np.linalg.norm(pts[i + 1] - v)
        a, b = v - t * u_in, v + t * u_out
        c1, c2 = a + (2.0 / 3.0) * (v - a), b + (2.0 / 3.0) * (v - b)
        out.append((1 - s) ** 3 * a + 3 * (1 - s) ** 2 * s * c1 + 3 * (1 - s) * s**2 * c2 + s**3 * b)
    out.append(pts[-1:])
    return np.vstack(out)


def segment_risk(model: PlanningModel, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Eq. 11 of each straight segment starts[k] → ends[k]: the line integral of R (as in
    :func:`track_metrics`, cell by cell)."""
    starts, ends = np.asarray(starts, dtype=float), np.asarray(ends, dtype=float)
    if len(starts) == 0:
        return np.zeros(0)
    size = np.asarray(model.field.grid.cell, dtype=float)
    owner, t0, t1 = split_segments(starts, ends, size)
    mid = starts[owner] + (0.5 * (t0 + t1))[:, None] * (ends[owner] - starts[owner])
    cells = np.clip(np.floor(mid / size).astype(np.int64), 0, np.asarray(model.risk.shape) - 1)
    length = np.linalg.norm(ends - starts, axis=1)
    return np.bincount(owner, weights=model.risk[tuple(cells.T)] * (t1 - t0) * length[owner], minlength=len(starts))


def smooth_track(model: PlanningModel, equivalent: np.ndarray, corridor: np.ndarray | None = None,
                 risk_budget: float | None = None) -> tuple[np.ndarray, dict]:
    """The optimal track: the equivalent track with its corners rounded (:func:`corner_fillets`).

    Each corner's tangent distance starts at min(``tracks.smoothing_m``, half of each leg) and is
    halved, corner by corner, while its fillet leaves the allowed cells (:func:`smoothing_mask`:
    the corridor and safe admissible cells, outside the Eq. 35 buffer shells when μ > 0; all
    admissible cells without a corridor), and, while the whole track's Eq. 11 risk exceeds
    ``risk_budget``, while its fillet carries more risk than the corner it replaces (a fillet
    through a risky corridor cell); after six halvings the corner stays sharp. The result is
    admissible by construction, never longer (nor costlier in Eq. 12) than the equivalent track,
    and within ``risk_budget`` whenever the equivalent track is.
    """
    cell = np.asarray(model.field.grid.cell)
    allowed = model.admissible if corridor is None else smoothing_mask(model, corridor)
    pts = np.asarray(equivalent, dtype=float)
    if len(pts) < 3:
        return pts, {"rounded_corners": 0, "sharp_corners": 0}
    legs = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    tangent = np.minimum(model.scenario.tracks.smoothing_m, 0.5 * np.minimum(legs[:-1], legs[1:]))
    samples = 8
    risk_shrunk = 0
    for attempt in range(7):
        track = corner_fillets(pts, tangent, samples)
        ok = polyline_in_mask(track, allowed, cell)
        # segments of corner i's fillet: the first point of the track is vertex 0, then blocks of samples
        bad_corner = np.zeros(len(tangent), dtype=bool)
        seg_owner = np.repeat(np.arange(len(tangent)), np.where(tangent > 0, samples, 1))
        seg_owner = np.concatenate([[-1], seg_owner])  # segment k ends at point k + 1
        owner_of_segment = np.maximum(seg_owner[1:], seg_owner[:-1])
        for k in np.flatnonzero(~ok):
            if owner_of_segment[k] >= 0:
                bad_corner[owner_of_segment[k]] = True
        bad_corner &= tangent > 0
        if risk_budget is not None and not bad_corner.any():
            adds = _fillets_adding_risk(model, pts, track, tangent, np.concatenate([seg_owner, [-1]]), samples)
            if adds.any() and segment_risk(model, track[:-1], track[1:]).sum() > risk_budget:
                bad_corner = adds
                risk_shrunk += int(adds.sum())
        if not bad_corner.any():
            break
        tangent = np.where(bad_corner, 0.0 if attempt >= 5 else 0.5 * tangent, tangent)
    track = corner_fillets(pts, tangent, samples)
    info = {"rounded_corners": int((tangent > 0).sum()), "sharp_corners": int((tangent <= 0).sum())}
    if risk_shrunk:
        info["fillets_shrunk_for_risk"] = risk_shrunk
    return simplify(track, tol=1e-9), info


def _fillets_adding_risk(model: PlanningModel, pts: np.ndarray, track: np.ndarray, tangent: np.ndarray,
                         point_owner: np.ndarray, samples: int) -> np.ndarray:
    """Rounded corners whose fillet (A → B through its samples) carries more Eq. 11 risk than the
    corner A → V → B it replaces."""
    inside = (point_owner[:-1] == point_owner[1:]) & (point_owner[:-1] >= 0)  # segments within a fillet
    along = segment_risk(model, track[:-1][inside], track[1:][inside])
    fillet = np.bincount(point_owner[:-1][inside], weights=along, minlength=len(tangent))
    rounded = np.flatnonzero(tangent > 0)
    block = np.where(tangent > 0, samples, 1)  # points of each corner in the track, after its first point
    first = 1 + np.concatenate([[0], np.cumsum(block)[:-1]])[rounded]  # A: the first sample of each rounded corner
    a, b, v = track[first], track[first + samples - 1], pts[rounded + 1]
    corner = np.zeros(len(tangent))
    corner[rounded] = segment_risk(model, a, v) + segment_risk(model, v, b)
    scale = max(float(model.risk.max()), 1e-300) * float(np.min(model.field.grid.cell))
    return (tangent > 0) & (fillet > corner + 1e-9 * scale)


@dataclass(frozen=True)
class TrackPlan:
    """All stages of one origin-destination plan, in Table 2 order."""

    origin: tuple[float, float, float]
    destination: tuple[float, float, float]
    stages: dict[str, TrackStage]
    midpoint: TrackStage | None = None
    warmup_seconds: float = 0.0  # compiling the search before the first stage (not in any stage's time)

    def to_frame(self):
        """One row per stage (Table 2): risk_cost C_R, transport_cost C_T, objective, buffer_cost,
        length_m, n_waypoints, seconds (pandas DataFrame indexed by stage)."""
        import pandas as pd

        rows = [{"stage": name, "risk_cost": s.risk_cost, "transport_cost": s.transport_cost,
                 "objective": s.objective, "buffer_cost": s.buffer_cost, "length_m": s.length_m,
                 "n_waypoints": s.n_waypoints, "seconds": s.seconds} for name, s in self.stages.items()]
        return pd.DataFrame(rows).set_index("stage")

    @classmethod
    def from_dict(cls, doc: dict) -> TrackPlan:
        """The plan of a ``tracks.json`` document (:meth:`as_dict`)."""
        def stage(name: str, d: dict) -> TrackStage:
            core = {"waypoints", "risk_cost", "transport_cost", "objective", "buffer_cost", "n_waypoints",
                    "length_m", "seconds"}
            return TrackStage(name=name, waypoints=np.asarray(d["waypoints"], dtype=float), risk_cost=float(d["risk_cost"]),
                              transport_cost=float(d["transport_cost"]), objective=float(d["objective"]),
                              buffer_cost=float(d.get("buffer_cost", 0.0)), length_m=float(d["length_m"]),
                              seconds=float(d["seconds"]), extra={k: v for k, v in d.items() if k not in core})

        mid = doc.get("equivalent_midpoint_rule")
        return cls(tuple(map(float, doc["origin"])), tuple(map(float, doc["destination"])),  # type: ignore[arg-type]
                   {name: stage(name, d) for name, d in doc["stages"].items()},
                   midpoint=stage("equivalent", mid) if mid else None,
                   warmup_seconds=float(doc.get("warmup_seconds", 0.0)))

    def as_dict(self) -> dict:
        out = {"stages": {k: v.as_dict() for k, v in self.stages.items()},
               "origin": list(self.origin), "destination": list(self.destination),
               "warmup_seconds": self.warmup_seconds}
        if self.midpoint is not None:
            out["equivalent_midpoint_rule"] = self.midpoint.as_dict()
        return out


def plan_track(model: PlanningModel, origin, destination, *, backend: str | None = None,
               heuristic: str | None = None, scale_check: bool = True) -> TrackPlan:
    """Plan all four stages from ``origin`` to ``destination``: (x, y, z) in metres, vertiport
    names (at the cruise altitude) or :class:`~uamopt.planning.endpoints.Endpoint`.

    The equivalent and optimal tracks carry at most (1 + ``tracks.risk_tolerance``) times the
    initial track's Eq. 11 risk (the ``exact`` and ``exact_cost`` programs bound it; smoothing
    keeps within it). With ``scale_check`` a :class:`TrackWeightsWarning` says when ω4·C_R and
    ω5·C_T of the shortest track differ by more than :data:`SCALE_WARNING_RATIO`.

    Raises
    ------
    UamoptError
        Origin or destination outside the grid or band, inside a building, no-fly zone or the
        clearance margin; the track longer than the range L_e (Eq. 17).
    NoTrackError
        No admissible track joins them, or they lie in the same cell.
    """
    cfg = model.scenario.tracks
    backend = backend or cfg.search
    heuristic = heuristic or cfg.heuristic
    o, d = as_endpoint(model.scenario, origin, "origin"), as_endpoint(model.scenario, destination, "destination")
    origin, destination = np.asarray(o.point, dtype=float), np.asarray(d.point, dtype=float)
    start, goal = endpoint_cell(model, origin, "origin", o.where), endpoint_cell(model, destination, "destination", d.where)
    if start == goal:  # a track needs two cells: the four stages of Fig. 18 start from a path of cells
        raise NoTrackError(f"origin {o.label} and destination {d.label} lie in the same cell {start}",
                           f"{o.where} / {d.where}", f"choose end points at least one cell apart (grid.cell = "
                           f"{', '.join(f'{c:g}' for c in model.field.grid.cell)} m)")
    cell = model.field.grid.cell
    stages: dict[str, TrackStage] = {}
    paths: dict[str, np.ndarray] = {}
    warmup_s = warm_up(backend)  # compiling the search is not the shortest stage's time
    for name in ("shortest", "initial"):
        result = grid_search(model.search_problem(name), start, goal, backend=backend, heuristic=heuristic)
        paths[name] = result.path
        stages[name] = _stage(model, name, _grid_waypoints(model, result.path), result.seconds,
                              search_cost=result.cost, expansions=result.expansions, cells=len(result.path))
    if scale_check:
        message = weight_scale_message(model, stages["shortest"])
        if message:
            warnings.warn(message, TrackWeightsWarning, stacklevel=2)
    path = paths["initial"]
    # the later stages may not give back the risk the initial track saved (docs/readings.md)
    budget = (1.0 + cfg.risk_tolerance) * stages["initial"].risk_cost
    t0 = time.perf_counter()
    midpoint = _stage(model, "equivalent", midpoint_track(path, cell, origin, destination), 0.0, rule="midpoint")
    t_mid = time.perf_counter() - t0
    t0 = time.perf_counter()
    if cfg.equivalent in ("exact", "exact_cost"):
        equivalent, bound = corridor_program(path, cell, origin, destination, model=model, risk_budget=budget,
                                             reference=stages["initial"].risk_cost,
                                             objective="length" if cfg.equivalent == "exact" else "cost")
        rule = "exact shortest (SOCP)" if cfg.equivalent == "exact" else "exact Eq. 10 (SOCP)"
        stages["equivalent"] = _stage(model, "equivalent", equivalent, time.perf_counter() - t0, rule=rule, **bound)
    else:
        stages["equivalent"] = TrackStage(**{**midpoint.__dict__, "seconds": t_mid})
    t0 = time.perf_counter()
    smoothed, info = smooth_track(model, stages["equivalent"].waypoints, corridor=path,
                                  risk_budget=max(budget, stages["equivalent"].risk_cost))
    stages["optimal"] = _stage(model, "optimal", smoothed, time.perf_counter() - t0, **info)
    limit = model.scenario.aircraft.range_m
    if stages["optimal"].length_m > limit:
        raise UamoptError(f"the track is {stages['optimal'].length_m:.0f} m long, beyond the range L_e = {limit:g} m (Eq. 17)",
                          "aircraft.range_m", "choose closer points or an aircraft with a longer range")
    return TrackPlan(tuple(map(float, origin)), tuple(map(float, destination)), stages,
                     midpoint=TrackStage(**{**midpoint.__dict__, "seconds": t_mid}), warmup_seconds=warmup_s)
