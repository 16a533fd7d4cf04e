"""A Dask client for the work that runs on a cluster: sweeps (uamopt/experiments/engine.py) and the
``windows`` solver's tasks (uamopt/solvers/windows.py). The tasks run on a ``LocalCluster`` on the
loopback interface (processes, one thread each), or on a running cluster at a scheduler's address
(``dask scheduler`` + ``dask worker`` processes with uamopt installed)."""

from __future__ import annotations

import logging
import os
import signal
import sys
import threading

from uamopt.errors import UamoptError, error_line

CONNECT_TIMEOUT_S = 3.0

# After an interrupted sweep the resource tracker (a child process multiprocessing starts beside
# the workers) finds a semaphore the stopped cluster did not release, removes it, and says so with
# a UserWarning on the terminal, after the interrupt's one line. The removal is its job; the
# message is noise. The tracker is started with this process's -W options, so the filter goes
# there, before the tracker starts.
TRACKER_QUIET = "ignore:resource_tracker:UserWarning:multiprocessing.resource_tracker"


def quiet_resource_tracker() -> None:
    """Mute the resource tracker's leaked-semaphore warning in the tracker this process starts
    next (the tracker still removes what it finds)."""
    if TRACKER_QUIET not in sys.warnoptions:
        sys.warnoptions.append(TRACKER_QUIET)


def connect(scheduler: str | None, workers: int | None, tasks: int, scratch: str | None = None):
    """A Dask client: on the cluster at ``scheduler``, or on a new loopback LocalCluster whose
    scratch space and TMPDIR are ``scratch`` (default: Dask's, ``dask-scratch-space`` in TMPDIR).

    Returns (client, cluster or None). Raises UamoptError when the scheduler cannot be reached
    within CONNECT_TIMEOUT_S.
    """
    import dask
    from distributed import Client, LocalCluster

    if scheduler:
        address = scheduler if "://" in scheduler else f"tcp://{scheduler}"
        logging.getLogger("distributed").setLevel(logging.ERROR)
        try:
            return Client(address, timeout=CONNECT_TIMEOUT_S), None
        except Exception as exc:  # noqa: BLE001 - OSError, TimeoutError, ValueError on a bad address
            raise UamoptError(f"cannot reach the Dask scheduler at {scheduler} ({error_line(exc)})", "--scheduler",
                              "start one with `dask scheduler`, check the address, or drop --scheduler") from None
    n = workers or max(1, min(os.cpu_count() or 1, tasks))
    quiet_resource_tracker()
    # Ctrl-C reaches every process of the terminal's group, and the workers printed tracebacks.
    # Processes started while SIGINT is ignored keep ignoring it, so the workers start so; this
    # process takes Ctrl-C again once they run, and stops them (a Ctrl-C during the start is lost).
    # A SIGTERM during the start is held until the cluster is up, then the cluster is closed and
    # the SIGTERM acted on: cut inside LocalCluster's start, its clean-up failed an assert of its
    # own (a worker still in Status.init) and printed that traceback instead of one line.
    main = threading.current_thread() is threading.main_thread()
    held: list[int] = []
    if main:
        previous_int = signal.signal(signal.SIGINT, signal.SIG_IGN)
        previous_term = signal.signal(signal.SIGTERM, lambda signum, frame: held.append(signum))
    try:
        # every temporary file of the cluster in ``scratch``, removed afterwards even where a worker
        # was stopped mid-task; worker logs muted (a task's error is in its row)
        with dask.config.set({"temporary-directory": scratch}):
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
                                   dashboard_address="127.0.0.1:0",  # a free loopback port
                                   silence_logs=logging.CRITICAL, env={"TMPDIR": scratch})
    finally:
        if main:
            signal.signal(signal.SIGINT, signal.SIG_DFL if previous_int is None else previous_int)
            signal.signal(signal.SIGTERM, signal.SIG_DFL if previous_term is None else previous_term)
    if held:
        cluster.close()
        if callable(previous_term):
            previous_term(signal.SIGTERM, None)  # raises Terminated (uamopt.interrupts)
        os.kill(os.getpid(), signal.SIGTERM)  # the default action: end the process
    return Client(cluster), cluster
