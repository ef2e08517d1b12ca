"""The registry of integration methods: what ``simulate(method=...)`` and ``--method`` take.

A method is a step method and a driver.  The step method is an explicit
Runge-Kutta tableau (:mod:`workbench.model.tableaus`), written into the
model's parameter array and taken by :func:`workbench.core.integrate.rk_step`
for every step, partial step and re-integration.  The driver is the kernel
that chooses the steps: :func:`workbench.core.hybrid.run_hybrid` (fixed
steps) or :func:`workbench.core.controlled.run_controlled` (steps chosen
by step doubling against a tolerance, which adds its controller's
arrays); both step through :func:`workbench.core.hybrid.advance`, the
event logic.  A new explicit method is a :class:`~workbench.model.tableaus.Tableau`
and one :func:`register` call, with no new kernel and no compile; a method
of another kind (implicit stages, an embedded estimate) is one kernel
module in ``workbench/core`` beside ``integrate.py`` and one
:func:`register` call.

``controlled`` (the default): RK4 steps on a lattice of dt / 2^k inside
each control interval, chosen by step doubling against ``tol`` (default
:data:`workbench.model.limits.DEFAULT_TOL`; :mod:`workbench.core.controlled`
states what is controlled and how it is scaled).  ``rk4``: fixed RK4 steps of dt, as given (``--dt``) or the
stability step, with no error estimate: earlier results are reproduced
with it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..core.controlled import run_controlled
from ..core.hybrid import run_hybrid
from .tableaus import RK4, Tableau

#: The finest level by default: steps down to dt / 2^DEFAULT_LEVEL_MAX (3.9e-7 s from 1e-4 s).
#: At level 6 the 0.635 mm chirp (studies/chirp.toml) accepted an interval at its floor with an
#: estimate of 30.7 times the tolerance (t = 161.257 s, an impact closing point 3 as point 1
#: left); at level 8 every interval of the four chirps meets the tolerance or is one whose two
#: paths' events differ, for 3 % more steps.
DEFAULT_LEVEL_MAX = 8
#: A control interval is at most this many base steps (a divisor of the output interval).
MAX_SEGMENT_STEPS = 16
#: Rows of the record of intervals accepted at the finest level.
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
        """The driver: the controlled or the fixed-step event loop."""
        return run_controlled if self.controlled else run_hybrid


METHODS: dict[str, Method] = {}


def register(method: Method) -> Method:
    METHODS[method.name] = method
    return method


# seconds_per_step: the 10 s sines at 200 N took 9.1 s for 1e5 base steps with the
# tip mass and 16.3 s for 1.6e5 without at the default tolerance; fixed RK4 about
# 2e-5 s per step on contact-rich runs (docs/performance.md).
register(Method("controlled", RK4, True,
                "RK4 on the output lattice, steps dt/2^k chosen by step doubling against tol",
                seconds_per_step=1e-4))
register(Method("rk4", RK4, False, "fixed-step RK4 (dt as given, or the stability step)",
                seconds_per_step=2e-5))

DEFAULT_METHOD = "controlled"


def segment_steps(decim: int, n_steps: int) -> int:
    """Base steps per control interval: the largest divisor of decim and n_steps up to MAX_SEGMENT_STEPS."""
    for seg in range(min(MAX_SEGMENT_STEPS, decim), 0, -1):
        if decim % seg == 0 and n_steps % seg == 0:
            return seg
    return 1
