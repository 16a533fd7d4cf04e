"""A time limit is a promise: a watched solve returns by ``time_limit_s × 1.05 + 5 s``, whatever its
engine does.

Why a process. HiGHS checks neither its time limit nor its interrupt callbacks in parts of its
presolve: a ``solvers/exact.toml`` run of 300 s on 600 flights of the paper city ran 674 s under load,
its main thread in ``HPresolve::enumerateSolutions`` → ``HighsCliqueTable::runCliqueMerging``. Nothing
inside the process can stop such a call. So the exact solvers (:data:`WATCHED`) run in a child
process, started from a ``forkserver`` that has the solver libraries imported already (tens of
milliseconds a solve), and this process keeps the clock:

- the child gets the time left to the parent's deadline (process start included) and keeps to it by
  its own means (HiGHS's limit and interrupt callback, CP-SAT's limit, the rounds' caps);
- while it runs it reports, through a pipe, every complete schedule it holds (the warm start, each
  round's mended point, each stage's best: :func:`report_incumbent`) and every bound valid for the
  continuous model (:func:`report_bound`);
- at :func:`kill_at` (``limit × 1.03 + 2 s``) a child that has not answered is ended (SIGKILL), and
  the answer is its best reported schedule, checked against the model here, with status
  ``time_limit``, the best reported bound or, if none came, the separable bound
  (:func:`separable_bound`: every flight at its own best choice, no pair or turnaround rows), so
  a bound is always reported; ``extras["watchdog"]`` says what happened.

Ctrl-C and SIGTERM are this process's: the child is in its own process group (a terminal's Ctrl-C
does not reach it), is ended at once, and the interrupt goes on as before (uamopt.interrupts). A
child whose parent dies ends itself (it watches a pipe whose other end only the parent holds).

Where a child cannot be had, the solve runs in this process and says so in ``extras["watchdog"]``:
inside a daemonic process (a Dask worker of a cluster uamopt did not start: uamopt's own clusters
start their workers non-daemonic), with an ``extra=`` callback that cannot be pickled (a lambda:
pass a module-level function to keep the promise), or with ``isolated = false`` in the profile.
"""

from __future__ import annotations

import math
import multiprocessing as mp
import os
import pickle
import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

import numpy as np

from uamopt.errors import UamoptError

if TYPE_CHECKING:
    from uamopt.schedule.model import Schedule, SchedulingProblem
    from uamopt.solvers import SolverProfile

#: the promise: a watched solve returns within limit × (1 + MARGIN_SHARE) + MARGIN_S seconds
MARGIN_SHARE, MARGIN_S = 0.05, 5.0
#: a child still running at limit × (1 + KILL_SHARE) + KILL_S is ended; the rest of the margin is for
#: ending it and making the answer here
KILL_SHARE, KILL_S = 0.03, 2.0
#: the solvers run in a child process (the heuristics keep time in Python, between their own steps)
WATCHED = frozenset({"highs", "cpsat", "timeindexed", "discovery", "rolling", "scip"})
#: imported by the forkserver once, so that a child starts with them loaded
PRELOAD = ["numpy", "scipy.sparse", "scipy.optimize", "highspy", "pyomo.environ", "ortools.sat.python.cp_model",
           "uamopt.schedule.model", "uamopt.solvers.milp", "uamopt.solvers.cpsat", "uamopt.solvers.timeindexed",
           "uamopt.solvers.discovery", "uamopt.solvers.rolling"]


def promised_s(limit_s: float) -> float:
    """The seconds a watched solve of limit ``limit_s`` returns within."""
    return limit_s * (1.0 + MARGIN_SHARE) + MARGIN_S


def kill_at(limit_s: float) -> float:
    """Seconds after the start at which a child that has not answered is ended."""
    return limit_s * (1.0 + KILL_SHARE) + KILL_S


# --- the child's side: reports ------------------------------------------------------------------

_CHANNEL: Any = None  # the child's end of the pipe to its parent (None: not in a watched child)
_TOP: int | None = None  # id() of the problem the parent asked for: only its schedules and bounds count
_LOCK = threading.Lock()  # CP-SAT calls back from its own threads
_LAST_BOUND = [-math.inf, 0.0]  # the best bound sent, and when (bounds are sent at most once a second)


_SINKS: dict[int, list] = {}  # id() of a problem solved in this process (unwatched) -> its reports, timed


def watched(problem) -> bool:
    """Whether reports about ``problem`` go anywhere: a watched child solving exactly this problem,
    or an exact solve of it in this process, whose reports make its trace (:func:`trace_of`)."""
    return (_CHANNEL is not None and id(problem) == _TOP) or id(problem) in _SINKS


def _send(message: tuple, problem=None) -> None:
    with _LOCK:
        if _CHANNEL is None:
            sink = _SINKS.get(id(problem))
            if sink is not None:
                sink.append((time.monotonic(), message))
            return
        try:
            _CHANNEL.send(message)
        except (OSError, ValueError):  # the parent is gone or closed the pipe: the lifeline ends us
            pass


@contextmanager
def _recorded(problem) -> Iterator[list]:
    """The reports about ``problem`` made in this process while the block runs, as (time, message)
    (nothing when another solve of the same object records already)."""
    if id(problem) in _SINKS:
        yield []
        return
    events: list = []
    _SINKS[id(problem)] = events
    _LAST_BOUND[:] = [-math.inf, 0.0]
    try:
        yield events
    finally:
        _SINKS.pop(id(problem), None)


def report_incumbent(problem, operated: np.ndarray, delay_s: np.ndarray, source: str) -> None:
    """Tell the parent about a complete schedule of ``problem`` (feasible as far as the caller knows;
    the parent checks it before using it). A no-op outside a watched child or for another problem."""
    if watched(problem):
        _send(("incumbent", np.asarray(operated, dtype=bool).copy(), np.asarray(delay_s, dtype=float).copy(), str(source)),
              problem)


def report_bound(problem, bound: float | None, source: str) -> None:
    """Tell the parent about a lower bound on ``problem``'s optimum valid for continuous delays
    (at most once a second unless it improved by more than 1e-9 relative). A no-op outside a
    watched child, for another problem, or for a bound that is not finite."""
    if not watched(problem) or bound is None or not math.isfinite(bound):
        return
    now = time.monotonic()
    if bound <= _LAST_BOUND[0] + 1e-9 * (1.0 + abs(bound)) and now - _LAST_BOUND[1] < 1.0:
        return
    if bound > _LAST_BOUND[0]:
        _LAST_BOUND[0] = float(bound)
    _LAST_BOUND[1] = now
    _send(("bound", float(bound), str(source)), problem)


def _lifeline(conn) -> None:
    """End this child once its parent's end of ``conn`` closes (the parent ended, however)."""
    try:
        conn.recv()
    except (EOFError, OSError):
        pass
    os._exit(1)


def _child(channel, lifeline, problem, profile, extra, body, deadline: float) -> None:
    """The child process: solve, send ("done", schedule) or ("error", exception), end."""
    global _CHANNEL, _TOP
    import dataclasses
    import sys

    os.setpgrp()  # a terminal's Ctrl-C reaches the parent only; the parent ends this process
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_lifeline, args=(lifeline,), name="uamopt-lifeline", daemon=True).start()
    _CHANNEL, _TOP = channel, id(problem)
    try:
        left = max(0.05, deadline - time.monotonic())
        schedule = body(problem, dataclasses.replace(profile, time_limit_s=left), extra)
        message: tuple = ("done", schedule)
    except BaseException as exc:  # noqa: BLE001 - every outcome goes to the parent, which raises it
        message = ("error", exc)
    try:
        pickle.dumps(message)
    except Exception:  # noqa: BLE001 - an exception of a library that does not pickle: its words
        failure = message[1]
        message = ("error", UamoptError(f"{type(failure).__name__}: {failure}", f"solver {profile.name or profile.solver}",
                                        "rerun with isolated = false in the profile to see the traceback"))
    _send(message)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


# --- the parent's side ----------------------------------------------------------------------------

_CONTEXT: list = []


def _context():
    """The forkserver context, its preload set once (the server starts on first use)."""
    if not _CONTEXT:
        ctx = mp.get_context("forkserver")
        ctx.set_forkserver_preload(PRELOAD)
        _CONTEXT.append(ctx)
    return _CONTEXT[0]


#: sun_path holds 108 bytes with its NUL; the forkserver's socket is ``<dir>/listener-XXXXXXXX``
_SUN_PATH_MAX = 107
_LISTENER_NAME = len("/listener-") + 8


@contextmanager
def _socket_dir_short_enough() -> Iterator[None]:
    """The forkserver listens on a Unix socket in multiprocessing's temporary folder, made under
    ``$TMPDIR``; a long ``$TMPDIR`` (a CI checkout's pytest folder, a deep home directory) makes
    that path longer than a Unix socket address may be, and the server cannot start
    ("AF_UNIX path too long"). Then the socket goes in a short folder of its own under ``/tmp``
    (or ``/dev/shm``, ``/var/tmp``), removed when this process exits, while the server starts."""
    import tempfile
    from multiprocessing import process, util

    config = process.current_process()._config  # type: ignore[attr-defined]  # where multiprocessing.util.get_temp_dir keeps it
    current = config.get("tempdir") or tempfile.gettempdir()
    if len(os.fsencode(current)) + len("/pymp-XXXXXXXX") + _LISTENER_NAME <= _SUN_PATH_MAX:
        yield
        return
    for base in ("/tmp", "/dev/shm", "/var/tmp"):
        try:
            short = tempfile.mkdtemp(prefix="uamopt-", dir=base)
            break
        except OSError:
            continue
    else:
        raise OSError(f"no folder short enough for the solver watchdog's socket: $TMPDIR ({current}) is "
                      "too long for a Unix socket address and /tmp, /dev/shm, /var/tmp are not writable")
    import shutil

    util.Finalize(None, shutil.rmtree, args=(short, True), exitpriority=-100)
    had = "tempdir" in config
    saved = config.get("tempdir")
    config["tempdir"] = short
    try:
        yield
    finally:
        if had:
            config["tempdir"] = saved
        else:
            config.pop("tempdir", None)


def _ensure_server() -> None:
    """Start the forkserver (if it is not running) with SIGINT ignored: an ignored signal stays
    ignored across exec and Python then leaves it so, so a Ctrl-C that reaches the whole process
    group while the server imports the solver libraries prints no traceback there
    (multiprocessing ignores SIGINT in it only after those imports). SIGINT is blocked meanwhile in
    this process, so a Ctrl-C to it during the start is held (Linux queues a blocked signal even
    while it is ignored) and acted on once the handler is back."""
    from multiprocessing import forkserver

    _context()
    if threading.current_thread() is not threading.main_thread():
        with _socket_dir_short_enough():
            forkserver.ensure_running()
        return
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    handler = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with _socket_dir_short_enough():
            forkserver.ensure_running()
    finally:
        signal.signal(signal.SIGINT, handler if handler is not None else signal.SIG_DFL)
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)


def warm() -> None:
    """Start the forkserver now (it imports the solver libraries in the background), so that the
    first watched solve does not wait for it. Harmless where it cannot start."""
    if "forkserver" in mp.get_all_start_methods() and not mp.current_process().daemon:
        try:
            _ensure_server()
        except Exception:  # noqa: BLE001 - the solve will say why, or run in this process
            pass


def warm_workers(client) -> None:
    """Start each Dask worker's forkserver now (:func:`warm`), so that its first watched solve does
    not spend its time limit importing the solver libraries (seconds at load 8). The callers of
    ``uamopt.cluster.connect`` (the windows solver, the sweep engine) call it."""
    try:
        client.run(warm)
    except Exception:  # noqa: BLE001 - a worker that cannot: its first solve starts the forkserver itself
        pass


def why_not_isolated(profile: SolverProfile, extra) -> str | None:
    """Why a solve runs in this process (None: it runs in a watched child)."""
    if profile.solver not in WATCHED:
        return "not watched: a heuristic that keeps time between its own steps"
    if not profile.isolated:
        return "isolated = false in the profile: the solve ran in this process, its time limit unguarded"
    if "forkserver" not in mp.get_all_start_methods():
        return "this platform has no forkserver: the solve ran in this process, its time limit unguarded"
    if mp.current_process().daemon:
        return "inside a daemonic process (a Dask worker?): the solve ran in it, its time limit unguarded"
    if extra is not None:
        if getattr(extra, "__module__", None) == "__main__":
            return ("the extra= callback lives in the main script, which a child process does not import: the solve "
                    "ran in this process, its time limit unguarded; define it in a module to keep it")
        try:
            pickle.dumps(extra)
        except Exception:  # noqa: BLE001 - a lambda or a closure
            return ("the extra= callback cannot be pickled (a lambda or closure): the solve ran in this process, "
                    "its time limit unguarded; pass a module-level function to keep it")
    return None


@contextmanager
def _main_not_reimported() -> Iterator[None]:
    """Start a child without it importing this process's ``__main__`` again. multiprocessing's
    forkserver (and spawn) children re-run the main script unless it is guarded by
    ``if __name__ == "__main__":``; a researcher's script calling ``ua.solve`` at top level would run
    again in every child. Nothing the child needs is in ``__main__`` (its target and arguments are
    uamopt's own, or a callback checked by :func:`why_not_isolated`), so the main module's file and
    spec are hidden while the child's preparation data is taken."""
    import sys

    main = sys.modules.get("__main__")
    if main is None:
        yield
        return
    saved: dict[str, Any] = {key: main.__dict__[key] for key in ("__file__", "__spec__") if key in main.__dict__}
    try:
        main.__dict__.pop("__file__", None)
        main.__dict__["__spec__"] = None
        yield
    finally:
        main.__dict__.pop("__spec__", None)
        main.__dict__.update(saved)


def run(problem: SchedulingProblem, profile: SolverProfile, extra, body) -> Schedule:
    """``body(problem, profile, extra)`` in a watched child process (module docstring), or in this
    process where that cannot be (the reason in ``extras["watchdog"]`` for a watched solver)."""
    why = why_not_isolated(profile, extra)
    if why is None:
        try:
            _ensure_server()
        except OSError as exc:  # no socket can be made: an unwatched solve beats none
            why = (f"the watchdog's process server could not start ({exc}): the solve ran in this process, "
                   "its time limit unguarded")
    if why is None:
        return _run_child(problem, profile, extra, body)
    if profile.solver not in WATCHED:
        return body(problem, profile, extra)
    t0 = time.monotonic()
    with _recorded(problem) as events:
        schedule = body(problem, profile, extra)
    schedule.extras.setdefault("watchdog", why)
    schedule.extras["trace"] = trace_of(problem, events, t0)
    return schedule


#: at most this many points in a trace (evenly thinned beyond)
TRACE_POINTS = 400


class Trace:
    """A solve's progress, built from its reports as they come (:func:`trace_of`); each improvement
    is also passed to the :func:`listening` callbacks."""

    def __init__(self, problem: SchedulingProblem, t0: float) -> None:
        self.problem, self.t0 = problem, t0
        self.best, self.bound = math.inf, -math.inf
        self.schedule: tuple[np.ndarray, np.ndarray, str] | None = None  # the best accepted (operated, delay, source)
        self.bound_source = ""
        self.reported = 0  # schedules reported
        self.points: list[list] = []

    def add(self, at: float, message: tuple) -> bool:
        """Take one report made at ``at`` (``time.monotonic()``); True when it improved the best
        schedule (one the model's own ``violations`` accept) or the best bound."""
        from uamopt.schedule.model import evaluate, violations

        if message[0] == "incumbent":
            self.reported += 1
            operated, delay = message[1], message[2]
            if len(operated) != self.problem.n_flights:
                return False
            value = float(evaluate(self.problem, operated, delay))
            if value >= self.best - 1e-9 * (1.0 + abs(value)) or violations(self.problem, operated, delay):
                return False
            self.best, self.schedule = value, (operated, delay, str(message[3]))
        elif message[0] == "bound":
            if not message[1] > self.bound:
                return False
            self.bound, self.bound_source = float(message[1]), str(message[2])
        else:
            return False
        point = [round(max(0.0, at - self.t0), 3), self.best if math.isfinite(self.best) else None,
                 self.bound if math.isfinite(self.bound) else None]
        self.points.append(point)
        for listener in list(_LISTENERS):
            try:
                listener(*point)
            except Exception:  # noqa: BLE001 - a progress display must never end the solve
                pass
        return True

    def thinned(self) -> list[list]:
        """The points, at most :data:`TRACE_POINTS` (evenly thinned beyond)."""
        points = self.points
        if len(points) > TRACE_POINTS:
            keep = np.unique(np.linspace(0, len(points) - 1, TRACE_POINTS).round().astype(int))
            points = [points[i] for i in keep.tolist()]
        return points


_LISTENERS: list = []  # callbacks(seconds, best objective or None, best bound or None) of watched solves


@contextmanager
def listening(callback) -> Iterator[None]:
    """While the block runs, ``callback(seconds, objective, bound)`` hears every improvement of a
    watched solve's best schedule or bound, as the parent receives it (``uamopt schedule``'s
    progress line; objective or bound None until the first)."""
    _LISTENERS.append(callback)
    try:
        yield
    finally:
        _LISTENERS.remove(callback)


def trace_of(problem: SchedulingProblem, events: list, t0: float) -> list[list]:
    """The solve's progress from its reports: ``[seconds, best objective, best bound]`` each time
    one of them improved (None until the first). An incumbent counts only if the model's own
    ``violations`` accept it; a bound as reported (every reported bound is valid for continuous
    delays). :func:`uamopt.solvers.solve` appends the final answer's point."""
    trace = Trace(problem, t0)
    for at, message in events:
        trace.add(at, message)
    return trace.thinned()


def _run_child(problem, profile, extra, body) -> Schedule:
    import dataclasses

    ctx = _context()
    t0 = time.monotonic()
    limit = float(profile.time_limit_s)
    deadline, end = t0 + limit, t0 + kill_at(limit)
    receive, channel = ctx.Pipe(duplex=False)
    keep, lifeline = ctx.Pipe(duplex=False)  # the child's lifeline: its recv ends when `keep` closes
    child = ctx.Process(target=_child, args=(channel, keep, problem, profile, extra, body, deadline),
                        name=f"uamopt-{profile.solver}", daemon=True)
    answer: tuple | None = None
    trace = Trace(problem, t0)
    try:
        _ensure_server()
        with _main_not_reimported():
            child.start()
        channel.close()
        keep.close()
        while answer is None:
            wait = end - time.monotonic()
            if wait <= 0:
                break
            if not receive.poll(min(wait, 1.0)):
                continue
            try:
                message = receive.recv()
            except (EOFError, OSError):  # the child ended without its answer
                break
            if message[0] in ("incumbent", "bound"):
                trace.add(time.monotonic(), message)
            else:
                answer = message
    finally:
        if child.pid is not None:  # started
            if child.is_alive():
                child.kill()
            child.join(5.0)
        receive.close()
        lifeline.close()
    seconds = time.monotonic() - t0
    if answer is not None:
        if answer[0] == "error":
            raise answer[1]
        schedule = answer[1]
        return dataclasses.replace(schedule, solve_seconds=seconds, extras={**schedule.extras, "watchdog": "child process",
                                                                          "trace": trace.thinned()})
    if time.monotonic() < end and child.exitcode not in (None, 0):  # died early: not a time limit
        how = f"signal {-child.exitcode}" if child.exitcode < 0 else f"exit code {child.exitcode}"
        hint = " (SIGKILL: often the machine's memory ran out)" if child.exitcode == -signal.SIGKILL else ""
        raise UamoptError(f"the solver's process ended without an answer, by {how}{hint}",
                          f"solver {profile.name or profile.solver}", "rerun with isolated = false in the profile to see why")
    schedule = _after_kill(problem, profile, trace, seconds)
    schedule.extras["trace"] = trace.thinned()
    return schedule


def _after_kill(problem, profile, trace: Trace, seconds) -> Schedule:
    """The answer of a child ended at its deadline: its best reported schedule that the model
    accepts (the trace keeps it; else every flight cancelled, where that is allowed), the best
    reported bound (else :func:`separable_bound`), status ``time_limit``."""
    from uamopt.schedule.model import evaluate, make_schedule, violations
    from uamopt.solvers.warmstart import no_schedule

    n = problem.n_flights
    best = None if trace.schedule is None else (trace.best, *trace.schedule)
    name = profile.name or profile.solver
    if best is None:
        none = np.zeros(n, dtype=bool)
        if violations(problem, none, np.zeros(n)):
            raise no_schedule(problem, name, f"the solver reported no schedule before it was ended at its "
                              f"time limit ({seconds:.1f} s)")
        best = (evaluate(problem, none, np.zeros(n)), none, np.zeros(n), "none reported: every flight cancelled")
    value, source = separable_bound(problem), "the separable bound (every flight at its own best choice)"
    if trace.bound > value:
        value, source = trace.bound, trace.bound_source
    extras = {"engine_termination": "ended at the time limit by the watchdog",
              "watchdog": f"the child process did not answer by {kill_at(profile.time_limit_s):.1f} s "
                          f"(limit {profile.time_limit_s:g} s) and was ended; {trace.reported} schedule(s) reported",
              "incumbent": best[3], "bound_source": source}
    return make_schedule(problem, profile.solver, "time_limit", best[1], best[2], bound=float(min(value, best[0])),
                         solve_seconds=seconds, seed=profile.seed, extras=extras)


def separable_bound(problem: SchedulingProblem) -> float:
    """A lower bound on every objective kind, valid for continuous delays: each flight at its own
    cheapest choice (cancelled, unless it must operate, or operated at its best delay in [0, U_f]),
    every pair, turnaround and precedence row dropped. Weak where the city is over capacity, but
    finite and at hand at once."""
    o = problem.objective
    upper = np.asarray(problem.delay_upper_s, dtype=float)
    # an operated flight's cost is convex piecewise linear in d: least at 0, its target or U_f
    candidates = [np.zeros_like(upper), upper]
    if o.per_flight_terms:
        candidates.append(np.clip(np.asarray(o.terms[0], dtype=float), 0.0, upper))
    cost = np.min([o.delay_cost(d) for d in candidates], axis=0) - o.per_flight
    pinned = np.asarray(problem.must_operate, dtype=bool)
    return float(np.sum(np.where(pinned, cost, np.minimum(cost, 0.0))))
