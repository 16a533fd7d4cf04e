"""Constraint families of the scheduling model: each rule written once, as named arrays.

A :class:`~uamopt.schedule.SchedulingProblem` carries its objective and a tuple of *families*
(``problem.families``). A family is a small frozen dataclass holding the named arrays of one rule
(PyPSA's shape: compute the arrays once, then one add-constraints call per solver), with

- ``name``: what the user sees (``"conflicts"``, ``"turnaround"``, ``"departure_spacing"``, ...);
- ``shape``: what an encoder reads. Every exact solver (``highs``, ``cpsat``, ``timeindexed``,
  ``bruteforce``) has one encoder per shape, and the heuristics (``greedy``, ``ga``, ``soa``,
  ``rolling``) reach the shapes through their decoder's one feasibility interface. Shapes:

  ``pairs``        for pairs (p, q): δ = dep_q − dep_p avoids open intervals (lo, hi) when both
                   operate (Eq. 24; any rule of that form: a separation, a spacing);
  ``turnaround``   for rows (e, f): d_f − d_e ≥ need when both operate (Eqs. 27-28);
  ``precedence``   f operated ⇒ requires[f] operated;
  ``bounds``       0 ≤ d_f ≤ upper_s[f] (Eqs. 26, 29; time windows);
  ``must_operate`` c_f = 1 where mask[f].
  ``cumulative``   events (flight, resource, offset, duration): at most capacity[r] operated
                   events hold resource r at once (vertiport pads); one-capacity resources are
                   read as ``pairs`` (``problem.pairs``), so only the rest needs this shape.

  A new family of an existing shape needs no solver change (docs/variants.md). A solver that has
  no encoder for a family's shape refuses before it starts (:func:`uamopt.solvers.check_supported`).
- ``description``: one line for logs and docs;
- ``violations(problem, operated, delay_s, tol_s)``: what a decision breaks, in words; the
  model's :func:`~uamopt.schedule.model.violations` is the concatenation over the families.
  (``uamopt verify`` checks written files with its own code, sharing none of this.)

The paper's model is five families, derived from the flight set and its conflict table by
:func:`paper_families`; more are added with ``SchedulingProblem(..., extra_families=(...))`` or
by a scenario key (:func:`scenario_families`).
"""

from __future__ import annotations

import importlib
import pkgutil
from typing import TYPE_CHECKING, Protocol, runtime_checkable

if TYPE_CHECKING:
    import numpy as np

    from uamopt.scenario import Scenario
    from uamopt.schedule.flights import FlightSet
    from uamopt.schedule.model import SchedulingProblem

SHAPES = ("pairs", "turnaround", "precedence", "bounds", "must_operate", "cumulative")


@runtime_checkable
class Family(Protocol):
    """What every family provides (module docstring); read-only, so that a frozen dataclass is one."""

    @property
    def name(self) -> str: ...

    @property
    def shape(self) -> str: ...

    @property
    def description(self) -> str: ...

    def violations(self, problem: SchedulingProblem, operated: np.ndarray, delay_s: np.ndarray,
                   tol_s: float) -> list[str]: ...


def paper_families(problem: SchedulingProblem) -> tuple[Family, ...]:
    """The five families of the paper's model (Sec. 4.3), from ``problem``'s flights and conflicts."""
    from uamopt.schedule.families.bounds import DelayBounds
    from uamopt.schedule.families.must import MustOperate
    from uamopt.schedule.families.pairs import PairIntervals
    from uamopt.schedule.families.turnaround import Precedence, Turnaround

    c = problem.conflicts
    return (DelayBounds.of(problem.flights), MustOperate(problem.must_operate), Precedence.of(problem.flights),
            Turnaround.of(problem.flights), PairIntervals.of_table("conflicts", c.p, c.q, c.ptr, c.intervals))


def scenario_families(flightset: FlightSet, scenario: Scenario | None) -> tuple[Family, ...]:
    """Families a scenario's keys switch on: every module of this package with a
    ``from_scenario(flightset, scenario)`` function contributes what it returns (None: nothing).
    A new family module is picked up without editing this file."""
    if scenario is None:
        return ()
    out = []
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{__name__}.{info.name}")
        make = getattr(module, "from_scenario", None)
        if make is not None:
            family = make(flightset, scenario)
            if family is not None:
                out.append(family)
    return tuple(out)
