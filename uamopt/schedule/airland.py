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

from uamopt.bounds import DURATION_S, TIME_S, Range, check_number, shown
from uamopt.checks import expect_path
from uamopt.errors import InputFileError

#: a flight's track: 25 m at 25 m/s, so a landing "flight" lasts 1 s (its arrival plays no part);
#: aircraft i flies it at y = 2i m, in cells of its own, so the verifier's geometric conflict search
#: finds none (the runway separation is the ``separation`` family, checked against the file)
_TRACK = np.array([[0.0, 0.0, 0.0], [25.0, 0.0, 0.0]])
_SPEED_MPS = 25.0


#: the file's numbers (docs/interfaces.md: every number passes one boundary check before any arithmetic)
AIRCRAFT = Range(1, 1_000_000_000, integer=True)  # P: the scenario keys' range of a count
COST = Range(0.0, 1e6)  # g_i, h_i per time unit: the range of an objective's weight
_FIELDS = (("appearance time", TIME_S), ("earliest time E", TIME_S), ("target time T", TIME_S),
           ("latest time L", TIME_S), ("early cost g", COST), ("late cost h", COST))
_FIX = "per aircraft: appearance E T L g h (times in [-1e7, 1e7], costs in [0, 1e6]) and P separations in [0, 1e7]"


def _exact(token: str):
    """A token as the number it spells, exactly (an int of any length where it is one), for the
    error line: 10**400 is named as the 401-digit integer, not as ``inf``."""
    try:
        return int(token)
    except ValueError:  # not an integer literal, or one beyond Python's int-string limit (named as written)
        return token if token.lstrip("+-").isdigit() else float(token)


def parse_airland(path: str | Path) -> dict:
    """The numbers of an OR-Library airland file: P, and per aircraft E, T, L, g, h and the (P, P)
    separation matrix S (diagonal ignored).

    Every number is checked before any arithmetic: P a whole number in [1, 10⁹] (the count of
    numbers the file must hold is computed from it exactly, before anything is allocated), times
    within ±10⁷, costs in [0, 10⁶], separations in [0, 10⁷] (the diagonal, ignored, within ±10⁷),
    E ≤ T ≤ L. Anything else is one :class:`~uamopt.errors.InputFileError` naming the value."""
    path = Path(path)
    where = str(path)
    try:
        tokens = path.read_text(encoding="utf-8").split()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputFileError(f"cannot read the airland file: {getattr(exc, 'strerror', None) or exc}", where,
                             "give an OR-Library airland text file") from None
    try:
        values = np.array([float(t) for t in tokens], dtype=float)
    except ValueError:
        n, word = next((n, t) for n, t in enumerate(tokens) if not _is_number(t))
        raise InputFileError(f"number {n + 1} is not a number: {shown(word)}", where,
                             "an airland file holds whitespace-separated numbers") from None
    if len(values) < 2:
        raise InputFileError(f"{len(values)} numbers, expected at least 2", where,
                             "start with 'P freeze_time' (P: the number of aircraft)")
    count = _exact(tokens[0])
    count = int(count) if isinstance(count, float) and count.is_integer() else count  # "10.0" is 10
    p = check_number(count, "the aircraft count P (the first number)", where,
                     "start with 'P freeze_time', P the number of aircraft", AIRCRAFT)
    check_number(_exact(tokens[1]), "the freeze time (the second number)", where, "give a time in the file's unit",
                 TIME_S)
    need = 2 + p * (6 + p)  # exact whatever P: compared before anything of that size exists
    if len(values) != need:
        raise InputFileError(f"{len(values)} numbers for {p} aircraft, expected {need}", where, _FIX)
    rows = values[2:].reshape(p, 6 + p)
    lo = np.empty_like(rows)
    hi = np.empty_like(rows)
    for k, (_, valid) in enumerate(_FIELDS):
        lo[:, k], hi[:, k] = valid.lo, valid.hi
    lo[:, 6:], hi[:, 6:] = DURATION_S.lo, DURATION_S.hi
    diagonal = (np.arange(p), 6 + np.arange(p))
    lo[diagonal], hi[diagonal] = TIME_S.lo, TIME_S.hi  # ignored, but a number like every other
    outside = ~((rows >= lo) & (rows <= hi))  # True for NaN
    if outside.any():
        i, k = (int(v) for v in np.argwhere(outside)[0])
        name, valid = _FIELDS[k] if k < 6 else (f"separation S_{i + 1},{k - 5}", TIME_S if k - 6 == i else DURATION_S)
        check_number(_exact(tokens[2 + i * (6 + p) + k]), f"aircraft {i + 1}: {name}", where, _FIX, valid)
    e, t, l_, g, h = (rows[:, k] for k in range(1, 6))
    if np.any(e > t) or np.any(t > l_):
        bad = int(np.flatnonzero((e > t) | (t > l_))[0])
        raise InputFileError(f"aircraft {bad + 1}: needs E ≤ T ≤ L, got E {e[bad]:g}, T {t[bad]:g}, L {l_[bad]:g}", where,
                             "check that aircraft's line")
    sep = rows[:, 6:].copy()
    np.fill_diagonal(sep, 0.0)
    return {"aircraft": p, "earliest": e, "target": t, "latest": l_, "early_cost": g, "late_cost": h, "separation": sep}


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


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
