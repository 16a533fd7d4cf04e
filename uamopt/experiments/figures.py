"""Figures of the sensitivity studies (Sec. 6.3), drawn from a sweep's ``results.parquet`` only.

``plot_sweep(table, kind)`` returns a matplotlib Figure; ``kind`` names the study:

- ``"altitude"`` (Fig. 20): the unsafe share of the cruise layer's free cells (Eq. 9) and the
  network's summed risk cost (Eq. 11) per cruise altitude ``network.cruise_altitude_m``.
- ``"cell"`` (Table 4): the optimal track's risk cost, transport cost (¥), waypoints and computing
  time per cell size ``grid.cell``, with the paper's Table 4 values beside ours at 10 m and 5 m.
- ``"weights"`` (Fig. 21): the optimal tracks' risk cost against transport cost per (ω4, ω5)
  ``tracks.weights``: the trade-off curve.
- ``"flights"`` (Fig. 22) and ``"speed"`` (Fig. 23): the average delay T_d (Eq. 21) and the share
  of planned flights operated per total planned flights ``schedule.flights`` or cruise speed
  ``aircraft.cruise_speed_mps``, one line per solver (the preliminary strategy ``greedy`` is the
  paper's "before optimization"), median over seeds with the seeds' range as a band.

Without ``kind``: the first swept key on the x axis and the stage's main metric (average delay,
or risk cost, or the cruise unsafe share) on the y axis.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

#: swept key of each study (its x axis)
KEYS = {"altitude": "network.cruise_altitude_m", "cell": "grid.cell", "weights": "tracks.weights",
        "flights": "schedule.flights", "speed": "aircraft.cruise_speed_mps"}
#: the paper's Table 4 (optimal tracks at 10 m and 5 m cells): risk, ¥, waypoints, seconds
PAPER_TABLE4 = {"[10.0, 10.0, 10.0]": (196.0, 27.1527, 386, 68.71), "[5.0, 5.0, 5.0]": (163.33, 25.7975, 636, 659.52)}


def _axes(ax, count: int, width: float = 5.2):
    """(figure, axes) from ``ax`` as every plot of uamopt.plotting takes it: None (a new page), a
    Figure or SubFigure (the page laid out in it), one Axes (the first panel only) or one Axes
    per panel."""
    from uamopt.plotting.style import panels

    def layout(page):
        if hasattr(page, "set_layout_engine"):
            page.set_layout_engine("constrained")
        return list(np.ravel(page.subplots(1, count)))

    fig, axes, _ = panels(ax, count, layout, figsize=(width * count, 4.0))
    return fig, axes


def _x_values(table, key: str) -> list:
    """The swept key's values in grid order (first appearance)."""
    return list(dict.fromkeys(table[key].tolist()))


def _by_solver(table, key: str, y, ax, ylabel: str, xlabel: str) -> None:
    """Median over seeds (line) and the seeds' range (band) per solver, against ``key``."""
    ok = table[table["status"] != "error"]
    xs = _x_values(table, key)
    numeric = all(isinstance(x, (int, float, np.number)) for x in xs)
    for solver, rows in ok.groupby("solver", sort=False):
        values = y(rows)
        grouped = values.groupby(rows[key], sort=False)
        stats = [(x, grouped.get_group(x)) for x in xs if x in grouped.groups]
        pos = [x if numeric else xs.index(x) for x, _ in stats]
        ax.plot(pos, [g.median() for _, g in stats], marker="o", label=str(solver))
        ax.fill_between(pos, [g.min() for _, g in stats], [g.max() for _, g in stats], alpha=0.15)
    if not numeric:
        ax.set_xticks(range(len(xs)), [str(x) for x in xs])
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend()


def _delays(table, key: str, ax, label: str):
    fig, axes = _axes(ax, 2)
    _by_solver(table, key, lambda r: r["avg_delay_s"], axes[0], "average delay T_d (s, Eq. 21)", label)
    axes[0].set_title("Average delay (median over seeds, band: range)")
    if len(axes) > 1:
        _by_solver(table, key, lambda r: 100.0 * r["operated"] / r["flights"], axes[1], "planned flights operated (%)",
                   label)
        axes[1].set_title("Task fulfilment")
    return fig


def _altitude(table, key: str, ax):
    has_network = "risk_cost" in table.columns and table["risk_cost"].notna().any()
    fig, axes = _axes(ax, 2 if has_network else 1)
    rows = table.drop_duplicates("case")
    xs = rows[key].to_numpy(dtype=float)
    width = 0.6 * (np.min(np.diff(np.sort(xs))) if len(xs) > 1 else 30.0)
    axes[0].bar(xs, 100.0 * rows["cruise_unsafe_share"], width=width, color="tab:red")
    axes[0].set_ylabel("unsafe cells in the cruise layer (%, Eq. 9)")
    axes[0].set_title("Unsafe airspace at the cruise altitude")
    if has_network and len(axes) > 1:
        axes[1].bar(xs, rows["risk_cost"], width=width, color="tab:purple")
        axes[1].set_ylabel("risk cost of the network (Σ Eq. 11)")
        axes[1].set_title("Risk along the planned route network")
    for a in axes:
        a.set_xticks(xs)
        a.set_xlabel("cruise altitude h (m)")
        a.grid(alpha=0.3, axis="y")
    return fig


def _cell(table, key: str, ax):
    fig, axes = _axes(ax, 4, width=3.4)
    rows = table.drop_duplicates("case")
    labels = [str(v) for v in rows[key]]
    metrics = (("risk_cost", "operational risk (Eq. 11)"), ("transport_cost", "transport cost (¥, Eq. 12)"),
               ("n_waypoints", "number of waypoints"), ("seconds", "computing time (s)"))
    pos = np.arange(len(labels))
    for i, (a, (column, title)) in enumerate(zip(axes, metrics)):
        a.bar(pos - 0.2, rows[column].astype(float), width=0.4, label="uamopt")
        paper = [PAPER_TABLE4.get(label, (np.nan,) * 4)[i] for label in labels]
        if np.isfinite(paper).any():
            a.bar(pos + 0.2, paper, width=0.4, label="paper (Table 4)")
        a.set_xticks(pos, [label.replace(".0", "") for label in labels], fontsize=8)
        a.set_title(title, fontsize=10)
        a.set_xlabel("cell (m)")
        a.grid(alpha=0.3, axis="y")
    axes[0].legend(fontsize=8)
    return fig


def _weights(table, key: str, ax):
    fig, axes = _axes(ax, 1, width=6.0)
    rows = table[table["status"] != "error"].drop_duplicates("case")
    weights = [tuple(float(v) for v in str(w).strip("[]").split(",")) for w in rows[key]]
    order = np.argsort([w[0] for w in weights])
    risk, cost = rows["risk_cost"].to_numpy()[order], rows["transport_cost"].to_numpy()[order]
    axes[0].plot(cost, risk, "-o", color="tab:blue")
    for i, j in enumerate(order):
        axes[0].annotate(f"ω4={weights[j][0]:g}", (cost[i], risk[i]), textcoords="offset points", xytext=(5, 4), fontsize=8)
    axes[0].set_xlabel("transport cost C_T (¥, Eq. 12)")
    axes[0].set_ylabel("operational risk C_R (Eq. 11)")
    axes[0].set_title("Trade-off between risk and transport cost (ω4, ω5)")
    axes[0].grid(alpha=0.3)
    return fig


def plot_sweep(table, kind: str | None = None, ax=None):
    """The study's figure from a sweep table (``uamopt.sweep(...)`` or ``results.parquet``);
    ``ax`` as in :mod:`uamopt.plotting` (None, a Figure, one Axes: the first panel, or one Axes
    per panel). Returns the Figure."""
    from uamopt.errors import UamoptError

    swept = [c for c in table.columns[1:] if "." in c]
    if kind is None:
        key = swept[0]
        if "avg_delay_s" in table and table["avg_delay_s"].notna().any():
            return _delays(table, key, ax, key)
        metric = "risk_cost" if "risk_cost" in table.columns else "cruise_unsafe_share"
        fig, axes = _axes(ax, 1)
        axes[0].plot([str(x) for x in table[key]], table[metric], "o-")
        axes[0].set_xlabel(key)
        axes[0].set_ylabel(metric)
        axes[0].grid(alpha=0.3)
        return fig
    if kind not in KEYS:
        raise UamoptError(f"unknown figure '{kind}'", "sweep figure", f"use one of {', '.join(KEYS)}")
    key = KEYS[kind]
    if key not in table.columns:
        raise UamoptError(f"figure '{kind}' needs the swept key '{key}'", "sweep figure", f"sweep \"{key}\" in [grid]")
    if kind in ("flights", "speed"):
        return _delays(table, key, ax, {"flights": "total planned flights F", "speed": "cruise speed v_g (m/s)"}[kind])
    return {"altitude": _altitude, "cell": _cell, "weights": _weights}[kind](table, key, ax)


def save_sweep_figure(table, spec, path: str | Path) -> Path:
    """Draw ``spec.figure`` from ``table`` into ``path`` (PNG, written atomically)."""
    from uamopt.experiments.store import atomic_write

    from uamopt.plotting.style import DPI

    fig = plot_sweep(table, spec.figure)
    fig.suptitle(f"{spec.name}{' (small)' if spec.small else ''}: {len(spec.cases)} cases", fontsize=10)
    atomic_write(Path(path), lambda p: fig.savefig(p, format="png", dpi=DPI))
    return Path(path)
