"""The exact scheduling model as a standard MPS or LP file, and another solver's answer read back.

Why: a solver benchmarker runs every MILP solver they have (SCIP, CBC, Gurobi, CPLEX, HiGHS's
own binary) on one model, as with MIPLIB. :func:`write_model` writes the continuous MILP of
Eqs. 20-31 that ``highs`` solves (uamopt/solvers/milp.py ``build_model``, every family the problem
has, on the problem as given) through Pyomo's writers, with readable names (``operate(3)``,
``delay(3)``, ``in_gap(7_1)``), and beside it ``<file>.columns.json``: the variable of each flight's
decision (``operate``, ``delay``), the flights' ids in order, and the problem's objective kind and
weights, so that the file can be traced to the flights without uamopt.

:func:`read_solution` takes a solution file of any of the usual plain-text kinds (HiGHS's
``writeSolution``, SCIP's ``write solution``, CBC's ``solu``, Gurobi's ``.sol``: each variable on
one line as its name and then its value; every other line, and any name the model lacks, is
ignored) and turns it into a :class:`~uamopt.schedule.model.Schedule`: ``operate`` read at 0.5,
then the delays recomputed exactly from the solver's choices (its gap binaries, and the pads'
order binaries), as ``highs`` does with its own answer (milp.py ``least_delays``): a solver's
delays carry its feasibility tolerance (about 1e-6), the verifier forgives 1e-6. The result is
checked against the model (:func:`~uamopt.schedule.model.violations`); its termination is
``stopped`` (the outside solver's claims are not ours to certify), its objective our own
evaluation of the decisions.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from uamopt.errors import InputFileError, UamoptError
from uamopt.schedule.model import Schedule, SchedulingProblem, make_schedule, violations

FORMATS = {".mps": "mps", ".lp": "lp"}
COLUMNS_SUFFIX = ".columns.json"


def _format(path: Path) -> str:
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise UamoptError(f"a model file must end in .mps or .lp, got {path.name!r}", str(path),
                          "name it model.mps (free MPS) or model.lp (CPLEX LP)")
    return fmt


def columns_path(model_path: str | Path) -> Path:
    """The mapping file written beside ``model_path``."""
    path = Path(model_path)
    return path.with_name(path.name + COLUMNS_SUFFIX)


def write_model(problem: SchedulingProblem, path: str | Path) -> tuple[Path, Path]:
    """Write the exact MILP of ``problem`` to ``path`` (.mps or .lp) and its variable mapping beside it;
    returns (model file, mapping file). Both are written whole or not at all."""
    import pyomo.environ as pyo

    from uamopt.solvers.milp import build_model

    path = Path(path)
    fmt = _format(path)
    model = build_model(problem)
    for var in model.component_data_objects(pyo.Var):  # a fixed column (must_operate) would vanish from the
        if var.fixed:                                   # file as a constant: kept as a column of equal bounds
            value = var.value
            var.unfix()
            var.setlb(value)
            var.setub(value)
    names = {}
    tmp = path.with_name(path.name + ".part")
    try:
        _, symbols = model.write(str(tmp), format=fmt, io_options={"symbolic_solver_labels": True})
        by_symbol = model.solutions.symbol_map[symbols].bySymbol
        names = {symbol: _component(obj).name for symbol, obj in by_symbol.items()
                 if _component(obj).is_variable_type()}  # the columns (the symbol map names the rows too)
        symbol_of = {name: symbol for symbol, name in names.items()}
        ids = [f.id for f in problem.flights.flights]
        mapping = {"format": fmt, "model": "continuous MILP of Eqs. 20-31 (uamopt/solvers/milp.py build_model)",
                   "objective_kind": problem.objective_kind, "weights": list(problem.weights),
                   "aircraft": problem.aircraft_count, "flights": ids,
                   "operate": {fid: symbol_of.get(f"operate[{i}]") for i, fid in enumerate(ids)},
                   "delay": {fid: symbol_of.get(f"delay[{i}]") for i, fid in enumerate(ids)},
                   "variables": names}
        side = columns_path(path)
        side_tmp = side.with_name(side.name + ".part")
        side_tmp.write_text(json.dumps(mapping, indent=1), encoding="utf-8")
        tmp.replace(path)
        side_tmp.replace(side)
    finally:
        for left in (tmp, columns_path(path).with_name(columns_path(path).name + ".part")):
            left.unlink(missing_ok=True)
    return path, columns_path(path)


def _component(obj):
    return obj() if callable(obj) and not hasattr(obj, "name") else obj  # a weak reference in some Pyomo versions


def read_values(solution_path: str | Path, symbols: set[str]) -> dict[str, float]:
    """{variable: value} of a plain-text solution file: on each line the first token that names a
    variable of the model, then the first number after it (module docstring)."""
    path = Path(solution_path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise InputFileError(f"cannot read the solution file: {exc.strerror or exc}", str(path),
                             "give the file your solver wrote") from None
    values: dict[str, float] = {}
    for line in text.splitlines():
        tokens = line.replace("\t", " ").split()
        for k, token in enumerate(tokens):
            if token in symbols:
                number = next((v for v in (_number(t) for t in tokens[k + 1:]) if v is not None), None)
                if number is not None:
                    values.setdefault(token, number)
                break
    return values


def _number(token: str) -> float | None:
    try:
        value = float(token.strip("(),;"))
    except ValueError:
        return None
    return value if math.isfinite(value) else None


ANSWER_TOL_S = 1e-3  # a solver's own delays may break a row by this much (its feasibility tolerance, scaled by big-M)


def _breaks(problem: SchedulingProblem, operated: np.ndarray, delay: np.ndarray) -> str | None:
    """The first pair interval or turnaround the solver's own delays break by more than ``ANSWER_TOL_S``,
    or a delay outside its bounds by as much, in words."""
    from uamopt.solvers.discovery import Constraints

    cons = Constraints.of(problem)
    pair, turn = cons.broken(operated, delay, ANSWER_TOL_S)
    ids = [f.id for f in problem.flights.flights]
    if len(pair):
        k = int(pair[0])
        return (f"{ids[cons.p[k]]} and {ids[cons.q[k]]} depart {delay[cons.q[k]] - delay[cons.p[k]]:.6g} s apart, "
                f"inside their forbidden ({cons.lo[k]:.6g}, {cons.hi[k]:.6g})")
    if len(turn):
        k = int(turn[0])
        short = cons.need[k] - (delay[cons.tf[k]] - delay[cons.te[k]])
        return f"{ids[cons.tf[k]]} leaves {short:.6g} s before its aircraft's turnaround ends"
    outside = np.flatnonzero(operated & ((delay < -ANSWER_TOL_S) | (delay > problem.delay_upper_s + ANSWER_TOL_S)))
    if len(outside):
        f = int(outside[0])
        return f"{ids[f]}'s delay {delay[f]:.6g} s is outside [0, {problem.delay_upper_s[f]:.6g}]"
    return None


def read_solution(problem: SchedulingProblem, model_path: str | Path, solution_path: str | Path,
                  solver: str = "external") -> Schedule:
    """The schedule of another solver's answer to the model :func:`write_model` wrote for ``problem``
    (module docstring). A file that names none of the flights' ``operate`` variables, an answer
    that breaks the model, or a mapping of other flights is one clear error."""
    mapping = read_mapping(problem, model_path)
    values = read_values(solution_path, set(mapping["variables"]))
    operated, delay = decisions(problem, mapping, values, str(solution_path))
    return make_schedule(problem, solver, "stopped", operated, delay,
                         extras={"model": "continuous", "model_kind": "continuous",
                                 "solution_file": str(solution_path), "model_file": str(model_path)})


def read_mapping(problem: SchedulingProblem, model_path: str | Path) -> dict:
    """The mapping file beside ``model_path``, checked to be of ``problem``'s flights."""
    side = columns_path(model_path)
    try:
        mapping = json.loads(side.read_text(encoding="utf-8"))
        dict(mapping["variables"]), dict(mapping["operate"]), dict(mapping["delay"])
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InputFileError(f"cannot read the model's mapping: {exc}", str(side),
                             "write the model again with write_model / uamopt flights --model mps") from None
    if list(mapping.get("flights", [])) != [f.id for f in problem.flights.flights]:
        raise InputFileError("the mapping is of other flights than this problem's", str(side),
                             "read the solution with the problem the model was written from")
    return mapping


def decisions(problem: SchedulingProblem, mapping: dict, values: dict[str, float], where: str
              ) -> tuple[np.ndarray, np.ndarray]:
    """(operated, delays) of a solver's column values (keyed by the file's names): ``operate`` at 0.5,
    the solver's own delays checked (:data:`ANSWER_TOL_S`), then the delays recomputed exactly from
    its gap and pad-order choices (milp.py ``least_delays``); any break is one InputFileError."""
    from uamopt.solvers.milp import build_model, chosen_gaps, least_cost_delays, least_delays, pad_orders

    ids = [f.id for f in problem.flights.flights]
    names, operate, delay_of = mapping["variables"], mapping["operate"], mapping["delay"]
    if not any(operate[fid] in values for fid in ids):
        raise InputFileError("the solution names none of the flights' operate variables", where,
                             f"write it with the variable names of the model file (e.g. {operate[ids[0]]})")
    operated = np.array([values.get(operate[fid], 0.0) > 0.5 for fid in ids])
    raw = np.array([values.get(delay_of[fid], 0.0) if delay_of.get(fid) else 0.0 for fid in ids])
    wrong = _breaks(problem, operated, np.where(operated, raw, 0.0))
    if wrong:
        raise InputFileError(f"the solution breaks the model: {wrong}", where,
                             "check that it is a feasible answer of this model (its delays as written)")
    model = build_model(problem)
    for symbol, value in values.items():
        component = model.find_component(names[symbol]) if symbol in names else None
        if component is not None:
            component.set_value(value, skip_validation=True)
    chosen, orders = chosen_gaps(model, operated), pad_orders(model, operated)
    delay = (least_delays(problem, operated, chosen, orders) if not problem.objective.per_flight_terms
             else least_cost_delays(problem, operated, chosen, orders))
    if delay is None:
        raise InputFileError("the solution's choices admit no delays within the bounds (it breaks the model)",
                             where, "check that it is a feasible answer of this model")
    delay = np.where(operated, delay, 0.0)
    bad = violations(problem, operated, delay)
    if bad:
        raise InputFileError(f"the solution breaks the model: {bad[0]}", where,
                             "check that it is a feasible answer of this model")
    return operated, delay
