"""The step method as a part you can swap (workbench/model/tableaus.py, workbench/model/methods.py).

An explicit Runge-Kutta method is a tableau (fixed steps) or an embedded
pair (controlled steps) and one ``register`` call: the drivers, the event
location, the error estimate and the dense output all take it from the
model's parameter array, with no kernel of its own.  Tested with textbook
methods that are not registered by the package: Kutta's third-order method
and the 3/8 rule (Hairer, Norsett & Wanner, Solving ODE I, Table II.1.1 and
II.1.2), and Bogacki & Shampine's 3(2) pair with its cubic Hermite dense
output (Appl. Math. Lett. 2, 1989).
"""
from __future__ import annotations

import numpy as np
import pytest

from workbench.core import layout as ly
from workbench.model import drives, methods
from workbench.model.packing import build
from workbench.model.params import Parameters
from workbench.model.simulate import simulate
from workbench.model.tableaus import DOP853, DOPRI5, RK4, Pair, Tableau, write_tableau

KUTTA3 = Tableau("kutta3", c=(0.0, 0.5, 1.0), a=((), (0.5,), (-1.0, 2.0)),
                 b=(1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0), order=3,
                 source="Kutta (1901); Hairer, Norsett & Wanner, Table II.1.1")
RULE38 = Tableau("rule38", c=(0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0),
                 a=((), (1.0 / 3.0,), (-1.0 / 3.0, 1.0), (1.0, -1.0, 1.0)),
                 b=(1.0 / 8.0, 3.0 / 8.0, 3.0 / 8.0, 1.0 / 8.0), order=4,
                 source="Kutta (1901); Hairer, Norsett & Wanner, Table II.1.2")
_BS3_B = (2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0, 0.0)
#: Bogacki-Shampine 3(2), FSAL; its dense output the cubic Hermite interpolant of the step's
#: ends and slopes, y0 + h [(3 th^2 - 2 th^3) sum b_i k_i + (th - 2 th^2 + th^3) k1 + (th^3 - th^2) k4].
BS3 = Pair("bs3", c=(0.0, 0.5, 0.75, 1.0), a=((), (0.5,), (0.0, 0.75), _BS3_B[:3]), b=_BS3_B,
           order=3, source="Bogacki & Shampine (1989)",
           e=(2 / 9 - 7 / 24, 1 / 3 - 1 / 4, 4 / 9 - 1 / 3, -1 / 8), embedded_order=2,
           dense=tuple(((1.0 if i == 0 else 0.0), 3 * b - (2.0 if i == 0 else 1.0 if i == 3 else 0.0),
                        -2 * b + (1.0 if i in (0, 3) else 0.0)) for i, b in enumerate(_BS3_B)))
JOINT_HELD = ("s", "v", "psi")


@pytest.fixture
def registered(monkeypatch):
    """Kutta's third-order method and the 3/8 rule (fixed steps), the BS3 pair (controlled)."""
    for name, tableau, controlled in (("kutta3", KUTTA3, False), ("rule38", RULE38, False),
                                      ("bs3", BS3, True)):
        monkeypatch.delitem(methods.METHODS, name, raising=False)   # undone after the test
        methods.register(methods.Method(name, tableau, controlled, tableau.name, 1e-4))


def tip_after(method, dt, duration=0.02):
    run = simulate(Parameters(), drives.sine(100.0, 20.0), duration, dt=dt, method=method,
                   fixed=JOINT_HELD, initial="paper", output_hz=1.0 / (4 * dt))
    assert run.status == ly.OK
    return run.states[-1, :ly.N_DOF]


@pytest.mark.parametrize("tableau", [KUTTA3, RULE38, RK4], ids=lambda t: t.name)
def test_a_registered_tableau_runs_at_its_own_order(registered, tableau):
    """Fixed steps through the event loop's driver: the slope of log error against log step
    is the tableau's order (the joint held, a 20 Hz sine, 20 ms)."""
    name = "rk4" if tableau is RK4 else tableau.name
    fine = tip_after(name, 2.5e-6)
    steps = np.array([4e-5, 2e-5, 1e-5])
    errors = [np.max(np.abs(tip_after(name, dt) - fine)) for dt in steps]
    slope = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert abs(slope - tableau.order) < 0.3, (slope, errors)


@pytest.mark.parametrize("name, local_order", [("bs3", 3), ("dopri5", 5)])
def test_the_controller_takes_the_estimate_of_the_pair(registered, name, local_order):
    """Steps held at dt (level_max 0: every step is the smallest), smooth motion: the
    embedded estimate is the local error of the pair's lower order, O(dt^(phat + 1)), so
    halving dt divides it by 2^3 for BS3 (2) and 2^5 for Dormand-Prince (4)."""
    est = [simulate(Parameters(), drives.sine(100.0, 20.0), 0.02, dt=dt, tol=1e-3, level_max=0,
                    method=name, fixed=JOINT_HELD, initial="paper",
                    output_hz=1.0 / dt).control["error_over_tol_max"]
           for dt in (1e-4, 5e-5)]
    ratio = est[0] / est[1]
    assert 0.75 * 2 ** local_order < ratio < 1.3 * 2 ** local_order, est


def test_a_pair_that_misses_its_conditions_is_refused():
    with pytest.raises(ValueError, match="misses an order-2 condition"):
        Pair("bad", BS3.c, BS3.a, BS3.b, order=3, source="", e=(0.1, 0.0, 0.0, -0.1),
             embedded_order=2, dense=BS3.dense)
    with pytest.raises(ValueError, match="must equal b at theta = 1"):
        Pair("bad", BS3.c, BS3.a, BS3.b, order=3, source="", e=BS3.e, embedded_order=2,
             dense=((1.0, 0.0, 0.0),) + BS3.dense[1:])
    with pytest.raises(ValueError, match="a controlled method steps with an embedded pair"):
        methods.Method("bad", RK4, True, "", 1e-4)
    assert DOPRI5.order == 5 and DOPRI5.embedded_order == 4 and DOPRI5.degree == 4


def test_the_tableau_is_written_where_the_kernels_read_it():
    P = build(Parameters()).P
    assert P[ly.P_RK_STAGES] == 4 and P[ly.P_RK_ORDER] == 4          # pack writes RK4
    write_tableau(P, KUTTA3)
    m = ly.MAX_RK_STAGES
    assert P[ly.P_RK_STAGES] == 3 and P[ly.P_RK_ORDER] == 3
    assert list(P[ly.P_RK_C:ly.P_RK_C + m]) == [0.0, 0.5, 1.0] + [0.0] * (m - 3)
    assert list(P[ly.P_RK_B:ly.P_RK_B + 3]) == list(KUTTA3.b)
    np.testing.assert_array_equal(P[ly.P_RK_A:ly.P_RK_E].reshape(m, m)[:3, :3], KUTTA3.matrix())
    assert not P[ly.P_RK_A:ly.P_RK_E].reshape(m, m)[3:].any()
    assert not P[ly.P_RK_E:ly.N_RK_END].any()        # no error weights, no dense output
    write_tableau(P, DOPRI5)
    assert P[ly.P_RK_DEGREE] == 4 and list(P[ly.P_RK_E:ly.P_RK_E + 7]) == list(DOPRI5.e)


def test_a_tableau_that_misses_its_order_is_refused():
    with pytest.raises(ValueError, match="misses an order-4 condition"):
        Tableau("bad", KUTTA3.c, KUTTA3.a, KUTTA3.b, order=4, source="")
    with pytest.raises(ValueError, match="c_i must equal"):
        Tableau("bad", (0.0, 0.4, 1.0), KUTTA3.a, KUTTA3.b, order=1, source="")
    with pytest.raises(ValueError, match="stages; the kernels take 1 to 16"):
        Tableau("bad", (0.0,) * 17, tuple((0.0,) * i for i in range(17)), (1.0,) + (0.0,) * 16,
                order=1, source="")


def test_dop853s_coefficients_are_scipys():
    """The file the package reads DOP853 from (workbench/model/dop853.json) holds scipy's
    coefficients, its dense output expanded per stage; the pair meets the order conditions
    (to 5, checked when made) and its dense output equals scipy's interpolant."""
    from scipy.integrate import DOP853 as ScipyDOP853

    from workbench.model.tableaus import dop853_from_scipy
    assert DOP853 == dop853_from_scipy()
    # y' = [y1, -y0] one step of 0.3: the dense output at 0.37 against scipy's
    solver = ScipyDOP853(lambda t, y: np.array([y[1], -y[0]]), 0.0, np.array([1.0, 0.0]), 1.0,
                         first_step=0.3, max_step=0.3, rtol=1e-3, atol=1e-6)
    solver.step()
    h = solver.t - solver.t_old
    interp = solver.dense_output()          # computes the three extra stages
    k = np.array(solver.K_extended)
    d = np.array(DOP853.dense)
    theta = 0.37
    ours = np.array([1.0, 0.0]) + h * (k.T @ (d @ theta ** np.arange(1, d.shape[1] + 1)))
    np.testing.assert_allclose(ours, interp(solver.t_old + theta * h), rtol=0, atol=1e-14)


@pytest.mark.parametrize("tableau, interval", [(RK4, 2.83), (DOP853, 5.96)], ids=lambda t: str(t))
def test_a_pairs_largest_step_stays_inside_its_stability_interval(tableau, interval):
    """|R(iy)| <= 1 up to the stability interval on the imaginary axis (where the beams'
    lightly damped axial modes sit): RK4's 2.83 sets the base step, and a pair's steps go
    up to max_step_factor base steps only inside its own (DOP853: 5.96 = 2.1 x RK4's)."""
    a, b = tableau.matrix(), np.array(tableau.b)
    s = len(b)

    def r(y):
        return abs(1 + 1j * y * b @ np.linalg.solve(np.eye(s) - 1j * y * a, np.ones(s)))
    assert all(r(y) <= 1 + 1e-12 for y in np.linspace(0.01, interval - 0.01, 400))
    assert r(interval + 0.05) > 1
    factor = getattr(tableau, "max_step_factor", 1.0)
    assert factor * 2.83 <= interval


@pytest.mark.parametrize("pair, order", [(DOPRI5, 4), (DOP853, 7)], ids=lambda p: str(p))
def test_a_pairs_dense_output_has_its_order(pair, order):
    """y' = i y from y(0) = 1: one step of h, the dense output at theta = 0.4 against
    exp(0.4 i h); the local error of an interpolant of order p is O(h^(p+1)) (the extra
    stages, after the step's, evaluated as the step's are)."""
    a = np.zeros((pair.stages + len(pair.extra),) * 2)
    a[:pair.stages, :pair.stages] = pair.matrix()
    for r, (_, row) in enumerate(pair.extra, start=pair.stages):
        a[r, :r] = row
    d = np.array(pair.dense)
    errors = []
    hs = np.array([0.4, 0.2, 0.1]) if order > 5 else np.array([0.1, 0.05, 0.025])
    for h in hs:
        k = np.zeros(len(a), dtype=complex)
        for i in range(len(a)):
            k[i] = 1j * (1.0 + h * a[i, :i] @ k[:i])
        theta = 0.4
        y = 1.0 + h * k @ (d @ theta ** np.arange(1, d.shape[1] + 1))
        errors.append(abs(y - np.exp(1j * theta * h)))
    slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert abs(slope - (order + 1)) < 0.3, (slope, errors)
