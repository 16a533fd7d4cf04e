"""Experiments: resumable sweeps over scenario keys on Dask, solver benchmarks, their figures.

``sweep(path, out=None, scheduler=None, workers=None, small=False) -> DataFrame`` (engine.py),
``benchmark(problems_or_scenarios, solvers, seeds=[0], time_limit_s=None) -> DataFrame``
(benchmark.py), ``plot_sweep(table, kind)`` (figures.py). Heavy imports (Dask, pandas) happen
inside the functions, so importing this package is cheap.
"""

from uamopt.experiments.benchmark import benchmark
from uamopt.experiments.case import run_case
from uamopt.experiments.engine import sweep
from uamopt.experiments.spec import SweepSpec, load_sweep

__all__ = ["SweepSpec", "benchmark", "load_sweep", "run_case", "sweep"]
