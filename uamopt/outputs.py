"""Writing results: all-or-nothing output folders and JSON helpers.

A command writes into a private staging folder and moves the finished files into ``--out`` only
when every one of them is complete, so a failure or an interrupt leaves nothing half-written.
"""

from __future__ import annotations

import json
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from uamopt.errors import UamoptError


def check_out_dir(out_dir: str | Path) -> Path:
    """Validate ``--out`` before any work is done."""
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise UamoptError(f"output path is a file: {out}", "--out", "give a folder path")
    return out


@contextmanager
def staged_output(out_dir: str | Path) -> Iterator[Path]:
    """Yield a staging folder; on success move its files into ``out_dir``, else discard them."""
    out = check_out_dir(out_dir)
    stage = Path(tempfile.mkdtemp(prefix="uamopt-stage-"))
    try:
        yield stage
        try:
            out.mkdir(parents=True, exist_ok=True)
            for item in sorted(stage.iterdir()):
                target = out / item.name
                if target.is_dir() and not target.is_symlink():
                    shutil.rmtree(target)
                shutil.move(str(item), str(target))
        except OSError as exc:
            raise UamoptError(f"cannot write the results: {exc.strerror or exc}", str(out), "check the folder's path and permissions") from None
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return None
    if isinstance(value, Path):
        return str(value)
    return value


def write_json(path: str | Path, data: Any) -> None:
    """Write ``data`` as indented JSON (numpy values converted, NaN/inf as null)."""
    Path(path).write_text(json.dumps(_jsonable(data), indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
