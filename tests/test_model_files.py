"""The exact model as MPS / LP for any MILP solver, and its answer read back (issue 40, point 9).

The outside solver is HiGHS's own file reader (``highspy.Highs.readModel``): it sees only the file,
never uamopt's model object, and writes its answer with ``writeSolution``, as any solver would.
The answer read back is checked by the enumeration oracle (tests/oracles.py) and the file verifier."""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import highspy
import pytest
from hypothesis import HealthCheck, given, settings
from instances import crossing_problem
from oracles import broken, exact_optimum, model_data, score
from strategies import tiny_problems

from uamopt.errors import InputFileError, UamoptError
from uamopt.schedule import write_schedule
from uamopt.schedule.verify import verify_dir
from uamopt.solvers.model_files import columns_path, read_solution, write_model

OBJ_TOL = 1e-6


def outside_solve(model_file, solution_file) -> tuple[str, float]:
    """HiGHS reading the file alone; (its model status, its objective)."""
    h = highspy.Highs()
    h.setOptionValue("output_flag", False)  # threads left alone: HiGHS keeps one pool per process (test_infeasible.py)
    assert h.readModel(str(model_file)) in (highspy.HighsStatus.kOk, highspy.HighsStatus.kWarning)
    h.run()
    h.writeSolution(str(solution_file), 0)
    return h.modelStatusToString(h.getModelStatus()), h.getInfo().objective_function_value


@settings(max_examples=10, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(tiny_problems(max_flights=5))
def test_an_outside_solver_on_the_file_finds_the_enumerated_optimum(case):
    _, problem = case
    with tempfile.TemporaryDirectory() as folder:
        _outside_agrees(problem, Path(folder))


def _outside_agrees(problem, tmp_path: Path) -> None:
    data = model_data(problem)
    best, _, _ = exact_optimum(data)
    for suffix in (".mps", ".lp"):
        model_file, _ = write_model(problem, tmp_path / f"model{suffix}")
        status, value = outside_solve(model_file, tmp_path / "answer.sol")
        assert status == "Optimal"
        assert value == pytest.approx(best, abs=OBJ_TOL)  # the file holds the paper's model, whole
        schedule = read_solution(problem, model_file, tmp_path / "answer.sol")
        assert broken(data, schedule.operated, schedule.delay_s) == []
        assert score(data, schedule.operated, schedule.delay_s) == pytest.approx(best, abs=OBJ_TOL)
        assert (schedule.termination, schedule.proved_for) == ("stopped", "none")  # the outside claim is not ours


def test_the_answer_written_as_a_folder_passes_the_verifier(tmp_path):
    problem = crossing_problem("lexicographic", (0.6, 0.4))
    model_file, side = write_model(problem, tmp_path / "model.mps")
    outside_solve(model_file, tmp_path / "answer.sol")
    schedule = read_solution(problem, model_file, tmp_path / "answer.sol", solver="highs-binary")
    write_schedule(tmp_path / "out", problem, schedule)
    assert verify_dir(tmp_path / "out") == []
    mapping = json.loads(side.read_text())
    text = model_file.read_text()
    assert mapping["flights"] == ["A1", "C1", "B1"]
    for fid in mapping["flights"]:  # each flight's decision is a column of the file
        assert f" {mapping['operate'][fid]} " in text and f" {mapping['delay'][fid]} " in text


def test_wrong_answers_and_files_are_one_clear_error(tmp_path):
    problem = crossing_problem("weighted", (0.6, 0.4))
    model_file, side = write_model(problem, tmp_path / "model.lp")
    mapping = json.loads(side.read_text())
    (tmp_path / "empty.sol").write_text("nothing here\n")
    with pytest.raises(InputFileError, match=r"none of the flights' operate variables"):
        read_solution(problem, model_file, tmp_path / "empty.sol")
    # A1 and C1 both flown at zero delay: they cross in one zone at once (tests/instances.py)
    lines = [f"{mapping['operate'][f]} 1" for f in ("A1", "C1")] + [f"{mapping['delay'][f]} 0" for f in ("A1", "C1")]
    (tmp_path / "bad.sol").write_text("\n".join(lines) + "\n")
    with pytest.raises(InputFileError, match=r"breaks the model: A1 and C1 depart 0 s apart"):
        read_solution(problem, model_file, tmp_path / "bad.sol")
    (tmp_path / "ok.sol").write_text(f"{mapping['operate']['B1']} 1\n")  # the other columns absent: 0
    assert read_solution(problem, model_file, tmp_path / "ok.sol").operated.tolist() == [False, False, True]
    side.write_text(json.dumps({**mapping, "flights": ["X", "C1", "B1"]}))
    with pytest.raises(InputFileError, match="other flights"):
        read_solution(problem, model_file, tmp_path / "ok.sol")
    with pytest.raises(UamoptError, match=r"\.mps or \.lp"):
        write_model(problem, tmp_path / "model.txt")
    assert not list(tmp_path.glob("*.part")) and not columns_path(tmp_path / "model.txt").exists()


def test_the_flights_command_writes_the_model(tmp_path):
    out = tmp_path / "inst"
    run = subprocess.run([sys.executable, "-m", "uamopt", "flights", "paper_case", "--out", str(out), "--model", "lp"],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert (out / "model.lp").is_file() and (out / "model.lp.columns.json").is_file()
    mapping = json.loads((out / "model.lp.columns.json").read_text())
    flights = json.loads((out / "flights.json").read_text())
    assert mapping["flights"] == [f["id"] for f in flights["flights"]] and mapping["objective_kind"] == "lexicographic"
