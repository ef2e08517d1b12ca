"""Equations of motion: mass matrix, energy, convergence order, reference.

Tiers (STYLE.md): numerical properties (M symmetric positive definite,
energy conserved, RK4's order 4), and a slow independent reference
(workbench/reference/equations.py: jets for every derivative, numpy.linalg.solve,
scipy's solve_ivp).
"""
import numpy as np
import pytest
from conftest import random_state
from workbench.reference import Reference

from workbench.model import packing as mdl
from workbench.core import layout as ly
from workbench.core.dynamics import energies, eval_inertia, eval_rhs
from workbench.model.drives import sine
from workbench.model.freeflight import integrate
from workbench.model.params import ParameterError, Parameters

#: A conservative configuration: no damping, no forcing, no contact; the
#: joint coordinates free but held by springs (linear cork on s, k_v, k_psi).
CONSERVATIVE = dict(zeta_a=0.0, zeta_b=0.0, cork="linear", cork_c=0.0, k_v=2.0e6, k_psi=5.0e7)


def total_energy(model, y, work):
    out = np.zeros(4)
    energies(y, model, work, out)
    return out


@pytest.mark.parametrize("seed", range(10))
def test_mass_matrix_symmetric_positive_definite(params, seed):
    model, work = mdl.build(params), mdl.make_work()
    y = random_state(np.random.default_rng(seed))
    eval_inertia(y[:9], y[9:], model, work)
    M = work.mat[ly.MAT_M]
    np.testing.assert_array_equal(M, M.T)
    assert np.linalg.eigvalsh(M).min() > 0.0


@pytest.mark.parametrize("seed", range(4))
def test_kernel_agrees_with_the_jet_reference_pointwise(params, seed):
    p = params.replace(cork="cubic", k_v=1e6, k_psi=1e7)
    ex = sine(3.0, 25.0)
    ref = Reference(p, excitation=lambda t: 3.0e5 * np.sin(2 * np.pi * 25.0 * t))
    model, work = mdl.build(p), mdl.make_work()
    y = random_state(np.random.default_rng(seed))
    ydot = np.zeros(18)
    assert eval_rhs(0.0137, y, model, ex, work, ydot) == ly.OK
    expected = ref.rhs(0.0137, y)
    np.testing.assert_allclose(ydot, expected, rtol=1e-10, atol=1e-10 * np.abs(expected).max())
    # energies too
    e = total_energy(model, y, work)
    assert e.sum() == pytest.approx(ref.energy(y), rel=1e-12)


def test_gravity_force_is_minus_the_gradient_of_its_energy():
    p = Parameters()
    model, work = mdl.build(p), mdl.make_work()
    y = random_state(np.random.default_rng(7))
    q = y[:9]
    eval_inertia(q, np.zeros(9), model, work)
    Qg = work.vec[ly.VEC_Q].copy()
    grad = np.zeros(9)
    for j in range(9):
        dq = np.zeros(9)
        dq[j] = 1e-6
        vp = eval_inertia(q + dq, np.zeros(9), model, work)
        vm = eval_inertia(q - dq, np.zeros(9), model, work)
        grad[j] = (vp - vm) / 2e-6
    np.testing.assert_allclose(Qg, -grad, rtol=1e-6, atol=1e-6 * np.abs(grad).max())


@pytest.mark.parametrize("tip", [True, False])
def test_energy_conserved_in_large_free_motion(tip):
    p = Parameters(tip_mass=tip, **CONSERVATIVE)
    model, work = mdl.build(p), mdl.make_work()
    # tip deflected by several cm: w_A = 3 cm, phi_A = 0.12 rad, w_B = 2 cm (~11 cm at the tip)
    y0 = mdl.state(q={"w_A": 3.0, "phi_A": 0.12, "w_B": 2.0, "phi_B": 0.09, "s": 0.05, "v": 0.01,
                      "psi": 0.004})
    tr = integrate(model, y0, 0.5, 2.5e-6, 400)
    assert tr.status == ly.OK
    e = np.array([total_energy(model, y, work) for y in tr.y])
    total = e.sum(axis=1)
    exchanged = np.ptp(e[:, 0])          # kinetic energy swing: the scale of the motion
    assert exchanged > 1e5               # a large motion, not a resting state
    drift = np.max(np.abs(total - total[0])) / exchanged
    assert drift < 1e-7, drift


def test_rk4_converges_with_order_four():
    p = Parameters(**CONSERVATIVE)
    model = mdl.build(p)
    y0 = mdl.state(q={"w_A": 2.0, "phi_A": 0.08, "w_B": 1.5, "phi_B": 0.05, "v": 0.01})
    T = 0.02
    # steps in the asymptotic range: omega dt <= 0.2 for the ~2.6 kHz axial mode
    fine = integrate(model, y0, T, T / 51200, 51200).y[-1]
    steps = np.array([T / 1600, T / 3200, T / 6400, T / 12800])
    errors = [np.max(np.abs(integrate(model, y0, T, dt, round(T / dt)).y[-1] - fine)[:9]) for dt in steps]
    slope = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert abs(slope - 4.0) < 0.3, (slope, errors)


def test_held_coordinates_stay_put_and_moving_ones_move():
    p = Parameters()
    model = mdl.build(p, fixed=("s", "v", "psi", "u_A"))
    y0 = mdl.state(q={"w_A": 1.0, "s": 0.02, "v": -0.01, "psi": 0.003})
    tr = integrate(model, y0, 0.05, 1e-5, 100)
    assert tr.status == ly.OK
    for name in ("s", "v", "psi", "u_A"):
        i = mdl.coordinate_index(name)
        assert np.all(tr.q[:, i] == y0[i]) and np.all(tr.qd[:, i] == 0.0)
    assert np.ptp(tr.q[:, ly.W_A]) > 0.1


def test_held_coordinates_must_start_at_rest_and_inputs_are_checked():
    model = mdl.build(Parameters(), fixed=mdl.JOINT)
    with pytest.raises(ParameterError, match="zero velocity"):
        integrate(model, mdl.state(qd={"v": 1.0}), 0.01, 1e-5)
    with pytest.raises(ParameterError, match="dt"):
        integrate(model, mdl.state(), 0.01, -1e-5)
    with pytest.raises(ParameterError, match="whole number"):
        integrate(model, mdl.state(), 0.01, 3e-5)
    with pytest.raises(ParameterError, match="unknown coordinate"):
        mdl.build(Parameters(), fixed=("theta",))
    with pytest.raises(ParameterError, match="every coordinate"):
        mdl.build(Parameters(), fixed=range(9))


def test_runaway_state_is_reported_not_raised():
    # a step far beyond RK4's stability limit for the axial modes blows up: status, not exception
    tr = integrate(mdl.build(Parameters()), mdl.state(q={"u_A": 0.01}), 0.5, 1e-3, 1)
    # it ends either on a NaN state or on a mass matrix that lost definiteness
    assert tr.status in (ly.ERR_NAN, ly.ERR_SINGULAR_MASS)
    assert tr.message == ly.MESSAGES[tr.status]
    assert 1 <= len(tr.t) < 500 and np.all(np.isfinite(tr.y))


@pytest.mark.slow
@pytest.mark.parametrize("fixed, duration", [(("u_A", "u_B"), 0.2), ((), 0.01)],
                         ids=["bending-0.2s", "all-9-dof-0.01s"])
def test_trajectory_agrees_with_solve_ivp_reference(fixed, duration):
    # The pure-Python reference costs ~2.5 ms per evaluation; with the kHz
    # axial modes free, DOP853 needs ~7e5 evaluations per second of motion,
    # so the full 9-DOF comparison runs 0.01 s and the 0.2 s one holds u_A, u_B.
    p = Parameters(cork="linear", k_v=1e6, k_psi=1e7)
    ex = sine(5.0, 20.0)
    held = {mdl.coordinate_index(c) for c in fixed}
    ref = Reference(p, free=[i for i in range(9) if i not in held],
                    excitation=lambda t: 5.0e5 * np.sin(2 * np.pi * 20.0 * t))
    y0 = mdl.state(q={"w_A": 2.0, "phi_A": 0.08, "w_B": 1.5, "phi_B": 0.05, "v": 0.01, "psi": 0.004})
    tr = integrate(mdl.build(p, fixed=fixed), y0, duration, 1e-5, 100, ex)
    assert tr.status == ly.OK
    y_ref, _ = ref.integrate(y0, tr.t, rtol=1e-9, atol=1e-12)
    scale = np.max(np.abs(y_ref[:, :9]))
    assert np.max(np.abs(tr.q - y_ref[:, :9])) < 1e-6 * scale


@pytest.mark.parametrize("tip", [True, False])
@pytest.mark.parametrize("seed", range(3))
def test_frame_sums_equal_the_element_sums(seed, tip):
    """core/inertia.py regroups sum m J^T J + I a a^T, sum m J^T kappa and gravity by frame:
    equal to the sums over the elements (kinematics of tests/core/test_kinematics.py) to round-off."""
    from test_kinematics import kinematics

    p = Parameters(tip_mass=tip)
    model, work = mdl.build(p), mdl.make_work()
    y = random_state(np.random.default_rng(seed))
    v = eval_inertia(y[:9], y[9:], model, work)
    k = kinematics(model, y[:9], y[9:])
    m, J, a = k["mass"], k["J"], k["a"]
    M = np.einsum("k,kri,krj->ij", m, J, J) + np.einsum("k,ki,kj->ij", k["rot"], a, a)
    h = np.einsum("k,kri,kr->i", m, J, k["kap"])
    Q = -model.P[ly.P_GRAV] * np.einsum("k,ki->i", m, J[:, 1])
    np.testing.assert_allclose(work.mat[ly.MAT_M], M, rtol=1e-13, atol=1e-13 * np.abs(M).max())
    assert np.abs(h).max() > 0.0                      # a moving state: h is not trivially zero
    np.testing.assert_allclose(work.vec[ly.VEC_H], h, rtol=1e-12, atol=1e-12 * np.abs(h).max())
    np.testing.assert_allclose(work.vec[ly.VEC_Q], Q, rtol=1e-13, atol=1e-13 * np.abs(Q).max())
    assert v == pytest.approx(model.P[ly.P_GRAV] * np.dot(m, k["r"][:, 1]), rel=1e-13)
