"""The check every solver output goes through in the tests: written files, the independent
verifier (uamopt/schedule/verify.py) and the objective recomputed by tests/oracles.py."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from oracles import objective_from_folder

from uamopt.schedule import write_schedule
from uamopt.schedule.verify import verify_dir

OBJ_TOL = 1e-6  # |objective| ≲ 200 and every time to ~1e-7 s: a safe absolute tolerance


def assert_verified(problem, schedule, folder: str | Path | None = None) -> float:
    """Write ``schedule``, check it with the verifier, and check its reported objective against
    Eqs. 20-22 recomputed from schedule.csv and flights.json. Returns that objective."""
    assert schedule.status != "infeasible" and schedule.objective is not None
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(folder) if folder is not None else Path(tmp) / "schedule"
        write_schedule(out, problem, schedule)
        assert verify_dir(out) == []
        recomputed = objective_from_folder(out, problem.weights, problem.objective_kind)
    assert schedule.objective == pytest.approx(recomputed, abs=OBJ_TOL)
    return recomputed
