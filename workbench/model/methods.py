"""The registry of integration methods: what ``simulate(method=...)`` and ``--method`` take.

A method is a step method and a driver.  The step method is an explicit
Runge-Kutta tableau (:mod:`workbench.model.tableaus`), written into the
model's parameter array.  The driver is the kernel that chooses the steps:
:func:`workbench.core.hybrid.run_hybrid` (fixed steps of
:func:`workbench.core.integrate.rk_step`) or
:func:`workbench.core.adaptive.run_adaptive` (steps of an embedded pair,
:mod:`workbench.core.pair`, chosen by its error estimate against a
tolerance); both apply events with :mod:`workbench.core.hybrid`.  A new
explicit method is a :class:`~workbench.model.tableaus.Tableau` (fixed
steps) or an FSAL :class:`~workbench.model.tableaus.Pair` with its error
weights and dense output (controlled steps) and one :func:`register`
call, with no new kernel and no compile.

``dop853`` (the default): Dormand-Prince 8(5,3) steps chosen one at a
time by its embedded estimates against ``tol`` (default
:data:`workbench.model.limits.DEFAULT_TOL`), events located on its dense
output of order 7 (:mod:`workbench.core.adaptive` states what is
controlled and how it is scaled).  ``dopri5``: Dormand-Prince 5(4) with
Shampine's dense output of order 4, the same way (on the accuracy
benchmark it needs 5e-6 for the bounds and 5e-7 for the 36 ms reference's
event times, and is then 1.5 times slower than ``dop853`` at 1e-5;
docs/performance.md).  ``rk4``: fixed RK4 steps of dt, as given (``--dt``)
or the stability step, with no error estimate: earlier results are
reproduced with it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..core.adaptive import run_adaptive
from ..core.hybrid import run_hybrid
from .tableaus import DOP853, DOPRI5, RK4, Pair, Tableau

#: The smallest step by default: dt / 2^DEFAULT_LEVEL_MAX (3.9e-7 s from 1e-4 s); a step
#: there is accepted whatever its estimate and reported (``floor_intervals``).
DEFAULT_LEVEL_MAX = 8
#: Rows of the record of steps accepted at the smallest step above the tolerance.
FLOOR_LOG_ROWS = 2000


@dataclass(frozen=True)
class Method:
    name: str
    tableau: Tableau
    controlled: bool
    description: str
    #: Wall seconds per base step (the stability step) a sweep's plan assumes
    #: before the study has run.
    seconds_per_step: float

    @property
    def kernel(self) -> Callable:
        """The driver: the error-controlled or the fixed-step event loop."""
        return run_adaptive if self.controlled else run_hybrid

    def __post_init__(self):
        if self.controlled != isinstance(self.tableau, Pair):
            raise ValueError(f"method {self.name!r}: a controlled method steps with an "
                             f"embedded pair (tableaus.Pair), a fixed-step one with a tableau")


METHODS: dict[str, Method] = {}


def register(method: Method) -> Method:
    METHODS[method.name] = method
    return method


# seconds_per_step: what the 10 s sines at 200 N take per base step (1e-4 s with the tip mass,
# 6.25e-5 s without) at the default tolerance, and fixed RK4 on contact-rich runs
# (docs/performance.md).
register(Method("dopri5", DOPRI5, True,
                "Dormand-Prince 5(4), steps chosen one at a time by its embedded estimate "
                "against tol, events on its dense output", seconds_per_step=2e-5))
register(Method("dop853", DOP853, True,
                "Dormand-Prince 8(5,3), steps chosen by its embedded estimates against tol, events "
                "on its dense output of order 7", seconds_per_step=2e-5))
register(Method("rk4", RK4, False, "fixed-step RK4 (dt as given, or the stability step)",
                seconds_per_step=2e-5))

DEFAULT_METHOD = "dop853"
