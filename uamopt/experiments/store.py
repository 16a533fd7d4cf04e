"""A sweep's results folder: written so that a kill at any moment leaves it readable.

::

    DIR/sweep.json              what the folder's sweep is (base scenario hash, stage, [set], solvers)
    DIR/parts/<case>-<k>.parquet  one file per finished case (its rows), written once, never rewritten
    DIR/results.parquet         every row of the current sweep in table order, rebuilt from the parts

Every file is written to a temporary name in its own folder, flushed to disk and renamed over its
final name (``os.replace`` is atomic), so a part either exists whole or not at all. Re-running a
sweep reads the parts, runs only the rows they lack and rebuilds ``results.parquet``; nothing in
the folder is ever deleted. A folder that is not a sweep's, holds another sweep, has an
unreadable or malformed ``sweep.json``, or a ``parts`` that is no folder, is refused before
anything runs.

Every part is read through one schema (:func:`part_problem`): its name ``<case>-<k>.parquet``,
the key columns, each known column's type, the ranges (seeds 0 to 2³¹ − 1, counts ≥ 0, shares in
[0, 1], a known status), rows of its own case only and one row per case × solver × seed. A part
that breaks it, and every part holding a row that conflicts with another part's row for the same
case, solver and seed (which of them is right is unknown), is set aside: renamed
``NAME.parquet.set-aside`` (``.set-aside-2``, ... when taken), never deleted, reported with a
:class:`SetAsideWarning`, and its rows are recomputed. An identical copy of a row is read once.

A full disk (ENOSPC, EDQUOT) or a file-size limit (EFBIG) during any write is one
:class:`~uamopt.errors.UamoptError` naming the file, the space it needs and the space free; the
temporary file is removed, every file written before it is kept.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import warnings
from pathlib import Path

from uamopt.errors import UamoptError
from uamopt.outputs import NO_SPACE, atomic_write, file_size, out_of_space, size_text

MANIFEST = "sweep.json"
PARTS = "parts"
RESULTS = "results.parquet"

#: column -> pandas dtype, in table order (the swept keys follow ``case``)
HEAD = {"case": "str"}
SCHEDULE = {"solver": "str", "seed": "Int64", "status": "str", "termination": "str", "proved_for": "str",
            "model": "str", "objective_kind": "str", "objective": "float64",
            "bound": "float64", "gap": "float64", "operated": "Int64", "cancelled": "Int64", "total_delay_s": "float64",
            "avg_delay_s": "float64", "verified": "boolean", "seconds": "float64"}
PLAN = {"risk_cost": "float64", "transport_cost": "float64", "length_m": "float64", "n_waypoints": "Int64"}
RISK = {"unsafe_share": "float64", "band_unsafe_share": "float64", "cruise_unsafe_share": "float64",
        "cruise_mean_risk": "float64"}
SIZE = {"flights": "Int64", "aircraft": "Int64", "conflicting_pairs": "Int64"}
TAIL = {"error": "str", "uamopt_version": "str"}
TIMING = ("seconds",)
KEYS = ("case", "solver", "seed", "status")
SET_ASIDE = ".set-aside"
PART_NAME = re.compile(r"([0-9a-f]{12})-[0-9a-f]{8}\.parquet")
MANIFEST_MAX_BYTES = 16 * 2**20
COUNTS = ("operated", "cancelled", "flights", "aircraft", "conflicting_pairs", "n_waypoints")
SHARES = ("unsafe_share", "band_unsafe_share", "cruise_unsafe_share")
NOT_NEGATIVE = ("seconds", "gap", "length_m", "cruise_mean_risk")


class SetAsideWarning(UserWarning):
    """A part of a results folder broke the schema and was renamed; its rows are recomputed."""


def columns(stage: str) -> dict:
    """The result columns (without the swept keys) of a stage, with their dtypes."""
    cols = dict(SCHEDULE)
    if stage != "risk":
        cols |= PLAN
    cols |= RISK
    if stage == "schedule":
        cols |= SIZE
    return cols | TAIL


def typed_frame(rows: list[dict], cols: dict):
    """A DataFrame of ``rows`` with exactly ``cols`` (missing values NA) in their dtypes."""
    import pandas as pd

    frame = pd.DataFrame.from_records(rows, columns=list(cols))
    for name, dtype in cols.items():
        if dtype == "str":
            frame[name] = frame[name].astype(object).where(frame[name].notna(), None).astype("string")
        else:
            frame[name] = frame[name].astype(dtype)
    return frame


def version() -> str:
    try:
        from importlib.metadata import version as _v

        return _v("uamopt")
    except Exception:  # noqa: BLE001 - not installed as a distribution
        from uamopt import __version__

        return __version__


def _column_problem(series, dtype: str) -> str | None:
    """Why ``series`` cannot be a column of ``dtype`` (None when it can); an all-empty column can."""
    from pandas.api import types

    values = series.dropna()
    if len(values) == 0:
        return None
    if dtype == "str":
        return None if all(isinstance(v, str) for v in values) else "is not text"
    if types.is_bool_dtype(series) and dtype != "boolean":
        return "is true/false, not a number"
    if dtype == "Int64":
        return None if types.is_integer_dtype(series) else "is not a whole number"
    if dtype == "float64":
        return None if types.is_numeric_dtype(series) else "is not a number"
    if dtype == "boolean":
        return None if types.is_bool_dtype(series) else "is not true or false"
    raise AssertionError(dtype)


def part_problem(frame, stage: str, name: str) -> str | None:
    """Why the part ``name`` holding ``frame`` breaks the results schema of ``stage`` (None when
    it does not): its name, the key columns, the type of each known column (others are ignored),
    the ranges, rows of its own case only, one row per case × solver × seed."""
    from uamopt.schedule.model import STATUSES
    from uamopt.solvers.options import SEED_MAX

    match = PART_NAME.fullmatch(name)
    if match is None:
        return "its name is not <case>-<k>.parquet"
    if frame.columns.duplicated().any():
        return "a column name repeats"
    missing = [c for c in KEYS if c not in frame.columns]
    if missing:
        return f"it lacks the column {missing[0]}"
    if len(frame) == 0:
        return "it holds no rows"
    for column, dtype in ({"case": "str"} | columns(stage)).items():
        problem = _column_problem(frame[column], dtype) if column in frame.columns else None
        if problem:
            return f"{column} {problem}"
    if frame["case"].isna().any() or (frame["case"] != match.group(1)).any():
        return f"it holds rows of another case than {match.group(1)}"
    solver, seed = frame["solver"], frame["seed"]
    if stage == "schedule":
        if solver.isna().any() or (solver == "").any():
            return "a row has no solver"
        if seed.isna().any() or not seed.between(0, SEED_MAX).all():
            return f"seed is not a whole number from 0 to {SEED_MAX}"
    elif solver.notna().any() or seed.notna().any():
        return f"a row has a solver or seed, which stage {stage} has not"
    status = frame["status"]
    words = (*STATUSES, "ok", "error")  # a solver's status, a stage done, a case that failed
    if status.isna().any() or not status.isin(words).all():
        bad = status[~status.isin(words)].iloc[0]
        return f"status {bad!r} is not one of {', '.join(words)}"[:200]
    for column in COUNTS + NOT_NEGATIVE:
        if column in frame.columns and (frame[column].dropna() < 0).any():
            return f"{column} is negative"
    for column in SHARES:
        if column in frame.columns and not frame[column].dropna().between(0.0, 1.0).all():
            return f"{column} is not a share from 0 to 1"
    keys = [row_key(c, s, d) for c, s, d in zip(frame["case"], solver, seed, strict=True)]
    if len(set(keys)) != len(keys):
        return "it holds two rows for the same case, solver and seed"
    return None


def _manifest_problem(doc) -> str | None:
    """Why ``doc`` (a parsed sweep.json) is not a manifest (None when it is one)."""
    from uamopt.experiments.spec import STAGES

    if not isinstance(doc, dict):
        return "not a JSON object"
    if type(doc.get("uamopt_sweep")) is not int or doc["uamopt_sweep"] != 1:
        return "not a sweep manifest: uamopt_sweep is not 1"
    for key in ("name", "base_sha256"):
        if not isinstance(doc.get(key), str):
            return f"{key} is not a string"
    if doc.get("stage") not in STAGES:
        return f"stage is not one of {', '.join(STAGES)}"
    if not isinstance(doc.get("small"), bool):
        return "small is not true or false"
    for key in ("set", "solvers"):
        table = doc.get(key)
        if not isinstance(table, dict) or not all(isinstance(k, str) and isinstance(v, str) for k, v in table.items()):
            return f"{key} is not an object of strings"
    return None


def row_key(case, solver, seed) -> tuple:
    import pandas as pd

    return (str(case), None if solver is None or pd.isna(solver) else str(solver),
            None if seed is None or pd.isna(seed) else int(seed))


class ResultsFolder:
    """The folder ``out`` of one sweep; :meth:`check` reads, the writers write atomically."""

    def __init__(self, out: str | Path):
        self.out = Path(out)
        self.parts = self.out / PARTS
        self._manifest: dict | None = None  # the folder's validated sweep.json, read by check

    def _corrupt(self, what: str, path: Path, fix: str):
        return UamoptError(f"corrupt results folder: {what}", str(path), fix)

    def _read_manifest(self, manifest: Path) -> dict:
        try:
            if manifest.stat().st_size > MANIFEST_MAX_BYTES:
                raise ValueError(f"larger than {size_text(MANIFEST_MAX_BYTES)}")
            doc = json.loads(manifest.read_text(encoding="utf-8"))
        except RecursionError:
            problem = "nested too deeply"
        except (ValueError, UnicodeDecodeError) as exc:
            problem = " ".join(str(exc).split())[:200]
        except OSError as exc:
            problem = exc.strerror or type(exc).__name__
        else:
            problem = _manifest_problem(doc)
            if problem:
                raise self._corrupt(f"{MANIFEST} is malformed ({problem})", manifest,
                                    "restore it, or use a new --out; nothing was changed")
        if problem:
            raise self._corrupt(f"{MANIFEST} is unreadable ({problem})", manifest,
                                "restore it, or use a new --out; nothing was changed")
        return doc

    def check(self, spec):
        """Validate the folder against ``spec`` and return ``(rows, broken)``: the rows already
        done (a DataFrame, or None when there are none) and the parts that break the schema,
        ``[(path, why), ...]``, which :meth:`start` sets aside. Writes nothing.

        Raises
        ------
        UamoptError
            ``out`` is a file, a folder that is not a sweep's or is another sweep's, its
            sweep.json is unreadable or malformed, its ``parts`` is not a folder.
        """
        if self.out.exists() and not self.out.is_dir():
            raise UamoptError(f"output path is a file: {self.out}", "--out", "give a folder path")
        if not self.out.exists() or not [p for p in self.out.iterdir() if not p.name.startswith(".")]:
            return None, []
        manifest = self.out / MANIFEST
        if not manifest.is_file():
            raise UamoptError(f"{self.out} is not a sweep results folder (no {MANIFEST})", "--out",
                              "give an empty or new folder; nothing was changed")
        old = self._read_manifest(manifest)
        new = spec.manifest()
        for key, label in (("base_sha256", "the base scenario"), ("stage", "the stage"), ("small", "--small"),
                           ("set", "the [set] overrides")):
            if old.get(key) != new[key]:
                raise UamoptError(f"the results folder holds another sweep ({label} differs)", str(self.out),
                                  "use a new --out for this sweep; nothing was changed")
        for name, text in new["solvers"].items():
            if name in old["solvers"] and old["solvers"][name] != text:
                raise UamoptError(f"the results folder holds solver profile '{name}' with other settings", str(self.out),
                                  "use a new --out, or give the changed profile another name")
        if os.path.lexists(self.parts) and not self.parts.is_dir():
            raise self._corrupt(f"{PARTS} is not a folder", self.parts,
                                f"move that file away (the finished cases are kept in the folder {PARTS}); nothing was changed")
        self._manifest = old
        return self.read_parts(spec.stage)

    def read_parts(self, stage: str):
        """``(rows, broken)`` of the parts (module docstring): the rows of every part that keeps
        the schema, typed, each (case, solver, seed) once, and ``[(path, why), ...]`` of the others."""
        import pandas as pd

        cols = {"case": "str"} | columns(stage)
        good, broken = [], []
        for part in sorted(self.parts.glob("*.parquet")) if self.parts.is_dir() else []:
            if not part.is_file():
                broken.append((part, "not a file"))
                continue
            try:
                frame = pd.read_parquet(part)
            except Exception as exc:  # noqa: BLE001 - any unreadable file
                broken.append((part, f"unreadable: {type(exc).__name__}"))
                continue
            problem = part_problem(frame, stage, part.name)
            if problem:
                broken.append((part, problem))
            else:
                good.append((part, typed_frame(frame.to_dict("records"), cols)))
        seen: dict = {}  # row key -> (part, row values)
        conflicts: dict = {}  # part -> why
        for part, frame in good:
            values = frame.astype(object).where(frame.notna(), None)
            for row in values.itertuples(index=False):
                key = row_key(row.case, row.solver, row.seed)
                if key not in seen:
                    seen[key] = (part, tuple(row))
                elif seen[key][1] != tuple(row):
                    other = seen[key][0]
                    label = f"case {key[0]}" + (f", solver {key[1]}, seed {key[2]}" if key[1] is not None else "")
                    conflicts.setdefault(part, f"its row for {label} differs from the one in part {other.name}")
                    conflicts.setdefault(other, f"its row for {label} differs from the one in part {part.name}")
        broken += list(conflicts.items())
        frames = [f for p, f in good if p not in conflicts]
        if not frames:
            return None, broken
        rows = pd.concat(frames, ignore_index=True)
        keys = [row_key(c, s, d) for c, s, d in zip(rows["case"], rows["solver"], rows["seed"], strict=True)]
        return rows[~pd.Series(keys).duplicated().to_numpy()].reset_index(drop=True), broken  # identical copies once

    def set_aside(self, broken: list, cases=None) -> list[str]:
        """Rename each broken part to ``NAME.set-aside`` (or ``-2``, ``-3``, ...: never over a
        file) and warn (``cases``: the ids of the sweep's cases, which are recomputed); returns the
        new paths."""
        moved = []
        for part, why in broken:
            target, n = part.with_name(part.name + SET_ASIDE), 2
            while os.path.lexists(target):
                target, n = part.with_name(f"{part.name}{SET_ASIDE}-{n}"), n + 1
            try:
                os.rename(part, target)
            except OSError as exc:
                raise UamoptError(f"cannot set aside the broken part {part} ({why}): {exc.strerror or exc}", str(self.out),
                                  "check the folder's permissions, or move that file away yourself") from None
            match = PART_NAME.fullmatch(part.name)
            then = ("its case is recomputed" if cases is None or (match and match.group(1) in cases)
                    else "its case is not one of this sweep")
            warnings.warn(f"part {part} breaks the results schema ({why}): set aside as {target.name}, {then}",
                          SetAsideWarning, stacklevel=2)
            moved.append(str(target))
        return moved

    def start(self, spec, broken: list = ()) -> list[str]:
        """Create the folder, set the ``broken`` parts aside and write (or extend with new
        solvers) its manifest; returns the set-aside paths."""
        try:
            self.parts.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            if exc.errno in NO_SPACE:
                raise out_of_space(exc, self.parts, 0, where=str(self.out), keep=self._keep()) from None
            raise UamoptError(f"cannot create {self.parts}: {exc.strerror or exc}", str(self.out),
                              "check the folder's path and permissions") from None
        moved = self.set_aside(list(broken), {c.id for c in spec.cases})
        doc = spec.manifest()
        if self._manifest is not None:
            doc["solvers"] = {**self._manifest["solvers"], **doc["solvers"]}
        atomic_write(self.out / MANIFEST, (json.dumps(doc, indent=2) + "\n").encode("utf-8"), where=str(self.out),
                     keep=self._keep())
        self._manifest = doc
        return moved

    def _parts_bytes(self) -> int:
        return sum(file_size(p) for p in self.parts.glob("*.parquet"))

    def _keep(self) -> str:
        """The end of a full disk's fix: what is kept, what a re-run does."""
        saved = len(list(self.parts.glob("*.parquet"))) if self.parts.is_dir() else 0
        if saved == 0:
            return "then re-run the same command (no case had been saved yet)"
        return (f"then re-run the same command: the {saved} finished case{'s' if saved != 1 else ''} saved in {PARTS}/ "
                f"{'are' if saved != 1 else 'is'} kept and only what is missing is computed")

    def write_part(self, case_id: str, frame, remaining: int = 0) -> Path:
        """Save one finished case's rows as a new part (a name no other part has); ``remaining``:
        the cases still to save after it (for the space a full disk's error says is needed)."""
        keys = ",".join(f"{s}:{d}" for s, d in zip(frame["solver"].astype(object), frame["seed"].astype(object), strict=True))
        path = self.parts / f"{case_id}-{hashlib.sha1(keys.encode()).hexdigest()[:8]}.parquet"
        data = frame.to_parquet(None, index=False)
        parts = len(data) * (1 + remaining)
        # this part, the parts after it, and results.parquet, at most about the size of all the parts
        need = parts + self._parts_bytes() + parts
        atomic_write(path, data, need=need, where=str(self.out), keep=self._keep())
        return path

    def write_results(self, frame) -> Path:
        path = self.out / RESULTS
        atomic_write(path, frame.to_parquet(None, index=False), where=str(self.out), keep=self._keep())
        return path
