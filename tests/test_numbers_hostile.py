"""Numbers at the boundary (issue 22, item 6): every number read from a file or ``--set`` passes one
check (finite, within its documented range, integers within int64), and what a run can afford is
refused up front or, past the guards, in one line.

The hostile command lines themselves are rows of tests/test_hostile.py's table (``number-*``,
``out-*``); here are the checks a table row cannot make: the key table declares a finite range
for every numeric key and docs/interfaces.md lists them, the readers' ranges are the verifier's,
and runs under an address-space limit (``ulimit -v``, ``resource.setrlimit(RLIMIT_AS)`` in a
child process) end in one line.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
import typing

import pytest
from conftest import PAPER_CASE, ROOT

from uamopt.scenario import key_ranges, schema as scenario_module

GB = 2**30


def _numeric_keys(model, prefix: str = "") -> set[str]:
    """Every scenario key whose type holds an int or a float, found from the annotations alone."""
    out = set()

    def leaves(tp):
        yield tp
        for arg in typing.get_args(tp):
            yield from leaves(arg)

    for name, info in model.model_fields.items():
        types = list(leaves(info.annotation))
        sub = [t for t in types if isinstance(t, type) and issubclass(t, scenario_module._Section)]
        if sub:
            out |= _numeric_keys(sub[0], f"{prefix}{name}.")
        elif any(t in (int, float) for t in types):
            out.add(prefix + name)
    return out


def test_every_numeric_scenario_key_declares_a_finite_range():
    """The key table is the one boundary check of scenarios: no numeric key without both bounds."""
    ranges = key_ranges()
    numeric = _numeric_keys(scenario_module.Scenario)
    assert len(numeric) > 80 and numeric == set(ranges), sorted(numeric ^ set(ranges))
    for key, text in ranges.items():
        assert "inf" not in text, (key, text)


def test_the_ranges_are_documented_in_interfaces_md():
    """docs/interfaces.md's table of ranges is the key table's, row for row."""
    doc = (ROOT / "docs" / "interfaces.md").read_text(encoding="utf-8")
    rows = dict(re.findall(r"^\| `([a-z0-9_.]+)` \| ([^|]+) \|$", doc, flags=re.MULTILINE))
    expected = key_ranges()
    assert {k: rows.get(k, "").strip() for k in expected} == expected


def test_the_readers_ranges_are_the_verifiers():
    """A flights file the verifier would refuse is refused first: the same bounds, twice written
    (the verifier shares no code with the model)."""
    from uamopt import bounds
    from uamopt.schedule import verify

    assert (bounds.SPEED_MPS.lo, bounds.SPEED_MPS.hi) == verify.SPEED_RANGE_MPS
    assert bounds.MAX_TIME_S == verify.MAX_TIME_S and bounds.MAX_COORD_M == verify.MAX_COORD_M
    assert bounds.CONFLICT_RADIUS.hi == verify.MAX_RADIUS and bounds.VERTICAL_RATE_MPS.hi == verify.VERTICAL_RATE_MPS


@pytest.mark.parametrize("value", [10**400, -(10**400), math.nan, math.inf, -math.inf, 1e300, True, "7", None])
def test_one_boundary_check_refuses_in_one_line(value):
    from uamopt.bounds import Range, check_number
    from uamopt.errors import InputFileError

    with pytest.raises(InputFileError) as info:
        check_number(value, "speed_mps", "flights.json: flight F1", "give m/s", Range(0.1, 200.0))
    line = info.value.line()
    assert line.startswith("speed_mps must be a number in [0.1, 200], got ") and len(line) < 200 and "\n" not in line


def test_integers_are_compared_exactly_and_held_to_int64():
    from uamopt.bounds import INT64_MAX, Range

    seed = Range(0, INT64_MAX, integer=True)
    assert seed.holds(INT64_MAX) and not seed.holds(INT64_MAX + 1) and not seed.holds(1.0) and not seed.holds(True)
    assert Range(0.0, 1e6).holds(10**6) and not Range(0.0, 1e6).holds(10**6 + 1)  # exact, no float rounding


def test_an_error_line_stays_one_line_whatever_it_holds():
    from uamopt.errors import UamoptError

    line = UamoptError("output path is a file: out/a\nb\x1b[2J", "--out", "give a folder\r").line()
    assert line == "output path is a file: out/a\\nb\\x1b[2J (--out): give a folder\\r"


# --- runs under an address-space limit ------------------------------------------------------------

def _limited(args: list[str], limit_gb: float, timeout_s: float = 120.0) -> subprocess.CompletedProcess:
    """``uamopt ARGS`` in a child process whose address space is limited to ``limit_gb`` (``ulimit -v``)."""
    code = ("import resource, sys; from uamopt.cli import main; "
            f"resource.setrlimit(resource.RLIMIT_AS, ({int(limit_gb * GB)}, {int(limit_gb * GB)})); "
            f"sys.exit(main({args!r}))")
    return subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=timeout_s,
                          check=False)


def _one_error_line(run: subprocess.CompletedProcess, fragment: str) -> str:
    assert "Traceback" not in run.stderr + run.stdout, run.stderr[-3000:]
    lines = [line for line in run.stderr.splitlines() if not line.startswith(("risk:", "flights:", "schedule:"))]
    assert run.returncode == 2 and len(lines) == 1 and lines[0].startswith("error: "), (run.returncode, run.stderr[-3000:])
    assert " (" in lines[0] and "): " in lines[0] and fragment in lines[0], lines[0]
    return lines[0]


def _untouched(out) -> None:
    assert [p.name for p in out.iterdir()] == ["keep.txt"]
    assert not [p for p in out.parent.iterdir() if "uamopt-stage" in p.name or p.name.endswith(".lock")]


@pytest.fixture
def out(tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    (folder / "keep.txt").write_text("written before the command", encoding="utf-8")
    return folder


def test_a_grid_past_the_address_space_limit_is_one_line(out):
    """``grid.memory_limit_gb = 1000`` under a 4 GB address-space limit: the guard lets the grid through
    (the user raised it), numpy cannot allocate it, and the run ends in one line, exit 2, --out as it
    was (it was numpy's ArrayMemoryError traceback)."""
    run = _limited(["risk", str(PAPER_CASE), "--set", "grid.cell=[2,2,2]", "--set", "grid.memory_limit_gb=1000",
                    "--out", str(out)], limit_gb=4)
    line = _one_error_line(run, "out of memory: Unable to allocate")
    assert "grid.memory_limit_gb" in line
    _untouched(out)


def test_the_default_memory_limit_honours_the_address_space_limit(out):
    """Without grid.memory_limit_gb the guard's default is within ``ulimit -v``: the same grid is refused
    before anything is allocated, naming its size and the limit."""
    run = _limited(["risk", str(PAPER_CASE), "--set", "grid.cell=[2,2,2]", "--out", str(out)], limit_gb=4)
    # 120 MiB + 50 B × 506,250,000 cells = 23.7 GiB (uamopt/grid/grid.py, MEMORY_MODEL["risk"])
    line = _one_error_line(run, "a grid of 506,250,000 cells needs about 23.7 GB, more than the limit of")
    assert float(re.search(r"limit of ([\d.]+) GB", line).group(1)) < 4
    _untouched(out)


def test_ten_million_aircraft_are_refused_up_front(out):
    """``schedule.aircraft = 10^7`` ran past 3 GB in 89 s: now the plan's size (6 × 10⁷ flights) is
    refused before a flight is made, with the estimate and the limit key (under a 3 GB address-space
    limit, so the unguarded code fails fast too)."""
    run = _limited(["flights", str(PAPER_CASE), "--set", "grid.cell=[250,250,60]", "--set", "network.tracks='straight'",
                    "--set", "schedule.aircraft=10000000", "--out", str(out)], limit_gb=3, timeout_s=60)
    line = _one_error_line(run, "a plan of 60,000,000 flights of 10,000,000 aircraft needs about 57.7 GB")
    assert "schedule.memory_limit_gb" in line
    _untouched(out)


def test_overlapping_flights_beyond_the_memory_limit_are_refused_before_the_conflict_search(out):
    """20,000 aircraft in one hour: 1.3 × 10⁹ pairs of overlapping flying windows (unguarded, the conflict
    search took 22 GB before the kernel killed it); refused from their count, before a pair is made,
    naming ``schedule.memory_limit_gb``."""
    run = _limited(["flights", str(PAPER_CASE), "--set", "grid.cell=[250,250,60]", "--set", "network.tracks='straight'",
                    "--set", "schedule.aircraft=20000", "--out", str(out)], limit_gb=3, timeout_s=90)
    line = _one_error_line(run, "scheduling 120,000 flights with ")
    assert "pairs of flights whose flying windows overlap needs about" in line and "schedule.memory_limit_gb" in line
    _untouched(out)


def test_the_plan_guard_lets_an_ordinary_plan_through(tmp_path):
    """The guard's estimate is not a refusal of ordinary plans: 200 aircraft (1,200 flights, 34,000
    conflicting pairs) are estimated at a few megabytes and scheduled."""
    from uamopt.pipeline import build_problem, generate_flights, scenario_grid
    from uamopt.scenario import load_scenario
    from uamopt.schedule.occupancy import candidate_count
    from uamopt.schedule.plan import (
        BYTES_PER_FLIGHT,
        BYTES_PER_WINDOW_PAIR,
        straight_network,
    )

    scenario = load_scenario(PAPER_CASE, ["grid.cell=[250,250,60]", "schedule.aircraft=200"])
    flights = generate_flights(scenario, straight_network(scenario, scenario_grid(scenario)))
    problem = build_problem(flights, scenario)
    assert len(flights) == 1200 and len(problem.conflicts) > 0
    need = len(flights) * BYTES_PER_FLIGHT + candidate_count(flights) * BYTES_PER_WINDOW_PAIR
    assert need < 0.1 * GB  # the estimate of a small plan is small


def test_the_schedule_memory_limit_key_acts():
    """``schedule.memory_limit_gb`` is read: the ordinary 200-aircraft plan above, under a limit of
    1 kB, is refused before a flight is made, naming the key (with the default limit it is scheduled)."""
    from uamopt.errors import UamoptError
    from uamopt.pipeline import generate_flights, scenario_grid
    from uamopt.scenario import load_scenario
    from uamopt.schedule.plan import straight_network

    scenario = load_scenario(PAPER_CASE, ["grid.cell=[250,250,60]", "schedule.aircraft=200",
                                          "schedule.memory_limit_gb=1e-6"])
    with pytest.raises(UamoptError, match=r"schedule\.memory_limit_gb"):
        generate_flights(scenario, straight_network(scenario, scenario_grid(scenario)))
