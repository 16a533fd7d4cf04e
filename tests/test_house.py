"""The house's data flow (docs/house.md): a stage module imports only earlier stages.

Every ``import`` in the library is read from the source (function-level and ``TYPE_CHECKING``
imports included: a lazy import is still a dependency) and mapped to its layer."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
# The stages (docs/house.md), then the command side in its own order: files (io) < the pipeline's
# calls < exports of a folder < figures < the simulator replay < sweeps and benchmarks < the
# commands' jobs (workflows) < the paper report < reproduce < the command line and the facade.
STAGES = ["base", "grid", "city", "risk", "planning", "schedule", "solvers"]
COMMANDS = ["io", "pipeline", "export", "plotting", "sim", "experiments", "workflows", "report", "reproduce", "cli"]
ORDER = STAGES + COMMANDS
LAYER_OF = {"errors": "base", "bounds": "base", "checks": "base", "scenario": "base", "outputs": "base", "interrupts": "base",
            "lazy": "base", "cluster": "base", "optional": "base", "shipped": "base", "progress": "base", "paper": "base",
            "__version__": "base",  # the facade's one attribute every layer may read (package metadata)
            "grid": "grid", "city": "city", "risk": "risk", "planning": "planning", "schedule": "schedule",
            "solvers": "solvers", "io": "io", "pipeline": "pipeline", "export": "export", "plotting": "plotting",
            "sim": "sim", "experiments": "experiments", "workflows": "workflows", "report": "report",
            "reproduce": "reproduce", "cli": "cli", "cli_export": "cli", "__main__": "cli", "__init__": "cli"}


def layer(module: str) -> str | None:
    """The layer of a module ``uamopt.x...``; None outside uamopt. The package itself (the facade
    ``uamopt/__init__.py``, whose names load every layer) is the top."""
    parts = module.split(".")
    if parts[0] != "uamopt":
        return None
    if len(parts) == 1:
        return "cli"
    if parts[1] not in LAYER_OF:
        raise AssertionError(f"{module}: a new top-level module; give it a layer in LAYER_OF (and docs/house.md)")
    return LAYER_OF[parts[1]]


def imports(path: Path) -> list[tuple[str, int]]:
    """Every module ``path`` imports, with its line; ``from uamopt import x`` is ``uamopt.x``."""
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out += [(a.name, node.lineno) for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module == "uamopt":
                out += [(f"uamopt.{a.name}", node.lineno) for a in node.names]
            else:
                out.append((node.module, node.lineno))
    return out


def module_of(path: Path) -> str:
    return ".".join(path.relative_to(ROOT).with_suffix("").parts)


# uamopt/models is package data (scenario files and the script that made one of their rasters)
ALL_MODULES = sorted(p for p in (ROOT / "uamopt").rglob("*.py") if p.relative_to(ROOT / "uamopt").parts[0] != "models")


def test_the_layers_are_found():
    found = {layer(module_of(p)) for p in ALL_MODULES}
    assert found == set(ORDER)
    assert layer("uamopt.grid.grid") == "grid" and layer("uamopt.plotting.risk") == "plotting"
    assert layer("uamopt") == "cli" and layer("uamopt.__version__") == "base"


@pytest.mark.parametrize("path", ALL_MODULES, ids=lambda p: str(p.relative_to(ROOT)))
def test_a_module_imports_only_earlier_layers(path):
    """Function-level and TYPE_CHECKING imports count: a lazy import is still a dependency."""
    me = layer(module_of(path))
    later = [f"{name} (line {line}, layer {layer(name)})" for name, line in imports(path)
             if layer(name) is not None and ORDER.index(layer(name)) > ORDER.index(me)]
    assert not later, f"{path.relative_to(ROOT)} ({me}) imports a later layer: {later}"


def test_no_import_cycle_between_packages():
    """Between two top-level modules or packages of uamopt, imports go one way (equal layers
    included: ``cli`` and ``cli_export``)."""
    edges: dict[str, set[str]] = {}
    for path in ALL_MODULES:
        me = module_of(path).split(".")
        a = me[1] if len(me) > 1 else "__init__"
        for name, _ in imports(path):
            parts = name.split(".")
            if parts[0] == "uamopt" and len(parts) > 1 and parts[1] != a:
                edges.setdefault(a, set()).add(parts[1])
    both = sorted({tuple(sorted((a, b))) for a, bs in edges.items() for b in bs if a in edges.get(b, set())})
    assert not [pair for pair in both if "__init__" not in pair], both


def test_the_schedule_stage_builds_no_city():
    """The schedule stage checks tracks against a surface it is given: the city is built by the
    command side (uamopt.pipeline), never inside the stage."""
    for path in (ROOT / "uamopt" / "schedule").rglob("*.py"):
        assert not [n for n, _ in imports(path) if n.startswith(("uamopt.city", "uamopt.risk"))], path.name


def test_the_flight_model_does_not_import_its_verifier():
    """The data model comes before its independent check: the limits they share live in
    uamopt.bounds, not in the verifier."""
    path = ROOT / "uamopt" / "schedule" / "flights.py"
    assert not [n for n, _ in imports(path) if n.startswith("uamopt.schedule.verify")]


def _validators(tree: ast.AST):
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            names = [d.func if isinstance(d, ast.Call) else d for d in node.decorator_list]
            if any(getattr(n, "id", getattr(n, "attr", "")).endswith("validator") for n in names):
                yield node


def test_no_validator_edits_a_frozen_model():
    """Scenario sections are frozen; a pydantic validator that fills in a derived value validates
    a new model from data (object.__setattr__ on a frozen model skips validation of the value)."""
    found = 0
    for path in ALL_MODULES:
        for fn in _validators(ast.parse(path.read_text(encoding="utf-8"))):
            found += 1
            calls = [node.lineno for node in ast.walk(fn) if isinstance(node, ast.Call)
                     and isinstance(node.func, ast.Attribute) and node.func.attr == "__setattr__"]
            assert not calls, f"{path.relative_to(ROOT)}: {fn.name} calls __setattr__ at lines {calls}"
    assert found >= 4  # the scenario's validators are seen


def test_the_grid_knows_nothing_of_cities():
    for path in (ROOT / "uamopt" / "grid").glob("*.py"):
        assert not [n for n, _ in imports(path) if n.startswith(("uamopt.city", "uamopt.risk"))], path.name


@pytest.mark.parametrize("path", sorted((ROOT / "uamopt").rglob("*.py")), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_module_imports_another_modules_private_names(path):
    """What one module needs of another is public there (docs/house.md): no ``from uamopt.x import _y``."""
    private = [f"{node.module}.{a.name} (line {node.lineno})" for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
               if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("uamopt")
               for a in node.names if a.name.startswith("_") and not a.name.startswith("__")]
    assert not private, f"{path.relative_to(ROOT)} imports private names: {private}"
