"""A Dask client for the work that runs on a cluster: sweeps (uamopt/experiments/engine.py) and the
``windows`` solver's tasks (uamopt/solvers/windows.py). The tasks run on a ``LocalCluster`` on the
loopback interface (processes, one thread each), or on a running cluster at a scheduler's address
(``dask scheduler`` + ``dask worker`` processes with uamopt installed)."""

from __future__ import annotations

import gc
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


#: the address schemes of a running Dask cluster (distributed's comm backends; "inproc" is within one process)
SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")


def scheduler_address(scheduler: str, in_process: bool = False) -> tuple[str, str, int]:
    """``--scheduler`` as Dask takes it, ``(address, host, port)``: ``SCHEME://HOST:PORT`` with a
    scheme of :data:`SCHEMES` (``HOST:PORT`` is tcp), a host and a port in 1-65535, nothing else
    (no path, no spaces); with ``in_process``, also an ``inproc://`` address of a cluster in this
    process (a notebook's ``LocalCluster(processes=False)`` handed to ``ua.sweep``: host "" and port 0;
    never from the command line, whose new process holds no cluster). Else one :class:`UamoptError` naming the
    option, before anything runs.

    >>> scheduler_address("127.0.0.1:8786")
    ('tcp://127.0.0.1:8786', '127.0.0.1', 8786)
    """
    from urllib.parse import urlsplit

    from uamopt.bounds import shown

    address = scheduler if "://" in scheduler else f"tcp://{scheduler}"
    if in_process and address.startswith("inproc://") and len(address) > 9 \
            and all(c.isprintable() and not c.isspace() for c in address):
        return address, "", 0  # a cluster in this very process (LocalCluster(processes=False)): no host, no port
    try:
        parts = urlsplit(address)
        host, port = parts.hostname, parts.port
    except ValueError:  # a port that is no number or beyond 65535, an unclosed [IPv6
        parts, host, port = None, None, None
    well_formed = (parts is not None and parts.scheme in SCHEMES and f"{parts.scheme}://{parts.netloc}" == address
                   and "@" not in parts.netloc and bool(host) and port is not None and 1 <= port <= 65535
                   and all(c.isprintable() and not c.isspace() for c in str(host)))
    if not well_formed:
        raise UamoptError(f"{shown(scheduler)} is not the address of a Dask scheduler", "--scheduler",
                          "give tcp://HOST:PORT as `dask scheduler` prints it, e.g. tcp://127.0.0.1:8786")
    return address, str(host), int(port)


def reach_scheduler(scheduler: str, in_process: bool = False) -> str:
    """The address of ``scheduler`` (:func:`scheduler_address`) once a Dask scheduler answers there
    within :data:`CONNECT_TIMEOUT_S`: a TCP connection (refused at once where nobody listens) and,
    for ``tcp://``, Dask's handshake (a server that accepts and stays silent held distributed's
    ``Client`` forever: its handshake read has no timeout). Else one :class:`UamoptError`, so a
    command says so before its work and no half-made Dask client is left behind."""
    import socket

    address, host, port = scheduler_address(scheduler, in_process)
    if address.startswith("inproc://"):  # in this process: the client's own connection says
        return address
    try:
        if not address.startswith("ucx://"):  # ucx is not TCP: the client's own connection says
            socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S).close()
        if address.startswith("tcp://"):  # tls and ws need the cluster's security settings: the client's
            _handshake(address)
    except OSError as exc:  # refused, unreachable, timed out (TimeoutError), an unknown host name
        raise UamoptError(f"cannot reach the Dask scheduler at {scheduler} ({error_line(exc)})", "--scheduler",
                          "start one with `dask scheduler`, check the address, or drop --scheduler") from None
    return address


def _handshake(address: str) -> None:
    """Open a Dask comm to ``address`` and close it, all within :data:`CONNECT_TIMEOUT_S`, on a
    loop of its own (a thread: the caller may run inside an event loop). Raises ``OSError``."""
    import asyncio

    from distributed.comm import connect as open_comm

    async def probe() -> None:
        comm = await asyncio.wait_for(open_comm(address, timeout=CONNECT_TIMEOUT_S), CONNECT_TIMEOUT_S)
        await comm.close()

    failure: list[BaseException] = []

    def run() -> None:
        try:
            asyncio.run(probe())
        except BaseException as exc:  # noqa: BLE001 - reported to the caller below
            failure.append(exc)

    thread = threading.Thread(target=run, name="uamopt-scheduler-probe", daemon=True)
    thread.start()
    thread.join(CONNECT_TIMEOUT_S + 2.0)
    if thread.is_alive() or (failure and isinstance(failure[0], (asyncio.TimeoutError, TimeoutError))):
        raise TimeoutError(f"no Dask handshake within {CONNECT_TIMEOUT_S:g} s: something else listens there")
    if failure:
        raise failure[0] if isinstance(failure[0], OSError) else OSError(error_line(failure[0]))


def connect(scheduler: str | None, workers: int | None, tasks: int, scratch: str | None = None):
    """A Dask client: on the cluster at ``scheduler``, or on a new loopback LocalCluster whose
    scratch space and TMPDIR are ``scratch`` (default: Dask's, ``dask-scratch-space`` in TMPDIR).

    Returns (client, cluster or None). Raises UamoptError when the scheduler cannot be reached
    within CONNECT_TIMEOUT_S.
    """
    import dask
    from distributed import Client, LocalCluster

    if scheduler:
        address = reach_scheduler(scheduler, in_process=True)
        logging.getLogger("distributed").setLevel(logging.ERROR)
        try:
            return Client(address, timeout=CONNECT_TIMEOUT_S), None
        except Exception as exc:  # noqa: BLE001 - OSError, TimeoutError: something listens there, not a scheduler
            failure = error_line(exc)
        # the half-made Client sits in a reference cycle; collected later, at an allocation inside the
        # next Client's start, its __del__ waited for the loop lock that start held (a bench run hung
        # there for the rest of its time limit): collect it here, where no lock is held
        gc.collect()
        raise UamoptError(f"cannot reach the Dask scheduler at {scheduler} ({failure})", "--scheduler",
                          "start one with `dask scheduler`, check the address, or drop --scheduler")
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
        # workers not daemonic: a daemonic process may not start children, and an exact solve in a
        # sweep's case runs in a child its time limit can end (uamopt/solvers/watchdog.py); the
        # cluster's close still ends them
        with dask.config.set({"temporary-directory": scratch, "distributed.worker.daemon": False}):
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

