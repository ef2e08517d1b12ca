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
conditions up to its order (checked up to order 5; Hairer, Norsett &
Wanner, Solving Ordinary Differential Equations I, 2nd ed., Table II.2.2).
An embedded pair (:class:`Pair`, :mod:`workbench.core.pair`) adds the error
weights e = b - bhat of its embedded solution (bhat checked to its order)
and its dense output's weights (equal to b at theta = 1), and is FSAL.
"""
from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from pathlib import Path

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
    (5, lambda b, c, a: b @ c ** 4, 1.0 / 5.0),
    (5, lambda b, c, a: (b * c ** 2) @ a @ c, 1.0 / 10.0),
    (5, lambda b, c, a: (b * c) @ a @ c ** 2, 1.0 / 15.0),
    (5, lambda b, c, a: (b * c) @ a @ a @ c, 1.0 / 30.0),
    (5, lambda b, c, a: b @ (a @ c) ** 2, 1.0 / 20.0),
    (5, lambda b, c, a: b @ a @ c ** 3, 1.0 / 20.0),
    (5, lambda b, c, a: b @ a @ (c * (a @ c)), 1.0 / 40.0),
    (5, lambda b, c, a: b @ a @ a @ c ** 2, 1.0 / 60.0),
    (5, lambda b, c, a: b @ a @ a @ a @ c, 1.0 / 120.0),
)
#: The largest order whose conditions are checked.
CHECKED_ORDER = 5
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
        if not 1 <= self.order:
            raise ValueError(f"tableau {self.name!r}: order {self.order}")
        b, c, a = np.array(self.b), np.array(self.c), self.matrix()
        if np.abs(a.sum(axis=1) - c).max() > _EPS:
            raise ValueError(f"tableau {self.name!r}: c_i must equal sum_j a_ij")
        _check_order(self.name, b, c, a, self.order)

    @property
    def stages(self) -> int:
        return len(self.b)

    def matrix(self) -> np.ndarray:
        """A as an (s, s) array."""
        a = np.zeros((self.stages, self.stages))
        for i, row in enumerate(self.a):
            a[i, :i] = row
        return a


def _check_order(name, b, c, a, order):
    """Butcher's conditions up to min(order, CHECKED_ORDER)."""
    for k, value, exact in _CONDITIONS:
        if k <= order and abs(value(b, c, a) - exact) > _EPS:
            raise ValueError(f"tableau {name!r} misses an order-{k} condition "
                             f"(sum {value(b, c, a):.15g}, needs {exact:.15g})")


@dataclass(frozen=True)
class Pair(Tableau):
    """An FSAL embedded pair with a dense output: ``e`` the error weights b - bhat,
    ``dense[i]`` the weights of k_i as coefficients of theta^1, theta^2, ..."""
    e: tuple[float, ...] = ()
    embedded_order: int = 0
    dense: tuple[tuple[float, ...], ...] = ()
    #: stages for the dense output only, after the step's: (c, (a_0 .. a_{r-1}))
    extra: tuple = ()
    #: a second error weight (DOP853's third-order one), or none
    e3: tuple[float, ...] = ()
    #: its steps are at most this many base steps (the step at which RK4 is stable): the
    #: ratio of its stability interval on the imaginary axis to RK4's (2.83), rounded down
    max_step_factor: float = 1.0

    def __post_init__(self):
        super().__post_init__()
        s = self.stages
        b, c, a = np.array(self.b), np.array(self.c), self.matrix()
        if len(self.e) != s or len(self.dense) != s + len(self.extra):
            raise ValueError(f"pair {self.name!r}: e needs {s} rows, dense {s + len(self.extra)}")
        if s + len(self.extra) > ly.MAX_RK_STAGES:
            raise ValueError(f"pair {self.name!r}: more than {ly.MAX_RK_STAGES} stages")
        degree = len(self.dense[0])
        if not 1 <= degree <= ly.MAX_DENSE_DEGREE or any(len(r) != degree for r in self.dense):
            raise ValueError(f"pair {self.name!r}: dense weights of one degree, 1 to "
                             f"{ly.MAX_DENSE_DEGREE}")
        if b[-1] != 0.0 or c[-1] != 1.0 or np.abs(a[-1, :-1] - b[:-1]).max() > _EPS:
            raise ValueError(f"pair {self.name!r}: the last stage must be f(t + h, y_new) (FSAL)")
        _check_order(self.name, b - np.array(self.e), c, a, self.embedded_order)
        at_one = np.sum(self.dense, axis=1)
        if np.abs(at_one[:s] - b).max() > _EPS or np.abs(at_one[s:]).max(initial=0.0) > _EPS:
            raise ValueError(f"pair {self.name!r}: the dense weights must equal b at theta = 1")

    @property
    def degree(self) -> int:
        return len(self.dense[0])


def write_tableau(P: np.ndarray, tableau: Tableau) -> None:
    """Put ``tableau`` into the parameter array P at layout ``P_RK_*``."""
    m = ly.MAX_RK_STAGES
    P[ly.P_RK_STAGES:ly.N_RK_END] = 0.0
    P[ly.P_RK_STAGES] = tableau.stages
    P[ly.P_RK_ORDER] = tableau.order
    for i in range(tableau.stages):
        P[ly.P_RK_C + i] = tableau.c[i]
        P[ly.P_RK_B + i] = tableau.b[i]
        for j, a_ij in enumerate(tableau.a[i]):
            P[ly.P_RK_A + m * i + j] = a_ij
    if isinstance(tableau, Pair):
        P[ly.P_RK_DEGREE] = tableau.degree
        P[ly.P_RK_EXTRA] = len(tableau.extra)
        P[ly.P_RK_STEP_FACTOR] = tableau.max_step_factor
        for i in range(tableau.stages):
            P[ly.P_RK_E + i] = tableau.e[i]
            if tableau.e3:
                P[ly.P_RK_E3 + i] = tableau.e3[i]
        for r, (c_r, row) in enumerate(tableau.extra, start=tableau.stages):
            P[ly.P_RK_C + r] = c_r
            for j, a_rj in enumerate(row):
                P[ly.P_RK_A + m * r + j] = a_rj
        for i, weights in enumerate(tableau.dense):
            for j, d in enumerate(weights):
                P[ly.P_RK_D + ly.MAX_DENSE_DEGREE * i + j] = d


#: Classical fourth-order Runge-Kutta (Kutta 1901; Hairer, Norsett & Wanner,
#: Table II.1.2, left).
RK4 = Tableau("rk4", c=(0.0, 0.5, 0.5, 1.0),
              a=((), (0.5,), (0.0, 0.5), (0.0, 0.0, 1.0)),
              b=(1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0), order=4,
              source="Kutta (1901); Hairer, Norsett & Wanner, Table II.1.2")


_DP5_B = (35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84)
#: Dormand & Prince 5(4) (J. R. Dormand, P. J. Prince, J. Comput. Appl. Math. 6, 1980; Hairer,
#: Norsett & Wanner, Table II.5.2) with Shampine's dense output of order 4 (Math. Comp. 46,
#: 1986; the coefficients as in scipy's integrate/_ivp/rk.py, RK45.P).
DOPRI5 = Pair(
    "dopri5", c=(0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0),
    a=((), (1 / 5,), (3 / 40, 9 / 40), (44 / 45, -56 / 15, 32 / 9),
       (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729),
       (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656), _DP5_B),
    b=_DP5_B + (0.0,), order=5,
    source="Dormand & Prince (1980); Shampine (1986); Hairer, Norsett & Wanner, Table II.5.2",
    e=(71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40),
    embedded_order=4,
    dense=((1.0, -8048581381 / 2820520608, 8663915743 / 2820520608,
            -12715105075 / 11282082432),
           (0.0, 0.0, 0.0, 0.0),
           (0.0, 131558114200 / 32700410799, -68118460800 / 10900136933,
            87487479700 / 32700410799),
           (0.0, -1754552775 / 470086768, 14199869525 / 1410260304,
            -10690763975 / 1880347072),
           (0.0, 127303824393 / 49829197408, -318862633887 / 49829197408,
            701980252875 / 199316789632),
           (0.0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844),
           (0.0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423)))


def dop853_from_scipy() -> Pair:
    """Dormand & Prince's 8(5,3) with its dense output of order 7 (Hairer, Norsett & Wanner I,
    §II.10), from the coefficients of scipy's integrate/_ivp/dop853_coefficients.py.

    scipy writes the interpolant as y0 + x (F0 + (1 - x)(F1 + x (F2 + ...))) with F0 = dy,
    F1 = h k1 - dy, F2 = 2 dy - h (k_new + k1), F3..F6 = h D k; here it is expanded into each
    stage's weight as a polynomial in theta.  The estimate is DOP853's: per component
    e5^2 / sqrt(e5^2 + 0.01 e3^2) (workbench.core.pair).
    """
    from numpy.polynomial import polynomial as poly
    from scipy.integrate._ivp import dop853_coefficients as k
    s = k.N_STAGES + 1                   # 12 stages and f(t + h, y_new)
    a = tuple(tuple(float(x) for x in k.A[i, :i]) for i in range(s))
    b = tuple(float(x) for x in k.B) + (0.0,)
    extra = tuple((float(k.C[r]), tuple(float(x) for x in k.A[r, :r]))
                  for r in range(s, k.N_STAGES_EXTENDED))
    n = k.N_STAGES_EXTENDED
    x, one_minus = np.array([0.0, 1.0]), np.array([1.0, -1.0])
    phi = [x, poly.polymul(x, one_minus)]
    for j in range(2, k.INTERPOLATOR_POWER):
        phi.append(poly.polymul(phi[-1], x if j % 2 == 0 else one_minus))
    bb = np.zeros(n)
    bb[:s] = b
    unit = np.eye(n)
    weights = [bb, unit[0] - bb, 2 * bb - unit[s - 1] - unit[0], *k.D]
    dense = np.zeros((n, k.INTERPOLATOR_POWER))
    for f, w in zip(phi, weights):
        coeffs = np.zeros(k.INTERPOLATOR_POWER + 1)
        coeffs[:len(f)] = f
        dense += np.outer(w, coeffs[1:])
    return Pair("dop853", c=tuple(float(x) for x in k.C[:s]), a=a, b=b, order=8,
                source=DOP853_SOURCE, e=tuple(float(x) for x in k.E5), embedded_order=5,
                dense=tuple(tuple(float(v) for v in r) for r in dense), extra=extra,
                e3=tuple(float(x) for x in k.E3), max_step_factor=2.0)


DOP853_SOURCE = ("Dormand & Prince 8(5,3) with its dense output of order 7; Hairer, Norsett & "
                 "Wanner I, §II.10; coefficients as scipy's integrate/_ivp/dop853_coefficients.py")
#: DOP853's coefficients, written by ``python -m workbench.model.tableaus`` from scipy's (read at
#: import they would cost every process scipy.integrate's 0.35 s); tests/model/test_methods.py
#: checks them against scipy's.
DOP853_FILE = Path(__file__).with_name("dop853.json")


def _pair_from_file(path: Path) -> Pair:
    data = json.loads(path.read_text())
    def tuples(x):
        return tuple(tuples(v) for v in x) if isinstance(x, list) else x
    return Pair(**{key: tuples(value) for key, value in data.items()})


DOP853 = _pair_from_file(DOP853_FILE)

if __name__ == "__main__":
    DOP853_FILE.write_text(json.dumps(dataclasses.asdict(dop853_from_scipy())) + "\n")
