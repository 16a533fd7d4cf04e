"""``uamopt bench --against FILE [--update]``: runs against a results file of best known values
(docs/benchmarks.md, uamopt/experiments/results.py), on real runs of models/benchmark_120.toml
(greedy and HiGHS, 2 s limits; about 5 s a run)."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from uamopt.cli import main

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = "models/benchmark_120.toml"
FORMAT = "uamopt-benchmark-results/1"


def bench(out: Path, *args) -> subprocess.CompletedProcess:
    """``uamopt bench models/benchmark_120.toml --solver greedy highs --seeds 2 --time-limit 2`` in a fresh process."""
    return subprocess.run([sys.executable, "-m", "uamopt", "bench", SCENARIO, "--solver", "greedy", "highs", "--seeds", "2",
                           "--time-limit", "2", "--out", str(out), *map(str, args)], cwd=ROOT, capture_output=True,
                          text=True, timeout=600)


def record(value: float, solver: str = "hand", model: str = "continuous") -> dict:
    return {"value": value, "solver": solver, "profile": solver, "model": model, "time_limit_s": 60.0, "threads": 2,
            "command": f"uamopt bench {SCENARIO} --solver {solver}"}


def entry(size: dict, objective: float | None, bound: float | None, instance: str = "benchmark_120", plan_seed=0,
          **changes) -> dict:
    """A hand-written row of a results file for the benchmark_120 instance of ``size``."""
    row = {"instance": instance, "scenario": SCENARIO, "set": [], "plan_seed": plan_seed, **size, "objective_kind": "weighted",
           "best_objective": None if objective is None else record(objective),
           "best_bound": None if bound is None else record(bound)}
    return row | changes


def write(path: Path, *entries: dict) -> Path:
    path.write_text(json.dumps({"format": FORMAT, "instances": list(entries)}, indent=2))
    return path


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    """One real bench (greedy and HiGHS × seeds 0, 1) with ``--against`` a file that does not exist
    yet and ``--update``: it creates the file. Returns (folder, bench.csv table, created file, size)."""
    folder = tmp_path_factory.mktemp("against")
    created = folder / "created.json"
    proc = bench(folder / "base", "--against", created, "--update")
    assert proc.returncode == 0, proc.stderr
    table = pd.read_csv(folder / "base" / "bench.csv")
    assert table["verified"].all() and len(table) == 4
    first = table.iloc[0]
    size = {"flights": int(first["flights"]), "aircraft": int(first["aircraft"]),
            "conflicting_pairs": int(first["conflicting_pairs"])}
    return folder, table, created, size


def runs_of(table, profile: str):
    return table[table["profile"] == profile]


def test_update_creates_the_file_from_the_verified_runs(base):
    _, table, created, size = base
    data = json.loads(created.read_text())
    assert data["format"] == FORMAT and len(data["instances"]) == 1
    row = data["instances"][0]
    assert (row["instance"], row["plan_seed"], row["scenario"], row["set"]) == ("benchmark_120", 0, SCENARIO, [])
    assert {k: row[k] for k in size} == size and row["objective_kind"] == "weighted"
    highs = runs_of(table, "highs")
    assert row["best_objective"]["value"] == table["objective"].min() == highs["objective"].iloc[0]
    assert row["best_objective"]["solver"] == "highs" and row["best_objective"]["seed"] == 0
    assert row["best_bound"]["value"] == highs["bound"].max() and row["best_bound"]["model"] == "continuous"
    # the command reruns that profile on the instance (a single --seeds value is a count: 2 = seeds 0 and 1)
    assert row["best_objective"]["command"] == (f"uamopt bench {SCENARIO} --seed 0 --solver highs --seeds 2 "
                                                f"--time-limit 2 --against {created}")
    assert table["plan_seed"].tolist() == [0] * 4 and set(table["set"]) == {"[]"}


def test_the_plan_seed_is_part_of_the_instance(base, tmp_path):
    """``--seed 7`` is another instance of the same name: the file's plan-seed-0 row is not run, and
    --update adds a row of plan seed 7 whose command asks for that plan."""
    _, _, created, _ = base
    path = tmp_path / "results.json"
    path.write_bytes(created.read_bytes())
    proc = subprocess.run([sys.executable, "-m", "uamopt", "bench", SCENARIO, "--solver", "greedy", "--seed", "7",
                           "--out", str(tmp_path / "out"), "--against", str(path), "--update"], cwd=ROOT,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    section = (tmp_path / "out" / "bench.md").read_text().split("## Against ")[1].split("## By solver profile")[0]
    assert "0 of 1 runs matched" in section
    assert f"Not in {path} (add with `--update`): benchmark_120 (plan seed 7)." in section
    assert "- benchmark_120 (plan seed 0): best objective" in section.split("Not run")[1]
    rows = json.loads(path.read_text())["instances"]
    assert [r["plan_seed"] for r in rows] == [0, 7] and rows[1]["instance"] == "benchmark_120"
    assert f"{SCENARIO} --seed 7 --solver greedy --seeds 1 " in rows[1]["best_objective"]["command"]
    assert rows[1]["best_bound"] is None  # greedy has no bound


@pytest.fixture(scope="module")
def compared(base):
    """The same bench against a hand-written file: the instance's row (objective −40 and bound −60:
    HiGHS's proven −41.3 beats both), the same name under plan seed 7 first (other values: a key
    without the plan seed would take them) and an instance not run."""
    folder, _, _, size = base
    path = write(folder / "hand.json", entry(size, -30.0, -46.0, plan_seed=7), entry(size, -40.0, -60.0),
                 entry(size, -9.0, None, instance="benchmark_120[schedule.aircraft=4]"))
    proc = bench(folder / "compared", "--against", path)
    assert proc.returncode == 0, proc.stderr
    return folder / "compared", proc


def test_distances_to_the_best_known(compared):
    out, _ = compared
    table = pd.read_csv(out / "bench.csv")
    assert list(table.columns[-4:]) == ["best_known_objective", "best_known_bound", "to_best_objective", "to_best_bound"]
    assert (table["best_known_objective"] == -40.0).all() and (table["best_known_bound"] == -60.0).all()
    for row in table.itertuples():
        # by hand: (objective − (−40)) / 40 and (−60 − bound) / 60
        assert row.to_best_objective == pytest.approx((row.objective + 40.0) / 40.0, rel=1e-12)
        if row.profile == "highs":
            assert row.to_best_bound == pytest.approx((-60.0 - row.bound) / 60.0, rel=1e-12)
            assert row.to_best_bound < 0 and row.to_best_objective < 0  # HiGHS's −41.3 beats −40 and −60
        else:
            assert math.isnan(row.to_best_bound)  # greedy has no bound
    greedy = table[table["profile"] == "greedy"].iloc[0]
    assert greedy["objective"] > 0 and greedy["to_best_objective"] > 1  # 6.6 against −40: (6.6 + 40) / 40


def test_the_report_says_what_beats_the_file_and_what_was_not_run(compared):
    out, proc = compared
    text = (out / "bench.md").read_text()
    section = text.split("## Against ")[1].split("## By solver profile")[0]
    assert "4 of 4 runs matched" in section
    beats = [line for line in section.splitlines() if "beats the best known" in line]
    runs = [f"- benchmark_120 (plan seed 0) highs seed {s}" for s in (0, 0, 1, 1)]
    assert sorted(line.split(": ")[0] for line in beats) == runs
    assert sum("beats the best known objective -40 " in line for line in beats) == 2
    assert sum("beats the best known bound -60 " in line for line in beats) == 2
    not_run = section.split("Not run")[1]
    assert "benchmark_120 (plan seed 7)" in not_run and "benchmark_120[schedule.aircraft=4] (plan seed 0)" in not_run
    assert "CONTRADICTION" not in text and "warning:" not in proc.stderr


def test_a_bound_above_a_verified_objective_is_a_contradiction(base):
    """The file's bound −30 lies above HiGHS's verified −41.3: said loudly in bench.md and on stderr,
    and --update leaves the file as it was (neither value is recorded until one is found wrong)."""
    folder, table, _, size = base
    path = write(folder / "contradicted.json", entry(size, -20.0, -30.0))
    before = path.read_bytes()
    proc = bench(folder / "contradiction", "--against", path, "--update")
    assert proc.returncode == 0, proc.stderr
    warnings = [line for line in proc.stderr.splitlines() if line.startswith("warning: ")]
    contradictions = [line for line in warnings if line.startswith("warning: contradiction")]
    assert len(contradictions) == 2 and all("best bound -30 " in line and "highs seed" in line for line in contradictions)
    assert any("not recorded" in line and "contradiction" in line for line in warnings)
    assert "**CONTRADICTION**" in (folder / "contradiction" / "bench.md").read_text()
    assert path.read_bytes() == before
    assert runs_of(table, "highs")["objective"].max() < -30.0  # the premise: a verified objective below the bound


def test_an_instance_of_another_size_is_not_compared(base):
    from uamopt.experiments.results import compare, read_results

    folder, table, _, size = base
    path = write(folder / "resized.json", entry(size | {"conflicting_pairs": size["conflicting_pairs"] + 1}, -50.0, -60.0))
    comparison = compare(table, read_results(path), str(path))
    assert len(comparison.mismatches) == 1 and "not the same instance" in comparison.mismatches[0]
    assert comparison.matched == 0 and comparison.table["best_known_objective"].isna().all()
    assert comparison.not_run == [] and comparison.warnings()[0].startswith("not compared with")


def test_a_bound_of_this_run_above_the_files_objective_is_a_contradiction(base, tmp_path):
    """The other way round: a file whose objective −50 lies below HiGHS's proven bound (about −41.3)."""
    from uamopt.experiments.results import compare, read_results

    _, table, _, size = base
    comparison = compare(table, read_results(write(tmp_path / "r.json", entry(size, -50.0, -60.0))))
    assert [c.split(": ")[0] for c in comparison.contradictions] == [f"benchmark_120 (plan seed 0) highs seed {s}"
                                                                     for s in (0, 1)]
    assert all("is above the file's best objective -50 " in c for c in comparison.contradictions)


def test_update_keeps_the_better_value(base, tmp_path):
    """Objective and bound each move only to a better value: a file with −40 / −45 takes HiGHS's
    −41.3 / −41.3; a later bench.csv with a worse objective (greedy's) and a worse bound leaves them."""
    from uamopt.experiments.results import update_results

    folder, table, _, size = base
    path = write(tmp_path / "results.json", entry(size, -40.0, -45.0))
    changes, skipped = update_results(path, folder / "base" / "bench.csv")
    assert len(changes) == 1 and skipped == []
    row = json.loads(path.read_text())["instances"][0]
    highs = runs_of(table, "highs")
    assert row["best_objective"]["value"] == highs["objective"].min() and row["best_objective"]["solver"] == "highs"
    assert row["best_bound"]["value"] == highs["bound"].max() and row["best_bound"]["time_limit_s"] == 2.0

    worse = table.copy()
    worse.loc[worse["profile"] == "highs", "bound"] = -43.0
    worse.loc[worse["profile"] == "highs", "objective"] = -41.0
    worse.to_csv(tmp_path / "worse.csv", index=False)
    before = path.read_bytes()
    assert update_results(path, tmp_path / "worse.csv") == ([], [])
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []  # no temporary file left


def test_update_takes_only_verified_rows_and_bounds_of_the_continuous_problem(base, tmp_path):
    """An unverified row with a better objective and a heuristic row carrying a bound change nothing;
    the same bound under model ``continuous`` is taken (the rule binds)."""
    from uamopt.experiments.results import update_results

    _, table, _, size = base
    best = runs_of(table, "highs")["objective"].min()
    path = write(tmp_path / "results.json", entry(size, best, -45.0))
    planted = table.copy()
    highs = planted["profile"] == "highs"
    planted.loc[highs, ["objective", "bound", "verified"]] = [best - 1.0, best - 1.5, False]
    greedy = planted.index[planted["profile"] == "greedy"]
    planted.loc[greedy[0], "bound"] = -43.0  # model "delay grid 10 s, heuristic"
    planted.to_csv(tmp_path / "planted.csv", index=False)
    before = path.read_bytes()
    assert update_results(path, tmp_path / "planted.csv")[0] == []
    assert path.read_bytes() == before

    planted.loc[greedy[0], "model"] = "continuous"
    planted.to_csv(tmp_path / "planted.csv", index=False)
    changes, _ = update_results(path, tmp_path / "planted.csv")
    row = json.loads(path.read_text())["instances"][0]
    assert len(changes) == 1 and row["best_bound"]["value"] == -43.0 and row["best_objective"]["value"] == best

    planted.loc[highs, "verified"] = True
    planted.to_csv(tmp_path / "planted.csv", index=False)
    update_results(path, tmp_path / "planted.csv")
    row = json.loads(path.read_text())["instances"][0]
    assert (row["best_objective"]["value"], row["best_bound"]["value"]) == (best - 1.0, best - 1.5)


def _bad(size: dict, fault: str) -> dict:
    data = {"format": FORMAT, "instances": [entry(size, -50.0, -60.0)]}
    row = data["instances"][0]
    if fault == "missing key":
        del row["conflicting_pairs"]
    elif fault == "nan":
        row["best_objective"]["value"] = math.nan  # json.dumps writes NaN, which Python's json reads back
    elif fault == "string for a number":
        row["best_bound"]["value"] = "-60"
    elif fault == "wrong format":
        data["format"] = "uamopt-benchmark-results/2"
    elif fault == "bound above objective":
        row["best_bound"]["value"] = -40.0
    elif fault == "boolean plan seed":
        row["plan_seed"] = True
    return data


@pytest.mark.parametrize(("fault", "fragment"), [
    ("missing key", "has no key 'conflicting_pairs'"),
    ("nan", "value must be a number in [-1e+15, 1e+15], got nan"),
    ("string for a number", "value must be a number in [-1e+15, 1e+15], got '-60'"),
    ("wrong format", "unknown format 'uamopt-benchmark-results/2'"),
    ("bound above objective", "best_bound -40.0 is above best_objective -50.0"),
    ("boolean plan seed", "plan_seed must be an integer in [0, 2^63 - 1], got True"),
])
def test_a_bad_results_file_is_one_line_and_exit_2(fault, fragment, tmp_path, capsys):
    size = {"flights": 120, "aircraft": 20, "conflicting_pairs": 289}
    path = tmp_path / "results.json"
    path.write_text(json.dumps(_bad(size, fault)))
    before = path.read_bytes()
    out = tmp_path / "out"
    for update in ([], ["--update"]):
        code = main(["bench", SCENARIO, "--solver", "greedy", "--out", str(out), "--against", str(path), *update])
        err = capsys.readouterr().err
        assert code == 2, err
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: ") and fragment in lines[0], err
        assert f"({path}" in lines[0] and "): " in lines[0]  # what (where): how to fix
        assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["results.json"]
        assert path.read_bytes() == before


def test_bad_options_are_one_line(tmp_path, capsys):
    out = tmp_path / "out"
    for args, fragment in ((["--update"], "--update needs --against FILE"),
                           (["--against", str(tmp_path / "none.json")], "results file not found"),
                           (["--against", str(tmp_path / "no" / "such" / "r.json"), "--update"], "its folder does not exist"),
                           (["--against", str(tmp_path / "r.json"), "--flights", "f.json"], "--flights or --network")):
        code = main(["bench", SCENARIO, "--solver", "greedy", "--out", str(out), *args])
        err = capsys.readouterr().err
        assert code == 2 and err.startswith("error: ") and fragment in err and len(err.strip().splitlines()) == 1, err
        assert not out.exists() and not (tmp_path / "r.json").exists()


def test_the_shipped_results_file_reads(base):
    """benchmarks/results.json (rows of real verified runs, docs/benchmarks.md) passes the reader,
    and its rows of benchmark_120 are the instance this code generates."""
    from uamopt.experiments.results import read_results

    _, _, _, size = base
    results = read_results(ROOT / "benchmarks" / "results.json")
    rows = [e for e in results.entries if e.instance == "benchmark_120" and e.plan_seed == 0]
    assert len(rows) == 1 and (rows[0].flights, rows[0].aircraft, rows[0].conflicting_pairs) == tuple(size.values())
    assert all(e.best_objective is None or e.best_objective.command.startswith("uamopt bench ") for e in results.entries)
