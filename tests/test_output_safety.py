"""Output safety (docs/interfaces.md, "Output folders"): after any interrupt ``--out`` is absent or
complete, TMPDIR and the folder beside ``--out`` hold no leftovers, a second run into the same
folder is refused at once, the user's own files in ``--out`` survive, and a full disk or
``--out ''`` end with one line.

Every run is a real ``uamopt`` subprocess with a private TMPDIR. Signals are real: SIGINT to the
whole process group (what Ctrl-C in a terminal sends) or SIGTERM to the process (what ``kill``
sends). ``UAMOPT_TEST_PAUSE_IN_MOVE`` (uamopt.outputs) holds a run inside its final move so a
signal lands there deterministically.
"""

from __future__ import annotations

import json
import os
import queue
import random
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import uamopt as ua
from uamopt.cli import main
from uamopt.outputs import PAUSE_ENV, staged_output

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "models" / "paper_case.toml"
TINY = ["--set", "grid.cell=[250,250,60]"]  # 1,080 cells: `uamopt risk` takes ~3 s, mostly imports and the figure
REPRODUCE = ["--set", "grid.cell=[50,50,50]", "--set", "tracks.table2_cell_m=50", "--set", "tracks.table4_cells=[50]",
             "--set", "schedule.aircraft=10", "--no-figures"]  # ~8 s
EXIT = {signal.SIGINT: 130, signal.SIGTERM: 143}
WORD = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated"}


# Starts `uamopt ARGS...` with SIGINT at its default (a shell ignores it in background jobs, such as
# `make test &`; a terminal's foreground command does not) and an optional real file-size limit.
AS_IN_A_TERMINAL = """import os, resource, signal, sys
signal.signal(signal.SIGINT, signal.SIG_DFL)
limit = int(sys.argv[1])
if limit >= 0:
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
os.execv(sys.executable, [sys.executable, "-m", "uamopt", *sys.argv[2:]])
"""


class Run:
    """A ``uamopt`` subprocess in its own session, its stderr read line by line."""

    def __init__(self, args, tmpdir: Path, pause_s: float | None = None, file_size_limit: int = -1):
        env = {k: v for k, v in os.environ.items() if k != PAUSE_ENV} | {"TMPDIR": str(tmpdir)}
        if pause_s is not None:
            env[PAUSE_ENV] = str(pause_s)
        self.proc = subprocess.Popen([sys.executable, "-c", AS_IN_A_TERMINAL, str(file_size_limit), *map(str, args)],
                                     cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                     start_new_session=True)
        self.lines: queue.Queue = queue.Queue()
        self.stderr: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stderr:
            self.stderr.append(line)
            self.lines.put(line)
        self.lines.put(None)

    def wait_for(self, text: str, timeout: float = 120.0) -> None:
        deadline = time.monotonic() + timeout
        while (line := self.lines.get(timeout=max(0.0, deadline - time.monotonic()))) is not None:
            if text in line:
                return
        pytest.fail(f"the run ended before printing {text!r}: {''.join(self.stderr)}")

    def send(self, sig: int) -> None:
        """SIGINT to the process group (Ctrl-C), SIGTERM to the process (kill)."""
        try:
            os.killpg(self.proc.pid, sig) if sig == signal.SIGINT else os.kill(self.proc.pid, sig)
        except ProcessLookupError:
            pass

    def finish(self, timeout: float = 180.0) -> tuple[int, str, str]:
        stdout = self.proc.stdout.read()
        code = self.proc.wait(timeout)
        while self.lines.get(timeout=timeout) is not None:
            pass
        return code, stdout, "".join(self.stderr)


def leftovers(out: Path) -> list[str]:
    """uamopt's staging folders and lock files beside ``out`` (and inside it)."""
    near = [p.name for p in out.parent.iterdir() if p.name.startswith(f".{out.name}.uamopt")] if out.parent.exists() else []
    inside = [p.name for p in out.iterdir() if p.name.startswith(".uamopt")] if out.is_dir() else []
    return near + inside


def risk_complete(out: Path, figures: bool = True) -> None:
    """Every file `uamopt risk` promises, loadable."""
    field = ua.load_risk(out)
    assert field.risk.shape == (10, 18, 6)  # 2500 x 4500 x 360 m at 250 x 250 x 60 m cells
    assert json.loads((out / "summary.json").read_text())["cells"] == 1080
    assert (out / "risk.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" if figures else not (out / "risk.png").exists()


def schedule_complete(out: Path) -> None:
    """Every file `uamopt schedule` promises, loadable, and the schedule passes the verifier."""
    schedule = ua.load_schedule(out)
    assert len(schedule.operated) == json.loads((out / "summary.json").read_text())["flights"]
    assert main(["verify", str(out)]) == 0


def check_outcome(code: int, stderr: str, out: Path, tmpdir: Path, sig: int, complete) -> str:
    """The invariants of an interrupted run; returns "absent" or "complete"."""
    seen = (code, signal.Signals(sig).name, stderr)
    assert "Traceback" not in stderr, seen
    assert leftovers(out) == [] and list(tmpdir.iterdir()) == [], seen
    last = stderr.strip().splitlines()[-1] if stderr.strip() else ""
    # -sig with nothing printed: the signal came before uamopt's handlers were in place or as the
    # interpreter exited, and took its default action
    killed = code == -sig and stderr == ""
    if not out.exists():
        # the shorter line: the signal came before the command line was read
        assert killed or (code == EXIT[sig] and last in (f"{WORD[sig]}: nothing was written to {out}",
                                                         f"{WORD[sig]}: nothing was written")), seen
        return "absent"
    complete(out)
    assert killed or code == 0 or (code == EXIT[sig] and last == f"{WORD[sig]}: the results in {out} were complete "
                                                                 "before the interrupt"), seen
    return "complete"


def test_ctrl_c_inside_the_move_completes_it(tmp_path):
    """The move is never torn: a signal inside it is held, and the run ends once the folder is whole."""
    tmpdir, out = tmp_path / "tmp", tmp_path / "out" / "risk"
    tmpdir.mkdir()
    run = Run(["risk", PAPER, *TINY, "--out", out], tmpdir, pause_s=1.5)
    run.wait_for(PAUSE_ENV)
    run.send(signal.SIGINT)
    code, _, stderr = run.finish()
    assert code == 130, stderr
    assert check_outcome(code, stderr, out, tmpdir, signal.SIGINT, risk_complete) == "complete"


def test_an_interrupt_while_merging_into_an_existing_folder_keeps_the_users_files(tmp_path):
    """Into an existing --out each file is replaced atomically; the pause falls after the first
    file moved, so only holding the signal until the last one makes the folder complete."""
    tmpdir, out = tmp_path / "tmp", tmp_path / "risk"
    tmpdir.mkdir()
    (out / "mine").mkdir(parents=True)
    (out / "mine" / "notes.txt").write_text("keep")
    (out / "summary.json").write_text("{}")  # an old result: replaced
    run = Run(["risk", PAPER, *TINY, "--out", out], tmpdir, pause_s=1.5)
    run.wait_for(PAUSE_ENV)
    assert (out / "risk.npz").exists() and not (out / "risk.png").exists()  # inside the move, one file in
    run.send(signal.SIGTERM)
    code, _, stderr = run.finish()
    assert code == 143
    assert check_outcome(code, stderr, out, tmpdir, signal.SIGTERM, risk_complete) == "complete"
    assert (out / "mine" / "notes.txt").read_text() == "keep"


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["ctrl-c", "sigterm"])
def test_an_interrupt_while_computing_leaves_nothing(sig, tmp_path):
    tmpdir, out = tmp_path / "tmp", tmp_path / "risk"
    tmpdir.mkdir()
    run = Run(["risk", PAPER, *TINY, "--out", out], tmpdir)
    deadline = time.monotonic() + 60
    while not any(p.name.startswith(".risk.uamopt-stage-") for p in tmp_path.iterdir()):  # staging: computing
        assert run.proc.poll() is None and time.monotonic() < deadline, "".join(run.stderr)
        time.sleep(0.005)
    run.send(sig)
    code, _, stderr = run.finish()
    assert check_outcome(code, stderr, out, tmpdir, sig, risk_complete) == "absent"


def test_a_second_run_into_the_same_folder_is_refused_at_once(tmp_path):
    """Two `schedule` runs into one folder used to verify each other's files; now the second one
    stops before doing anything while the first holds the folder (until it has verified)."""
    tmpdir, out = tmp_path / "tmp", tmp_path / "sched"
    tmpdir.mkdir()
    first = Run(["schedule", PAPER, "--solver", "greedy", "--out", out], tmpdir, pause_s=2.5)
    first.wait_for(PAUSE_ENV)
    second = Run(["schedule", PAPER, "--solver", "greedy", "--out", out], tmpdir)
    code, stdout, stderr = second.finish()
    assert first.proc.poll() is None  # refused while the first is still in its move
    assert code == 2 and stdout == ""
    assert stderr == f"error: another uamopt run is writing to {out} (--out): wait for it to finish, or choose " \
                     "another folder\n"
    code, _, stderr = first.finish()
    assert code == 0 and "Traceback" not in stderr
    schedule_complete(out)
    assert leftovers(out) == [] and list(tmpdir.iterdir()) == []


@pytest.mark.slow
def test_ctrl_c_in_a_sweep_keeps_the_finished_cases_and_prints_no_traceback(tmp_path):
    """Ctrl-C reaches the Dask worker processes too, which printed tracebacks; they ignore it now
    and the sweep stops them. The finished cases stay; TMPDIR (the cluster's scratch) is clean."""
    tmpdir, out = tmp_path / "tmp", tmp_path / "sweep"
    tmpdir.mkdir()
    run = Run(["sweep", ROOT / "tests/data/sweeps/tiny.toml", "--out", out, "--workers", 2], tmpdir)
    deadline = time.monotonic() + 120
    while not list((out / "parts").glob("*.parquet")):
        assert run.proc.poll() is None and time.monotonic() < deadline, "".join(run.stderr)
        time.sleep(0.01)
    run.send(signal.SIGINT)
    code, _, stderr = run.finish()
    assert code == 130 and "Traceback" not in stderr, stderr
    assert f"interrupted: finished cases are saved in {out}: re-run the same command to finish\n" in stderr
    assert list((out / "parts").glob("*.parquet")) and not (out / "results.parquet").exists()
    assert leftovers(out) == [] and list(tmpdir.iterdir()) == []


HOLD = """import sys, time
from uamopt.outputs import output_lock
with output_lock(sys.argv[1]):
    print("held", flush=True)
    time.sleep(60)
"""


def test_a_sweep_into_a_folder_in_use_is_refused(tmp_path, capsys):
    """The results folder of a sweep is locked like any --out (another process holds it here)."""
    out = tmp_path / "sweep"
    holder = subprocess.Popen([sys.executable, "-c", HOLD, str(out)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline() == "held\n"
        assert main(["sweep", str(ROOT / "tests/data/sweeps/tiny.toml"), "--out", str(out)]) == 2
    finally:
        holder.kill()
        holder.wait()
    assert capsys.readouterr().err == (f"error: another uamopt run is writing to {out} (--out): wait for it to finish, "
                                       "or choose another folder\n")
    assert not out.exists()


@pytest.mark.slow
def test_the_next_run_clears_what_a_killed_run_left(tmp_path):
    """SIGKILL cannot be caught: the run's staging folder and lock file stay beside --out until
    the next run into the same folder, which takes the (released) lock and removes them."""
    tmpdir, out = tmp_path / "tmp", tmp_path / "risk"
    tmpdir.mkdir()
    run = Run(["risk", PAPER, *TINY, "--no-figures", "--out", out], tmpdir, pause_s=30)
    run.wait_for(PAUSE_ENV)
    run.send(signal.SIGKILL)
    assert run.finish()[0] == -signal.SIGKILL
    left = leftovers(out)
    assert sorted(name.split("-stage-")[0] for name in left) == [".risk.uamopt", ".risk.uamopt.lock"] and not out.exists()
    assert main(["risk", str(PAPER), *TINY, "--no-figures", "--out", str(out)]) == 0
    risk_complete(out, figures=False)
    assert leftovers(out) == []


def test_a_users_folder_is_never_replaced(tmp_path, capsys):
    """A folder where the command writes a file is refused before anything is written."""
    out = tmp_path / "risk"
    (out / "summary.json").mkdir(parents=True)
    (out / "summary.json" / "mine.txt").write_text("keep")
    assert main(["risk", str(PAPER), *TINY, "--no-figures", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == (f"error: the folder {out / 'summary.json'} is in the way of the file summary.json that the command "
                   f"writes (--out): move it away or choose another folder; nothing was written\n")
    assert sorted(p.name for p in out.iterdir()) == ["summary.json"] and leftovers(out) == []
    assert (out / "summary.json" / "mine.txt").read_text() == "keep"


def test_a_subfolder_is_merged_not_replaced(tmp_path):
    """A subfolder the command writes (reproduce's schedules/) joins the user's folder of that
    name: the user's files in it stay, the command's files replace their namesakes."""
    out = tmp_path / "paper"
    (out / "schedules" / "mine").mkdir(parents=True)
    (out / "schedules" / "mine" / "notes.txt").write_text("keep")
    (out / "schedules" / "weighted").mkdir()
    (out / "schedules" / "weighted" / "old.csv").write_text("old")
    (out / "report.md").write_text("old")
    with staged_output(out) as stage:
        (stage / "schedules" / "weighted").mkdir(parents=True)
        (stage / "schedules" / "weighted" / "new.csv").write_text("new")
        (stage / "report.md").write_text("new")
    assert {str(p.relative_to(out)): p.read_text() for p in out.rglob("*") if p.is_file()} == {
        "schedules/mine/notes.txt": "keep", "schedules/weighted/old.csv": "old", "schedules/weighted/new.csv": "new",
        "report.md": "new"}
    assert leftovers(out) == []


@pytest.mark.slow
def test_reproduce_keeps_the_users_files_and_subfolders(tmp_path):
    """`reproduce` used to delete a same-named subfolder the user had in --out."""
    tmpdir, out = tmp_path / "tmp", tmp_path / "paper"
    tmpdir.mkdir()
    (out / "schedules" / "mine").mkdir(parents=True)
    (out / "schedules" / "mine" / "notes.txt").write_text("keep")
    (out / "notes.txt").write_text("mine")
    (out / "report.md").write_text("old")
    code, _, stderr = Run(["reproduce", PAPER, *REPRODUCE, "--out", out], tmpdir).finish()
    assert code == 0, stderr
    assert (out / "schedules" / "mine" / "notes.txt").read_text() == "keep" and (out / "notes.txt").read_text() == "mine"
    assert (out / "report.md").read_text().startswith("# ")  # the new report replaced the old one
    for solver in ("greedy", "ga", "soa", "highs", "cpsat"):
        schedule_complete(out / "schedules" / "weighted" / solver)
    assert leftovers(out) == [] and list(tmpdir.iterdir()) == []


@pytest.mark.parametrize("command", [["risk", str(PAPER)], ["sweep", str(ROOT / "tests/data/sweeps/tiny.toml")]])
def test_an_empty_out_is_refused(command, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main([*command, "--out", ""]) == 2
    assert capsys.readouterr().err == "error: the output folder is an empty path (--out): give a folder, e.g. --out out/run\n"
    assert list(tmp_path.iterdir()) == []


def test_a_full_disk_leaves_the_folder_untouched(tmp_path):
    """A real file-size limit (RLIMIT_FSIZE) makes writing risk.npz fail, as a full disk would."""
    tmpdir, out = tmp_path / "tmp", tmp_path / "risk"
    tmpdir.mkdir()
    out.mkdir()
    (out / "summary.json").write_text("old")

    code, stdout, stderr = Run(["risk", PAPER, *TINY, "--no-figures", "--out", out], tmpdir,
                               file_size_limit=8192).finish()  # risk.npz is 21 kB at these cells
    assert code == 2 and stdout == ""
    assert stderr == (f"error: cannot write the results: File too large ({out}): free some space or choose a folder on "
                      f"another disk; nothing was written to it\n")
    assert sorted(p.name for p in out.iterdir()) == ["summary.json"] and (out / "summary.json").read_text() == "old"
    assert leftovers(out) == [] and list(tmpdir.iterdir()) == []


COMMANDS = {  # what a random trial runs: arguments, the completeness check, a typical run's seconds
    "risk": (["risk", PAPER, *TINY], risk_complete, 3.5),
    "schedule": (["schedule", PAPER, "--solver", "cpsat"], schedule_complete, 5.0),
    "plan": (["plan", PAPER, *TINY, "--no-figures"], lambda out: ua.load_tracks(out), 8.0),
}


def interrupt_trials(tmp_path: Path, trials: int, seed: int, commands: list[str]) -> dict[str, int]:
    """Signals at seeded random moments, from 0.5 s after the start (the interpreter is up) to
    past a typical run's end, or inside the move (the pause hook) in a quarter of the trials;
    returns the count of each outcome."""
    rng = random.Random(seed)
    outcomes: dict[str, int] = {}
    for trial in range(trials):
        name = rng.choice(commands)
        args, complete, typical_s = COMMANDS[name]
        sig = rng.choice([signal.SIGINT, signal.SIGTERM])
        tmpdir, out = tmp_path / f"tmp{trial}", tmp_path / f"out{trial}" / name
        tmpdir.mkdir()
        in_move = rng.random() < 0.25
        run = Run([*args, "--out", out], tmpdir, pause_s=1.0 if in_move else None)
        if in_move:
            run.wait_for(PAUSE_ENV)
        else:
            time.sleep(rng.uniform(0.5, 1.2 * typical_s))
        run.send(sig)
        code, _, stderr = run.finish()
        state = check_outcome(code, stderr, out, tmpdir, sig, complete)
        key = f"{name} {signal.Signals(sig).name} {'in the move' if in_move else 'at random'}: {state}"
        outcomes[key] = outcomes.get(key, 0) + 1
    return outcomes


def test_interrupts_at_random_moments(tmp_path):
    """Two interrupted `risk` runs; check_outcome holds each to the invariants (no traceback, no
    staging folder or temporary file left, the folder absent or complete, the right last line)."""
    interrupt_trials(tmp_path, trials=2, seed=10, commands=["risk"])


@pytest.mark.slow
def test_many_interrupts_at_random_moments(tmp_path):
    outcomes = interrupt_trials(tmp_path, trials=40, seed=2024, commands=list(COMMANDS))
    print(json.dumps(outcomes, indent=1, sort_keys=True))
    assert any(k.endswith("absent") for k in outcomes) and any(k.endswith("complete") for k in outcomes)
