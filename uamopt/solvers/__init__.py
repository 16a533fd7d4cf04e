"""Solvers behind one interface (linopy/PyPSA pattern): ``solve(problem, profile) -> Schedule``.

A solver never builds the model: it takes a :class:`~uamopt.schedule.SchedulingProblem` as data
and returns a :class:`~uamopt.schedule.Schedule` (status, objective, bound, gap, time, seed).
Profiles are TOML files naming a solver and its options; the shipped ones are package data in
``uamopt/solvers/profiles/`` (a checkout's ``solvers/`` links there; :mod:`uamopt.shipped`)::

    solver = "highs"        # greedy | ga | soa | highs | cpsat | rolling | timeindexed
    time_limit_s = 60.0
    seed = 0
    threads = 2
    [options]               # solver-specific (see each module's docstring)
    mip_rel_gap = 0.0

Every field and option is typed and checked when the profile is made (:mod:`uamopt.solvers.options`).
"""

from __future__ import annotations

import dataclasses
import importlib
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from uamopt.errors import ScenarioError, UamoptError
from uamopt.optional import missing_extra, require
from uamopt.shipped import profile_path, profiles_dir

if TYPE_CHECKING:
    from uamopt.schedule import Schedule, SchedulingProblem

#: solver name -> module implementing ``solve(problem, profile) -> Schedule``
SOLVERS = {
    "greedy": "uamopt.solvers.greedy",
    "ga": "uamopt.solvers.genetic",
    "soa": "uamopt.solvers.genetic",
    "highs": "uamopt.solvers.milp",
    "cpsat": "uamopt.solvers.cpsat",
    "rolling": "uamopt.solvers.rolling",
    "timeindexed": "uamopt.solvers.timeindexed",
    "discovery": "uamopt.solvers.discovery",
    "windows": "uamopt.solvers.windows",
    "scip": "uamopt.solvers.scip",
}
#: the shipped profiles (package data, read with importlib.resources: :func:`uamopt.shipped.profiles_dir`)
PROFILE_DIR = profiles_dir()
_KEYS = {"solver", "time_limit_s", "seed", "threads", "isolated", "options", "description"}


@dataclass(frozen=True)
class SolverProfile:
    """A solver and its options, typed and checked on creation (:mod:`uamopt.solvers.options`):
    an unknown option or an invalid value is refused here, before any work; ``name`` is the
    profile's file stem. ``time_limit_s`` bounds the whole solve, model building included."""

    solver: str
    name: str = ""
    time_limit_s: float = 60.0
    seed: int = 0
    threads: int = 2
    options: dict = field(default_factory=dict)
    isolated: bool = True

    def __post_init__(self) -> None:
        from uamopt.solvers.options import check_options, check_profile_fields

        if not isinstance(self.solver, str) or self.solver not in SOLVERS:
            raise UamoptError(f"unknown solver {self.solver!r}", f"profile {self.name or self.solver}",
                              f"use one of {', '.join(SOLVERS)}")
        check_profile_fields(self.name or self.solver, self.time_limit_s, self.seed, self.threads)
        if not isinstance(self.isolated, bool):
            raise UamoptError(f"isolated must be true or false, got {self.isolated!r}"[:200],
                              f"profile {self.name or self.solver}",
                              "write isolated = true (a child process its time limit can end) or false")
        try:  # options passed through to HiGHS or CP-SAT are checked by them: the [exact] extra
            check_options(self.solver, self.options, self.name or self.solver)
        except ModuleNotFoundError as exc:
            raise (missing_extra(exc, f"the {self.solver} solver") or exc) from None

    def option(self, key: str, default=None):
        """The typed value of option ``key`` (checked on creation), else its declared default
        (:data:`uamopt.solvers.options.OWN`), else ``default``."""
        from uamopt.solvers.options import OWN

        if key in self.options:
            spec = OWN.get(self.solver, {}).get(key)
            return spec.kind(self.options[key]) if spec is not None else self.options[key]
        spec = OWN.get(self.solver, {}).get(key)
        return spec.default if spec is not None and spec.default is not None else default


def load_profile(name_or_path: str | Path) -> SolverProfile:
    """A profile by path (``solvers/highs.toml``) or bare name (``highs``, looked up in the shipped
    profiles, :data:`PROFILE_DIR`). A relative ``solvers/NAME.toml`` that is no file where the command
    runs (outside a checkout) is the shipped profile of that name."""
    text = str(name_or_path)
    path = Path(text)
    if not path.suffix:
        path = PROFILE_DIR / f"{text}.toml"
        if not path.is_file() and text in SOLVERS:
            return SolverProfile(solver=text, name=text)
    else:
        path = Path(profile_path(text))
    if not path.is_file():
        raise UamoptError(f"solver profile not found: {text}", "--solver",
                          f"give a profile file or one of {', '.join(sorted(p.stem for p in PROFILE_DIR.glob('*.toml')))}")
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"malformed TOML: {exc}", str(path), "fix the syntax at that line") from None
    except UnicodeDecodeError:
        raise ScenarioError("the profile is not UTF-8 text", str(path), "save it as UTF-8") from None
    except (OSError, RecursionError) as exc:
        raise ScenarioError(f"cannot read the profile: {getattr(exc, 'strerror', None) or exc}", str(path),
                            "give a readable TOML file") from None
    except ValueError as exc:  # an integer of more than 4300 digits (Python's int-string limit)
        from uamopt.bounds import parse_error

        raise ScenarioError(f"the profile holds {parse_error(exc)}", str(path),
                            "every number of a profile has a range (uamopt/solvers/options.py)") from None
    unknown = set(raw) - _KEYS
    if unknown:
        raise ScenarioError(f"unknown key '{sorted(unknown)[0]}'", str(path), f"valid keys are {', '.join(sorted(_KEYS))}")
    if "solver" not in raw:
        raise ScenarioError("missing key 'solver'", str(path), f"name one of {', '.join(SOLVERS)}")
    return SolverProfile(solver=raw["solver"], name=path.stem, time_limit_s=raw.get("time_limit_s", 60.0),
                         seed=raw.get("seed", 0), threads=raw.get("threads", 2), options=raw.get("options", {}),
                         isolated=raw.get("isolated", True))


#: solvers whose model accepts ``extra=`` callbacks (docs/variants.md): highs gets ``extra(m, problem)``
#: on the Pyomo model, cpsat ``extra(model, problem, operate, delay)`` on the CP-SAT model
EXTRA = ("highs", "cpsat")
BRUTEFORCE = "uamopt.solvers.bruteforce"


def unsupported(module, problem: SchedulingProblem) -> str | None:
    """What of ``problem`` a solver module cannot encode: the first family whose shape (or, for a
    solver that lists ``FAMILIES``, whose name) it lacks, or the objective kind; None if it can."""
    for family in problem.families:
        names = getattr(module, "FAMILIES", None)
        shape = family.shape
        if shape == "cumulative" and len(family.residual().flight) == 0:
            shape = "pairs"  # only one-pad resources: disjunctive, read through problem.pairs
        if shape not in module.SHAPES or (names is not None and family.name not in names):
            return f"family '{family.name}'"
    if problem.objective.kind not in module.OBJECTIVES:
        return f"objective '{problem.objective.kind}'"
    return None


#: the packages of the [exact] extra each exact solver imports (on use: looked up, not imported, up front)
NEEDS = {"highs": ("pyomo",), "cpsat": ("ortools",), "rolling": ("ortools", "pyomo"), "timeindexed": ("ortools",),
         "scip": ("pyomo", "pyscipopt")}
#: the extra that brings a solver's packages, where it is not [exact]
EXTRA_OF = {"scip": "scip"}


def solver_module(solver: str):
    """The module of ``solver`` (:data:`SOLVERS`; the enumeration oracle for any other name); a
    solver whose package is an extra not installed is a :class:`~uamopt.optional.MissingExtraError`."""
    for module in NEEDS.get(solver, ()):
        require(module, extra=EXTRA_OF.get(solver, "exact") if module == "pyscipopt" else "exact",
                what=f"the {solver} solver")
    try:
        return importlib.import_module(SOLVERS[solver] if solver in SOLVERS else BRUTEFORCE)
    except ModuleNotFoundError as exc:
        raise (missing_extra(exc, f"the {solver} solver") or exc) from None


def _installed(solver: str) -> bool:
    try:
        solver_module(solver)
    except ImportError:
        return False
    return True


def check_supported(solver: str, problem: SchedulingProblem, where: str | None = None) -> None:
    """Refuse, before any work, a problem with a family or objective the solver has no encoder for:
    one line naming it and the solvers that support it."""
    module = solver_module(solver)
    missing = unsupported(module, problem)
    if missing is None:
        return
    able = [name for name in SOLVERS if _installed(name) and unsupported(solver_module(name), problem) is None]
    raise UamoptError(f"solver {solver} has no encoder for the {missing}", where or f"solver {solver}",
                      f"use one of: {', '.join(able)}" if able else "no solver supports this problem")


def solve(problem: SchedulingProblem, profile: SolverProfile | str, *, extra=None) -> Schedule:
    """Run the profile's solver on the problem.

    ``extra``: a callback that adds rows to the exact model between build and solve (PyPSA's
    ``extra_functionality``), for ``highs`` and ``cpsat`` only (:data:`EXTRA`; docs/variants.md).
    """
    if not isinstance(profile, SolverProfile):
        profile = load_profile(profile)
    check_supported(profile.solver, problem, f"profile {profile.name or profile.solver}")
    if extra is not None and profile.solver not in EXTRA:
        raise UamoptError(f"solver {profile.solver} takes no extra= callback", f"profile {profile.name or profile.solver}",
                          f"use one of {', '.join(EXTRA)}, whose models the callback can edit")
    from uamopt.solvers import watchdog

    profile = capped_threads(profile)
    schedule = watchdog.run(problem, profile, extra, solve_here)
    schedule.extras.setdefault("model_kind", model_kind(profile, problem))
    schedule.extras["threads"] = profile.threads
    if profile.solver in watchdog.WATCHED and schedule.bound is None and schedule.objective is not None:
        # a bound is always reported: where the solver's own gave none, the separable one (weak, valid)
        bound = min(watchdog.separable_bound(problem), schedule.objective)
        schedule.extras.setdefault("bound_source", "the separable bound (every flight at its own best choice)")
        schedule = dataclasses.replace(schedule, bound=bound,
                                       gap=abs(schedule.objective - bound) / max(abs(schedule.objective), 1e-10))
    # the progress over time (watchdog.trace_of; a heuristic's is its answer alone), ending at the answer
    final = [round(float(schedule.solve_seconds), 3),
             float(schedule.objective) if schedule.found and schedule.objective is not None else None,
             float(schedule.bound) if schedule.bound is not None and math.isfinite(schedule.bound) else None]
    schedule.extras["trace"] = [*schedule.extras.get("trace", []), final]
    return schedule


#: an environment variable capping every solver's threads: for a machine whose cores several solves
#: share (HiGHS's threads spin against each other when they outnumber the cores: airland1's time-indexed
#: model took 159 s on 2 threads and 49 s on 1 at load 4). The test suite sets it to 1 (tests/conftest.py).
THREADS_ENV = "UAMOPT_MAX_THREADS"


def capped_threads(profile: SolverProfile) -> SolverProfile:
    """``profile`` with its threads at most ``$UAMOPT_MAX_THREADS`` (unset or empty: no cap)."""
    import dataclasses
    import os

    raw = os.environ.get(THREADS_ENV, "").strip()
    if not raw:
        return profile
    if not raw.isdigit() or len(raw) > 6 or int(raw) < 1:
        raise UamoptError(f"{THREADS_ENV} must be a whole number of at least 1, got {raw[:40]!r}", "the environment",
                          f"unset it, or set e.g. {THREADS_ENV}=1")
    return profile if profile.threads <= int(raw) else dataclasses.replace(profile, threads=int(raw))


def solve_here(problem: SchedulingProblem, profile: SolverProfile, extra=None) -> Schedule:
    """:func:`solve`'s work in this process, with no watchdog (a watched child runs this)."""
    from uamopt.schedule.families.speed import speed_choice_of

    module = solver_module(profile.solver)
    choice = speed_choice_of(problem)
    try:  # a solver's own lazy imports (OR-Tools, HiGHS inside rolling, timeindexed): the [exact] extra
        if choice is not None and profile.solver in SPEED_FIRST and extra is None:
            return _speed_solve(problem, profile, module, choice)
        return module.solve(problem, profile) if extra is None else module.solve(problem, profile, extra=extra)
    except ModuleNotFoundError as exc:
        raise (missing_extra(exc, f"the {profile.solver} solver") or exc) from None


#: exact solvers that solve the cruise-speed model first when a problem has speed options, and
#: start the speed model from its schedule (never worse than flying every flight at v_g)
SPEED_FIRST = ("highs", "cpsat", "timeindexed")
SPEED_BASE_SHARE = 0.4  # of the time limit, for the cruise-speed model


def _speed_solve(problem, profile, module, choice):
    """The speed-options model, started from the cruise-speed model's schedule (module
    ``families/speed.py``): the base gets ``SPEED_BASE_SHARE`` of the time limit, the copies the rest."""
    import dataclasses
    import time

    from uamopt.solvers.warmstart import SEEDS

    t0 = time.perf_counter()
    base_profile = dataclasses.replace(profile, time_limit_s=SPEED_BASE_SHARE * profile.time_limit_s)
    first = module.solve(choice.base_problem, base_profile)
    lifted = choice.lift(first.operated, first.delay_s) if first.found else None
    left = max(0.1, profile.time_limit_s - (time.perf_counter() - t0))
    if lifted is not None:
        SEEDS[id(problem)] = [("cruise-speed model", *lifted)]
    try:
        schedule = module.solve(problem, dataclasses.replace(profile, time_limit_s=left))
    finally:
        SEEDS.pop(id(problem), None)
    schedule.extras.update(cruise_speed_model={"status": first.status, "objective": first.objective,
                                               "operated": first.operated_count, "total_delay_s": first.total_delay_s})
    schedule.extras.setdefault("model_kind", model_kind(profile, problem))
    return dataclasses.replace(schedule, solve_seconds=time.perf_counter() - t0)


def model_kind(profile: SolverProfile, problem: SchedulingProblem) -> str:
    """Which problem a profile's status is about: ``continuous`` (the model of Sec. 4.3),
    ``delay grid S s`` (delays restricted to multiples of S), ``discretised U s`` (CP-SAT's
    lattice of U, constraints rounded outward), a relaxation, or a heuristic on one of these."""
    o = profile.option
    if profile.solver == "highs":
        return "continuous"
    if profile.solver == "cpsat":
        return f"discretised {o('time_unit_s'):g} s"
    if profile.solver == "timeindexed":
        step = float(o("step_s"))
        return f"delay grid {step:g} s" if o("model") == "grid" else f"delay cells {step:g} s (relaxation)"
    if profile.solver in ("discovery", "windows"):
        return "continuous"
    if profile.solver == "rolling":
        return f"time windows ({o('inner') or 'cpsat'}), heuristic"
    if o("exact_gaps"):
        return "continuous, heuristic"
    return f"delay grid {float(o('step_s') or problem.time_step_s):g} s, heuristic"
