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
        self.stream.write(f"{self.label}: {self.done}/{self.total} {self.unit}, {elapsed:.0f} s" + (f" - {note}" if note else "") + "\n")
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
