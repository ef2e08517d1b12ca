"""The compiled static-equilibrium iteration (workbench.core.equilibrium)."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from workbench.core import layout as ly
from workbench.core.equilibrium import _gauss_solve
from workbench.model import statics
from workbench.model.params import Parameters
from workbench.model.regimes import CONTACT_CODES


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 14), seed=st.integers(0, 2**32 - 1))
def test_gauss_solve_agrees_with_lapack(n, seed):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n)) * 10.0 ** rng.integers(-3, 4, size=n)   # rows of unequal scale
    b = rng.normal(size=n)
    expected = np.linalg.solve(A, b)
    x = np.zeros(n)
    assert _gauss_solve(A.copy(), b.copy(), x, n)
    cond = np.linalg.cond(A)
    assert np.max(np.abs(x - expected)) <= 1e-13 * cond * max(1.0, np.max(np.abs(expected)))


def test_gauss_solve_reports_a_singular_matrix():
    A = np.array([[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 1.0, 1.0]])
    assert not _gauss_solve(A, np.ones(3), np.zeros(3), 3)


def _set_index(code):
    return CONTACT_CODES.index(code)


def test_newton_converges_in_the_pried_set_and_gives_up_on_a_lone_corner():
    """With the tip mass the rig rests on corners 2 and 3 (docs/model.md §8): the iteration
    converges there, with both gaps closed and the free coordinates' forces balanced; on corner
    3 alone there is no equilibrium near the undeformed start, and it stops damped out."""
    p = Parameters(tip_mass=True)
    problem = statics._Statics(p, (), 0.0)
    q0 = np.zeros(ly.N_DOF)
    pried = _set_index(23)
    coords, points, friction = problem.unknowns(pried, True)
    z = np.concatenate([q0[coords], np.zeros(points.size + 1)])
    assert problem.newton(z, q0.copy(), pried, True)
    q, Q, gaps, _, _ = problem.state(z, q0, pried, True)
    assert np.max(np.abs(gaps[points])) < 1e-12                  # cm
    assert np.max(np.abs(Q[coords])) < 1e-3                       # dyn, of forces ~1e6
    assert np.all(z[coords.size:coords.size + 2] > 0)             # pressing, not pulling
    lone = _set_index(3)
    coords, points, friction = problem.unknowns(lone, True)
    z = np.concatenate([q0[coords], np.zeros(points.size + 1)])
    assert not problem.newton(z, q0.copy(), lone, True)


@pytest.mark.parametrize("tip", [True, False])
def test_a_tip_load_moves_the_tip_by_what_it_asks(tip):
    p = Parameters(tip_mass=tip)
    base = statics.static_equilibrium(p)
    load, eq = statics.tip_load_for_deflection(p, 0.5, base=base)
    assert eq.tip_y - base.tip_y == pytest.approx(0.5, abs=1e-6)
    assert load > 0                                               # up, to lift the tip
