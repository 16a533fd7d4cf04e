"""Scenario input: TOML files, ``--set KEY=VALUE`` overrides, and the one-line error of a value
the schema (:mod:`uamopt.scenario.schema`) refuses, naming the key, its meaning and its range.

Reading: ``load_scenario(path, overrides=["grid.cell=[10,10,10]"])``. Overrides use TOML value
syntax with dotted keys (docs/interfaces.md); a value that is not valid TOML is taken as a string, so
``--set city.source=osm`` works without quotes.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Sequence
from contextvars import ContextVar
from pathlib import Path
from typing import Annotated, Any

from pydantic import BaseModel, ValidationError

from uamopt.bounds import Range, parse_error
from uamopt.checks import expect_path
from uamopt.errors import ScenarioError
from uamopt.scenario.schema import Scenario


def parse_override(item: str) -> tuple[list[str], Any]:
    """Split ``a.b.c=VALUE`` into the key path and the TOML-parsed value."""
    if "=" not in item:
        raise ScenarioError(f"override '{item}' has no '='", "--set", "write KEY=VALUE, e.g. grid.cell=[10,10,10]")
    key, _, text = item.partition("=")
    key = key.strip()
    if not key or any(not part for part in key.split(".")):
        raise ScenarioError(f"override '{item}' has an empty key", "--set", "write KEY=VALUE, e.g. grid.cell=[10,10,10]")
    try:
        value = tomllib.loads(f"v = {text.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = text.strip()  # bare words such as osm or helsinki
    except ValueError as exc:  # an integer of more than 4300 digits (Python's int-string limit)
        raise ScenarioError(f"the value of '{key}' holds {parse_error(exc)}", "--set",
                            f"'{key}' takes {_range_text(key.split('.')) or 'a shorter value'}") from None
    except RecursionError:
        raise ScenarioError(f"the value of '{key}' is nested too deeply", "--set", "give a flat value, e.g. [10,10,10]") from None
    return key.split("."), value


def apply_overrides(raw: dict, overrides: list[str]) -> dict:
    for item in overrides:
        path, value = parse_override(item)
        node = raw
        for part in path[:-1]:
            child = node.get(part)
            if child is None:
                child = node[part] = {}
            if not isinstance(child, dict):
                raise ScenarioError(
                    f"'{'.'.join(path)}' goes below '{part}', which is not a section", "--set", "check the key"
                )
            node = child
        node[path[-1]] = value
    return raw


def _field_info(loc: tuple):
    """The pydantic FieldInfo at a validation-error location, or None."""
    model: Any = Scenario
    info = None
    for part in loc:
        if not isinstance(part, str) or model is None:
            continue
        info = model.model_fields.get(part)
        if info is None:
            return None
        ann = info.annotation
        model = ann if isinstance(ann, type) and issubclass(ann, BaseModel) else None
    return info


def _section_keys(loc: tuple) -> list[str]:
    model: Any = Scenario
    for part in loc[:-1]:
        field = model.model_fields.get(part) if isinstance(part, str) else None
        if field is None or not (isinstance(field.annotation, type) and issubclass(field.annotation, BaseModel)):
            return []
        model = field.annotation
    return sorted(model.model_fields)


def _ranges_of(annotation) -> list[Range] | None:
    """The ranges of a numeric key's annotation (one per element of a tuple), None if not numeric."""
    import types
    import typing

    import annotated_types as at

    args, origin = typing.get_args(annotation), typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType, tuple):  # X | None; a tuple's elements (tuple[X, ...] too)
        found = [r for a in args if a not in (type(None), Ellipsis) for r in (_ranges_of(a) or [])]
        return found or None
    if origin is not Annotated or args[0] not in (int, float):
        return None
    meta = [m for item in annotation.__metadata__ for m in getattr(item, "metadata", [item])]  # Field(...) holds its own
    b = {kind.__name__.lower(): getattr(m, kind.__name__.lower()) for m in meta for kind in (at.Ge, at.Gt, at.Le, at.Lt)
         if isinstance(m, kind)}
    return [Range(b.get("gt", b.get("ge", -math.inf)), b.get("lt", b.get("le", math.inf)), lo_open="gt" in b,
                  hi_open="lt" in b, integer=args[0] is int)]


def _field_annotation(model, name: str):
    """A field's annotation with its Field constraints (pydantic keeps them apart from the type)."""
    info = model.model_fields[name]
    if info.annotation in (int, float) and info.metadata:
        return Annotated[info.annotation, *info.metadata]
    return info.annotation


def key_ranges() -> dict[str, str]:
    """Every numeric scenario key (dotted; a vertiport's ``network.vertiports.x``) and its range, as
    text: the key table's boundary check, listed in docs/interfaces.md.

    >>> key_ranges()["schedule.aircraft"], key_ranges()["grid.cell"]
    ('an integer in [1, 1000000000]', '(0, 1e+06]')
    """
    out: dict[str, str] = {}

    def walk(model, prefix: str) -> None:
        for name in model.model_fields:
            ann = _field_annotation(model, name)
            sub = [a for a in (ann, *getattr(ann, "__args__", ())) for a in (a, *getattr(a, "__args__", ()))
                   if isinstance(a, type) and issubclass(a, BaseModel)]
            if sub:
                walk(sub[0], f"{prefix}{name}.")
                continue
            ranges = _ranges_of(ann)
            if ranges:
                texts = list(dict.fromkeys(r.interval() for r in ranges))
                kind = "an integer in " if ranges[0].integer else ""
                out[prefix + name] = kind + (texts[0] if len(texts) == 1 else ", ".join(r.interval() for r in ranges))

    walk(Scenario, "")
    return out


def _range_text(path: list[str]) -> str:
    return key_ranges().get(".".join(path), "")


def _brief(text: str, limit: int = 80) -> str:
    """``text``, cut to ``limit`` characters for an error line."""
    return text if len(text) <= limit else f"{text[:limit - 1]}… ({len(text):,} characters)"


def validation_error(exc: ValidationError, source: str, overrides: Sequence[str] = ()) -> ScenarioError:
    """pydantic's error as one line naming the key, its meaning and its range: ``source`` is where the
    values came from (the file, ``Scenario(...)``), or the ``--set`` item that set the key."""
    err = exc.errors()[0]
    loc = tuple(err["loc"])
    key = ".".join(str(p) for p in loc if not isinstance(p, int)) or "<root>"
    where = source
    for item in overrides:
        if item.partition("=")[0].strip() and key.startswith(item.partition("=")[0].strip()):
            where = f"--set {_brief(item)}"
    if err["type"] == "extra_forbidden":
        keys = _section_keys(loc)
        section = ".".join(str(p) for p in loc[:-1]) or "top level"
        fix = f"valid keys in [{section}] are {', '.join(keys)}" if keys else "remove it"
        return ScenarioError(f"unknown key '{key}'", where, fix)
    value = err.get("input")
    shown = f" {_brief(repr(value))}" if not isinstance(value, (dict, list, tuple)) or len(repr(value)) < 60 else ""
    msg = err["msg"].replace("Value error, ", "")
    info = _field_info(loc)
    fix = f"'{key}' is {info.description}" if info is not None and info.description else "see uamopt/scenario/schema.py"
    valid = _range_text([str(p) for p in loc if not isinstance(p, int)])
    if valid and err["type"] not in ("literal_error", "missing"):
        fix += f"; it takes {valid}"
    return ScenarioError(f"invalid value{shown} for '{key}': {msg}", where, fix)


def checked_overrides(overrides, function: str) -> list[str]:
    """``overrides`` (None, or a list or tuple of ``"KEY=VALUE"`` strings) as a list; else ``TypeError``
    naming ``function``'s ``overrides`` (a bare string would be read one character at a time)."""
    if overrides is None:
        return []
    rule = f'{function}(): overrides must be a list or tuple of "KEY=VALUE" strings (e.g. ["grid.cell=[10,10,10]"]) or None'
    if not isinstance(overrides, (list, tuple)):
        raise TypeError(f"{rule}, got {type(overrides).__name__}")
    for n, item in enumerate(overrides):
        if not isinstance(item, str):
            raise TypeError(f"{rule}, got {type(item).__name__} {str(item)[:40]!r} as item {n}")
    return list(overrides)


#: where the values being validated came from, for :func:`validation_error`: pydantic calls
#: ``Scenario.__init__`` from ``model_validate`` too (a model with its own ``__init__``), and that
#: ``__init__`` turns pydantic's error into the one line; outside :func:`validate`, ``Scenario(...)``
_SOURCE: ContextVar[tuple[str, tuple[str, ...]]] = ContextVar("scenario_source", default=("Scenario(...)", ()))


def source_of_values() -> tuple[str, tuple[str, ...]]:
    """(source, overrides) of the scenario being validated (``Scenario(...)`` when built directly)."""
    return _SOURCE.get()


def validate(raw: dict, source: str, base_dir: Path, overrides: list[str]) -> Scenario:
    token = _SOURCE.set((source, tuple(overrides)))
    try:
        scenario = Scenario.model_validate(raw)
    except ValidationError as exc:  # (Scenario.__init__ raises the ScenarioError itself)
        raise validation_error(exc, source, overrides) from None
    finally:
        _SOURCE.reset(token)
    scenario._base_dir = base_dir
    scenario._source = source
    return scenario


def load_scenario(path: str | Path, overrides: list[str] | None = None) -> Scenario:
    """Load, override and validate a scenario TOML file.

    Parameters
    ----------
    path : str or Path
        The scenario file (``models/paper_case.toml``).
    overrides : list or tuple of str, optional
        ``KEY=VALUE`` items, dotted keys, TOML values (``grid.cell=[10,10,10]``); None: none.

    Raises
    ------
    ScenarioError
        Missing or malformed file, unknown key, value out of range.
    TypeError
        ``path`` is not a path, ``overrides`` not a list or tuple of strings.
    """
    expect_path(path, "path", "load_scenario")
    overrides = checked_overrides(overrides, "load_scenario")
    from uamopt.shipped import scenario_path

    path = Path(scenario_path(path))  # a shipped scenario's name, or models/... outside the checkout
    if not path.is_file():
        raise ScenarioError(f"scenario file not found: {path}", str(path),
                            "give the path of a .toml scenario, e.g. models/paper_case.toml")
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"malformed TOML: {exc}", str(path), "fix the syntax at that line") from None
    except UnicodeDecodeError:  # (a ValueError: before the int-string limit below)
        raise ScenarioError("scenario is not UTF-8 text", str(path), "save it as UTF-8 TOML") from None
    except RecursionError:
        raise ScenarioError("the scenario is nested too deeply to read", str(path),
                            "a scenario has sections of keys; flatten the nested arrays or tables") from None
    except OSError as exc:
        raise ScenarioError(f"cannot read the scenario: {exc.strerror or exc}", str(path),
                            "check that the file is readable (permissions, a disk error)") from None
    except ValueError as exc:  # an integer of more than 4300 digits (Python's int-string limit)
        raise ScenarioError(f"the scenario holds {parse_error(exc)}", str(path),
                            "every number of a scenario has a range (docs/interfaces.md); write it in range") from None
    raw = apply_overrides(raw, overrides)
    return validate(raw, str(path), path.resolve().parent, overrides)
