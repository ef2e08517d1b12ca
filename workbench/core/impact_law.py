"""Moreau's impact law with Coulomb friction for at most two points (docs/model.md §7).

The law alone, without the model's geometry: the points' normal and
tangential rows enter only through the Delassus matrix G = W M^-1 W^T and
the pre-impact rates u- = W q'-.  Rows are ordered (n_1, t_1, n_2, t_2);
the impulses P in the same order give u+ = u- + G P and
q'+ = q'- + M^-1 W^T P.  At every point (Moreau 1988; Glocker & Pfeiffer;
Stewart & Trinkle 1996, restitution e = 0):

    0 <= u_n+  _|_  P_n >= 0                 (plastic: stays closed or leaves)
    |P_t| <= mu P_n,  u_t+ != 0  =>  P_t = -mu P_n sign(u_t+)   (post-impact slip)

Per point the solution is in one of four modes: open (P = 0, u_n+ >= 0),
stick (u_n+ = u_t+ = 0, |P_t| <= mu P_n) or slip+/slip- (u_n+ = 0,
P_t = -+mu P_n, u_t+ of the slip's sign).  :func:`solve_impact` enumerates
the 4^m mode combinations, keeps the consistent ones and returns the most
dissipative, T+ - T- = P^T u- + P^T G P / 2 <= 0.  When both points stick
and their tangential rows are dependent (a flat double contact, or any
double contact of the loose joint, whose rows live in the three joint
coordinates) the system is singular along one direction that changes the
impulses and not the velocities; the impulse is then chosen along that
direction so that every condition holds, if any choice does (the two rows
handled as one).  If no combination is consistent (round-off at a
degenerate state), the same problem posed as the standard linear
complementarity problem (Stewart & Trinkle 1996; per point P_n, beta+,
beta-, and the slip speed) is solved by Lemke's complementary pivoting, whose
result is kept only if it satisfies the law to LEMKE_CHECK_TOL.
"""
import math

import numba as nb
import numpy as np

from .config import (CONSISTENCY_REL, ENERGY_TIE_REL, JIT, JIT_INLINE, LAW_RANK_TOL, LAW_REL_TOL,
                     LEMKE_CHECK_TOL, OPEN_RATE_REL, SLOPE_REL, SLOPE_ROUND_OFF)
from . import layout as ly

OPEN, STICK, SLIP_POS, SLIP_NEG = 0, 1, 2, 3
#: Solution sources returned by :func:`solve_impact`.
FOUND_ENUMERATION, FOUND_LEMKE, NOT_FOUND = 1, 2, 0


@nb.njit(**JIT_INLINE)
def _sigma(mode):
    return 1.0 if mode == SLIP_POS else -1.0


@nb.njit(**JIT_INLINE)
def _mode_of(combo, i):
    """Mode of point i in enumeration index combo (modes in the order stick, slip+, slip-, open)."""
    code = (combo >> (2 * i)) & 3
    return (STICK, SLIP_POS, SLIP_NEG, OPEN)[code]


@nb.njit(**JIT_INLINE)
def _inside(lo, hi):
    """The middle of [lo, hi], or where unbounded the point of the interval nearest 0."""
    if lo > -1e299 and hi < 1e299:
        return 0.5 * (lo + hi)
    if lo > -1e299:
        return max(lo, 0.0)
    if hi < 1e299:
        return min(hi, 0.0)
    return 0.0


@nb.njit(**JIT)
def _combo_impulse(G, u, mu, m, modes, lw, P):
    """Impulses P (2m) of one mode combination that satisfy every condition, if any.

    lw is scratch (>= 12 rows of >= 10 columns).  Returns True when a
    consistent P was found.
    """
    # unknowns z: P_n of each closed point, then P_t of each sticking point;
    # E (2m x k) maps z to P; the equations are the rows of the closed normals
    # and the sticking tangents: (G E)[rows] z = -u[rows]
    E = lw[0:4]
    A = lw[4:8]
    k = 0
    for r in range(2 * m):
        for j in range(4):
            E[r, j] = 0.0
    rows = 0
    eq = lw[8]          # eq[j]: the row of equation j
    for i in range(m):
        if modes[i] != OPEN:
            E[2 * i, k] = 1.0
            if modes[i] != STICK:
                E[2 * i + 1, k] = -_sigma(modes[i]) * mu[i]
            eq[rows] = 2 * i
            rows += 1
            k += 1
    for i in range(m):
        if modes[i] == STICK:
            E[2 * i + 1, k] = 1.0
            eq[rows] = 2 * i + 1
            rows += 1
            k += 1
    z0 = lw[9]
    dz = lw[10]
    for j in range(4):
        z0[j] = 0.0
        dz[j] = 0.0
    if k > 0:
        # A z = b with A = (G E)[eq], b = -u[eq] in A's column k
        for a in range(k):
            r = int(eq[a])
            for j in range(k):
                acc = 0.0
                for c in range(2 * m):
                    acc += G[r, c] * E[c, j]
                A[a, j] = acc
            A[a, k] = -u[r]
        g_max = 0.0
        for r in range(2 * m):
            for c in range(2 * m):
                g_max = max(g_max, abs(G[r, c]))
        if not _solve_with_null(A, np.int64(k), z0, dz, lw[11], g_max):
            return False
    # P(alpha) = E (z0 + alpha dz): every condition is c + d alpha >= 0
    u_scale = 0.0
    g_scale = 0.0
    for r in range(2 * m):
        u_scale = max(u_scale, abs(u[r]))
        g_scale = max(g_scale, abs(G[r, r]))
    tol_u = LAW_REL_TOL * u_scale + 1e-300
    tol_p = tol_u / max(g_scale, 1e-300)
    lo = -1e300
    hi = 1e300
    P0 = lw[11]
    dP = lw[8]          # eq no longer needed
    for r in range(2 * m):
        a0 = 0.0
        a1 = 0.0
        for j in range(k):
            a0 += E[r, j] * z0[j]
            a1 += E[r, j] * dz[j]
        P0[r] = a0
        dP[r] = a1
    for i in range(m):
        n = 2 * i
        t = n + 1
        if modes[i] == OPEN:
            un0, un1, un1_abs = _rate(G, u, P0, dP, m, n)
            lo, hi = _clip(un0 + tol_u, un1, un1_abs, lo, hi)
            continue
        lo, hi = _clip(P0[n] + tol_p, dP[n], abs(dP[n]), lo, hi)
        if modes[i] == STICK:
            # |P_t| <= mu P_n: mu P_n - P_t >= 0 and mu P_n + P_t >= 0
            d_abs = mu[i] * abs(dP[n]) + abs(dP[t])
            lo, hi = _clip(mu[i] * P0[n] - P0[t] + tol_p, mu[i] * dP[n] - dP[t], d_abs, lo, hi)
            lo, hi = _clip(mu[i] * P0[n] + P0[t] + tol_p, mu[i] * dP[n] + dP[t], d_abs, lo, hi)
        else:
            ut0, ut1, ut1_abs = _rate(G, u, P0, dP, m, t)
            s = _sigma(modes[i])
            lo, hi = _clip(s * ut0 + tol_u, s * ut1, ut1_abs, lo, hi)
    if lo > hi:
        return False
    alpha = _inside(lo, hi)
    for r in range(2 * m):
        P[r] = P0[r] + alpha * dP[r]
    return True


@nb.njit(**JIT_INLINE)
def _rate(G, u, P0, dP, m, r):
    """Row r of u + G P(alpha) as (value at alpha = 0, slope, sum of the slope's |terms|)."""
    a0 = u[r]
    a1 = 0.0
    a1_abs = 0.0
    for c in range(2 * m):
        a0 += G[r, c] * P0[c]
        a1 += G[r, c] * dP[c]
        a1_abs += abs(G[r, c] * dP[c])
    return a0, a1, a1_abs


@nb.njit(**JIT_INLINE)
def _clip(c, d, d_abs, lo, hi):
    """Intersect [lo, hi] with {alpha: c + d alpha >= 0}.

    d_abs is the sum of the magnitudes of the terms that make up the slope
    d: a slope within SLOPE_ROUND_OFF of it is round-off of a row that does
    not change along the null direction, and counts as zero (its ratio -c/d
    would be an arbitrary bound).
    """
    scale = abs(c) + 1e-300
    if abs(d) <= SLOPE_REL * scale or abs(d) <= SLOPE_ROUND_OFF * d_abs:
        if c < 0.0:
            return 1.0, -1.0
        return lo, hi
    x = -c / d
    if d > 0.0:
        return max(lo, x), hi
    return lo, min(hi, x)


@nb.njit(**JIT)
def _solve_with_null(A, k, z0, dz, piv_row, g_max):
    """Solve A[:k, :k] z = A[:, k] (in place): a particular z0 and, if rank k - 1, a null dz.

    Gaussian elimination with full pivoting; a pivot below LAW_RANK_TOL of
    the largest entry of A or of the Delassus matrix (g_max) counts as zero
    (a row with no mobility).  Returns False if the rank is below k - 1 or
    the system is inconsistent.
    """
    scale = 0.0
    for i in range(k):
        for j in range(k):
            scale = max(scale, abs(A[i, j]))
    tiny = LAW_RANK_TOL * max(scale, g_max)
    if scale <= tiny:
        return False
    for j in range(k):
        piv_row[j] = j           # column permutation: position j holds unknown piv_row[j]
    rank = 0
    for col in range(k):
        # full pivot over the remaining block
        best = 0.0
        bi = col
        bj = col
        for i in range(col, k):
            for j in range(col, k):
                if abs(A[i, j]) > best:
                    best = abs(A[i, j])
                    bi = i
                    bj = j
        if best <= tiny:
            break
        if bi != col:
            for j in range(k + 1):
                tmp = A[col, j]
                A[col, j] = A[bi, j]
                A[bi, j] = tmp
        if bj != col:
            for i in range(k):
                tmp = A[i, col]
                A[i, col] = A[i, bj]
                A[i, bj] = tmp
            tmp = piv_row[col]
            piv_row[col] = piv_row[bj]
            piv_row[bj] = tmp
        for i in range(col + 1, k):
            f = A[i, col] / A[col, col]
            if f != 0.0:
                for j in range(col, k + 1):
                    A[i, j] -= f * A[col, j]
        rank += 1
    if rank < k - 1:
        return False
    rhs_scale = 0.0
    for i in range(k):
        rhs_scale = max(rhs_scale, abs(A[i, k]))
    for i in range(rank, k):
        if abs(A[i, k]) > CONSISTENCY_REL * rhs_scale + 1e-300:
            return False         # inconsistent
    # particular solution (free unknown 0) and the null direction (free unknown 1)
    for which in range(2):
        if which == 1 and rank == k:
            break
        out = z0 if which == 0 else dz
        for j in range(k):
            out[j] = 0.0
        xs = 0.0
        if rank < k:
            xs = 0.0 if which == 0 else 1.0
        for i in range(rank - 1, -1, -1):
            acc = A[i, k] if which == 0 else 0.0
            if rank < k:
                acc -= A[i, k - 1] * xs
            for j in range(i + 1, rank):
                acc -= A[i, j] * out[int(piv_row[j])]
            out[int(piv_row[i])] = acc / A[i, i]
        if rank < k:
            out[int(piv_row[k - 1])] = xs
    return True


@nb.njit(**JIT_INLINE)
def energy_change(G, u, P, m):
    """T+ - T- = P^T u- + P^T G P / 2 of impulses P (erg, for G in 1/g and P in dyn s)."""
    acc = 0.0
    for r in range(2 * m):
        gp = 0.0
        for c in range(2 * m):
            gp += G[r, c] * P[c]
        acc += P[r] * (u[r] + 0.5 * gp)
    return acc


@nb.njit(**JIT)
def solve_impact(G, u, mu, m, lw, P, modes):
    """Moreau's impact law at m (1 or 2) points: the most dissipative consistent P.

    G (>= 2m x 2m) the Delassus matrix in the row order (n1, t1, n2, t2)
    (1/g, cm/(g s) ... per unit impulse), u (2m) the pre-impact rates
    (cm/s), mu (m) the friction coefficients.  Writes P (2m, dyn s) and
    modes (m: OPEN, STICK, SLIP_POS, SLIP_NEG).  lw is scratch of at least
    (12 + 4 m) rows and (4 m + 2) columns.  Returns FOUND_ENUMERATION,
    FOUND_LEMKE or NOT_FOUND (then P = 0).
    """
    trial = lw[12]
    best_de = 1e300
    found = False
    n_combo = 1 << (2 * m)
    for combo in range(n_combo):
        for i in range(m):
            modes[i] = _mode_of(combo, i)
        if not _combo_impulse(G, u, mu, m, modes, lw, trial):
            continue
        de = energy_change(G, u, trial, m)
        scale = 0.0
        for r in range(2 * m):
            scale = max(scale, abs(trial[r] * u[r]))
        if not found or de < best_de - ENERGY_TIE_REL * scale:
            found = True
            best_de = de
            for r in range(2 * m):
                P[r] = trial[r]
            lw[13, 0] = combo
    if found:
        combo = int(lw[13, 0])
        for i in range(m):
            modes[i] = _mode_of(combo, i)
        return FOUND_ENUMERATION
    if lemke_impact(G, u, mu, m, lw, P):
        classify(G, u, P, m, modes)
        return FOUND_LEMKE
    for r in range(2 * m):
        P[r] = 0.0
    for i in range(m):
        modes[i] = OPEN
    return NOT_FOUND


@nb.njit(**JIT_INLINE)
def _post_rates(G, u, P, m, i):
    """Point i's post-impact normal and tangential rates (u + G P)_n, (u + G P)_t (cm/s)."""
    n = 2 * i
    un = u[n]
    ut = u[n + 1]
    for c in range(2 * m):
        un += G[n, c] * P[c]
        ut += G[n + 1, c] * P[c]
    return un, ut


@nb.njit(**JIT)
def classify(G, u, P, m, modes):
    """Modes of a solution P: open if P_n is negligible and the point leaves, else stick or slip."""
    u_scale = 0.0
    for r in range(2 * m):
        u_scale = max(u_scale, abs(u[r]))
    tol = OPEN_RATE_REL * u_scale + 1e-300
    for i in range(m):
        un, ut = _post_rates(G, u, P, m, i)
        if un > tol:
            modes[i] = OPEN
        elif abs(ut) <= tol:
            modes[i] = STICK
        else:
            modes[i] = SLIP_POS if ut > 0.0 else SLIP_NEG


@nb.njit(**JIT)
def lemke_impact(G, u, mu, m, lw, P):
    """The law as an LCP w = M z + q, z, w >= 0, z^T w = 0, solved by Lemke's method.

    Per point z = (P_n, beta+, beta-, s) with P_t = beta+ - beta-:
    w = (u_n+, u_t+ + s, -u_t+ + s, mu P_n - beta+ - beta-).  The tableau
    (4m rows, 8m + 2 columns) lives in lw rows 14.. .  Returns True if a
    solution was found and it satisfies the law (:func:`satisfies_law`);
    else P = 0.
    """
    n = 4 * m
    T = lw[14:14 + n]
    cols = 2 * n + 2            # w (n), z (n), z0, q
    for i in range(n):
        for j in range(cols):
            T[i, j] = 0.0
    # build -M z + w = q  ->  tableau [I | -M | -e | q]
    for i in range(m):
        for a in range(4):
            T[4 * i + a, 4 * i + a] = 1.0
    for i in range(m):
        for j in range(m):
            gnn = G[2 * i, 2 * j]
            gnt = G[2 * i, 2 * j + 1]
            gtn = G[2 * i + 1, 2 * j]
            gtt = G[2 * i + 1, 2 * j + 1]
            # M rows of point i, columns (P_n, b+, b-, s) of point j
            _set_m(T, n, 4 * i + 0, 4 * j, gnn, gnt, -gnt, 0.0)
            _set_m(T, n, 4 * i + 1, 4 * j, gtn, gtt, -gtt, 1.0 if i == j else 0.0)
            _set_m(T, n, 4 * i + 2, 4 * j, -gtn, -gtt, gtt, 1.0 if i == j else 0.0)
            if i == j:
                _set_m(T, n, 4 * i + 3, 4 * j, mu[i], -1.0, -1.0, 0.0)
        T[4 * i + 0, 2 * n + 1] = u[2 * i]
        T[4 * i + 1, 2 * n + 1] = u[2 * i + 1]
        T[4 * i + 2, 2 * n + 1] = -u[2 * i + 1]
        T[4 * i + 3, 2 * n + 1] = 0.0
    for i in range(n):
        T[i, 2 * n] = -1.0
    basis = lw[14 + n]
    for i in range(n):
        basis[i] = i             # w basic
    # initial pivot: z0 enters at the row of the most negative q
    r = -1
    qmin = 0.0
    for i in range(n):
        if T[i, 2 * n + 1] < qmin:
            qmin = T[i, 2 * n + 1]
            r = i
    if r < 0:
        for i in range(2 * m):
            P[i] = 0.0
        return True
    # ratios within round-off of q's scale are ties (an absolute tie would merge
    # every ratio of a problem whose rates are themselves of order 1e-16)
    tie = 1e-300
    for i in range(n):
        tie = max(tie, 1e-15 * abs(T[i, 2 * n + 1]))
    entering = 2 * n
    done = False
    for _ in range(50 * n):
        leaving = int(basis[r])
        _pivot(T, n, cols, r, entering)
        basis[r] = entering
        if leaving == 2 * n:
            done = True
            break
        entering = leaving + n if leaving < n else leaving - n
        # ratio test on the entering column
        r = -1
        best = 1e300
        for i in range(n):
            a = T[i, entering]
            if a > 1e-12:
                ratio = T[i, 2 * n + 1] / a
                if ratio < best - tie or (abs(ratio - best) <= tie and int(basis[i]) == 2 * n):
                    best = ratio
                    r = i
        if r < 0:
            return False         # ray termination
    if not done:
        return False
    for i in range(2 * m):
        P[i] = 0.0
    for i in range(n):
        b = int(basis[i])
        if n <= b < 2 * n:
            zi = b - n
            pt = zi // 4
            which = zi % 4
            val = T[i, 2 * n + 1]
            if which == 0:
                P[2 * pt] = val
            elif which == 1:
                P[2 * pt + 1] += val
            elif which == 2:
                P[2 * pt + 1] -= val
    if satisfies_law(G, u, mu, m, P, LEMKE_CHECK_TOL):
        return True
    for i in range(2 * m):
        P[i] = 0.0
    return False


@nb.njit(**JIT)
def satisfies_law(G, u, mu, m, P, tol):
    """Whether impulses P satisfy Moreau's law at every point, to tol of the scales.

    Rates are compared with tol max|u-|, impulses with tol times the larger
    of max|P| and max|u-| / max G_ii.  Lemke's pivoting on a nearly
    singular G can end on a basis whose values are round-off (impulses of
    1e5 off the friction cone's edge, a closed point left approaching): its
    result is kept only if it passes.
    """
    scale_u = 1e-300
    g_diag = 1e-300
    scale_p = 0.0
    for r in range(2 * m):
        scale_u = max(scale_u, abs(u[r]))
        g_diag = max(g_diag, abs(G[r, r]))
        scale_p = max(scale_p, abs(P[r]))
    scale_p = max(scale_p, scale_u / g_diag)
    for i in range(m):
        un, ut = _post_rates(G, u, P, m, i)
        pn = P[2 * i]
        pt = P[2 * i + 1]
        if pn < -tol * scale_p or un < -tol * scale_u:
            return False
        if abs(pn * un) > tol * scale_p * scale_u:
            return False
        if abs(pt) > mu[i] * pn + tol * scale_p:
            return False
        if abs(ut) > tol * scale_u and abs(pt + math.copysign(mu[i] * pn, ut)) > tol * scale_p:
            return False
    return True


@nb.njit(**JIT_INLINE)
def _set_m(T, n, row, col0, a, b, c, d):
    """Tableau entries -M[row, col0..col0+3] = -(a, b, c, d) in the z columns."""
    T[row, n + col0] = -a
    T[row, n + col0 + 1] = -b
    T[row, n + col0 + 2] = -c
    T[row, n + col0 + 3] = -d


@nb.njit(**JIT_INLINE)
def _pivot(T, n, cols, r, c):
    inv = 1.0 / T[r, c]
    for j in range(cols):
        T[r, j] *= inv
    for i in range(n):
        if i != r:
            f = T[i, c]
            if f != 0.0:
                for j in range(cols):
                    T[i, j] -= f * T[r, j]


def eval_impact(G, u, mu, m):
    """:func:`solve_impact` for tests and Python callers: (source, P, modes)."""
    lw = np.zeros((ly.N_LAW, ly.N_LAW_COLS))
    P = np.zeros(2 * m)
    modes = np.zeros(m)
    source = solve_impact(np.ascontiguousarray(G, dtype=float), np.ascontiguousarray(u, dtype=float),
                          np.ascontiguousarray(mu, dtype=float), m, lw, P, modes)
    return source, P, modes.astype(int)
