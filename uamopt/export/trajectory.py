"""The flyable trajectory nearest to a flight's plan: what the BlueSky export commands.

The plan flies the track's polyline at the constant speed v_g (Eq. 31: the occupancy's timing)
and turns instantly at every waypoint. No aircraft can: at bank φ it turns on a radius
v²/(g tan φ) (64 m at 25 m/s and 45°), so BlueSky, handed the waypoints, cuts every corner
tighter than that and, flying the shorter path at v_g, gets ahead of the plan for the rest of the
flight (docs/export.md). The export therefore designs, once per track, the trajectory a(t)
at nodes t_0 = 0 < t_1 < … < t_n = T that stays nearest to the plan p(t) *at the same time* while
never asking for more acceleration than the aircraft can pull:

    minimise   e + (λ/(n+1)) Σ_k |a_k − p(t_k)|²
    subject to |a_k − p(t_k)| ≤ e                          every node t_k
               |a(τ_j) − p(τ_j)| ≤ e                       every waypoint time τ_j of the plan
               |v_k − v_{k−1}| ≤ η·g·tan φ·(h_{k−1} + h_k)/2   every interior node, with
                         h_k = t_{k+1} − t_k and v_k = (a_{k+1} − a_k)/h_k
               a_0 = p(0),  a_n = p(T)

in the horizontal plane (a second-order cone program, solved exactly by Clarabel through cvxpy).
The nodes lie every h seconds, plus the plan's changes of climb gradient; z is the plan's at
every node, so the designed z profile is the plan's and BlueSky's VNAV flies it leg by leg.
Between breakpoints both a(t) and p(t) are linear in t, so |a − p| is convex there and its
largest value lies at a node or at a waypoint time: ``max_error_m`` = e is the exact largest
distance between the designed polyline and the plan at equal times. The velocity change per
node bounds the acceleration (lateral and along-track together) by η·g·tan φ; η = 0.9 leaves a
tenth of the bank's lateral acceleration to BlueSky's own fly-by guidance between the nodes. The
trajectory leaves from the plan's first point at the departure (BlueSky creates the aircraft
there already moving, along the first designed leg: the plan's own velocity at that instant is no
constraint, so a corner soon after the departure can be prepared from the start) and arrives at
the destination at the planned time; on the way it may speed up or slow down
(``speed_range_mps``) to stay on time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uamopt.errors import UamoptError

G_MPS2 = 9.80665
DESIGN_STEP_S = 0.25  # h: node spacing, s (6.25 m at 25 m/s; BlueSky follows 0.5 s nodes ~1 m less closely)
ACCEL_SHARE = 0.9  # η: share of the bank's lateral acceleration the design may use
SMOOTHING_WEIGHT = 1e-3  # λ, 1/m: among minimax trajectories, the one nearest to the plan on average
STRAIGHT_TOL_MPS = 4e-4  # a node where the velocity changes by less than this, m/s, is dropped
GRADE_CHANGE = 1e-3  # a plan corner where dz/ds changes by more than this is also a node


@dataclass(frozen=True)
class Trajectory:
    """A time-stamped polyline: ``times_s`` (n,) from the departure, ``points`` (n, 3) in the local frame, m."""

    times_s: np.ndarray
    points: np.ndarray
    max_error_m: float  # e: largest distance to the plan at equal times (0 for the plan itself)

    @property
    def speed_range_mps(self) -> tuple[float, float]:
        """Slowest and fastest horizontal speed over the legs, m/s."""
        speed = np.linalg.norm(np.diff(self.points[:, :2], axis=0), axis=1) / np.diff(self.times_s)
        return float(speed.min()), float(speed.max())

    def rest_from(self, t_s: float) -> Trajectory:
        """The trajectory from ``t_s`` on: the point reached then, then the later nodes (times unchanged)."""
        if t_s <= self.times_s[0]:
            return self
        t_s = min(t_s, float(self.times_s[-1]))
        start = np.array([np.interp(t_s, self.times_s, self.points[:, k]) for k in range(3)])
        later = self.times_s > t_s + 1e-9
        times, points = self.times_s[later], self.points[later]
        if len(times) > 1 and np.linalg.norm(points[0] - start) < 1e-6:
            times, points = times[1:], points[1:]  # the time falls on a node: do not repeat it
        return Trajectory(np.concatenate([[t_s], times]), np.vstack([start, points]), self.max_error_m)


def plan_trajectory(waypoints: np.ndarray, speed_mps: float) -> Trajectory:
    """The plan itself (Eq. 31): the waypoints at the times v_g reaches them; repeated points dropped."""
    wp = np.asarray(waypoints, float)
    wp = wp[np.concatenate([[True], np.linalg.norm(np.diff(wp, axis=0), axis=1) > 1e-6])]
    times = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(wp, axis=0), axis=1))]) / speed_mps
    return Trajectory(times, wp, 0.0)


def _plan_at(plan: Trajectory, t: np.ndarray) -> np.ndarray:
    return np.column_stack([np.interp(t, plan.times_s, plan.points[:, k]) for k in range(3)])


def _nodes(plan: Trajectory, step_s: float) -> np.ndarray:
    """Node times: every ``step_s`` from 0 to T, and the plan's changes of climb gradient (so that
    z, the plan's at every node, breaks exactly where the plan's does); a regular node closer
    than half a step to one of those gives way to it."""
    total = float(plan.times_s[-1])
    regular = np.linspace(0.0, total, max(2, int(np.ceil(total / step_s - 1e-9))) + 1)
    legs = np.diff(plan.points, axis=0)
    grade = legs[:, 2] / np.maximum(np.linalg.norm(legs[:, :2], axis=1), 1e-9)
    slope = plan.times_s[1:-1][np.abs(np.diff(grade)) > GRADE_CHANGE]
    if not len(slope):
        return regular
    near = np.abs(regular[:, None] - slope[None, :]).min(axis=1) < 0.5 * step_s
    near[[0, -1]] = False
    return np.union1d(regular[~near], slope)


def flyable_trajectory(waypoints: np.ndarray, speed_mps: float, bank_deg: float, *,
                       step_s: float = DESIGN_STEP_S, accel_share: float = ACCEL_SHARE) -> Trajectory:
    """The trajectory nearest to the plan within the acceleration η·g·tan φ (module docstring).

    Parameters
    ----------
    waypoints : (m, 3) array
        The track, m (local frame).
    speed_mps : float
        v_g, m/s (Eq. 31).
    bank_deg : float
        φ, the aircraft's bank limit, degrees (0 < φ < 90).
    step_s, accel_share : float
        h, the node spacing, s, and η.

    Returns
    -------
    Trajectory
        Nodes every h seconds from the departure and at the plan's changes of gradient (nodes
        on straight runs flown at constant velocity dropped) and e, the exact largest distance
        to the plan at equal times.

    Raises
    ------
    UamoptError
        The cone program does not solve (it is always feasible: a stop-free plan is within reach).

    Examples
    --------
    >>> straight = flyable_trajectory([[0, 0, 120], [500, 0, 120]], 25.0, 45.0)
    >>> straight.points[:, 0].tolist(), straight.times_s.tolist(), round(straight.max_error_m, 6)
    ([0.0, 500.0], [0.0, 20.0], 0.0)
    """
    import cvxpy as cp
    import scipy.sparse as sp

    plan = plan_trajectory(waypoints, speed_mps)
    t = _nodes(plan, step_s)
    n, span = len(t) - 1, np.diff(t)
    target = _plan_at(plan, t)
    p = target[:, :2]
    tau = plan.times_s[1:-1]  # the plan's corners: breakpoints of p(t)
    k = np.clip(np.searchsorted(t, tau, side="right") - 1, 0, n - 1)
    w = (tau - t[k]) / span[k]
    rows = np.arange(len(tau))
    at_tau = sp.csr_matrix((np.concatenate([1 - w, w]), (np.concatenate([rows, rows]), np.concatenate([k, k + 1]))),
                           shape=(len(tau), n + 1))
    velocity = sp.diags(1.0 / span) @ sp.diags([-np.ones(n), np.ones(n)], [0, 1], shape=(n, n + 1))
    change = sp.diags([-np.ones(n - 1), np.ones(n - 1)], [0, 1], shape=(n - 1, n)) @ velocity
    a, e = cp.Variable((n + 1, 2)), cp.Variable()
    accel = accel_share * G_MPS2 * np.tan(np.radians(bank_deg))
    constraints = [a[0] == p[0], a[n] == p[n],
                   cp.norm(a - p, axis=1) <= e, cp.norm(change @ a, axis=1) <= accel * 0.5 * (span[:-1] + span[1:])]
    if len(tau):
        constraints.append(cp.norm(at_tau @ a - plan.points[1:-1, :2], axis=1) <= e)
    problem = cp.Problem(cp.Minimize(e + SMOOTHING_WEIGHT / (n + 1) * cp.sum_squares(a - p)), constraints)
    problem.solve(solver=cp.CLARABEL)
    if a.value is None or problem.status not in ("optimal", "optimal_inaccurate"):
        raise UamoptError(f"the flyable trajectory did not solve (status {problem.status})", "export bluesky",
                          "replay the track's own waypoints: --trajectory waypoints")
    points = np.column_stack([a.value, target[:, 2]])
    points[[0, -1]] = target[[0, -1]]
    bend = np.linalg.norm(np.diff(np.diff(points, axis=0) / span[:, None], axis=0), axis=1)
    keep = np.concatenate([[True], bend > STRAIGHT_TOL_MPS, [True]])
    # the exact largest distance of the kept polyline (nodes and plan corners), not the solver's e
    flown = Trajectory(t[keep], points[keep], 0.0)
    when = np.concatenate([t, plan.times_s])
    error = float(np.linalg.norm((_plan_at(flown, when) - _plan_at(plan, when))[:, :2], axis=1).max())
    return Trajectory(t[keep], points[keep], error)
