"""Lazy public names (PEP 562): a package lists ``name -> module`` and imports each module on first
access, so importing the package (and building the CLI's parser) loads no heavy library."""

from __future__ import annotations

import importlib
import sys


def lazy_getattr(package: str, names: dict[str, str]):
    """The module-level ``__getattr__`` of ``package`` for the public ``names`` (cached once loaded)."""

    def __getattr__(name: str):
        if name in names:
            value = getattr(importlib.import_module(names[name]), name)
            setattr(sys.modules[package], name, value)
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__
