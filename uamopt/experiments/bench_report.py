"""``bench.csv``, ``bench.md`` and the performance profile of a benchmark table (benchmark.py).

bench.md: the instances with their best known objective (the least objective of any verified run)
and the profiles that found it; per instance and profile the runs, how many verified, the statuses, the objective's
median and range over the seeds, its distance to the best known (median − best) / |best|, the
median gap and the times; then every run. With several instances, a Dolan–Moré performance
profile (``performance_profile.png``): for each profile the fraction of instances on which its
median objective lies within a factor τ of the best profile's, with the ratio taken on the
objective's distance to the best, r = 1 + (obj − best) / |best| (the objectives of Eq. 20 are
negative, so a plain quotient would not order them); a run without a solution has r = ∞.
Then *Incumbent and bound over time* (:func:`over_time`, ``convergence.png``): from each run's
trace, the seconds to its first incumbent, to within 1 % of the best known objective and to its
last bound gain, and its primal integral.

With ``--against FILE`` (uamopt/experiments/results.py) a section *Against FILE* follows the
instances: first, loudly, the contradictions (a bound of the file above a verified objective of
this run, or this run's bound above the file's objective: one of the two is wrong) and the
instances whose size differs from the file's; then per run the best known objective and bound,
the distances ``to_best_objective`` and ``to_best_bound`` (negative: this run is better), the runs
that beat the file in words, the instances the file does not have, and the file's rows no run matched.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from uamopt.plotting.benchmark import distance, plot_convergence, plot_performance_profile, run_trace, step_values

TINY = 1e-9  # a value below this (rounding noise, e.g. a gap of 1.3e-15) is printed as 0


def _seconds(value: float) -> str:
    """Three significant digits, never in exponent form: 0.00869, 12.3, 1230."""
    value = float(f"{value:.3g}")
    places = max(0, 2 - math.floor(math.log10(abs(value))))
    return f"{value:.{places}f}"


def _num(value, digits: int = 6, column: str = "") -> str:
    """A table cell of bench.md: ``-`` when missing; a ``gap`` column as a percentage with two
    decimals; a timing column (``wall s median``, ``solve_seconds``, ``time_limit_s``, ...) to
    three significant digits; other numbers to ``digits``; below 1e-9 in magnitude, 0."""
    import pandas as pd

    if value is None or value is pd.NA or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    if isinstance(value, (float, np.floating)):
        if "gap" in column:
            return "0.00 %" if abs(value) < TINY else f"{100.0 * value:.2f} %"
        if abs(value) < TINY:
            return "0"
        if " s " in f" {column} " or "seconds" in column or column == "time_limit_s":
            return _seconds(value)
        return f"{value:.{digits}g}"
    return str(value)


def _markdown(frame, columns: list[str]) -> list[str]:
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(_num(v, column=c) for c, v in zip(columns, row, strict=True)) + " |"
              for row in frame[columns].itertuples(index=False)]
    return lines


def best_known(table):
    """Per instance: the least objective of a verified run with a solution, and the profiles
    that reached it (within a relative 1e-9)."""
    ok = table[table["verified"].fillna(False).astype(bool) & table["objective"].notna()]
    best = ok.groupby("instance", sort=False)["objective"].min()
    found_by = {i: ", ".join(dict.fromkeys(ok[(ok["instance"] == i)
                                              & (ok["objective"] <= b + 1e-9 * max(1.0, abs(b)))]["profile"]))
                for i, b in best.items()}
    return best, found_by


def summary(table):
    """One row per instance × profile: medians and ranges over the seeds (see the module docstring)."""
    import pandas as pd

    best, _ = best_known(table)
    rows = []
    for (instance, profile), runs in table.groupby(["instance", "profile"], sort=False):
        obj = runs["objective"].dropna()
        median = float(obj.median()) if len(obj) else math.nan
        statuses = runs["status"].value_counts()
        models = runs["model"].dropna().unique() if "model" in runs else []
        rows.append({
            "instance": instance, "profile": profile, "model": ", ".join(map(str, models)) or "-", "runs": len(runs),
            "verified": f"{int(runs['verified'].fillna(False).astype(bool).sum())}/{len(runs)}",
            "status": ", ".join(f"{s} ×{n}" for s, n in statuses.items()),
            "objective median": median,
            "objective range": f"{_num(obj.min())} – {_num(obj.max())}" if len(obj) else "-",
            "to best known %": 100.0 * distance(median, best.get(instance, math.nan)),
            "gap median": float(runs["gap"].median()) if runs["gap"].notna().any() else math.nan,
            "wall s median": float(runs["wall_seconds"].median()),
            "wall s max": float(runs["wall_seconds"].max()),
            "solve s median": float(runs["solve_seconds"].median()) if runs["solve_seconds"].notna().any() else math.nan,
            "build s median": float(runs["build_seconds"].median()) if runs["build_seconds"].notna().any() else math.nan,
        })
    return pd.DataFrame(rows)


#: bench.csv columns the Runs table of bench.md leaves out (said elsewhere, or in the Against section)
NOT_IN_RUNS = ("error", "objective_kind", "plan_seed", "scenario", "set", "best_known_objective", "best_known_bound",
               "to_best_objective", "to_best_bound", "trace")

#: a run is "within 1 %" once its incumbent is at most this far above the best known objective
TARGET_DISTANCE = 0.01


def primal_gap(value: float, best: float) -> float:
    """Berthold's primal gap of an incumbent against the best known objective: 1 without an
    incumbent or when the two differ in sign, else |value − best| / max(|value|, |best|) (0 when both are 0)."""
    if not math.isfinite(value) or not math.isfinite(best) or value * best < 0:
        return 1.0
    scale = max(abs(value), abs(best))
    return 0.0 if scale == 0 else min(1.0, abs(value - best) / scale)


def over_time(table):
    """One row per run with a trace: seconds to its first incumbent, to an incumbent within
    ``TARGET_DISTANCE`` of the instance's best known objective, to its last bound improvement, and
    its primal integral (Berthold, "Measuring the impact of primal heuristics", Oper. Res. Lett.
    41(6), 2013): ∫ primal gap dt from 0 to the run's time limit (a run that ended sooner keeps its
    answer's gap to the limit, so a quick heuristic is not rewarded for stopping), in seconds (0:
    the best known at once; the time limit: nothing useful)."""
    import pandas as pd

    best, _ = best_known(table)
    rows = []
    for run in table.itertuples(index=False):
        trace = run_trace(getattr(run, "trace", None))
        if not trace:
            continue
        ref = best.get(run.instance, math.nan)
        end = float(trace[-1][0])
        times, values = step_values(trace, 1)
        bound_times, bounds = step_values(trace, 2)
        gains = bound_times[np.concatenate([[True], np.diff(bounds) > 0])] if len(bounds) else bound_times
        near = [t for t, v in zip(times, values, strict=True) if math.isfinite(ref) and distance(v, ref) <= TARGET_DISTANCE]
        integral, before, gap = 0.0, 0.0, 1.0
        for t, v in zip(times, values, strict=True):
            integral += gap * (min(t, end) - before)
            before, gap = min(t, end), primal_gap(v, ref)
        horizon = max(end, float(run.time_limit_s)) if math.isfinite(float(run.time_limit_s)) else end
        integral += gap * (horizon - before)
        rows.append({"instance": run.instance, "profile": run.profile, "seed": run.seed,
                     "first incumbent s": float(times[0]) if len(times) else math.nan,
                     "within 1 % s": float(near[0]) if near else math.nan,
                     "last bound gain s": float(gains[-1]) if len(gains) else math.nan,
                     "primal integral s": integral, "solve s": end, "gap": run.gap})
    return pd.DataFrame(rows, columns=["instance", "profile", "seed", "first incumbent s", "within 1 % s",
                                       "last bound gain s", "primal integral s", "solve s", "gap"])


def against_section(comparison) -> list[str]:
    """The lines of bench.md's *Against FILE* section (module docstring)."""
    from uamopt.experiments.results import REL_TOL, key_text

    source = comparison.source
    lines = ["", f"## Against {source}", ""]
    for line in comparison.contradictions:
        lines.append(f"- **CONTRADICTION**: {line}. Check the file's value (its `command` reruns it) and this run "
                     "(`uamopt verify` on its schedule); do not record either until one is found wrong.")
    for line in comparison.mismatches:
        lines.append(f"- **NOT COMPARED**: {line}.")
    if comparison.contradictions or comparison.mismatches:
        lines.append("")
    lines += [f"{comparison.matched} of {len(comparison.table)} runs matched a row of {source} (by `instance` and "
              "`plan_seed`). `to_best_objective` = (objective − best_known_objective) / |best_known_objective|, "
              "`to_best_bound` = (best_known_bound − bound) / |best_known_bound| with `bound` a lower bound of the "
              "continuous problem; both negative when this run is better, shown here in %; values within "
              f"{REL_TOL:g} × max(1, |value|) count as equal.", ""]
    table = comparison.table
    matched = table[table["best_known_objective"].notna() | table["best_known_bound"].notna()].copy()
    if len(matched):
        matched["to best objective %"] = 100.0 * matched["to_best_objective"]
        matched["to best bound %"] = 100.0 * matched["to_best_bound"]
        lines += _markdown(matched, ["instance", "plan_seed", "profile", "seed", "status", "verified", "objective",
                                     "best_known_objective", "to best objective %", "bound", "best_known_bound",
                                     "to best bound %"])
        lines.append("")
    if comparison.improvements:
        lines += ["Runs that beat the best known values (record them with `--against "
                  f"{source} --update`):", ""] + [f"- {line}." for line in comparison.improvements] + [""]
    elif len(matched):
        lines += ["No run beats the best known objective or bound.", ""]
    if comparison.not_in_file:
        lines.append(f"Not in {source} (add with `--update`): {', '.join(comparison.not_in_file)}.")
        lines.append("")
    if comparison.not_run:
        lines += [f"Not run (rows of {source} no run matched):", ""]
        lines += [f"- {key_text(*e.key)}: best objective {_num(e.best_objective.value) if e.best_objective else '-'}, "
                  f"best bound {_num(e.best_bound.value) if e.best_bound else '-'}" for e in comparison.not_run]
        lines.append("")
    return lines[:-1]


def bench_markdown(table, comparison=None) -> str:
    best, found_by = best_known(table)
    size = ["instance", "flights", "aircraft", "conflicting_pairs"] + (["plan_seed"] if "plan_seed" in table else [])
    instances = table.drop_duplicates("instance")[size].copy()
    instances["best known objective"] = [best.get(i, math.nan) for i in instances["instance"]]
    instances["found by"] = [found_by.get(i, "-") for i in instances["instance"]]
    limits = sorted({_num(v) for v in table["time_limit_s"]})
    load = ", ".join(f"{v:.2f}" for v in os.getloadavg()) if hasattr(os, "getloadavg") else "n/a"
    lines = ["# Benchmark", "",
             f"{len(table)} runs: {table['instance'].nunique()} instances × {table['profile'].nunique()} profiles × "
             f"seeds {sorted(set(table['seed']))}; time limit {', '.join(limits)} s; objective "
             f"{', '.join(sorted(set(table['objective_kind'])))}; {os.cpu_count()} CPUs, load average {load} at the end.",
             "", "## Instances", "", *_markdown(instances, list(instances.columns))]
    if comparison is not None:
        lines += against_section(comparison)
    lines += ["", "## By solver profile (median and range over seeds)", "",
              "`to best known %` = 100 (median objective − best known) / |best known|; `gap` = |objective − bound| / |objective| "
              "with `bound` always a bound of the continuous problem (Sec. 4.3; empty where the solver has none); "
              "`model` is what the status is about: `continuous`, `delay grid S s` or `discretised U s` (restrictions: "
              "their `optimal_on_grid` is optimal for delays on that grid only), or a heuristic; `solve s` is the "
              "solver's own clock, which the "
              "time limit bounds, `build s` the rest of the wall time (model building, data transfer). Each solver ran "
              "once untimed on a few flights first (imports, helper processes).", ""]
    lines += _markdown(summary(table), ["instance", "profile", "model", "runs", "verified", "status", "objective median",
                                        "objective range", "to best known %", "gap median", "wall s median", "wall s max",
                                        "solve s median", "build s median"])
    if table["instance"].nunique() > 1:
        lines += ["", "## Performance profile", "", "![performance profile](performance_profile.png)"]
    progress = over_time(table) if "trace" in table else None
    if progress is not None and len(progress):
        lines += ["", "## Incumbent and bound over time", "",
                  "![incumbent and bound over time](convergence.png)", "",
                  "From each run's trace (bench.csv `trace`: `[seconds, best objective, best bound]` each time one "
                  "improved). `within 1 % s`: the first time its incumbent was within 1 % of the best known objective "
                  "above; `primal integral s`: ∫ primal gap dt from 0 to its time limit (Berthold 2013; the gap is 1 "
                  "without an incumbent, and a run that ended sooner keeps its answer's gap), smaller is better; "
                  "empty: never.", "",
                  *_markdown(progress, list(progress.columns))]
    lines += ["", "## Runs", "", *_markdown(table, [c for c in table.columns if c not in NOT_IN_RUNS])]
    errors = table[table["error"].notna()]
    if len(errors):
        lines += ["", "## Errors", ""] + [f"- {r.instance} {r.profile} seed {r.seed}: {r.error}" for r in errors.itertuples()]
    return "\n".join(lines) + "\n"


def write_bench(out: str | Path, table, comparison=None) -> str:
    """Write bench.csv, bench.md (and performance_profile.png, convergence.png) into ``out``, all or nothing;
    ``comparison`` (uamopt.experiments.results.compare): the Against section of bench.md."""
    from uamopt.outputs import staged_output
    from uamopt.plotting.output import save

    text = bench_markdown(table, comparison)
    with staged_output(out) as stage:
        table.to_csv(stage / "bench.csv", index=False, na_rep="")
        (stage / "bench.md").write_text(text, encoding="utf-8")
        if table["instance"].nunique() > 1:
            save(plot_performance_profile(table), stage / "performance_profile.png")
        if "trace" in table and len(over_time(table)):
            save(plot_convergence(table), stage / "convergence.png")
    return text
