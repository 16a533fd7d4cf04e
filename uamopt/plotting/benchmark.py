"""The Dolan–Moré performance profile of a benchmark table (``uamopt bench``,
:mod:`uamopt.experiments.bench_report`): its ratios and its figure.

For each solver profile, the fraction of instances on which its median objective lies within a
factor τ of the best profile's, with the ratio taken on the objective's distance to the best,
r = 1 + (obj − best) / |best| (the objectives of Eq. 20 are negative, so a plain quotient would not
order them); a run without a solution has r = ∞.
"""

from __future__ import annotations

import math

import numpy as np

from uamopt.plotting.layout import single_axes


def distance(value: float, best: float) -> float:
    """(value − best) / |best|; 0 at the best, NaN without a value or reference."""
    if not (math.isfinite(value) and math.isfinite(best)):
        return math.nan
    return (value - best) / abs(best) if best != 0 else (0.0 if value == best else math.inf)


def performance_ratios(table):
    """instance × profile matrix of r = 1 + (median obj − best median) / |best median| (∞: no solution)."""
    medians = table.groupby(["instance", "profile"], sort=False)["objective"].median().unstack("profile")
    best = medians.min(axis=1)
    ratios = medians.copy()
    for instance in medians.index:
        for profile in medians.columns:
            d = distance(medians.loc[instance, profile], best[instance])
            ratios.loc[instance, profile] = math.inf if math.isnan(d) else 1.0 + d
    return ratios.astype(float)


def plot_performance_profile(table, ax=None):
    """Dolan–Moré profile: fraction of instances with ratio ≤ τ, one step line per profile.
    ``ax`` as in :mod:`uamopt.plotting` (None, a Figure, or an Axes); returns the Figure."""
    ratios = performance_ratios(table)
    finite = ratios.to_numpy()[np.isfinite(ratios.to_numpy())]
    tau_max = max(1.05, float(finite.max()) * 1.05 if finite.size else 2.0)
    fig, ax, _ = single_axes(ax, (6.5, 4.2))
    n = len(ratios)
    for profile in ratios.columns:
        r = np.sort(ratios[profile].to_numpy())
        taus = np.concatenate([[1.0], r[np.isfinite(r)], [tau_max]])
        share = [np.sum(r <= t) / n for t in taus]
        ax.step(taus, share, where="post", label=profile, linewidth=1.6)
    ax.set_xlim(1.0, tau_max)
    ax.set_ylim(0.0, 1.02)
    ax.set_xlabel("τ (ratio to the best objective, 1 + distance)")
    ax.set_ylabel("fraction of instances within τ")
    ax.set_title(f"Performance profile over {n} instances (median over seeds)")
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right")
    return fig


# --- incumbent and bound over time ------------------------------------------------------------------

#: instances drawn in convergence.png at most (the first ones of the table; bench.md lists every run)
MAX_CONVERGENCE_PANELS = 12


def run_trace(value) -> list[list]:
    """A bench.csv ``trace`` cell (a JSON list of ``[seconds, objective, bound]``) as a list; [] when empty."""
    import json

    if value is None or (isinstance(value, float) and math.isnan(value)) or value == "":
        return []
    return json.loads(value) if isinstance(value, str) else list(value)


def step_values(trace: list[list], column: int) -> tuple[np.ndarray, np.ndarray]:
    """(times, values) of one column of a trace (1: objective, 2: bound), points without a value left out."""
    points = [(t[0], t[column]) for t in trace if t[column] is not None]
    if not points:
        return np.zeros(0), np.zeros(0)
    times, values = zip(*points, strict=True)
    return np.asarray(times, dtype=float), np.asarray(values, dtype=float)


def plot_convergence(table, ax=None):
    """Incumbent (solid) and bound (dashed) over the solve's own seconds, one panel per instance
    (the first :data:`MAX_CONVERGENCE_PANELS`), one colour per solver profile, one line per seed.
    ``ax`` as in :mod:`uamopt.plotting` (None, a Figure, or a sequence of Axes); returns the Figure."""
    from uamopt.plotting.layout import panels

    instances = list(dict.fromkeys(table["instance"]))[:MAX_CONVERGENCE_PANELS]
    columns = min(3, len(instances))
    rows = -(-len(instances) // columns)

    def layout(page):
        page.set_layout_engine("constrained")
        return list(np.ravel(page.subplots(rows, columns, squeeze=False)))[:len(instances)]

    fig, axes, page = panels(ax, len(instances), layout, (4.6 * columns, 3.4 * rows))
    colours = {p: f"C{i % 10}" for i, p in enumerate(dict.fromkeys(table["profile"]))}
    for axis, instance in zip(axes, instances, strict=False):
        labelled: set = set()
        answers = []  # each run's final objective and bound: the y range shows them, not a first poor incumbent
        for run in table[table["instance"] == instance].itertuples(index=False):
            trace = run_trace(getattr(run, "trace", None))
            colour = colours[run.profile]
            for column, style, what in ((1, "-", "incumbent"), (2, "--", "bound")):
                times, values = step_values(trace, column)
                if not len(times):
                    continue
                label = f"{run.profile} {what}" if (run.profile, what) not in labelled else None
                labelled.add((run.profile, what))
                axis.step(times, values, where="post", linestyle=style, color=colour, linewidth=1.4, label=label)
                axis.plot(times[-1:], values[-1:], "o" if column == 1 else "v", color=colour, markersize=3.5)
                answers.append(float(values[-1]))
        if answers:
            low, high = min(answers), max(answers)
            span = max(high - low, 1e-6 * max(1.0, abs(high)))
            axis.set_ylim(low - 0.1 * span, high + 0.8 * span)
        axis.set_title(str(instance), fontsize=9)
        axis.set_xlabel("solve seconds")
        axis.set_ylabel("objective")
        axis.grid(alpha=0.3)
        if labelled:
            axis.legend(fontsize=7, loc="best")
    if page is not None:
        page.suptitle("Incumbent (solid) and bound (dashed) over time; markers: each run's answer "
                      "(the axis is cut above the answers)", fontsize=10)
    return fig
