"""The best known values of benchmark instances: ``benchmarks/results.json`` (docs/benchmarks.md).

One JSON document, ``{"format": "uamopt-benchmark-results/1", "instances": [...]}``; each instance
is named as ``bench.csv`` names it (``instance``: the scenario's name and the ``--set`` overrides,
:func:`uamopt.experiments.benchmark.instance_name`) together with its ``plan_seed`` (null for an
instance that is no generated plan: an OR-Library airland file), and carries its size (``flights``,
``aircraft``, ``conflicting_pairs``), its ``objective_kind``, the ``scenario`` file and ``set``
overrides that make it, and the best verified objective and the best lower bound of the continuous
problem known for it, each with the solver, profile, model, time limit, threads, seed and the
``uamopt bench`` command that reproduces it.

- :func:`read_results`: the file read and checked the project's way (every number through
  :func:`uamopt.bounds.check_number`; bad input is one :class:`~uamopt.errors.InputFileError`).
- :func:`compare`: a benchmark table against the file (``uamopt bench --against FILE``): per run
  ``best_known_objective``, ``best_known_bound``, ``to_best_objective`` = (objective − best) / |best|
  and ``to_best_bound`` = (best bound − bound) / |best bound| (both negative when the run is better),
  the runs that beat the file, the contradictions (a bound above a verified objective), the
  instances whose size differs from the file's (not compared) and the file's rows no run matched.
- :func:`update_results`: a ``bench.csv``'s verified rows merged into the file (``--update``),
  keeping the better objective and the better bound per instance, written atomically.

Values are compared with a relative tolerance :data:`REL_TOL` (× max(1, |value|)): closer values are
equal (rounding, solver tolerances), so a tie neither beats the file nor contradicts it.
"""

from __future__ import annotations

import json
import math
import shlex
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from uamopt.bounds import INT64_MAX, Range, check_number, read_json, shown
from uamopt.errors import InputFileError

FORMAT = "uamopt-benchmark-results/1"
REL_TOL = 1e-6  # values closer than this × max(1, |value|) are equal
OBJECTIVE_KINDS = ("weighted", "lexicographic", "earliness_tardiness")

VALUE = Range(-1e15, 1e15)  # an objective or a bound
TIME_LIMIT_S = Range(0.0, 1e7, lo_open=True)  # a profile's time_limit_s
THREADS = Range(1, 100_000, integer=True)
SOLVER_SEED = Range(0, 2**31 - 1, integer=True)  # a profile's seed
PLAN_SEED = Range(0, INT64_MAX, integer=True)
COUNT = Range(1, 1_000_000_000, integer=True)  # flights, aircraft (the scenario keys' range)
PAIRS = Range(0, INT64_MAX, integer=True)

RECORD_REQUIRED = {"best_objective": ("value", "solver", "profile", "time_limit_s", "threads", "model", "command"),
                   "best_bound": ("value", "solver", "model", "time_limit_s", "command")}
RECORD_KEYS = ("value", "solver", "profile", "model", "time_limit_s", "threads", "seed", "command", "uamopt_version")
ENTRY_KEYS = ("instance", "scenario", "set", "plan_seed", "flights", "aircraft", "conflicting_pairs", "objective_kind",
              "best_objective", "best_bound")
#: the columns bench.csv gains with --against
AGAINST_COLUMNS = ["best_known_objective", "best_known_bound", "to_best_objective", "to_best_bound"]
#: the bench.csv columns update_results reads
BENCH_COLUMNS = ("instance", "plan_seed", "scenario", "set", "flights", "aircraft", "conflicting_pairs", "objective_kind",
                 "solver", "profile", "seed", "threads", "time_limit_s", "model", "objective", "bound", "verified")


def tol(value: float) -> float:
    """The tolerance of a comparison with ``value``: :data:`REL_TOL` × max(1, |value|)."""
    return REL_TOL * max(1.0, abs(value))


def bound_model(model) -> bool:
    """True when a bench.csv ``model`` says the row's ``bound`` is a lower bound of the continuous
    problem: a model a solver proves or bounds (``continuous``, ``delay grid S s``, ``discretised
    U s``, ``delay cells S s (relaxation)``: docs/exact_scheduling.md, where ``bound`` is always the
    continuous problem's), not a heuristic's (``…, heuristic``) nor an empty or unknown one."""
    import re

    return isinstance(model, str) and re.fullmatch(
        r"continuous|delay grid \S+ s|discretised \S+ s|delay cells \S+ s \(relaxation\)", model) is not None


@dataclass(frozen=True)
class Record:
    """A best value and where it came from (``best_objective`` or ``best_bound`` of an entry)."""

    value: float
    solver: str
    model: str
    time_limit_s: float
    command: str
    profile: str | None = None
    threads: int | None = None
    seed: int | None = None
    uamopt_version: str | None = None

    def to_dict(self) -> dict:
        out = {key: getattr(self, key) for key in RECORD_KEYS}
        return {k: v for k, v in out.items() if v is not None or k == "value"}

    def credit(self) -> str:
        """``highs seed 1, 20 s`` (who found it)."""
        seed = f" seed {self.seed}" if self.seed is not None else ""
        return f"{self.profile or self.solver}{seed}, {self.time_limit_s:g} s"


@dataclass(frozen=True)
class Entry:
    """One instance of the results file."""

    instance: str
    scenario: str
    set: tuple[str, ...]
    plan_seed: int | None
    flights: int
    aircraft: int
    conflicting_pairs: int
    objective_kind: str
    best_objective: Record | None
    best_bound: Record | None

    @property
    def key(self) -> tuple[str, int | None]:
        return (self.instance, self.plan_seed)

    def to_dict(self) -> dict:
        return {"instance": self.instance, "scenario": self.scenario, "set": list(self.set), "plan_seed": self.plan_seed,
                "flights": self.flights, "aircraft": self.aircraft, "conflicting_pairs": self.conflicting_pairs,
                "objective_kind": self.objective_kind,
                "best_objective": self.best_objective.to_dict() if self.best_objective else None,
                "best_bound": self.best_bound.to_dict() if self.best_bound else None}

    def size(self) -> tuple[int, int, int, str]:
        return (self.flights, self.aircraft, self.conflicting_pairs, self.objective_kind)


@dataclass(frozen=True)
class Results:
    """The results file: its entries in file order, found by (instance, plan seed)."""

    entries: tuple[Entry, ...] = ()
    description: str | None = None

    def get(self, key: tuple[str, int | None]) -> Entry | None:
        return next((e for e in self.entries if e.key == key), None)

    def to_dict(self) -> dict:
        out: dict[str, Any] = {"format": FORMAT}
        if self.description is not None:
            out["description"] = self.description
        out["instances"] = [e.to_dict() for e in self.entries]
        return out


def key_text(instance: str, plan_seed: int | None) -> str:
    """An instance as the report names it: ``benchmark_120 (plan seed 0)``."""
    return instance if plan_seed is None else f"{instance} (plan seed {plan_seed})"


# --- reading ------------------------------------------------------------------------------------


def _text(raw: dict, key: str, where: str, fix: str, limit: int = 10_000) -> str:
    value = raw[key]
    if not (isinstance(value, str) and value.strip() and len(value) <= limit):
        raise InputFileError(f"'{key}' must be a non-empty string of at most {limit} characters, got {shown(value)}",
                             where, fix)
    return value


def _keys(raw: Any, required: tuple[str, ...], allowed: tuple[str, ...], what: str, where: str, fix: str) -> dict:
    if not isinstance(raw, dict):
        raise InputFileError(f"{what} is not a JSON object, got {shown(raw)}", where, fix)
    missing = [k for k in required if k not in raw]
    if missing:
        raise InputFileError(f"{what} has no key '{missing[0]}'", where, f"give {', '.join(required)} (docs/benchmarks.md)")
    unknown = [k for k in raw if k not in allowed]
    if unknown:
        raise InputFileError(f"{what} has an unknown key {shown(unknown[0])}", where,
                             f"use only {', '.join(allowed)} (docs/benchmarks.md)")
    return raw


def _record(raw: Any, name: str, where: str) -> Record | None:
    if raw is None:
        return None
    where = f"{where}: {name}"
    fix = "see docs/benchmarks.md for the fields of a best value"
    raw = _keys(raw, RECORD_REQUIRED[name], RECORD_KEYS, f"'{name}'", where, fix)
    optional = {k: raw.get(k) for k in ("profile", "threads", "seed", "uamopt_version")}
    return Record(
        value=check_number(raw["value"], "value", where, "give the objective or bound as a finite number", VALUE),
        solver=_text(raw, "solver", where, "name the solver (highs, exact, ...)", 200),
        model=_text(raw, "model", where, "give bench.csv's model column of the run (continuous, delay grid 10 s, ...)", 200),
        time_limit_s=check_number(raw["time_limit_s"], "time_limit_s", where, "give the run's time limit in seconds",
                                  TIME_LIMIT_S),
        command=_text(raw, "command", where, "give the uamopt bench command that reproduces the value"),
        profile=None if optional["profile"] is None else _text(raw, "profile", where, "give the profile's name", 200),
        threads=None if optional["threads"] is None else check_number(raw["threads"], "threads", where,
                                                                      "give the profile's threads", THREADS),
        seed=None if optional["seed"] is None else check_number(raw["seed"], "seed", where, "give the solver seed",
                                                                SOLVER_SEED),
        uamopt_version=None if optional["uamopt_version"] is None else _text(raw, "uamopt_version", where,
                                                                            "give the version string", 100),
    )


def _entry(raw: Any, n: int, source: str) -> Entry:
    where = f"{source}: instances[{n}]"
    if isinstance(raw, dict) and isinstance(raw.get("instance"), str):
        where = f"{where} {raw['instance'][:80]}"
    raw = _keys(raw, ENTRY_KEYS, ENTRY_KEYS, "an instance", where, "see docs/benchmarks.md for the fields of an instance")
    sets = raw["set"]
    if not (isinstance(sets, list) and all(isinstance(s, str) and s for s in sets)):
        raise InputFileError(f"'set' must be a list of KEY=VALUE strings, got {shown(sets)}", where,
                             "give the --set overrides of the instance, [] for none")
    kind = raw["objective_kind"]
    if kind not in OBJECTIVE_KINDS:
        raise InputFileError(f"'objective_kind' must be one of {', '.join(OBJECTIVE_KINDS)}, got {shown(kind)}", where,
                             "give bench.csv's objective_kind")
    entry = Entry(
        instance=_text(raw, "instance", where, "give bench.csv's instance name, e.g. benchmark_600", 1000),
        scenario=_text(raw, "scenario", where, "give the scenario file, e.g. models/benchmark_600.toml", 1000),
        set=tuple(sets),
        plan_seed=None if raw["plan_seed"] is None else check_number(
            raw["plan_seed"], "plan_seed", where, "give the plan seed (bench.csv's plan_seed), null for no generated plan",
            PLAN_SEED),
        flights=check_number(raw["flights"], "flights", where, "give bench.csv's flights", COUNT),
        aircraft=check_number(raw["aircraft"], "aircraft", where, "give bench.csv's aircraft", COUNT),
        conflicting_pairs=check_number(raw["conflicting_pairs"], "conflicting_pairs", where,
                                       "give bench.csv's conflicting_pairs", PAIRS),
        objective_kind=kind,
        best_objective=_record(raw["best_objective"], "best_objective", where),
        best_bound=_record(raw["best_bound"], "best_bound", where),
    )
    if entry.best_objective is None and entry.best_bound is None:
        raise InputFileError("the instance has neither a best_objective nor a best_bound", where,
                             "give at least one of them, or remove the instance")
    obj, bound = entry.best_objective, entry.best_bound
    if obj is not None and bound is not None and bound.value > obj.value + tol(obj.value):
        raise InputFileError(f"best_bound {bound.value!r} is above best_objective {obj.value!r}: a lower bound cannot "
                             "exceed a verified objective", where, "one of the two is wrong: check them and fix the file")
    return entry


def read_results(path: str | Path, where: str = "--against") -> Results:
    """Read and check a results file (module docstring; docs/benchmarks.md).

    Raises
    ------
    InputFileError
        A missing or unreadable file, malformed JSON, another ``format``, a missing or unknown key,
        a number that is not a finite number in its range (NaN, ``"7"``, ``true``), two entries of
        one instance and plan seed, a bound above the objective of its own entry.
    """
    path = Path(path)
    source = str(path)
    if path.exists() and not path.is_file():  # a folder, a FIFO: not "not found" (--update would not create it)
        raise InputFileError(f"the results file is {'a folder' if path.is_dir() else 'not a regular file'}: {path}", where,
                             "give the path of a results.json file (docs/benchmarks.md)")
    if not path.is_file():
        raise InputFileError(f"results file not found: {path}", where,
                             "give the path of a results.json (docs/benchmarks.md), or add --update to create it")
    raw = read_json(path, "the results file", source, "a results.json as docs/benchmarks.md describes")
    raw = _keys(raw, ("format", "instances"), ("format", "description", "instances"), "the results file", source,
                f'write {{"format": "{FORMAT}", "instances": [...]}}')
    if raw["format"] != FORMAT:
        raise InputFileError(f"unknown format {shown(raw['format'])}", source,
                             f'this version reads "format": "{FORMAT}" (docs/benchmarks.md)')
    description = raw.get("description")
    if description is not None:
        description = _text(raw, "description", source, "give a string or leave it out")
    if not isinstance(raw["instances"], list):
        raise InputFileError(f"'instances' must be a list, got {shown(raw['instances'])}", source, "give a list of instances")
    entries: list[Entry] = []
    for n, item in enumerate(raw["instances"]):
        entry = _entry(item, n, source)
        if any(e.key == entry.key for e in entries):
            raise InputFileError(f"two instances are {key_text(*entry.key)}", f"{source}: instances[{n}]",
                                 "keep one row per instance and plan seed")
        entries.append(entry)
    return Results(tuple(entries), description)


def write_results(path: str | Path, results: Results) -> None:
    """Write the file atomically (a temporary file beside it, flushed, renamed over it)."""
    from uamopt.outputs import atomic_write

    text = json.dumps(results.to_dict(), indent=2, ensure_ascii=False, allow_nan=False) + "\n"
    try:
        atomic_write(Path(path), text.encode("utf-8"), where=str(path), keep=f"{path} is as it was")
    except OSError as exc:  # not a full disk (atomic_write says that in its own line): permissions, a folder gone
        raise InputFileError(f"cannot write the results file: {exc.strerror or exc}", str(path),
                             f"check the folder's permissions; {path} is as it was") from None


# --- a benchmark table against the file ---------------------------------------------------------


@dataclass
class Comparison:
    """What :func:`compare` found; ``table`` is the benchmark table with :data:`AGAINST_COLUMNS`."""

    source: str
    table: Any
    contradictions: list[str] = field(default_factory=list)
    mismatches: list[str] = field(default_factory=list)
    improvements: list[str] = field(default_factory=list)
    not_run: list[Entry] = field(default_factory=list)
    not_in_file: list[str] = field(default_factory=list)
    matched: int = 0

    def warnings(self) -> list[str]:
        """The lines ``uamopt bench`` writes to stderr as ``warning: ...``."""
        return ([f"contradiction with {self.source}: {c}" for c in self.contradictions]
                + [f"not compared with {self.source}: {m}" for m in self.mismatches])


def _plan_seed(value) -> int | None:
    import pandas as pd

    return None if value is None or value is pd.NA or (isinstance(value, float) and math.isnan(value)) else int(value)


def _finite(value) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        return math.nan
    return value if math.isfinite(value) else math.nan


def _verified(value) -> bool:
    return value is True or str(value).strip().lower() == "true"


def _size_text(size: tuple) -> str:
    return f"{size[0]} flights, {size[1]} aircraft, {size[2]} conflicting pairs, {size[3]} objective"


def compare(table, results: Results, source: str = "--against") -> Comparison:
    """The runs of a benchmark table (with its ``plan_seed`` column) against the results file.

    A run matches the entry of its (``instance``, ``plan_seed``). A matched run whose size or
    objective kind differs from the entry's is not compared (the instance generator or the model
    changed: ``mismatches``). Else the run gets ``best_known_objective``, ``best_known_bound``,
    ``to_best_objective`` = (objective − best_known_objective) / |best_known_objective| (where the run
    has an objective) and ``to_best_bound`` = (best_known_bound − bound) / |best_known_bound| (where it
    has a bound of the continuous problem, :func:`bound_model`); both NaN at a best known value of 0.
    A verified run below the file's bound, or a run's bound above the file's objective, is a
    contradiction; a verified run below the file's objective, or a bound above the file's bound,
    beats it (``improvements``)."""
    out = table.copy()
    columns: dict[str, list[float]] = {c: [] for c in AGAINST_COLUMNS}
    comparison = Comparison(source, out)
    seen: set[tuple[str, int | None]] = set()
    mismatched: set[tuple[str, int | None]] = set()
    for row in table.itertuples(index=False):
        key = (row.instance, _plan_seed(getattr(row, "plan_seed", None)))
        seen.add(key)
        entry = results.get(key)
        values = dict.fromkeys(AGAINST_COLUMNS, math.nan)
        if entry is not None:
            size = (int(row.flights), int(row.aircraft), int(row.conflicting_pairs), row.objective_kind)
            if size != entry.size():
                if key not in mismatched:
                    mismatched.add(key)
                    comparison.mismatches.append(
                        f"{key_text(*key)} has {_size_text(size)} here and {_size_text(entry.size())} in the file: not "
                        "the same instance (the instance generator or the model changed); its runs are not compared")
            else:
                comparison.matched += 1
                _compare_run(row, entry, values, comparison)
        for column in AGAINST_COLUMNS:
            columns[column].append(values[column])
    for column in AGAINST_COLUMNS:
        out[column] = columns[column]
        out[column] = out[column].astype("float64")
    comparison.not_run = [e for e in results.entries if e.key not in seen]
    comparison.not_in_file = [key_text(*k) for k in dict.fromkeys(seen) if results.get(k) is None]
    return comparison


def _compare_run(row, entry: Entry, values: dict, comparison: Comparison) -> None:
    run = f"{key_text(entry.instance, entry.plan_seed)} {row.profile} seed {row.seed}"
    objective, bound = _finite(row.objective), _finite(row.bound)
    verified = _verified(row.verified)
    has_bound = math.isfinite(bound) and bound_model(row.model)
    best_obj, best_bound = entry.best_objective, entry.best_bound
    if best_obj is not None:
        values["best_known_objective"] = best_obj.value
        if math.isfinite(objective) and best_obj.value != 0:
            values["to_best_objective"] = (objective - best_obj.value) / abs(best_obj.value)
        if has_bound and bound > best_obj.value + tol(best_obj.value):
            comparison.contradictions.append(
                f"{run}: its bound {bound:.9g} ({row.model}) is above the file's best objective {best_obj.value:.9g} "
                f"({best_obj.credit()}); one of the two is wrong")
        if verified and math.isfinite(objective) and objective < best_obj.value - tol(best_obj.value):
            comparison.improvements.append(
                f"{run}: verified objective {objective:.9g} beats the best known objective {best_obj.value:.9g} "
                f"({best_obj.credit()})")
    if best_bound is not None:
        values["best_known_bound"] = best_bound.value
        if has_bound and best_bound.value != 0:
            values["to_best_bound"] = (best_bound.value - bound) / abs(best_bound.value)
        if verified and math.isfinite(objective) and best_bound.value > objective + tol(objective):
            comparison.contradictions.append(
                f"{run}: the file's best bound {best_bound.value:.9g} ({best_bound.credit()}, {best_bound.model}) is above "
                f"this run's verified objective {objective:.9g}; one of the two is wrong")
        if verified and has_bound and bound > best_bound.value + tol(best_bound.value):
            comparison.improvements.append(
                f"{run}: bound {bound:.9g} ({row.model}) beats the best known bound {best_bound.value:.9g} "
                f"({best_bound.credit()})")
    if best_obj is None and verified and math.isfinite(objective):
        comparison.improvements.append(f"{run}: verified objective {objective:.9g}; the file has no objective for it")
    if best_bound is None and verified and has_bound:
        comparison.improvements.append(f"{run}: bound {bound:.9g} ({row.model}); the file has no bound for it")


# --- merging a bench.csv into the file ----------------------------------------------------------


def read_bench_csv(path: str | Path):
    """A ``bench.csv`` as a DataFrame, with the columns :func:`update_results` needs."""
    import pandas as pd

    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"bench.csv not found: {path}", str(path), "give the bench.csv a uamopt bench run wrote")
    try:
        table = pd.read_csv(path, dtype={"instance": str, "scenario": str, "set": str, "model": str, "profile": str,
                                         "solver": str, "objective_kind": str}, keep_default_na=False,
                            na_values={c: [""] for c in ("plan_seed", "objective", "bound", "time_limit_s")})
    except (ValueError, UnicodeDecodeError, pd.errors.ParserError) as exc:
        raise InputFileError(f"cannot read bench.csv: {' '.join(str(exc).split())[:200]}", str(path),
                             "give the bench.csv a uamopt bench run wrote") from None
    missing = [c for c in BENCH_COLUMNS if c not in table.columns]
    if missing:
        raise InputFileError(f"bench.csv has no column '{missing[0]}'", str(path),
                             "give a bench.csv of this version's uamopt bench (it names the scenario and plan seed)")
    return table


def _number(value, what: str, where: str, valid: Range):
    """A bench.csv cell through the boundary check (pandas gives numpy scalars or strings)."""
    if isinstance(value, str):
        try:
            value = int(value) if valid.integer else float(value)
        except ValueError:
            pass
    elif hasattr(value, "item"):
        value = value.item()
    if valid.integer and isinstance(value, float) and value.is_integer():
        value = int(value)
    return check_number(value, what, where, "give the bench.csv a uamopt bench run wrote", valid)


def _command(scenario: str, sets: tuple[str, ...], plan_seed: int | None, profile: str, seeds: list[int],
             time_limit_s: float, results_path: str) -> str:
    """The ``uamopt bench`` command that runs this profile with these seeds on the instance again."""
    parts = ["uamopt", "bench", scenario, *[a for s in sets for a in ("--set", s)]]
    if plan_seed is not None and not scenario.lower().endswith(".txt"):
        parts += ["--seed", str(plan_seed)]
    parts += ["--solver", profile]
    if seeds == list(range(len(seeds))):
        parts += ["--seeds", str(len(seeds))]
    elif len(seeds) > 1:
        parts += ["--seeds", *map(str, seeds)]
    # one seed other than 0: the profile's own seed (a single --seeds value is a count)
    parts += ["--time-limit", f"{time_limit_s:g}", "--against", results_path]
    return shlex.join(parts)


def _shown_scenario(path: str) -> str:
    """A shipped scenario as ``models/NAME.toml`` (found from any folder), else the path as given."""
    from uamopt.shipped import models_dir

    try:
        real, models = Path(path).resolve(), models_dir().resolve()
        return f"models/{real.relative_to(models).as_posix()}" if real.is_relative_to(models) else path
    except (OSError, ValueError):
        return path


def _record_of(row, value: float, entry: Entry, seeds: list[int], here: str, results_path: str) -> Record:
    """The provenance of a best value: the bench.csv row that reached it."""
    from uamopt import __version__

    t = _number(row["time_limit_s"], "time_limit_s", here, TIME_LIMIT_S)
    profile = str(row["profile"])
    return Record(value=value, solver=str(row["solver"]), model=str(row["model"]), time_limit_s=t,
                  command=_command(entry.scenario, entry.set, entry.plan_seed, profile, seeds, t, results_path),
                  profile=profile, threads=_number(row["threads"], "threads", here, THREADS),
                  seed=_number(row["seed"], "seed", here, SOLVER_SEED), uamopt_version=__version__)


def _new_entry(ok, key: tuple[str, int | None], size: tuple) -> Entry | None:
    """The entry of an instance not yet in the file, from the bench.csv's scenario and set columns."""
    scenario, sets = str(ok["scenario"].iloc[0]), str(ok["set"].iloc[0])
    try:
        overrides = json.loads(sets)
    except ValueError:
        overrides = None
    if not scenario or not (isinstance(overrides, list) and all(isinstance(s, str) for s in overrides)):
        return None
    return Entry(key[0], _shown_scenario(scenario), tuple(overrides), key[1], *size, None, None)


def merge_results(results: Results, table, results_path: str = "benchmarks/results.json", where: str = "bench.csv"):
    """``results`` with the verified rows of a bench table merged in: (new Results, changes, skipped).

    Per (instance, plan seed): the least verified objective replaces the file's when it is lower by
    more than the tolerance; the greatest bound of a verified row whose ``model`` makes it a bound of
    the continuous problem (:func:`bound_model`) replaces the file's when higher. An instance whose
    size differs from the file's, or whose merged bound would lie above its merged objective (a
    contradiction), is skipped with the reason, unchanged."""
    entries = list(results.entries)
    changes: list[str] = []
    skipped: list[str] = []
    plan = [None if _missing(p) else _number(p, "plan_seed", f"{where}: row {n + 1}", PLAN_SEED)
            for n, p in enumerate(table["plan_seed"])]
    instance = [str(i) for i in table["instance"]]
    for key in dict.fromkeys(zip(instance, plan, strict=True)):
        runs = table[[(i, p) == key for i, p in zip(instance, plan, strict=True)]]
        name = key_text(*key)
        here = f"{where}: {name}"
        ok = runs[[_verified(v) for v in runs["verified"]]]
        if not len(ok):
            skipped.append(f"{name}: no verified run")
            continue
        sizes = {(_number(r["flights"], "flights", here, COUNT), _number(r["aircraft"], "aircraft", here, COUNT),
                  _number(r["conflicting_pairs"], "conflicting_pairs", here, PAIRS), str(r["objective_kind"]))
                 for _, r in ok.iterrows()}
        size = sizes.pop()
        if sizes or size[3] not in OBJECTIVE_KINDS:
            skipped.append(f"{name}: its rows disagree on the instance's size or objective kind")
            continue
        index = next((n for n, e in enumerate(entries) if e.key == key), None)
        entry = entries[index] if index is not None else _new_entry(ok, key, size)
        if entry is None:
            skipped.append(f"{name}: {where} does not say which scenario and overrides made it (a problem given to "
                           "ua.benchmark); run it with uamopt bench")
            continue
        if entry.size() != size:
            skipped.append(f"{name}: {_size_text(size)} in {where}, {_size_text(entry.size())} in the file: not the same "
                           "instance; not merged")
            continue

        def seeds_of(profile, runs=runs, here=here) -> list[int]:
            return sorted({_number(s, "seed", here, SOLVER_SEED) for s in runs[runs["profile"] == profile]["seed"]})

        best_obj, best_bound, said = entry.best_objective, entry.best_bound, []
        values = [(_number(v, "objective", here, VALUE), n) for n, v in enumerate(ok["objective"]) if not _missing(v)]
        if values:
            value, n = min(values)
            if best_obj is None or value < best_obj.value - tol(best_obj.value):
                row = ok.iloc[n]
                best_obj = _record_of(row, value, entry, seeds_of(row["profile"]), here, results_path)
                said.append(f"best objective {value:.9g} ({best_obj.credit()})")
        values = [(_number(v, "bound", here, VALUE), n) for n, (v, m) in enumerate(zip(ok["bound"], ok["model"], strict=True))
                  if not _missing(v) and bound_model(m)]
        if values:
            value, n = max(values, key=lambda pair: (pair[0], -pair[1]))
            if best_bound is None or value > best_bound.value + tol(best_bound.value):
                row = ok.iloc[n]
                best_bound = _record_of(row, value, entry, seeds_of(row["profile"]), here, results_path)
                said.append(f"best bound {value:.9g} ({best_bound.credit()}, {best_bound.model})")
        if best_obj is not None and best_bound is not None and best_bound.value > best_obj.value + tol(best_obj.value):
            skipped.append(f"{name}: the bound {best_bound.value:.9g} would lie above the objective {best_obj.value:.9g} "
                           "(a contradiction: one of them is wrong); not merged")
            continue
        if not said:
            continue
        new = replace(entry, best_objective=best_obj, best_bound=best_bound)
        if index is None:
            entries.append(new)
            changes.append(f"{name}: added, {', '.join(said)}")
        else:
            entries[index] = new
            changes.append(f"{name}: {', '.join(said)}")
    return replace(results, entries=tuple(entries)), changes, skipped


def _missing(value) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value)) or (isinstance(value, str) and not value)


def update_results(results_path: str | Path, bench_csv_path: str | Path) -> tuple[list[str], list[str]]:
    """Merge the verified rows of ``bench_csv_path`` into the results file (:func:`merge_results`)
    and rewrite it atomically when anything changed; a missing file is created. Returns the changes
    and the instances skipped, in words.

    Raises
    ------
    InputFileError
        The results file or the bench.csv is malformed (the file is then left as it was).
    """
    path = Path(results_path)
    results = read_results(path, where=str(path)) if path.exists() else Results()
    table = read_bench_csv(bench_csv_path)
    merged, changes, skipped = merge_results(results, table, str(results_path), where=str(bench_csv_path))
    if changes:
        write_results(path, merged)
    return changes, skipped
