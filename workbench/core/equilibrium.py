"""Static equilibrium of the rig in one contact set: a damped Newton iteration (docs/model.md §8).

For a set of contact points (``points``) the unknowns z are the free
coordinates ``coords`` (cm, rad), then the normal forces lambda_n of the
set's points (dyn), then, when ``friction`` holds the slide, the tangential
force lambda_t of its first point (dyn).  The residual f(z), scaled so that
its rows are of order one, is

    Q(q) + W_n^T lambda_n + W_t^T lambda_t     on coords, and on s if friction
                                               (dyn, dyn cm; over FORCE_SCALE)
    g_k(q)                                     on the set's points (cm; over GAP_SCALE)

with Q the generalised force at rest (gravity, elastic, cork; the right-hand
side of :mod:`workbench.core.dynamics` at q' = 0) plus a vertical tip load on
beam B's tip.  The contact forces act on the joint coordinates (s, v, psi)
through the gradients of :func:`workbench.core.contact.fill_geometry`.

:func:`newton_set` iterates z <- z + alpha dz with J dz = -f, J by central
differences and alpha halved until the residual's largest entry falls by a
quarter of alpha.  Which set is the equilibrium (admissible forces, open
gaps, friction, least potential energy) is decided by
:mod:`workbench.model.statics`.
"""
import numba as nb
import numpy as np

from .config import ALPHA_MIN, FD_COORD, FD_FORCE, FORCE_SCALE, GAP_SCALE, JIT, JIT_ALLOC, JIT_INLINE
from . import layout as ly
from .contact import fill_geometry
from .dynamics import add_applied_forces, assemble_inertia, cork_energy
from .kinematics import element, n_elements

@nb.njit(**JIT)
def _residual(z, case, model, ex, work, q, qd, Q, f):
    """f(z) into f; q, the force Q with the contact forces, and the geometry (cg) of z.

    Returns the tip's height (cm).  Not inlined: its callers call it five times,
    and each copy would compile the mass matrix's assembly again.
    """
    q_base, coords, points, friction, tip_load = case
    P, tab, kc = model.P, model.tab, model.kc
    rec, mat, vec, cg = work.rec, work.mat, work.vec, work.cg
    nc = coords.size
    npt = points.size
    for i in range(ly.N_DOF):
        q[i] = q_base[i]
    for k in range(nc):
        q[coords[k]] = z[k]
    assemble_inertia(q, qd, P, tab, rec, mat, vec)
    add_applied_forces(0.0, q, qd, P, tab, kc, ex, rec, vec)
    for i in range(ly.N_DOF):
        Q[i] = vec[ly.VEC_Q, i] - vec[ly.VEC_H, i]
    # the frames are assemble_inertia's: the last element is the tip point
    element(n_elements(P) - 1, q, qd, P, tab, rec)
    tip = rec[ly.REC_POINT]
    for i in range(ly.N_DOF):
        Q[i] += tip_load * tip[ly.JY + i]
    tip_y = tip[ly.RY]
    fill_geometry(q, P, cg)
    for k in range(npt):
        row = ly.CG_G + points[k]
        lam = z[nc + k]
        Q[ly.S] += lam * cg[row, ly.CG_DS]
        Q[ly.V] += lam * cg[row, ly.CG_DV]
        Q[ly.PSI] += lam * cg[row, ly.CG_DPSI]
    if friction:
        row = ly.CG_T + points[0]
        lam = z[nc + npt]
        Q[ly.S] += lam * cg[row, ly.CG_DS]
        Q[ly.V] += lam * cg[row, ly.CG_DV]
        Q[ly.PSI] += lam * cg[row, ly.CG_DPSI]
    for k in range(nc):
        f[k] = Q[coords[k]] / FORCE_SCALE
    n_force = nc
    if friction:
        f[nc] = Q[ly.S] / FORCE_SCALE
        n_force += 1
    for k in range(npt):
        f[n_force + k] = cg[ly.CG_G + points[k], ly.CG_VAL] / GAP_SCALE
    return tip_y


@nb.njit(**JIT_INLINE)
def _largest(f, n):
    """max |f_i| over the first n entries; inf if any is not finite."""
    out = 0.0
    for i in range(n):
        a = abs(f[i])
        if not a <= 1e300:
            return np.inf
        out = max(out, a)
    return out


@nb.njit(**JIT_INLINE)
def _gauss_solve(A, b, x, n):
    """Solve A x = b (n x n) by Gaussian elimination with partial pivoting; A and b are
    overwritten.  Returns False when a pivot is exactly zero (A singular)."""
    for col in range(n):
        piv = col
        for r in range(col + 1, n):
            if abs(A[r, col]) > abs(A[piv, col]):
                piv = r
        if A[piv, col] == 0.0:
            return False
        if piv != col:
            for j in range(n):
                A[col, j], A[piv, j] = A[piv, j], A[col, j]
            b[col], b[piv] = b[piv], b[col]
        for r in range(col + 1, n):
            m = A[r, col] / A[col, col]
            if m != 0.0:
                for j in range(col, n):
                    A[r, j] -= m * A[col, j]
                b[r] -= m * b[col]
    for i in range(n - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, n):
            acc -= A[i, j] * x[j]
        x[i] = acc / A[i, i]
    return True


@nb.njit(**JIT_ALLOC)
def static_state(z, case, model, ex, work, q, Q, f, energy):
    """The state of unknowns z: q (9,), the force Q with the contact forces (9,), the
    scaled residual f, and energy (4,): elastic, gravity and cork potential (erg) and
    the tip's height (cm).  The gaps and their gradients are left in ``cg``."""
    P, tab, kc = model.P, model.tab, model.kc
    rec, mat, vec = work.rec, work.mat, work.vec
    qd = np.zeros(ly.N_DOF)
    tip_y = _residual(z, case, model, ex, work, q, qd, Q, f)
    K = kc[ly.KC_K]
    elastic = 0.0
    for i in range(ly.N_DOF):
        for j in range(ly.N_DOF):
            elastic += 0.5 * q[i] * K[i, j] * q[j]
    energy[0] = elastic
    energy[1] = assemble_inertia(q, qd, P, tab, rec, mat, vec)
    energy[2] = cork_energy(q[ly.S], P)
    energy[3] = tip_y


@nb.njit(**JIT_ALLOC)
def newton_set(z, case, tol, max_iter, max_damped, model, ex, work):
    """Solve f(z) = 0 from z (overwritten with the solution); returns a status.

    ``case`` is (q_base, coords, points, friction, tip_load): the coordinates q (cm, rad)
    the unknowns start from, the free coordinates and the set's points (int64 arrays),
    whether friction holds the slide, and the vertical tip load (dyn).
    ``tol`` bounds the scaled residual's largest entry; ``max_iter`` Newton
    steps at most; ``max_damped`` damped steps in a row mean no equilibrium
    near the start.  Status: :data:`~workbench.core.layout.EQ_CONVERGED`,
    ``EQ_DAMPED_OUT``, ``EQ_SINGULAR`` (a Jacobian with a zero pivot) or
    ``EQ_NOT_CONVERGED``.
    """
    n = z.size
    q = np.zeros(ly.N_DOF)
    qd = np.zeros(ly.N_DOF)
    Q = np.zeros(ly.N_DOF)
    f = np.zeros(n)
    f_try = np.zeros(n)
    f_minus = np.zeros(n)
    z_try = np.zeros(n)
    dz = np.zeros(n)
    J = np.zeros((n, n))
    _residual(z, case, model, ex, work, q, qd, Q, f)
    nc = case[1].size
    damped = 0
    for _ in range(max_iter):
        norm = _largest(f, n)
        if norm < tol:
            return ly.EQ_CONVERGED
        if damped >= max_damped:
            return ly.EQ_DAMPED_OUT
        for j in range(n):
            step = (FD_COORD if j < nc else FD_FORCE) * max(1.0, abs(z[j]))
            for i in range(n):
                z_try[i] = z[i]
            z_try[j] = z[j] + step
            _residual(z_try, case, model, ex, work, q, qd, Q, f_try)
            z_try[j] = z[j] - step
            _residual(z_try, case, model, ex, work, q, qd, Q, f_minus)
            for i in range(n):
                J[i, j] = (f_try[i] - f_minus[i]) / (2.0 * step)
        for i in range(n):
            f_minus[i] = -f[i]
        if not _gauss_solve(J, f_minus, dz, n):
            return ly.EQ_SINGULAR
        alpha = 1.0
        while True:
            for i in range(n):
                z_try[i] = z[i] + alpha * dz[i]
            _residual(z_try, case, model, ex, work, q, qd, Q, f_try)
            if _largest(f_try, n) < (1.0 - 0.25 * alpha) * norm or 0.5 * alpha <= ALPHA_MIN:
                break
            alpha *= 0.5
        damped = damped + 1 if alpha < 1.0 else 0
        for i in range(n):
            z[i] = z_try[i]
            f[i] = f_try[i]
    return ly.EQ_CONVERGED if _largest(f, n) < tol else ly.EQ_NOT_CONVERGED
