"""Explicit Runge-Kutta tableaus: the step methods the integrators take.

A tableau is Butcher's (c, A, b) and its order p: a step of dt with s stages
advances y by dt sum_i b_i k_i, k_i = f(t + c_i dt, y + dt sum_{j<i} a_ij k_j).
:func:`write_tableau` puts it into the parameter array at layout ``P_RK_*``,
where :func:`workbench.core.integrate.rk_step` reads it: every integrator
(fixed steps, the error-controlled steps, free flight, the partial steps
that locate events) steps with the tableau of its model, so a new tableau
needs no new kernel and no compile.  A method of
:mod:`workbench.model.methods` names its tableau.

Each tableau is checked when it is made: at most MAX_RK_STAGES stages,
strictly lower-triangular A, c_i = sum_j a_ij, and Butcher's order
conditions up to its order (checked up to order 4; Hairer, Norsett &
Wanner, Solving Ordinary Differential Equations I, 2nd ed., Table II.2.2).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core import layout as ly

#: Butcher's order conditions up to order 4, as (order, the sum as a
#: function of (b, c, A), its value).
_CONDITIONS = (
    (1, lambda b, c, a: b.sum(), 1.0),
    (2, lambda b, c, a: b @ c, 1.0 / 2.0),
    (3, lambda b, c, a: b @ c ** 2, 1.0 / 3.0),
    (3, lambda b, c, a: b @ a @ c, 1.0 / 6.0),
    (4, lambda b, c, a: b @ c ** 3, 1.0 / 4.0),
    (4, lambda b, c, a: (b * c) @ a @ c, 1.0 / 8.0),
    (4, lambda b, c, a: b @ a @ c ** 2, 1.0 / 12.0),
    (4, lambda b, c, a: b @ a @ a @ c, 1.0 / 24.0),
)
#: The largest order whose conditions are checked.
CHECKED_ORDER = 4
#: Tolerance of the checks (the coefficients are rounded to doubles).
_EPS = 1e-13


@dataclass(frozen=True)
class Tableau:
    """An explicit Runge-Kutta method: ``a[i]`` holds a_i0 .. a_i,i-1 (row 0 is empty)."""
    name: str
    c: tuple[float, ...]
    a: tuple[tuple[float, ...], ...]
    b: tuple[float, ...]
    order: int
    source: str

    def __post_init__(self):
        s = len(self.b)
        if not 1 <= s <= ly.MAX_RK_STAGES:
            raise ValueError(f"tableau {self.name!r}: {s} stages; the kernels take 1 to "
                             f"{ly.MAX_RK_STAGES}")
        if len(self.c) != s or len(self.a) != s or any(len(row) != i
                                                        for i, row in enumerate(self.a)):
            raise ValueError(f"tableau {self.name!r}: c needs {s} nodes and a row i needs i "
                             f"coefficients (explicit, strictly lower-triangular A)")
        if not 1 <= self.order <= CHECKED_ORDER:
            raise ValueError(f"tableau {self.name!r}: order {self.order}; orders 1 to "
                             f"{CHECKED_ORDER} are checked and taken")
        b, c, a = np.array(self.b), np.array(self.c), self.matrix()
        if np.abs(a.sum(axis=1) - c).max() > _EPS:
            raise ValueError(f"tableau {self.name!r}: c_i must equal sum_j a_ij")
        for order, value, exact in _CONDITIONS:
            if order <= self.order and abs(value(b, c, a) - exact) > _EPS:
                raise ValueError(f"tableau {self.name!r} misses an order-{order} condition "
                                 f"(sum {value(b, c, a):.15g}, needs {exact:.15g})")

    @property
    def stages(self) -> int:
        return len(self.b)

    def matrix(self) -> np.ndarray:
        """A as an (s, s) array."""
        a = np.zeros((self.stages, self.stages))
        for i, row in enumerate(self.a):
            a[i, :i] = row
        return a


def write_tableau(P: np.ndarray, tableau: Tableau) -> None:
    """Put ``tableau`` into the parameter array P at layout ``P_RK_*``."""
    m = ly.MAX_RK_STAGES
    P[ly.P_RK_STAGES:ly.P_RK_A + m * m] = 0.0
    P[ly.P_RK_STAGES] = tableau.stages
    P[ly.P_RK_ORDER] = tableau.order
    for i in range(tableau.stages):
        P[ly.P_RK_C + i] = tableau.c[i]
        P[ly.P_RK_B + i] = tableau.b[i]
        for j, a_ij in enumerate(tableau.a[i]):
            P[ly.P_RK_A + m * i + j] = a_ij


#: Classical fourth-order Runge-Kutta (Kutta 1901; Hairer, Norsett & Wanner,
#: Table II.1.2, left).
RK4 = Tableau("rk4", c=(0.0, 0.5, 0.5, 1.0),
              a=((), (0.5,), (0.0, 0.5), (0.0, 0.0, 1.0)),
              b=(1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0), order=4,
              source="Kutta (1901); Hairer, Norsett & Wanner, Table II.1.2")
