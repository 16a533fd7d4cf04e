"""The hostile census: count how uamopt ends on bad luck and bad input, per class of case.

    .venv/bin/python tests/benchmarks/hostile_census.py [--code ROOT] [--only CLASS,...] [--list] [--timeout S]

Each case runs the code under ``--code`` (default: this checkout; give a worktree of an older
commit, e.g. ``git worktree add /tmp/before 73dac3b``, to count the same cases against it) in a
child process, with the address space limited to 3 GB and a 120 s limit, and is classed as

- ``traceback``: a Python traceback reached the user (or an API call raised something other than
  ``TypeError``/``UamoptError``),
- ``wrong exit``: an exit code other than the case's, or bad input accepted silently (``accepted``),
- ``error line``: exit 2 without exactly one ``error: what (where): fix`` line,
- ``torn output``: ``--out`` written on bad input, or incomplete after an interrupt, or an input
  changed,
- ``hang/memory``: past the time limit or the 3 GB address space (MemoryError, killed),
- ``child left``: a process of the command still running after it ended.

Classes: ``table`` (tests/test_hostile.py's command lines, in this process), ``infeasible`` (every
solver on two instances no schedule satisfies), ``api`` (the Python API with bad arguments and
damaged saved folders), ``verify`` (crafted schedule folders), ``sweeps`` (damaged results folders,
sweep files, a full disk and a file-size limit), ``interrupts`` (SIGINT and SIGTERM at several
moments of each long command, SIGKILL of a replay) and ``memory`` (requests that grow with the input).
The tests assert each case; this script counts, so that the figures can be quoted.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import traceback
import uuid
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
CHECKOUT = HERE.parents[1]
sys.path[:0] = [str(CHECKOUT / "tests"), str(HERE)]

GB = 2**30
LIMIT_GB = 3
FAULTS = ("traceback", "wrong exit", "error line", "torn output", "hang/memory", "child left")
#: a signal before the command's main() ran (the interpreter's start, site and the path finders, the
#: import of uamopt.cli: the first ~0.1 s): Python's default action, nothing written (counted, shown apart)
OUTSIDE = ("before uamopt",)
PROGRESS = ("risk:", "plan:", "flights:", "schedule:", "network:", "sweep:", "tracks:", "reproduce:",
            "replay:", "warning:", "sweep ")


# --- one child process --------------------------------------------------------------------------

@dataclass
class Case:
    cls: str
    name: str
    argv: list[str]  # uamopt's arguments, or ["-c", CODE] for Python code
    expect: tuple[int, ...] = (2,)
    fragment: str = ""  # in the error line (exit 2) or in stdout (exit 0/1)
    out: Path | None = None  # must stay absent or hold only keep.txt on bad input
    complete: str | None = None  # after an interrupt, --out is absent or holds this file
    inputs: Path | None = None  # must be unchanged
    signal_at: tuple[int, float] | None = None
    fsize: int | None = None
    timeout: float = 120.0
    check: object = None  # a function (proc) -> list of faults, run after the standard checks
    cwd: Path | None = None
    lines_ok: bool = False  # exit 2 may print more than one line (a child's own refusal)


def _prelude(case: Case) -> str:
    lines = ["import resource, signal, sys",
             f"resource.setrlimit(resource.RLIMIT_AS, ({LIMIT_GB * GB}, {LIMIT_GB * GB}))"]
    if case.fsize is not None:
        lines += ["signal.signal(signal.SIGXFSZ, signal.SIG_IGN)",
                  f"resource.setrlimit(resource.RLIMIT_FSIZE, ({case.fsize}, {case.fsize}))"]
    return "\n".join(lines) + "\n"


def _command(case: Case) -> list[str]:
    if case.argv[:1] == ["-c"]:
        return [sys.executable, "-c", _prelude(case) + case.argv[1]]
    # as the console script runs it: main() reads sys.argv
    return [sys.executable, "-c", _prelude(case) + f"sys.argv = ['uamopt', *{case.argv!r}]\n"
            "from uamopt.cli import main\nsys.exit(main())"]


def _default_signals() -> None:
    """A shell's background job ignores SIGINT, and its children inherit that: a user's command does not."""
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGQUIT):
        signal.signal(sig, signal.SIG_DFL)


def _tagged(tag: str) -> list[int]:
    """Processes still running whose environment holds ``tag`` (a command's children)."""
    found = []
    for proc in Path("/proc").iterdir():
        if not proc.name.isdigit():
            continue
        try:
            if tag.encode() in (proc / "environ").read_bytes():
                found.append(int(proc.name))
        except OSError:
            continue
    return found


def _snapshot(root: Path | None) -> dict:
    if root is None or not root.exists():
        return {}
    if root.is_file():
        return {root.name: root.read_bytes()}
    return {str(p.relative_to(root)): (p.read_bytes() if p.is_file() else None) for p in sorted(root.rglob("*"))}


def run_case(case: Case, code: Path) -> tuple[list[str], str]:
    """(faults, detail) of one case against the code under ``code``."""
    tag = f"UAMOPT_CENSUS_{uuid.uuid4().hex}"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(code), str(CHECKOUT / "tests"), str(HERE)]),
               UAMOPT_CENSUS_TAG=tag, PYTHONUNBUFFERED="1")
    before = _snapshot(case.inputs)
    proc = subprocess.Popen(_command(case), cwd=case.cwd or code, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True, preexec_fn=_default_signals)
    faults: list[str] = []
    try:
        if case.signal_at is not None:
            sig, after = case.signal_at
            try:
                proc.wait(after)
            except subprocess.TimeoutExpired:
                proc.send_signal(sig)
        stdout, stderr = proc.communicate(timeout=case.timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        stdout, stderr = proc.communicate()
        faults.append("hang/memory")
    code_ = proc.returncode
    time.sleep(0.5 if case.signal_at and case.signal_at[0] == signal.SIGKILL else 0.0)
    left = _tagged(tag)
    if left:
        faults.append("child left")
        for pid in left:
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)
    text = stdout + stderr
    if "MemoryError" in text or "Cannot allocate memory" in text or "std::bad_alloc" in text:
        faults.append("hang/memory")
    if "Traceback (most recent call last)" in text:
        if case.signal_at is not None and not re.search(r'uamopt/cli\.py", line \d+, in _?main', text):
            faults.append("before uamopt")  # the signal came before main() ran: Python's start, site, the imports
        else:
            faults.append("traceback")
    if (case.signal_at is not None and case.signal_at[1] <= 0.1 and code_ == -case.signal_at[0] and not text.strip()
            and case.signal_at[0] != signal.SIGKILL):
        faults.append("before uamopt")  # killed by the default action before uamopt's handlers were installed
    if "hang/memory" not in faults and "before uamopt" not in faults and code_ not in case.expect:
        faults.append("wrong exit")
    lines = [line for line in stderr.splitlines() if line.strip() and not line.startswith(PROGRESS)]
    if code_ == 2 and 2 in case.expect and not case.lines_ok:
        if not (len(lines) == 1 and lines[0].startswith("error: ") and " (" in lines[0] and "): " in lines[0]
                and case.fragment in lines[0]):
            faults.append("error line")
    elif case.signal_at is not None and code_ in (130, 143) and len(lines) != 1:
        faults.append("error line")  # an interrupt: one line, e.g. "interrupted: nothing was written"
    elif code_ in (0, 1) and code_ in case.expect and case.fragment and case.fragment not in stdout:
        faults.append("wrong exit")
    if case.out is not None:
        present = sorted(p.name for p in case.out.iterdir()) if case.out.is_dir() else None
        if case.complete is not None:  # an interrupt: absent, as before, or complete
            if present not in (None, [], ["keep.txt"]) and case.complete not in (present or []):
                faults.append("torn output")
        elif code_ != 0 and present not in (None, ["keep.txt"]):
            faults.append("torn output")
    if case.inputs is not None and _snapshot(case.inputs) != before:
        faults.append("torn output")
    if case.check is not None and not faults:
        faults += case.check(subprocess.CompletedProcess(case.argv, code_, stdout, stderr))
    shown = " | ".join(lines[-3:]) if lines else (stdout.strip().splitlines() or [""])[-1]
    detail = f"exit {code_}, {len(lines)} line(s): " + shown[:400]
    return sorted(set(faults)), detail


def _out(tmp: Path, name: str = "out") -> Path:
    out = tmp / name
    out.mkdir(parents=True)
    (out / "keep.txt").write_text("written before the command", encoding="utf-8")
    return out


# --- class: infeasible and api (one child each, cases in a table) -------------------------------

INFEASIBLE = """
import json, traceback
import uamopt as ua
from test_infeasible import crossing, turnaround
for make in (crossing, turnaround):
    for kind in ("weighted", "lexicographic"):
        for solver in ("highs", "cpsat", "timeindexed", "exact", "greedy", "ga", "soa", "rolling"):
            name = f"{solver}-{make.__name__}-{kind}"
            try:
                s = ua.solve(make(kind), solver, time_limit_s=20)
                outcome = "clean" if s.status == "infeasible" else f"accepted: status {s.status}"
            except ua.UamoptError as exc:
                outcome = "raised: " + exc.line()
            except Exception as exc:
                outcome = "traceback: " + repr(exc)[:200]
            print("CENSUS " + json.dumps([name, outcome]), flush=True)
"""

API_SETUP = """
import json, math, sys, traceback
from pathlib import Path
import numpy as np
import uamopt as ua
from uamopt.grid import AirspaceGrid
from uamopt.schedule import straight_network
PAPER = "models/paper_case.toml"
scenario = ua.load_scenario(PAPER)
network = dict(straight_network(scenario, AirspaceGrid.from_extent(scenario.grid.cell, scenario.grid.extent)))
flights = ua.generate_flights(scenario, network, seed=0)
small = ua.load_scenario(PAPER, ["schedule.flights=30"])
small_problem = ua.build_problem(ua.generate_flights(small, network, seed=0), small)
FOLDERS = json.loads(sys.argv[1])

def run(name, expect, call):
    try:
        call()
        outcome = "clean" if expect == "ok" else "accepted"
    except TypeError as exc:
        outcome = "clean" if expect == "type" else "traceback: TypeError " + str(exc)[:160]
    except ua.UamoptError as exc:
        line = exc.line()
        outcome = ("clean" if expect == "error" and "\\n" not in line else "raised: " + line[:160])
    except Exception as exc:
        outcome = "traceback: " + repr(exc)[:200]
    print("CENSUS " + json.dumps([name, outcome]), flush=True)
"""

#: (name, expected: "type" | "error" | "ok", a Python expression using the names of API_SETUP)
API_CASES = [
    ("verify-another-problem", "error", "ua.verify(ua.build_problem(flights, scenario), ua.solve(small_problem, 'greedy'))"),
    *[(f"build-grid-cell-{i}", "error", f"ua.build_grid((1000, 1000, 300), {cell})")
      for i, cell in enumerate(["(0, 50, 30)", "(50, -1, 30)", "(50, 50, math.nan)"])],
    ("plan-network-of-a-scenario", "type", "ua.plan_network(scenario)"),
    ("load-scenario-none", "ok", "ua.load_scenario(PAPER, None)"),
    ("planning-model-other-cells", "error",
     "ua.planning_model(scenario, ua.compute_risk(ua.load_scenario(PAPER, ['grid.cell=[100,100,60]'])))"),
    ("planning-model-other-risk", "error",
     "ua.planning_model(scenario, ua.compute_risk(ua.load_scenario(PAPER, ['risk.weights=[0.2,0.3,0.5]'])))"),
    ("generate-flights-seed-1.5", "error", "ua.generate_flights(scenario, network, seed=1.5)"),
    ("solve-seed-1.5", "error", "ua.solve(small_problem, 'greedy', seed=1.5)"),
    ("zero-length-tracks", "error",
     "ua.generate_flights(scenario, {n: np.array([w[0], w[0]]) for n, w in network.items()}, seed=0)"),
    *[(f"weights-{i}", "error", f"ua.build_problem(flights, scenario, weights={w})")
      for i, w in enumerate(["(math.nan, 0.4)", "(-0.6, 0.4)", "(0.6, math.inf)", "(0.0, 0.0)"])],
    ("weights-string", "type", "ua.build_problem(flights, scenario, weights='0.6,0.4')"),
    ("benchmark-no-solvers", "error", "ua.benchmark(small_problem, [], progress=False)"),
    *[(f"solver-profile-{b}", "type", f"ua.solver_profile({b})") for b in ("3", "None", "2.5")],
    ("solve-profile-3", "type", "ua.solve(small_problem, 3)"),
    *[(f"scenario-weights-zero-{k}", "error", f"ua.load_scenario(PAPER, ['{k}={v}'])")
      for k, v in (("risk.weights", "[0,0,0]"), ("tracks.weights", "[0,0]"), ("schedule.weights", "[0,0]"))],
    *[(f"{fn}-first-argument-{b}", "type", f"ua.{fn}({b})")
      for fn in ("scenario_grid", "compute_risk", "planning_model", "plan_track", "plan_network", "generate_flights",
                 "build_problem", "solve", "verify", "benchmark")
      for b in ("None", "'models/paper_case.toml'", "3")],
    *[(f"{fn}-path-{b}", "type", f"ua.{fn}({b})")
      for fn in ("load_scenario", "load_risk", "load_tracks", "load_network", "load_flights", "load_schedule")
      for b in ("None", "3")],
    ("plot-sweep-wrong-type", "type", "ua.plot_sweep(3)"),
]


def _damaged_folders(tmp: Path) -> dict[str, list[str]]:
    """Damaged risk and schedule folders (tests/test_loaders_hostile.py's edits), made with this checkout."""
    import test_loaders_hostile as lh

    import uamopt as ua
    from uamopt.grid import AirspaceGrid
    from uamopt.io import save_risk
    from uamopt.schedule import straight_network
    from uamopt.schedule.model import write_schedule

    paper = str(CHECKOUT / "models" / "paper_case.toml")
    risk = tmp / "risk-base"
    save_risk(ua.compute_risk(ua.load_scenario(paper, ["grid.cell=[100,100,60]"])), risk)
    sc = ua.load_scenario(paper, ["schedule.flights=20"])
    net = dict(straight_network(sc, AirspaceGrid.from_extent(sc.grid.cell, sc.grid.extent)))
    problem = ua.build_problem(ua.generate_flights(sc, net, seed=0), sc)
    sched = tmp / "schedule-base"
    sched.mkdir()
    write_schedule(sched, problem, ua.solve(problem, "greedy"))
    out: dict[str, list[str]] = {"risk": [], "schedule": []}
    for name, array, edit, summary, _ in lh.RISK_CASES:
        out["risk"].append(str(lh._copy_risk(risk, tmp / f"risk-{name}", array, edit, summary)))
    for name, row, summary, _ in lh.SCHEDULE_CASES:
        out["schedule"].append(str(lh._copy_schedule(sched, tmp / f"schedule-{name}", row, summary)))
    return out


def _table_child(cls: str, code: Path, script: str, argv: tuple = ()) -> list[tuple[str, list[str], str]]:
    """Run a child that prints ``CENSUS [name, outcome]`` lines; a crash counts its missing cases."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(code), str(CHECKOUT / "tests"), str(HERE)]))
    prelude = _prelude(Case(cls, "", []))
    try:
        proc = subprocess.run([sys.executable, "-c", prelude + script, *argv], cwd=code, env=env, capture_output=True,
                              text=True, timeout=1800, check=False)
        text = proc.stdout
    except subprocess.TimeoutExpired as exc:
        text = exc.stdout.decode() if isinstance(exc.stdout, bytes) else (exc.stdout or "")
    rows = []
    for line in text.splitlines():
        if line.startswith("CENSUS "):
            name, outcome = json.loads(line[7:])
            kind = outcome.split(":")[0]
            faults = {"clean": [], "accepted": ["wrong exit"], "raised": ["wrong exit"], "traceback": ["traceback"]}[kind]
            rows.append((name, faults, outcome))
    return rows


def api_script(folders: dict[str, list[str]]) -> str:
    body = "".join(f"run({n!r}, {e!r}, lambda: {expr})\n" for n, e, expr in API_CASES)
    body += "for p in FOLDERS['risk']: run('load-risk-' + Path(p).name, 'error', lambda: ua.load_risk(p))\n"
    body += "for p in FOLDERS['schedule']: run('load-schedule-' + Path(p).name, 'error', lambda: ua.load_schedule(p))\n"
    return API_SETUP + body


# --- class: verify ------------------------------------------------------------------------------

def verify_cases(tmp: Path) -> list[Case]:
    import test_verify_hostile as vh
    import test_verify_hostile_folders as vf

    from uamopt.cli import main

    cases = []
    for name, kwargs, expected, fragment in vf.CASES:
        folder = vf.write_folder(tmp / "verify" / name, **copy.deepcopy(kwargs))
        cases.append(Case("verify", name, ["verify", str(folder)], (expected,), fragment, inputs=folder))
    for name, summary in (("empty-with-summary", vf.EMPTY_SUMMARY),):
        folder = vf.write_folder(tmp / "verify" / name, flights=(), rows=(), summary=summary)
        cases.append(Case("verify", name, ["verify", str(folder)], (0,), "", inputs=folder))
    good = tmp / "verify" / "good"
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(["schedule", str(CHECKOUT / "models" / "paper_case.toml"), "--solver", "greedy", "--set",
                     "tracks.layering='none'", "--out", str(good)]) == 0
    crafted = tmp / "verify" / "crafted"
    crafted.mkdir()
    for name, edit, expected, fragment in (("turnaround-negative", vh._set("outbound_gap_s", -3000.0), 2, "must be ≥ 0"),
                                           ("before-service-start", vh._set("service_start_s", 300.0), 1,
                                            "before the service start")):
        (crafted / name).mkdir()
        folder = vh.tampered(good, crafted / name, edit)
        cases.append(Case("verify", name, ["verify", str(folder)], (expected,), fragment, inputs=folder))
    (crafted / "negative-planned").mkdir()
    folder, _ = vh._shifted(good, crafted / "negative-planned", -50.0)
    doc = json.loads((folder / "flights.json").read_text())
    doc["service_start_s"], doc["service_end_s"] = 0.0, 3600.0
    (folder / "flights.json").write_text(json.dumps(doc))
    cases.append(Case("verify", "negative-planned", ["verify", str(folder)], (1,), "before the service start",
                      inputs=folder))
    for what in ("departure", "arrival"):
        (crafted / f"late-{what}").mkdir()
        folder, rows = vh._shifted(good, crafted / f"late-{what}", 9e6)
        row = next(r for r in rows if r["operated"] == "1")
        if what == "departure":
            row["departure_s"] = repr(float(row["departure_s"]) - 8.0)
            row["arrival_s"] = repr(float(row["arrival_s"]) - 8.0)
        else:
            row["arrival_s"] = repr(float(row["arrival_s"]) + 8.0)
        vh._rewrite(folder, rows)
        cases.append(Case("verify", f"9e6-s-{what}-8-s-off", ["verify", str(folder)], (1,), f": {what}", inputs=folder))
    return cases


# --- class: sweeps ------------------------------------------------------------------------------

def sweep_cases(tmp: Path, code: Path) -> list[Case]:
    import pandas as pd
    import test_sweep_hostile as sh

    sweep = tmp / "sweeps" / "fast.toml"
    sweep.parent.mkdir(parents=True)
    sweep.write_text(sh.SWEEP.replace(sh.PAPER.as_posix(), str(code / "models" / "paper_case.toml")))
    reference = tmp / "sweeps" / "reference"
    env = dict(os.environ, PYTHONPATH=str(code))
    proc = subprocess.run([sys.executable, "-m", "uamopt", "sweep", str(sweep), "--out", str(reference)], cwd=code, env=env,
                          capture_output=True, text=True, timeout=600, check=False)
    if proc.returncode != 0:
        raise SystemExit(f"the reference sweep failed: {proc.stderr[-2000:]}")
    table = pd.read_parquet(reference / "results.parquet").drop(columns=["seconds"])

    def same_table(out):
        def check(proc):
            try:
                got = pd.read_parquet(out / "results.parquet").drop(columns=["seconds"])
                pd.testing.assert_frame_equal(got, table)
            except Exception:  # noqa: BLE001 - a missing or different table
                return ["wrong exit"]  # accepted silently: the final table differs from an uninterrupted run's
            return []
        return check

    def copy_(name):
        out = tmp / "sweeps" / name
        shutil.copytree(reference, out)
        return out

    def parts(out):
        return sorted((out / "parts").glob("*.parquet"))

    cases = []
    for damage in ("seed-string", "seed-float", "operated-negative", "truncated"):
        out = copy_(f"part-{damage}")
        part = parts(out)[0]
        if damage == "truncated":
            part.write_bytes(part.read_bytes()[:100])
        else:
            change = {"seed-string": sh._seed_string, "seed-float": sh._seed_float,
                      "operated-negative": sh._operated_negative}[damage]
            change(pd.read_parquet(part)).to_parquet(part, index=False)
        cases.append(Case("sweeps", f"part-{damage}", ["sweep", str(sweep), "--out", str(out)], (0,),
                          check=same_table(out), timeout=300))
    for where in ("same-part", "another-part-of-the-case", "a-part-of-another-case"):
        out = copy_(f"duplicate-{where}")
        first, second = parts(out)[:2]
        genuine = pd.read_parquet(second if where == "a-part-of-another-case" else first)
        rogue = genuine[genuine["solver"] == "highs"].copy()
        rogue["objective"] -= 1.0
        if where == "another-part-of-the-case":
            rogue.to_parquet(first.with_name(first.name.split("-")[0] + "-00000000.parquet"), index=False)
        else:
            pd.concat([rogue, pd.read_parquet(first)], ignore_index=True).to_parquet(first, index=False)
        cases.append(Case("sweeps", f"duplicate-{where}", ["sweep", str(sweep), "--out", str(out)], (0,),
                          check=same_table(out), timeout=300))
    out = copy_("parts-a-file")
    shutil.rmtree(out / "parts")
    (out / "parts").write_text("not a folder")
    cases.append(Case("sweeps", "parts-a-file", ["sweep", str(sweep), "--out", str(out)], (2,), "parts", inputs=out))
    for label, solvers in (("list", ["greedy", "highs"]), ("string", "greedy"), ("nested", None)):
        out = copy_(f"manifest-{label}")
        if solvers is None:
            (out / "sweep.json").write_text('{"uamopt_sweep": 1, "solvers": ' + "[" * 10**5 + "]" * 10**5 + "}")
        else:
            manifest = json.loads((out / "sweep.json").read_text())
            manifest["solvers"] = solvers
            (out / "sweep.json").write_text(json.dumps(manifest))
        cases.append(Case("sweeps", f"manifest-{label}", ["sweep", str(sweep), "--out", str(out)], (2,), "sweep.json",
                          inputs=out))
    head = f'base = "{code / "models" / "paper_case.toml"}"\n'
    values = ", ".join(str(v) for v in range(1, 101))
    grid8 = "".join(f'"{k}" = [{values}]\n' for k in ("schedule.aircraft", "schedule.flights", "schedule.plan_seed",
                                                       "city.seed"))
    files = {
        "grid-date": '[grid]\n"schedule.aircraft" = [2, 1979-05-27]\n',
        "set-time": '[set]\n"schedule.service_s" = 07:32:00\n[grid]\n"schedule.aircraft" = [2]\n',
        "grid-datetime": '[grid]\n"aircraft.cruise_speed_mps" = [1979-05-27T07:32:00Z]\n',
        "seed-2^40": f'solvers = ["highs"]\nseeds = [0, {2**40}]\n[grid]\n"schedule.aircraft" = [2]\n',
        "small-5": 'small = 5\n[grid]\n"schedule.aircraft" = [2]\n',
        "small-list": 'small = ["seeds"]\n[grid]\n"schedule.aircraft" = [2]\n',
        "small-seeds-word": '[grid]\n"schedule.aircraft" = [2]\n[small]\nseeds = "all"\n',
        "set-5": 'set = 5\n[grid]\n"schedule.aircraft" = [2]\n',
        "grid-5": "grid = 5\n",
        "name-5": 'name = 5\n[grid]\n"schedule.aircraft" = [2]\n',
        "seed-5000-digits": f'seeds = [{"9" * 5000}]\n[grid]\n"schedule.aircraft" = [2]\n',
        "seed-400-digits": f'seeds = [{"9" * 400}]\n[grid]\n"schedule.aircraft" = [2]\n',
        "grid-10^8-cases": f'solvers = ["greedy", "highs"]\n[grid]\n{grid8}',
    }
    for name, body in files.items():
        path = tmp / "sweeps" / f"{name}.toml"
        path.write_text(head + body, encoding="utf-8")
        cls = "memory" if name == "grid-10^8-cases" else "sweeps"
        cases.append(Case(cls, f"sweep-file-{name}", ["sweep", str(path), "--out", str(tmp / "sweeps" / f"out-{name}")],
                          (2,), out=tmp / "sweeps" / f"out-{name}"))
    largest = max(p.stat().st_size for p in parts(reference))
    for label, limit in (("part", largest - 1000),
                         ("results", (largest + (reference / "results.parquet").stat().st_size) // 2)):
        out = tmp / "sweeps" / f"fsize-{label}"
        cases.append(Case("sweeps", f"file-size-limit-{label}", ["sweep", str(sweep), "--out", str(out)], (2,),
                          "File too large", fsize=limit, timeout=300))
        cases.append(Case("sweeps", f"file-size-limit-{label}-resume", ["sweep", str(sweep), "--out", str(out)], (0,),
                          check=same_table(out), timeout=300))
    disk = tmp / "sweeps" / "disk"
    disk.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=200k", "tmpfs", str(disk)], capture_output=True,
                      check=False).returncode == 0:
        page = os.sysconf("SC_PAGE_SIZE")
        part_pages = math.ceil(largest / page)
        (disk / "filler").write_bytes(b"\0" * ((os.statvfs(disk).f_bavail - (2 + 2 * part_pages)) * page))
        out = disk / "out"

        def free_then_check(proc, out=out):
            (disk / "filler").unlink()
            again = subprocess.run([sys.executable, "-m", "uamopt", "sweep", str(sweep), "--out", str(out)], cwd=code,
                                   env=env, capture_output=True, text=True, timeout=600, check=False)
            return [] if again.returncode == 0 and not same_table(out)(again) else ["wrong exit"]

        cases.append(Case("sweeps", "full-disk-then-resume", ["sweep", str(sweep), "--out", str(out)], (2,),
                          "No space left on device", check=free_then_check, timeout=300))
    return cases


# --- class: interrupts --------------------------------------------------------------------------

def interrupt_cases(tmp: Path, code: Path) -> list[Case]:
    paper = str(code / "models" / "paper_case.toml")
    commands = {
        "risk": (["risk", paper, "--set", "grid.cell=[10,10,10]"], "summary.json"),
        "plan": (["plan", paper, "--no-figures"], "tracks.json"),
        "schedule-highs": (["schedule", paper, "--solver", "highs"], "summary.json"),
        "schedule-cpsat": (["schedule", paper, "--solver", "cpsat"], "summary.json"),
        # an interrupted sweep keeps its finished cases for a resume: sweep.json and parts/, not torn
        "sweep": (["sweep", str(tmp / "sweeps" / "fast.toml")], "sweep.json"),
    }
    cases = []
    for name, (argv, complete) in commands.items():
        for sig, code_ in ((signal.SIGINT, 130), (signal.SIGTERM, 143)):
            for at in (0.05, 0.6, 2.0, 5.0):
                out = tmp / "interrupts" / f"{name}-{sig.name}-{at}"
                out.parent.mkdir(parents=True, exist_ok=True)
                cases.append(Case("interrupts", f"{name}-{sig.name}-at-{at}-s", [*argv, "--out", str(out)],
                                  (code_, 0), out=out, complete=complete, signal_at=(sig, at), lines_ok=False))
    good = tmp / "verify" / "good"
    for at in (3.0, 8.0):
        cases.append(Case("interrupts", f"replay-SIGKILL-at-{at}-s", ["replay", str(good)], (-9, 0),
                          signal_at=(signal.SIGKILL, at), timeout=300))
    return cases


# --- class: memory ------------------------------------------------------------------------------

def _flights_file(path: Path, n: int, spread: bool) -> Path:
    """``n`` flights: spread over a 20 km city in time and space, or all through one cell at once."""
    import numpy as np

    rng = np.random.default_rng(0)
    rows, csv_rows = [], []
    for i in range(n):
        if spread:
            x, y = rng.uniform(0, 19000, 2)
            dep = float(rng.uniform(0, 86400 * 30))
        else:
            x, y, dep = 100.0, 100.0, float(i % 50)
        rows.append(f'{{"id": "F{i}", "aircraft": "A{i}", "route": "R{i}", "origin": "O", "destination": "D", '
                    f'"speed_mps": 25.0, "planned_departure_s": {dep}, "max_delay_s": 600.0, '
                    f'"waypoints": [[{x:.1f}, {y:.1f}, 120.0], [{x + 500:.1f}, {y:.1f}, 120.0]]}}')
        csv_rows.append(f"F{i},A{i},R{i},1,{dep},0.0,{dep},{dep + 20.0}\n")
    path.mkdir(parents=True)
    head = ('{"cell": [50.0, 50.0, 30.0], "conflict_radius": 1, "service_start_s": 0.0, "service_end_s": 2600000.0, '
            '"outbound_gap_s": 60.0, "return_gap_s": 90.0, "flights": [')
    (path / "flights.json").write_text(head + ", ".join(rows) + "]}", encoding="utf-8")
    (path / "schedule.csv").write_text("flight,aircraft,route,operated,planned_departure_s,delay_s,departure_s,arrival_s\n"
                                       + "".join(csv_rows), encoding="utf-8")
    return path


def memory_cases(tmp: Path, code: Path) -> list[Case]:
    paper = str(code / "models" / "paper_case.toml")
    spread = _flights_file(tmp / "memory" / "million", 10**6, True)
    dense = _flights_file(tmp / "memory" / "one-cell", 8000, False)
    cases = []
    for label, folder in (("10^6-flights-spread", spread), ("8000-flights-one-cell", dense)):
        cases.append(Case("memory", f"verify-{label}", ["verify", str(folder)], (0, 1, 2), inputs=None, lines_ok=True))
        out = _out(tmp / "memory", f"out-{label}")
        cases.append(Case("memory", f"schedule-{label}", ["schedule", paper, "--solver", "greedy", "--flights",
                                                          str(folder / "flights.json"), "--out", str(out)],
                          (0, 2), out=out, lines_ok=False))
    out = _out(tmp / "memory", "out-aircraft")
    cases.append(Case("memory", "schedule-aircraft-10^7", ["schedule", paper, "--solver", "greedy", "--set",
                                                           "schedule.aircraft=10000000", "--out", str(out)], (2,), out=out))
    return cases


# --- class: table (in this process, as tests/test_hostile.py runs it) ---------------------------

def table_rows(timeout_s: int) -> list[tuple[str, list[str], str]]:
    from hostile_files import write_all
    from test_hostile import CASES, _argv, _snapshot as snap

    from uamopt.cli import main

    rows = []

    def alarm(signum, frame):
        raise TimeoutError

    with tempfile.TemporaryDirectory(prefix="hostile-") as tmp:
        files = write_all(Path(tmp) / "files")
        for n, (name, line, expected, fragment) in enumerate(CASES):
            out = _out(Path(tmp) / f"case{n}")
            before = snap(files)
            stdout, stderr = io.StringIO(), io.StringIO()
            faults = []
            signal.signal(signal.SIGALRM, alarm)
            signal.alarm(timeout_s)
            with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
                try:
                    code = main(_argv(line, files, out))
                except SystemExit as exc:
                    code = exc.code
                except TimeoutError:
                    faults, code = ["hang/memory"], None
                except MemoryError:
                    faults, code = ["hang/memory"], None
                except BaseException:  # noqa: BLE001 - a traceback the user would see
                    traceback.print_exc()
                    code = None
                finally:
                    signal.alarm(0)
            if (code is None and not faults) or "Traceback" in stderr.getvalue():
                faults.append("traceback")
            if code != expected and "hang/memory" not in faults:
                faults.append("wrong exit")
            lines = stderr.getvalue().strip().splitlines()
            if expected == 2 and code == 2 and not (len(lines) == 1 and lines[0].startswith("error: ") and fragment in lines[0]):
                faults.append("error line")
            if sorted(p.name for p in out.iterdir()) != ["keep.txt"] or snap(files) != before:
                faults.append("torn output")
            rows.append((name, sorted(set(faults)), f"exit {code}"))
    return rows


# --- the census ---------------------------------------------------------------------------------

CLASSES = ("table", "infeasible", "api", "verify", "sweeps", "interrupts", "memory")


def census(code: Path, only: set[str], show: bool, timeout_s: int) -> dict[str, Counter]:
    counts: dict[str, Counter] = defaultdict(Counter)

    def record(cls, name, faults, detail):
        counts[cls]["cases"] += 1
        counts[cls].update(faults)
        if set(faults) - set(OUTSIDE):
            counts[cls]["faulty"] += 1
        if show and faults:
            print(f"  {cls}/{name}: {', '.join(faults)} -- {detail}", flush=True)

    with tempfile.TemporaryDirectory(prefix="census-") as t:
        tmp = Path(t)
        if "infeasible" in only:
            for name, faults, detail in _table_child("infeasible", code, INFEASIBLE):
                record("infeasible", name, faults, detail)
        if "api" in only:
            folders = _damaged_folders(tmp / "api")
            for name, faults, detail in _table_child("api", code, api_script(folders), (json.dumps(folders),)):
                record("api", name, faults, detail)
            want = len(API_CASES) + sum(len(v) for v in folders.values())
            for _ in range(want - counts["api"]["cases"]):  # the child ended before these
                record("api", "(not reached)", ["traceback"], "the child process ended")
        cases: list[Case] = []
        if {"verify", "interrupts"} & only:
            cases += [c for c in verify_cases(tmp) if "verify" in only]
        if {"sweeps", "interrupts", "memory"} & only:
            cases += [c for c in sweep_cases(tmp, code) if c.cls in only]
        if "interrupts" in only:
            cases += interrupt_cases(tmp, code)
        if "memory" in only:
            cases += memory_cases(tmp, code)
        for case in cases:
            faults, detail = run_case(case, code)
            record(case.cls, case.name, faults, detail)
        if "table" in only:
            if Path(code).resolve() != CHECKOUT:  # the table runs in this process: the code must be importable
                sys.path.insert(0, str(code))
                for mod in [m for m in sys.modules if m == "uamopt" or m.startswith("uamopt.")]:
                    del sys.modules[mod]
            for name, faults, detail in table_rows(timeout_s):
                record("table", name, faults, detail)
        with contextlib.suppress(Exception):
            subprocess.run(["umount", "-l", str(tmp / "sweeps" / "disk")], capture_output=True, check=False)
    return counts


def print_table(counts: dict[str, Counter]) -> None:
    head = ["class", "cases", "clean", *FAULTS, *OUTSIDE]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    total: Counter = Counter()
    for cls in CLASSES:
        if cls in counts:
            c = counts[cls]
            total.update(c)
            print(f"| {cls} | {c['cases']} | {c['cases'] - c['faulty']} | "
                  + " | ".join(str(c[f]) for f in FAULTS + OUTSIDE) + " |")
    print(f"| all | {total['cases']} | {total['cases'] - total['faulty']} | "
          + " | ".join(str(total[f]) for f in FAULTS + OUTSIDE) + " |")


if __name__ == "__main__":
    args = sys.argv[1:]
    code = Path(args[args.index("--code") + 1]).resolve() if "--code" in args else CHECKOUT
    only = set(args[args.index("--only") + 1].split(",")) if "--only" in args else set(CLASSES)
    timeout = int(args[args.index("--timeout") + 1]) if "--timeout" in args else 120
    started = time.monotonic()
    result = census(code, only, "--list" in args, timeout)
    print_table(result)
    print(f"code: {code}; {time.monotonic() - started:.0f} s")
