"""The OR-Library aircraft-landing problem (Beasley, Krishnamoorthy, Sharaiha and Abramson,
"Scheduling aircraft landings — the static case", Transportation Science 34(2), 2000) as a
:class:`~uamopt.schedule.SchedulingProblem`: a published benchmark with known optima, solved by
the same solvers through the same families as the paper's model.

File format (whitespace-separated numbers): ``P freeze_time``, then per aircraft i
``appearance E_i T_i L_i g_i h_i`` and P separations S_i1 … S_iP (S_ij: the time that must pass
after i lands before j lands, if i lands first).

Mapping (one runway, the static problem):

- aircraft i is flight ``a<i>`` of its own aircraft (no turnaround rows, no precedence); its
  *departure* in our model is its landing time x_i, with planned departure D_i = E_i and delay
  bound L_i − E_i (the ``delay_bounds`` family: the time window [E_i, L_i]);
- every pair i < j: x_j − x_i ≥ S_ij or x_i − x_j ≥ S_ji, i.e. δ = x_j − x_i avoids the open
  interval (−S_ji, S_ij) — a ``pairs`` family named ``separation`` over *every* pair (the matrix
  need not satisfy the triangle inequality, so consecutive pairs are not enough);
- every aircraft lands (``must_operate`` everywhere);
- objective ``earliness_tardiness``: Σ_i g_i (T_i − x_i)⁺ + h_i (x_i − T_i)⁺, i.e. target delay
  a_i = T_i − E_i, early cost g_i and late cost h_i per time unit (the files' unit; read as seconds).

``summary.json`` of a written schedule names the file (``instance_file``), and ``uamopt verify``
checks the landing times against the file itself with its own parser (uamopt/schedule/verify.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from uamopt.checks import expect_path
from uamopt.errors import InputFileError

#: a flight's track: 25 m at 25 m/s, so a landing "flight" lasts 1 s (its arrival plays no part);
#: aircraft i flies it at y = 2i m, in cells of its own, so the verifier's geometric conflict search
#: finds none (the runway separation is the ``separation`` family, checked against the file)
_TRACK = np.array([[0.0, 0.0, 0.0], [25.0, 0.0, 0.0]])
_SPEED_MPS = 25.0


def parse_airland(path: str | Path) -> dict:
    """The numbers of an OR-Library airland file: P, and per aircraft E, T, L, g, h and the (P, P)
    separation matrix S (diagonal ignored)."""
    path = Path(path)
    try:
        tokens = path.read_text(encoding="utf-8").split()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputFileError(f"cannot read the airland file: {getattr(exc, 'strerror', None) or exc}", str(path),
                             "give an OR-Library airland text file") from None
    try:
        values = [float(t) for t in tokens]
    except ValueError as exc:
        raise InputFileError(f"not a number: {exc}", str(path), "an airland file holds whitespace-separated numbers") from None
    if len(values) < 2 or values[0] != int(values[0]) or values[0] < 1:
        raise InputFileError("the first number is not an aircraft count", str(path), "start with 'P freeze_time'")
    p = int(values[0])
    need = 2 + p * (6 + p)
    if len(values) != need:
        raise InputFileError(f"{len(values)} numbers for {p} aircraft, expected {need}", str(path),
                             "per aircraft: appearance E T L g h and P separations")
    rows = np.array(values[2:], dtype=float).reshape(p, 6 + p)
    e, t, l_, g, h = (rows[:, k] for k in range(1, 6))
    if np.any(e > t) or np.any(t > l_) or np.any(g < 0) or np.any(h < 0):
        bad = int(np.flatnonzero((e > t) | (t > l_) | (g < 0) | (h < 0))[0]) + 1
        raise InputFileError(f"aircraft {bad}: needs E ≤ T ≤ L and costs ≥ 0", str(path), "check that aircraft's line")
    sep = rows[:, 6:].copy()
    np.fill_diagonal(sep, 0.0)
    if np.any(sep < 0):
        raise InputFileError("a negative separation", str(path), "separations are times ≥ 0")
    return {"aircraft": p, "earliest": e, "target": t, "latest": l_, "early_cost": g, "late_cost": h, "separation": sep}


def read_airland(path: str | Path):
    """An OR-Library airland file as a :class:`~uamopt.schedule.SchedulingProblem` (module docstring).

    Examples
    --------
    >>> import uamopt as ua  # doctest: +SKIP
    >>> problem = ua.read_airland("tests/data/airland/airland1.txt")  # doctest: +SKIP
    >>> ua.solve(problem, "highs").objective  # doctest: +SKIP
    700.0
    """
    expect_path(path, "path", "read_airland")

    from uamopt.schedule.core import Objective
    from uamopt.schedule.families.pairs import PairIntervals
    from uamopt.schedule.flights import Flight, FlightSet
    from uamopt.schedule.model import SchedulingProblem
    from uamopt.schedule.occupancy import ConflictTable

    data = parse_airland(path)
    p, e, t, l_ = data["aircraft"], data["earliest"], data["target"], data["latest"]
    flights = tuple(Flight(id=f"a{i + 1}", aircraft=f"a{i + 1}", route="runway", origin="approach", destination="runway",
                           speed_mps=_SPEED_MPS, planned_departure_s=float(e[i]), max_delay_s=float(l_[i] - e[i]),
                           waypoints=_TRACK + np.array([0.0, 2.0 * i, 0.0])) for i in range(p))
    service_end = float(np.max(l_)) + 2.0  # never binds: the window is the delay bound
    fs = FlightSet(cell=(1.0, 1.0, 1.0), conflict_radius=0, flights=flights, service_start_s=float(min(0.0, np.min(e))),
                   service_end_s=service_end, outbound_gap_s=0.0, return_gap_s=0.0,
                   notes=(f"OR-Library aircraft landing instance {Path(path).name}",))
    sep = data["separation"]
    rows = [(i, j, -float(sep[j, i]), float(sep[i, j])) for i in range(p) for j in range(i + 1, p)]
    import hashlib

    source = Path(path).resolve()
    record = {"airland_file": str(source), "sha256": hashlib.sha256(source.read_bytes()).hexdigest()}
    separation = PairIntervals.of_rows("separation", rows, description="runway separation: x_j − x_i ≥ S_ij or x_i − x_j ≥ S_ji",
                                       record_data=record)
    objective = Objective.earliness_tardiness(t - e, data["early_cost"], data["late_cost"])
    return SchedulingProblem(flights=fs, conflicts=ConflictTable.empty(), aircraft_count=p,
                             objective_kind="earliness_tardiness", time_step_s=1.0, must_operate=np.ones(p, dtype=bool),
                             extra_families=(separation,), objective_terms=objective)
