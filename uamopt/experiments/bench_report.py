"""``bench.csv``, ``bench.md`` and the performance profile of a benchmark table (benchmark.py).

bench.md: the instances with their best known objective (the least objective of any verified run)
and the profiles that found it; per instance and profile the runs, how many verified, the statuses, the objective's
median and range over the seeds, its distance to the best known (median − best) / |best|, the
median gap and the times; then every run. With several instances, a Dolan–Moré performance
profile (``performance_profile.png``): for each profile the fraction of instances on which its
median objective lies within a factor τ of the best profile's, with the ratio taken on the
objective's distance to the best, r = 1 + (obj − best) / |best| (the objectives of Eq. 20 are
negative, so a plain quotient would not order them); a run without a solution has r = ∞.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from uamopt.plotting.benchmark import distance, plot_performance_profile

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


def bench_markdown(table) -> str:
    best, found_by = best_known(table)
    instances = table.drop_duplicates("instance")[["instance", "flights", "aircraft", "conflicting_pairs"]].copy()
    instances["best known objective"] = [best.get(i, math.nan) for i in instances["instance"]]
    instances["found by"] = [found_by.get(i, "-") for i in instances["instance"]]
    limits = sorted({_num(v) for v in table["time_limit_s"]})
    load = ", ".join(f"{v:.2f}" for v in os.getloadavg()) if hasattr(os, "getloadavg") else "n/a"
    lines = ["# Benchmark", "",
             f"{len(table)} runs: {table['instance'].nunique()} instances × {table['profile'].nunique()} profiles × "
             f"seeds {sorted(set(table['seed']))}; time limit {', '.join(limits)} s; objective "
             f"{', '.join(sorted(set(table['objective_kind'])))}; {os.cpu_count()} CPUs, load average {load} at the end.",
             "", "## Instances", "", *_markdown(instances, list(instances.columns))]
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
    lines += ["", "## Runs", "", *_markdown(table, [c for c in table.columns if c not in ("error", "objective_kind")])]
    errors = table[table["error"].notna()]
    if len(errors):
        lines += ["", "## Errors", ""] + [f"- {r.instance} {r.profile} seed {r.seed}: {r.error}" for r in errors.itertuples()]
    return "\n".join(lines) + "\n"


def write_bench(out: str | Path, table) -> str:
    """Write bench.csv, bench.md (and performance_profile.png) into ``out``, all or nothing."""
    from uamopt.outputs import staged_output
    from uamopt.plotting.output import save

    text = bench_markdown(table)
    with staged_output(out) as stage:
        table.to_csv(stage / "bench.csv", index=False, na_rep="")
        (stage / "bench.md").write_text(text, encoding="utf-8")
        if table["instance"].nunique() > 1:
            save(plot_performance_profile(table), stage / "performance_profile.png")
    return text
