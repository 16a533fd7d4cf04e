"""Hypothesis strategies shared by the solver tests: tiny scheduling instances."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from uamopt.schedule import Flight, FlightSet, build_problem


@st.composite
def tiny_problems(draw, max_flights: int = 6):
    """(lattice, problem): 2..max_flights flights of 1..3 aircraft on short crossing tracks in a
    60 × 60 m box.

    ``lattice`` instances put every time on a 0.5 s grid (axis-parallel tracks through whole
    5 m points at 5 or 10 m/s, integer departures, gaps and delay bounds), where CP-SAT is exact.
    """
    lattice = draw(st.booleans())
    n_aircraft = draw(st.sampled_from([2, 3, 2, 3, 1]))  # one aircraft (no conflicts) in a fifth
    counts = [draw(st.integers(1, 3)) for _ in range(n_aircraft)]
    while sum(counts) > max_flights:
        counts[counts.index(max(counts))] -= 1
    if sum(counts) < 2:
        counts[0] += 1
    num = (lambda lo, hi: st.integers(lo, hi).map(float)) if lattice else (
        lambda lo, hi: st.floats(lo, hi, allow_nan=False, allow_infinity=False))
    gaps = (draw(num(0, 6)), draw(num(0, 8)))  # T_D, T_R, s
    flights = []
    for g, count in enumerate(counts):
        departure = draw(num(0, 10))
        for leg in range(count):
            # every track runs from one side of the box to the other, so tracks cross near the middle
            if lattice:
                axis, fixed, z = draw(st.integers(0, 1)), 5.0 * draw(st.integers(4, 8)), 5.0 * draw(st.integers(0, 2))
                a, b = 5.0 * draw(st.integers(0, 5)), 5.0 * draw(st.integers(7, 12))
                a, b = (b, a) if draw(st.booleans()) else (a, b)
                ends = [[a, fixed, z], [b, fixed, z]] if axis == 0 else [[fixed, a, z], [fixed, b, z]]
                speed = draw(st.sampled_from([5.0, 10.0]))
            else:
                start = [draw(num(0, 60)), draw(num(0, 60)), draw(num(0, 15))]
                # the far end near the mirror point, kept in the local frame (x, y ≥ 0, as the verifier requires)
                ends = [start, [max(0.0, 60.0 - start[0] + draw(num(-10, 10))), max(0.0, 60.0 - start[1] + draw(num(-10, 10))),
                                draw(num(0, 15))]]
                speed = draw(num(4, 12))
            waypoints = np.array(ends)
            if np.linalg.norm(waypoints[1] - waypoints[0]) < 1.0:
                waypoints[1, 0] = waypoints[0, 0] + (5.0 if waypoints[0, 0] < 30 else -5.0)
            flight = Flight(id=f"F{len(flights)}", aircraft=f"A{g}", route=f"R{len(flights)}", origin="O", destination="D",
                            speed_mps=speed, planned_departure_s=departure, max_delay_s=draw(num(0, 20)), waypoints=waypoints)
            flights.append(flight)
            departure = departure + flight.flight_time_s + gaps[leg % 2] + draw(num(0, 5))
    last = max(f.planned_arrival_s for f in flights)
    service_end = draw(st.sampled_from([1000.0, float(np.ceil(last)) + draw(num(0, 10))]))
    fs = FlightSet(cell=(10.0, 10.0, 10.0), conflict_radius=draw(st.integers(0, 1)), flights=tuple(flights),
                   service_end_s=service_end, outbound_gap_s=gaps[0], return_gap_s=gaps[1])
    weights = draw(st.sampled_from([(0.6, 0.4), (0.9, 0.1), (0.1, 0.9), (0.5, 0.05)]))
    objective = draw(st.sampled_from(["weighted", "weighted", "lexicographic"]))
    return lattice, build_problem(fs, weights=weights, objective=objective)
