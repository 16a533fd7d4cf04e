"""A sweep's results folder: written so that a kill at any moment leaves it readable.

::

    DIR/sweep.json              what the folder's sweep is (base scenario hash, stage, [set], solvers)
    DIR/parts/<case>-<k>.parquet  one file per finished case (its rows), written once, never rewritten
    DIR/results.parquet         every row of the current sweep in table order, rebuilt from the parts

Every file is written to a temporary name in its own folder, flushed to disk and renamed over its
final name (``os.replace`` is atomic), so a part either exists whole or not at all. Re-running a
sweep reads the parts, runs only the rows they lack and rebuilds ``results.parquet``; nothing in
the folder is ever deleted. A folder that is not a sweep's, holds another sweep, or has an
unreadable file is refused before anything runs.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from pathlib import Path

from uamopt.errors import UamoptError

MANIFEST = "sweep.json"
PARTS = "parts"
RESULTS = "results.parquet"

#: column -> pandas dtype, in table order (the swept keys follow ``case``)
HEAD = {"case": "str"}
SCHEDULE = {"solver": "str", "seed": "Int64", "status": "str", "model": "str", "objective_kind": "str", "objective": "float64", "bound": "float64",
            "gap": "float64", "operated": "Int64", "cancelled": "Int64", "total_delay_s": "float64",
            "avg_delay_s": "float64", "verified": "boolean", "seconds": "float64"}
PLAN = {"risk_cost": "float64", "transport_cost": "float64", "length_m": "float64", "n_waypoints": "Int64"}
RISK = {"unsafe_share": "float64", "band_unsafe_share": "float64", "cruise_unsafe_share": "float64",
        "cruise_mean_risk": "float64"}
SIZE = {"flights": "Int64", "aircraft": "Int64", "conflicting_pairs": "Int64"}
TAIL = {"error": "str", "uamopt_version": "str"}
TIMING = ("seconds",)


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
        import uamopt

        return uamopt.__version__


def atomic_write(path: Path, write) -> None:
    """Call ``write(tmp_path)``, flush the file to disk and rename it over ``path``."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp's 0600 would make results private
    try:
        write(Path(tmp))
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    try:  # make the rename itself durable
        dfd = os.open(path.parent, os.O_RDONLY)
        try:
            os.fsync(dfd)
        finally:
            os.close(dfd)
    except OSError:
        pass


def row_key(case, solver, seed) -> tuple:
    import pandas as pd

    return (str(case), None if solver is None or pd.isna(solver) else str(solver), None if seed is None or pd.isna(seed) else int(seed))


class ResultsFolder:
    """The folder ``out`` of one sweep; :meth:`check` reads, the writers write atomically."""

    def __init__(self, out: str | Path):
        self.out = Path(out)
        self.parts = self.out / PARTS

    def _corrupt(self, what: str, path: Path, fix: str):
        return UamoptError(f"corrupt results folder: {what}", str(path), fix)

    def check(self, spec):
        """Validate the folder against ``spec`` and return the rows already done (a DataFrame, or
        None when there are none). Writes nothing."""
        import pandas as pd

        if self.out.exists() and not self.out.is_dir():
            raise UamoptError(f"output path is a file: {self.out}", "--out", "give a folder path")
        if not self.out.exists() or not [p for p in self.out.iterdir() if not p.name.startswith(".")]:
            return None
        manifest = self.out / MANIFEST
        if not manifest.is_file():
            raise UamoptError(f"{self.out} is not a sweep results folder (no {MANIFEST})", "--out",
                              "give an empty or new folder; nothing was changed")
        try:
            old = json.loads(manifest.read_text(encoding="utf-8"))
            if not isinstance(old, dict) or old.get("uamopt_sweep") != 1:
                raise ValueError("not a sweep manifest")
        except (ValueError, UnicodeDecodeError) as exc:
            raise self._corrupt(f"{MANIFEST} is unreadable ({exc})", manifest, "restore it, or use a new --out") from None
        new = spec.manifest()
        for key, label in (("base_sha256", "the base scenario"), ("stage", "the stage"), ("small", "--small"),
                           ("set", "the [set] overrides")):
            if old.get(key) != new[key]:
                raise UamoptError(f"the results folder holds another sweep ({label} differs)", str(self.out),
                                  "use a new --out for this sweep; nothing was changed")
        for name, text in new["solvers"].items():
            if name in old.get("solvers", {}) and old["solvers"][name] != text:
                raise UamoptError(f"the results folder holds solver profile '{name}' with other settings", str(self.out),
                                  "use a new --out, or give the changed profile another name")
        frames = []
        for part in sorted(self.parts.glob("*.parquet")) if self.parts.is_dir() else []:
            try:
                frame = pd.read_parquet(part)
            except Exception as exc:  # noqa: BLE001 - any unreadable file
                raise self._corrupt(f"part {part.name} is unreadable ({type(exc).__name__})", part,
                                    "delete that file to recompute its case; nothing was changed") from None
            if not {"case", "solver", "seed", "status"} <= set(frame.columns):
                raise self._corrupt(f"part {part.name} lacks the key columns", part,
                                    "delete that file to recompute its case; nothing was changed")
            frames.append(frame)
        return pd.concat(frames, ignore_index=True) if frames else None

    def start(self, spec) -> None:
        """Create the folder and write (or extend with new solvers) its manifest."""
        self.parts.mkdir(parents=True, exist_ok=True)
        manifest = self.out / MANIFEST
        doc = spec.manifest()
        if manifest.is_file():
            old = json.loads(manifest.read_text(encoding="utf-8"))
            doc["solvers"] = {**old.get("solvers", {}), **doc["solvers"]}
        atomic_write(manifest, lambda p: p.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8"))

    def write_part(self, case_id: str, frame) -> Path:
        """Save one finished case's rows as a new part (a name no other part has)."""
        keys = ",".join(f"{s}:{d}" for s, d in zip(frame["solver"].astype(object), frame["seed"].astype(object)))
        path = self.parts / f"{case_id}-{hashlib.sha1(keys.encode()).hexdigest()[:8]}.parquet"
        atomic_write(path, lambda p: frame.to_parquet(p, index=False))
        return path

    def write_results(self, frame) -> Path:
        path = self.out / RESULTS
        atomic_write(path, lambda p: frame.to_parquet(p, index=False))
        return path
