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
- ``"pads"`` (the vertiport variant, docs/variants.md): the same two panels per pads per
  vertiport ``network.pads``.

Without ``kind``, any sweep table: ``plot_sweep(table, x=..., hue=..., y=...)`` draws the metric
``y`` against the swept key ``x``, one line per value of ``hue`` (a second key, or the solver),
the median over seeds with their min–max range as a band, one panel per value of any other key
that varies (see :func:`plot_sweep`).
"""

from __future__ import annotations

import io
import math
import re
from pathlib import Path

import numpy as np

from uamopt.paper import table4_row

#: swept key of each study (its x axis)
KEYS = {"altitude": "network.cruise_altitude_m", "cell": "grid.cell", "weights": "tracks.weights",
        "flights": "schedule.flights", "speed": "aircraft.cruise_speed_mps", "pads": "network.pads"}
#: the paper's Table 4 (optimal tracks at 10 m and 5 m cells): risk, ¥, waypoints, seconds
#: the metric drawn when ``y`` is not given, by the stage the sweep ran to
DEFAULT_METRIC = {"schedule": "avg_delay_s", "network": "risk_cost", "plan": "risk_cost", "risk": "cruise_unsafe_share"}
#: metrics computed from the table's columns
DERIVED = {"fulfilment": ("planned flights operated (%)", lambda t: 100.0 * _float(t["operated"]) / _float(t["flights"]))}
#: axis labels of the result columns (docs/sweeps.md) and of the keys the paper's studies sweep
LABELS = {
    "avg_delay_s": "average delay T_d (s, Eq. 21)", "total_delay_s": "total delay Σd (s)",
    "operated": "flights operated S (Eq. 22)", "cancelled": "flights cancelled",
    "objective": "objective (schedule.objective: lexicographic or Eq. 20)",
    "bound": "bound of the objective", "gap": "gap |objective − bound| / |objective|",
    "seconds": "computing time of the stage (s)", "risk_cost": "operational risk C_R (Eq. 11)",
    "transport_cost": "transport cost C_T (¥, Eq. 12)", "length_m": "length (m)", "n_waypoints": "waypoints",
    "unsafe_share": "unsafe share of all cells (Eq. 9)",
    "band_unsafe_share": "unsafe share of the band's free cells (Eq. 9)",
    "cruise_unsafe_share": "unsafe share of the cruise layer's free cells (Eq. 9)",
    "cruise_mean_risk": "mean risk R of the cruise layer (per flight hour, Eq. 8)",
    "conflicting_pairs": "conflicting flight pairs", "flights": "planned flights", "aircraft": "aircraft",
    "solver": "solver", "seed": "seed",
    "schedule.flights": "total planned flights F", "aircraft.cruise_speed_mps": "cruise speed v_g (m/s)",
    "network.cruise_altitude_m": "cruise altitude h (m)", "grid.cell": "cell (Δx, Δy, Δz) (m)",
    "tracks.weights": "weights (ω4, ω5)", "schedule.aircraft": "aircraft G",
    "network.pads": "pads per vertiport (FATO)",
}
MAX_PANELS = 12  # one panel per value of the keys left over; more is a table to filter first
MAX_TICK_LABELS = 12  # categorical x: more labels than this are thinned


def _axes(ax, count: int, width: float = 5.2):
    """(figure, axes) from ``ax`` as every plot of uamopt.plotting takes it: None (a new page), a
    Figure or SubFigure (the page laid out in it), one Axes (the first panel only) or one Axes
    per panel."""
    from uamopt.plotting.layout import panels

    def layout(page):
        if hasattr(page, "set_layout_engine"):
            page.set_layout_engine("constrained")
        return list(np.ravel(page.subplots(1, count)))

    fig, axes, _ = panels(ax, count, layout, figsize=(width * count, 4.0))
    return fig, axes


def _float(column):
    """A column as float64 (pandas' nullable integers and NA become floats and NaN)."""
    import pandas as pd

    return pd.to_numeric(column, errors="coerce").astype("float64")


def _x_values(table, key: str) -> list:
    """The swept key's values in grid order (first appearance), without missing values."""
    import pandas as pd

    return list(dict.fromkeys(v for v in table[key].tolist() if not pd.isna(v)))


def swept_keys(table) -> list[str]:
    """The swept keys of a sweep table: the dotted columns (they follow ``case``)."""
    return [c for c in table.columns[1:] if "." in c]


def sweep_stage(table) -> str:
    """The stage a sweep table was run to, from its columns (docs/sweeps.md)."""
    if "flights" in table.columns:
        return "schedule"
    if "risk_cost" in table.columns:
        return "network" if "network.cruise_altitude_m" in table.columns else "plan"
    return "risk"


def _is_numeric(values: list) -> bool:
    return bool(values) and all(isinstance(v, (int, float, np.number)) and not isinstance(v, (bool, np.bool_))
                                for v in values)


def _short(value) -> str:
    """A tick label: numbers with :g, list text without trailing ``.0`` ("[10, 10, 10]")."""
    if isinstance(value, (float, np.floating)):
        return f"{value:g}"
    return re.sub(r"(\d)\.0\b", r"\1", str(value))


def _label(name: str) -> str:
    if name in DERIVED:
        return DERIVED[name][0]
    return f"{LABELS[name]} ({name})" if name in LABELS and "." in name else LABELS.get(name, name)


def _metric(table, y: str):
    """The values of metric ``y`` (a column or a :data:`DERIVED` name) as floats."""
    return DERIVED[y][1](table) if y in DERIVED else _float(table[y])


def _category_ticks(ax, labels: list[str]) -> None:
    """Categorical ticks that stay readable: rotated when long, every k-th when many."""
    step = max(1, math.ceil(len(labels) / MAX_TICK_LABELS))
    shown = [text if i % step == 0 else "" for i, text in enumerate(labels)]
    width_in = ax.get_position().width * ax.figure.get_figwidth() if hasattr(ax.figure, "get_figwidth") else 4.0
    chars = sum(len(t) for t in shown if t) + 2 * len([t for t in shown if t])
    rotate = chars * 0.075 > width_in  # about 0.075 in per character at 9 pt
    ax.set_xticks(range(len(labels)), shown, rotation=30 if rotate else 0, ha="right" if rotate else "center",
                  rotation_mode="anchor" if rotate else "default")


def _lines(ax, rows, x: str, hue: str | None, values, xs: list, hues: list, colours: dict) -> None:
    """Median over the remaining rows (the seeds) per value of ``x``, one line per ``hue`` value,
    the rows' min–max range as a band."""
    numeric = _is_numeric(xs)
    for h in hues if hue is not None else [None]:
        sub = rows if hue is None else rows[(rows[hue] == h).fillna(False).to_numpy(dtype=bool)]
        if not len(sub):
            continue
        v = values.loc[sub.index]
        stats = v.groupby(sub[x].astype(object), sort=False).agg(["median", "min", "max"]).dropna()
        order = [p for p in xs if p in stats.index]
        if not order:
            continue
        stats = stats.loc[order]
        pos = [float(p) for p in order] if numeric else [xs.index(p) for p in order]
        colour = colours.get(h)
        ax.plot(pos, stats["median"], marker="o", color=colour, label=None if h is None else _short(h))
        if (stats["max"] > stats["min"]).any():
            ax.fill_between(pos, stats["min"], stats["max"], color=colour, alpha=0.15, lw=0)
    if numeric:
        if len(xs) <= MAX_TICK_LABELS:
            ax.set_xticks(sorted(float(p) for p in xs), [_short(p) for p in sorted(xs)])
    else:
        _category_ticks(ax, [_short(p) for p in xs])
    ax.grid(alpha=0.3)


def sweep_lines(table, x: str | None = None, hue: str | None = None, y: str | None = None, ax=None):
    """The generic sweep figure of :func:`plot_sweep` (its ``kind=None`` branch)."""
    import matplotlib

    from uamopt.errors import UamoptError

    swept = swept_keys(table)
    if not swept:
        raise UamoptError("the table has no swept key", "sweep figure", "pass a sweep's results.parquet")
    stage = sweep_stage(table)
    choices = [c for c in table.columns if c not in ("case", "status", "error", "uamopt_version", "model")]
    x = x or swept[0]
    varying = [c for c in [*swept, "solver"] if c in table.columns and c != x and table[c].nunique(dropna=True) > 1]
    hue = hue if hue is not None else (varying[0] if varying else None)
    y = y or DEFAULT_METRIC[stage]
    for name, what in ((x, "x"), (hue, "hue")):
        if name is not None and name not in table.columns:
            raise UamoptError(f"no column '{name}' for {what}", "sweep figure", f"use one of {', '.join(choices)}")
    if y not in table.columns and y not in DERIVED:
        raise UamoptError(f"no metric '{y}'", "sweep figure", f"use one of {', '.join([*choices, *DERIVED])}")
    ok = table[(table["status"] != "error").fillna(True).to_numpy(dtype=bool)] if "status" in table else table
    values = _metric(ok, y)
    facets = [c for c in varying if c != hue]
    groups = list(ok.groupby([ok[c].astype(object) for c in facets], sort=False)) if facets else [((), ok)]
    if len(groups) > MAX_PANELS:
        raise UamoptError(f"{len(groups)} panels (one per value of {', '.join(facets)})", "sweep figure",
                          f"pass hue= one of them, or filter the table to at most {MAX_PANELS} combinations")
    xs, hues = _x_values(ok, x), (_x_values(ok, hue) if hue is not None else [])
    palette = matplotlib.colormaps["tab10" if len(hues) <= 10 else "tab20"].colors
    colours = {h: palette[i % len(palette)] for i, h in enumerate(hues)}
    fig, axes = _axes(ax, len(groups))
    for a, (key, rows) in zip(axes, groups, strict=False):
        _lines(a, rows, x, hue, values, xs, hues, colours)
        a.set_xlabel(_label(x))
        a.set_ylabel(_label(y))
        key = key if isinstance(key, tuple) else (key,)
        note = objective_note(rows) if y in ("avg_delay_s", "total_delay_s", "fulfilment", "objective") else ""
        a.set_title(", ".join(f"{k} = {_short(v)}" for k, v in zip(facets, key, strict=True)) + (" — " if facets else "")
                    + "median over seeds, band: min–max" + (f"\n{note}" if note else ""), fontsize=9)
        if hue is not None:
            a.legend(title=_label(hue), fontsize=8, title_fontsize=8)
        _bounded(a, y)
    return fig


def _bounded(ax, metric: str) -> None:
    """Axes of a share of the plan run from 0 % to 100 % (the lines at 100 % drawn whole, the
    legend below them); delays start at 0 s."""
    if metric == "fulfilment":
        ax.set_ylim(0.0, 100.0)
        for line in ax.lines:
            line.set_clip_on(False)
        if ax.get_legend() is not None:
            ax.get_legend().set_loc("lower left")
    elif metric in ("avg_delay_s", "total_delay_s"):
        ax.set_ylim(bottom=0.0)


def _by_solver(table, key: str, y, ax, ylabel: str, xlabel: str) -> None:
    """Median over seeds (line) and the seeds' range (band) per solver, against ``key``."""
    import matplotlib

    ok = table[table["status"] != "error"]
    solvers = _x_values(ok, "solver")
    colours = dict(zip(solvers, matplotlib.colormaps["tab10"].colors, strict=False))
    _lines(ax, ok, key, "solver", y(ok), _x_values(table, key), solvers, colours)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.legend(title="solver")


def objective_note(table) -> str:
    """The objective(s) a schedule table was solved under, as a figure names them."""
    if "objective_kind" not in table:
        return ""
    kinds = [str(k) for k in dict.fromkeys(table["objective_kind"].dropna())]
    words = {"lexicographic": "lexicographic objective (most flights, then least delay)",
             "weighted": "Eq. 20 weighted objective"}
    return ", ".join(words.get(k, k) for k in kinds)


def _delays(table, key: str, ax, label: str):
    fig, axes = _axes(ax, 2)
    _by_solver(table, key, lambda r: _float(r["avg_delay_s"]), axes[0], "average delay T_d (s, Eq. 21)", label)
    note = objective_note(table)
    axes[0].set_title("Average delay (median over seeds, band: range)" + (f"\n{note}" if note else ""), fontsize=10)
    _bounded(axes[0], "avg_delay_s")
    if len(axes) > 1:
        _by_solver(table, key, DERIVED["fulfilment"][1], axes[1], "planned flights operated (%)", label)
        _bounded(axes[1], "fulfilment")  # a share of the plan: from none to all of it
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


def _numbers(value) -> tuple[float, ...]:
    """A swept list value as its numbers: the table holds lists as their TOML text ("[10.0, 10.0, 10.0]")."""
    return tuple(float(v) for v in str(value).strip("[]").split(","))


def _cell(table, key: str, ax):
    fig, axes = _axes(ax, 4, width=3.4)
    rows = table.drop_duplicates("case")
    labels = [str(v) for v in rows[key]]
    metrics = (("risk_cost", "operational risk (Eq. 11)"), ("transport_cost", "transport cost (¥, Eq. 12)"),
               ("n_waypoints", "number of waypoints"), ("seconds", "computing time (s)"))
    pos = np.arange(len(labels))
    for i, (a, (column, title)) in enumerate(zip(axes, metrics, strict=False)):
        a.bar(pos - 0.2, rows[column].astype(float), width=0.4, label="uamopt")
        paper = [(table4_row(_numbers(cell)) or (np.nan,) * 4)[i] for cell in rows[key]]
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
    weights = [_numbers(w) for w in rows[key]]
    order = np.argsort([w[0] for w in weights])
    risk, cost = rows["risk_cost"].to_numpy()[order], rows["transport_cost"].to_numpy()[order]
    axes[0].plot(cost, risk, "-o", color="tab:blue")
    for i, j in enumerate(order):
        axes[0].annotate(f"ω4={weights[j][0]:g}", (cost[i], risk[i]), textcoords="offset points", xytext=(5, 4), fontsize=8)
    spread = np.nanmax(cost) / max(np.nanmin(cost), 1e-12) if len(cost) else 1.0
    if spread > 2.0:  # one far point (ω4 = 1 at several times the others' cost) would squeeze the rest
        axes[0].set_xscale("log")
    axes[0].set_xlabel("transport cost C_T (¥, Eq. 12)" + (", log scale" if spread > 2.0 else ""))
    axes[0].set_ylabel("operational risk C_R (Eq. 11)")
    axes[0].set_title("Risk against transport cost over the weights (ω4, ω5)")
    axes[0].grid(alpha=0.3)
    return fig


def plot_sweep(table, kind: str | None = None, ax=None, *, x: str | None = None, hue: str | None = None,
               y: str | None = None):
    """A sweep's figure from its table (``uamopt.sweep(...)`` or ``results.parquet``); returns the
    Figure. ``ax`` as in :mod:`uamopt.plotting`: None (a new figure), a Figure or SubFigure, one
    Axes (the first panel), or one Axes per panel.

    ``kind`` names one of the paper's studies (module docstring: ``"altitude"``, ``"cell"``,
    ``"weights"``, ``"flights"``, ``"speed"``, ``"pads"``). Without it, any sweep table:

    - ``x``: the column on the x axis, numeric (drawn to scale, a tick per value up to 12) or
      categorical (list values such as ``grid.cell`` as "[10, 10, 10]", in grid order; long
      labels rotated, more than 12 thinned); default the first swept key.
    - ``hue``: a second column, one line per value with a legend (e.g. another swept key, or
      ``"solver"``); default the next swept key that varies, else the solver when several ran.
    - ``y``: the metric, a result column (docs/sweeps.md) or ``"fulfilment"`` (planned flights
      operated, %, on a 0–100 % axis); default per stage: ``avg_delay_s`` (schedule),
      ``risk_cost`` (plan, network), ``cruise_unsafe_share`` (risk).

    Rows with the same ``x`` and ``hue`` (the seeds) are aggregated: the line is their median,
    the band their min–max range. Every other column that varies among the swept keys and the
    solver gets one panel per value (at most 12), so no dimension of the sweep is averaged away
    silently. Failed cases (status ``error``) are left out.

    Examples
    --------
    >>> table = ua.sweep("my_sweep.toml", out="out/my")                           # doctest: +SKIP
    >>> ua.plot_sweep(table, x="aircraft.cruise_speed_mps", hue="schedule.aircraft")  # doctest: +SKIP
    >>> ua.plot_sweep(table, x="schedule.aircraft", hue="solver", y="fulfilment")  # doctest: +SKIP

    Raises
    ------
    UamoptError
        An unknown ``kind``, a study's key missing from the table, a column or metric the
        table lacks, or more than 12 panels.
    """
    import pandas as pd

    from uamopt.checks import expect
    from uamopt.errors import UamoptError

    expect(table, pd.DataFrame, "table", "plot_sweep")
    for name, value in (("kind", kind), ("x", x), ("hue", hue), ("y", y)):  # a column's or a study's name
        if value is not None:
            expect(value, str, name, "plot_sweep")
    if kind is None:
        return sweep_lines(table, x=x, hue=hue, y=y, ax=ax)
    if kind not in KEYS:
        raise UamoptError(f"unknown figure '{kind}'", "sweep figure", f"use one of {', '.join(KEYS)}")
    key = KEYS[kind]
    if key not in table.columns:
        raise UamoptError(f"figure '{kind}' needs the swept key '{key}'", "sweep figure", f"sweep \"{key}\" in [grid]")
    if kind in ("flights", "speed", "pads"):
        return _delays(table, key, ax, LABELS[key])
    return {"altitude": _altitude, "cell": _cell, "weights": _weights}[kind](table, key, ax)


def save_sweep_figure(table, spec, path: str | Path) -> Path:
    """Draw ``spec.figure`` from ``table`` into ``path`` (PNG, written atomically)."""
    from uamopt.outputs import atomic_write
    from uamopt.plotting.style import DPI

    fig = plot_sweep(table, spec.figure)
    fig.suptitle(f"{spec.name}{' (small)' if spec.small else ''}: {len(spec.cases)} cases", fontsize=10)
    buffer = io.BytesIO()  # drawn in memory: a full disk's error then knows the size needed
    fig.savefig(buffer, format="png", dpi=DPI)
    atomic_write(Path(path), buffer.getvalue())
    return Path(path)
