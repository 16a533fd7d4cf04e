"""Count the outcomes of tests/test_hostile.py's table: cases tried, tracebacks, wrong exit codes,
malformed error lines and torn outputs (``--out`` or an input changed).

    .venv/bin/python tests/benchmarks/hostile_census.py [--list] [--timeout SECONDS]

The test asserts each case; this script runs the same table in one process without stopping, so
the counts can be quoted (and compared with an older checkout of uamopt on ``PYTHONPATH``).
"""

from __future__ import annotations

import contextlib
import io
import signal
import sys
import tempfile
import traceback
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from hostile_files import write_all
from test_hostile import CASES, _argv, _out, _snapshot

from uamopt.cli import main


class Hang(Exception):
    """A case still running after --timeout seconds."""


def _alarm(signum, frame):
    raise Hang


def run_case(case, files: Path, tmp: Path, timeout_s: int = 0) -> list[str]:
    """The faults of one case: 'hang', 'traceback', 'exit code', 'error line', 'torn output'."""
    _, line, expected, fragment = case
    out = _out(tmp)
    before = _snapshot(files)
    stdout, stderr = io.StringIO(), io.StringIO()
    faults = []
    signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(timeout_s)
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        try:
            code = main(_argv(line, files, out))
        except SystemExit as exc:
            code = exc.code
        except Hang:
            faults, code = ["hang"], None
        except BaseException:  # noqa: BLE001 - a traceback the user would see
            traceback.print_exc()
            code = None
        finally:
            signal.alarm(0)
    if (code is None and not faults) or "Traceback" in stderr.getvalue():
        faults.append("traceback")
    if code != expected:
        faults.append("exit code")
    lines = stderr.getvalue().strip().splitlines()
    if expected == 2 and code == 2 and not (len(lines) == 1 and lines[0].startswith("error: ") and fragment in lines[0]):
        faults.append("error line")
    if sorted(p.name for p in out.iterdir()) != ["keep.txt"] or _snapshot(files) != before:
        faults.append("torn output")
    return faults


def main_census(show: bool, timeout_s: int = 0) -> Counter:
    with tempfile.TemporaryDirectory(prefix="hostile-") as tmp:
        files = write_all(Path(tmp) / "files")
        counts: Counter = Counter()
        for n, case in enumerate(CASES):
            (Path(tmp) / f"case{n}").mkdir()
            faults = run_case(case, files, Path(tmp) / f"case{n}", timeout_s)
            counts.update(faults)
            if show and faults:
                print(f"{case[0]}: {', '.join(faults)}")
    print(f"cases tried: {len(CASES)}; hangs: {counts['hang']}; tracebacks: {counts['traceback']}; "
          f"wrong exit codes: {counts['exit code']}; "
          f"malformed error lines: {counts['error line']}; torn outputs: {counts['torn output']}")
    return counts


if __name__ == "__main__":
    args = sys.argv[1:]
    main_census("--list" in args, int(args[args.index("--timeout") + 1]) if "--timeout" in args else 0)
