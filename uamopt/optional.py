"""Optional dependencies: which extra of pyproject.toml brings each, and the one line a missing one gives.

The core (``pip install uamopt``) computes risk fields, plans tracks and networks, generates flights,
schedules them with the heuristics (greedy, ga, soa) and verifies schedules. The rest is in extras::

    pip install 'uamopt[exact]'    # the exact solvers: highs (Pyomo), cpsat, rolling, timeindexed, exact (OR-Tools)
    pip install 'uamopt[all]'      # every extra but the developers' tools

A module that needs one imports it with :func:`need`, which names the extra in a
:class:`MissingExtraError` (a :class:`~uamopt.errors.UamoptError`, so the command line prints it as one
``error: ...`` line and exits with code 2)::

    pyrosm = need("pyrosm", extra="osm", what="reading OpenStreetMap")

>>> print(MissingExtraError("pyrosm", "osm", "reading OpenStreetMap").line())
pyrosm is not installed: reading OpenStreetMap needs the [osm] extra; pip install 'uamopt[osm]'
"""

from __future__ import annotations

import importlib
import importlib.util
from types import ModuleType

from uamopt.errors import UamoptError

#: import name of an optional package -> (extra, what needs it): the line of an import that failed
#: where no :func:`need` names its use (:func:`missing_extra`); kept in step with pyproject.toml
MODULES = {
    "pyomo": ("exact", "the HiGHS MILP solver (profiles highs, rolling with inner = \"highs\")"),
    "ortools": ("exact", "the CP-SAT solver (profiles cpsat, rolling, timeindexed, exact)"),
    "highspy": ("exact", "the HiGHS solver"),
    "pyrosm": ("osm", "reading OpenStreetMap"),
    "geopandas": ("osm", "reading OpenStreetMap"),
    "dask": ("sweep", "uamopt sweep (Dask)"),
    "distributed": ("sweep", "uamopt sweep (Dask)"),
    "pyarrow": ("sweep", "a sweep's results.parquet"),
    "plotly": ("view", "uamopt view (the 3-D view)"),
    "bluesky": ("sim", "uamopt replay (BlueSky)"),
    "pyscipopt": ("scip", "the SCIP solver (profile scip)"),
}


class MissingExtraError(UamoptError, ImportError):
    """An optional package is not installed: names the extra that brings it. Also an
    :class:`ImportError`, so ``except ImportError`` (a feature probed, then skipped) still holds."""

    def __init__(self, package: str, extra: str, what: str, needed_by: str | None = None) -> None:
        self.package, self.extra = package, extra
        missing = f"{package} (needed by {needed_by})" if needed_by and needed_by != package else package
        super().__init__(f"{missing} is not installed", "", f"{what} needs the [{extra}] extra; pip install 'uamopt[{extra}]'")
        self.name = package


def _top(name: str | None) -> str:
    return (name or "").split(".")[0]


def need(module: str, *, extra: str, what: str) -> ModuleType:
    """``importlib.import_module(module)``, or a :class:`MissingExtraError` naming ``extra`` when the
    package (or a package it needs) is not installed. A module that is there but fails to import
    for another reason raises as Python does."""
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if not exc.name:
            raise
        raise MissingExtraError(_top(exc.name), extra, what, needed_by=_top(module)) from None


def require(*modules: str, extra: str, what: str) -> None:
    """Refuse up front, before any work, when one of ``modules`` is not installed (a
    :class:`MissingExtraError` naming ``extra``); looks them up without importing them."""
    for module in modules:
        try:
            found = importlib.util.find_spec(module) is not None
        except (ImportError, ValueError):  # a parent package missing, or a module set to None
            found = False
        if not found:
            raise MissingExtraError(_top(module), extra, what)


def missing_extra(exc: BaseException, what: str | None = None) -> MissingExtraError | None:
    """The :class:`MissingExtraError` of an import that failed where no :func:`need` guards it (a
    module-level import of an optional package): None unless ``exc`` is a
    :class:`ModuleNotFoundError` of a package in :data:`MODULES`."""
    if isinstance(exc, MissingExtraError):
        return exc
    if not isinstance(exc, ModuleNotFoundError) or _top(exc.name) not in MODULES:
        return None
    extra, use = MODULES[_top(exc.name)]
    return MissingExtraError(_top(exc.name), extra, what or use)
