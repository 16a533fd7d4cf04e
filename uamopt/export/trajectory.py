"""The flyable trajectory nearest to a flight's plan: what the BlueSky export commands.

The plan flies the track's polyline at the constant speed v_g (Eq. 31: the occupancy's timing)
and turns instantly at every waypoint. No aircraft can: at bank φ it turns on a radius
v²/(g tan φ) (64 m at 25 m/s and 45°), so BlueSky, handed the waypoints, cuts every corner
tighter than that and, flying the shorter path at v_g, gets ahead of the plan for the rest of the
flight (docs/export.md). The export therefore designs, once per track, the trajectory a(t)
sampled every h seconds that stays nearest to the plan p(t) *at the same time* while never asking
for more acceleration than the aircraft can pull:

    minimise   e + (λ/(n+1)) Σ_k |a_k − p(t_k)|²
    subject to |a_k − p(t_k)| ≤ e                          every node t_k = k·h, k = 0 … n
               |a(τ_j) − p(τ_j)| ≤ e                       every waypoint time τ_j of the plan
               |a_{k+1} − 2a_k + a_{k−1}| ≤ η·g·tan φ·h²   every interior node
               a_0 = p(0),  a_1 − a_0 = p(t_1) − p(0),  a_n = p(T)

in the horizontal plane (a second-order cone program, solved exactly by Clarabel through cvxpy);
z is the plan's at every node, which BlueSky's VNAV flies leg by leg. Between breakpoints both
a(t) and p(t) are linear in t, so |a − p| is convex there and its largest value lies at a node or
at a waypoint time: ``max_error_m`` = e is the exact largest distance between the designed
polyline and the plan at equal times. The second difference is the velocity change over one node,
so the acceleration (lateral and along-track together) stays ≤ η·g·tan φ; η = 0.9 leaves a tenth
of the bank's lateral acceleration to BlueSky's own fly-by guidance between the nodes. The
trajectory leaves on the plan at the plan's velocity and arrives at the destination at the
planned time; on the way it may speed up or slow down (``speed_range_mps``) to stay on time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uamopt.errors import UamoptError

G_MPS2 = 9.80665
DESIGN_STEP_S = 0.25  # h: node spacing, s (6.25 m at 25 m/s; BlueSky follows 0.5 s nodes ~1 m less closely)
ACCEL_SHARE = 0.9  # η: share of the bank's lateral acceleration the design may use
SMOOTHING_WEIGHT = 1e-3  # λ, 1/m: among minimax trajectories, the one nearest to the plan on average
STRAIGHT_TOL_M = 1e-3  # a node whose velocity does not change (|Δ²a| below this) is dropped


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
        Nodes every h seconds from the departure (nodes on straight runs flown at constant
        velocity dropped) and e, the exact largest distance to the plan at equal times.

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
    total = float(plan.times_s[-1])
    n = max(2, int(np.ceil(total / step_s - 1e-9)))
    h = total / n
    t = np.linspace(0.0, total, n + 1)
    target = _plan_at(plan, t)
    p = target[:, :2]
    tau = plan.times_s[1:-1]  # the plan's corners: breakpoints of p(t)
    k = np.minimum((tau / h).astype(int), n - 1)
    w = tau / h - k
    rows = np.arange(len(tau))
    at_tau = sp.csr_matrix((np.concatenate([1 - w, w]), (np.concatenate([rows, rows]), np.concatenate([k, k + 1]))),
                           shape=(len(tau), n + 1))
    second = sp.diags([np.ones(n - 1), -2 * np.ones(n - 1), np.ones(n - 1)], [0, 1, 2], shape=(n - 1, n + 1))
    a, e = cp.Variable((n + 1, 2)), cp.Variable()
    accel = accel_share * G_MPS2 * np.tan(np.radians(bank_deg))
    constraints = [a[0] == p[0], a[1] - a[0] == p[1] - p[0], a[n] == p[n],
                   cp.norm(a - p, axis=1) <= e, cp.norm(second @ a, axis=1) <= accel * h * h]
    if len(tau):
        constraints.append(cp.norm(at_tau @ a - plan.points[1:-1, :2], axis=1) <= e)
    problem = cp.Problem(cp.Minimize(e + SMOOTHING_WEIGHT / (n + 1) * cp.sum_squares(a - p)), constraints)
    problem.solve(solver=cp.CLARABEL)
    if a.value is None or problem.status not in ("optimal", "optimal_inaccurate"):
        raise UamoptError(f"the flyable trajectory did not solve (status {problem.status})", "export bluesky",
                          "replay the track's own waypoints: --trajectory waypoints")
    points = np.column_stack([a.value, target[:, 2]])
    points[[0, -1]] = target[[0, -1]]
    bend = np.linalg.norm(points[2:] - 2 * points[1:-1] + points[:-2], axis=1)
    keep = np.concatenate([[True], bend > STRAIGHT_TOL_M, [True]])
    # the exact largest distance of the kept polyline (nodes and plan corners), not the solver's e
    flown = Trajectory(t[keep], points[keep], 0.0)
    when = np.concatenate([t, plan.times_s])
    error = float(np.linalg.norm((_plan_at(flown, when) - _plan_at(plan, when))[:, :2], axis=1).max())
    return Trajectory(t[keep], points[keep], error)
