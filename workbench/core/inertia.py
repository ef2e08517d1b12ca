"""Mass matrix, convective and gravity terms summed frame by frame (docs/model.md §5).

The per-element sums of :mod:`workbench.core.dynamics`

    M = sum m J^T J + I a a^T,   h = sum m J^T kappa,   Q_g = -g sum m J_y^T

are regrouped by the frame each element moves with: beam A (the ground
frame), the joint body (joint frame) and the loose body, beam B and the
tip mass (loose-body frame).  For a point rho(q) of a frame (r0, alpha),
in the frame's axes (R^T J = R^T J0 + D + S rho a^T, D = d(rho)/dq on the
beam's own three coordinates):

    sum m J^T J = U^T B U + U^T F + F^T U + G
    U = [R^T J0 rows x, y; a] (3 x 9),  B = [[m, 0, -c_y], [0, m, c_x], [-c_y, c_x, I_rho]]
    F = [sum m D_x; sum m D_y; sum m (S rho)^T D],   G = sum m D^T D

with m, c = sum m rho and I_rho = sum m |rho|^2 of the frame's points, and
likewise for h, gravity and the rotary inertia (the angle row of an element
is a + d, d its own slope terms).  So each element adds a few local sums,
and the 9 x 9 work is done once per frame.  A beam's local sums are
polynomials of degree at most four in its own coordinates (w, phi, u) and
their rates, so they are formed from the beam's inertia invariants
(weighted sums over its Gauss points, ``layout.INV_*``, computed once by
:func:`fill_invariants`) rather than point by point.  Results equal the
element sums to round-off (``tests/core/test_dynamics.py`` checks them
against the independent reference).
"""
import numba as nb

from .config import JIT, JIT_INLINE
from . import layout as ly
from .kinematics import beam_point_motion, tip_row

# Accumulator layout: a row of ``rec`` (REC_ACC), reset per frame.  The
# rotary inertia enters as a third Jacobian row (the angle row a + d).
A_M = 0                 # sum m (g)
A_C = 1                 # c = sum m rho (2)
A_E = 3                 # sum m D, rows x then y, 3 local columns each (6)
A_G = 9                 # sum m D^T D + I d d^T, 3 x 3 row-major, upper triangle used (9)
A_F3 = 18               # sum m (S rho)^T D + I d (3)
A_B22 = 21              # sum m |rho|^2 + I
A_L = 22                # sum m ell, ell the local convective acceleration (2)
A_DL = 24               # sum m D^T ell (3)
A_SL = 27               # sum m (S rho)^T ell
N_ACC = 28
assert N_ACC <= ly.N_REC


@nb.njit(**JIT_INLINE)
def _reset(acc):
    for i in range(N_ACC):
        acc[i] = 0.0


@nb.njit(**JIT_INLINE)
def _add_rigid_point(acc, m, rot, rx, ry, omega):
    """Add a point fixed in a frame: mass m (g), rotary inertia rot (g cm^2) at (rx, ry) (cm).

    Its D and d are zero and its convective acceleration ell = -omega^2 rho
    (omega the frame's angle rate, rad/s) is parallel to rho, so only the
    mass, first and second moments and sum m ell change.
    """
    acc[A_M] += m
    acc[A_C] += m * rx
    acc[A_C + 1] += m * ry
    acc[A_B22] += m * (rx * rx + ry * ry) + rot
    acc[A_L] -= m * omega * omega * rx
    acc[A_L + 1] -= m * omega * omega * ry


@nb.njit(**JIT_INLINE)
def _add_beam_point(acc, m, rot, row, q, qd, i0, x_offset, d0, d1, omega):
    """Add a point of a beam (a shape-table row) to its root frame's sums.

    Mass m (g), rotary inertia rot (g cm^2); ``i0`` the beam's first
    coordinate, ``x_offset`` its root along the frame's x axis (cm), (d0, d1)
    the point's own angle derivatives on (w, phi), ``omega`` the frame's
    angle rate (rad/s).  The kinematics of
    :func:`~workbench.core.kinematics.beam_point_motion`; on the
    beam's (w, phi, u) the Jacobian rows are D_x = (-(Sigma b)_0,
    -(Sigma b)_1, xi) and D_y = (N1, N2, 0), so only their nonzero entries
    and the upper triangle of sum m D^T D are formed.
    """
    rx, ry, vx, vy, kx, sb0, sb1 = beam_point_motion(row, q, qd, i0, x_offset)
    xi = row[ly.T_XI]
    n1 = row[ly.T_N1]
    n2 = row[ly.T_N2]
    # ell = rho''_conv + 2 omega S rho' - omega^2 rho
    lx = kx - 2.0 * omega * vy - omega * omega * rx
    ly_ = 2.0 * omega * vx - omega * omega * ry
    x0 = -sb0
    x1 = -sb1
    acc[A_M] += m
    acc[A_C] += m * rx
    acc[A_C + 1] += m * ry
    acc[A_B22] += m * (rx * rx + ry * ry) + rot
    acc[A_E] += m * x0
    acc[A_E + 1] += m * x1
    acc[A_E + 2] += m * xi
    acc[A_E + 3] += m * n1
    acc[A_E + 4] += m * n2
    acc[A_F3] += m * (-ry * x0 + rx * n1) + rot * d0
    acc[A_F3 + 1] += m * (-ry * x1 + rx * n2) + rot * d1
    acc[A_F3 + 2] -= m * ry * xi
    acc[A_DL] += m * (x0 * lx + n1 * ly_)
    acc[A_DL + 1] += m * (x1 * lx + n2 * ly_)
    acc[A_DL + 2] += m * xi * lx
    acc[A_G] += m * (x0 * x0 + n1 * n1) + rot * d0 * d0
    acc[A_G + 1] += m * (x0 * x1 + n1 * n2) + rot * d0 * d1
    acc[A_G + 2] += m * x0 * xi
    acc[A_G + 4] += m * (x1 * x1 + n2 * n2) + rot * d1 * d1
    acc[A_G + 5] += m * x1 * xi
    acc[A_G + 8] += m * xi * xi
    acc[A_L] += m * lx
    acc[A_L + 1] += m * ly_
    acc[A_SL] += m * (-ry * lx + rx * ly_)


@nb.njit(**JIT)
def fill_invariants(P, tab):
    """Write both beams' inertia invariants (``layout.INV_*``) into P from ``tab``'s Gauss rows.

    Beam A's points lie at X = x in the ground frame, beam B's at X = L4 + x
    in the loose-body frame; masses mu w (g), rotary inertias rho_I w (g cm^2).
    """
    ng = int(P[ly.P_N_GAUSS])
    for base, first, mu, rhoi, x_offset in ((ly.P_INV_A, 0, P[ly.P_MU_A], P[ly.P_RHOI_A], 0.0),
                                            (ly.P_INV_B, ng, P[ly.P_MU_B], P[ly.P_RHOI_B],
                                             P[ly.P_L4])):
        for i in range(ly.N_INV):
            P[base + i] = 0.0
        for k in range(first, first + ng):
            row = tab[k]
            m = mu * row[ly.T_WEIGHT]
            r = rhoi * row[ly.T_WEIGHT]
            x = x_offset + row[ly.T_X]
            xi = row[ly.T_XI]
            n = (row[ly.T_N1], row[ly.T_N2])
            s = (row[ly.T_S00], row[ly.T_S01], row[ly.T_S11])
            d = (row[ly.T_DN1], row[ly.T_DN2])
            P[base + ly.INV_M] += m
            P[base + ly.INV_X] += m * x
            P[base + ly.INV_XX] += m * x * x
            P[base + ly.INV_XI] += m * xi
            P[base + ly.INV_XIXI] += m * xi * xi
            P[base + ly.INV_XXI] += m * x * xi
            P[base + ly.INV_NN] += m * n[0] * n[0]
            P[base + ly.INV_NN + 1] += m * n[0] * n[1]
            P[base + ly.INV_NN + 2] += m * n[1] * n[1]
            P[base + ly.INV_R] += r
            P[base + ly.INV_RDD] += r * d[0] * d[0]
            P[base + ly.INV_RDD + 1] += r * d[0] * d[1]
            P[base + ly.INV_RDD + 2] += r * d[1] * d[1]
            for j in range(2):
                P[base + ly.INV_N + j] += m * n[j]
                P[base + ly.INV_XIN + j] += m * xi * n[j]
                P[base + ly.INV_XN + j] += m * x * n[j]
                P[base + ly.INV_RD + j] += r * d[j]
            c = 0
            for a in range(3):
                P[base + ly.INV_S + a] += m * s[a]
                P[base + ly.INV_XS + a] += m * x * s[a]
                P[base + ly.INV_XIS + a] += m * xi * s[a]
                P[base + ly.INV_NS + a] += m * n[0] * s[a]
                P[base + ly.INV_NS + 3 + a] += m * n[1] * s[a]
                for b in range(a, 3):
                    P[base + ly.INV_SS + c] += m * s[a] * s[b]
                    c += 1


@nb.njit(**JIT_INLINE)
def _quad(P, i, x0, x1, y0, y1):
    """x^T A y for the symmetric 2 x 2 matrix A = (P[i], P[i+1]; P[i+1], P[i+2])."""
    return P[i] * x0 * y0 + P[i + 1] * (x0 * y1 + x1 * y0) + P[i + 2] * x1 * y1


@nb.njit(**JIT_INLINE)
def _add_beam(acc, P, base, q, qd, i0, omega):
    """Add a beam's Gauss points to its root frame's sums, from its invariants at ``P[base]``.

    The sums :func:`_add_beam_point` forms point by point, in closed form in
    the beam's (w, phi, u) = b, u and their rates (``i0`` its first
    coordinate, ``omega`` the frame's angle rate, rad/s).  Per point,
    Sigma b = S b, q_f = b^T S b (twice the foreshortening), rx = X + xi u
    - q_f / 2, ry = N.b; the cubic and quartic sums come from
    Z_j = sum m (S b)_j S and W = sum m (N.b) S.
    """
    w, p, u = q[i0], q[i0 + 1], q[i0 + 2]
    wd, pd, ud = qd[i0], qd[i0 + 1], qd[i0 + 2]
    o2 = omega * omega
    ss = base + ly.INV_SS
    # Z_0 = sum m (S b)_0 S and Z_1 = sum m (S b)_1 S, each (00, 01, 11)
    z00 = w * P[ss] + p * P[ss + 1]
    z01 = w * P[ss + 1] + p * P[ss + 3]
    z02 = w * P[ss + 2] + p * P[ss + 4]
    z10 = w * P[ss + 1] + p * P[ss + 2]
    z11 = w * P[ss + 3] + p * P[ss + 4]
    z12 = w * P[ss + 4] + p * P[ss + 5]
    zq0 = z00 * w * w + 2.0 * z01 * w * p + z02 * p * p      # sum m (S b)_0 q_f
    zq1 = z10 * w * w + 2.0 * z11 * w * p + z12 * p * p      # sum m (S b)_1 q_f
    # W = sum m (N.b) S and Wd = sum m (N.b') S
    ns = base + ly.INV_NS
    wm0 = w * P[ns] + p * P[ns + 3]
    wm1 = w * P[ns + 1] + p * P[ns + 4]
    wm2 = w * P[ns + 2] + p * P[ns + 5]
    wd0 = wd * P[ns] + pd * P[ns + 3]
    wd1 = wd * P[ns + 1] + pd * P[ns + 4]
    wd2 = wd * P[ns + 2] + pd * P[ns + 5]
    # (sum m S) b, (sum m X S) b, (sum m xi S) b
    i = base + ly.INV_S
    sb0 = P[i] * w + P[i + 1] * p
    sb1 = P[i + 1] * w + P[i + 2] * p
    i = base + ly.INV_XS
    xsb0 = P[i] * w + P[i + 1] * p
    xsb1 = P[i + 1] * w + P[i + 2] * p
    i = base + ly.INV_XIS
    isb0 = P[i] * w + P[i + 1] * p
    isb1 = P[i + 1] * w + P[i + 2] * p
    isbb = isb0 * w + isb1 * p                                # sum m xi q_f
    m_xixi, m_xxi, m_xi = P[base + ly.INV_XIXI], P[base + ly.INV_XXI], P[base + ly.INV_XI]
    n0, n1 = P[base + ly.INV_N], P[base + ly.INV_N + 1]
    xin0, xin1 = P[base + ly.INV_XIN], P[base + ly.INV_XIN + 1]
    nn = base + ly.INV_NN
    cx = P[base + ly.INV_X] + m_xi * u - 0.5 * (sb0 * w + sb1 * p)    # sum m rx
    cy = n0 * w + n1 * p                                                # sum m ry
    sum_rx2 = (P[base + ly.INV_XX] + m_xixi * u * u + 0.25 * (w * zq0 + p * zq1)
               + 2.0 * m_xxi * u - (xsb0 * w + xsb1 * p) - u * isbb)
    sum_kx = -_quad(P, base + ly.INV_S, wd, pd, wd, pd)
    sum_vx = -(sb0 * wd + sb1 * pd) + m_xi * ud
    sum_vy = n0 * wd + n1 * pd
    sum_rxvx = (-(xsb0 * wd + xsb1 * pd) + m_xxi * ud - u * (isb0 * wd + isb1 * pd)
                + m_xixi * u * ud + 0.5 * (zq0 * wd + zq1 * pd) - 0.5 * ud * isbb)
    acc[A_M] += P[base + ly.INV_M]
    acc[A_C] += cx
    acc[A_C + 1] += cy
    acc[A_B22] += sum_rx2 + _quad(P, nn, w, p, w, p) + P[base + ly.INV_R]
    acc[A_E] -= sb0
    acc[A_E + 1] -= sb1
    acc[A_E + 2] += m_xi
    acc[A_E + 3] += n0
    acc[A_E + 4] += n1
    acc[A_F3] += (wm0 * w + wm1 * p + P[base + ly.INV_XN] + u * xin0
                  - 0.5 * _quad(P, ns, w, p, w, p) + P[base + ly.INV_RD])
    acc[A_F3 + 1] += (wm1 * w + wm2 * p + P[base + ly.INV_XN + 1] + u * xin1
                      - 0.5 * _quad(P, ns + 3, w, p, w, p) + P[base + ly.INV_RD + 1])
    acc[A_F3 + 2] -= xin0 * w + xin1 * p
    acc[A_DL] += (z00 * wd * wd + 2.0 * z01 * wd * pd + z02 * pd * pd
                  + 2.0 * omega * (wd0 * w + wd1 * p)
                  + o2 * (xsb0 + u * isb0 - 0.5 * zq0)
                  + 2.0 * omega * (-((P[ns] * w + P[ns + 1] * p) * wd
                                     + (P[ns + 1] * w + P[ns + 2] * p) * pd) + xin0 * ud)
                  - o2 * (P[nn] * w + P[nn + 1] * p))
    acc[A_DL + 1] += (z10 * wd * wd + 2.0 * z11 * wd * pd + z12 * pd * pd
                      + 2.0 * omega * (wd1 * w + wd2 * p)
                      + o2 * (xsb1 + u * isb1 - 0.5 * zq1)
                      + 2.0 * omega * (-((P[ns + 3] * w + P[ns + 4] * p) * wd
                                         + (P[ns + 4] * w + P[ns + 5] * p) * pd) + xin1 * ud)
                      - o2 * (P[nn + 1] * w + P[nn + 2] * p))
    acc[A_DL + 2] += (-_quad(P, base + ly.INV_XIS, wd, pd, wd, pd)
                      - 2.0 * omega * (xin0 * wd + xin1 * pd)
                      - o2 * (m_xxi + m_xixi * u - 0.5 * isbb))
    rdd = base + ly.INV_RDD
    acc[A_G] += z00 * w + z01 * p + P[nn] + P[rdd]
    acc[A_G + 1] += z01 * w + z02 * p + P[nn + 1] + P[rdd + 1]
    acc[A_G + 2] -= isb0
    acc[A_G + 4] += z11 * w + z12 * p + P[nn + 2] + P[rdd + 2]
    acc[A_G + 5] -= isb1
    acc[A_G + 8] += m_xixi
    acc[A_L] += sum_kx - 2.0 * omega * sum_vy - o2 * cx
    acc[A_L + 1] += 2.0 * omega * sum_vx - o2 * cy
    acc[A_SL] += (wm0 * wd * wd + 2.0 * wm1 * wd * pd + wm2 * pd * pd
                  + 2.0 * omega * (_quad(P, nn, w, p, wd, pd) + sum_rxvx))


@nb.njit(**JIT_INLINE)
def _add_frame(acc, f, u, moving, rigid, i0, n_moving, g, M, h, Q):
    """Add the accumulated points of frame record ``f`` to M, h and Q_g.

    ``moving`` False is the ground frame (beam A): R = I, J0 = 0, a = 0.
    ``rigid`` True: the frame holds rigid points only (its local sums D, G
    and D^T ell are zero and not added); else a moving frame's local columns
    lie beyond the coordinates it moves with (i0 >= n_moving).
    ``u`` is a scratch record for the frame's rotated Jacobian rows.
    ``i0`` the first of the three local columns; the frame's origin and
    angle move with the first ``n_moving`` coordinates only (its Jacobian
    rows J0 and a are zero beyond).  Fills the upper triangle of M only.
    Returns the frame's gravitational energy (erg).
    """
    m = acc[A_M]
    cx = acc[A_C]
    cy = acc[A_C + 1]
    if moving:
        co = f[ly.COS]
        si = f[ly.SIN]
        # kappa0 in the frame's axes
        kx = co * f[ly.KX] + si * f[ly.KY]
        ky = -si * f[ly.KX] + co * f[ly.KY]
        # B (3 x 3, symmetric); the rotary inertia is in the (a, a) entry
        b00, b01, b02, b11, b12, b22 = m, 0.0, -cy, m, cx, acc[A_B22]
        # coefficients of U^T for h and gravity
        hx = m * kx + acc[A_L]
        hy = m * ky + acc[A_L + 1]
        ha = -cy * kx + cx * ky + acc[A_SL]
        gx = -g * (m * si)
        gy = -g * (m * co)
        ga = -g * (-cy * si + cx * co)
        # U's rows x and y (R^T J0) once, into the scratch record u
        for i in range(n_moving):
            u[ly.JX + i] = co * f[ly.JX + i] + si * f[ly.JY + i]
            u[ly.JY + i] = -si * f[ly.JX + i] + co * f[ly.JY + i]
        for i in range(n_moving):
            ui0 = u[ly.JX + i]
            ui1 = u[ly.JY + i]
            ui2 = f[ly.AA + i]
            vi0 = b00 * ui0 + b01 * ui1 + b02 * ui2
            vi1 = b01 * ui0 + b11 * ui1 + b12 * ui2
            vi2 = b02 * ui0 + b12 * ui1 + b22 * ui2
            for j in range(i, n_moving):
                M[i, j] += vi0 * u[ly.JX + j] + vi1 * u[ly.JY + j] + vi2 * f[ly.AA + j]
            h[i] += ui0 * hx + ui1 * hy + ui2 * ha
            Q[i] += ui0 * gx + ui1 * gy + ui2 * ga
            if not rigid:
                # U^T F on the local columns, all beyond i (their F^T U below the diagonal)
                for k in range(3):
                    M[i, i0 + k] += (ui0 * acc[A_E + k] + ui1 * acc[A_E + 3 + k]
                                     + ui2 * acc[A_F3 + k])
        v_grav = g * (m * f[ly.RY] + si * cx + co * cy)
        if rigid:
            return v_grav
        # local parts of h and gravity: E^T kappa0 + sum m D^T ell, -g (sin E_x + cos E_y)
        for k in range(3):
            h[i0 + k] += acc[A_E + k] * kx + acc[A_E + 3 + k] * ky + acc[A_DL + k]
            Q[i0 + k] -= g * (si * acc[A_E + k] + co * acc[A_E + 3 + k])
    else:
        for k in range(3):
            h[i0 + k] += acc[A_DL + k]
            Q[i0 + k] -= g * acc[A_E + 3 + k]
        v_grav = g * cy
    for j in range(3):
        for k in range(j, 3):
            M[i0 + j, i0 + k] += acc[A_G + 3 * j + k]
    return v_grav


@nb.njit(**JIT_INLINE)
def frame_sums(q, qd, P, tab, rec, M, h, Q):
    """Add every element's M (upper triangle), h and gravity Q; return V_gravity (erg).

    The frames in ``rec`` must be current (:func:`~.kinematics.compute_frames`).
    """
    acc = rec[ly.REC_ACC]
    g = P[ly.P_GRAV]
    # beam A: the ground frame
    _reset(acc)
    _add_beam(acc, P, ly.P_INV_A, q, qd, ly.W_A, 0.0)
    v_grav = _add_frame(acc, rec[ly.REC_JOINT], rec[ly.REC_U], False, False, ly.W_A, 0, g, M, h,
                        Q)
    # joint body: a rigid point of the joint frame
    fj = rec[ly.REC_JOINT]
    _reset(acc)
    _add_rigid_point(acc, P[ly.P_M3], P[ly.P_I3], P[ly.P_C3], 0.0, fj[ly.RATE])
    v_grav += _add_frame(acc, fj, rec[ly.REC_U], True, True, ly.W_A, ly.U_A + 1, g, M, h, Q)
    # loose body, beam B and the tip mass: the loose-body frame
    fl = rec[ly.REC_LOOSE]
    omega = fl[ly.RATE]
    _reset(acc)
    _add_rigid_point(acc, P[ly.P_M4], P[ly.P_I4], P[ly.P_C4], 0.0, omega)
    _add_beam(acc, P, ly.P_INV_B, q, qd, ly.W_B, omega)
    _add_beam_point(acc, P[ly.P_M6], P[ly.P_I6], tab[tip_row(P, ly.R_TIP_B)], q, qd, ly.W_B,
                    P[ly.P_L4], 0.0, 1.0, omega)
    v_grav += _add_frame(acc, fl, rec[ly.REC_U], True, False, ly.W_B, ly.PSI + 1, g, M, h, Q)
    return v_grav
