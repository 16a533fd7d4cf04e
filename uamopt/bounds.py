"""One boundary check for every number read from a file or the command line (docs/interfaces.md).

A number from outside is untrusted: JSON and TOML allow integers of any length (a 400-digit
departure overflows ``float()``; more than 4300 digits is Python's int-string limit, a
``ValueError`` while parsing), and ``nan``, ``inf`` or ``1e300`` are valid floats. Every reader
therefore passes each number through :func:`check_number` against a :class:`Range`, *before* any
arithmetic: the comparison of a Python int with the range's bounds is exact whatever its size,
and it refuses NaN (every comparison with NaN is false) and ±inf (the bounds are finite).
Integers are also held to int64, so numpy can take them. Scenario keys declare the same ranges in
their pydantic fields (uamopt/scenario/schema.py, the key table); solver profiles in
uamopt/solvers/options.py.

The ranges are what a quantity can mean, not what a run can afford: how much memory a grid or a
flight plan may take is a separate guard (``grid.memory_limit_gb``, ``schedule.memory_limit_gb``).

>>> check_number(25, "speed_mps", "flights.json", "give m/s", SPEED_MPS)
25.0
>>> check_number(10 ** 400, "speed_mps", "flights.json", "give m/s", SPEED_MPS)
Traceback (most recent call last):
...
uamopt.errors.InputFileError: speed_mps must be a number in [0.1, 200], got 1000000000000000000000000000000000000000… (401 characters) (flights.json): give m/s
"""  # noqa: E501 - the doctest above shows the whole one-line message

from __future__ import annotations

import math
from dataclasses import dataclass

from uamopt.errors import InputFileError, UamoptError

INT64_MAX = 2**63 - 1
MAX_COORD_M = 1e6  # |x|, |y|, |z| of the local frame, m (1,000 km: the verifier's range)
MAX_TIME_S = 1e7  # times and durations of a schedule, s (about 116 days: the verifier's range)
MAX_DIGITS = 4300  # Python's int-string conversion limit (sys.get_int_max_str_digits)
MAX_WEIGHT = 1e6  # a weight of an objective (schedule.weights, ω6 and ω7): the scenario key's range
GRID_TOL_M = 1e-6  # slack beyond the grid's top faces (x_max, y_max, z_max) for round-off, m: see outside_grid


def shown(value, limit: int = 40) -> str:
    """``repr(value)`` cut to ``limit`` characters (a 400-digit number in an error line).

    >>> shown(10 ** 400), shown(10 ** 5000)
    ('1000000000000000000000000000000000000000… (401 characters)', 'an integer of about 5001 digits')
    """
    try:
        text = repr(value)
    except ValueError:  # an int beyond Python's int-string limit (made in Python, not read from a file)
        return f"an integer of about {digits(value)} digits"
    return text if len(text) <= limit else f"{text[:limit]}… ({len(text)} characters)"


def digits(value: int) -> int:
    """The number of decimal digits of an integer; beyond Python's int-string limit, from its bit length
    (exact or one too many)."""
    try:
        return len(str(abs(value)))
    except ValueError:
        return math.floor(abs(value).bit_length() * math.log10(2)) + 1


@dataclass(frozen=True)
class Range:
    """The values a quantity can take: ``lo`` to ``hi`` (finite), each end closed unless
    ``lo_open`` / ``hi_open``; ``integer``: whole numbers only (and within int64)."""

    lo: float
    hi: float
    lo_open: bool = False
    hi_open: bool = False
    integer: bool = False

    def __post_init__(self) -> None:
        assert math.isfinite(self.lo) and math.isfinite(self.hi) and self.lo <= self.hi, self
        assert not self.integer or -INT64_MAX - 1 <= self.lo <= self.hi <= INT64_MAX, self

    def holds(self, value) -> bool:
        """``value`` is a number of the right kind inside the range (exact for ints of any size)."""
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return False
        if self.integer and not isinstance(value, int):
            return False
        above = self.lo < value if self.lo_open else self.lo <= value
        below = value < self.hi if self.hi_open else value <= self.hi
        return above and below  # False for NaN

    def interval(self) -> str:
        """The range as an interval: ``(0, 1e+07]``; ``[0, 2^63 - 1]`` for int64's top."""
        lo, hi = (("2^63 - 1" if b == INT64_MAX else f"{int(b)}") if self.integer else f"{b:g}" for b in (self.lo, self.hi))
        return f"{'(' if self.lo_open else '['}{lo}, {hi}{')' if self.hi_open else ']'}"

    def text(self) -> str:
        """What the range holds, in words: ``a number in (0, 1e+07]``, ``an integer in [0, 10]``."""
        return f"{'an integer' if self.integer else 'a number'} in {self.interval()}"


def check_number(value, what: str, where: str, fix: str, valid: Range, error: type[UamoptError] = InputFileError):
    """``value`` as a float (an int when ``valid.integer``) if ``valid`` holds it, else ``error``
    in one line: ``<what> must be <the range>, got <value, cut to 40 characters>``."""
    if valid.holds(value):
        return int(value) if valid.integer else float(value)
    raise error(f"{what} must be {valid.text()}, got {shown(value)}", where, fix)


def check_cell(raw, where: str, fix: str = "give [dx, dy, dz] in metres", error: type[UamoptError] = InputFileError):
    """A file's ``cell``: three sizes in :data:`CELL_M`, as a tuple of floats; else ``error``."""
    if not (isinstance(raw, (list, tuple)) and len(raw) == 3 and all(CELL_M.holds(c) for c in raw)):
        raise error(f"'cell' must be three positive sizes in metres, each in {CELL_M.interval()}, got {shown(raw)}", where, fix)
    return tuple(float(c) for c in raw)


def check_points(raw, what: str, where: str, fix: str, minimum: int = 2, error: type[UamoptError] = InputFileError):
    """``raw`` (a list of [x, y, z]) as an (n, 3) float array of at least ``minimum`` points whose
    coordinates are numbers within ±:data:`MAX_COORD_M`; else ``error``."""
    import numpy as np

    valid = Range(-MAX_COORD_M, MAX_COORD_M)
    rule = (f"{what} must be a list of at least {'two' if minimum == 2 else minimum} finite [x, y, z] points within "
            f"±{MAX_COORD_M:g} m (the local frame)")
    if not (isinstance(raw, (list, tuple)) and len(raw) >= minimum
            and all(isinstance(p, (list, tuple)) and len(p) == 3 for p in raw)):
        raise error(f"{rule}, got {shown(raw)}", where, fix)
    for n, p in enumerate(raw):
        bad = [v for v in p if not valid.holds(v)]
        if bad:
            raise error(f"{rule}: point {n + 1} holds {shown(bad[0])}", where, fix)
    return np.array(raw, dtype=float)


def outside_grid(points, extent):
    """Per point of ``points`` ((n, 3), m), True where it lies outside the grid [0, x_max] × [0, y_max]
    × [0, z_max] = ``extent``: the one rule of the flights and network readers, the pipeline's
    airspace check and ``uamopt verify``, so that a track one accepts no other refuses.

    The top faces get :data:`GRID_TOL_M` of slack (an extent of n whole cells, a track planned on
    its face, carry round-off); the lower faces none: 0 is the origin of the local frame, exact in
    floating point (a planned track is clipped to it), and the verifier holds every coordinate to
    the frame, ≥ 0, whatever the grid.

    >>> outside_grid([[0.0, 5.0, 1.0], [10.0 + 5e-7, 5.0, 1.0], [-5e-7, 5.0, 1.0]], (10.0, 10.0, 10.0)).tolist()
    [False, False, True]
    """
    import numpy as np

    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    top = np.asarray(extent, dtype=float) + GRID_TOL_M
    return np.any((pts < 0.0) | (pts > top), axis=1)


def read_json(path, what: str, source: str, fix: str):
    """The JSON document of the file ``path`` (UTF-8, a BOM allowed), else one
    :class:`~uamopt.errors.InputFileError` naming ``what`` ("the flights file") at ``source``:
    malformed JSON, not UTF-8, an integer beyond Python's limit, nesting too deep, unreadable.
    ``fix`` says what a good file is (docs/interfaces.md)."""
    import json
    from pathlib import Path

    try:
        return json.loads(Path(path).read_text(encoding="utf-8-sig"))
    except json.JSONDecodeError as exc:
        # json's "Unterminated string starting at" ends in "at" already
        raise InputFileError(f"malformed JSON: {exc.msg.removesuffix(' at')} at line {exc.lineno} column {exc.colno}", source,
                             "fix the syntax") from None
    except UnicodeDecodeError:
        raise InputFileError(f"{what} is not UTF-8 text", source, "save it as UTF-8 JSON") from None
    except ValueError as exc:  # an integer of more than 4300 digits (Python's int-string limit)
        raise InputFileError(f"malformed JSON: {parse_error(exc)}", source, f"write every number in its range ({fix})") from None
    except RecursionError:
        raise InputFileError(f"{what} is nested too deeply to read", source, f"give {fix}") from None
    except OSError as exc:
        raise InputFileError(f"cannot read {what}: {exc.strerror or exc}", source, "check that the file is readable") from None


def parse_error(exc: ValueError) -> str:
    """What a JSON or TOML parser's ``ValueError`` says, on one line; Python's int-string limit
    (an integer of more than 4300 digits) in words a user can act on."""
    text = " ".join(str(exc).split())
    if "integer string conversion" in text:
        return f"an integer of more than {MAX_DIGITS} digits"
    return text


#: ranges shared by the flights and network readers and the scenario keys
SPEED_MPS = Range(0.1, 200.0)  # ground speeds the verifier accepts, m/s
TIME_S = Range(-MAX_TIME_S, MAX_TIME_S)  # a planned departure, s
DURATION_S = Range(0.0, MAX_TIME_S)  # a delay bound, a gap, a service time, s
CELL_M = Range(0.0, MAX_COORD_M, lo_open=True)  # a cell side, m
VERTICAL_RATE_MPS = Range(0.0, 50.0, lo_open=True)  # the verifier's range, m/s
CONFLICT_RADIUS = Range(0, 10, integer=True)  # r: a zone of at most 21³ cells
