"""The step method as a part you can swap (workbench/model/tableaus.py, workbench/model/methods.py).

An explicit Runge-Kutta method is a tableau and one ``register`` call: the
fixed-step and the controlled drivers, the event location and the
controller's Richardson factor all take it from the model's parameter
array, with no kernel of its own.  Tested with two textbook tableaus that
are not registered by the package: Kutta's third-order method and the 3/8
rule (Hairer, Norsett & Wanner, Solving ODE I, Table II.1.1 and II.1.2).
"""
from __future__ import annotations

import numpy as np
import pytest

from workbench.core import layout as ly
from workbench.model import drives, methods
from workbench.model.packing import build
from workbench.model.params import Parameters
from workbench.model.simulate import simulate
from workbench.model.tableaus import RK4, Tableau, write_tableau

KUTTA3 = Tableau("kutta3", c=(0.0, 0.5, 1.0), a=((), (0.5,), (-1.0, 2.0)),
                 b=(1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0), order=3,
                 source="Kutta (1901); Hairer, Norsett & Wanner, Table II.1.1")
RULE38 = Tableau("rule38", c=(0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0),
                 a=((), (1.0 / 3.0,), (-1.0 / 3.0, 1.0), (1.0, -1.0, 1.0)),
                 b=(1.0 / 8.0, 3.0 / 8.0, 3.0 / 8.0, 1.0 / 8.0), order=4,
                 source="Kutta (1901); Hairer, Norsett & Wanner, Table II.1.2")
JOINT_HELD = ("s", "v", "psi")


@pytest.fixture
def registered(monkeypatch):
    """Kutta's third-order method and the 3/8 rule, fixed-step and controlled."""
    for tableau in (KUTTA3, RULE38):
        for name, controlled in ((tableau.name, False), (f"{tableau.name}_controlled", True)):
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


def test_the_controller_takes_the_order_of_the_tableau(registered):
    """Step doubling over the same 0.1 ms control intervals: the estimate of the pair
    (dt, dt/2) over that of (dt/2, dt/4) is 2^3 for Kutta's third-order method, whose
    Richardson factor the controller takes from the tableau (2^3 - 1)."""
    est = [simulate(Parameters(), drives.sine(100.0, 20.0), 0.05, dt=dt, tol=1e-3, level_max=1,
                    method="kutta3_controlled", fixed=JOINT_HELD, initial="paper",
                    output_hz=10000).control["error_over_tol_max"]
           for dt in (1e-4, 5e-5)]
    assert 7.0 < est[0] / est[1] < 9.0, est


def test_the_tableau_is_written_where_the_kernels_read_it():
    P = build(Parameters()).P
    assert P[ly.P_RK_STAGES] == 4 and P[ly.P_RK_ORDER] == 4          # pack writes RK4
    write_tableau(P, KUTTA3)
    m = ly.MAX_RK_STAGES
    assert P[ly.P_RK_STAGES] == 3 and P[ly.P_RK_ORDER] == 3
    assert list(P[ly.P_RK_C:ly.P_RK_C + m]) == [0.0, 0.5, 1.0, 0.0, 0.0, 0.0]
    assert list(P[ly.P_RK_B:ly.P_RK_B + 3]) == list(KUTTA3.b)
    np.testing.assert_array_equal(P[ly.P_RK_A:].reshape(m, m)[:3, :3], KUTTA3.matrix())
    assert not P[ly.P_RK_A:].reshape(m, m)[3:].any()


def test_a_tableau_that_misses_its_order_is_refused():
    with pytest.raises(ValueError, match="misses an order-4 condition"):
        Tableau("bad", KUTTA3.c, KUTTA3.a, KUTTA3.b, order=4, source="")
    with pytest.raises(ValueError, match="c_i must equal"):
        Tableau("bad", (0.0, 0.4, 1.0), KUTTA3.a, KUTTA3.b, order=1, source="")
    with pytest.raises(ValueError, match="stages; the kernels take 1 to 6"):
        Tableau("bad", (0.0,) * 7, tuple((0.0,) * i for i in range(7)), (1.0,) + (0.0,) * 6,
                order=1, source="")
