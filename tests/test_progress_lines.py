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


def test_the_commands_use_it():
    from uamopt.workflows import progress

    bar = progress(2, "risk")
    try:
        assert isinstance(bar, Steps)
    finally:
        bar.close()
