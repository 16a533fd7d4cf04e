"""Small scheduling instances with hand-checked answers, shared by the solver tests."""

from __future__ import annotations

import numpy as np

from uamopt.schedule import Flight, FlightSet, build_problem

# Greedy is known to be suboptimal here (hand-checked, 50 m cells, r = 1, 25 m/s): A1 flies east
# along y = 275 m from x = 25 to 525 m (20 s) at t = 0; C1 (t = 0) and B1 (t = 10 s) fly north
# across it at x = 275 m and x = 475 m, 200 m apart (they never meet), and may not wait (Δd = 0).
# A1 and C1 share the conflict zone when dep_C − dep_A ∈ (−4, 8) s, A1 and B1 when
# dep_B − dep_A ∈ (4, 15) s. The preliminary strategy places A1 first (earliest, then lowest
# index) on time, so B1 and C1 cannot fit and are cancelled: S = 1. Delaying A1 by d ≥ 6 s lets all
# three fly; on the ΔT_a = 10 s grid of the GA's chromosome that is d = 10 s.
CROSS_A = np.array([[25.0, 275.0, 45.0], [525.0, 275.0, 45.0]])
CROSS_C = np.array([[275.0, 75.0, 45.0], [275.0, 475.0, 45.0]])
CROSS_B = np.array([[475.0, 75.0, 45.0], [475.0, 475.0, 45.0]])


def crossing_problem(objective: str, weights: tuple[float, float]):
    def flight(fid, track, dep, max_delay):
        return Flight(id=fid, aircraft=fid[0], route=fid, origin="a", destination="b", speed_mps=25.0,
                      planned_departure_s=dep, max_delay_s=max_delay, waypoints=track)

    flights = (flight("A1", CROSS_A, 0.0, 400.0), flight("C1", CROSS_C, 0.0, 0.0), flight("B1", CROSS_B, 10.0, 0.0))
    return build_problem(FlightSet(cell=(50.0, 50.0, 30.0), conflict_radius=1, flights=flights),
                         weights=weights, objective=objective)
