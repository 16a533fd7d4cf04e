"""Shared fixtures: the repository root and small scenarios computed once per session."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAPER_CASE = ROOT / "models" / "paper_case.toml"

os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def paper_run():
    """The paper case at its default 50 × 50 × 30 m cells."""
    from uamopt.scenario import load_scenario
    from uamopt.stages import compute_risk

    return compute_risk(load_scenario(PAPER_CASE))


@pytest.fixture(scope="session")
def paper_straight_plan():
    """(scenario, grid, straight network, generated plan) of the paper case, seed 0, with Eq. 29
    taken with equality (max_delay_scale = 1, not the calibrated 0.3)."""
    from uamopt.grid import AirspaceGrid
    from uamopt.scenario import load_scenario
    from uamopt.schedule import generate_plan, straight_network

    scenario = load_scenario(PAPER_CASE)
    grid = AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent)
    network = straight_network(scenario, grid)
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
        deadline = time.monotonic() + 60
        while not scheduler_file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        for _ in range(2):
            procs.append(subprocess.Popen([str(dask), "worker", address, "--nthreads", "1", "--no-dashboard",
                                           "--host", "127.0.0.1"], **quiet))
        with Client(address, timeout=30) as client:
            client.wait_for_workers(2, timeout=120)
        yield address
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
