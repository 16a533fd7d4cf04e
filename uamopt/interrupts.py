"""Ctrl-C and SIGTERM: a command stops cleanly, and the step that publishes results is never cut.

Ctrl-C raises ``KeyboardInterrupt`` in Python; :func:`install_handlers` makes SIGTERM raise
:class:`Terminated` (a ``KeyboardInterrupt``) the same way, so every ``finally`` clause runs: the
staging folder is removed and the ``--out`` lock released (uamopt.outputs). Inside
:func:`deferred_signals` both signals are held and delivered when the block ends, so a publish
or a clean-up always completes. :func:`stopping` makes a running HiGHS or CP-SAT solve stop at
once. The CLI turns either signal into one line and exit code 130 (SIGINT) or 143 (SIGTERM):
docs/interfaces.md.

Where interrupts got lost before: CP-SAT's own SIGINT handler (``catch_sigint_signal``, off in
uamopt) ended the search, returned its incumbent as if the time limit had come, and left SIGINT
at its default, so a later Ctrl-C killed the process without clean-up; a KeyboardInterrupt
raised inside a C callback (numba's compiler calls Python back through ctypes) was printed as
"Exception ignored" with a traceback and the command went on.
"""

from __future__ import annotations

import logging
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress

EXIT_SIGINT = 130  # 128 + SIGINT, the shell's code for Ctrl-C
EXIT_SIGTERM = 143  # 128 + SIGTERM


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that clean-up code runs."""


#: the last interrupt raised by a handler of ours: an extension module's import that a signal cut
#: (shapely's Cython init) reports a plain ImportError with no chain back to it (interrupt_of)
_LAST: list[KeyboardInterrupt] = []


def _raise_terminated(signum, frame) -> None:
    _LAST[:] = [Terminated()]
    raise _LAST[0]


def _raise_interrupt(signum, frame) -> None:
    _LAST[:] = [KeyboardInterrupt()]
    raise _LAST[0]


def _unraisable_hook(default):
    def hook(unraisable) -> None:
        interrupt = unraisable.exc_value
        if isinstance(interrupt, KeyboardInterrupt):
            # Raised inside a C callback (numba's compiler calls back through ctypes), which can
            # only print it and go on: signal the main thread again a moment later, from a timer,
            # so that it surfaces in the command's own code (or here again, until it does).
            signum = signal.SIGTERM if isinstance(interrupt, Terminated) else signal.SIGINT
            timer = threading.Timer(0.05, signal.pthread_kill, args=(threading.main_thread().ident, signum))
            timer.daemon = True
            timer.start()
            return
        default(unraisable)

    hook.uamopt = True
    return hook


def install_handlers() -> None:
    """Make SIGTERM raise :class:`Terminated`, and an interrupt that a C callback swallowed come
    back instead of printing a traceback (the CLI calls this once, in the main thread)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _raise_terminated)
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # the same, recorded
            signal.signal(signal.SIGINT, _raise_interrupt)
        if not getattr(sys.unraisablehook, "uamopt", False):
            sys.unraisablehook = _unraisable_hook(sys.unraisablehook)


class _NotDuringAnInterrupt(logging.Filter):
    """Drops a record logged while a KeyboardInterrupt is being handled (the logging call inside
    the library's ``except:``, as :func:`sys.exc_info` then shows)."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not isinstance(sys.exc_info()[1], KeyboardInterrupt)


def quiet_on_interrupt(logger: str) -> None:
    """Keep a library from logging an interrupt as its own error: Pyomo's ``pyomo.core`` logs
    "ERROR: Constructing component 'gap_below' from data=None failed: KeyboardInterrupt" on stdout
    when Ctrl-C lands while a model is built, then re-raises it (seen in CI). The interrupt itself
    still propagates; only the record is dropped. Idempotent."""
    log = logging.getLogger(logger)
    if not any(isinstance(f, _NotDuringAnInterrupt) for f in log.filters):
        log.addFilter(_NotDuringAnInterrupt())


def interrupt_of(exc: BaseException) -> KeyboardInterrupt | None:
    """The interrupt behind ``exc``: itself, or one in its cause/context chain (a library may
    wrap a KeyboardInterrupt raised inside its callback in an error of its own), or else the
    interrupt our handler raised last, if one was: an extension module that a signal cut may drop
    it and raise an error of its own with no chain (shapely's Cython initialisation raised
    ImportError "PyCapsule_Import could not import module"; matplotlib's Agg renderer, cut inside
    ``draw_path``, raised ValueError "Invalid affine transformation matrix"). Once the process was
    told to stop, an error on the way out is that stop, not a bug to print."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    if _LAST:
        return _LAST[0]
    return None


def handled(interrupt: KeyboardInterrupt) -> int:
    """The exit code of a handled interrupt: 130 for Ctrl-C, 143 for SIGTERM.

    CPython 3.11 marks a KeyboardInterrupt that leaves an ``exec`` of a string (scipy's array-API
    layer imports numpy that way) as unhandled, even when caught later, and then ends
    ``python -m uamopt`` by SIGINT instead of with this code; the mark is cleared here.
    """
    with suppress(Exception):  # another interpreter: no such mark
        import ctypes

        ctypes.c_int.in_dll(ctypes.pythonapi, "_Py_UnhandledKeyboardInterrupt").value = 0
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


@contextmanager
def stopping(stop: Callable[[], object]) -> Iterator[None]:
    """Let Ctrl-C and SIGTERM stop a solver that runs in C++ inside the block.

    Python runs signal handlers between the main thread's bytecodes, so during a long C++ call
    (HiGHS, CP-SAT) an interrupt would wait for the solver's time limit, and a library that saw
    it might turn it into an error or a result of its own. Inside the block both signals are
    held (:func:`deferred_signals`); a watcher thread, woken through :func:`signal.set_wakeup_fd`,
    calls ``stop`` (``CpSolver.stop_search``, ``Highs.cancelSolve``) until the block ends, and the
    block's end raises the interrupt. Outside the main thread this is a no-op.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    read_fd, write_fd = os.pipe()
    os.set_blocking(write_fd, False)
    ended = threading.Event()

    def watch() -> None:
        while data := os.read(read_fd, 1):  # b"" once the block ends and closes the pipe
            if data[0] in (signal.SIGINT, signal.SIGTERM):
                while not ended.is_set():  # again and again: the solver may not have started yet
                    with suppress(Exception):
                        stop()
                    ended.wait(0.1)
                return

    previous = signal.set_wakeup_fd(write_fd, warn_on_full_buffer=False)
    watcher = threading.Thread(target=watch, name="uamopt-interrupt-watcher", daemon=True)
    watcher.start()
    try:
        with deferred_signals():
            yield
    finally:
        ended.set()
        signal.set_wakeup_fd(previous)
        os.close(write_fd)
        watcher.join()
        os.close(read_fd)
