"""Figures of every stage: each plot function draws, returns the matplotlib Figure and writes
nothing; :func:`save` writes a figure to a file.

    import uamopt.plotting as plotting
    fig = plotting.risk(field, vertiports=scenario.network.vertiports)   # a Figure: Jupyter shows it
    plotting.save(fig, "risk.png")
    plotting.tracks(plan, model, ax=my_axes)                             # draw map (a) into your axes

Every function takes ``ax=``: None (a new figure in the page layout the CLI writes), a Figure
or SubFigure (the page laid out in it), one Axes (the first panel only), or, for the multi-panel
pages, a sequence of Axes with one per panel. See each function for its panels.

============================  ==================================================  =========
function                      draws                                               panels
============================  ==================================================  =========
:func:`risk`                  risk map, city, section, profiles (Eqs. 8–9, 14)    5
:func:`risk_components`       each term of Eq. 8 by altitude                      4
:func:`tracks`                the four stages of Fig. 18 / Table 2               3
:func:`network`               every route and direction, a profile row per route  2
:func:`pareto`                the risk–transport fronts of Fig. 21 (axis cut)     1
:func:`gantt`                 one schedule per aircraft (Eqs. 24–28)              1
:func:`delays`                delay per flight and solver (Fig. 19)               1
:func:`sweep`                 a study, or any sweep (x, hue, y), from results     1–12
:func:`performance_profile`   Dolan–Moré profile of a benchmark table             1
============================  ==================================================  =========

:func:`explore` is the one interactive view: a schedule folder in 3-D (plotly, an offline HTML file
or inline in Jupyter; :mod:`uamopt.plotting.explore`), not a matplotlib Figure.

Importing this package in Jupyter lets a returned Figure display as a PNG without pyplot
(:func:`uamopt.plotting.output.show_figures_in`). This package imports matplotlib; ``import uamopt`` does not import
it. The submodules ``risk``, ``tracks``, ``network`` and ``schedule`` are shadowed here by the functions of the same name
(import from them with ``from uamopt.plotting.tracks import STAGE_STYLE``). The helpers the plot
functions share are public, one job per module, each importing only those above it:

=================================  ===========================================================
:mod:`uamopt.plotting.style`       constants: resolution, page size, colours, label halo, credit
:mod:`uamopt.plotting.geometry`    plain numpy: grid layers and windows, track geometry
:mod:`uamopt.plotting.layout`      figures and axes: the ``ax=`` argument, pages in inches,
                                   colour-bar axes, title and data credit
:mod:`uamopt.plotting.draw`        shared drawing on an Axes: risk colours, cells, maps,
                                   vertiports, log axes, panel letters and titles
:mod:`uamopt.plotting.output`      :func:`save`, PNG bytes and the Jupyter display
=================================  ===========================================================
"""

from uamopt.plotting.benchmark import plot_performance_profile as performance_profile
from uamopt.plotting.explore import explore
from uamopt.plotting.network import network
from uamopt.plotting.output import save, show_figures_in
from uamopt.plotting.risk import risk, risk_components
from uamopt.plotting.schedule import delays, gantt
from uamopt.plotting.style import DPI
from uamopt.plotting.sweeps import plot_sweep as sweep
from uamopt.plotting.tracks import pareto, tracks


def _running_shell():
    """The IPython shell this code runs in, if any (IPython is not imported for it)."""
    import sys

    ipython = sys.modules.get("IPython")
    return ipython.get_ipython() if ipython is not None else None


show_figures_in(_running_shell())

__all__ = ["DPI", "delays", "explore", "gantt", "network", "pareto", "performance_profile", "risk", "risk_components", "save",
           "sweep", "tracks"]
