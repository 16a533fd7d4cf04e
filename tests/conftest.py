"""Shared fixtures: the repository root and the paper-case stages, each computed once per session."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

pytest.register_assert_rewrite("checks", "oracles")

ROOT = Path(__file__).resolve().parents[1]
PAPER_CASE = ROOT / "models" / "paper_case.toml"

os.environ.setdefault("MPLBACKEND", "Agg")

# Property tests: under CI (CI set, as .ci/run does) the same examples every run, so a red CI can
# be re-run and reproduced; elsewhere Hypothesis explores new examples each run (and keeps the
# failing ones in .hypothesis/). HYPOTHESIS_PROFILE=ci derandomises a local run too.
from hypothesis import settings  # noqa: E402

settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("dev", print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if os.environ.get("CI") else "dev"))

#: every solve of the suite on one thread (uamopt.solvers.THREADS_ENV): two pytest workers share the 2
#: cores, and HiGHS's threads spin against each other when they outnumber them (a solve 3x slower at
#: load 4). Tests about threads unset it with monkeypatch.
os.environ.setdefault("UAMOPT_MAX_THREADS", "1")

#: the longest test files (10-60 s each on 2 cores), run first: ``make test``'s two workers take
#: whole files in collection order, and a long file taken last leaves the other worker idle
LONGEST_FIRST = ("test_notebooks.py", "test_replay.py", "test_sweep.py", "test_variants.py", "test_output_safety.py",
                 "test_benchmark.py", "test_report.py", "test_environment.py", "test_search_agreement.py")


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session):
    """Fill the on-disk caches once, in the controlling process, before ``make test``'s workers
    start: on a fresh clone each worker and each command run as a subprocess would otherwise
    compile the numba search for itself (about 7 s each), and on a fresh machine build
    matplotlib's font cache for itself. Both are instant when the caches exist."""
    if not hasattr(session.config, "workerinput"):
        import matplotlib.font_manager  # noqa: F401  (builds the font cache when there is none)

        from uamopt.planning.search import warm_up

        warm_up()


def pytest_collection_modifyitems(config, items):
    rank = {name: n for n, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: the rest keep their order


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


def _risk_run(path, overrides=()):
    """The scenario and its risk field (grid and city within), as ``.scenario``, ``.grid``, ``.field``."""
    from types import SimpleNamespace

    from uamopt.pipeline import compute_risk
    from uamopt.scenario import load_scenario

    scenario = load_scenario(path, list(overrides))
    field = compute_risk(scenario)
    return SimpleNamespace(scenario=scenario, grid=field.grid, city=field.city, field=field)


@pytest.fixture(scope="session")
def paper_run():
    """The paper case at its default 50 × 50 × 30 m cells."""
    return _risk_run(PAPER_CASE)


@pytest.fixture(scope="session")
def paper_model(paper_run):
    """The planning model (admissible cells, costs, buffer) of the paper case at 50 × 50 × 30 m."""
    from uamopt.planning import planning_model

    return planning_model(paper_run.scenario, paper_run.field)


@pytest.fixture(scope="session")
def coarse_run():
    """The paper case at 100 × 100 × 60 m cells: small enough for graph and figure tests."""
    return _risk_run(PAPER_CASE, ["grid.cell=[100,100,60]"])


@pytest.fixture(scope="session")
def paper_straight_plan():
    """(scenario, grid, straight network, generated plan) of the paper case, seed 0, with Eq. 29
    taken with equality (max_delay_scale = 1, not the calibrated 0.3).

    The return directions fly one cell layer up (``layer_offset_cells=1``), inside the r = 1
    conflict zone, not on the r + 1 layer of the planned network: opposite directions then meet
    head-on, a harder scheduling instance, and the one the regression values of the solver tests
    were recorded on."""
    from uamopt.grid import AirspaceGrid
    from uamopt.scenario import load_scenario
    from uamopt.schedule import generate_plan, straight_network

    scenario = load_scenario(PAPER_CASE)
    grid = AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent)
    network = straight_network(scenario, grid, layer_offset_cells=1)
    return scenario, grid, network, generate_plan(scenario, network, seed=0, max_delay_scale=1.0)


@pytest.fixture(scope="session")
def cluster(tmp_path_factory) -> str:
    """A separately started ``dask scheduler`` and two ``dask worker`` processes on loopback
    (random free ports); yields the scheduler's address."""
    import json
    import subprocess
    import sys
    import time

    from distributed import Client

    folder = tmp_path_factory.mktemp("cluster")
    dask = Path(sys.executable).parent / "dask"
    scheduler_file = folder / "scheduler.json"
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "cwd": folder}
    procs = [subprocess.Popen([str(dask), "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                               "--scheduler-file", str(scheduler_file)], **quiet)]
    try:
        # The scheduler creates the file before it finishes writing it: wait for whole JSON, not for
        # the file (an empty read made 17 tests error on a loaded CI machine).
        deadline = time.monotonic() + 60
        address = None
        while address is None:
            try:
                address = json.loads(scheduler_file.read_text())["address"]
            except (OSError, ValueError, KeyError):
                if time.monotonic() > deadline or procs[0].poll() is not None:
                    raise RuntimeError(f"dask scheduler wrote no usable {scheduler_file} "
                                       f"(exit code {procs[0].poll()})") from None
                time.sleep(0.1)
        for _ in range(2):
            procs.append(subprocess.Popen([str(dask), "worker", address, "--nthreads", "1", "--no-dashboard",
                                           "--host", "127.0.0.1"], **quiet))
        with Client(address, timeout=30) as client:
            client.wait_for_workers(2, timeout=120)
        yield address
        try:
            with Client(address, timeout=30) as client:
                client.shutdown()  # the scheduler closes its workers: 2-3 s where SIGTERM to each takes 8 s
        except (OSError, TimeoutError):
            pass  # a cluster that no longer answers is terminated below
    finally:
        deadline = time.monotonic() + 10
        for p in procs:
            try:
                p.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                p.terminate()
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


@pytest.fixture(scope="session")
def paper_schedule_dir(tmp_path_factory) -> Path:
    """A schedule folder of the paper case (highs, planned network) written by ``uamopt schedule``.

    Read-only for tests: copy it before changing anything in it.
    """
    from uamopt.cli import main

    out = tmp_path_factory.mktemp("paper_schedule") / "highs"
    assert main(["schedule", str(PAPER_CASE), "--solver", "highs", "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="session")
def paper_export(paper_schedule_dir, tmp_path_factory):
    """``paper_export(kind)``: a fresh copy of ``paper_schedule_dir`` after ``uamopt export KIND``."""
    import shutil

    from uamopt.cli import main

    def export(kind: str) -> Path:
        folder = tmp_path_factory.mktemp(kind) / "highs"
        shutil.copytree(paper_schedule_dir, folder)
        assert main(["export", kind, str(folder)]) == 0
        return folder

    return export


@pytest.fixture(scope="session")
def paper_problem(paper_straight_plan):
    """The scheduling model of the generated paper-case plan (120 flights, seed 0, straight tracks)."""
    from uamopt.schedule import build_problem

    scenario, _, _, flights = paper_straight_plan
    return build_problem(flights, scenario)


@pytest.fixture(scope="session")
def calibrated_problem(paper_straight_plan):
    """The scheduling model of the calibrated paper-case plan (uamopt/schedule/calibration.py)."""
    from uamopt.schedule import build_problem
    from uamopt.schedule.calibration import paper_case_plan

    scenario, _, network, _ = paper_straight_plan
    return build_problem(paper_case_plan(scenario, network, seed=0), scenario)


@pytest.fixture(scope="session")
def paper_highs(paper_problem):
    """HiGHS's proven optimum of ``paper_problem`` (a few seconds; solved once per session)."""
    from uamopt.solvers import SolverProfile, milp

    return milp.solve(paper_problem, SolverProfile("highs", time_limit_s=30.0, threads=2))
