"""Sweep files (``models/variants/*.toml``): a base scenario, fixed overrides and a grid of cases.

::

    base = "../paper_case.toml"          # scenario, relative to this file
    stage = "schedule"                   # how far each case runs: risk | plan | network | schedule
    solvers = ["greedy", "soa", "highs"] # profiles (names or paths), stage = "schedule" only
    seeds = [0, 1, 2]                    # solver seeds; the plan seed is schedule.plan_seed + seed
    time_limit_s = 30.0                  # optional: every solver's time limit
    figure = "flights"                   # optional: the figure drawn from the results (figures.py)
    [set]                                # fixed overrides, any scenario key
    "grid.cell" = [50.0, 50.0, 30.0]
    [grid]                               # the cartesian product of these lists is the set of cases
    "schedule.flights" = [60, 120, 180, 240]
    [small]                              # what --small changes: seeds, solvers, time_limit_s,
    seeds = [0]                          # [small.set] merged into [set], [small.grid] lists
    [small.grid]                         # replacing (or adding) [grid] lists
    "schedule.flights" = [60, 120]

Everything is validated here, before any case runs: unknown keys (of the file and of the
scenario), the types of the tables and values (a TOML date or time is no value of any scenario
key), ``[small]`` whether or not ``--small`` is given, an empty grid, the number of cases (at most
``max_cases``, default :data:`MAX_CASES`, counted before any case is built), every case's
scenario (:func:`load_sweep` builds each one), the solver profiles and seeds (0 to 2³¹ − 1, the
solvers' 32-bit seeds). A case's id is a hash of all its overrides, fixed and swept, so it is
stable across runs and machines.
"""

from __future__ import annotations

import datetime
import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from uamopt.checks import expect, expect_path
from uamopt.errors import ScenarioError, UamoptError

STAGES = ("risk", "plan", "network", "schedule")
FILE_KEYS = {"base", "stage", "solvers", "seeds", "time_limit_s", "figure", "name", "description", "set", "grid", "small",
             "max_cases"}
SMALL_KEYS = {"solvers", "seeds", "time_limit_s", "set", "grid"}
#: the most cases a sweep file may have unless its ``max_cases`` says otherwise: every case's
#: scenario is built (and checked) before anything runs, some milliseconds each
MAX_CASES = 10_000


@dataclass(frozen=True)
class Case:
    """One point of the grid: its position, stable id, swept values and the scenario they give."""

    index: int
    id: str
    values: dict  # swept key -> value (as written in the file)
    overrides: tuple[str, ...]  # KEY=VALUE, fixed then swept
    scenario: Any  # uamopt.scenario.Scenario


@dataclass(frozen=True)
class SweepSpec:
    """A parsed and validated sweep file."""

    path: Path
    name: str
    base: Path
    stage: str
    solvers: tuple  # SolverProfile, time limit applied
    seeds: tuple[int, ...]
    fixed: dict  # key -> value of [set]
    grid: dict  # key -> list of values
    cases: tuple[Case, ...]
    time_limit_s: float | None = None
    figure: str | None = None
    small: bool = False

    @property
    def swept_keys(self) -> list[str]:
        return list(self.grid)

    def row_keys(self) -> list[tuple]:
        """(case id, solver, seed) of every row the sweep must hold, in table order."""
        if self.stage != "schedule":
            return [(c.id, None, None) for c in self.cases]
        return [(c.id, p.name, s) for c in self.cases for p in self.solvers for s in self.seeds]

    def manifest(self) -> dict:
        """What a results folder records of its sweep; a resumed run must agree on all of it."""
        return {
            "uamopt_sweep": 1, "name": self.name, "base_sha256": hashlib.sha256(self.base.read_bytes()).hexdigest(),
            "stage": self.stage, "small": self.small, "set": {k: toml_value(v) for k, v in sorted(self.fixed.items())},
            "solvers": {p.name: _profile_text(p) for p in self.solvers},
        }


def toml_value(value: Any) -> str:
    """``value`` written as a TOML value (the syntax of ``--set KEY=VALUE``)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        return repr(value) if math.isfinite(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{json.dumps(str(k))} = {toml_value(v)}" for k, v in value.items()) + "}"
    raise TypeError(f"no TOML form for {value!r}")


def case_id(overrides: list[str] | tuple[str, ...]) -> str:
    """A stable 12-hex-digit id of a case from its overrides (order-independent)."""
    return hashlib.sha1("\n".join(sorted(overrides)).encode("utf-8")).hexdigest()[:12]


def _profile_text(profile) -> str:
    return json.dumps({"solver": profile.solver, "time_limit_s": profile.time_limit_s, "threads": profile.threads,
                       "options": profile.options}, sort_keys=True, default=str)


def _flatten(table: dict, prefix: str = "") -> dict:
    """``{"a": {"b": 1}}`` and ``{"a.b": 1}`` both give ``{"a.b": 1}`` (quoted or bare dotted keys).
    Iterative: a key dotted thousands of levels deep is no RecursionError."""
    out: dict = {}
    stack = [(prefix, iter(table.items()))]
    while stack:
        name, items = stack[-1]
        for key, value in items:
            if isinstance(value, dict):
                stack.append((f"{name}{key}.", iter(value.items())))
                break
            out[f"{name}{key}"] = value
        else:
            stack.pop()
    return out


def _table(raw: dict, key: str, where: str, label: str | None = None) -> dict:
    """``raw[key]`` (a TOML table, default empty) flattened; refused when it is not a table or
    holds a date or time (no scenario key takes one)."""
    label = label or key
    value = raw.get(key, {})
    if not isinstance(value, dict):
        raise ScenarioError(f"[{label}] must be a table, got {value!r}"[:200], where,
                            f'write it as a table, e.g. [{label}] then "schedule.aircraft" = '
                            + ("[10, 20]" if "grid" in label else "10"))
    flat = _flatten(value)
    for name, item in flat.items():
        bad = _date_or_time(item)
        if bad is not None:
            raise ScenarioError(f"[{label}] \"{name}\" holds a TOML date or time ({bad.isoformat()}), not a number", where,
                                "write the number (or the value) the scenario key takes")
    return flat


def _date_or_time(value: Any):
    """The first TOML date, time or date-time in ``value`` (lists and inline tables included), else None."""
    stack = [value]
    while stack:
        item = stack.pop()
        if isinstance(item, (datetime.date, datetime.time)):  # datetime.datetime is a date
            return item
        if isinstance(item, list):
            stack.extend(item)
        elif isinstance(item, dict):
            stack.extend(item.values())
    return None


def _read(path: Path) -> dict:
    if not path.is_file():
        raise UamoptError(f"sweep file not found: {path}", str(path),
                          "give the path of a sweep .toml, e.g. models/variants/speed.toml")
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"malformed TOML: {exc}", str(path), "fix the syntax at that line") from None
    except UnicodeDecodeError:
        raise ScenarioError("sweep file is not UTF-8 text", str(path), "save it as UTF-8 TOML") from None
    except ValueError as exc:  # an integer of more than 4300 digits (Python's int-string limit)
        from uamopt.bounds import parse_error

        raise ScenarioError(f"the sweep file holds {parse_error(exc)}", str(path),
                            "every number of a sweep has a range (docs/interfaces.md)") from None
    except RecursionError:
        raise ScenarioError("the sweep file is nested too deeply to read", str(path), "flatten its arrays") from None
    except OSError as exc:
        raise ScenarioError(f"cannot read the sweep file: {exc.strerror or exc}", str(path),
                            "check that the file is readable") from None


def _check_small(raw: dict, where: str) -> None:
    """``[small]``'s shape, whether or not --small is given: a table of known keys of the right
    types (its cases are built only with --small)."""
    small = raw.get("small", {})
    if not isinstance(small, dict):
        raise ScenarioError(f"[small] must be a table, got {small!r}"[:200], where,
                            f"write it as a table [small] of keys among {', '.join(sorted(SMALL_KEYS))}")
    unknown = sorted(set(small) - SMALL_KEYS)
    if unknown:
        raise ScenarioError(f"unknown key 'small.{unknown[0]}'", where, f"[small] takes {', '.join(sorted(SMALL_KEYS))}")
    for key in ("set", "grid"):
        _table(small, key, where, f"small.{key}")
    if "seeds" in small:
        _seeds(small["seeds"], where, "small.seeds")
    if "time_limit_s" in small:
        _time_limit(small["time_limit_s"], where, "small.time_limit_s")
    solvers = small.get("solvers", ["greedy"])
    if not isinstance(solvers, list) or not solvers or not all(isinstance(s, str) for s in solvers):
        raise ScenarioError(f"small.solvers must be a non-empty list of profile names, got {solvers!r}"[:200], where,
                            'write e.g. solvers = ["greedy"]')


def _apply_small(raw: dict, where: str) -> dict:
    small = raw.get("small", {})
    out = dict(raw)
    for key in ("solvers", "seeds", "time_limit_s"):
        if key in small:
            out[key] = small[key]
    for key in ("set", "grid"):
        if key in small:
            out[key] = {**_table(raw, key, where), **_table(small, key, where, f"small.{key}")}
    return out


def _time_limit(value: Any, where: str, key: str = "time_limit_s") -> float | None:
    """Every solver's time limit: the solver profiles' range (0, 10⁷] s, through the one boundary
    check (a 400-digit integer, NaN or inf is one line, not an OverflowError)."""
    from uamopt.bounds import check_number
    from uamopt.solvers.options import TIME_LIMIT_S

    if value is None:
        return None
    return check_number(value, key, where, "give seconds, e.g. 30.0", TIME_LIMIT_S, ScenarioError)


def _seeds(raw: Any, where: str, key: str = "seeds") -> tuple[int, ...]:
    """Solver seeds: whole numbers 0 to SEED_MAX (2³¹ − 1: HiGHS and CP-SAT seeds are 32-bit, as a
    profile's ``seed`` is)."""
    from uamopt.solvers.options import SEED_MAX

    if not isinstance(raw, list) or not raw or not all(isinstance(s, int) and not isinstance(s, bool) and 0 <= s <= SEED_MAX
                                                       for s in raw):
        raise ScenarioError(f"{key} must be a non-empty list of integers from 0 to {SEED_MAX}, got {raw!r}"[:300], where,
                            "write e.g. seeds = [0, 1, 2] (solver seeds are 32-bit)")
    if len(set(raw)) != len(raw):
        raise ScenarioError(f"{key} repeat a value: {raw!r}"[:300], where, "list each seed once")
    return tuple(raw)


def _max_cases(raw: dict, where: str) -> int:
    from uamopt.bounds import INT64_MAX, shown

    limit = raw.get("max_cases", MAX_CASES)
    if isinstance(limit, bool) or not isinstance(limit, int) or not 1 <= limit <= INT64_MAX:
        raise ScenarioError(f"max_cases must be a whole number ≥ 1 (at most 2^63 − 1), got {shown(limit)}", where,
                            f"give the most cases the sweep may have, e.g. max_cases = {MAX_CASES}")
    return limit


def _check_size(grid: dict, limit: int, rows_per_case: int, where: str) -> None:
    """Refuse a grid of more than ``limit`` cases from the lengths of its lists, before any is built."""
    cases = math.prod(len(v) for v in grid.values())
    if cases > limit:
        rows = f" ({cases * rows_per_case:,} rows)" if rows_per_case > 1 else ""
        raise ScenarioError(f"the grid has {cases:,} cases{rows}, more than the limit of {limit:,} cases", f"{where} [grid]",
                            f"sweep fewer values, or raise the limit in the file (max_cases = {cases}) if you mean it")


def _profiles(raw: Any, base_dir: Path, time_limit_s: float | None, where: str) -> tuple:
    from uamopt.solvers import load_profile

    if not isinstance(raw, list) or not raw or not all(isinstance(s, str) for s in raw):
        raise ScenarioError(f"solvers must be a non-empty list of profile names, got {raw!r}", where,
                            'write e.g. solvers = ["greedy", "highs"]')
    profiles = []
    for text in raw:
        path = Path(text)
        try:
            profile = load_profile(base_dir / path if path.suffix and not path.is_absolute() else text)
        except UamoptError as exc:
            raise type(exc)(exc.what, f"{where} solvers", exc.fix) from None
        if time_limit_s is not None:
            profile = replace(profile, time_limit_s=time_limit_s)
        profiles.append(profile)
    names = [p.name for p in profiles]
    if len(set(names)) != len(names):
        raise ScenarioError(f"two solver profiles share a name: {names}", where, "list each profile once")
    return tuple(profiles)


def _scenario(base: Path, overrides: list[str], where: str, key: str | None = None):
    from uamopt.scenario import load_scenario

    try:
        return load_scenario(base, overrides)
    except ScenarioError as exc:
        place = f"{where} [grid] \"{key}\"" if key else where
        raise ScenarioError(exc.what, place, exc.fix) from None


def load_sweep(path: str | Path, small: bool = False) -> SweepSpec:
    """Parse and validate a sweep file; every case's scenario is built (and so checked) here.

    Parameters
    ----------
    path : str or Path
        The sweep TOML file.
    small : bool
        Apply the file's ``[small]`` table (the fast version the tests run).

    Raises
    ------
    ScenarioError, UamoptError
        Unknown key (in the file or a scenario key in ``[set]``/``[grid]``), empty grid, bad
        stage, seeds or solvers, a case whose scenario is invalid.
    """
    expect_path(path, "path", "load_sweep")
    expect(small, bool, "small", "load_sweep")
    from uamopt.shipped import scenario_path

    path = Path(scenario_path(path))  # a shipped sweep's name (variants/speed), or models/... anywhere
    where = str(path)
    raw = _read(path)
    unknown = sorted(set(raw) - FILE_KEYS)
    if unknown:
        raise ScenarioError(f"unknown key '{unknown[0]}'", where, f"a sweep file takes {', '.join(sorted(FILE_KEYS))}")
    _check_small(raw, where)
    limit = _max_cases(raw, where)
    if small:
        if "small" not in raw:
            raise ScenarioError("the sweep file has no [small] table", where, "add [small] overrides or drop --small")
        raw = _apply_small(raw, where)
    name = raw.get("name", path.stem)
    if not isinstance(name, str):
        raise ScenarioError(f"name must be a string, got {name!r}"[:200], where, 'write e.g. name = "speed"')
    if not isinstance(raw.get("base"), str):
        raise ScenarioError("missing key 'base'", where, 'name the base scenario, e.g. base = "../paper_case.toml"')
    base = (path.parent / raw["base"]).resolve()
    stage = raw.get("stage", "schedule")
    if stage not in STAGES:
        raise ScenarioError(f"unknown stage {stage!r}", where, f"use one of {', '.join(STAGES)}")
    time_limit = _time_limit(raw.get("time_limit_s"), where)
    if stage == "schedule":
        solvers = _profiles(raw.get("solvers", ["greedy"]), path.parent, None if time_limit is None else float(time_limit), where)
        seeds = _seeds(raw.get("seeds", [0]), where)
    else:
        for key in ("solvers", "seeds", "time_limit_s"):
            if key in raw:
                raise ScenarioError(f"'{key}' applies to stage = \"schedule\" only", where,
                                    "remove it or set stage = \"schedule\"")
        solvers, seeds = (), ()
    fixed = _table(raw, "set", where)
    grid = _table(raw, "grid", where)
    if not grid:
        raise ScenarioError("empty grid: no [grid] lists", where, 'add a [grid] table, e.g. "schedule.flights" = [60, 120]')
    for key, values in grid.items():
        if not isinstance(values, list):
            raise ScenarioError(f"[grid] \"{key}\" must be a list of values, got {values!r}"[:200], where,
                                f"write \"{key}\" = [{toml_value(values)}] (a list, even of one value)")
        if not values:
            raise ScenarioError(f"empty grid: [grid] \"{key}\" has no values", where,
                                f"give \"{key}\" a non-empty list of values")
        if len({toml_value(v) for v in values}) != len(values):
            raise ScenarioError(f"[grid] \"{key}\" repeats a value", where, "list each value once")
        if key in fixed:
            raise ScenarioError(f"'{key}' is both in [set] and in [grid]", where, "keep it in one of them")
    _check_size(grid, limit, max(1, len(solvers) * len(seeds)), where)
    figure = raw.get("figure")
    if figure is not None:
        from uamopt.plotting.sweeps import KEYS

        if figure not in KEYS:
            raise ScenarioError(f"unknown figure {figure!r}", where, f"use one of {', '.join(KEYS)}, or remove it")
        if KEYS[figure] not in grid:
            raise ScenarioError(f"figure {figure!r} needs \"{KEYS[figure]}\" in [grid]", where, "sweep that key or remove it")
    fixed_overrides = [f"{k}={toml_value(v)}" for k, v in fixed.items()]
    for key, value in fixed.items():  # name the faulty key before trying combinations
        _scenario(base, [f"{key}={toml_value(value)}"], f"{where} [set] \"{key}\"")
    for key, values in grid.items():
        _scenario(base, [*fixed_overrides, f"{key}={toml_value(values[0])}"], where, key)
    cases = []
    for index, combo in enumerate(itertools.product(*grid.values())):
        values = dict(zip(grid, combo, strict=True))  # combo is one value per key (product)
        overrides = tuple(fixed_overrides + [f"{k}={toml_value(v)}" for k, v in values.items()])
        shown = ", ".join(f"{k} = {toml_value(v)}" for k, v in values.items())
        cases.append(Case(index, case_id(overrides), values, overrides,
                          _scenario(base, list(overrides), f"{where} case {shown}")))
    return SweepSpec(path=path, name=name, base=base, stage=stage, solvers=solvers, seeds=seeds,
                     fixed=fixed, grid=grid, cases=tuple(cases), time_limit_s=time_limit, figure=figure, small=small)
