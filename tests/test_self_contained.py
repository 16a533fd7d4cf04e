"""The repository is self-contained: nothing in it points outside it (users do not have the
project's working folder beside their checkout), and the documentation's links resolve."""

from __future__ import annotations

import re
import subprocess

from conftest import ROOT

# Spelled in pieces so that this file does not match itself.
OUTSIDE = ("shared" + "/", "MODEL" + "_NOTES", "INTERFACES" + ".md")
SKIP_DIRS = {".git", ".venv", "out", "build", "__pycache__", ".hypothesis", ".pytest_cache"}


def tracked_files() -> list:
    """``git ls-files``, or every file outside build and cache folders when this is no checkout."""
    try:
        names = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True,
                               timeout=60).stdout.decode().split("\0")
        return [ROOT / n for n in names if n and (ROOT / n).is_file()]
    except (OSError, subprocess.CalledProcessError):
        return [p for p in ROOT.rglob("*") if p.is_file() and not (SKIP_DIRS & set(p.relative_to(ROOT).parts))
                and not any(part.endswith(".egg-info") for part in p.parts)]


def test_no_file_points_outside_the_repository():
    offenders = []
    for path in tracked_files():
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:  # binary data (figures, rasters, .pbf)
            continue
        for number, line in enumerate(text.splitlines(), 1):
            offenders += [f"{path.relative_to(ROOT)}:{number}: {word}" for word in OUTSIDE if word in line]
    assert not offenders, "\n".join(offenders)


def test_documentation_links_resolve():
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    assert {p.name for p in pages} >= {"README.md", "readings.md", "interfaces.md"}
    broken = []
    for page in pages:
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", page.read_text(encoding="utf-8")):
            if "://" not in target and not (page.parent / target).exists():
                broken.append(f"{page.relative_to(ROOT)} -> {target}")
    assert not broken, broken


def test_docstrings_cite_pages_that_exist():
    cited = set()
    for path in (ROOT / "uamopt").rglob("*.py"):
        cited |= set(re.findall(r"docs/[a-z_]+\.md", path.read_text(encoding="utf-8")))
    assert {"docs/readings.md", "docs/interfaces.md", "docs/exact_scheduling.md"} <= cited
    assert all((ROOT / page).is_file() for page in cited)
