"""A hostile census of four input surfaces (docs/interfaces.md, Exit codes and errors): bad input is
exit code 2, exactly one stderr line ``error: what (where): how to fix`` naming the file or the
option, no traceback, and nothing written (no --out, the input files as they were).

1. OR-Library airland files (``uamopt bench FILE.txt``, ``ua.read_airland``; uamopt/schedule/airland.py);
2. tampered folders given to ``uamopt view`` (uamopt/plotting/explore.py, uamopt/export/folder.py);
3. ``uamopt bench --against FILE [--update]`` results files (uamopt/experiments/results.py; the
   cases of tests/test_bench_against.py are not repeated);
4. ``--scheduler ADDRESS`` of the windows solver (uamopt/cluster.py; the flag with another solver,
   and bench's error row for a well-formed address nobody answers at, are tests/test_windows.py's).
"""

from __future__ import annotations

import csv
import json
import shutil
import socket
import threading
import time
import tracemalloc
from pathlib import Path

import pytest

import uamopt as ua
from uamopt.cli import main
from uamopt.errors import UamoptError

ROOT = Path(__file__).resolve().parents[1]
AIRLAND = ROOT / "tests" / "data" / "airland"


def listing(folder: Path) -> list[str]:
    """Every path under ``folder``, relative, sorted (hidden staging folders and lock files included)."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def one_error_line(err: str, *names: str) -> str:
    """The one stderr line, checked: ``error: ``, no traceback, and it names one of ``names``."""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err[:2000]
    line = lines[0]
    assert line.startswith("error: ") and "Traceback" not in err, line
    assert any(n in line for n in names), (names, line)
    assert " (" in line and "): " in line, line  # what (where): how to fix
    return line


# --- 1. airland files ---------------------------------------------------------------------------

#: two aircraft, good: "P freeze", then per aircraft "appearance E T L g h" and P separations
GOOD = "2 10\n 0 10 20 30 1 2\n 0 5\n 0 15 25 35 1 2\n 5 0\n"


def _with(old: str, new: str) -> str:
    assert GOOD.count(old) == 1, old
    return GOOD.replace(old, new)


AIRLAND_TEXT = {
    "empty": ("", "0 numbers"),
    "only whitespace": (" \n\t  \n", "0 numbers"),
    "a word": (_with("15 25", "15 abc"), "'abc'"),
    "a NaN target": (_with("15 25", "15 nan"), "got nan"),
    "an inf target": (_with("15 25", "15 inf"), "got inf"),
    "1e400 target": (_with("15 25", "15 1e400"), "got inf"),
    "1e300 latest time": (_with("20 30", "20 1e300"), "got 1e+300"),
    "an inf cost": (_with("30 1 2", "30 inf 2"), "early cost g"),
    "a NaN separation": (_with(" 0 5\n", " 0 nan\n"), "separation S_1,2"),
    "a NaN freeze time": (_with("2 10", "2 nan"), "freeze time"),
    "a negative count": (_with("2 10", "-2 10"), "got -2"),
    "a zero count": ("0 10\n", "got 0"),
    "a count of 2.5": (_with("2 10", "2.5 10"), "got 2.5"),
    "a NaN count": (_with("2 10", "nan 10"), "got nan"),
    "a 400-digit count": (_with("2 10", "9" * 400 + " 10"), "(400 characters)"),
    "a count of 10**9 and 10 numbers": ("1000000000 10\n 0 10 20 30 1 2 0 5\n", "expected 1000000006000000002"),
    "too few numbers": (GOOD.rsplit(" ", 2)[0], "16 numbers for 2 aircraft, expected 18"),
    "too many numbers": (GOOD + " 7\n", "19 numbers for 2 aircraft, expected 18"),
    "earliest after latest": (_with("0 10 20 30", "0 40 20 30"), "needs E ≤ T ≤ L"),
    "target before earliest": (_with("0 10 20 30", "0 10 5 30"), "needs E ≤ T ≤ L"),
    "target after latest": (_with("0 10 20 30", "0 10 40 30"), "needs E ≤ T ≤ L"),
    "a negative cost": (_with("30 1 2", "30 -1 2"), "early cost g must be a number in [0, 1e+06], got -1"),
    "a negative separation": (_with(" 0 5\n", " 0 -5\n"), "separation S_1,2 must be a number in [0, 1e+07], got -5"),
    "a 400-digit time": (_with("15 25", "15 " + "9" * 400), "(400 characters)"),
    "a 5000-digit time": (_with("15 25", "15 " + "9" * 5000), "(5002 characters)"),
}


def _airland_file(tmp_path: Path, case: str) -> Path:
    if case == "binary (not UTF-8)":
        path = tmp_path / "binary.txt"
        path.write_bytes(b"\xff\xfe\x00\x81 2 10 \x80")
    elif case == "a directory":
        path = tmp_path / "folder.txt"
        path.mkdir()
    elif case == "a missing file":
        path = tmp_path / "missing.txt"
    else:
        path = tmp_path / "airland_bad.txt"
        path.write_text(AIRLAND_TEXT[case][0], encoding="utf-8")
    return path


AIRLAND_CASES = [*AIRLAND_TEXT, "binary (not UTF-8)", "a directory", "a missing file"]


@pytest.mark.parametrize("case", AIRLAND_CASES)
def test_a_hostile_airland_file_is_one_line_exit_2_and_nothing_written(case, tmp_path, capsys):
    path = _airland_file(tmp_path, case)
    before = listing(tmp_path)
    content = path.read_bytes() if path.is_file() else None
    out = tmp_path / "out"
    started = time.perf_counter()
    assert main(["bench", str(path), "--solver", "greedy", "--out", str(out)]) == 2
    assert time.perf_counter() - started < 30  # refused up front (10**9 aircraft: nothing of that size made)
    line = one_error_line(capsys.readouterr().err, path.name)
    if case in AIRLAND_TEXT:
        assert AIRLAND_TEXT[case][1] in line, line
    assert not out.exists() and listing(tmp_path) == before
    assert (path.read_bytes() if path.is_file() else None) == content
    with pytest.raises(UamoptError) as raised:  # the Python API: the same error, one line
        ua.read_airland(path)
    assert "\n" not in str(raised.value) and path.name in str(raised.value)


def test_a_huge_declared_count_is_refused_without_allocating_for_it(tmp_path):
    path = tmp_path / "huge.txt"
    path.write_text("1000000000 10\n" + " 1" * 1000 + "\n", encoding="utf-8")
    tracemalloc.start()
    try:
        with pytest.raises(UamoptError, match="for 1000000000 aircraft"):
            ua.read_airland(path)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 20e6, peak  # the file's 1,002 numbers, not 10**18


def test_read_airland_takes_a_path_only():
    with pytest.raises(TypeError, match="path"):
        ua.read_airland(123)
    with pytest.raises(TypeError):
        ua.read_airland(AIRLAND / "airland1.txt", runways=2)  # one runway: there is no such argument


def test_the_shipped_airland_files_pass_the_checks():
    from uamopt.schedule.airland import parse_airland

    for k in range(1, 9):
        data = parse_airland(AIRLAND / f"airland{k}.txt")
        assert data["separation"].shape == (data["aircraft"], data["aircraft"])


# --- 2. uamopt view on tampered folders ---------------------------------------------------------


@pytest.fixture(scope="module")
def schedule_dir(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("view-source") / "sched"
    assert main(["schedule", "models/paper_case.toml", "--solver", "greedy", "--set", "schedule.flights=12", "--set",
                 "schedule.aircraft=4", "--out", str(folder)]) == 0
    return folder


def _flights(fn):
    def tamper(d: Path) -> None:
        doc = json.loads((d / "flights.json").read_text(encoding="utf-8"))
        fn(doc["flights"][0])
        (d / "flights.json").write_text(json.dumps(doc), encoding="utf-8")
    return tamper


def _rows(fn):
    def tamper(d: Path) -> None:
        with open(d / "schedule.csv", newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
        fn(rows)
        with open(d / "schedule.csv", "w", newline="", encoding="utf-8") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
    return tamper


def _summary(**changes):
    def tamper(d: Path) -> None:
        doc = json.loads((d / "summary.json").read_text(encoding="utf-8"))
        for key, value in changes.items():
            if key.startswith("scenario_"):
                doc["scenario"][key.removeprefix("scenario_")] = value
            else:
                doc[key] = value
        (d / "summary.json").write_text(json.dumps(doc), encoding="utf-8")
    return tamper


def _write(name: str, data: bytes | str):
    def tamper(d: Path) -> None:
        (d / name).write_bytes(data if isinstance(data, bytes) else data.encode("utf-8"))
    return tamper


def _to_folder(name: str):
    def tamper(d: Path) -> None:
        (d / name).unlink()
        (d / name).mkdir()
    return tamper


def _unset_row(key: str, value: str):
    return _rows(lambda rows: rows[0].update({key: value}))


#: tamper -> (the name the line must hold, the view's options); --no-city unless the city is the point
VIEW_REFUSED = {
    "flights.json missing": (lambda d: (d / "flights.json").unlink(), "flights.json", ["--no-city"]),
    "flights.json not JSON": (_write("flights.json", '{"cell": [50, 50'), "flights.json", ["--no-city"]),
    "flights.json not UTF-8": (_write("flights.json", b"\xff\xfe\x80{}"), "flights.json", ["--no-city"]),
    "flights.json a list": (_write("flights.json", "[]"), "flights.json", ["--no-city"]),
    "flights.json a folder": (_to_folder("flights.json"), "flights.json", ["--no-city"]),
    "a flight with a NaN waypoint": (_flights(lambda f: f["waypoints"][1].__setitem__(0, float("nan"))), "flights.json",
                                     ["--no-city"]),
    "waypoints as strings": (_flights(lambda f: f.update(waypoints=[[str(v) for v in p] for p in f["waypoints"]])),
                             "flights.json", ["--no-city"]),
    "waypoints a string": (_flights(lambda f: f.update(waypoints="abc")), "flights.json", ["--no-city"]),
    "schedule.csv missing": (lambda d: (d / "schedule.csv").unlink(), "schedule.csv", ["--no-city"]),
    "schedule.csv empty": (_write("schedule.csv", ""), "schedule.csv", ["--no-city"]),
    "schedule.csv not UTF-8": (_write("schedule.csv", b"\xff\xfe\x80\n"), "schedule.csv", ["--no-city"]),
    "a delay that is no number": (_unset_row("delay_s", "soon"), "schedule.csv", ["--no-city"]),
    "a NaN departure": (_unset_row("departure_s", "nan"), "schedule.csv", ["--no-city"]),
    "a flight id not in flights.json": (_unset_row("flight", "ZZZ"), "schedule.csv", ["--no-city"]),
    "summary.json not JSON": (_write("summary.json", "{oops"), "summary.json", ["--no-city"]),
    "summary.json a list": (_write("summary.json", "[]"), "summary.json", ["--no-city"]),
    "summary.json a 5000-digit integer": (_write("summary.json", '{"x": ' + "9" * 5000 + "}"), "summary.json",
                                          ["--no-city"]),
    "summary.json a malformed frame": (_summary(frame={"crs": 1}), "summary.json", ["--no-city"]),
    # the city comes from the recorded scenario: a record that cannot name one is refused
    "the recorded --set an integer": (_summary(scenario_set=5), "summary.json", []),
    "the recorded --set a string": (_summary(scenario_set="abc"), "summary.json", []),
    "the recorded scenario a list": (_summary(scenario=[]), "summary.json", []),
    "the recorded scenario file missing": (_summary(scenario_file="/nonexistent/x.toml"), "x.toml", []),
    "summary.json missing, city asked": (lambda d: (d / "summary.json").unlink(), "summary.json", []),
}


@pytest.mark.parametrize("case", VIEW_REFUSED)
def test_view_of_a_tampered_schedule_folder_is_one_line_exit_2(case, schedule_dir, tmp_path, capsys):
    tamper, name, options = VIEW_REFUSED[case]
    folder = tmp_path / "sched"
    shutil.copytree(schedule_dir, folder)
    tamper(folder)
    before = listing(tmp_path)
    assert main(["view", str(folder), *options]) == 2  # default --out: DIR/view.html
    one_error_line(capsys.readouterr().err, name)
    assert listing(tmp_path) == before  # no view.html, no staging file, the folder as it was


@pytest.mark.parametrize("case", ["a file", "missing"])
def test_view_of_a_folder_that_is_no_folder_is_one_line_exit_2(case, tmp_path, capsys):
    folder = tmp_path / "sched"
    if case == "a file":
        folder.write_text("not a folder", encoding="utf-8")
    out = tmp_path / "view.html"
    before = listing(tmp_path)
    assert main(["view", str(folder), "--out", str(out), "--no-city"]) == 2
    one_error_line(capsys.readouterr().err, str(folder))
    assert not out.exists() and listing(tmp_path) == before


#: folders of plan and network runs (no schedule.csv): the view reads tracks.json or network.json
STATIC_REFUSED = {
    "network.json routes a list": ("network.json", '{"routes": [1]}', ["--no-city"]),
    "network.json truncated": ("network.json", '{"routes": {"A-B": {"waypoints": [[0, 0, 1], [1, 1, 1]]}}', ["--no-city"]),
    "tracks.json stages a list": ("tracks.json", '{"stages": [1]}', []),
    "tracks.json scenario file an integer": ("tracks.json", '{"scenario": {"file": 5}, "stages": {}}', []),
    "tracks.json nested too deeply": ("tracks.json", "[" * 100_000 + "]" * 100_000, ["--no-city"]),
}


@pytest.mark.parametrize("case", STATIC_REFUSED)
def test_view_of_a_tampered_plan_or_network_folder_is_one_line_exit_2(case, tmp_path, capsys):
    name, text, options = STATIC_REFUSED[case]
    folder = tmp_path / "plan"
    folder.mkdir()
    (folder / name).write_text(text, encoding="utf-8")
    before = listing(tmp_path)
    assert main(["view", str(folder), *options]) == 2
    one_error_line(capsys.readouterr().err, name)
    assert listing(tmp_path) == before


def test_a_bad_recorded_scenario_is_harmless_to_a_view_without_the_city(tmp_path, capsys):
    folder = tmp_path / "plan"
    folder.mkdir()
    doc = {"scenario": {"file": 5}, "stages": {"optimal": {"waypoints": [[300, 300, 120], [650, 550, 120]]}}}
    (folder / "tracks.json").write_text(json.dumps(doc), encoding="utf-8")
    assert main(["view", str(folder), "--no-city"]) == 0
    assert (folder / "view.html").is_file() and "error" not in capsys.readouterr().err


def _move_onto_each_other(rows: list[dict]) -> None:
    """Two aircraft's first flights (every route of the case leaves V1) off V1 at one time: a pair
    the verifier rejects."""
    first: dict[str, dict] = {}
    for r in sorted(rows, key=lambda r: float(r["departure_s"])):
        first.setdefault(r["aircraft"], r)
    a, b = list(first.values())[:2]
    shift = float(a["departure_s"]) - float(b["departure_s"])
    for key in ("delay_s", "departure_s", "arrival_s"):
        b[key] = repr(float(b[key]) + shift)


#: harmless to the view (docs/export.md: the view draws what the verifier rejects, red, and says so)
VIEW_DRAWN = {
    "summary.json missing": (lambda d: (d / "summary.json").unlink(), None),
    "the recorded scenario a list, no city asked": (_summary(scenario=[]), None),
    "a summary objective that is no number": (_summary(objective="abc"), None),
    "a pair the verifier rejects": (_rows(_move_onto_each_other), "the verifier rejects"),
}


@pytest.mark.parametrize("case", VIEW_DRAWN)
def test_view_of_a_folder_the_view_can_draw_is_exit_0(case, schedule_dir, tmp_path, capsys):
    tamper, said = VIEW_DRAWN[case]
    folder = tmp_path / "sched"
    shutil.copytree(schedule_dir, folder)
    tamper(folder)
    out = tmp_path / "view.html"
    assert main(["view", str(folder), "--out", str(out), "--no-city"]) == 0
    captured = capsys.readouterr()
    assert out.is_file() and captured.out.startswith("view: ") and "error" not in captured.err
    if said:
        assert said in captured.out, captured.out  # and in the page's title
        assert "verifier rejects" in out.read_text(encoding="utf-8")
        assert main(["verify", str(folder)]) == 1


# --- 3. bench --against results files -----------------------------------------------------------

FORMAT = "uamopt-benchmark-results/1"


def _record(value) -> dict:
    return {"value": value, "solver": "hand", "profile": "hand", "model": "continuous", "time_limit_s": 60.0, "threads": 2,
            "command": "uamopt bench models/benchmark_120.toml --solver hand"}


def _entry(**changes) -> dict:
    return {"instance": "benchmark_120", "scenario": "models/benchmark_120.toml", "set": [], "plan_seed": 0,
            "flights": 120, "aircraft": 20, "conflicting_pairs": 289, "objective_kind": "weighted",
            "best_objective": _record(-50.0), "best_bound": _record(-60.0)} | changes


def _doc(*entries) -> str:
    return json.dumps({"format": FORMAT, "instances": list(entries)})


_GOOD_RESULTS = _doc(_entry())
RESULTS = {  # content -> a fragment of the line
    "truncated JSON": (_GOOD_RESULTS[: len(_GOOD_RESULTS) // 2], "malformed JSON"),
    "an empty file": ("", "malformed JSON"),
    "a top-level list": ("[]", "not a JSON object"),
    "instances an object": (json.dumps({"format": FORMAT, "instances": {}}), "'instances' must be a list"),
    "instances a string": (json.dumps({"format": FORMAT, "instances": "abc"}), "'instances' must be a list"),
    "an instance that is a number": (json.dumps({"format": FORMAT, "instances": [7]}), "an instance is not a JSON object"),
    "a 400-digit value": (_GOOD_RESULTS.replace("-50.0", "9" * 400), "(400 characters)"),
    "a 5000-digit value": (_GOOD_RESULTS.replace("-50.0", "9" * 5000), "more than 4300 digits"),
    "a value of 1e309": (_GOOD_RESULTS.replace("-50.0", "1e309"), "got inf"),
    "a negative flights count": (_doc(_entry(flights=-5)), "flights must be an integer in [1, 1000000000], got -5"),
    "a 10 MB instance name": (_doc(_entry(instance="x" * 10_000_000)), "(10000002 characters)"),
    "a 10 MB command": (_doc(_entry(best_objective=_record(-50.0) | {"command": "y" * 10_000_000})),
                        "(10000002 characters)"),
    "a 10 MB key": (json.dumps({"format": FORMAT, "instances": [], "k" * 10_000_000: 1}), "(10000002 characters)"),
    "not UTF-8": (b"\xff\xfe\x80" + _GOOD_RESULTS.encode(), "not UTF-8"),
    "nested too deeply": ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
    "a folder": (None, "is a folder"),
}


@pytest.mark.parametrize("update", [False, True], ids=["against", "against-update"])
@pytest.mark.parametrize("case", RESULTS)
def test_a_hostile_results_file_is_one_line_exit_2_and_left_as_it_was(case, update, tmp_path, capsys):
    content, fragment = RESULTS[case]
    path = tmp_path / "results.json"
    if content is None:
        path.mkdir()
    else:
        path.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
    before = listing(tmp_path)
    out = tmp_path / "out"
    started = time.perf_counter()
    code = main(["bench", "models/benchmark_120.toml", "--solver", "greedy", "--out", str(out), "--against", str(path),
                 *(["--update"] if update else [])])
    assert code == 2 and time.perf_counter() - started < 60  # refused before anything runs
    line = one_error_line(capsys.readouterr().err, str(path))
    assert fragment in line and len(line) < 1000, line[:1000]
    assert not out.exists() and listing(tmp_path) == before
    if content is not None:
        assert path.read_bytes() == (content if isinstance(content, bytes) else content.encode("utf-8"))


# --- 4. --scheduler -----------------------------------------------------------------------------

WINDOWS = ["--solver", "windows", "--set", 'schedule.objective="weighted"', "--set", "schedule.flights=12", "--set",
           "schedule.aircraft=4"]


@pytest.fixture
def silent_listener():
    """A TCP port that accepts connections and never says a word (not a Dask scheduler)."""
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(16)
    server.settimeout(0.2)
    stop = threading.Event()
    held: list[socket.socket] = []

    def accept() -> None:
        while not stop.is_set():
            try:
                held.append(server.accept()[0])
            except OSError:
                pass

    thread = threading.Thread(target=accept, daemon=True)
    thread.start()
    yield f"tcp://127.0.0.1:{server.getsockname()[1]}"
    stop.set()
    thread.join(5)
    for s in [*held, server]:
        s.close()


@pytest.mark.parametrize(("address", "fragment"), [
    ("tcp://127.0.0.1:1", "cannot reach the Dask scheduler"),  # nobody listens: refused at once
    ("not a url", "is not the address of a Dask scheduler"),
    ("tcp://", "is not the address of a Dask scheduler"),
    ("", "is not the address of a Dask scheduler"),
    ("tcp://127.0.0.1:99999", "is not the address of a Dask scheduler"),
    ("tcp://127.0.0.1:8786/path", "is not the address of a Dask scheduler"),
    ("inproc://x", "is not the address of a Dask scheduler"),
    ("silent", "no Dask handshake"),  # something listens and never answers: distributed's Client waited forever
])
def test_schedule_with_a_bad_scheduler_is_one_line_exit_2_within_the_connect_timeout(address, fragment, tmp_path,
                                                                                      capsys, request):
    pytest.importorskip("distributed")
    from uamopt.cluster import CONNECT_TIMEOUT_S

    if address == "silent":
        address = request.getfixturevalue("silent_listener")
    out = tmp_path / "out"
    started = time.perf_counter()
    assert main(["schedule", "models/paper_case.toml", *WINDOWS, "--scheduler", address, "--out", str(out)]) == 2
    assert time.perf_counter() - started < CONNECT_TIMEOUT_S + 15  # before the network is planned
    line = one_error_line(capsys.readouterr().err, "--scheduler")
    assert fragment in line, line
    assert listing(tmp_path) == []


@pytest.mark.parametrize("address", ["not a url", "tcp://", "tcp://127.0.0.1:0"])
def test_bench_with_a_malformed_scheduler_address_is_one_line_exit_2(address, tmp_path, capsys):
    pytest.importorskip("distributed")
    out = tmp_path / "out"
    assert main(["bench", "models/paper_case.toml", *WINDOWS, "--seeds", "1", "--scheduler", address, "--out",
                 str(out)]) == 2
    line = one_error_line(capsys.readouterr().err, "--scheduler")
    assert "is not the address of a Dask scheduler" in line
    assert listing(tmp_path) == []


def test_connect_refuses_a_bad_address_and_a_silent_port_in_one_line(silent_listener):
    """The windows solver's own connection (a profile's ``scheduler`` option reaches it with no CLI
    check): one UamoptError, within the connect timeout, and no half-made Dask client left."""
    pytest.importorskip("distributed")
    from uamopt.cluster import CONNECT_TIMEOUT_S, connect

    for address in ("not a url", "tcp://127.0.0.1:1", silent_listener):
        started = time.perf_counter()
        with pytest.raises(UamoptError) as raised:
            connect(address, None, 1)
        assert time.perf_counter() - started < CONNECT_TIMEOUT_S + 5
        assert "\n" not in str(raised.value) and raised.value.where == "--scheduler"
