"""``uamopt view DIR``: the offline interactive 3-D view of a schedule (uamopt/plotting/explore.py).

The file's own content is checked here without a browser: no element loads anything from the
network, the size, and the playback's aircraft positions read back from the HTML equal the
positions the test computes itself from flights.json and schedule.csv (each waypoint at departure
+ its distance / speed, the vertical phases at their rate). tests/test_view_browser.py opens the
file in a real Chromium."""

from __future__ import annotations

import csv
import itertools
import json
import math
import re
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from uamopt.cli import main

ROOT = Path(__file__).resolve().parents[1]
PAPER_CASE = ROOT / "models" / "paper_case.toml"
SMALL = ['network.tracks="straight"', "network.vertical_phases=true", 'network.routes=[["V1","V5"],["V5","V4"]]',
         "schedule.aircraft=4", "schedule.flights=12", "network.pads=2"]


def small_schedule(folder: Path) -> Path:
    args = ["schedule", str(PAPER_CASE), "--solver", "cpsat", "--out", str(folder)]
    for k in SMALL:
        args += ["--set", k]
    assert main(args) == 0
    return folder


@pytest.fixture(scope="module")
def viewed(tmp_path_factory) -> tuple[Path, Path]:
    folder = small_schedule(tmp_path_factory.mktemp("view") / "sched")
    assert main(["view", str(folder)]) == 0
    return folder, folder / "view.html"


class _Links(HTMLParser):
    """Every src and href of the document's elements (a script's text is not markup)."""

    def __init__(self):
        super().__init__()
        self.links: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.links += [v for k, v in attrs if k in ("src", "href") and v]


def figure_frames(text: str) -> list[dict]:
    """The frames plotly wrote into the page (the JSON argument of Plotly.addFrames)."""
    at = re.search(r"Plotly\.addFrames\('[^']+',\s*", text)
    assert at, "no frames in the page"
    frames, _ = json.JSONDecoder().raw_decode(text, at.end())
    return frames


def figure_data(text: str) -> list[dict]:
    """The traces plotly wrote into the page (the data argument of Plotly.newPlot)."""
    at = re.search(r"Plotly\.newPlot\(\s*\"[^\"]+\",\s*", text)
    assert at, "no figure in the page"
    data, _ = json.JSONDecoder().raw_decode(text, at.end())
    return data


def route_colours(data: list[dict]):
    """value -> colour of the aircraft coloured by route, decoded as plotly.js maps a marker's value:
    its position (v - cmin) / (cmax - cmin) on the trace's colour-scale stops."""
    base = next(tr for tr in data if tr["name"] == "aircraft (colour: route)")["marker"]
    scale, lo, hi = base["colorscale"], base["cmin"], base["cmax"]

    def colour(value: float) -> str:
        at = (value - lo) / (hi - lo)
        return next(c for (p0, c), (p1, _) in itertools.pairwise(scale) if p0 <= at <= p1)

    return colour


def values(v) -> list:
    """A data array as plotly writes it: a JSON list, or a typed array {"dtype", "bdata": base64}."""
    if isinstance(v, dict) and "bdata" in v:
        import base64

        return np.frombuffer(base64.b64decode(v["bdata"]), dtype=np.dtype(v["dtype"])).tolist()
    return list(v)


def planned(folder: Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per operated flight: (clock time of each waypoint, waypoints), computed here."""
    flights = {f["id"]: f for f in json.loads((folder / "flights.json").read_text())["flights"]}
    out = {}
    with open(folder / "schedule.csv", newline="") as fh:
        for row in csv.DictReader(fh):
            if row["operated"] != "1":
                continue
            f = flights[row["flight"]]
            wp = np.asarray(f["waypoints"], float)
            seg = [math.dist(a, b) for a, b in itertools.pairwise(wp)]
            rate = [f["speed_mps"]] * len(seg)
            if f.get("vertical_rate_mps"):
                rate[0] = rate[-1] = f["vertical_rate_mps"]
            times = float(row["departure_s"]) + np.concatenate([[0.0], np.cumsum(np.array(seg) / np.array(rate))])
            assert times[-1] == pytest.approx(float(row["arrival_s"]), abs=1e-6)
            out[row["flight"]] = (times, wp)
    return out


def test_the_page_loads_nothing_from_the_network_and_is_small(viewed):
    _, page = viewed
    text = page.read_text(encoding="utf-8")
    parser = _Links()
    parser.feed(text)
    remote = [link for link in parser.links if re.match(r"\s*(https?:)?//", link)]
    assert remote == []
    assert "<script src" not in text  # plotly.js is inlined
    size = page.stat().st_size
    assert 3e6 < size < 10e6  # plotly.js (~4.8 MB) and the data; the paper case's bound is 10 MB


def test_the_playback_puts_each_aircraft_where_the_schedule_says(viewed):
    folder, page = viewed
    text = page.read_text(encoding="utf-8")
    frames = figure_frames(text)
    plans = planned(folder)
    meta = json.loads(re.search(r'"meta":\s*(\{"uamopt".*?\}\})', text).group(1))["uamopt"]
    clock = meta["times_s"]
    assert len(frames) == len(clock) >= 50 and meta["step_s"] == pytest.approx(10.0)
    with open(folder / "schedule.csv", newline="") as fh:
        rows = {r["flight"]: r for r in csv.DictReader(fh)}
    seen = set()
    checked = 0
    for frame, t in zip(frames, clock, strict=True):
        by_route = frame["data"][0]  # the aircraft coloured by route
        ids = [c[0] for c in by_route["customdata"]]  # the hover's flight id
        airborne = {fid for fid, (times, _) in plans.items() if times[0] <= t <= times[-1]}
        assert set(ids) == airborne, t
        xs, ys, zs = (values(by_route[k]) for k in "xyz")
        assert len(xs) == len(ids)
        for fid, x, y, z in zip(ids, xs, ys, zs, strict=True):
            times, wp = plans[fid]
            want = [np.interp(t, times, wp[:, k]) for k in range(3)]
            assert [x, y, z] == pytest.approx(want, abs=1e-2), (fid, t)  # float32 in the page: < 1 mm at 3 km
            checked += 1
        for custom in by_route["customdata"]:  # the hover: aircraft, route and delay of schedule.csv
            row = rows[custom[0]]
            delay = float(row["departure_s"]) - float(row["planned_departure_s"])
            assert custom[1:] == [row["aircraft"], row["route"], f"{delay:.1f}"]
        by_delay = frame["data"][1]  # the same aircraft, coloured by their delay
        assert [c[0] for c in by_delay["customdata"]] == ids and values(by_delay["x"]) == xs
        for fid, value in zip(ids, values(by_delay["marker"]["color"]), strict=True):
            row = rows[fid]
            assert value == pytest.approx(float(row["departure_s"]) - float(row["planned_departure_s"]), abs=1e-3)
        seen |= set(ids)
    assert seen == set(plans) and checked > 100  # every operated flight flies in the playback
    assert meta["cancelled"] == sorted({json.loads((folder / "flights.json").read_text())["flights"][i]["id"]
                                           for i in range(12)} - set(plans))


def test_each_aircraft_has_its_tracks_colour(viewed):
    """Colour by route: an aircraft's marker value, through the trace's stepped colour scale, is the
    colour of its route's track line (the scale is decoded here as plotly.js maps it)."""
    folder, page = viewed
    text = page.read_text(encoding="utf-8")
    data = figure_data(text)
    line = {tr["name"].removeprefix("track "): tr["line"]["color"] for tr in data if tr["name"].startswith("track ")}
    colour = route_colours(data)
    with open(folder / "schedule.csv", newline="") as fh:
        route = {r["flight"]: r["route"] for r in csv.DictReader(fh)}
    seen = 0
    for frame in figure_frames(text):
        trace = frame["data"][0]
        for custom, value in zip(trace["customdata"], values(trace["marker"]["color"]), strict=True):
            assert colour(value) == line[route[custom[0]]], custom
            seen += 1
    assert seen > 100


def test_the_city_and_the_unsafe_layers_are_drawn(viewed):
    _, page = viewed
    text = page.read_text(encoding="utf-8")
    assert '"name":"buildings"' in text and '"type":"mesh3d"' in text
    layers = re.findall(r'"name":"unsafe (\d+)\\u2013(\d+) m"', text)  # the en dash, JSON-escaped
    assert len(layers) >= 5 and all(int(b) - int(a) == 30 for a, b in layers)  # one per 30 m layer, toggled in the legend
    assert text.count('"visible":"legendonly"') >= len(layers)
    assert all(f'"track V{a}-V{b}"' in text.replace('"name":', '') for a, b in (("1", "5"), ("5", "1"), ("5", "4")))


def test_a_verifier_rejected_pair_is_drawn_red(tmp_path):
    """Two flights moved onto each other in schedule.csv: the verifier rejects the pair, and the
    view draws both in the conflict colour and says so in its title."""
    folder = small_schedule(tmp_path / "bad")
    with open(folder / "schedule.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    first = {}  # each aircraft's first flight: moving it earlier keeps its own chain feasible
    for r in sorted(rows, key=lambda r: float(r["planned_departure_s"])):
        first.setdefault(r["aircraft"], r)
    by_route: dict[str, list] = {}
    for r in first.values():
        if r["operated"] == "1":
            by_route.setdefault(r["route"], []).append(r)
    a, b = next(v for v in by_route.values() if len(v) >= 2)[:2]  # two aircraft in the same cells at once
    shift = float(a["departure_s"]) - float(b["departure_s"])
    for key in ("planned_departure_s", "departure_s", "arrival_s"):
        b[key] = repr(float(b[key]) + shift)
    with open(folder / "schedule.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    doc = json.loads((folder / "flights.json").read_text())
    for f in doc["flights"]:
        if f["id"] == b["flight"]:
            f["planned_departure_s"] = float(b["planned_departure_s"])
    (folder / "flights.json").write_text(json.dumps(doc))
    assert main(["verify", str(folder)]) == 1
    assert main(["view", str(folder), "--no-city"]) == 0
    text = (folder / "view.html").read_text(encoding="utf-8")
    meta = json.loads(re.search(r'"meta":\s*(\{"uamopt".*?\}\})', text).group(1))["uamopt"]
    assert {a["flight"], b["flight"]} <= set(meta["rejected"])
    assert "verifier rejects" in text
    colour = route_colours(figure_data(text))
    drawn = {}  # flight -> set of (colour, size) over the frames
    for frame in figure_frames(text):
        trace = frame["data"][0]
        sizes = values(trace["marker"]["size"]) if isinstance(trace["marker"]["size"], dict) else None
        for n, (custom, value) in enumerate(zip(trace["customdata"], values(trace["marker"]["color"]), strict=True)):
            drawn.setdefault(custom[0], set()).add((colour(value), sizes[n] if sizes else trace["marker"]["size"]))
    red = {fid for fid, seen in drawn.items() if all(c == "#d62728" for c, _ in seen)}
    assert red == set(meta["rejected"]) and {a["flight"], b["flight"]} <= red
    big = max(size for seen in drawn.values() for _, size in seen)
    assert all(seen == {("#d62728", big)} for fid, seen in drawn.items() if fid in red)  # red and larger
    assert all(all(c != "#d62728" and s < big for c, s in seen) for fid, seen in drawn.items() if fid not in red)


@pytest.mark.parametrize(("args", "fragment"), [
    (["view", "/nonexistent/folder"], "not a folder"),
    (["view", "{dir}", "--out", "{dir}"], "--out is a folder"),
    (["view", "{dir}", "--out", "{dir}/missing/view.html"], "does not exist"),
    (["view", "{dir}", "--step", "0"], "positive number of seconds"),
])
def test_bad_input_is_one_line_and_exit_2(viewed, capsys, args, fragment):
    folder, _ = viewed
    before = sorted(p.name for p in folder.iterdir())
    assert main([a.format(dir=folder) for a in args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:") and fragment in err[0]
    assert sorted(p.name for p in folder.iterdir()) == before  # nothing written


def test_the_python_call_shows_inline_and_saves(viewed, tmp_path):
    """``ua.plotting.explore``: the same view for a notebook (an HTML fragment with plotly.js in it,
    no <html> page) and ``.save`` writes the page."""
    import uamopt as ua

    folder, _ = viewed
    view = ua.plotting.explore(folder, city=False, step_s=30.0)
    fragment = view._repr_html_()
    assert "<html" not in fragment[:200].lower() and "Plotly.newPlot" in fragment
    assert view.figure.layout.meta["uamopt"]["step_s"] == 30.0
    saved = view.save(tmp_path / "v.html")
    assert saved.read_text(encoding="utf-8").lstrip().lower().startswith(("<!doctype html>", "<html"))
    assert '"name":"buildings"' not in saved.read_text(encoding="utf-8")  # city=False: no city


def test_plan_network_and_risk_folders_are_viewed_without_playback(tmp_path):
    """A plan folder shows its four stages (Table 2), a network folder its routes (the city from
    --scenario: network.json records no scenario file), a risk folder the city; an empty folder
    is one line and exit 2."""
    plan, network, risk = tmp_path / "plan", tmp_path / "network", tmp_path / "risk"
    fast = ["--set", "grid.cell=[100,100,30]", "--no-figures"]
    assert main(["plan", str(PAPER_CASE), "--out", str(plan), *fast]) == 0
    assert main(["view", str(plan)]) == 0
    text = (plan / "view.html").read_text(encoding="utf-8")
    stages = json.loads((plan / "tracks.json").read_text())["stages"]
    assert set(stages) == {"shortest", "initial", "equivalent", "optimal"}
    assert all(f'"name":"{s} track"' in text for s in stages) and '"name":"buildings"' in text
    assert "Plotly.addFrames" not in text  # nothing to play
    assert main(["network", str(PAPER_CASE), "--out", str(network), "--set", 'network.tracks="straight"', *fast]) == 0
    assert main(["view", str(network), "--no-city"]) == 0
    routes = json.loads((network / "network.json").read_text())["routes"]
    text = (network / "view.html").read_text(encoding="utf-8")
    assert len(routes) == 20 and all(f'"name":"track {r}"' in text for r in routes)
    assert main(["risk", str(PAPER_CASE), "--out", str(risk), *fast]) == 0
    assert main(["view", str(risk)]) == 0
    assert '"name":"buildings"' in (risk / "view.html").read_text(encoding="utf-8")
    (tmp_path / "empty").mkdir()
    assert main(["view", str(tmp_path / "empty")]) == 2
