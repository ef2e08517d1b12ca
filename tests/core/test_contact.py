"""Contact geometry (docs/model.md §7): hand-derived derivatives against finite differences."""
import numpy as np
import pytest

from workbench.model import packing as mdl
from workbench.core import layout as ly
from workbench.core.contact import eval_geometry
from workbench.model.params import Parameters

COLS = (ly.CG_DS, ly.CG_DV, ly.CG_DPSI)
HESS = {(0, 0): ly.CG_HSS, (0, 1): ly.CG_HSV, (0, 2): ly.CG_HSP, (1, 1): ly.CG_HVV,
        (1, 2): ly.CG_HVP, (2, 2): ly.CG_HPP}
JOINT = (ly.S, ly.V, ly.PSI)


def _geom(P, q):
    cg = np.zeros((2 * ly.N_POINTS, ly.N_CG))
    eval_geometry(q, P, cg)
    return cg


@pytest.mark.parametrize("seed", range(5))
def test_gradients_and_hessians_match_finite_differences(seed):
    rng = np.random.default_rng(seed)
    P = mdl.pack(Parameters())
    q = np.zeros(ly.N_DOF)
    q[list(JOINT)] = rng.normal(size=3) * (0.5, 0.05, 0.05)
    cg = _geom(P, q)
    h = 1e-6
    for i, ci in enumerate(JOINT):
        dq = np.zeros(ly.N_DOF)
        dq[ci] = h
        plus, minus = _geom(P, q + dq), _geom(P, q - dq)
        fd = (plus[:, ly.CG_VAL] - minus[:, ly.CG_VAL]) / (2 * h)
        np.testing.assert_allclose(cg[:, COLS[i]], fd, rtol=1e-7, atol=1e-9)
        for j in range(3):
            fd2 = (plus[:, COLS[j]] - minus[:, COLS[j]]) / (2 * h)
            np.testing.assert_allclose(cg[:, HESS[tuple(sorted((i, j)))]], fd2, rtol=1e-6, atol=1e-8)


def test_gaps_at_rest_and_rocking_closure():
    p = Parameters()
    P = mdl.pack(p)
    cg = _geom(P, np.zeros(ly.N_DOF))
    np.testing.assert_allclose(cg[ly.CG_G:ly.CG_G + 4, ly.CG_VAL], p.gap / 2, rtol=1e-12)
    # docs/model.md: with v = -gap/2, point 4 closes at psi ~ gap / D
    q = np.zeros(ly.N_DOF)
    q[ly.V] = -p.gap / 2
    D = p.x_lip - p.x_in
    q[ly.PSI] = p.gap / D
    g4 = _geom(P, q)[ly.CG_G + 3, ly.CG_VAL]
    assert abs(g4) < 0.01 * p.gap
    # corner geometry: gap 3 is the distance of the lip corner below the lower face
    rng = np.random.default_rng(1)
    for _ in range(5):
        s, v, psi = rng.normal(size=3) * (0.3, 0.02, 0.01)
        q = np.zeros(ly.N_DOF)
        q[[ly.S, ly.V, ly.PSI]] = s, v, psi
        cg = _geom(P, q)
        R = np.array([[np.cos(psi), -np.sin(psi)], [np.sin(psi), np.cos(psi)]])
        origin = np.array([p.x_in + s, v])
        H = p.h4 / 2 + p.gap / 2
        local3 = R.T @ (np.array([p.x_lip, -H]) - origin)
        np.testing.assert_allclose(cg[ly.CG_G + 2, ly.CG_VAL], -p.h4 / 2 - local3[1], atol=1e-13)
        np.testing.assert_allclose(cg[ly.CG_T + 2, ly.CG_VAL], -local3[0], atol=1e-13)
        corner1 = origin + R @ np.array([0.0, -p.h4 / 2])
        np.testing.assert_allclose(cg[ly.CG_G + 0, ly.CG_VAL], corner1[1] + H, atol=1e-13)


def test_two_point_contacts_have_rows_of_rank_three():
    """Every two-point contact the model can reach, over the slot's whole travel: the rows
    (n_i, t_i, n_j, t_j) on (s, v, psi) keep rank 3, so Moreau's law meets at most a
    one-dimensional null space of G there (rank 2 would need s = x_lip - x_in, beyond
    the travel).  Points 1 and 2 never close together: g1 + g2 = gap + h4 (1 - cos psi) > 0."""
    from scipy.optimize import brentq

    P = mdl.pack(Parameters())
    travel = P[ly.P_S_TRAVEL]
    smallest = {}
    for i, j in ((0, 2), (0, 3), (1, 2), (1, 3)):
        for s in np.linspace(-travel, travel, 9):
            # close point i at each tilt psi (its gap is linear in v), then find the tilt
            # that closes point j too
            def state(psi):
                q = np.zeros(ly.N_DOF)
                q[ly.S], q[ly.PSI] = s, psi
                cg = _geom(P, q)
                q[ly.V] -= cg[ly.CG_G + i, ly.CG_VAL] / cg[ly.CG_G + i, ly.CG_DV]
                return q

            def gap_j(psi):
                return _geom(P, state(psi))[ly.CG_G + j, ly.CG_VAL]

            psi = brentq(gap_j, -0.2, 0.2, xtol=1e-15)
            cg = _geom(P, state(psi))
            assert abs(cg[ly.CG_G + i, ly.CG_VAL]) < 1e-12 and abs(cg[ly.CG_G + j, ly.CG_VAL]) < 1e-12
            assert cg[ly.CG_G:ly.CG_G + ly.N_POINTS, ly.CG_VAL].min() > -1e-12
            W = cg[[ly.CG_G + i, ly.CG_T + i, ly.CG_G + j, ly.CG_T + j]][:, list(COLS)]
            sv = np.linalg.svd(W, compute_uv=False)
            smallest[(i, j)] = min(smallest.get((i, j), np.inf), sv[2] / sv[0])
    assert min(smallest.values()) > 0.1, smallest
