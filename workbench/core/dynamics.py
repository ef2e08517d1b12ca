"""Gibbs-Appell equations of motion in free flight (docs/model.md §5-6).

    M(q) q'' = Q(q, q', t) - h(q, q'),     M = sum m J^T J + I a a^T,
                                           h = sum m J^T kappa

with Q the elastic, damping, gravity, cork and shaker forces.  Coordinates
not in ``free`` are held fixed: their rows are dropped and their
accelerations are zero (their velocities must be zero too).

Argument convention of every kernel here (see :mod:`workbench.model.packing`):
``P, tab, kc, free`` describe the model, ``ex`` the excitation, and
``rec, mat, vec`` are scratch.  All functions are jit-compiled; those that
can fail return a status code of :mod:`workbench.core.layout`.
"""
import math

import numba as nb

from .config import CHOLESKY_REL_PIVOT, JIT, JIT_INLINE
from . import layout as ly
from .cork import cork_potential, cork_spring
from .excitation import EXC_HAMMER_JOINT, X_KIND, hammer_force, shaker_force
from .inertia import frame_sums
from .kinematics import beam_b_point, compute_frames, rigid_point, tip_row


@nb.njit(**JIT)
def fill_stiffness_damping(P, kc):
    """Linear stiffness kc[KC_K] and damping kc[KC_C] (9, 9), docs/model.md §5.

    Per beam: bending EI/L^3 [[12, -6L], [-6L, 4L^2]] on (w, phi) and axial
    EA/L on u (exact for the Hermite shapes); damping C_b = beta K_b on the
    bending block and the axial coordinate's own damping c_ax on u
    (:meth:`workbench.model.params.Parameters.axial_damping`).  The optional
    springs k_v, k_psi on the loose body (0 in the paper's model) are
    undamped.
    """
    K = kc[ly.KC_K]
    C = kc[ly.KC_C]
    K[:, :] = 0.0
    C[:, :] = 0.0
    for i0, L, EI, EA, beta, c_ax in (
            (ly.W_A, P[ly.P_L_A], P[ly.P_EI_A], P[ly.P_EA_A], P[ly.P_BETA_A], P[ly.P_C_AX_A]),
            (ly.W_B, P[ly.P_L_B], P[ly.P_EI_B], P[ly.P_EA_B], P[ly.P_BETA_B], P[ly.P_C_AX_B])):
        kb = EI / L ** 3
        K[i0, i0] = 12.0 * kb
        K[i0, i0 + 1] = -6.0 * L * kb
        K[i0 + 1, i0] = -6.0 * L * kb
        K[i0 + 1, i0 + 1] = 4.0 * L * L * kb
        K[i0 + 2, i0 + 2] = EA / L
        for i in range(i0, i0 + 2):
            for j in range(i0, i0 + 2):
                C[i, j] = beta * K[i, j]
        C[i0 + 2, i0 + 2] = c_ax
    K[ly.V, ly.V] = P[ly.P_K_V]
    K[ly.PSI, ly.PSI] = P[ly.P_K_PSI]


@nb.njit(**JIT_INLINE)
def slot_overtravel(s, P):
    """How far the slide s is past the slot's end stop (cm): |s| - s_travel, or 0."""
    return max(abs(s) - P[ly.P_S_TRAVEL], 0.0)


@nb.njit(**JIT_INLINE)
def cork_force(s, sd, P):
    """Cork force on the slide s (dyn), docs/model.md §6.

    The law's spring (:mod:`workbench.core.cork`) + c s', plus the slot's end
    stop k_stop (|s| - s_travel) sign(s) beyond |s| > s_travel.
    """
    stop = P[ly.P_K_STOP] * math.copysign(slot_overtravel(s, P), s)
    spring = cork_spring(s, P[ly.P_CORK_FORM], P[ly.P_CORK_N], P[ly.P_CORK_K])
    return spring + stop + P[ly.P_CORK_C] * sd


@nb.njit(**JIT_INLINE)
def cork_energy(s, P):
    """Cork potential V(s) + k_stop (|s| - s_travel)_+^2 / 2 (erg), docs/model.md §6."""
    over = slot_overtravel(s, P)
    spring = cork_potential(s, P[ly.P_CORK_FORM], P[ly.P_CORK_N], P[ly.P_CORK_K])
    return spring + 0.5 * P[ly.P_K_STOP] * over * over


@nb.njit(**JIT_INLINE)
def inertia_terms(q, qd, P, tab, rec, mat, vec):
    """Fill M (mat[MAT_M]), h (vec[VEC_H]) and gravity (vec[VEC_Q]); return V_gravity.

    M (g, g cm, g cm^2 by coordinate), h = sum m J^T kappa and
    Q_gravity = sum m J^T (0, -g) (dyn, dyn cm), summed frame by frame
    (:mod:`workbench.core.inertia`): the upper triangle, then mirrored.
    Returns the gravitational energy sum m g y (erg).
    """
    M = mat[ly.MAT_M]
    h = vec[ly.VEC_H]
    Q = vec[ly.VEC_Q]
    for i in range(ly.N_DOF):
        h[i] = 0.0
        Q[i] = 0.0
        for j in range(ly.N_DOF):
            M[i, j] = 0.0
    compute_frames(q, qd, P, tab, rec)
    v_grav = frame_sums(q, qd, P, tab, rec, M, h, Q)
    for i in range(ly.N_DOF):
        for j in range(i):
            M[i, j] = M[j, i]
    return v_grav


@nb.njit(**JIT)
def assemble_inertia(q, qd, P, tab, rec, mat, vec):
    """:func:`inertia_terms` as a kernel of its own, for the callers off the right-hand side."""
    return inertia_terms(q, qd, P, tab, rec, mat, vec)


@nb.njit(**JIT_INLINE)
def add_applied_forces(t, q, qd, P, tab, kc, ex, rec, vec):
    """Add elastic, damping, cork, shaker and hammer forces to Q = vec[VEC_Q].

    Units dyn, dyn cm.  The frames in ``rec`` must be current; the point
    record rows are overwritten by a hammer.  Writes the excitation's power
    and the structural damping's dissipation q'^T C q' (erg/s) and the
    shaker and hammer forces (dyn) into vec[VEC_AUX].
    """
    Q = vec[ly.VEC_Q]
    aux = vec[ly.VEC_AUX]
    K = kc[ly.KC_K]
    C = kc[ly.KC_C]
    # K and C are block diagonal (fill_stiffness_damping): the beams' 3 x 3
    # blocks and the loose body's springs on v and psi.
    p_damp = 0.0
    for i0 in (ly.W_A, ly.W_B):
        for i in range(i0, i0 + 3):
            elastic = 0.0
            damping = 0.0
            for j in range(i0, i0 + 3):
                elastic += K[i, j] * q[j]
                damping += C[i, j] * qd[j]
            Q[i] -= elastic + damping
            p_damp += qd[i] * damping
    for i in (ly.V, ly.PSI):
        Q[i] -= K[i, i] * q[i] + C[i, i] * qd[i]
        p_damp += qd[i] * C[i, i] * qd[i]
    aux[ly.AUX_P_DAMP] = p_damp
    Q[ly.S] -= cork_force(q[ly.S], qd[ly.S], P)
    # Shaker: J^T (0, F) at force1; the vertical Jacobian row of a beam A
    # point is (N1, N2) on (w_A, phi_A).
    F = shaker_force(t, ex)
    row = tab[tip_row(P, ly.R_FORCE1)]
    Q[ly.W_A] += row[ly.T_N1] * F
    Q[ly.PHI_A] += row[ly.T_N2] * F
    power = F * (row[ly.T_N1] * qd[ly.W_A] + row[ly.T_N2] * qd[ly.PHI_A])
    aux[ly.AUX_F_SHAKER] = F
    # Hammer: J^T F e at the struck point, e its direction.
    Fh = hammer_force(t, ex)
    aux[ly.AUX_F_HAMMER] = Fh
    if Fh != 0.0:
        pt = rec[ly.REC_POINT]
        if int(ex[X_KIND]) == EXC_HAMMER_JOINT:   # vertical, joint body base
            rigid_point(rec, ly.REC_JOINT, 0.0, 0.0, ly.REC_POINT)
            ex_, ey_ = 0.0, 1.0
        else:                                           # along beam B's axis at its tip
            beam_b_point(tab[tip_row(P, ly.R_TIP_B)], q, qd, P, rec, ly.REC_POINT)
            angle = q[ly.PHI_A] + q[ly.PSI] + q[ly.PHI_B]
            ex_, ey_ = math.cos(angle), math.sin(angle)
        for i in range(ly.N_DOF):
            gi = Fh * (ex_ * pt[ly.JX + i] + ey_ * pt[ly.JY + i])
            Q[i] += gi
            power += gi * qd[i]
    aux[ly.AUX_P_EXT] = power


#: Which rows the factor and solves take (``rows`` of :func:`_at`): the coordinates listed in
#: ``free``, every coordinate, or the beams' (ly.BEAM_COORDS: the joint's three skipped).
LISTED, ALL_FREE, BEAMS_ONLY = 0, 1, 2
#: With every coordinate free the factor's rows are the beams' coordinates, then the joint's
#: (s, v, psi) last: M^-1's joint block and a solve with a force on the joint alone need
#: only the factor's last three rows (:func:`joint_block`, :func:`add_joint_solve`).
JOINT_ROW = ly.N_DOF - 3


@nb.njit(**JIT_INLINE)
def _joint_last(i):
    """The coordinate of the factor's row i with every coordinate free: the beams', then the
    joint's."""
    if i < ly.S:
        return i
    return i + 3 if i < JOINT_ROW else i + ly.S - JOINT_ROW


@nb.njit(**JIT_INLINE)
def _at(free, i, rows):
    """Coordinate of the i-th row: free[i]; with every coordinate free, the beams' coordinates
    then the joint's; or the i-th of the beams' coordinates (the joint's s, v, psi are 3..5)."""
    if rows == ALL_FREE:
        return _joint_last(i)
    if rows == BEAMS_ONLY:
        return i if i < ly.S else i + (ly.PSI + 1 - ly.S)
    return free[i]


@nb.njit(**JIT_INLINE)
def _factor(free, n, rows, mat):
    """LDL^T factor of M_ff (n free rows) into mat[MAT_CHOL]; returns a status.

    Stores the unit lower triangle L below the diagonal, 1 / D_j on it and
    D L^T above it (L_ij D_j at (j, i), the products before the scaling):
    no square roots, one division per row, and the solves multiply where a
    Cholesky factor's would divide (the factor and the substitutions are
    dependency chains: with a Cholesky factor the solves held about 22 % and
    the factor's diagonal about 5 % of the kernels' time, measured by perf
    samples mapped onto the kernels' source lines).
    """
    L = mat[ly.MAT_CHOL]
    M = mat[ly.MAT_M]
    big = 0.0
    for i in range(n):
        fi = _at(free, i, rows)
        big = max(big, M[fi, fi])
    for j in range(n):
        fj = _at(free, j, rows)
        d = M[fj, fj]
        for k in range(j):
            d -= L[j, k] * L[k, j]
        if not d > CHOLESKY_REL_PIVOT * big:
            return ly.ERR_SINGULAR_MASS
        inv = 1.0 / d
        L[j, j] = inv
        for i in range(j + 1, n):
            acc = M[_at(free, i, rows), fj]
            for k in range(j):
                acc -= L[i, k] * L[k, j]
            L[j, i] = acc
            L[i, j] = acc * inv
    return ly.OK


@nb.njit(**JIT_INLINE)
def factor_free(free, mat):
    """LDL^T factor of M_ff (M = mat[MAT_M], f the free coordinates) into mat[MAT_CHOL]
    (L below the diagonal, 1 / D_j on it).

    Returns a status code.  With every coordinate free the loops run over
    the compile-time size N_DOF with direct indices (measured 0.20 -> 0.12
    µs per factor).
    """
    if free.shape[0] == ly.N_DOF:
        return _factor(free, ly.N_DOF, ALL_FREE, mat)
    return _factor(free, free.shape[0], LISTED, mat)


@nb.njit(**JIT_INLINE)
def _solve(free, n, rows, mat, b, x):
    L = mat[ly.MAT_CHOL]
    for i in range(ly.N_DOF):
        x[i] = 0.0
    # forward L z = b, scale y = D^-1 z, back L^T x = y (kept in x's free slots)
    for i in range(n):
        acc = b[_at(free, i, rows)]
        for k in range(i):
            acc -= L[i, k] * x[_at(free, k, rows)]
        x[_at(free, i, rows)] = acc
    for i in range(n):
        x[_at(free, i, rows)] *= L[i, i]
    for i in range(n - 1, -1, -1):
        acc = x[_at(free, i, rows)]
        for k in range(i + 1, n):
            acc -= L[k, i] * x[_at(free, k, rows)]
        x[_at(free, i, rows)] = acc


@nb.njit(**JIT_INLINE)
def solve_factored(free, mat, b, x):
    """x = M_ff^-1 b_f with the factor of :func:`factor_free`; x of fixed coordinates = 0."""
    if free.shape[0] == ly.N_DOF:
        _solve(free, ly.N_DOF, ALL_FREE, mat, b, x)
    else:
        _solve(free, free.shape[0], LISTED, mat, b, x)


@nb.njit(**JIT_INLINE)
def joint_block(mat):
    """(M^-1) on the joint's (s, v, psi), 3 x 3 as a tuple of rows, from the factor of
    :func:`factor_free` with every coordinate free (its last three rows are the joint's):
    W = U^T D_j^-1 U with U = L_jj^-1, L's unit lower 3 x 3 block on the joint."""
    L = mat[ly.MAT_CHOL]
    j = JOINT_ROW
    l10, l20, l21 = L[j + 1, j], L[j + 2, j], L[j + 2, j + 1]
    u10, u20, u21 = -l10, l10 * l21 - l20, -l21
    d0, d1, d2 = L[j, j], L[j + 1, j + 1], L[j + 2, j + 2]
    w00 = d0 + d1 * u10 * u10 + d2 * u20 * u20
    w01 = d1 * u10 + d2 * u20 * u21
    w02 = d2 * u20
    w11 = d1 + d2 * u21 * u21
    w12 = d2 * u21
    return ((w00, w01, w02), (w01, w11, w12), (w02, w12, d2))


@nb.njit(**JIT_INLINE)
def add_joint_solve(mat, f, x, y):
    """x += M^-1 (f on the joint's s, v, psi; f a 3-tuple): the factor of :func:`factor_free`
    with every coordinate free, whose forward substitution touches its last three rows only;
    y (9,) is scratch."""
    L = mat[ly.MAT_CHOL]
    j = JOINT_ROW
    z0 = f[0]
    z1 = f[1] - L[j + 1, j] * z0
    z2 = f[2] - L[j + 2, j] * z0 - L[j + 2, j + 1] * z1
    for i in range(j):
        y[i] = 0.0
    y[j] = z0 * L[j, j]
    y[j + 1] = z1 * L[j + 1, j + 1]
    y[j + 2] = z2 * L[j + 2, j + 2]
    for i in range(ly.N_DOF - 1, -1, -1):
        acc = y[i]
        for k in range(i + 1, ly.N_DOF):
            acc -= L[k, i] * y[k]
        y[i] = acc
        x[_joint_last(i)] += acc


@nb.njit(**JIT_INLINE)
def solve_free(free, mat, b, x):
    """Solve M_ff x_f = b_f by its LDL^T factor (M = mat[MAT_M]); x of fixed coordinates = 0.

    Overwrites mat[MAT_CHOL].  Returns a status code.
    """
    status = factor_free(free, mat)
    if status == ly.OK:
        solve_factored(free, mat, b, x)
    return status


@nb.njit(**JIT_INLINE)
def _add_forces(t, y, v_grav, P, tab, kc, ex, rec, vec, ydot):
    """q' into ydot[:N_DOF], the applied forces added to the gravity in vec[VEC_Q], b = Q - h
    into vec[VEC_RHS] and V_gravity (erg) into vec[VEC_AUX], after M, h and gravity at y."""
    q = y[:ly.N_DOF]
    qd = y[ly.N_DOF:]
    for i in range(ly.N_DOF):
        ydot[i] = qd[i]
    vec[ly.VEC_AUX, ly.AUX_VGRAV] = v_grav
    add_applied_forces(t, q, qd, P, tab, kc, ex, rec, vec)
    Q = vec[ly.VEC_Q]
    b = vec[ly.VEC_RHS]
    for i in range(ly.N_DOF):
        b[i] = Q[i] - vec[ly.VEC_H, i]


@nb.njit(**JIT_INLINE)
def net_forces(t, y, P, tab, kc, ex, rec, mat, vec, ydot):
    """M (mat[MAT_M]) and b = Q - h (vec[VEC_RHS]) at y; q' into ydot[:N_DOF].

    Units: dyn, dyn cm.  Leaves the scalars of vec[VEC_AUX] (gravity energy,
    excitation power and forces).  Inlined whole into its caller
    (:func:`~workbench.core.constrained.rhs_regime`, the hot path): a call
    passes each of its arrays as a struct of pointers, shape and strides,
    and as a chain of five calls it cost the sines 10 % (docs/performance.md).
    """
    v_grav = inertia_terms(y[:ly.N_DOF], y[ly.N_DOF:], P, tab, rec, mat, vec)
    _add_forces(t, y, v_grav, P, tab, kc, ex, rec, vec, ydot)


@nb.njit(**JIT)
def rhs(t, y, P, tab, kc, free, ex, rec, mat, vec, ydot):
    """First-order right-hand side y' = (q', q'') of the 18-state system in free flight.

    Units: y = (q, q') in cm, rad and their rates; t in s.  Returns a status.
    Leaves M's LDL^T factor in mat[MAT_CHOL] and the scalars of
    vec[VEC_AUX] (gravity energy, excitation power and forces).
    """
    v_grav = assemble_inertia(y[:ly.N_DOF], y[ly.N_DOF:], P, tab, rec, mat, vec)
    _add_forces(t, y, v_grav, P, tab, kc, ex, rec, vec, ydot)
    return solve_free(free, mat, vec[ly.VEC_RHS], ydot[ly.N_DOF:])


@nb.njit(**JIT_INLINE)
def solve_beams(mat, b, x):
    """Solve M_rr x_r = b_r over the beams' coordinates r (ly.BEAM_COORDS), the joint's held.

    Factors M_rr (M = mat[MAT_M]) into mat[MAT_CHOL]; x of the joint's
    coordinates = 0.  Returns a status code.
    """
    status = _factor(ly.BEAM_COORDS, 6, BEAMS_ONLY, mat)
    if status == ly.OK:
        _solve(ly.BEAM_COORDS, 6, BEAMS_ONLY, mat, b, x)
    return status


@nb.njit(**JIT)
def eval_rhs(t, y, model, ex, work, ydot):
    """:func:`rhs` as a compiled entry point: ``eval_rhs(t, y, *model, ex, *work, ydot)``."""
    P, tab, kc, free = model.P, model.tab, model.kc, model.free
    rec, mat, vec = work.rec, work.mat, work.vec
    return rhs(t, y, P, tab, kc, free, ex, rec, mat, vec, ydot)


@nb.njit(**JIT)
def eval_inertia(q, qd, model, work):
    """:func:`assemble_inertia` as an entry point: ``eval_inertia(q, qd, *model, *work)``.

    Leaves M in mat[MAT_M], h in vec[VEC_H], gravity in vec[VEC_Q]; returns V_gravity.
    """
    P, tab = model.P, model.tab
    rec, mat, vec = work.rec, work.mat, work.vec
    return assemble_inertia(q, qd, P, tab, rec, mat, vec)


@nb.njit(**JIT)
def energies(y, model, work, out):
    """Energies of state y (erg) into out: kinetic, elastic, gravity, cork.

    Called as ``energies(y, *model, *work, out)``.
    Elastic includes the optional loose-body springs; cork is the potential
    of the cork spring.  Damping, forcing and contact do not enter.
    """
    P, tab, kc = model.P, model.tab, model.kc
    rec, mat, vec = work.rec, work.mat, work.vec
    q = y[:ly.N_DOF]
    qd = y[ly.N_DOF:]
    v_grav = assemble_inertia(q, qd, P, tab, rec, mat, vec)
    M = mat[ly.MAT_M]
    K = kc[ly.KC_K]
    kin = 0.0
    ela = 0.0
    for i in range(ly.N_DOF):
        for j in range(ly.N_DOF):
            kin += 0.5 * qd[i] * M[i, j] * qd[j]
            ela += 0.5 * q[i] * K[i, j] * q[j]
    out[0] = kin
    out[1] = ela
    out[2] = v_grav
    out[3] = cork_energy(q[ly.S], P)
