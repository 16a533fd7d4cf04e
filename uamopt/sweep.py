"""Resumable sweeps over scenario keys on Dask (``uamopt sweep``; docs/sweeps.md).

::

    import uamopt as ua
    table = ua.sweep("models/variants/speed.toml", out="out/speed")   # the rows of results.parquet
    ua.plot_sweep(table, "speed")                                      # the study's figure

The engine lives in :mod:`uamopt.experiments` (spec.py: the file format; case.py: one case on
the pipeline; store.py: the results folder; engine.py: Dask; figures.py: the figures).
"""

from uamopt.experiments.case import run_case
from uamopt.experiments.engine import sweep
from uamopt.experiments.figures import plot_sweep
from uamopt.experiments.spec import SweepSpec, load_sweep

__all__ = ["SweepSpec", "load_sweep", "plot_sweep", "run_case", "sweep"]
