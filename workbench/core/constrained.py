"""Constrained dynamics of the 17 regimes (docs/model.md §7), jit-compiled.

A regime is a contact set (``rg[RG_SET]``, 0..8) and a stick flag.  Its
active rows are the normal rows W_n = dg/dq of the set's points and, when
sticking, the tangential row W_t = dtau/dq of the set's first point:

    stick:  M q'' = Q - h + W_n^T lambda_n + W_t^T lambda_t
    slip:   M q'' = Q - h + sum_k (W_n,k - mu_k sigma W_t,k)^T lambda_n,k
    both:   W q'' + W' q' = 0 for every active row

Slipping, each point's friction acts along its own tangential row W_t,k.
Sticking, one tangential row (:func:`tangent_point`) with the normal rows
locks the joint; in a double contact the split of the contact force between
the two points is then one free parameter, and the regime sticks while some
split satisfies both friction cones (:func:`stick_margin`): at the end of
that interval the sticking force equals the per-point slipping force, so
stick -> slip is continuous.

With rows A, force directions B (B = A when sticking) and the unconstrained
accelerations a0 = M^-1 (Q - h):

    q'' = a0 + X lambda,   X = M^-1 B^T,   (A X) lambda = -A' q' - A a0.

The dense systems are at most 3x3 and solved in place in the work array
``cw`` (layout ``CW_*``); a row that vanishes on the free coordinates (a
held coordinate) gets lambda = 0.  Impacts and the choice of the regime
are in :mod:`workbench.core.transitions`.

Drift of the active constraints is removed by :func:`project`: a
least-squares Newton projection of (s, v, psi) onto the active gaps (and
onto any open gap the correction would push past its impact event) and of
their rates onto the active rows.
"""
import numba as nb
import numpy as np

from .config import (FRICTION_REL_EPS, JIT, JIT_INLINE, LAMBDA_EPS, LOCK_DET_REL, NULL_COFACTOR_REL,
                     PIVOT_REL, TINY_STATE)
from . import layout as ly
from .contact import fill_geometry, in_set, row_convective, row_rate, row_to_dof
from .dynamics import (add_joint_solve, joint_block, net_forces, solve_beams, solve_factored,
                       solve_free)


@nb.njit(**JIT_INLINE)
def _put_row(cg, cw, r, geometry_row, friction_row, friction):
    """Constraint row r: A = d(geometry_row)/dq, B = A + friction d(friction_row)/dq."""
    a = cw[ly.CW_A + r]
    b = cw[ly.CW_B + r]
    for j in range(ly.N_DOF):
        a[j] = 0.0
        b[j] = 0.0
    row_to_dof(cg, geometry_row, 1.0, a)
    row_to_dof(cg, geometry_row, 1.0, b)
    if friction != 0.0:
        row_to_dof(cg, friction_row, friction, b)


@nb.njit(**JIT_INLINE)
def set_rows(set_index, stick, sign, P, cg, cw):
    """Rows A and force directions B (9-vectors) of a regime into cw; return their number.

    Row order: the normal rows of the set's first and second point, then,
    when sticking, the tangential row of the set's first point.  Slipping,
    each point's force direction is W_n,k - mu_k sigma W_t,k with its own
    tangential row (docs/model.md §7).
    """
    m = 0
    friction = 0.0 if stick else -P[ly.P_MU_K] * sign
    for which in range(2):
        p = ly.SET_FIRST[set_index] if which == 0 else ly.SET_SECOND[set_index]
        if p >= 0:
            _put_row(cg, cw, m, ly.CG_G + p, ly.CG_T + p, friction)
            m += 1
    if stick:
        tangent = ly.CG_T + tangent_point(set_index)
        _put_row(cg, cw, m, tangent, tangent, 0.0)
        m += 1
    return m


@nb.njit(**JIT_INLINE)
def tangent_point(set_index):
    """The point whose tangential row a sticking regime holds: the set's first (docs/model.md §7).

    In a double contact both normal rows and this row span the three joint
    coordinates, so the joint is locked; how the contact force splits
    between the points is then one free parameter (:func:`stick_margin`).
    """
    return ly.SET_FIRST[set_index]


@nb.njit(**JIT_INLINE)
def row_geometry_index(set_index, stick, r):
    """The geometry row (CG_G + k or CG_T + k) behind constraint row r of a regime."""
    p1 = ly.SET_FIRST[set_index]
    p2 = ly.SET_SECOND[set_index]
    if r == 0:
        return ly.CG_G + p1
    if r == 1 and p2 >= 0:
        return ly.CG_G + p2
    return ly.CG_T + tangent_point(set_index)


@nb.njit(**JIT_INLINE)
def small_solve(cw, m):
    """Solve D x = c (m <= MAX_ROWS) held in rows CW_D.. of cw; x into column CW_L_COL.

    Gaussian elimination with partial pivoting.  An unknown whose pivot is
    negligible (below PIVOT_REL of the largest entry: a row that is zero on the
    free coordinates or dependent on the others) is set to 0.
    """
    scale = 0.0
    for i in range(m):
        for j in range(m):
            scale = max(scale, abs(cw[ly.CW_D + i, j]))
    tiny = PIVOT_REL * scale
    for col in range(m):
        piv = col
        for r in range(col + 1, m):
            if abs(cw[ly.CW_D + r, col]) > abs(cw[ly.CW_D + piv, col]):
                piv = r
        if piv != col:
            for j in range(ly.CW_C_COL + 1):
                tmp = cw[ly.CW_D + col, j]
                cw[ly.CW_D + col, j] = cw[ly.CW_D + piv, j]
                cw[ly.CW_D + piv, j] = tmp
        if not abs(cw[ly.CW_D + col, col]) > tiny:
            for j in range(m):
                cw[ly.CW_D + col, j] = 0.0
            cw[ly.CW_D + col, col] = 1.0
            cw[ly.CW_D + col, ly.CW_C_COL] = 0.0
            continue
        inv = 1.0 / cw[ly.CW_D + col, col]
        for r in range(col + 1, m):
            f = cw[ly.CW_D + r, col] * inv
            if f != 0.0:
                for j in range(col, m):
                    cw[ly.CW_D + r, j] -= f * cw[ly.CW_D + col, j]
                cw[ly.CW_D + r, ly.CW_C_COL] -= f * cw[ly.CW_D + col, ly.CW_C_COL]
    for i in range(m - 1, -1, -1):
        acc = cw[ly.CW_D + i, ly.CW_C_COL]
        for j in range(i + 1, m):
            acc -= cw[ly.CW_D + i, j] * cw[ly.CW_D + j, ly.CW_L_COL]
        cw[ly.CW_D + i, ly.CW_L_COL] = acc / cw[ly.CW_D + i, i]


@nb.njit(**JIT_INLINE)
def _dot9(a, b):
    acc = 0.0
    for j in range(ly.N_DOF):
        acc += a[j] * b[j]
    return acc


@nb.njit(**JIT_INLINE)
def fill_delassus(free, mat, cw, m):
    """X_r = M^-1 B_r and D = A X (rows CW_D, columns 0..m-1); M's factor must be current."""
    for r in range(m):
        solve_factored(free, mat, cw[ly.CW_B + r], cw[ly.CW_X + r])
    for i in range(m):
        for j in range(m):
            cw[ly.CW_D + i, j] = _dot9(cw[ly.CW_A + i], cw[ly.CW_X + j])


@nb.njit(**JIT_INLINE)
def _joint_delassus(mat, cw, m):
    """D = A M^-1 B^T (rows CW_D, columns 0..m-1) from M^-1's joint block (every coordinate
    free, M's factor current): the rows act on the joint's (s, v, psi) only (set_rows)."""
    W = joint_block(mat)
    for j in range(m):
        b = cw[ly.CW_B + j]
        wb0 = W[0][0] * b[ly.S] + W[0][1] * b[ly.V] + W[0][2] * b[ly.PSI]
        wb1 = W[1][0] * b[ly.S] + W[1][1] * b[ly.V] + W[1][2] * b[ly.PSI]
        wb2 = W[2][0] * b[ly.S] + W[2][1] * b[ly.V] + W[2][2] * b[ly.PSI]
        for i in range(m):
            a = cw[ly.CW_A + i]
            cw[ly.CW_D + i, j] = a[ly.S] * wb0 + a[ly.V] * wb1 + a[ly.PSI] * wb2


@nb.njit(**JIT)
def rhs_regime(t, y, model, ex, work, ydot):
    """Right-hand side of the augmented state in the regime of ``rg``.

    Writes ydot (N_AUG,): (q', q'') and the powers integrated for the
    energy account (erg/s); the contact forces lambda (dyn) into rg.
    Returns a status code.  A sticking double contact whose rows lock the
    joint takes :func:`locked_joint_accelerations`, the same equations
    solved by blocks.
    """
    P, tab, kc, free = model.P, model.tab, model.kc, model.free
    rec, mat, vec, cg, cw, rg = work.rec, work.mat, work.vec, work.cg, work.cw, work.rg
    set_index = int(rg[ly.RG_SET])
    det = 0.0
    if rg[ly.RG_STICK] != 0.0 and ly.SET_SECOND[set_index] >= 0 and free.shape[0] == ly.N_DOF:
        fill_geometry(y, P, cg)
        det = locking_determinant(set_index, cg)
    locked = det != 0.0
    net_forces(t, y, P, tab, kc, ex, rec, mat, vec, ydot)
    if locked:
        status = locked_joint_accelerations(y, mat, vec[ly.VEC_RHS], cg, rg, det, ydot)
    else:
        status = solve_free(free, mat, vec[ly.VEC_RHS], ydot[ly.N_DOF:])
    if status != ly.OK:
        return status
    rg[ly.RG_VGRAV] = vec[ly.VEC_AUX, ly.AUX_VGRAV]
    ydot[ly.A_WORK] = vec[ly.VEC_AUX, ly.AUX_P_EXT]
    ydot[ly.A_DAMP] = vec[ly.VEC_AUX, ly.AUX_P_DAMP]
    ydot[ly.A_CORK] = P[ly.P_CORK_C] * y[ly.N_DOF + ly.S] * y[ly.N_DOF + ly.S]
    if not locked:
        add_contact_forces(y, P, free, mat, cg, cw, rg, ydot)
    return ly.OK


@nb.njit(**JIT_INLINE)
def _joint_row(cg, row):
    """A geometry row's gradient on the joint's coordinates (s, v, psi)."""
    return (cg[row, ly.CG_DS], cg[row, ly.CG_DV], cg[row, ly.CG_DPSI])


@nb.njit(**JIT_INLINE)
def _locked_rows(set_index, cg):
    """A sticking double contact's three rows on (s, v, psi), in constraint-row order."""
    return (_joint_row(cg, row_geometry_index(set_index, True, 0)),
            _joint_row(cg, row_geometry_index(set_index, True, 1)),
            _joint_row(cg, row_geometry_index(set_index, True, 2)))


@nb.njit(**JIT_INLINE)
def locking_determinant(set_index, cg):
    """The determinant of a sticking double contact's 3 x 3 rows on (s, v, psi) (cg current)
    when they lock the joint, else 0.

    They lock it when the determinant exceeds LOCK_DET_REL of Hadamard's
    bound (the product of the rows' lengths).
    """
    a, b, c = _locked_rows(set_index, cg)
    bound = 1.0
    for r in (a, b, c):
        bound *= (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]) ** 0.5
    det = _det3(a, b, c)
    return det if abs(det) > LOCK_DET_REL * bound else 0.0


@nb.njit(**JIT_INLINE)
def joint_locked(set_index, cg):
    """Do the rows of a sticking double contact (cg current) lock the joint's coordinates?"""
    return locking_determinant(set_index, cg) != 0.0


@nb.njit(**JIT_INLINE)
def locked_joint_accelerations(y, mat, b, cg, rg, det, ydot):
    """q'' and the contact forces of a sticking double contact that locks the joint.

    The regime's rows A (the two normals, the first point's tangent) are
    zero on the beams' coordinates r and an invertible 3 x 3 block A_j on
    the joint's j = (s, v, psi), so M q'' = b + A^T lambda with
    A q'' = -A' q' splits into blocks: A_j q_j'' = -A' q',
    M_rr q_r'' = b_r - M_rj q_j'', A_j^T lambda = M_j. q'' - b_j.  These are
    the equations of :func:`add_contact_forces`, without the solves with M
    on the joint's rows.  M in mat[MAT_M] and b = Q - h must be y's, det
    A_j's determinant (:func:`locking_determinant`); b's beam rows are left
    as b_r - M_rj q_j'' and mat[MAT_CHOL] with the factor of M_rr.  Writes
    q'' into ydot, lambda (dyn) into rg and the constraint and friction
    powers (erg/s).  Returns a status code.
    """
    M = mat[ly.MAT_M]
    qd = y[ly.N_DOF:ly.N_STATE]
    qdd = ydot[ly.N_DOF:ly.N_STATE]
    set_index = int(rg[ly.RG_SET])
    rows = (row_geometry_index(set_index, True, 0), row_geometry_index(set_index, True, 1),
            row_geometry_index(set_index, True, 2))
    a, bb, c = _locked_rows(set_index, cg)
    inv_det = 1.0 / det
    conv = (-row_convective(cg, rows[0], qd), -row_convective(cg, rows[1], qd),
            -row_convective(cg, rows[2], qd))
    # the joint's accelerations by Cramer's rule on the columns of A_j
    c0 = (a[0], bb[0], c[0])
    c1 = (a[1], bb[1], c[1])
    c2 = (a[2], bb[2], c[2])
    qj = (_det3(conv, c1, c2) * inv_det, _det3(c0, conv, c2) * inv_det,
          _det3(c0, c1, conv) * inv_det)
    for i in ly.BEAM_COORDS:
        b[i] -= M[i, ly.S] * qj[0] + M[i, ly.V] * qj[1] + M[i, ly.PSI] * qj[2]
    status = solve_beams(mat, b, qdd)
    if status != ly.OK:
        return status
    qdd[ly.S] = qj[0]
    qdd[ly.V] = qj[1]
    qdd[ly.PSI] = qj[2]
    # b_j was not changed: the residual of the joint's rows is A_j^T lambda
    res = (_dot9(M[ly.S], qdd) - b[ly.S], _dot9(M[ly.V], qdd) - b[ly.V],
           _dot9(M[ly.PSI], qdd) - b[ly.PSI])
    lam = (_det3(res, bb, c) * inv_det, _det3(a, res, c) * inv_det, _det3(a, bb, res) * inv_det)
    for k in range(ly.N_POINTS):
        rg[ly.RG_LN + k] = 0.0
        ydot[ly.A_FRIC_P + k] = 0.0
    rg[ly.RG_LN + ly.SET_FIRST[set_index]] = lam[0]
    rg[ly.RG_LN + ly.SET_SECOND[set_index]] = lam[1]
    rg[ly.RG_LT] = lam[2]
    p_constr = 0.0
    for r in range(3):
        p_constr += lam[r] * row_rate(cg, rows[r], qd)
    ydot[ly.A_FRIC] = 0.0
    ydot[ly.A_CONSTR] = p_constr
    return ly.OK


@nb.njit(**JIT)
def add_contact_forces(y, P, free, mat, cg, cw, rg, ydot):
    """Add the regime's contact forces to the free accelerations in ydot.

    ydot[N_DOF:N_STATE] holds M^-1 (Q - h) on entry (M's factor current)
    and q'' of the regime of ``rg`` on return; lambda (dyn) into rg, the
    friction and constraint powers into ydot[A_FRIC], ydot[A_CONSTR], and each
    point's friction power into ydot[A_FRIC_P + k].
    """
    qd = y[ly.N_DOF:ly.N_STATE]
    qdd = ydot[ly.N_DOF:ly.N_STATE]
    for k in range(ly.N_POINTS):
        rg[ly.RG_LN + k] = 0.0
        ydot[ly.A_FRIC_P + k] = 0.0
    rg[ly.RG_LT] = 0.0
    p_constr = 0.0
    p_fric = 0.0
    set_index = int(rg[ly.RG_SET])
    if set_index > 0:
        stick = rg[ly.RG_STICK] != 0.0
        sign = rg[ly.RG_SIGN]
        fill_geometry(y, P, cg)
        m = set_rows(set_index, stick, sign, P, cg, cw)
        all_free = free.shape[0] == ly.N_DOF
        if all_free:
            _joint_delassus(mat, cw, m)
        else:
            fill_delassus(free, mat, cw, m)
        for r in range(m):
            conv = row_convective(cg, row_geometry_index(set_index, stick, r), qd)
            cw[ly.CW_D + r, ly.CW_C_COL] = -conv - _dot9(cw[ly.CW_A + r], qdd)
        small_solve(cw, m)
        f0 = f1 = f2 = 0.0             # B^T lambda on (s, v, psi)
        for r in range(m):
            lam = cw[ly.CW_D + r, ly.CW_L_COL]
            if all_free:
                b = cw[ly.CW_B + r]
                f0 += b[ly.S] * lam
                f1 += b[ly.V] * lam
                f2 += b[ly.PSI] * lam
            else:
                x = cw[ly.CW_X + r]
                for j in range(ly.N_DOF):
                    qdd[j] += x[j] * lam
            p_constr += lam * _dot9(cw[ly.CW_A + r], qd)
        if all_free:
            add_joint_solve(mat, (f0, f1, f2), qdd, cw[ly.CW_X])
        p1 = ly.SET_FIRST[set_index]
        p2 = ly.SET_SECOND[set_index]
        rg[ly.RG_LN + p1] = cw[ly.CW_D + 0, ly.CW_L_COL]
        n_normal = 1
        if p2 >= 0:
            rg[ly.RG_LN + p2] = cw[ly.CW_D + 1, ly.CW_L_COL]
            n_normal = 2
        if stick:
            rg[ly.RG_LT] = cw[ly.CW_D + n_normal, ly.CW_L_COL]
        else:
            # friction force -mu_k sigma lambda_n,k W_t,k: dissipates mu_k sigma lambda_n,k tau_k'
            for which in range(n_normal):
                p = p1 if which == 0 else p2
                power = P[ly.P_MU_K] * sign * rg[ly.RG_LN + p] * row_rate(cg, ly.CG_T + p, qd)
                ydot[ly.A_FRIC_P + p] = power
                p_fric += power
    ydot[ly.A_FRIC] = p_fric
    ydot[ly.A_CONSTR] = p_constr


@nb.njit(**JIT_INLINE)
def _det3(a, b, c):
    return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))


@nb.njit(**JIT_INLINE)
def _bound(c, d, lo, hi, short):
    """Intersect [lo, hi] with {alpha: c + d alpha >= 0}.

    A condition that does not depend on alpha (d = 0) and fails lowers
    ``short`` to c.  Returns (lo, hi, short).
    """
    if d == 0.0:
        return lo, hi, min(short, c)
    x = -c / d
    if d > 0.0:
        return max(lo, x), hi, short
    return lo, min(hi, x), short


@nb.njit(**JIT_INLINE)
def _masked(cg, row, ms, mv, mp):
    """A geometry row's gradient on the free joint coordinates (s, v, psi)."""
    r = _joint_row(cg, row)
    return (ms * r[0], mv * r[1], mp * r[2])


@nb.njit(**JIT_INLINE)
def stick_margin(P, free, cg, rg):
    """How far a sticking regime is inside the friction cone (dyn): >= 0 while sticking holds.

    One point: mu_s lambda_n - |lambda_t|.  Two points (the forces in rg
    solved with the first point's tangential row, cg current): the contact
    force on the free joint coordinates splits into per-point normal and
    tangential forces along the null direction d of the four rows (n1, t1,
    n2, t2), scaled to unit largest entry; sticking holds while some split
    alpha has lambda_n,k >= 0 and |lambda_t,k| <= mu_s lambda_n,k at both
    points.  The margin is the width of that interval of alpha (dyn), so
    that it reaches 0 where the per-point slip of docs/model.md §7 takes over.
    When the four rows span less than three dimensions (a flat double
    contact with psi held: the points' rows coincide) the margin is
    mu_s sum lambda_n - |lambda_t|.
    """
    set_index = int(rg[ly.RG_SET])
    p1 = ly.SET_FIRST[set_index]
    p2 = ly.SET_SECOND[set_index]
    mu = P[ly.P_MU_S]
    shared = mu * (rg[ly.RG_LN + p1] + (rg[ly.RG_LN + p2] if p2 >= 0 else 0.0)) \
        - abs(rg[ly.RG_LT])
    if p2 < 0:
        return shared
    ms = _free_mask(free, ly.S)
    mv = _free_mask(free, ly.V)
    mp = _free_mask(free, ly.PSI)
    n1 = _masked(cg, ly.CG_G + p1, ms, mv, mp)
    t1 = _masked(cg, ly.CG_T + p1, ms, mv, mp)
    n2 = _masked(cg, ly.CG_G + p2, ms, mv, mp)
    t2 = _masked(cg, ly.CG_T + p2, ms, mv, mp)
    # null vector of the 3 x 4 matrix [n1 t1 n2 t2] by cofactors
    d0 = _det3(t1, n2, t2)
    d1 = -_det3(n1, n2, t2)
    d2 = _det3(n1, t1, t2)
    d3 = -_det3(n1, t1, n2)
    big = max(max(abs(d0), abs(d1)), max(abs(d2), abs(d3)))
    scale = 1.0
    for r in (n1, t1, n2, t2):
        scale = max(scale, abs(r[0]) + abs(r[1]) + abs(r[2]))
    if big <= NULL_COFACTOR_REL * scale ** 3:
        return shared
    d0 /= big
    d1 /= big
    d2 /= big
    d3 /= big
    a1 = rg[ly.RG_LN + p1]
    b1 = rg[ly.RG_LT]
    a2 = rg[ly.RG_LN + p2]
    lo = -1e300
    hi = 1e300
    short = 0.0
    lo, hi, short = _bound(a1, d0, lo, hi, short)
    lo, hi, short = _bound(mu * a1 - b1, mu * d0 - d1, lo, hi, short)
    lo, hi, short = _bound(mu * a1 + b1, mu * d0 + d1, lo, hi, short)
    lo, hi, short = _bound(a2, d2, lo, hi, short)
    lo, hi, short = _bound(mu * a2, mu * d2 - d3, lo, hi, short)
    lo, hi, short = _bound(mu * a2, mu * d2 + d3, lo, hi, short)
    if short < 0.0:
        return short
    return min(hi - lo, 1e300)


@nb.njit(**JIT_INLINE)
def stick_tolerance(P, rg):
    """Round-off band of the stick margin (dyn): stick -> slip fires below minus this."""
    total = 0.0
    for k in range(ly.N_POINTS):
        total += abs(rg[ly.RG_LN + k])
    return FRICTION_REL_EPS * P[ly.P_MU_S] * total + LAMBDA_EPS


@nb.njit(**JIT_INLINE)
def _free_mask(free, i):
    for k in range(free.shape[0]):
        if free[k] == i:
            return 1.0
    return 0.0


@nb.njit(**JIT_INLINE)
def _projection_row(set_index, stick, rows, held, r):
    """Geometry row of projection row r: the regime's rows, then the held open points."""
    if r < rows:
        return row_geometry_index(set_index, stick, r)
    k = r - rows
    for p in range(ly.N_POINTS):
        if held & (1 << p):
            if k == 0:
                return ly.CG_G + p
            k -= 1
    return -1


@nb.njit(**JIT)
def _project_rows(y, offset, set_index, stick, rows, held, P, free, cg, cw):
    """One least-squares correction of y[offset + (S, V, PSI)] by the given rows.

    ``rows`` counts the regime's rows used: the normal rows (1 or 2), plus 1
    for the tangential row of a sticking regime; ``held`` is a bit mask of
    open points whose gaps are held at zero as well.  The residuals are the
    gap values (offset 0) or the row rates (offset N_DOF).  Returns the
    largest residual (cm or cm/s).
    """
    ms = _free_mask(free, ly.S)
    mv = _free_mask(free, ly.V)
    mp = _free_mask(free, ly.PSI)
    qd = y[ly.N_DOF:ly.N_STATE]
    n = rows
    for p in range(ly.N_POINTS):
        if held & (1 << p):
            n += 1
    worst = 0.0
    for r in range(n):
        g = _projection_row(set_index, stick, rows, held, r)
        a = cw[ly.CW_A + r]
        for j in range(ly.N_DOF):
            a[j] = 0.0
        a[ly.S] = ms * cg[g, ly.CG_DS]
        a[ly.V] = mv * cg[g, ly.CG_DV]
        a[ly.PSI] = mp * cg[g, ly.CG_DPSI]
        res = cg[g, ly.CG_VAL] if offset == 0 else row_rate(cg, g, qd)
        cw[ly.CW_D + r, ly.CW_C_COL] = res
        worst = max(worst, abs(res))
    if worst == 0.0:
        return 0.0
    for i in range(n):
        for j in range(n):
            cw[ly.CW_D + i, j] = _dot9(cw[ly.CW_A + i], cw[ly.CW_A + j])
    small_solve(cw, n)
    for r in range(n):
        mu = cw[ly.CW_D + r, ly.CW_L_COL]
        for j in (ly.S, ly.V, ly.PSI):
            y[offset + j] -= cw[ly.CW_A + r, j] * mu
    return worst


@nb.njit(**JIT)
def _project_gaps(y, set_index, stick, n_normal, held, P, free, cg, cw):
    """Two Newton steps of the positions onto the active (and held) gaps; geometry refilled.

    Returns the largest |g| of those gaps before the projection (cm).
    """
    before = _project_rows(y, np.int64(0), set_index, stick, n_normal, held, P, free, cg, cw)
    if before > 0.0:
        fill_geometry(y, P, cg)
        if _project_rows(y, np.int64(0), set_index, stick, n_normal, held, P, free, cg, cw) > 0.0:
            fill_geometry(y, P, cg)
    return before


@nb.njit(**JIT)
def project(y, P, free, cg, cw, rg, hold_open_below):
    """Pull the state onto the active constraints of the regime in rg.

    Positions: two Newton steps onto the active gaps g = 0 (the gaps are
    nearly linear in (s, v, psi) over a step's drift).  Moving the joint
    coordinates moves the open gaps too: an open point that this correction
    alone would carry past its impact event (g + rg[RG_ARM] from >= 0 to
    < 0) is held at g = 0 with the active ones, so that a projection never
    creates a penetration.  With ``hold_open_below`` (a regime just chosen)
    every open point left below g = 0 is held at g = 0 as well: a point the
    new regime releases leaves from contact, not from the depth to which
    the projection onto the remaining contact carried it.  Velocities: the
    active rows' rates (normal, and tangential when sticking) to zero.
    Only free joint coordinates move.  Then the components of (q, q') below
    config.TINY_STATE are set to zero (round-off of a locked joint's rates).

    Returns ``(correction, drift)`` (cm): the largest |g| of the active gaps
    before the projection (the step's truncation error on the constraint)
    and after it (what the solution keeps).
    """
    set_index = int(rg[ly.RG_SET])
    if set_index == 0:
        return 0.0, 0.0
    n_normal = 1 if ly.SET_SECOND[set_index] < 0 else 2
    fill_geometry(y, P, cg)
    stick = rg[ly.RG_STICK] != 0.0
    armed = 0
    for p in range(ly.N_POINTS):
        if not in_set(set_index, p) and cg[ly.CG_G + p, ly.CG_VAL] + rg[ly.RG_ARM + p] >= 0.0:
            armed |= 1 << p
    correction = _project_gaps(y, set_index, stick, n_normal, np.int64(0), P, free, cg, cw)
    held = np.int64(0)
    for p in range(ly.N_POINTS):
        if in_set(set_index, p):
            continue
        g = cg[ly.CG_G + p, ly.CG_VAL]
        if (armed & (1 << p) and g + rg[ly.RG_ARM + p] < 0.0) or (hold_open_below and g < 0.0):
            held |= 1 << p
    if held != 0:
        _project_gaps(y, set_index, stick, n_normal, held, P, free, cg, cw)
    drift = 0.0
    for r in range(n_normal):
        drift = max(drift, abs(cg[row_geometry_index(set_index, stick, r), ly.CG_VAL]))
    rows = n_normal + (1 if stick else 0)
    _project_rows(y, ly.N_DOF, set_index, stick, rows, np.int64(0), P, free, cg, cw)
    for i in range(ly.N_STATE):
        if abs(y[i]) < TINY_STATE:
            y[i] = 0.0
    return correction, drift


@nb.njit(**JIT_INLINE)
def kinetic_energy(qd, mat):
    """1/2 q'^T M q' (erg) with M = mat[MAT_M]."""
    M = mat[ly.MAT_M]
    acc = 0.0
    for i in range(ly.N_DOF):
        for j in range(ly.N_DOF):
            acc += qd[i] * M[i, j] * qd[j]
    return 0.5 * acc
