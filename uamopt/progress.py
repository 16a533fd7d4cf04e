"""Progress of long runs: a tqdm bar on a terminal, plain lines otherwise (logs, CI, notebooks)."""

from __future__ import annotations

import sys
import time


class Progress:
    """Counts finished units of work.

    On a terminal: a tqdm bar. Elsewhere: one line ``<label>: k/n <unit> ... , <elapsed> s`` at the
    start, then at most every ``interval_s`` seconds (every update when ``every = True``), and at
    the end. Lines go to ``stream`` (stderr by default), never to stdout.
    """

    def __init__(self, total: int, label: str, unit: str = "cases", *, interval_s: float = 10.0, every: bool = False,
                 stream=None):
        self.total, self.label, self.unit = total, label, unit
        self.interval_s, self.every = interval_s, every
        self.stream = stream if stream is not None else sys.stderr
        self.done = 0
        self.start = self.last = time.monotonic()
        self.bar = None
        if hasattr(self.stream, "isatty") and self.stream.isatty():
            from tqdm import tqdm

            self.bar = tqdm(total=total, desc=label, unit=unit.rstrip("s") or None, file=self.stream, leave=False)
        else:
            self._line("started")

    def _line(self, note: str) -> None:
        elapsed = time.monotonic() - self.start
        self.stream.write(f"{self.label}: {self.done}/{self.total} {self.unit}, {elapsed:.0f} s"
                          + (f" - {note}" if note else "") + "\n")
        self.stream.flush()
        self.last = time.monotonic()

    def update(self, n: int = 1, note: str = "") -> None:
        self.done += n
        if self.bar is not None:
            self.bar.update(n)
            if note:
                self.bar.set_postfix_str(note[:60], refresh=False)
        elif self.every or time.monotonic() - self.last >= self.interval_s:
            self._line(note)

    def close(self, note: str = "done") -> None:
        if self.bar is not None:
            self.bar.close()
        else:
            self._line(note)

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close("done" if exc[0] is None else "stopped")


class Steps:
    """Progress of one command's steps (``uamopt risk``, ``plan``, ``network``, ``schedule``,
    ``reproduce``, ``replay``), with tqdm's ``update`` / ``set_description``.

    On a terminal: a tqdm bar. Elsewhere (a log, CI, a notebook's subprocess): silent for the first
    ``after_s`` seconds, so that a quick command prints nothing; then one plain line
    ``<label>: k/n steps, T s - <current step>`` at most every ``interval_s`` seconds, written by a
    daemon thread so that one long step (a solver, the BlueSky run) still shows it is alive, and a
    last line when it ends. Lines go to ``stream`` (stderr), never to stdout.
    """

    def __init__(self, total: int, label: str, *, after_s: float = 5.0, interval_s: float = 10.0, stream=None):
        import threading

        self.total, self.label, self.after_s, self.interval_s = total, label, after_s, interval_s
        self.stream = stream if stream is not None else sys.stderr
        self.done, self.note, self.printed = 0, "", False
        self.start = time.monotonic()
        self.last = self.start - interval_s  # the first line may come as soon as after_s has passed
        self.bar = None
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = None
        if hasattr(self.stream, "isatty") and self.stream.isatty():
            from tqdm import tqdm

            self.bar = tqdm(total=total, desc=label, file=self.stream, leave=False)
        else:
            self._thread = threading.Thread(target=self._tick, name=f"uamopt-progress-{label}", daemon=True)
            self._thread.start()

    def _line(self, note: str) -> None:
        with self._lock:
            elapsed = time.monotonic() - self.start
            text = f"{self.label}: {self.done}/{self.total} steps, {elapsed:.0f} s" + (f" - {note}" if note else "")
            try:
                self.stream.write(text + "\n")
                self.stream.flush()
            except (OSError, ValueError):  # a closed or full stream must not end the work
                pass
            self.printed, self.last = True, time.monotonic()

    def _due(self) -> bool:
        now = time.monotonic()
        return now - self.start >= self.after_s and now - self.last >= self.interval_s

    def _tick(self) -> None:
        while not self._stop.wait(min(0.5, self.interval_s)):
            if self._due():
                self._line(self.note)

    def update(self, n: int = 1) -> None:
        self.done += n
        if self.bar is not None:
            self.bar.update(n)
        elif self._due():
            self._line(self.note)

    def set_description(self, text: str) -> None:
        """Name the step now running (shown on the next line, or beside the bar)."""
        self.note = str(text)
        if self.bar is not None:
            self.bar.set_description(f"{self.label}: {text}")

    def close(self, note: str = "done") -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=1.0)
        if self.bar is not None:
            self.bar.close()
        elif self.printed:
            self._line(note)

    def __enter__(self) -> Steps:
        return self

    def __exit__(self, *exc) -> None:
        self.close("done" if exc[0] is None else "stopped")
