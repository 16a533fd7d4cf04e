"""The README's notebook snippet runs verbatim (issue 39: it loaded folders only the command-line
examples had written). It runs in a temporary folder whose ``models`` is the repository's, so
nothing is written into the checkout."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def python_blocks(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


@pytest.mark.slow
def test_the_readme_python_snippet_runs_verbatim(tmp_path):
    (block,) = python_blocks((ROOT / "README.md").read_text(encoding="utf-8"))
    (tmp_path / "models").symlink_to(ROOT / "models")
    script = tmp_path / "snippet.py"
    script.write_text(block + "\nprint('objective', ua.load_schedule('out/nb_sched').objective, schedule.objective)\n",
                      encoding="utf-8")
    env = {**os.environ, "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=1800)
    assert done.returncode == 0, done.stderr[-3000:]
    loaded, solved = map(float, done.stdout.split("objective")[-1].split())
    assert loaded == pytest.approx(solved, rel=1e-12)
    assert (tmp_path / "risk.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
