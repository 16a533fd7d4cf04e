"""``uamopt reproduce`` on a small case, and report.md read back: every number its Table 3,
Table 4 and Fig. 21 sections show must be the one in the files it claims to summarise
(schedules/*/*/summary.json, tracks.json), or what an independent command computes."""

from __future__ import annotations

import contextlib
import io
import itertools
import json
import re
from pathlib import Path

import pytest
from conftest import PAPER_CASE
from oracles import objective_from_folder
from test_cli import cli

from uamopt.cli import main
from uamopt.schedule.verify import verify_dir

# 50 m cubic cells everywhere (Table 2 on the same grid as the network and the Pareto sweep),
# Table 4 at 50 and 100 m, 10 aircraft (60 flights) so that every solver finishes in a second.
SMALL = ["grid.cell=[50,50,50]", "tracks.table2_cell_m=50", "tracks.table4_cells=[50,100]", "schedule.aircraft=10"]
EXTENT = "grid.extent=[2500.0,4500.0,350.0]"  # the 50 m grid's whole cells: what Table 4's runs use


@pytest.fixture(scope="module")
def reproduced(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("reproduce") / "paper"
    args = ["reproduce", str(PAPER_CASE), "--out", str(out)]
    for item in SMALL:
        args += ["--set", item]
    err = io.StringIO()
    with contextlib.redirect_stderr(err):  # the progress lines (plain off a terminal)
        assert main(args) == 0
    (out.parent / "stderr.txt").write_text(err.getvalue(), encoding="utf-8")
    return out


def test_the_progress_counts_every_step(reproduced):
    """Was: "reproduce: 34/36 steps, 47 s - done" (the buffer variant and the Pareto front never counted)."""
    lines = [line for line in (reproduced.parent / "stderr.txt").read_text().splitlines() if line.startswith("reproduce: ")]
    last = re.fullmatch(r"reproduce: (\d+)/(\d+) steps, \d+ s - done", lines[-1])
    assert last and last.group(1) == last.group(2), lines


def sections(report: str) -> dict[str, str]:
    """Heading (without '## ') -> body."""
    parts = re.split(r"^## ", report, flags=re.M)[1:]
    return {p.split("\n", 1)[0]: p.split("\n", 1)[1] for p in parts}


def table(body: str) -> list[list[str]]:
    """The rows (cells stripped) of the first Markdown table in ``body``, header excluded."""
    rows = [line for line in body.splitlines() if line.startswith("|")]
    return [[c.strip() for c in row.strip("|").split("|")] for row in rows[2:]]


def number(cell: str) -> float:
    """A table cell's own figure, without the paper's in brackets or a unit."""
    return float(cell.split("[")[0].split()[0])


def section(reproduced: Path, start: str) -> str:
    found = [body for head, body in sections((reproduced / "report.md").read_text()).items() if head.startswith(start)]
    assert len(found) == 1, start
    return found[0]


def test_reproduce_writes_the_report(reproduced):
    report = (reproduced / "report.md").read_text()
    assert "Operational risk field" in report and "![risk map](risk.png)" in report
    assert "27.4684" in report  # terminal speed at m_p = 0 beside the reference 27.468
    assert "Table 2 analogue" in report and "Route network" in report
    expected = {"risk.npz", "risk.png", "summary.json", "report.md", "tracks.json", "tracks.png", "network.json",
                "network.png", "pareto.png", "gantt.png", "delays.png", "gantt_weighted.png", "delays_weighted.png",
                "view.html"}
    assert expected <= {p.name for p in reproduced.iterdir()}
    view = (reproduced / "view.html").read_text(encoding="utf-8")  # the best schedule's 3-D playback (uamopt view)
    assert "Plotly.addFrames" in view and '"name":"buildings"' in view
    for objective in ("lexicographic", "weighted"):  # a Gantt per solver, not only the best one's
        assert all((reproduced / "schedules" / objective / s / "gantt.png").stat().st_size > 0
                   for s in ("greedy", "ga", "soa", "highs", "cpsat"))


@pytest.mark.parametrize("objective", ["weighted", "lexicographic"])
def test_table3_shows_the_written_schedules(reproduced, objective):
    rows = table(section(reproduced, f"Multi-aircraft scheduling: Table 3 analogue, {objective}"))
    assert [r[0] for r in rows] == ["greedy", "ga", "soa", "highs", "cpsat"]
    summaries = {}
    for r in rows:
        folder = reproduced / "schedules" / objective / r[0]
        s = summaries[r[0]] = json.loads((folder / "summary.json").read_text())
        assert r[1] == s["status"]
        assert (number(r[2]), number(r[3])) == (s["operated"], s["cancelled"])
        assert number(r[4]) == pytest.approx(s["total_delay_s"], abs=0.05 + 1e-9)  # printed to 0.1 s
        assert number(r[5]) == pytest.approx(s["total_delay_s"] / 10, abs=0.005)  # T_d = total / G, Eq. 21
        # the objective shown is Eqs. 20-22 of the written schedule, recomputed independently
        assert number(r[6]) == pytest.approx(objective_from_folder(folder, (0.6, 0.4), objective), abs=5e-5)
        assert r[7] == ("-" if s["bound"] is None else f"{s['bound']:.4f}")
        assert r[10] == ("yes" if verify_dir(folder) == [] else "NO") == "yes"
    optimum = min(s["objective"] for s in summaries.values() if s["status"] == "optimal")
    for r in rows:  # 'to optimum' is the distance to the best proven optimum
        assert number(r[8]) == pytest.approx(summaries[r[0]]["objective"] - optimum, abs=5e-5)
        assert number(r[8]) >= -5e-5
    assert summaries["highs"]["status"] == "optimal" and number(rows[3][8]) == 0.0


def test_table4_shows_the_optimal_tracks(reproduced, tmp_path, capsys):
    rows = table(section(reproduced, "Track planning at finer cells: Table 4 analogue"))
    assert [r[0] for r in rows] == ["50 m", "100 m"]
    # 50 m: the Table 2 run, written to tracks.json
    optimal = json.loads((reproduced / "tracks.json").read_text())["stages"]["optimal"]
    expected = [f"{optimal['risk_cost']:.1f}", f"{optimal['transport_cost']:.4f}", str(optimal["n_waypoints"]),
                f"{optimal['length_m']:.0f}"]
    assert [c.split(" [")[0] for c in rows[0][1:5]] == expected
    # 100 m: what `uamopt plan` computes on its own at those cells over the same extent
    code, _, err = cli(capsys, "plan", str(PAPER_CASE), "--set", "grid.cell=[100,100,100]", "--set", EXTENT,
                       "--out", str(tmp_path / "plan100"))
    assert code == 0, err
    optimal = json.loads((tmp_path / "plan100" / "tracks.json").read_text())["stages"]["optimal"]
    assert [c.split(" [")[0] for c in rows[1][1:5]] == [
        f"{optimal['risk_cost']:.1f}", f"{optimal['transport_cost']:.4f}", str(optimal["n_waypoints"]),
        f"{optimal['length_m']:.0f}"]
    assert number(rows[0][5]) > 0 and number(rows[1][5]) > 0


def test_pareto_section_is_a_front(reproduced):
    rows = table(section(reproduced, "Risk–cost trade-off: Fig. 21 analogue"))
    groups: dict[str, list[tuple[float, float]]] = {}
    for label, w4, w5, risk, cost in rows:
        assert float(w4) + float(w5) == pytest.approx(1.0, abs=1e-3)  # ω4 + ω5 = 1 (4 significant digits)
        groups.setdefault(label, []).append((float(risk), float(cost)))
    assert set(groups) == {"Eq. 10", "Eq. 10 + μ·R(t)"} and len(groups["Eq. 10"]) >= 3
    for points in groups.values():
        # non-dominated: sorted by rising transport cost, the risk cost falls strictly
        assert [c for _, c in points] == sorted(c for _, c in points)
        assert all(r1 > r2 for (r1, _), (r2, _) in itertools.pairwise(points))
    # the cheapest point without the buffer is the least-transport track: Table 2's shortest track
    shortest = json.loads((reproduced / "tracks.json").read_text())["stages"]["shortest"]
    assert groups["Eq. 10"][0] == (round(shortest["risk_cost"], 1), round(shortest["transport_cost"], 4))
