"""An exponential Runge-Kutta step (ETDRK4) with the regime's Jacobian frozen, jit-compiled.

Experiment (branch exp/etd-hybrid, not adopted): steps between events on the
sample lattice with the axial modes' linear part taken exactly.

On w = (y, t) (y the N_STATE components of the state, t the time), with L the
Jacobian of w' = (f(t, y), 1) of the current regime at some earlier state of
that regime (frozen), N(w) = F(w) - L w and Z = hL, Cox & Matthews' ETDRK4 in
increment form (Hochbruck & Ostermann, Acta Numerica 19 (2010), eq. 2.39):

    a = w + h/2 phi1(Z/2) F(w)
    b = a + h/2 phi1(Z/2) D_a
    c = a + e^(Z/2) (a - w) + h phi1(Z/2) D_b
    w_new = w + h phi1(Z) F(w) + h (2 phi2 - 4 phi3)(Z) (D_a + D_b) + h (4 phi3 - phi2)(Z) D_c

with D_x = F(x) - F(w) - L (x - w).  The energy account's components (no
linear part) take the classical RK4 weights, to which ETDRK4 reduces at L = 0.
The estimate is h (2 phi2 - 4 phi3)(Z) (D_a + D_b - D_c), the difference from the
exponential trapezoidal rule w + h phi1 F(w) + h phi2 D_c (ETD2RK with c as its
predictor), an estimate of order 3.
"""
import numba as nb
import numpy as np

from .config import JIT, JIT_ALLOC
from . import layout as ly
from .constrained import rhs_regime
from .pair import _stage_events_min, project_step_end

N = ly.N_STATE
NW = N + 1
#: The operators kept per regime: L, e^(Z/2), h/2 phi1(Z/2), h phi1(Z), h(2 phi2 - 4 phi3)(Z),
#: h(4 phi3 - phi2)(Z).
OP_L, OP_E2, OP_P1H, OP_P1, OP_B23, OP_B4, OP_MS, OP_MC = range(8)
N_OPS = 8
#: Regimes: contact set (0..8) x stick x slip sign.
N_KEYS = 9 * 4
#: opkey rows: per regime (time taken, h); row N_KEYS: (enabled, largest age (s)); row
#: N_KEYS + 1: (operators computed, exponential steps taken); row N_KEYS + 2: (fallbacks, -).
KEY_SET = N_KEYS
KEY_COUNT = N_KEYS + 1
KEY_FALL = N_KEYS + 2
KEY_MODE = N_KEYS + 3      # (samples a step, largest err, tolerance factor)
KEY_ARG = N_KEYS + 4
N_KEY_ROWS = N_KEYS + 4 + 80
#: Taylor series of degree DEGREE once ||Z / 2^s||_1 <= THETA (balanced).
THETA = 0.5
DEGREE = 13
INV_FACT = np.array([1.0 / np.prod(np.arange(1.0, j + 1.0)) for j in range(DEGREE + 4)])
#: scratch (N_SCRATCH, NW, NW): J, A, the powers, the products, the phi set, the balance.
SC_J = 0
SC_A = 1
SC_POW = 2
SC_PROD = SC_POW + DEGREE
SC_PHI = SC_PROD + 4
N_SCRATCH = SC_PHI + 8 + 1
FD_REL = 1e-7
#: The row of stages the state at the step's middle goes to.
STAGE_MID = 12
#: The row of stages the last-stage estimate goes to (compared by etd_step_check.py only).
STAGE_ALT_ERR = 13


def new_arrays(enabled, age_s):
    """The experiment's arrays: (ops, opkey, scratch)."""
    opkey = np.zeros((N_KEY_ROWS, 3))
    opkey[:N_KEYS, 0] = -np.inf
    opkey[KEY_SET, :2] = (1.0 if enabled else 0.0, age_s)
    return np.zeros((N_KEYS, N_OPS, NW, NW)), opkey, np.zeros((N_SCRATCH, NW, NW))


@nb.njit(**JIT)
def regime_key(rg):
    return int(rg[ly.RG_SET]) * 4 + (2 if rg[ly.RG_STICK] != 0.0 else 0) + (
        1 if rg[ly.RG_SIGN] > 0.0 else 0)


@nb.njit(**JIT)
def _balance(Z, d):
    """Parlett-Reinsch balancing in place: Z <- D^-1 Z D with d = diag(D), powers of 2."""
    n = Z.shape[0]
    for i in range(n):
        d[i] = 1.0
    for _ in range(20):
        done = True
        for i in range(n):
            c = 0.0
            r = 0.0
            for j in range(n):
                if j != i:
                    c += abs(Z[j, i])
                    r += abs(Z[i, j])
            if c == 0.0 or r == 0.0:
                continue
            f = 1.0
            s = c + r
            while c < r / 2.0:
                c *= 2.0
                r /= 2.0
                f *= 2.0
            while c >= r * 2.0:
                c /= 2.0
                r *= 2.0
                f /= 2.0
            if (c + r) < 0.95 * s:
                done = False
                d[i] *= f
                for j in range(n):
                    Z[i, j] /= f
                    Z[j, i] *= f
        if done:
            break


@nb.njit(**JIT_ALLOC)
def _matmul(a, b, c):
    np.dot(a, b, c)


@nb.njit(**JIT_ALLOC)
def phi_set(Z, sc):
    """sc[SC_PHI + 0..3] = phi_0..3(Z), sc[SC_PHI + 4..7] = phi_0..3(Z / 2); returns the
    squarings (Skaflestad & Wright, Appl. Numer. Math. 59 (2009), eq. 2.4)."""
    n = Z.shape[0]
    out = sc[SC_PHI:SC_PHI + 8]
    d = sc[SC_PHI + 8, 0]
    A = sc[SC_A]
    A[:, :] = Z
    _balance(A, d)
    norm = 0.0
    for j in range(n):
        s = 0.0
        for i in range(n):
            s += abs(A[i, j])
        norm = max(norm, s)
    sq = 0
    while norm > THETA:
        norm *= 0.5
        sq += 1
    sq = max(sq, 1)
    scale = 0.5 ** sq
    for i in range(n):
        for j in range(n):
            A[i, j] *= scale
    P = sc[SC_POW:SC_POW + DEGREE]
    P[0, :, :] = A
    for p in range(1, DEGREE):
        _matmul(P[p - 1], A, P[p])
    for k in range(4):
        phi = out[k]
        for i in range(n):
            for j in range(n):
                phi[i, j] = INV_FACT[k] if i == j else 0.0
        for p in range(DEGREE):
            c = INV_FACT[p + 1 + k]
            for i in range(n):
                for j in range(n):
                    phi[i, j] += c * P[p, i, j]
    prod = sc[SC_PROD:SC_PROD + 4]
    for level in range(sq):
        if level == sq - 1:
            out[4, :, :] = out[0]
            out[5, :, :] = out[1]
            out[6, :, :] = out[2]
            out[7, :, :] = out[3]
        for k in range(4):
            _matmul(out[0], out[k], prod[k])
        for i in range(n):
            for j in range(n):
                p1, p2, p3 = out[1, i, j], out[2, i, j], out[3, i, j]
                out[0, i, j] = prod[0, i, j]
                out[1, i, j] = 0.5 * (prod[1, i, j] + p1)
                out[2, i, j] = 0.25 * (prod[2, i, j] + p1 + p2)
                out[3, i, j] = 0.125 * (prod[3, i, j] + 0.5 * p1 + p2 + p3)
    for k in range(8):
        for i in range(n):
            for j in range(n):
                out[k, i, j] *= d[i] / d[j]
    return sq


@nb.njit(**JIT)
def jacobian(t, y, model, ex, work, J):
    """J (NW x NW) of w = (y, t) -> (f(t, y), 1) by forward differences in the regime of rg;
    k1 = f(t, y) in stages[STAGE_K1].  Uses stages[STAGE_TMP], [STAGE_KTRY].  Returns a
    status."""
    stages = work.stages
    f0 = stages[ly.STAGE_K1]
    buf = stages[ly.STAGE_TMP]
    f1 = stages[ly.STAGE_KTRY]
    for j in range(NW):
        for i in range(ly.N_AUG):
            buf[i] = y[i]
        tt = t
        if j < N:
            d = FD_REL * max(abs(y[j]), 1e-3)
            buf[j] += d
        else:
            d = FD_REL * max(abs(t), 1e-3)
            tt += d
        status = rhs_regime(tt, buf, model, ex, work, f1)
        if status != ly.OK:
            return status
        for i in range(N):
            J[i, j] = (f1[i] - f0[i]) / d
        J[N, j] = 0.0
    return ly.OK


@nb.njit(**JIT)
def operators(t, y, h, model, ex, work, ops, sc):
    """The operators of ETDRK4 for step h (s) at (t, y) in the regime of rg into ops (N_OPS,
    NW, NW).  Returns a status."""
    J = sc[SC_J]
    status = jacobian(t, y, model, ex, work, J)
    if status != ly.OK:
        return status
    for i in range(NW):
        for j in range(NW):
            ops[OP_L, i, j] = J[i, j]
            J[i, j] *= h
    phi_set(J, sc)
    phi = sc[SC_PHI:SC_PHI + 8]
    for i in range(NW):
        for j in range(NW):
            ops[OP_E2, i, j] = phi[4, i, j]
            ops[OP_P1H, i, j] = 0.5 * h * phi[5, i, j]
            ops[OP_P1, i, j] = h * phi[1, i, j]
            ops[OP_B23, i, j] = h * (2.0 * phi[2, i, j] - 4.0 * phi[3, i, j])
            ops[OP_B4, i, j] = h * (4.0 * phi[3, i, j] - phi[2, i, j])
            ops[OP_MS, i, j] = 0.5 * h * phi[6, i, j] - h * phi[7, i, j]
            ops[OP_MC, i, j] = h * phi[7, i, j] - 0.25 * h * phi[6, i, j]
    return ly.OK


@nb.njit(**JIT)
def _mv_add(M, x, xt, c, out):
    """out[:N] += c (M[:N, :N] x[:N] + M[:N, N] xt)."""
    for i in range(N):
        acc = M[i, N] * xt
        for j in range(N):
            acc += M[i, j] * x[j]
        out[i] += c * acc


@nb.njit(**JIT)
def _increment(Fx, Fw, L, x, y, dtx, D):
    """D = F(x) - F(w) - L (x - w) (state rows; dtx the time increment)."""
    for i in range(N):
        acc = L[i, N] * dtx
        for j in range(N):
            acc += L[i, j] * (x[j] - y[j])
        D[i] = Fx[i] - Fw[i] - acc


@nb.njit(**JIT)
def etd_step(t, y, h, model, ex, work, st, ops, y_new, mid):
    """One ETDRK4 step of h (s) from (t, y) into y_new as pair_step (:mod:`workbench.core.pair`):
    k1 in stages[STAGE_K1], f(t + h, y_new) into stages[s - 1], the estimate into
    stages[STAGE_ERR], the event functions' smallest values at the stages into ev[EV_MIN].
    ops: the regime's operators for this h.  With ``mid`` the state at t + h/2 into
    stages[STAGE_MID]: the continuous extension of the quadratic through N(w), N_m, N(c),
    w + h/2 phi1(Z/2) F(w) + h/4 phi2(Z/2) (2 S - D_c) + h/2 phi3(Z/2) (2 D_c - 2 S),
    S = D_a + D_b.  Returns a status."""
    P, free = model.P, model.free
    stages, cg, cw, rg, ev = work.stages, work.cg, work.cw, work.rg, work.ev
    s = int(P[ly.P_RK_STAGES])
    Fw = stages[ly.STAGE_K1]
    a, Fa, b, Fb, c, Fc = stages[1], stages[2], stages[3], stages[4], stages[5], stages[6]
    Da, Db, Dc, tmp = stages[7], stages[8], stages[9], stages[10]
    L = ops[OP_L]
    h2 = 0.5 * h
    for e in range(ly.N_EV):
        ev[ly.EV_MIN, e] = ev[ly.EV_START, e]
    for i in range(ly.N_AUG):
        a[i] = y[i] + (0.0 if i < N else h2 * Fw[i])
    _mv_add(ops[OP_P1H], Fw, 1.0, 1.0, a)
    status = rhs_regime(t + h2, a, model, ex, work, Fa)
    if status != ly.OK:
        return status
    _stage_events_min(a, P, free, cg, rg, ev)
    _increment(Fa, Fw, L, a, y, h2, Da)
    for i in range(ly.N_AUG):
        b[i] = a[i] if i < N else y[i] + h2 * Fa[i]
    _mv_add(ops[OP_P1H], Da, 0.0, 1.0, b)
    status = rhs_regime(t + h2, b, model, ex, work, Fb)
    if status != ly.OK:
        return status
    _stage_events_min(b, P, free, cg, rg, ev)
    _increment(Fb, Fw, L, b, y, h2, Db)
    for i in range(ly.N_AUG):
        c[i] = a[i] if i < N else y[i] + h * Fb[i]
        tmp[i] = a[i] - y[i]
    _mv_add(ops[OP_E2], tmp, h2, 1.0, c)
    _mv_add(ops[OP_P1H], Db, 0.0, 2.0, c)
    status = rhs_regime(t + h, c, model, ex, work, Fc)
    if status != ly.OK:
        return status
    _stage_events_min(c, P, free, cg, rg, ev)
    _increment(Fc, Fw, L, c, y, h, Dc)
    for i in range(ly.N_AUG):
        y_new[i] = y[i] if i < N else y[i] + h / 6.0 * (Fw[i] + 2.0 * (Fa[i] + Fb[i]) + Fc[i])
        tmp[i] = Da[i] + Db[i]
    _mv_add(ops[OP_P1], Fw, 1.0, 1.0, y_new)
    _mv_add(ops[OP_B23], tmp, 0.0, 1.0, y_new)
    _mv_add(ops[OP_B4], Dc, 0.0, 1.0, y_new)
    for i in range(ly.N_AUG):
        if not np.isfinite(y_new[i]):
            return ly.ERR_NAN
    project_step_end(y_new, P, free, cg, cw, rg, st)
    Fn = stages[s - 1]
    status = rhs_regime(t + h, y_new, model, ex, work, Fn)
    if status != ly.OK:
        return status
    if mid:
        ym = stages[STAGE_MID]
        for i in range(ly.N_AUG):
            if i < N:
                ym[i] = a[i]
                tmp[i] = Da[i] + Db[i]
            else:
                ym[i] = a[i] + h / 12.0 * (Fa[i] + Fb[i] - 2.0 * Fw[i]) + h / 24.0 * (Fc[i] - Fw[i])
        _mv_add(ops[OP_MS], tmp, 0.0, 1.0, ym)
        _mv_add(ops[OP_MC], Dc, 0.0, 1.0, ym)
    err = stages[ly.STAGE_ERR]
    for i in range(ly.N_AUG):
        err[i] = 0.0 if i < N else h / 3.0 * (Fa[i] + Fb[i] - Fc[i] - Fw[i])
        tmp[i] = Da[i] + Db[i] - Dc[i]
    _mv_add(ops[OP_B23], tmp, 0.0, 1.0, err)
    # for comparison only (etd_step_check.py): the last-stage estimate of classical RK4's kind,
    # h (4 phi3 - phi2)(Z) (D_new - D_c), into stages[STAGE_ALT_ERR]
    alt = stages[STAGE_ALT_ERR]
    _increment(Fn, Fc, L, y_new, c, 0.0, tmp)
    for i in range(ly.N_AUG):
        alt[i] = 0.0 if i < N else h / 6.0 * (Fn[i] - Fc[i])
    _mv_add(ops[OP_B4], tmp, 0.0, 1.0, alt)
    return ly.OK
