"""Constrained dynamics of the 17 regimes (MODEL.md §7), jit-compiled.

A regime is a contact set (``rg[RG_SET]``, 0..8) and a stick flag.  Its
active rows are the normal rows W_n = dg/dq of the set's points and, when
sticking, the tangential row W_t = dtau/dq of the set's first point:

    stick:  M q'' = Q - h + W_n^T lambda_n + W_t^T lambda_t
    slip:   M q'' = Q - h + sum_k (W_n,k - mu_k sigma W_t)^T lambda_n,k
    both:   W q'' + W' q' = 0 for every active row

W_t is the tangential row of one point of the set (:func:`tangent_point`).
In a double contact the slipping friction, of magnitude mu_k sum lambda_n,
acts along that same row, where MODEL.md §7 writes one row per point.  The
deviation is deliberate: with per-point rows the friction force of a
double contact that starts to slip differs from the sticking force at the
threshold (the rows' moment arms differ), so neither regime is consistent
there and the run chatters between them (measured: a flood of stick-slip
events 0.42 s into a free-flight start).  With the shared row the force is
continuous at stick -> slip, as in the single contacts.

With rows A, force directions B (B = A when sticking) and the unconstrained
accelerations a0 = M^-1 (Q - h):

    q'' = a0 + X lambda,   X = M^-1 B^T,   (A X) lambda = -A' q' - A a0.

The same rows give the momentum transfer of an impact (MODEL.md §7):
q'+ = q'- + X P with (A X) P = -A q'-.  The dense systems are at most 3x3
and solved in place in the work array ``cw`` (layout ``CW_*``); a row that
vanishes on the free coordinates (a held coordinate) gets lambda = 0.

Drift of the active constraints is removed by :func:`project`: a
least-squares Newton projection of (s, v, psi) onto the active gaps and of
their rates onto the active rows.
"""
import numba as nb

from ..config import FRICTION_REL_EPS, JIT, JIT_INLINE, LAMBDA_EPS, RATE_EPS
from . import layout as ly
from .contact import fill_geometry, row_convective, row_rate, row_to_dof
from .dynamics import rhs, solve_factored


@nb.njit(**JIT_INLINE)
def _put_row(cw, r, cg, geometry_row, friction_row, friction):
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
def set_rows(set_index, stick, sign, tpt, P, cg, cw):
    """Rows A and force directions B (9-vectors) of a regime into cw; return their number.

    Row order: the normal rows of the set's first and second point, then,
    when sticking, the tangential row of the point ``tangent_point(set_index, tpt)``.
    """
    m = 0
    friction = 0.0 if stick else -P[ly.P_MU_K] * sign
    tangent = ly.CG_T + tangent_point(set_index, tpt)
    for which in range(2):
        p = ly.SET_FIRST[set_index] if which == 0 else ly.SET_SECOND[set_index]
        if p >= 0:
            _put_row(cw, m, cg, ly.CG_G + p, tangent, friction)
            m += 1
    if stick:
        _put_row(cw, m, cg, tangent, tangent, 0.0)
        m += 1
    return m


@nb.njit(**JIT_INLINE)
def tangent_point(set_index, tpt):
    """The point whose tangential row a sticking regime holds.

    The set's first point (MODEL.md §7), or its second when ``tpt`` is 1: a
    sticking double contact locks the joint whichever row is used, but the
    split of the contact forces depends on it.  :func:`settle` moves the row
    to the point that stays before it lets the other separate, so that the
    separation is consistent (the released gap then opens, by the Schur
    complement of the symmetric sticking system).
    """
    p2 = ly.SET_SECOND[set_index]
    return p2 if (tpt == 1 and p2 >= 0) else ly.SET_FIRST[set_index]


@nb.njit(**JIT_INLINE)
def row_geometry_index(set_index, stick, tpt, r):
    """The geometry row (CG_G + k or CG_T + k) behind constraint row r of a regime."""
    p1 = ly.SET_FIRST[set_index]
    p2 = ly.SET_SECOND[set_index]
    if r == 0:
        return ly.CG_G + p1
    if r == 1 and p2 >= 0:
        return ly.CG_G + p2
    return ly.CG_T + tangent_point(set_index, tpt)


@nb.njit(**JIT_INLINE)
def small_solve(cw, m):
    """Solve D x = c (m <= 3) held in rows CW_D.. of cw; x into column CW_L_COL.

    Gaussian elimination with partial pivoting.  An unknown whose pivot is
    negligible (below 1e-12 of the largest entry: a row that is zero on the
    free coordinates or dependent on the others) is set to 0.
    """
    scale = 0.0
    for i in range(m):
        for j in range(m):
            scale = max(scale, abs(cw[ly.CW_D + i, j]))
    tiny = 1e-12 * scale
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


@nb.njit(**JIT)
def rhs_regime(t, y, P, tab, kc, free, ex, rec, mat, vec, cg, cw, rg, ydot):
    """Right-hand side of the augmented state in the regime of ``rg``.

    Writes ydot (N_AUG,): (q', q'') and the powers integrated for the
    energy account (erg/s); the contact forces lambda (dyn) into rg.
    Returns a status code.
    """
    status = rhs(t, y, P, tab, kc, free, ex, rec, mat, vec, ydot)
    if status != ly.OK:
        return status
    qd = y[ly.N_DOF:ly.N_STATE]
    qdd = ydot[ly.N_DOF:ly.N_STATE]
    for k in range(ly.N_POINTS):
        rg[ly.RG_LN + k] = 0.0
    rg[ly.RG_LT] = 0.0
    rg[ly.RG_VGRAV] = vec[ly.VEC_AUX, ly.AUX_VGRAV]
    p_constr = 0.0
    p_fric = 0.0
    set_index = int(rg[ly.RG_SET])
    if set_index > 0:
        stick = rg[ly.RG_STICK] != 0.0
        sign = rg[ly.RG_SIGN]
        tpt = int(rg[ly.RG_TPT])
        fill_geometry(y, P, cg)
        m = set_rows(set_index, stick, sign, tpt, P, cg, cw)
        fill_delassus(free, mat, cw, m)
        for r in range(m):
            conv = row_convective(cg, row_geometry_index(set_index, stick, tpt, r), qd)
            cw[ly.CW_D + r, ly.CW_C_COL] = -conv - _dot9(cw[ly.CW_A + r], qdd)
        small_solve(cw, m)
        for r in range(m):
            lam = cw[ly.CW_D + r, ly.CW_L_COL]
            x = cw[ly.CW_X + r]
            for j in range(ly.N_DOF):
                qdd[j] += x[j] * lam
            p_constr += lam * _dot9(cw[ly.CW_A + r], qd)
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
            # friction force -mu_k sigma lambda_n W_t: dissipates mu_k sigma lambda_n tau'
            rate = row_rate(cg, ly.CG_T + tangent_point(set_index, tpt), qd)
            for which in range(n_normal):
                p = p1 if which == 0 else p2
                p_fric += P[ly.P_MU_K] * sign * rg[ly.RG_LN + p] * rate
    ydot[ly.A_WORK] = vec[ly.VEC_AUX, ly.AUX_P_EXT]
    ydot[ly.A_DAMP] = vec[ly.VEC_AUX, ly.AUX_P_DAMP]
    ydot[ly.A_CORK] = P[ly.P_CORK_C] * qd[ly.S] * qd[ly.S]
    ydot[ly.A_FRIC] = p_fric
    ydot[ly.A_CONSTR] = p_constr
    return ly.OK


@nb.njit(**JIT_INLINE)
def stick_margin(P, rg):
    """mu_s sum lambda_n - |lambda_t| (dyn): >= 0 while sticking holds."""
    total = 0.0
    for k in range(ly.N_POINTS):
        total += rg[ly.RG_LN + k]
    return P[ly.P_MU_S] * total - abs(rg[ly.RG_LT])


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
def _project_rows(y, offset, set_index, stick, tpt, rows, P, free, cg, cw):
    """One least-squares correction of y[offset + (S, V, PSI)] by the given rows.

    ``rows`` counts the rows used: the normal rows (1 or 2), plus 1 for the
    tangential row of a sticking regime.  The residuals are the gap values (offset 0) or
    the row rates (offset N_DOF).  Returns the largest residual (cm or cm/s).
    """
    ms = _free_mask(free, ly.S)
    mv = _free_mask(free, ly.V)
    mp = _free_mask(free, ly.PSI)
    qd = y[ly.N_DOF:ly.N_STATE]
    worst = 0.0
    for r in range(rows):
        g = row_geometry_index(set_index, stick, tpt, r)
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
    for i in range(rows):
        for j in range(rows):
            cw[ly.CW_D + i, j] = _dot9(cw[ly.CW_A + i], cw[ly.CW_A + j])
    small_solve(cw, rows)
    for r in range(rows):
        mu = cw[ly.CW_D + r, ly.CW_L_COL]
        for j in (ly.S, ly.V, ly.PSI):
            y[offset + j] -= cw[ly.CW_A + r, j] * mu
    return worst


@nb.njit(**JIT)
def project(y, P, free, cg, cw, rg):
    """Pull the state onto the active constraints of the regime in rg.

    Positions: two Newton steps onto the active gaps g = 0 (the gaps are
    nearly linear in (s, v, psi) over a step's drift).  Velocities: the
    active rows' rates (normal, and tangential when sticking) to zero.  Only
    free joint coordinates move.  Returns the largest |g| found before the
    projection (cm), the drift.
    """
    set_index = int(rg[ly.RG_SET])
    if set_index == 0:
        return 0.0
    n_normal = 1 if ly.SET_SECOND[set_index] < 0 else 2
    fill_geometry(y, P, cg)
    stick = rg[ly.RG_STICK] != 0.0
    tpt = int(rg[ly.RG_TPT])
    drift = _project_rows(y, 0, set_index, stick, tpt, n_normal, P, free, cg, cw)
    if drift > 0.0:
        fill_geometry(y, P, cg)
        if _project_rows(y, 0, set_index, stick, tpt, n_normal, P, free, cg, cw) > 0.0:
            fill_geometry(y, P, cg)
    rows = n_normal + (1 if stick else 0)
    _project_rows(y, ly.N_DOF, set_index, stick, tpt, rows, P, free, cg, cw)
    return drift


@nb.njit(**JIT)
def apply_impulse(set_index, stick, sign, tpt, qd_minus, qd_plus, P, free, mat, cg, cw):
    """Momentum transfer into a candidate regime: q'+ = q'- + M^-1 B^T P.

    (A M^-1 B^T) P = -A q'-, MODEL.md §7.  Geometry and M's factor must be
    current.  The impulses (dyn s) are left in cw[CW_D + r, CW_L_COL] in the
    row order of :func:`set_rows`; returns the number of rows.
    """
    m = set_rows(set_index, stick, sign, tpt, P, cg, cw)
    fill_delassus(free, mat, cw, m)
    for r in range(m):
        cw[ly.CW_D + r, ly.CW_C_COL] = -_dot9(cw[ly.CW_A + r], qd_minus)
    small_solve(cw, m)
    for j in range(ly.N_DOF):
        qd_plus[j] = qd_minus[j]
    for r in range(m):
        imp = cw[ly.CW_D + r, ly.CW_L_COL]
        for j in range(ly.N_DOF):
            qd_plus[j] += cw[ly.CW_X + r, j] * imp
    return m


@nb.njit(**JIT_INLINE)
def kinetic_energy(qd, mat):
    """1/2 q'^T M q' (erg) with M = mat[MAT_M]."""
    M = mat[ly.MAT_M]
    acc = 0.0
    for i in range(ly.N_DOF):
        for j in range(ly.N_DOF):
            acc += qd[i] * M[i, j] * qd[j]
    return 0.5 * acc


@nb.njit(**JIT)
def settle(t, y, P, tab, kc, free, ex, rec, mat, vec, cg, cw, rg, ydot):
    """Choose the consistent regime at y without a velocity jump (MODEL.md §7).

    Starts from the regime in rg.  Drops the point with the most negative
    lambda_n (separation; a sticking double contact first moves its
    tangential row to the staying point, see :func:`tangent_point`); turns stick into slip with sigma = -sign(lambda_t)
    when |lambda_t| > mu_s sum lambda_n; a slipping set takes the sign of
    its slip velocity unless that is below RATE_EPS.  Projects y onto the
    chosen regime and leaves its rhs in ydot.  Returns a status code.
    """
    for _ in range(12):
        set_index = int(rg[ly.RG_SET])
        if set_index > 0 and rg[ly.RG_STICK] == 0.0:
            fill_geometry(y, P, cg)
            rate = row_rate(cg, ly.CG_T + tangent_point(set_index, int(rg[ly.RG_TPT])),
                            y[ly.N_DOF:ly.N_STATE])
            if abs(rate) > RATE_EPS:
                rg[ly.RG_SIGN] = 1.0 if rate > 0.0 else -1.0
        project(y, P, free, cg, cw, rg)
        status = rhs_regime(t, y, P, tab, kc, free, ex, rec, mat, vec, cg, cw, rg, ydot)
        if status != ly.OK:
            return status
        if set_index == 0:
            return ly.OK
        p1 = ly.SET_FIRST[set_index]
        p2 = ly.SET_SECOND[set_index]
        worst = -1
        worst_val = -LAMBDA_EPS
        for p in (p1, p2):
            if p >= 0 and rg[ly.RG_LN + p] < worst_val:
                worst = p
                worst_val = rg[ly.RG_LN + p]
        if worst >= 0:
            keep = p2 if worst == p1 else p1
            if keep >= 0 and tangent_point(set_index, int(rg[ly.RG_TPT])) == worst:
                rg[ly.RG_TPT] = 1.0 if keep == p2 else 0.0   # hold the staying point's row
                continue
            rg[ly.RG_SET] = 0.0 if keep < 0 else float(keep + 1)   # set {keep + 1}
            rg[ly.RG_TPT] = 0.0
            continue
        if rg[ly.RG_STICK] != 0.0 and stick_margin(P, rg) < -0.5 * stick_tolerance(P, rg):
            rg[ly.RG_STICK] = 0.0
            rg[ly.RG_SIGN] = -1.0 if rg[ly.RG_LT] > 0.0 else 1.0
            continue
        return ly.OK
    return ly.ERR_NO_REGIME
