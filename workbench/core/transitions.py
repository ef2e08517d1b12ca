"""Transitions of the 17-regime model (docs/model.md §7), jit-compiled.

:func:`impact` is the momentum transfer: Moreau's impact law with e = 0
(:mod:`workbench.core.impact_law`) over the impact set, the point that
fired and every other point whose gap is within ``gap_tol`` of closing.
Each point contributes its normal row W_n = dg/dq and its tangential row
W_t = dtau/dq; G = W M^-1 W^T, u- = W q'-, q'+ = q'- + M^-1 W^T P.  The
new regime is read from the solution: the points that did not open form
the contact set; it sticks if every one of them sticks, else it slips in
the direction of the post-impact slip.

:func:`choose_regime` is the same problem at acceleration level: over the
closed points (gap within ``gap_tol``, normal rate within CLOSED_RATE of
zero) it enumerates the regimes (every subset of the points; stick, or
slip in the direction of the slip velocity, or from rest either way) and
takes the first consistent one: lambda_n >= 0 at the points kept, the
gap accelerations of the points let go >= 0, |lambda_t| <= mu_s sum
lambda_n when sticking, and a slip from rest accelerating in its own
direction.  The regime proposed by the transition is tried first.  When
none is consistent (Painlevé-type: the outward-sliding wedge), the state
is resolved by the impact law at zero approach (a tangential impact,
Génot & Brogliato 1999) and the choice is made again; what still has no
consistent regime takes the least violated one.  Both are counted in the
run statistics.
"""
import math

import numba as nb
import numpy as np

from .config import (CLOSED_RATE, GAP_EPS, GAP_TOL, JIT, JIT_INLINE, LAMBDA_EPS, REGIME_REL_TOL,
                     REST_RATE)
from . import layout as ly
from .constrained import (add_contact_forces, fill_delassus, kinetic_energy, project, rhs_regime,
                          stick_margin, stick_tolerance, tangent_point, _put_row)
from .contact import fill_geometry, in_set, row_convective, row_rate, set_of_pair
from .dynamics import rhs
from .impact_law import NOT_FOUND, OPEN, SLIP_POS, STICK, solve_impact



@nb.njit(**JIT_INLINE)
def _compatible(pts, m, p):
    """Whether point p can join the points pts[:m] in one contact set."""
    if m == 0:
        return True
    if m >= 2:
        return False
    return set_of_pair(int(pts[0]), p) > 0


@nb.njit(**JIT)
def closed_points(y, point, P, cg, rg, pts, gap_tol, rate_tol, lookahead):
    """The points of an impact or regime choice into pts; returns their number (<= 2).

    ``point`` first (if >= 0), then the active points of rg, then the open
    points nearest to closing with gap + lookahead * min(rate, 0) <=
    gap_tol and |normal rate| <= rate_tol (rate_tol < 0: any rate).
    """
    fill_geometry(y, P, cg)
    qd = y[ly.N_DOF:ly.N_STATE]
    m = 0
    for k in range(2):
        pts[k] = -1.0
    if point >= 0:
        pts[0] = point
        m = 1
    set_index = int(rg[ly.RG_SET])
    for p in (ly.SET_FIRST[set_index], ly.SET_SECOND[set_index]):
        if p >= 0 and p != point and _compatible(pts, m, p):
            pts[m] = p
            m += 1
    for _ in range(2):
        best = -1
        best_g = gap_tol
        for p in range(ly.N_POINTS):
            if (m > 0 and int(pts[0]) == p) or (m > 1 and int(pts[1]) == p):
                continue
            rate = row_rate(cg, ly.CG_G + p, qd)
            g = cg[ly.CG_G + p, ly.CG_VAL] + lookahead * min(rate, 0.0)
            if g <= best_g and _compatible(pts, m, p):
                if rate_tol >= 0.0 and abs(rate) > rate_tol:
                    continue
                best = p
                best_g = g
        if best >= 0:
            pts[m] = best
            m += 1
    return m


@nb.njit(**JIT)
def impact(y, point, P, free, mat, cg, cw, rg, gap_tol, a0, close_within, lookahead):
    """Momentum transfer at y over the impact set of ``point`` (-1: the closed points).

    M and its factor must be current at y.  Updates q' in y and the regime
    in rg (read from the solution, not yet chosen at acceleration level);
    leaves P in cw[CW_P] for the points in cw[CW_PTS] and the kinetic energy
    each point's impulses removed in cw[CW_LOSS] (they sum to the total:
    T- - T+ = -sum_r P_r (u-_r + u+_r) / 2 over the rows, normal and
    tangential, of the points).

    ``close_within`` > 0 (s) closes an accumulation (docs/model.md §7): a point
    of the set that leaves the impact slower than its free gap acceleration
    (from the free accelerations a0, 9 values) brings it back within that
    time is held closed: one more normal impulse brings the normal rates
    of the set to zero (it removes kinetic energy:
    u^T G_nn^-1 u / 2).  Returns ``(status, number of points, kinetic
    energy lost (erg))``.
    """
    pts = cw[ly.CW_PTS]
    m = closed_points(y, point, P, cg, rg, pts, gap_tol, np.float64(-1.0), lookahead)
    if m == 0:
        return ly.OK, 0, 0.0
    qd = y[ly.N_DOF:ly.N_STATE]
    u = cw[ly.CW_U]
    mu = cw[ly.CW_MU]
    for i in range(m):
        p = int(pts[i])
        _put_row(cg, cw, 2 * i, ly.CG_G + p, ly.CG_G + p, 0.0)
        _put_row(cg, cw, 2 * i + 1, ly.CG_T + p, ly.CG_T + p, 0.0)
        u[2 * i] = row_rate(cg, ly.CG_G + p, qd)
        u[2 * i + 1] = row_rate(cg, ly.CG_T + p, qd)
        mu[i] = P[ly.P_MU_K]
    fill_delassus(free, mat, cw, 2 * m)
    G = cw[ly.CW_D:ly.CW_D + ly.MAX_ROWS]
    imp = cw[ly.CW_P]
    modes = cw[ly.CW_MODES]
    source = solve_impact(G, u, mu, m, cw[ly.CW_LAW:ly.CW_LAW + ly.N_LAW], imp, modes)
    if source == NOT_FOUND:
        return ly.ERR_NO_IMPACT_CANDIDATE, m, 0.0
    ke_minus = kinetic_energy(qd, mat)
    for r in range(2 * m):
        x = cw[ly.CW_X + r]
        for j in range(ly.N_DOF):
            qd[j] += x[j] * imp[r]
    if close_within > 0.0:
        _close_accumulation(y, P, cg, cw, pts, m, modes, a0, close_within)
    ke_plus = kinetic_energy(qd, mat)
    for i in range(m):
        p = int(pts[i])
        un = row_rate(cg, ly.CG_G + p, qd)
        ut = row_rate(cg, ly.CG_T + p, qd)
        cw[ly.CW_LOSS, i] = -(imp[2 * i] * (u[2 * i] + un)
                              + imp[2 * i + 1] * (u[2 * i + 1] + ut)) / 2.0
    # the new regime: the points that did not open
    first = -1
    second = -1
    stick = True
    sign = 0.0
    for i in range(m):
        if modes[i] == OPEN:
            continue
        p = int(pts[i])
        if first < 0:
            first = p
        else:
            second = p
        if modes[i] != STICK:
            stick = False
            if sign == 0.0:
                sign = 1.0 if modes[i] == SLIP_POS else -1.0
    set_index = 0
    if first >= 0:
        set_index = first + 1 if second < 0 else set_of_pair(first, second)
    rg[ly.RG_SET] = set_index
    rg[ly.RG_STICK] = 1.0 if (stick and set_index > 0) else 0.0
    rg[ly.RG_SIGN] = sign if sign != 0.0 else 1.0
    if set_index > 0 and not stick:
        rate = row_rate(cg, ly.CG_T + tangent_point(set_index), qd)
        if abs(rate) > REST_RATE:
            rg[ly.RG_SIGN] = 1.0 if rate > 0.0 else -1.0
    return ly.OK, m, ke_minus - ke_plus


@nb.njit(**JIT)
def book_losses(st, cw, n_pts, lost):
    """Add an impact's kinetic energy lost (erg; :func:`impact`) to the run's statistics: the
    total to st[ST_E_IMPACT], each point's part to st[ST_E_IMPACT_P + k]."""
    st[ly.ST_E_IMPACT] += lost
    for i in range(n_pts):
        st[ly.ST_E_IMPACT_P + int(cw[ly.CW_PTS, i])] += cw[ly.CW_LOSS, i]


@nb.njit(**JIT)
def _close_accumulation(y, P, cg, cw, pts, m, modes, a0, close_within):
    """Hold closed the points of an accumulation that leave slowly (see :func:`impact`).

    Rows, X = M^-1 W^T and G of the impact are still in cw.  Normal rows
    only: G_nn dP = -u_n+ over the points held; their tangential rates are
    left to the regime choice.
    """
    qd = y[ly.N_DOF:ly.N_STATE]
    held = 0
    for i in range(m):
        p = int(pts[i])
        un = row_rate(cg, ly.CG_G + p, qd)
        an = _gap_acceleration(cg, p, qd, a0)
        if modes[i] == OPEN and not (0.0 <= un <= -an * close_within):
            return
        if modes[i] == OPEN:
            held += 1
    if held == 0:
        return
    # G_nn restricted to the set's normal rows: rows 0 and 2 of G (columns too)
    G = cw[ly.CW_D:ly.CW_D + ly.MAX_ROWS]
    u0 = row_rate(cg, ly.CG_G + int(pts[0]), qd)
    if m == 1:
        dp0 = -u0 / G[0, 0]
        dp1 = 0.0
    else:
        u1 = row_rate(cg, ly.CG_G + int(pts[1]), qd)
        det = G[0, 0] * G[2, 2] - G[0, 2] * G[2, 0]
        dp0 = (-u0 * G[2, 2] + u1 * G[0, 2]) / det
        dp1 = (-u1 * G[0, 0] + u0 * G[2, 0]) / det
    for j in range(ly.N_DOF):
        qd[j] += cw[ly.CW_X + 0, j] * dp0 + (cw[ly.CW_X + 2, j] * dp1 if m > 1 else 0.0)
    cw[ly.CW_P, 0] += dp0
    if m > 1:
        cw[ly.CW_P, 2] += dp1
    for i in range(m):
        if modes[i] == OPEN:
            modes[i] = STICK if abs(row_rate(cg, ly.CG_T + int(pts[i]), qd)) <= REST_RATE \
                else SLIP_POS


@nb.njit(**JIT_INLINE)
def _gap_acceleration(cg, p, qd, qdd):
    return row_rate(cg, ly.CG_G + p, qdd) + row_convective(cg, ly.CG_G + p, qd)


@nb.njit(**JIT)
def _violation(y, P, free, cg, rg, ydot, pts, m, slip_from_rest):
    """How far the regime in rg (forces in rg, q'' in ydot) is from consistent (<= 0: consistent).

    Normalised by the scales of the contact forces and the accelerations.
    """
    qd = y[ly.N_DOF:ly.N_STATE]
    qdd = ydot[ly.N_DOF:ly.N_STATE]
    set_index = int(rg[ly.RG_SET])
    f_scale = LAMBDA_EPS
    for k in range(ly.N_POINTS):
        f_scale = max(f_scale, abs(rg[ly.RG_LN + k]))
    f_scale = max(f_scale, abs(rg[ly.RG_LT]))
    a_scale = 1e-9
    for i in range(m):
        a_scale = max(a_scale, abs(_gap_acceleration(cg, int(pts[i]), qd, qdd)))
    stick = set_index > 0 and rg[ly.RG_STICK] != 0.0
    double_stick = stick and ly.SET_SECOND[set_index] >= 0
    worst = -1.0
    for i in range(m):
        p = int(pts[i])
        if in_set(set_index, p):
            if double_stick:
                continue        # the split of the forces is in the stick margin
            v = -(rg[ly.RG_LN + p] + LAMBDA_EPS) / f_scale
        else:
            v = -_gap_acceleration(cg, p, qd, qdd) / a_scale
        worst = max(worst, v)
    if set_index > 0:
        if stick:
            margin = stick_margin(P, free, cg, rg)
            worst = max(worst, -(margin + 0.5 * stick_tolerance(P, rg)) / f_scale)
        elif slip_from_rest:
            g = ly.CG_T + tangent_point(set_index)
            at = row_rate(cg, g, qdd) + row_convective(cg, g, qd)
            worst = max(worst, -rg[ly.RG_SIGN] * at / max(a_scale, abs(at)))
    return worst - REGIME_REL_TOL


@nb.njit(**JIT)
def _evaluate(y, model, work, a0, ydot, pts, m, set_index, stick, sign, slip_from_rest):
    """Contact forces of one candidate regime from the free accelerations a0; its violation."""
    P, free = model.P, model.free
    mat, cg, cw, rg = work.mat, work.cg, work.cw, work.rg
    rg[ly.RG_SET] = set_index
    rg[ly.RG_STICK] = 1.0 if stick else 0.0
    rg[ly.RG_SIGN] = sign
    for j in range(ly.N_DOF):
        ydot[ly.N_DOF + j] = a0[j]
    add_contact_forces(y, P, free, mat, cg, cw, rg, ydot)
    return _violation(y, P, free, cg, rg, ydot, pts, m, slip_from_rest)


@nb.njit(**JIT)
def _enumerate(y, model, work, a0, ydot, pts, m, best):
    """Try the proposed regime (in rg), then every regime over pts; the first consistent wins.

    best (3,) receives (set, stick, sign) of the consistent regime or,
    if there is none, of the least violated.  Returns True if consistent.
    """
    P = model.P
    cg, rg = work.cg, work.rg
    qd = y[ly.N_DOF:ly.N_STATE]
    p_set = int(rg[ly.RG_SET])
    p_stick = rg[ly.RG_STICK] != 0.0
    p_sign = rg[ly.RG_SIGN]
    best_v = 1e300
    # the proposal, if its points are all closed
    ok_prop = True
    for p in (ly.SET_FIRST[p_set], ly.SET_SECOND[p_set]):
        if p >= 0 and not ((m > 0 and int(pts[0]) == p) or (m > 1 and int(pts[1]) == p)):
            ok_prop = False
    n_subsets = 1 << m
    for trial in range(-1, n_subsets):
        if trial == -1:
            if not ok_prop:
                continue
            set_index = p_set
        else:
            # subsets largest first: trial 0 is all points, the last is none
            mask = n_subsets - 1 - trial
            first = -1
            second = -1
            for i in range(m):
                if mask & (1 << i):
                    if first < 0:
                        first = int(pts[i])
                    else:
                        second = int(pts[i])
            set_index = 0
            if first >= 0:
                set_index = first + 1 if second < 0 else set_of_pair(first, second)
                if set_index < 0:
                    continue
        if set_index == 0:
            v = _evaluate(y, model, work, a0, ydot, pts, m, np.int64(0), np.bool_(False), 1.0,
                          np.bool_(False))
            if v < best_v:
                best_v = v
                best[0], best[1], best[2] = 0.0, 0.0, 1.0
            if v <= 0.0:
                return True
            continue
        fill_geometry(y, P, cg)
        rate = row_rate(cg, ly.CG_T + tangent_point(set_index), qd)
        at_rest = abs(rate) <= REST_RATE
        # modes: 0 stick, 1 slip +, 2 slip -
        for mode in range(3):
            if trial == -1:
                if mode > 0:
                    break
                stick = p_stick
                sign = p_sign
                if not stick and not at_rest:
                    sign = 1.0 if rate > 0.0 else -1.0
                if stick and not at_rest:
                    continue
            else:
                stick = mode == 0
                sign = 1.0 if mode != 2 else -1.0
                if stick and not at_rest:
                    continue
                if not stick and not at_rest:
                    if (rate > 0.0) != (mode == 1):
                        continue
            v = _evaluate(y, model, work, a0, ydot, pts, m, set_index, stick, sign,
                          (not stick) and at_rest)
            if v < best_v:
                best_v = v
                best[0] = set_index
                best[1] = 1.0 if stick else 0.0
                best[2] = sign
            if v <= 0.0:
                return True
    return False


@nb.njit(**JIT)
def choose_regime(t, y, model, ex, work, ydot, st, gap_tol):
    """Choose the consistent regime at y (docs/model.md §7 "Choosing the regime").

    The regime in rg is the proposal.  Projects y onto the chosen regime
    and leaves its right-hand side in ydot and its forces in rg.  A state
    with no consistent regime is resolved by the impact law at zero
    approach (counted in st[ST_N_INCONSISTENT], its energy in
    st[ST_E_INCONSISTENT] and st[ST_E_IMPACT]); if none is consistent even
    then, the least violated regime is taken (st[ST_N_UNRESOLVED]).
    Returns a status code (errors only for NaN or a singular mass matrix).
    """
    P, tab, kc, free = model.P, model.tab, model.kc, model.free
    rec, mat, vec = work.rec, work.mat, work.vec
    stages, cg, cw, rg = work.stages, work.cg, work.cw, work.rg
    a0 = stages[ly.STAGE_QD]
    best = cw[ly.CW_MODES]
    pts = cw[ly.CW_PTS]
    for attempt in range(2):
        status = rhs(t, y, P, tab, kc, free, ex, rec, mat, vec, ydot)
        if status != ly.OK:
            return status
        for j in range(ly.N_DOF):
            a0[j] = ydot[ly.N_DOF + j]
        m = closed_points(y, np.int64(-1), P, cg, rg, pts, gap_tol, CLOSED_RATE, np.float64(0.0))
        consistent = _enumerate(y, model, work, a0, ydot, pts, m, best)
        rg[ly.RG_SET] = best[0]
        rg[ly.RG_STICK] = best[1]
        rg[ly.RG_SIGN] = best[2]
        if consistent or attempt == 1 or m == 0:
            if not consistent:
                st[ly.ST_N_UNRESOLVED] += 1.0
            break
        # no consistent regime: the impact law at zero approach over the closed points
        status, n_pts, lost = impact(y, np.int64(-1), P, free, mat, cg, cw, rg, gap_tol, a0, np.float64(0.0), np.float64(0.0))
        if status != ly.OK:
            return status
        st[ly.ST_N_INCONSISTENT] += 1.0
        st[ly.ST_E_INCONSISTENT] += lost
        book_losses(st, cw, n_pts, lost)
    project(y, P, free, cg, cw, rg, np.bool_(True))
    arm_gaps(y, P, cg, rg)
    return rhs_regime(t, y, model, ex, work, ydot)


@nb.njit(**JIT)
def arm_gaps(y, P, cg, rg):
    """Arm the impact events of the open points at y (rg[RG_ARM + k], cm).

    An impact fires when g_k falls below -GAP_EPS; a point released at a
    gap already below that (the event that released it was located just
    past zero) fires below its release depth instead, so that it is
    watched from the start.
    """
    fill_geometry(y, P, cg)
    set_index = int(rg[ly.RG_SET])
    for p in range(ly.N_POINTS):
        g = cg[ly.CG_G + p, ly.CG_VAL]
        rg[ly.RG_ARM + p] = GAP_EPS
        if not in_set(set_index, p) and g < 0.0:
            rg[ly.RG_ARM + p] = GAP_EPS - g


@nb.njit(**JIT)
def moreau_jean_step(t, h, model, ex, work, st):
    """One Moreau-Jean step (theta = 1/2) of h (s) from STAGE_CUR, in place (docs/model.md §7).

    Acary & Brogliato (2008), §10.1: q_m = q + h/2 q'; the free velocity
    v_f = q' + h M(q_m)^-1 (Q - h)(t + h/2, q_m, q'); the impact law over
    the points whose gap at q_m is within GAP_TOL gives v+ = v_f +
    M^-1 W^T P; q+ = q_m + h/2 v+.  The energy integrals take the midpoint
    powers; the kinetic energy the impulses remove is counted in
    st[ST_E_STEPPED] and st[ST_E_IMPACT].  Leaves the regime read from the
    impulses in rg (to be chosen again).  Returns a status.
    """
    P, tab, kc, free = model.P, model.tab, model.kc, model.free
    rec, mat, vec = work.rec, work.mat, work.vec
    stages, cg, cw, rg = work.stages, work.cg, work.cw, work.rg
    y = stages[ly.STAGE_CUR]
    ym = stages[ly.STAGE_TRY]
    k = stages[ly.STAGE_KTRY]
    for i in range(ly.N_AUG):
        ym[i] = y[i]
    for i in range(ly.N_DOF):
        ym[i] = y[i] + 0.5 * h * y[ly.N_DOF + i]
    status = rhs(t + 0.5 * h, ym, P, tab, kc, free, ex, rec, mat, vec, k)
    if status != ly.OK:
        return status
    sd = ym[ly.N_DOF + ly.S]
    ym[ly.A_WORK] += h * vec[ly.VEC_AUX, ly.AUX_P_EXT]
    ym[ly.A_DAMP] += h * vec[ly.VEC_AUX, ly.AUX_P_DAMP]
    ym[ly.A_CORK] += h * P[ly.P_CORK_C] * sd * sd
    for i in range(ly.N_DOF):
        ym[ly.N_DOF + i] += h * k[ly.N_DOF + i]
    rg[ly.RG_SET] = 0.0
    status, n_pts, lost = impact(ym, np.int64(-1), P, free, mat, cg, cw, rg, GAP_TOL,
                                 k[ly.N_DOF:ly.N_STATE], h, 0.5 * h)
    if status != ly.OK:
        return status
    st[ly.ST_E_STEPPED] += lost
    book_losses(st, cw, n_pts, lost)
    st[ly.ST_N_STEPPED] += 1.0
    for i in range(ly.N_DOF):
        y[i] = ym[i] + 0.5 * h * ym[ly.N_DOF + i]
    for i in range(ly.N_DOF, ly.N_AUG):
        y[i] = ym[i]
    for i in range(ly.N_AUG):
        if not math.isfinite(y[i]):
            return ly.ERR_NAN
    return ly.OK
