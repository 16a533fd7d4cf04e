"""Experiments: resumable sweeps over scenario keys on Dask, solver benchmarks, their figures.

Public names (``import uamopt as ua``): ``ua.sweep`` (engine.py), ``ua.load_sweep`` (spec.py),
``ua.plot_sweep`` (figures.py), ``ua.benchmark`` (benchmark.py). Modules: spec.py (sweep files),
case.py (one case on the pipeline), store.py (the results folder), engine.py (Dask, the ``sweep``
command), figures.py (Sec. 6.3 figures), benchmark.py and bench_report.py (``uamopt bench``,
bench.md, the performance profile), progress.py. Heavy imports (Dask, pandas, matplotlib) happen
inside the functions.
"""
