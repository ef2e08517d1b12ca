"""The regimes' accelerations and contact forces (workbench/core/constrained.py).

A sticking double contact whose rows lock the joint is solved by blocks
(``locked_joint_accelerations``); every other regime by the multipliers of
``add_contact_forces``.  Both solve M q'' = Q - h + A^T lambda, A q'' = -A' q',
so on the same state they must agree to round-off, also off the constraint
manifold (joint rates not zero), and the accelerations must satisfy the rows.
"""
import numpy as np
import pytest
from conftest import random_state

from workbench.model import packing as mdl
from workbench.core import layout as ly
from workbench.core.config import TINY_STATE
from workbench.core.constrained import add_contact_forces, joint_locked, project, rhs_regime
from workbench.core.contact import eval_geometry, row_convective
from workbench.core.dynamics import rhs
from workbench.model.drives import sine
from workbench.model.params import Parameters

DOUBLE_SETS = (5, 6, 7, 8)


def _both_ways(y, model, work, ex, set_index):
    """rhs_regime's (ydot, rg) and those of the free rhs with add_contact_forces."""
    rg = work.rg
    rg[:] = 0.0
    rg[ly.RG_SET], rg[ly.RG_STICK], rg[ly.RG_SIGN] = set_index, 1.0, 1.0
    fast = np.zeros(ly.N_AUG)
    assert rhs_regime(0.013, y, model, ex, work, fast) == ly.OK
    rg_fast = rg.copy()
    slow = np.zeros(ly.N_AUG)
    assert rhs(0.013, y, model.P, model.tab, model.kc, model.free, ex, work.rec, work.mat,
               work.vec, slow) == ly.OK
    add_contact_forces(y, model.P, model.free, work.mat, work.cg, work.cw, rg, slow)
    return fast, rg_fast, slow, rg.copy()


def _agree(fast, rg_fast, slow, rg_slow):
    qdd = slice(ly.N_DOF, ly.N_STATE)
    scale = np.abs(slow[qdd]).max()
    assert np.abs(fast[qdd] - slow[qdd]).max() <= 1e-11 * scale
    forces = slice(ly.RG_LN, ly.RG_LT + 1)
    assert np.abs(rg_fast[forces] - rg_slow[forces]).max() <= 1e-11 * np.abs(rg_slow[forces]).max()
    for a in (ly.A_FRIC, ly.A_CONSTR):
        assert abs(fast[a] - slow[a]) <= 1e-11 * max(1.0, abs(slow[a]))


@pytest.mark.parametrize("tip", [True, False])
def test_locked_joint_blocks_equal_the_multiplier_solution(tip):
    model, work, ex = mdl.build(Parameters().replace(tip_mass=tip)), mdl.make_work(), sine(200.0, 20.0)
    rng = np.random.default_rng(7)
    locked = 0
    for trial in range(40):
        y = np.zeros(ly.N_AUG)
        y[:ly.N_STATE] = random_state(rng)
        set_index = DOUBLE_SETS[trial % 4]
        fast, rg_fast, slow, rg_slow = _both_ways(y, model, work, ex, set_index)
        _agree(fast, rg_fast, slow, rg_slow)
        # the accelerations satisfy the rows: A q'' + A' q' = 0
        qd, qdd = y[ly.N_DOF:ly.N_STATE], fast[ly.N_DOF:ly.N_STATE]
        cg = work.cg
        for row in (ly.CG_G + ly.SET_FIRST[set_index], ly.CG_G + ly.SET_SECOND[set_index],
                    ly.CG_T + ly.SET_FIRST[set_index]):
            acc = (cg[row, ly.CG_DS] * qdd[ly.S] + cg[row, ly.CG_DV] * qdd[ly.V]
                   + cg[row, ly.CG_DPSI] * qdd[ly.PSI] + row_convective(cg, row, qd))
            assert abs(acc) <= 1e-9 * (1.0 + np.abs(qdd).max())
        locked += joint_locked(set_index, cg)
    assert locked == 40                     # every trial took the block path


def test_nearly_dependent_rows_take_the_pivoted_elimination():
    """At psi = 0 and s = x_lip - x_in the rows of points 1 and 3 (set 5) are dependent:
    the multipliers' elimination decides, and the result is its own."""
    model, work, ex = mdl.build(Parameters()), mdl.make_work(), sine(200.0, 20.0)
    y = np.zeros(ly.N_AUG)
    y[:ly.N_STATE] = random_state(np.random.default_rng(3))
    y[ly.PSI] = 0.0
    y[ly.S] = model.P[ly.P_X_LIP] - model.P[ly.P_X_IN]
    eval_geometry(y, model.P, work.cg)
    assert not joint_locked(5, work.cg)
    y[ly.S] -= 0.05                         # 0.5 mm away the block path is taken
    eval_geometry(y, model.P, work.cg)
    assert joint_locked(5, work.cg)
    y[ly.S] += 0.05
    fast, rg_fast, slow, rg_slow = _both_ways(y, model, work, ex, 5)
    assert np.array_equal(fast[:ly.N_STATE], slow[:ly.N_STATE])
    assert np.array_equal(rg_fast, rg_slow)


def test_held_coordinates_take_the_multiplier_solution():
    """With a coordinate held (psi) the block path does not apply: rhs_regime is the
    multipliers' solution exactly."""
    model = mdl.build(Parameters(), fixed=("psi",))
    work, ex = mdl.make_work(), sine(200.0, 20.0)
    y = np.zeros(ly.N_AUG)
    y[:ly.N_STATE] = random_state(np.random.default_rng(5))
    y[ly.PSI] = y[ly.N_DOF + ly.PSI] = 0.0
    for set_index in DOUBLE_SETS:
        fast, rg_fast, slow, rg_slow = _both_ways(y, model, work, ex, set_index)
        assert np.array_equal(fast[:ly.N_STATE], slow[:ly.N_STATE])
        assert np.array_equal(rg_fast, rg_slow)


def test_the_projection_sets_the_state_s_tiny_components_to_zero():
    """A locked joint's rates are zero in exact arithmetic; their round-off must not be left to
    decay into the subnormal doubles (config.TINY_STATE): a projection onto a sticking double
    contact sets every component of (q, q') below TINY_STATE to zero, and gives the same state
    as from those components at zero."""
    model, work = mdl.build(Parameters()), mdl.make_work()
    y = np.zeros(ly.N_AUG)
    y[:ly.N_STATE] = random_state(np.random.default_rng(11))
    rg = work.rg
    rg[:] = 0.0
    rg[ly.RG_SET], rg[ly.RG_STICK], rg[ly.RG_SIGN] = 5, 1.0, 1.0
    project(y, model.P, model.free, work.cg, work.cw, rg, np.bool_(False))
    tiny = {ly.N_DOF + ly.V: 5e-323, ly.N_DOF + ly.PSI: -2e-310, ly.N_DOF + ly.W_B: -3e-200,
            ly.U_A: 1e-160}
    for i in tiny:
        y[i] = 0.0
    at_zero = y.copy()
    for i, value in tiny.items():
        y[i] = value
    assert all(abs(v) < TINY_STATE for v in tiny.values())
    project(at_zero, model.P, model.free, work.cg, work.cw, rg, np.bool_(False))
    project(y, model.P, model.free, work.cg, work.cw, rg, np.bool_(False))
    assert all(y[i] == 0.0 for i in tiny)
    assert np.array_equal(y, at_zero)
