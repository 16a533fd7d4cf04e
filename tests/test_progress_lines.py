"""Plain-line progress off a terminal (uamopt.progress.Steps): what a log, CI or a
notebook's subprocess sees from ``risk``, ``plan``, ``network``, ``schedule``, ``reproduce`` and
``replay``: nothing from a quick command, a line at least every interval from a long one, even
while one step (a solver, the BlueSky run) runs on."""

from __future__ import annotations

import io
import time

from uamopt.progress import Steps


def test_a_quick_command_prints_nothing():
    stream = io.StringIO()
    with Steps(3, "plan", stream=stream) as bar:  # the default 5 s before the first line
        bar.set_description("search")
        bar.update(3)
    assert stream.getvalue() == ""


def test_a_long_step_shows_it_is_alive_and_the_end_is_said():
    stream = io.StringIO()
    with Steps(2, "replay", after_s=0.2, interval_s=0.3, stream=stream) as bar:
        bar.update(1)
        bar.set_description("BlueSky simulating 116 flights")
        time.sleep(1.6)  # one long step with no update: the ticker thread writes the lines
        bar.update(1)
    lines = stream.getvalue().splitlines()
    during = [line for line in lines if "BlueSky simulating 116 flights" in line and line.startswith("replay: 1/2 steps, ")]
    assert len(during) >= 2, lines
    assert lines[-1].startswith("replay: 2/2 steps, ") and lines[-1].endswith(" - done")


def test_an_interrupted_run_says_stopped():
    stream = io.StringIO()
    try:
        with Steps(4, "reproduce", after_s=0.0, interval_s=0.1, stream=stream) as bar:
            bar.set_description("schedule (lexicographic): soa")
            time.sleep(0.3)
            raise KeyboardInterrupt
    except KeyboardInterrupt:
        pass
    assert stream.getvalue().splitlines()[-1].endswith(" - stopped")


def test_a_long_command_prints_its_lines_when_piped(tmp_path):
    """`uamopt schedule` with a 15 s exact solve (longer than the 10 s between lines), its stderr a
    pipe: plain step lines, the solve's own among them, and no bar."""
    import subprocess
    import sys

    profile = tmp_path / "h.toml"
    profile.write_text('solver = "highs"\ntime_limit_s = 15.0\nthreads = 1\n', encoding="utf-8")
    done = subprocess.run([sys.executable, "-m", "uamopt", "schedule", "paper_case", "--solver", str(profile),
                           "--set", 'schedule.objective="weighted"', "--set", "schedule.flights=600",
                           "--set", "schedule.aircraft=100", "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    lines = done.stderr.splitlines()
    assert lines and all(line.startswith("schedule: ") for line in lines), done.stderr
    assert any(" - solving (h): " in line and "incumbent" in line for line in lines), done.stderr
    assert lines[-1].endswith(" - done") and "\r" not in done.stderr
