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
