"""Ctrl-C and SIGTERM: a command stops cleanly, and the step that publishes results is never cut.

Ctrl-C raises ``KeyboardInterrupt`` in Python; :func:`raise_on_sigterm` makes SIGTERM raise
:class:`Terminated` (a ``KeyboardInterrupt``) the same way, so every ``finally`` clause runs: the
staging folder is removed and the ``--out`` lock released (uamopt.outputs). Inside
:func:`deferred_signals` both signals are held and delivered when the block ends, so a publish
or a clean-up always completes. The CLI turns either into one line and exit code 130 (SIGINT)
or 143 (SIGTERM): docs/interfaces.md.
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

EXIT_SIGINT = 130  # 128 + SIGINT, the shell's code for Ctrl-C
EXIT_SIGTERM = 143  # 128 + SIGTERM


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that clean-up code runs."""


def _raise_terminated(signum, frame) -> None:
    raise Terminated()


def raise_on_sigterm() -> None:
    """Make SIGTERM raise :class:`Terminated` in the main thread (the CLI calls this once)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _raise_terminated)


def interrupt_of(exc: BaseException) -> KeyboardInterrupt | None:
    """The interrupt behind ``exc``: itself, or one in its cause/context chain (a library may
    wrap a KeyboardInterrupt raised inside its callback in an error of its own)."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


def exit_code(interrupt: KeyboardInterrupt) -> int:
    """130 for Ctrl-C, 143 for SIGTERM."""
    return EXIT_SIGTERM if isinstance(interrupt, Terminated) else EXIT_SIGINT


def describe(interrupt: KeyboardInterrupt) -> str:
    """``"terminated"`` (SIGTERM) or ``"interrupted"`` (Ctrl-C)."""
    return "terminated" if isinstance(interrupt, Terminated) else "interrupted"


@contextmanager
def deferred_signals() -> Iterator[None]:
    """Hold SIGINT and SIGTERM for the block, then act on the first one that came.

    Python runs signal handlers in the main thread only, so elsewhere this is a no-op (signals
    cannot interrupt a non-main thread's code anyway).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    pending: list[int] = []
    held = (signal.SIGINT, signal.SIGTERM)
    previous = {s: signal.signal(s, lambda signum, frame: pending.append(signum)) for s in held}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, signal.SIG_DFL if handler is None else handler)
        if pending:
            handler = previous[pending[0]]
            if callable(handler):
                handler(pending[0], None)  # raises KeyboardInterrupt / Terminated, or an outer block holds it
            elif handler in (signal.SIG_DFL, None):
                os.kill(os.getpid(), pending[0])  # the default action: end the process
