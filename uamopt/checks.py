"""Argument checks of the Python API (docs/interfaces.md, Python API): a wrong *type* raises
``TypeError`` naming the function, the parameter and the expected type, as numpy and pandas do;
a wrong *value* or mismatched objects raise a :class:`~uamopt.errors.UamoptError` subclass.

>>> expect(3, str, "path", "load_scenario")
Traceback (most recent call last):
...
TypeError: load_scenario(): path must be a str, got int
"""

from __future__ import annotations


def _name(types) -> str:
    names = [t.__name__ for t in (types if isinstance(types, tuple) else (types,))]
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " or " + names[-1]


def expect(value, types, parameter: str, function: str):
    """``value`` if it is an instance of ``types`` (a type or a tuple of types), else
    ``TypeError("function(): parameter must be a T, got U")``."""
    allowed = types if isinstance(types, tuple) else (types,)
    if isinstance(value, types) and not (isinstance(value, bool) and bool not in allowed):
        return value
    name = _name(types)
    article = "an" if name[:1].lower() in "aeiou" else "a"
    raise TypeError(f"{function}(): {parameter} must be {article} {name}, got {type(value).__name__}")


def expect_path(value, parameter: str, function: str):
    """``value`` if it is a path (a ``str`` or an ``os.PathLike``), else ``TypeError``."""
    import os

    if isinstance(value, (str, os.PathLike)):
        return value
    raise TypeError(f"{function}(): {parameter} must be a str or os.PathLike (a path), got {type(value).__name__}")
