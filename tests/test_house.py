"""The house's data flow (docs/house.md): a stage module imports only earlier stages.

Every ``import`` in the library is read from the source (function-level and ``TYPE_CHECKING``
imports included: a lazy import is still a dependency) and mapped to its layer."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ORDER = ["base", "grid", "city", "risk", "planning", "schedule", "solvers", "commands"]
LAYER_OF = {"errors": "base", "bounds": "base", "checks": "base", "scenario": "base", "outputs": "base", "interrupts": "base",
            "lazy": "base", "optional": "base", "shipped": "base", "grid": "grid", "city": "city", "risk": "risk",
            "planning": "planning", "schedule": "schedule", "solvers": "solvers"}


def layer(module: str) -> str | None:
    parts = module.split(".")
    if parts[0] != "uamopt":
        return None
    return "commands" if len(parts) == 1 else LAYER_OF.get(parts[1], "commands")


def imports(path: Path) -> list[tuple[str, int]]:
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out += [(a.name, node.lineno) for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            out.append((node.module, node.lineno))
    return out


STAGE_MODULES = [p for p in sorted((ROOT / "uamopt").rglob("*.py"))
                 if layer(".".join(p.relative_to(ROOT).with_suffix("").parts)) != "commands"]


def test_the_layers_are_found():
    found = {layer(".".join(p.relative_to(ROOT).with_suffix("").parts)) for p in STAGE_MODULES}
    assert found == set(ORDER) - {"commands"}
    assert layer("uamopt.grid.grid") == "grid" and layer("uamopt.plotting.risk") == "commands"


@pytest.mark.parametrize("path", STAGE_MODULES, ids=lambda p: str(p.relative_to(ROOT)))
def test_a_stage_imports_only_earlier_stages(path):
    me = layer(".".join(path.relative_to(ROOT).with_suffix("").parts))
    later = [f"{name} (line {line}, layer {layer(name)})" for name, line in imports(path)
             if layer(name) is not None and ORDER.index(layer(name)) > ORDER.index(me)]
    assert not later, f"{path.relative_to(ROOT)} ({me}) imports a later stage: {later}"


def test_the_grid_knows_nothing_of_cities():
    for path in (ROOT / "uamopt" / "grid").glob("*.py"):
        assert not [n for n, _ in imports(path) if n.startswith(("uamopt.city", "uamopt.risk"))], path.name


def test_the_command_line_parser_loads_no_heavy_library():
    """``uamopt --help`` and argument errors stay instant: building the parser imports no numerical
    or plotting library (they load when a command runs)."""
    import subprocess
    import sys

    code = ("import sys; from uamopt import cli; cli.build_parser(); "
            "print(sorted(m for m in ('numpy', 'pandas', 'matplotlib', 'scipy', 'dask', 'pyomo', 'ortools', 'cvxpy')"
            " if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize("path", sorted((ROOT / "uamopt").rglob("*.py")), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_module_imports_another_modules_private_names(path):
    """What one module needs of another is public there (docs/house.md): no ``from uamopt.x import _y``."""
    private = [f"{node.module}.{a.name} (line {node.lineno})" for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
               if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("uamopt")
               for a in node.names if a.name.startswith("_") and not a.name.startswith("__")]
    assert not private, f"{path.relative_to(ROOT)} imports private names: {private}"
