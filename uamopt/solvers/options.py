"""Typed solver options: each solver's ``[options]`` are applied as written or refused, never ignored.

Each solver declares its own options here (name, type, accepted range, default). ``highs`` and
``cpsat`` also pass any other key to the underlying solver; those keys are checked against the
solver itself before the run (``highspy.Highs.setOptionValue`` and CP-SAT's ``SatParameters``),
so an unknown name or an invalid value (``mip_rel_gap = -1``, ``"abc"``) is a one-line error
naming the option, never a silently ignored setting.

Profile-level fields (``solvers/*.toml``), strict types (a bool is not a number, a string not an int):

=============== ============================== ==============================================
key             type / range                   meaning
=============== ============================== ==============================================
solver          one of :data:`SOLVERS`         which solver
time_limit_s    float in (0, 10⁷]              wall-clock limit of the whole solve, model
                                               building included, s (10⁷ s: about 116 days)
seed            int in [0, 2³¹ − 1]            random seed (HiGHS and CP-SAT take 32-bit seeds)
threads         int in [1, max(64, 4·cores)]   threads for HiGHS / CP-SAT
options         table                          per solver, below
=============== ============================== ==============================================

Every number goes through the one boundary check (uamopt/bounds.py): a 400-digit integer, NaN or
inf is refused in one line, never an ``OverflowError``. Each solver's own options declare a finite
range (:data:`OWN`; ``ga``/``soa``: ``GeneticOptions.RANGES``): a delay-grid step or lattice unit
of at least a millisecond (a microsecond for CP-SAT's unit) and at most 10⁷ s, a GA population of
at most 10⁴. Options passed to HiGHS are refused when NaN, or infinite unless HiGHS's own default
for the option is (``objective_bound``); HiGHS and CP-SAT then check their own ranges.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

from uamopt.bounds import MAX_TIME_S, Range, check_number, shown
from uamopt.errors import UamoptError

SEED_MAX = 2**31 - 1
THREADS_MAX = max(64, 4 * (os.cpu_count() or 1))
TIME_LIMIT_S = Range(0.0, MAX_TIME_S, lo_open=True)


@dataclass(frozen=True)
class Opt:
    """One option: its type (float, int, bool, str), default, and its range (numbers) or choices."""

    kind: type
    default: Any = None
    valid: Range | None = None  # numbers: the values it can take (finite ends)
    choices: tuple = ()

    def check(self, key: str, value: Any, where: str) -> Any:
        bad = UamoptError
        if self.kind is bool:
            if not isinstance(value, bool):
                raise bad(f"option {key} must be true or false, got {shown(value)}", where, f"write {key} = true or false")
            return value
        if self.kind is str:
            if not isinstance(value, str) or (self.choices and value not in self.choices):
                raise bad(f"option {key} = {shown(value)} is not one of {', '.join(map(repr, self.choices))}", where,
                          f"use one of {', '.join(self.choices)}")
            return value
        assert self.valid is not None, f"option {key} declares no range"  # every numeric option declares one
        return check_number(value, f"option {key}", where, f"use {self.valid.text()}", self.valid, error=bad)


STEP_S = Range(1e-3, MAX_TIME_S)  # a delay grid's step, s: a millisecond to 10⁷ s
POSITIVE_S = Opt(float, valid=STEP_S)
SECONDS = Range(0.0, MAX_TIME_S)
#: each solver's own options (``ga``/``soa`` are declared by ``GeneticOptions`` in genetic.py)
OWN: dict[str, dict[str, Opt]] = {
    "greedy": {"step_s": POSITIVE_S, "exact_gaps": Opt(bool, False)},
    "highs": {},
    "scip": {"mip_rel_gap": Opt(float, 0.0, valid=Range(0.0, 1.0))},
    "cpsat": {"time_unit_s": Opt(float, 0.01, valid=Range(1e-6, MAX_TIME_S)), "continuous_bound": Opt(bool, True)},
    "rolling": {"window_s": Opt(float, 900.0, valid=Range(1.0, MAX_TIME_S)),
                "inner": Opt(str, "cpsat", choices=("cpsat", "highs")),
                "window_time_limit_s": Opt(float, valid=TIME_LIMIT_S),
                "time_unit_s": Opt(float, 0.01, valid=Range(1e-6, MAX_TIME_S)),
                "step_s": POSITIVE_S},
    "timeindexed": {"step_s": Opt(float, 10.0, valid=STEP_S), "model": Opt(str, "grid", choices=("grid", "relaxed")),
                    "engine": Opt(str, "auto", choices=("auto", "highs", "cpsat", "hybrid")),
                    "warm_soa_s": Opt(float, 0.0, valid=SECONDS), "continuous_bound_s": Opt(float, 0.0, valid=SECONDS),
                    "continuous_bound_step_s": POSITIVE_S, "mip_rel_gap": Opt(float, 0.0, valid=Range(0.0, 1e6)),
                    "cliques": Opt(bool, True), "refine_step_s": Opt(float, 0.0, valid=Range(0.0, MAX_TIME_S))},
    "discovery": {"step_s": Opt(float, 10.0, valid=STEP_S), "mip_rel_gap": Opt(float, 0.005, valid=Range(0.0, 1.0)),
                  "cliques": Opt(bool, False), "lns_share": Opt(float, 0.35, valid=Range(0.0, 1.0)),
                  "round_time_limit_s": Opt(float, 15.0, valid=TIME_LIMIT_S),
                  "lns_window": Opt(int, 250, valid=Range(2, 10**6, integer=True)),
                  "lns_window_time_limit_s": Opt(float, 20.0, valid=TIME_LIMIT_S)},
    "windows": {"step_s": Opt(float, 10.0, valid=STEP_S), "mip_rel_gap": Opt(float, 0.005, valid=Range(0.0, 1.0)),
                "cliques": Opt(bool, False), "rounds": Opt(int, 60, valid=Range(1, 10**6, integer=True)),
                "round_time_limit_s": Opt(float, 15.0, valid=TIME_LIMIT_S),
                "window_flights": Opt(int, 1000, valid=Range(2, 10**7, integer=True)),
                "window_time_limit_s": Opt(float, valid=TIME_LIMIT_S),
                "workers": Opt(int, 2, valid=Range(1, 4096, integer=True)), "scheduler": Opt(str, ""),
                "lns_window": Opt(int, 250, valid=Range(2, 10**6, integer=True)),
                "lns_window_time_limit_s": Opt(float, 20.0, valid=TIME_LIMIT_S)},
}
#: solvers that hand every other option to the underlying library, after checking it there
PASS_THROUGH = {"highs": "HiGHS", "cpsat": "CP-SAT"}
#: library options the profile's own fields set (an option would silently fight the field)
RESERVED = {"highs": {"time_limit": "time_limit_s", "threads": "threads", "random_seed": "seed"},
            "cpsat": {"max_time_in_seconds": "time_limit_s", "num_workers": "threads", "num_search_workers": "threads",
                      "random_seed": "seed", "catch_sigint_signal": "Ctrl-C handling (uamopt.interrupts)"}}
def refuse_unknown(options: dict, known: set[str], solver: str) -> None:
    """Raise on an option the solver does not know (validate at the boundary)."""
    unknown = sorted(set(options) - known)
    if unknown:
        raise UamoptError(f"unknown option '{unknown[0]}' for solver {solver}", f"profile {solver} [options]",
                          f"valid options are {', '.join(sorted(known)) or 'none'}")


def check_profile_fields(name: str, time_limit_s: Any, seed: Any, threads: Any) -> None:
    """Strict types and ranges of a profile's own fields (module docstring)."""
    where = f"profile {name}"
    check_number(time_limit_s, "time_limit_s", where, "give a time limit in seconds, e.g. 60", TIME_LIMIT_S, error=UamoptError)
    check_number(seed, "seed", where, "HiGHS and CP-SAT take 32-bit seeds; use e.g. 0", Range(0, SEED_MAX, integer=True),
                 error=UamoptError)
    check_number(threads, "threads", where, f"use 1 to {THREADS_MAX} (this machine has {os.cpu_count()} cores)",
                 Range(1, THREADS_MAX, integer=True), error=UamoptError)


def check_options(solver: str, options: Any, name: str) -> None:
    """Refuse an unknown option or an invalid value for ``solver`` (module docstring)."""
    where = f"profile {name} [options]"
    if not isinstance(options, dict):
        raise UamoptError(f"[options] must be a table, got {type(options).__name__}", where, "write key = value lines")
    if solver in ("ga", "soa"):
        from uamopt.solvers.genetic import GeneticOptions

        GeneticOptions.from_options(options, solver)
        return
    own = OWN[solver]
    for key, value in options.items():
        if key in own:
            own[key].check(key, value, where)
    rest = {k: v for k, v in options.items() if k not in own}
    if not rest:
        return
    if solver not in PASS_THROUGH:
        refuse_unknown(options, set(own), solver)
    for key in rest:
        if key in RESERVED[solver]:
            raise UamoptError(f"option {key} is set by the profile's {RESERVED[solver][key]}", where,
                              f"write {RESERVED[solver][key]} = ... above [options] instead")
    (_check_highs if solver == "highs" else _check_cpsat)(rest, where)


def _check_highs(options: dict, where: str) -> None:
    import highspy

    from uamopt.solvers.highs import quiet_highs

    h = quiet_highs()
    for key, value in options.items():
        known = h.getOptionType(key)[0] == highspy.HighsStatus.kOk
        if isinstance(value, bool) and h.getOptionType(key)[1] != highspy.HighsOptionType.kBool:
            ok = False  # HiGHS would read true as 1
        elif isinstance(value, float) and not math.isfinite(value):
            # HiGHS takes NaN for any double and inf for a gap: refused, but where HiGHS's own default is
            # infinite (objective_bound = inf: no bound), inf means that default
            default = h.getOptionValue(key)[1] if known else None
            ok = not math.isnan(value) and isinstance(default, float) and math.isinf(default) \
                and h.setOptionValue(key, value) == highspy.HighsStatus.kOk
        elif isinstance(value, int) and not isinstance(value, bool) and not -2**63 <= value < 2**63:
            ok = False  # beyond int64: no HiGHS option is that wide
        else:
            ok = h.setOptionValue(key, value) == highspy.HighsStatus.kOk
        if not ok:
            raise UamoptError(f"HiGHS {'refuses' if known else 'has no option'} {key}"
                              + (f" = {shown(value)}" if known else ""), where,
                              "see https://ergo-code.github.io/HiGHS/stable/options/definitions/")


def _check_cpsat(options: dict, where: str) -> None:
    """Set each option on a CP-SAT solver's parameters, then let CP-SAT check their ranges on a
    one-variable model (milliseconds)."""
    from ortools.sat.python import cp_model

    solver = cp_model.CpSolver()
    params = solver.parameters
    for key, value in options.items():
        if key.startswith("_") or not hasattr(params, key) or callable(getattr(params, key)):
            raise UamoptError(f"CP-SAT has no parameter {key}", where, "see ortools/sat/sat_parameters.proto")
        try:
            current = getattr(params, key)
            if isinstance(value, bool) != isinstance(current, bool):
                raise TypeError("a bool for a non-bool parameter, or the reverse")
            if isinstance(value, list):
                getattr(params, key).extend(value)
            else:
                setattr(params, key, value)
        except (AttributeError, TypeError, ValueError) as exc:
            reason = " ".join(str(exc).split()[:12])  # pybind's message lists every signature: keep its start
            raise UamoptError(f"CP-SAT refuses {key} = {shown(value)} ({reason})", where,
                              "see ortools/sat/sat_parameters.proto") from None
    model = cp_model.CpModel()
    model.add_bool_or([model.new_bool_var("x")])
    params.max_time_in_seconds = 1.0
    params.num_workers = 1
    params.catch_sigint_signal = False  # CP-SAT's own Ctrl-C handler would replace ours (uamopt.interrupts)
    if solver.solve(model) == cp_model.MODEL_INVALID:
        raise UamoptError(f"CP-SAT refuses the options: {solver.solution_info()}", where,
                          "see ortools/sat/sat_parameters.proto")
