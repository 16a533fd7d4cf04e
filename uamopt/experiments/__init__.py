"""Experiments: resumable sweeps over scenario keys on Dask, solver benchmarks, their figures.

Public names (``import uamopt as ua``): ``ua.sweep`` (engine.py), ``ua.load_sweep`` (spec.py),
``ua.benchmark`` (benchmark.py); the figures are in :mod:`uamopt.plotting` (``ua.plot_sweep``:
plotting/sweeps.py, the performance profile: plotting/benchmark.py). Modules: spec.py (sweep files),
case.py (one case on the pipeline), store.py (the results folder), engine.py (Dask, the ``sweep``
command), commands.py (its arguments), benchmark.py and bench_report.py (``uamopt bench``,
bench.md). Heavy imports (Dask, pandas, matplotlib) happen inside the functions.
"""
