"""One case of a sweep, run to its stage with the pipeline's functions (uamopt/pipeline.py): ``run_case``.

The rows it returns are plain dicts (one per solver × seed at stage ``schedule``, one otherwise);
the engine adds the case id, the swept values and the version. A failure inside a case becomes
an ``error`` row (status ``"error"``, the one-line message) instead of an exception, so one bad
case never stops a sweep.

Row keys by stage (docs/sweeps.md, docs/interfaces.md "Sweep files"):

- every stage: ``status``, ``seconds`` (this stage's own computing time), ``error``, and the risk
  field's ``unsafe_share`` (Eq. 9, whole grid), ``band_unsafe_share`` (free cells of the altitude
  band, Eq. 14), ``cruise_unsafe_share`` and ``cruise_mean_risk`` (free cells of the cell layer
  holding ``network.cruise_altitude_m``; risk per flight hour, Eq. 8);
- ``plan``: the optimal P_O → P_D track's ``objective`` (Eq. 10), ``risk_cost`` (Eq. 11),
  ``transport_cost`` (Eq. 12), ``length_m``, ``n_waypoints``;
- ``network`` and ``schedule``: those four metrics summed over every directed route;
- ``schedule``: ``solver``, ``seed``, ``status``, ``objective`` (Eq. 20), ``bound``, ``gap``,
  ``operated`` (S, Eq. 22), ``cancelled``, ``total_delay_s``, ``avg_delay_s`` (Eq. 21),
  ``verified`` (the independent verifier), ``flights``, ``aircraft``, ``conflicting_pairs``.
"""

from __future__ import annotations

import math
import time

import numpy as np

from uamopt.errors import error_line


def _unless_out_of_space(exc: Exception) -> None:
    """Re-raise a write that a full disk, a quota or a file-size limit stopped (NoSpaceError, or a
    raw OSError with that errno): the machine's state, not the case's result. The sweep then stops
    in one line with the cases saved before it, and a resume runs this case again (never a row)."""
    from uamopt.errors import NoSpaceError
    from uamopt.outputs import NO_SPACE

    if isinstance(exc, NoSpaceError):
        raise exc
    if isinstance(exc, OSError) and exc.errno in NO_SPACE:
        raise NoSpaceError(f"cannot write {exc.filename or 'a temporary file'}: {exc.strerror}", "a sweep case",
                           "free some space or raise the file size limit (ulimit -f), then run the sweep again") from exc


#: the last case's risk field in this process, with its key and its risk metrics: a worker runs case
#: after case, and the cases of a sweep over planning or scheduling keys (weights, μ, solvers)
#: share one field, and with it the planning model's costly arrays (uamopt.planning.problem.field_arrays)
_LAST_FIELD: list = []


def case_field(scenario) -> tuple:
    """(field, its risk metrics) of the case: the last case's when this one's field inputs are the
    same. The key is the scenario's name, the digests of the field's sections
    (uamopt.risk.field_inputs) and its ``[network]`` section (the synthetic city keeps its vertiports
    clear of buildings; the cruise layer of the metrics). The field keeps only Eq. 9's cells: its
    continuous risk is computed for the metrics and then released."""
    import hashlib
    import json

    from uamopt.pipeline import compute_risk
    from uamopt.risk import field_inputs

    network = hashlib.sha256(json.dumps(scenario.network.model_dump(mode="json"), sort_keys=True).encode()).hexdigest()
    key = (scenario.name, tuple(sorted(field_inputs(scenario).items())), network)
    if _LAST_FIELD and _LAST_FIELD[0][0] == key:
        return _LAST_FIELD[0][1:]
    _LAST_FIELD.clear()  # the old field is freed before the next one is computed
    field = compute_risk(scenario, keep_risk=False)
    metrics = risk_metrics(scenario, field)
    field.release()
    _LAST_FIELD.append((key, field, metrics))
    return field, metrics


def risk_metrics(scenario, field) -> dict:
    """Unsafe shares of the whole grid, the band and the cruise layer; mean risk at cruise."""
    summary = field.summary()
    g = field.grid
    k = min(math.floor(scenario.network.cruise_altitude_m / g.cell[2]), g.shape[2] - 1)
    free = ~field.obstacle[:, :, k]
    return {"unsafe_share": summary["unsafe_share"], "band_unsafe_share": summary["band_unsafe_share"],
            "cruise_unsafe_share": float(field.unsafe[:, :, k][free].mean()) if free.any() else math.nan,
            "cruise_mean_risk": float(np.nanmean(field.risk[:, :, k][free])) if free.any() else math.nan}


def found_solution(schedule) -> bool:
    """False when the solver stopped without an incumbent (its schedule then cancels everything)."""
    return schedule.found and not str(schedule.extras.get("incumbent", "")).startswith("none found")


def schedule_row(problem, schedule, seconds: float) -> dict:
    """A solved instance as a row; objective and gap are NaN where undefined (no incumbent, no
    bound, or an objective of 0, where a relative gap divides by zero), never a sentinel.
    ``verified``: the independent verifier on the written schedule files (``uamopt.verify``)."""
    from uamopt.pipeline import verify

    solved = found_solution(schedule)
    objective = schedule.objective if solved and schedule.objective is not None else math.nan
    bound = schedule.bound if schedule.bound is not None else math.nan
    gap = math.nan
    if solved and math.isfinite(bound) and abs(objective) > 1e-9:
        gap = abs(objective - bound) / abs(objective)
    return {"status": schedule.status, "termination": schedule.termination, "proved_for": schedule.proved_for,
            "model": schedule.extras.get("model_kind"),
            "objective_kind": problem.objective_kind, "objective": objective, "bound": bound, "gap": gap,
            "operated": schedule.operated_count, "cancelled": schedule.cancelled_count,
            "total_delay_s": schedule.total_delay_s, "avg_delay_s": schedule.avg_delay_s,
            "verified": schedule.found and verify(problem, schedule).ok,  # infeasible / no_solution: no schedule
            "seconds": seconds}


def network_totals(network) -> dict:
    """The plan metrics summed over every directed route of a RouteNetwork."""
    routes = network.to_frame()
    return {"risk_cost": float(routes["risk_cost"].sum()), "transport_cost": float(routes["transport_cost"].sum()),
            "length_m": float(routes["length_m"].sum()), "n_waypoints": int(routes["n_waypoints"].sum())}


def scheduling_problem(scenario, network, seed: int):
    """The generated flight plan (plan seed = ``schedule.plan_seed`` + ``seed``) and its model."""
    from uamopt.pipeline import build_problem, generate_flights

    return build_problem(generate_flights(scenario, network, scenario.schedule.plan_seed + seed), scenario)


def _plan_row(model) -> dict:
    from uamopt.pipeline import plan_track

    t0 = time.perf_counter()
    best = plan_track(model).stages["optimal"]  # the scenario's route (tracks.route, else P_O → P_D)
    return {"status": "ok", "objective": best.objective, "risk_cost": best.risk_cost, "transport_cost": best.transport_cost,
            "length_m": best.length_m, "n_waypoints": best.n_waypoints, "seconds": time.perf_counter() - t0}


def _schedule_rows(scenario, network, common: dict, solvers, seeds) -> list[dict]:
    from uamopt.pipeline import solve

    rows = []
    for seed in seeds:
        try:
            problem = scheduling_problem(scenario, network, seed)
        except Exception as exc:  # noqa: BLE001 - recorded in the rows
            _unless_out_of_space(exc)
            rows += [{"solver": p.name, "seed": seed, **common, "status": "error", "error": error_line(exc)} for p in solvers]
            continue
        size = {"flights": problem.n_flights, "aircraft": problem.aircraft_count, "conflicting_pairs": len(problem.conflicts)}
        for profile in solvers:
            row = {"solver": profile.name, "seed": seed, **size, **common}
            try:
                t0 = time.perf_counter()
                schedule = solve(problem, profile, seed=seed)
                row.update(schedule_row(problem, schedule, time.perf_counter() - t0))
            except Exception as exc:  # noqa: BLE001 - recorded in the row
                _unless_out_of_space(exc)
                row.update(status="error", error=error_line(exc))
            rows.append(row)
    return rows


def run_case(scenario, stage: str, solvers=(), seeds=(0,)) -> list[dict]:
    """Run one scenario to ``stage`` (risk | plan | network | schedule) and return its rows.

    Parameters
    ----------
    scenario : Scenario
        The case's scenario (base + overrides).
    stage : str
        How far to run; rows and their keys are listed in the module docstring.
    solvers : sequence of SolverProfile
        Stage ``schedule``: each profile solves each seed's instance (its seed replaced by the seed).
    seeds : sequence of int
        Stage ``schedule``: the solver seed and the plan seed offset (``schedule.plan_seed + seed``).

    Returns
    -------
    list of dict
        Never raises for a failing case: its rows carry ``status = "error"`` and ``error``.
    """
    from uamopt.pipeline import plan_network, planning_model

    schedule = stage == "schedule"
    keys = [{"solver": p.name, "seed": s} for p in solvers for s in seeds] if schedule else [{}]
    try:
        t0 = time.perf_counter()
        field, metrics = case_field(scenario)
        common = {**metrics, "seconds": time.perf_counter() - t0}
        if stage == "risk":
            return [{**common, "status": "ok"}]
        model = planning_model(scenario, field)
        if stage == "plan":
            return [{**common, **_plan_row(model)}]
        t0 = time.perf_counter()
        network = plan_network(model)
        common |= network_totals(network)
        if stage == "network":
            return [{**common, "status": "ok", "seconds": time.perf_counter() - t0}]
        return _schedule_rows(scenario, network, common, solvers, seeds)
    except Exception as exc:  # noqa: BLE001 - a failing case is a row, not a crash
        _unless_out_of_space(exc)
        return [{**k, "status": "error", "error": error_line(exc)} for k in keys]
