"""Multi-aircraft scheduling (Sec. 4.3, 5.2): the model as data, for any solver.

Data flow::

    network = straight_network(scenario, grid)          # or planned tracks, route -> waypoints
    flights = generate_plan(scenario, network, seed=0)  # or load_flights("flights.json", scenario, grid)
    problem = build_problem(flights, scenario)          # pair conflicts: forbidden departure gaps
    schedule = some_solver(problem)                     # -> Schedule (make_schedule)
    write_schedule("out/x", problem, schedule)          # flights.json, schedule.csv, summary.json
    assert verify_dir("out/x") == []                    # independent check

The verifier (``uamopt.schedule.verify``) is imported on its own, not from here, so that it stays
independent of the model.
"""

from uamopt.schedule.flights import Flight, FlightSet
from uamopt.schedule.flights_file import check_flightset, load_flights, save_flights
from uamopt.schedule.model import (
    Schedule,
    SchedulingProblem,
    build_problem,
    evaluate,
    make_schedule,
    violations,
    write_schedule,
)
from uamopt.schedule.occupancy import (
    ConflictTable,
    Occupancy,
    PairConflict,
    conflict_table,
    flight_occupancies,
    forbidden_gaps,
    track_occupancy,
)
from uamopt.schedule.plan import (
    flights_per_aircraft,
    generate_plan,
    grid_vertiports,
    route_name,
    straight_network,
)

__all__ = [
    "ConflictTable",
    "Flight",
    "FlightSet",
    "Occupancy",
    "PairConflict",
    "Schedule",
    "SchedulingProblem",
    "build_problem",
    "check_flightset",
    "conflict_table",
    "evaluate",
    "flight_occupancies",
    "flights_per_aircraft",
    "forbidden_gaps",
    "generate_plan",
    "grid_vertiports",
    "load_flights",
    "make_schedule",
    "route_name",
    "save_flights",
    "straight_network",
    "track_occupancy",
    "violations",
    "write_schedule",
]
