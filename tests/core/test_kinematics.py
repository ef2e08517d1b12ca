"""Kinematics: every Jacobian and convective term against finite differences.

For each mass element the kernel returns r(q), J = dr/dq, kappa = J' q'
(the acceleration with q'' = 0) and the angle row a.  Central differences
with step h = 1e-6 (cm or rad): truncation ~h^2 and round-off ~1e-16 |r| / h,
both far below the tolerance relative to the largest lever arm.
"""
import numba as nb
import numpy as np
import pytest
from conftest import random_state

from workbench.model import packing as mdl
from workbench.core import layout as ly
from workbench.core.kinematics import SMALL_ANGLE, cos_sin, element_kinematics
from workbench.core.shapes import fill_shape_row
from workbench.model.params import Parameters


def kinematics(model, q, qd):
    n = 2 * int(model.P[ly.P_N_GAUSS]) + 3
    out = dict(r=np.zeros((n, 2)), J=np.zeros((n, 2, 9)), kap=np.zeros((n, 2)), a=np.zeros((n, 9)),
               mass=np.zeros(n), rot=np.zeros(n), angle=np.zeros(n))
    work = mdl.make_work()
    element_kinematics(q, qd, model.P, model.tab, work.rec, out["r"], out["J"], out["kap"],
                       out["a"], out["mass"], out["rot"], out["angle"])
    return out


@pytest.mark.parametrize("seed", range(5))
def test_jacobians_and_angle_rows_by_central_differences(params, seed):
    model = mdl.build(params)
    y = random_state(np.random.default_rng(seed))
    q, qd = y[:9], y[9:]
    k0 = kinematics(model, q, qd)
    scale = np.max(np.abs(k0["J"]))
    assert scale > 10.0          # lever arms of tens of cm: the check is not vacuous
    for j in range(9):
        h = 1e-6                 # cm or rad
        dq = np.zeros(9)
        dq[j] = h
        kp, km = kinematics(model, q + dq, qd), kinematics(model, q - dq, qd)
        dr = (kp["r"] - km["r"]) / (2 * h)
        np.testing.assert_allclose(k0["J"][:, :, j], dr, rtol=1e-6, atol=1e-7 * scale)
        np.testing.assert_allclose(k0["a"][:, j], (kp["angle"] - km["angle"]) / (2 * h), atol=1e-8)


@pytest.mark.parametrize("seed", range(5))
def test_convective_terms_by_differentiating_j_along_the_motion(params, seed):
    # kappa = d/dt (J(q) q') at fixed q' = lim (J(q + e q') - J(q - e q')) q' / (2e)
    model = mdl.build(params)
    y = random_state(np.random.default_rng(100 + seed))
    q, qd = y[:9], y[9:]
    k0 = kinematics(model, q, qd)
    eps = 1e-7
    jp = kinematics(model, q + eps * qd, qd)["J"]
    jm = kinematics(model, q - eps * qd, qd)["J"]
    fd = np.einsum("kij,j->ki", (jp - jm) / (2 * eps), qd)
    scale = np.max(np.abs(fd))
    np.testing.assert_allclose(k0["kap"], fd, atol=1e-6 * scale)


def test_undeformed_positions_follow_the_drawing():
    p = Parameters()
    k = kinematics(mdl.build(p), np.zeros(9), np.zeros(9))
    ng = p.n_gauss
    assert k["r"][ng] == pytest.approx([p.l_a + p.c3, 0.0])                 # joint body CM
    assert k["r"][ng + 1] == pytest.approx([p.l_a + p.x_in + p.loose_cm, 0.0])
    assert k["r"][-1] == pytest.approx([p.l_a + p.x_in + p.l4 + p.l_b, 0.0])  # tip mass
    assert k["mass"].sum() == pytest.approx(p.mu_a * p.l_a + p.m3 + p.m4 + p.mu_b * p.l_b + p.m6)


def test_rigid_rotation_of_the_joint_moves_the_tip_on_a_circle():
    # phi_A alone with w_A = 0 rotates everything outboard about beam A's tip
    p = Parameters()
    q = np.zeros(9)
    q[ly.PHI_A] = 0.3
    k = kinematics(mdl.build(p), q, np.zeros(9))
    # beam A's foreshortening by phi alone: f = 1/2 Sigma_11(L) phi^2 = L phi^2 / 15
    tip_a = np.array([p.l_a - p.l_a * 0.3 ** 2 / 15, 0.0])
    arm = p.x_in + p.l4 + p.l_b
    np.testing.assert_allclose(k["r"][-1], tip_a + arm * np.array([np.cos(0.3), np.sin(0.3)]), rtol=1e-12)


def test_shape_rows_derivatives_and_foreshortening_integral():
    L = 33.0
    rows = {}
    for xi in (0.3, 0.3 + 1e-6, 0.3 - 1e-6, 1.0):
        r = np.zeros(ly.N_TAB)
        fill_shape_row(xi, L, 0.0, r)
        rows[xi] = r
    h = 1e-6 * L
    for f, df in ((ly.T_N1, ly.T_DN1), (ly.T_N2, ly.T_DN2), (ly.T_DN1, ly.T_DDN1), (ly.T_DN2, ly.T_DDN2)):
        assert rows[0.3][df] == pytest.approx((rows[0.3 + 1e-6][f] - rows[0.3 - 1e-6][f]) / (2 * h), rel=1e-7)
    # dSigma/dx = n' n'^T
    r = rows[0.3]
    dsig = [(rows[0.3 + 1e-6][c] - rows[0.3 - 1e-6][c]) / (2 * h) for c in (ly.T_S00, ly.T_S01, ly.T_S11)]
    assert dsig == pytest.approx([r[ly.T_DN1] ** 2, r[ly.T_DN1] * r[ly.T_DN2], r[ly.T_DN2] ** 2], rel=1e-7)
    # tip values: the cubic element's geometric stiffness 6/(5L), -1/10, 2L/15
    t = rows[1.0]
    assert (t[ly.T_S00], t[ly.T_S01], t[ly.T_S11]) == pytest.approx((6 / (5 * L), -0.1, 2 * L / 15))
    assert (t[ly.T_N1], t[ly.T_N2], t[ly.T_DN1], t[ly.T_DN2]) == pytest.approx((1, 0, 0, 1), abs=1e-14)


@nb.njit
def _cos_sin_all(x, c, s):
    for i in range(x.size):
        c[i], s[i] = cos_sin(x[i])


def test_small_angle_cosine_and_sine_within_an_ulp_of_libm():
    rng = np.random.default_rng(3)
    tiny = np.geomspace(1e-300, SMALL_ANGLE, 2000)
    x = np.concatenate([np.linspace(-SMALL_ANGLE, SMALL_ANGLE, 100_001),
                        rng.uniform(-SMALL_ANGLE, SMALL_ANGLE, 100_000), tiny, -tiny, [0.0, -0.0],
                        [0.3, -0.7, 2.0, 3.1, -40.0]])
    c, s = np.empty_like(x), np.empty_like(x)
    _cos_sin_all(x, c, s)
    assert np.all(np.abs(c - np.cos(x)) <= np.spacing(np.abs(np.cos(x))))
    assert np.all(np.abs(s - np.sin(x)) <= np.spacing(np.abs(np.sin(x))))
    big = np.abs(x) > SMALL_ANGLE                       # libm's own values
    assert big.sum() == 5 and np.array_equal(c[big], np.cos(x[big]))
    assert np.array_equal(s[big], np.sin(x[big]))
    assert (c == np.cos(x)).mean() > 0.98 and (s == np.sin(x)).mean() > 0.98
