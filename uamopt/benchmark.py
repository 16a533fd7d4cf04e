"""Solver benchmarks (``uamopt bench``; docs/sweeps.md): every profile × seed on every instance.

::

    import uamopt as ua
    table = ua.benchmark("models/paper_case.toml", ["greedy", "soa", "highs"], seeds=[0, 1, 2], time_limit_s=20)

The code lives in :mod:`uamopt.experiments.benchmark` (rows) and
:mod:`uamopt.experiments.bench_report` (bench.md, the performance profile).
"""

from uamopt.experiments.bench_report import plot_performance_profile, write_bench
from uamopt.experiments.benchmark import benchmark

__all__ = ["benchmark", "plot_performance_profile", "write_bench"]
