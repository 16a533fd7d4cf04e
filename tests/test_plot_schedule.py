"""The scheduling figures (uamopt/plotting/schedule.py), read back from the SVG they write: the bars,
their positions and lengths must be the schedule's departures, flight times and delays."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from instances import crossing_problem

from uamopt import plotting
from uamopt.solvers import SolverProfile, solve


def plot_gantt(problem, schedule, path):
    return plotting.save(plotting.gantt(problem, schedule), path)


def plot_delay_comparison(problem, schedules, path):
    return plotting.save(plotting.delays(problem, schedules), path)


SVG = "{http://www.w3.org/2000/svg}"
CRIMSON = "#dc143c"  # the delay line of the Gantt chart


def data_shapes(path) -> list[dict]:
    """Every path drawn inside the axes' clip box (bars and data lines; not spines, ticks or the
    legend), in SVG pixels: x grows right, y grows down."""
    shapes = []
    for element in ET.parse(path).iter(f"{SVG}path"):
        if "clip-path" not in element.attrib:
            continue
        numbers = [float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", element.attrib["d"])]
        xs, ys = numbers[0::2], numbers[1::2]
        style = dict(item.split(": ") for item in element.attrib.get("style", "").split("; ") if ": " in item)
        shapes.append({"x0": min(xs), "x1": max(xs), "y0": min(ys), "y1": max(ys), "closed": "z" in element.attrib["d"],
                       "fill": style.get("fill", ""), "stroke": style.get("stroke", "")})
    return shapes


def bars(shapes, kind: str) -> list[dict]:
    """Filled bars (``"filled"``) or hollow, hatched ones (``"hatched"``)."""
    hatched = [s for s in shapes if s["closed"] and s["fill"].startswith("url(")]
    filled = [s for s in shapes if s["closed"] and s["fill"].startswith("#")]
    return filled if kind == "filled" else hatched


@pytest.fixture(scope="module")
def crossing():
    """Greedy cancels B1 and C1; SOA flies all three with A1 delayed 10 s (tests/instances.py)."""
    problem = crossing_problem("weighted", (0.1, 0.9))
    return problem, solve(problem, "greedy"), solve(problem, "soa")


def test_gantt_bars_are_the_flights(crossing, tmp_path):
    problem, _, soa = crossing
    assert soa.delay_s.tolist() == [10.0, 0.0, 0.0]
    out = plot_gantt(problem, soa, tmp_path / "gantt.svg")
    assert out == tmp_path / "gantt.svg"
    shapes = data_shapes(out)
    rows = sorted(bars(shapes, "filled"), key=lambda s: s["y0"])  # rows top-down: aircraft A, B, C
    assert len(rows) == 3 and not bars(shapes, "hatched")
    a, b, c = rows
    px_per_s = (c["x1"] - c["x0"]) / 16.0  # C1 flies 400 m at 25 m/s
    assert (a["x1"] - a["x0"]) / px_per_s == pytest.approx(20.0, rel=1e-4)  # A1: 500 m
    assert (b["x1"] - b["x0"]) / px_per_s == pytest.approx(16.0, rel=1e-4)
    # departures: A1 at 0 + 10 s delay, B1 at 10 s, C1 at 0 s
    assert (a["x0"] - c["x0"]) / px_per_s == pytest.approx(10.0, rel=1e-4)
    assert (b["x0"] - c["x0"]) / px_per_s == pytest.approx(10.0, rel=1e-4)
    (delay,) = [s for s in shapes if s["stroke"] == CRIMSON]  # A1's delay, from its planned departure
    assert (delay["x1"] - delay["x0"]) / px_per_s == pytest.approx(10.0, rel=1e-4) and delay["x0"] == pytest.approx(c["x0"])
    assert a["y0"] < delay["y0"] < a["y1"]


def test_gantt_draws_cancelled_flights_hatched_at_their_planned_slot(crossing, tmp_path):
    problem, greedy, _ = crossing
    shapes = data_shapes(plot_gantt(problem, greedy, tmp_path / "gantt.svg"))
    (flown,) = bars(shapes, "filled")
    b, c = sorted(bars(shapes, "hatched"), key=lambda s: s["y0"])
    assert flown["y1"] < b["y0"] and b["y1"] < c["y0"]  # rows A, B, C
    px_per_s = (flown["x1"] - flown["x0"]) / 20.0
    assert (b["x0"] - flown["x0"]) / px_per_s == pytest.approx(10.0, rel=1e-4)  # B1 planned at 10 s
    assert c["x0"] == pytest.approx(flown["x0"]) and (c["x1"] - c["x0"]) / px_per_s == pytest.approx(16.0, rel=1e-4)
    assert not [s for s in shapes if s["stroke"] == CRIMSON]  # nobody delayed


def test_delay_comparison_bar_heights_are_the_delays(calibrated_problem, tmp_path):
    problem = calibrated_problem
    schedules = {"greedy": solve(problem, "greedy"),
                 "greedy_exact": solve(problem, SolverProfile("greedy", options={"exact_gaps": True}))}
    shapes = data_shapes(plot_delay_comparison(problem, schedules, tmp_path / "delays.svg"))
    filled = [s for s in bars(shapes, "filled") if s["y1"] - s["y0"] > 1e-6]
    hollow = [s for s in bars(shapes, "hatched") if s["y1"] - s["y0"] > 1e-6]
    heights = np.sort([s["y1"] - s["y0"] for s in filled])
    delays = np.sort(np.concatenate([s.delay_s[s.operated & (s.delay_s > 0)] for s in schedules.values()]))
    assert len(heights) == len(delays) > 20
    np.testing.assert_allclose(heights / heights[-1], delays / delays[-1], rtol=1e-4)
    # a cancelled flight is a hollow bar as tall as its delay threshold Δd, on the same scale
    thresholds = np.sort(np.concatenate([problem.delay_upper_s[~s.operated] for s in schedules.values()]))
    thresholds = thresholds[thresholds > 0]
    assert len(hollow) == len(thresholds) > 10
    np.testing.assert_allclose(np.sort([s["y1"] - s["y0"] for s in hollow]) / heights[-1], thresholds / delays[-1],
                               rtol=1e-4)
