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
and the 9 x 9 work is done once per frame.  Results equal the element sums
to round-off (``tests/core/test_dynamics.py`` checks them against the
independent reference).
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


@nb.njit(**JIT_INLINE)
def _add_frame(acc, f, u, moving, i0, g, M, h, Q):
    """Add the accumulated points of frame record ``f`` to M, h and Q_g.

    ``moving`` False is the ground frame (beam A): R = I, J0 = 0, a = 0.
    ``u`` is a scratch record for the frame's rotated Jacobian rows.
    ``i0`` the first of the three local columns.  Fills the upper triangle
    of M only.  Returns the frame's gravitational energy (erg).
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
        for i in range(ly.N_DOF):
            u[ly.JX + i] = co * f[ly.JX + i] + si * f[ly.JY + i]
            u[ly.JY + i] = -si * f[ly.JX + i] + co * f[ly.JY + i]
        for i in range(ly.N_DOF):
            ui0 = u[ly.JX + i]
            ui1 = u[ly.JY + i]
            ui2 = f[ly.AA + i]
            if ui0 == 0.0 and ui1 == 0.0 and ui2 == 0.0:
                continue
            vi0 = b00 * ui0 + b01 * ui1 + b02 * ui2
            vi1 = b01 * ui0 + b11 * ui1 + b12 * ui2
            vi2 = b02 * ui0 + b12 * ui1 + b22 * ui2
            for j in range(i, ly.N_DOF):
                M[i, j] += vi0 * u[ly.JX + j] + vi1 * u[ly.JY + j] + vi2 * f[ly.AA + j]
            h[i] += ui0 * hx + ui1 * hy + ui2 * ha
            Q[i] += ui0 * gx + ui1 * gy + ui2 * ga
            # U^T F and F^T U on the local columns
            for k in range(3):
                fk = (ui0 * acc[A_E + k] + ui1 * acc[A_E + 3 + k]
                      + ui2 * acc[A_F3 + k])
                c = i0 + k
                if c > i:
                    M[i, c] += fk
                elif c < i:
                    M[c, i] += fk
                else:
                    M[i, i] += 2.0 * fk
        v_grav = g * (m * f[ly.RY] + si * cx + co * cy)
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


@nb.njit(**JIT)
def frame_sums(q, qd, P, tab, rec, M, h, Q):
    """Add every element's M (upper triangle), h and gravity Q; return V_gravity (erg).

    The frames in ``rec`` must be current (:func:`~.kinematics.compute_frames`).
    """
    acc = rec[ly.REC_ACC]
    g = P[ly.P_GRAV]
    ng = int(P[ly.P_N_GAUSS])
    # beam A: the ground frame
    _reset(acc)
    for k in range(ng):
        row = tab[k]
        w = row[ly.T_WEIGHT]
        _add_beam_point(acc, P[ly.P_MU_A] * w, P[ly.P_RHOI_A] * w, row, q, qd, ly.W_A, 0.0,
                        row[ly.T_DN1], row[ly.T_DN2], 0.0)
    v_grav = _add_frame(acc, rec[ly.REC_JOINT], rec[ly.REC_U], False, ly.W_A, g, M, h, Q)
    # joint body: a rigid point of the joint frame
    fj = rec[ly.REC_JOINT]
    _reset(acc)
    _add_rigid_point(acc, P[ly.P_M3], P[ly.P_I3], P[ly.P_C3], 0.0, fj[ly.RATE])
    v_grav += _add_frame(acc, fj, rec[ly.REC_U], True, ly.W_A, g, M, h, Q)
    # loose body, beam B and the tip mass: the loose-body frame
    fl = rec[ly.REC_LOOSE]
    omega = fl[ly.RATE]
    _reset(acc)
    _add_rigid_point(acc, P[ly.P_M4], P[ly.P_I4], P[ly.P_C4], 0.0, omega)
    for k in range(ng):
        row = tab[ng + k]
        w = row[ly.T_WEIGHT]
        _add_beam_point(acc, P[ly.P_MU_B] * w, P[ly.P_RHOI_B] * w, row, q, qd, ly.W_B,
                        P[ly.P_L4], row[ly.T_DN1], row[ly.T_DN2], omega)
    _add_beam_point(acc, P[ly.P_M6], P[ly.P_I6], tab[tip_row(P, ly.R_TIP_B)], q, qd, ly.W_B,
                    P[ly.P_L4], 0.0, 1.0, omega)
    v_grav += _add_frame(acc, fl, rec[ly.REC_U], True, ly.W_B, g, M, h, Q)
    return v_grav
