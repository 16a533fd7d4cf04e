"""Experiments: resumable sweeps over scenario keys on Dask, solver benchmarks, their figures.

Public entry points: ``uamopt.sweep`` (uamopt/sweep.py) and ``uamopt.benchmark``
(uamopt/benchmark.py). Modules: spec.py (sweep files), case.py (one case on the pipeline),
store.py (the results folder), engine.py (Dask, the ``sweep`` command), figures.py (Sec. 6.3
figures), benchmark.py and bench_report.py (``uamopt bench``), progress.py. Heavy imports (Dask,
pandas, matplotlib) happen inside the functions.
"""
