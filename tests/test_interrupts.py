"""Ctrl-C and SIGTERM inside C++ and C callbacks (uamopt.interrupts): the interrupt is never
swallowed, stops a long solver at once, and leaves Python's own handler in place.

Each case runs in a fresh interpreter (real signals to itself; the test process is not touched).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _as_from_a_terminal() -> None:
    """The child starts with Ctrl-C at its default disposition, as a command typed in a terminal. An
    ignored SIGINT is inherited across exec: twice in full ``make test`` runs (stop 32) a pytest
    worker had SIGINT ignored when these scripts ran, and their interrupts never arrived; which
    earlier test leaves it so is not found yet (alone, or after test_windows, test_sweep or
    test_discovery in one worker, these tests pass)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def run(script: str, timeout: float = 120.0) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True, check=False,
                          timeout=timeout, preexec_fn=_as_from_a_terminal)


CALLBACK = """import ctypes, sys, time
from uamopt.interrupts import install_handlers
install_handlers()

def notify():  # numba's compiler calls Python back like this (llvmlite's object cache)
    raise KeyboardInterrupt

ctypes.CFUNCTYPE(None)(notify)()  # ctypes can only report the exception, then goes on
try:
    time.sleep(5)
except KeyboardInterrupt:
    sys.exit("the interrupt came back")
"""


def test_an_interrupt_swallowed_by_a_c_callback_comes_back():
    """Ctrl-C while numba compiled printed "Exception ignored on calling ctypes callback
    function", a traceback, and the command went on."""
    done = run(CALLBACK)
    assert (done.returncode, done.stderr) == (1, "the interrupt came back\n")


AFTER_CPSAT = """import os, signal, sys, time
sys.path.insert(0, "tests")
from instances import crossing_problem
import uamopt as ua
schedule = ua.solve(crossing_problem("weighted", (1.0, 10.0)), "cpsat")
assert schedule.status == "optimal", schedule.status
try:
    os.kill(os.getpid(), signal.SIGINT)
    time.sleep(5)
except KeyboardInterrupt:
    sys.exit("Ctrl-C still raises after CP-SAT")
"""


def test_ctrl_c_still_raises_after_a_cpsat_solve():
    """CP-SAT's own Ctrl-C handler (catch_sigint_signal) left SIGINT at SIG_DFL after every solve:
    a later Ctrl-C killed the process with no clean-up (staging folder and lock left behind)."""
    done = run(AFTER_CPSAT)
    assert (done.returncode, done.stderr) == (1, "Ctrl-C still raises after CP-SAT\n")


DURING = """import os, signal, sys, threading, time
sys.path.insert(0, "tests/benchmarks")
from bench_exact import ladder_problem
import uamopt as ua
from uamopt.interrupts import Terminated, install_handlers
from uamopt.solvers import SolverProfile
install_handlers()
problem = ladder_problem(1000)  # 1,000 flights: CP-SAT searches its whole time limit
threading.Timer(8.0, os.kill, (os.getpid(), signal.{sig})).start()  # after the warm start, inside the search
started = time.perf_counter()
try:
    schedule = ua.solve(problem, SolverProfile("{solver}", time_limit_s=120.0))
except KeyboardInterrupt as exc:
    sys.exit(f"{{type(exc).__name__}} after {{time.perf_counter() - started:.0f}} s")
print(schedule.status, schedule.solve_seconds)
"""


@pytest.mark.slow
@pytest.mark.parametrize(("solver", "sig", "raised"), [("cpsat", "SIGINT", "KeyboardInterrupt"),
                                                       ("cpsat", "SIGTERM", "Terminated"),
                                                       ("highs", "SIGINT", "KeyboardInterrupt")])
def test_an_interrupt_stops_a_long_solve_at_once(solver, sig, raised):
    """Ctrl-C in a CP-SAT search used to stop the search and return its incumbent as a
    "time_limit" schedule (written, exit 0); in HiGHS it waited for the time limit."""
    done = run(DURING.format(solver=solver, sig=sig), timeout=300)
    assert done.returncode == 1 and done.stdout == "", (done.stdout, done.stderr)
    name, seconds = done.stderr.split(" after ")
    # stopped by the interrupt (sent at 8 s), not by the 120 s limit: a margin no loaded machine closes
    assert name == raised and 8 <= int(seconds.split()[0]) < 90, done.stderr


def _swallowed(signum: int) -> Exception:
    """What an extension module does when our handler raises inside it: drops the interrupt and
    returns an error of its own, with no chain back (no ``__context__``, as from C)."""
    from uamopt import interrupts

    try:
        (interrupts._raise_terminated if signum == 15 else interrupts._raise_interrupt)(signum, None)
    except KeyboardInterrupt:
        pass
    return ValueError("Invalid affine transformation matrix")


@pytest.mark.parametrize("error", [ImportError('PyCapsule_Import could not import module "shapely"'),
                                   ValueError("Invalid affine transformation matrix")])
def test_an_error_with_no_chain_is_the_interrupt_only_after_a_signal(monkeypatch, error):
    """SIGTERM during shapely's Cython initialisation surfaced as an ImportError, and SIGTERM inside
    matplotlib's Agg ``draw_path`` (uamopt risk writing its figures) as ValueError("Invalid affine
    transformation matrix"), neither chained to the Terminated our handler raised: the CLI printed
    a traceback (both seen in CI, test_output_safety's random interrupts). The handler records
    what it raised, and interrupt_of finds it behind any error once a signal came."""
    from uamopt import interrupts

    monkeypatch.setattr(interrupts, "_LAST", [])
    assert interrupts.interrupt_of(error) is None  # no signal came: a real error stays one
    assert error.__context__ is None and error.__cause__ is None
    _swallowed(15)
    found = interrupts.interrupt_of(error)
    assert isinstance(found, interrupts.Terminated) and interrupts.handled(found) == interrupts.EXIT_SIGTERM
    monkeypatch.setattr(interrupts, "_LAST", [])
    _swallowed(2)
    found = interrupts.interrupt_of(error)
    assert type(found) is KeyboardInterrupt and interrupts.handled(found) == interrupts.EXIT_SIGINT


CLI_CUT = """import os, signal, sys
import uamopt.cli as cli

def cut(args):  # a command whose library drops the interrupt and raises its own error (matplotlib's Agg)
    try:
        os.kill(os.getpid(), signal.SIGTERM)
        signal.pthread_kill(signal.pthread_self(), 0)  # run the handler now
    except KeyboardInterrupt:
        pass
    raise ValueError("Invalid affine transformation matrix")

def plain(args):
    raise ValueError("a real bug")

parser = cli.build_parser
def patched():
    p = parser()
    for name, func in (("cut", cut), ("plain", plain)):
        p._subparsers._group_actions[0].add_parser(name).set_defaults(func=func)
    return p
cli.build_parser = patched
sys.exit(cli.main([sys.argv[1]]))
"""


@pytest.mark.parametrize(("command", "code", "line"), [("cut", 143, "terminated: nothing was written\n"),
                                                      ("plain", 1, None)])
def test_the_cli_reports_a_swallowed_sigterm_as_one_line(command, code, line):
    """Through ``uamopt.cli.main`` in a fresh interpreter: the error that replaced the interrupt is
    one line and exit 143; the same error with no signal is still a traceback (a bug stays one)."""
    done = subprocess.run([sys.executable, "-c", CLI_CUT, command], cwd=ROOT, capture_output=True, text=True,
                          check=False, timeout=120)
    assert done.returncode == code, done.stderr
    if line is None:
        assert "Traceback" in done.stderr and "a real bug" in done.stderr
    else:
        assert done.stderr == line


PYOMO_CUT = """import sys
import pyomo.environ as pyo
import uamopt.solvers.milp  # installs the filter on pyomo.core
m = pyo.ConcreteModel()
def rule(m, i):
    raise {error}
try:
    m.c = pyo.Constraint([1, 2], rule=rule)
except BaseException as exc:
    print("raised", type(exc).__name__)
"""


@pytest.mark.parametrize(("error", "logged"), [("KeyboardInterrupt", False), ("ValueError('a bug')", True)])
def test_pyomo_does_not_log_an_interrupt_during_a_model_build(error, logged):
    """Ctrl-C while HiGHS's Pyomo model was built printed "ERROR: Constructing component 'gap_below'
    from data=None failed: KeyboardInterrupt" on stdout before the interrupt went on (CI, the slow
    interrupt test on a loaded machine). The interrupt still propagates; a real error is still logged."""
    done = run(PYOMO_CUT.format(error=error))
    name = error.split("(")[0]
    assert done.returncode == 0 and f"raised {name}" in done.stdout, (done.stdout, done.stderr)
    assert ("Constructing component" in done.stdout + done.stderr) is logged


AT_DEADLINE = """import sys
sys.path.insert(0, "tests/benchmarks")
from bench_exact import ladder_problem
import uamopt as ua
from uamopt.solvers import SolverProfile
schedule = ua.solve(ladder_problem(1000), SolverProfile("highs", time_limit_s=20.0, threads=1))
print("status", schedule.status, schedule.extras.get("engine_termination"))
"""


@pytest.mark.slow
def test_highs_stopped_at_its_deadline_prints_no_pyomo_warning():
    """HiGHS stopped by uamopt's deadline callback (solvers/highs.py) made Pyomo print "WARNING: Received
    unhandled status=<HighsModelStatus.kInterrupt: 17> from solver HiGHS." before every time-limit
    result (seen in uamopt bench on airland9). The status is the time limit, with no warning."""
    done = run(AT_DEADLINE, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "status time_limit" in done.stdout, done.stdout
    assert "unhandled" not in done.stdout + done.stderr, (done.stdout, done.stderr)


SLOW_EXIT = """import sys, threading, time
import uamopt.cli as cli
end = cli._end_process
def announced(code):  # the command is over: only the end of the process is left
    print("EXITING", flush=True)
    end(code)
cli._end_process = announced
threading.Thread(target=time.sleep, args=(5,)).start()  # a library's worker thread the process waits for
sys.argv = ["uamopt", *sys.argv[1:]]
sys.exit(cli.main())  # as the console script calls it
"""


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_signal_during_the_shutdown_of_a_finished_command_keeps_its_exit_code(tmp_path, sig):
    """The console script's run is over (its line printed, --out complete) when the signal comes,
    during the interpreter's shutdown: exit 0 at once, as finished. Before, the run ended killed by
    the signal with a KeyboardInterrupt (or Terminated) traceback, its output complete."""
    import signal as signals

    out = tmp_path / "risk"
    proc = subprocess.Popen([sys.executable, "-c", SLOW_EXIT, "risk", "models/paper_case.toml", "--out", str(out)],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = proc.stdout.readline()  # the command's one result line: its work is done
    assert "risk" in first and (out / "summary.json").is_file(), first
    assert proc.stdout.readline() == "EXITING\n"  # the command has returned: only the shutdown is left
    proc.send_signal(getattr(signals, sig))
    _stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 0, (proc.returncode, stderr)
    assert "Traceback" not in stderr and "KeyboardInterrupt" not in stderr, stderr


TEARDOWN_PROBE = """import atexit, builtins, os
marks = os.environ["UAMOPT_TEST_MARKS"]
atexit.register(lambda: open(os.path.join(marks, "atexit"), "w").close())
class Probe:
    def __del__(self, open=open, join=os.path.join):  # runs only in the interpreter's teardown
        open(join(marks, "teardown"), "w").close()
builtins._uamopt_teardown_probe = Probe()
"""


def test_a_finished_command_runs_the_exit_hooks_and_skips_the_interpreters_teardown(tmp_path):
    """The console script ends a finished command after the exit hooks, without the teardown in
    which a library's daemon or native thread re-entering Python aborted the process (CI: ``uamopt
    risk`` stopped by SIGTERM printed its line, then "Fatal Python error: PyEval_RestoreThread ...
    Python runtime state: finalizing", exit -6; CPython gh-87135). A ``sitecustomize`` registers an
    exit hook and an object whose ``__del__`` only the teardown runs; before, both marks appeared."""
    site, marks, out = tmp_path / "site", tmp_path / "marks", tmp_path / "risk"
    site.mkdir()
    marks.mkdir()
    (site / "sitecustomize.py").write_text(TEARDOWN_PROBE)
    env = os.environ | {"PYTHONPATH": os.pathsep.join([str(site), *filter(None, [os.environ.get("PYTHONPATH")])]),
                        "UAMOPT_TEST_MARKS": str(marks)}
    done = subprocess.run([sys.executable, "-m", "uamopt", "risk", "models/paper_case.toml", "--set",
                           "grid.cell=[250,250,60]", "--no-figures", "--out", str(out)], cwd=ROOT, env=env,
                          capture_output=True, text=True, check=False, timeout=300)
    assert done.returncode == 0 and (out / "summary.json").is_file(), done.stderr
    assert done.stdout.startswith("risk field: 1,080 cells"), done.stdout  # stdout flushed before the end
    assert sorted(p.name for p in marks.iterdir()) == ["atexit"], done.stderr

    # the probe can see a teardown: the same interpreter with no uamopt command runs one
    (marks / "atexit").unlink()
    subprocess.run([sys.executable, "-c", "pass"], env=env, check=True, timeout=60)
    assert sorted(p.name for p in marks.iterdir()) == ["atexit", "teardown"]


def assert_one_interrupt_line(script: str, out) -> None:
    """``script`` (a uamopt command whose import is cut by Ctrl-C) ends with exit 130, the one line
    and nothing written to ``out``."""
    done = subprocess.run([sys.executable, "-c", script, str(out)], cwd=ROOT, capture_output=True, text=True,
                          check=False, timeout=120)
    assert done.returncode == 130, done.stderr[-3000:]
    assert done.stderr == f"interrupted: nothing was written to {out}\n"
    assert not out.exists()


NUMPY_CUT = """import sys
class Cut:  # numpy's import cut by Ctrl-C, as a signal inside its C extension's initialisation leaves it
    calls = 0
    def find_spec(self, name, path=None, target=None):
        if name == "numpy":
            Cut.calls += 1
            if Cut.calls == 1:
                raise KeyboardInterrupt
            raise ImportError("cannot load module more than once per process")
        return None
sys.meta_path.insert(0, Cut())
sys.argv = ["uamopt", "plan", "models/paper_case.toml", "--no-figures", "--out", sys.argv[1]]
from uamopt.cli import main
sys.exit(main())
"""


def test_ctrl_c_inside_numpys_import_is_one_line(tmp_path):
    """The census (SIGINT 0.05 s into `uamopt plan`, 1-3 of 42 interrupt cases) found the signal
    inside numpy's first import; the interrupt's own line then imported numpy again (through
    uamopt.outputs), which a half-initialised extension refuses: a 40-line ImportError traceback,
    exit 1. The line after an interrupt imports nothing heavy now."""
    out = tmp_path / "plan"
    assert_one_interrupt_line(NUMPY_CUT, out)


SHIPPED_CUT = """import sys
class Cut:  # Ctrl-C while the shipped-scenario lookup is imported, just after the command line is read
    def find_spec(self, name, path=None, target=None):
        if name == "uamopt.shipped":
            raise KeyboardInterrupt
        return None
sys.meta_path.insert(0, Cut())
sys.argv = ["uamopt", "risk", "paper_case", "--out", sys.argv[1]]
from uamopt.cli import main
sys.exit(main())
"""


def test_ctrl_c_while_the_shipped_scenario_is_looked_up_is_one_line(tmp_path):
    """The census (SIGINT into `uamopt risk`, SIGTERM into `uamopt schedule`, 0.035-0.05 s in)
    found the signal in the step between reading the command line and running it (the shipped
    scenario's lookup, importing importlib.resources), which no handler covered: a
    KeyboardInterrupt traceback and exit -2, or a Terminated traceback and exit 1."""
    out = tmp_path / "risk"
    assert_one_interrupt_line(SHIPPED_CUT, out)


CLUSTER_CUT = """import os, signal, sys, threading
import distributed
start = distributed.LocalCluster.__init__
def cut(self, *args, **kwargs):  # SIGTERM 0.3 s into the local cluster's start (its workers still starting)
    threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGTERM)).start()
    start(self, *args, **kwargs)
distributed.LocalCluster.__init__ = cut
sys.argv = ["uamopt", "sweep", sys.argv[1], "--out", sys.argv[2], "--workers", "2"]
from uamopt.cli import main
sys.exit(main())
"""


def test_sigterm_while_the_local_cluster_starts_is_one_line(tmp_path):
    """Before, the SIGTERM cut LocalCluster's start and its clean-up failed its own assert (a worker
    still in Status.init): a 30-line AssertionError traceback, exit 143."""
    from test_sweep_hostile import SWEEP

    sweep = tmp_path / "fast.toml"
    sweep.write_text(SWEEP)
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-c", CLUSTER_CUT, str(sweep), str(out)], cwd=ROOT, capture_output=True,
                          text=True, check=False, timeout=300)
    lines = [line for line in done.stderr.splitlines() if not line.startswith("sweep ")]
    assert done.returncode == 143 and "Traceback" not in done.stderr, done.stderr[-3000:]
    assert len(lines) == 1 and lines[0].startswith("terminated: "), done.stderr


def test_ctrl_c_just_after_the_result_line_keeps_exit_0(tmp_path):
    """Ctrl-C at several moments after ``uamopt plan`` printed its result line (its --out complete):
    each run exits 0 (or 130 saying the results were complete). Before, 11 of 12 such runs ended
    killed by SIGINT (-2, no line): the signal came in the interpreter's own teardown, where Python drops its handlers."""
    import signal as signals
    import time

    codes = []
    for k in range(6):
        out = tmp_path / f"plan{k}"
        proc = subprocess.Popen([sys.executable, "-m", "uamopt", "plan", "models/paper_case.toml", "--no-figures",
                                 "--out", str(out)], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        proc.stdout.readline()  # the result line: the work is done
        time.sleep(0.04 * k)  # a moment of the shutdown, not a timing assertion
        proc.send_signal(signals.SIGINT)
        _, stderr = proc.communicate(timeout=120)
        codes.append((proc.returncode, stderr[-300:]))
        assert (out / "tracks.json").is_file()
    # exit 0; or, where the signal still found the command's own code running (between its line and
    # its return: wider on a loaded machine), exit 130 with the one line saying the results were complete
    assert all(code == 0 or (code == 130 and err.strip().endswith("were complete before the interrupt")
                             and "Traceback" not in err) for code, err in codes), codes


LEAK = """import multiprocessing, os, sys
if sys.argv[1] == "quiet":
    from uamopt.experiments.engine import quiet_resource_tracker
    quiet_resource_tracker()
# what an interrupted sweep leaves: a semaphore registered with the tracker and never released
semaphore = multiprocessing.get_context("spawn").Lock()
sys.stderr.flush()
os._exit(0)  # no finalizer runs, as after a stopped cluster
"""


@pytest.mark.parametrize("mode", ["quiet", "default"])
def test_the_resource_tracker_cleans_up_a_leaked_semaphore_without_a_warning(mode):
    """After a sweep's interrupt line the tracker printed "UserWarning: resource_tracker: There
    appear to be 1 leaked semaphore objects" (2 of 9 SIGINTs 1.8-2.2 s into a sweep). The
    ``default`` case shows the leak is real, so the ``quiet`` case can fail."""
    proc = subprocess.run([sys.executable, "-c", LEAK, mode], cwd=ROOT, capture_output=True, text=True, check=False,
                          timeout=60)
    assert proc.returncode == 0, proc.stderr
    leaked = "leaked semaphore" in proc.stderr
    assert leaked == (mode == "default"), proc.stderr
