"""The paper-case flight plan calibrated so that the preliminary strategy behaves like the paper's.

Sec. 6.2 reports for the initial plan of 120 flights (20 eVTOLs, 10 routes) after the preliminary
strategy (Sec. 5.2.1): 109 operated, 11 cancelled, total delay 2401 s (Table 3). The paper does not
publish its plan, so ours is generated (:func:`uamopt.schedule.generate_plan`) and calibrated.

Finding (greedy solver, ΔT_a = 10 s steps, straight network with the return direction one cell
layer up, i.e. inside the r = 1 conflict zone, as the calibration was made; 32 seeds): with the generator
alone no setting comes near. Eq. 29 taken with equality gives Δd = round(L/v_g) + ΔT = 317-517 s,
so a flight is almost never pushed past its threshold, and Eq. 27 taken with equality leaves no
slack between an aircraft's flights, so every conflict delay is carried by all its later flights.
Over first-departure windows 0-1112 s (the widest that fits T_f = 3600 s), departure grids of
1, 10 and 60 s and service windows of 2600-3600 s, the median greedy result is 0-4 cancellations
and 4000-9500 s of total delay (window 600 s, 1 s grid: median 1 cancelled, 5810 s; 80 of 120
flights delayed). Concentrating traffic (a narrower window) adds delay, not cancellations: with
window 0 every seed gives 0 cancelled, 9470 s. Cancellations appear only where the service end
(Eq. 26) binds, at the end of a wide window.

What the plan needs is a tighter delay threshold. Eq. 29 is an upper bound (Δd ≤ round(L/v_g) +
ΔT), so Δd = 0.3 × that bound (95-155 s) is within the paper's model. With it and the generator's
default 600 s window on a 10 s (ΔT_a) grid, the greedy strategy gives over seeds 0-31 a median of
12 cancelled (quartiles 10-15) and 2415 s of total delay (quartiles 1945-2633 s), mean 12.7 and
2305 s, against the paper's 11 and 2401 s. Seed 0 gives 104 operated, 16 cancelled, 2260 s
(56 flights delayed; the paper has 20: our chains carry delays, see above). Other settings near
the target: scale 0.3 with an 800 s window (median 13 / 2340 s), scale 0.32 with 800 s (11.5 /
2500 s). Still unmatched: the paper's largest delay, 226 s (Table 3), exceeds these Δd.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from uamopt.schedule.flights import FlightSet
from uamopt.schedule.plan import generate_plan

if TYPE_CHECKING:
    from uamopt.scenario import Scenario

MAX_DELAY_SCALE = 0.3  # Δd = 0.3 × (round(L/v_g) + ΔT), Eq. 29 as an inequality
FIRST_DEPARTURE_WINDOW_S = 600.0  # generate_plan's default window, s
DEPARTURE_STEP_S = 10.0  # first departures on the ΔT_a grid (Table B.3), s


def paper_case_plan(
    scenario: Scenario,
    network: Mapping[str, np.ndarray],
    seed: int = 0,
    *,
    max_delay_scale: float = MAX_DELAY_SCALE,
    first_departure_window_s: float = FIRST_DEPARTURE_WINDOW_S,
    departure_step_s: float = DEPARTURE_STEP_S,
) -> FlightSet:
    """The calibrated initial plan of Sec. 6.2 (see the module docstring) whatever the scenario's
    ``[schedule]`` knobs say: ``models/paper_case.toml`` sets the same values, so there
    :func:`~uamopt.schedule.generate_plan` gives this plan.

    Parameters
    ----------
    scenario, network
        As for :func:`~uamopt.schedule.generate_plan`.
    seed : int
        Seeds the first departures.
    max_delay_scale : float
        Δd_f = round_half_up(scale × (round(L/v_g) + ΔT)) s (Eq. 29 allows any Δd up to the bound).
    first_departure_window_s, departure_step_s : float
        Passed to ``generate_plan``, s.

    Examples
    --------
    The calibration figures (the paper's Table 3 has 109, 11 and 2401 s on its own plan), on the
    straight network the calibration used (return direction one layer up):

    >>> from pathlib import Path
    >>> import uamopt
    >>> from uamopt.grid import AirspaceGrid
    >>> from uamopt.scenario import load_scenario
    >>> from uamopt.schedule import build_problem, straight_network
    >>> from uamopt.solvers import solve
    >>> scenario = load_scenario(Path(uamopt.__file__).parents[1] / "models" / "paper_case.toml")
    >>> grid = AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent)
    >>> plan = paper_case_plan(scenario, straight_network(scenario, grid, layer_offset_cells=1))
    >>> greedy = solve(build_problem(plan, scenario), "greedy")
    >>> greedy.operated_count, greedy.cancelled_count, greedy.total_delay_s
    (104, 16, 2260.0)

    Raises
    ------
    UamoptError
        ``max_delay_scale`` outside (0, 1] (above 1 would break Eq. 29).
    """
    return generate_plan(scenario, network, seed, max_delay_scale=max_delay_scale,
                         first_departure_window_s=first_departure_window_s, departure_step_s=departure_step_s)
