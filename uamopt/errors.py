"""Named exceptions. The CLI turns every :class:`UamoptError` into one line and exit code 2.

Every message follows docs/interfaces.md: ``<what> (<where>): <how to fix>``, on one line whatever
the input put in it: a path or an id holding a newline, NUL or ESC is shown escaped (:func:`printable`).
"""

from __future__ import annotations


def printable(text: str) -> str:
    """``text`` on one line: a control character a crafted file or path put in it (a newline, NUL,
    ESC) is shown escaped, as Python writes it in a string (``\\n``, ``\\x00``).

    >>> printable("out/a\\nb")
    'out/a\\\\nb'
    """
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


class UamoptError(Exception):
    """Base class of every error caused by the user's input or a model that cannot be solved."""

    def __init__(self, what: str, where: str = "", fix: str = "") -> None:
        self.what, self.where, self.fix = what, where, fix
        super().__init__(self.line())

    def __reduce__(self):  # pickled whole (a watched solver's child process sends its errors)
        return _rebuild, (type(self), self.__dict__)

    def line(self) -> str:
        text = self.what
        if self.where:
            text += f" ({self.where})"
        if self.fix:
            text += f": {self.fix}"
        return printable(text)


def _rebuild(cls: type, state: dict) -> UamoptError:
    """A pickled :class:`UamoptError` (or subclass, whatever its ``__init__``), with its state."""
    error = Exception.__new__(cls)
    error.__dict__.update(state)
    Exception.__init__(error, error.line())
    return error


class ScenarioError(UamoptError):
    """A scenario file or ``--set`` override is malformed, unknown or out of range."""


class InputFileError(UamoptError):
    """An input data file (.pbf, GeoTIFF, GeoJSON, flights.json) is missing or unreadable."""


class GridError(UamoptError):
    """The airspace grid is empty or a point lies outside it."""


class NoTrackError(UamoptError):
    """No admissible track joins the requested origin and destination."""


class NoSpaceError(UamoptError):
    """A write stopped by a full disk, a quota or a file-size limit: the machine's state, not the
    input, so a sweep stops on it instead of recording the case as failed."""


class InfeasibleScheduleError(UamoptError):
    """No schedule satisfies the constraints."""


def error_line(exc: BaseException) -> str:
    """An exception as one short line: ``Type: message`` (a UamoptError's own line)."""
    text = exc.line() if isinstance(exc, UamoptError) else str(exc)
    first = (text.strip().splitlines() or [""])[0]
    return f"{type(exc).__name__}: {first}"[:400]
