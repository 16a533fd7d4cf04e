"""The files shipped inside the package, found with :mod:`importlib.resources`: one copy serves a
checkout and an installed wheel alike.

- ``uamopt/models/``: the scenarios (``paper_case.toml``, ``helsinki.toml``, ``dsm_example.toml`` and
  its ``data/``, the ``benchmark_*.toml`` ladder) and the sweep files of ``variants/``;
- ``uamopt/solvers/profiles/``: the solver profiles (``highs.toml``, ``rolling.toml``, ...).

A checkout's top-level ``models/`` and ``solvers/`` are symbolic links to these two folders (see
pyproject.toml), so ``models/paper_case.toml`` and ``solvers/highs.toml`` name the same files in a
checkout; elsewhere (an installed wheel, another working folder) :func:`scenario_path` and
:func:`profile_path` find the shipped copy of such a name.

>>> scenario_path("paper_case") == models_dir() / "paper_case.toml"
True
>>> profile_path("rolling") == profiles_dir() / "rolling.toml"
True
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path, PurePosixPath

from uamopt.errors import UamoptError


def package_dir(*parts: str) -> Path:
    """A folder of the installed package, as a path on the file system."""
    root = files("uamopt").joinpath(*parts)
    if not isinstance(root, Path):  # a zipped install (zipimport): no folder to read a scenario's rasters from
        raise UamoptError("the package's shipped files are not on the file system", f"uamopt/{'/'.join(parts)}",
                          "install uamopt unzipped (pip install uamopt)")
    return root


def models_dir() -> Path:
    """``uamopt/models``: the shipped scenarios and sweep files (the checkout's ``models/``)."""
    return package_dir("models")


def profiles_dir() -> Path:
    """``uamopt/solvers/profiles``: the shipped solver profiles (the checkout's ``solvers/``)."""
    return package_dir("solvers", "profiles")


def _shipped(text: str, folder: str, base: Path) -> Path | None:
    """The file under ``base`` that ``text`` names as ``NAME``, ``NAME.toml``, ``folder/NAME.toml``
    or with sub-folders (``variants/speed``); None when there is none."""
    parts = PurePosixPath(text.replace("\\", "/")).parts
    if parts[:1] == (folder,):
        parts = parts[1:]
    if not parts or ".." in parts or parts[0] == "/":
        return None
    name = PurePosixPath(*parts)
    if not name.suffix:
        name = name.with_name(name.name + ".toml")
    if name.suffix != ".toml":
        return None
    candidate = base.joinpath(*name.parts)
    return candidate if candidate.is_file() else None


def _resolve(text, folder: str, base) -> str | Path:
    """``text`` when it is a file or names no shipped one under ``base()``, else the shipped file."""
    if not isinstance(text, (str, Path)):
        return text
    try:
        if Path(text).is_file():
            return text
        return _shipped(str(text), folder, base()) or text
    except (OSError, ValueError, UamoptError):  # a name no file system takes, a zipped install: not ours
        return text


def scenario_path(text: str | Path) -> str | Path:
    """The scenario or sweep file a command names: ``text`` itself when it is a file (or names no
    shipped file: the loader then says what is wrong with it), else the shipped one it names:
    ``paper_case``, ``paper_case.toml``, ``models/paper_case.toml``, ``variants/speed``."""
    return _resolve(text, "models", models_dir)


def profile_path(text: str | Path) -> str | Path:
    """The solver profile a name or path means: ``text`` itself when it is a file (or names no
    shipped profile), else the shipped profile it names: ``rolling``, ``rolling.toml``,
    ``solvers/rolling.toml``."""
    return _resolve(text, "solvers", profiles_dir)
