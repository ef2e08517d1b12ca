"""Positions, Jacobians and convective accelerations of every mass element.

docs/model.md §4-5.  The chain is: beam A (root frame = global frame), the joint
frame at beam A's tip (angle alpha3 = phi_A), the loose-body frame at
d = (x_in + s, v) in the joint frame (angle alpha4 = phi_A + psi), and beam B
and the tip mass in the loose-body frame, offset by l4.

Every point is "a point rho(q) in a moving frame (r0, alpha)", and two rules
give its acceleration r'' = J q'' + kappa:

    r      = r0 + R(alpha) rho
    J      = J0 + R d(rho)/dq + R S rho a^T              (a = d(alpha)/dq)
    kappa  = kappa0 + R (rho''_conv + 2 alpha' S rho' - alpha'^2 rho)

with R S = S R the derivative of the rotation, and for a beam point the
convective part of the foreshortening -b'^T Sigma b' (docs/model.md §5).

All functions are jit-compiled and write point records (layout ``RX`` ...
``RATE`` of :mod:`~workbench.core.layout`) into rows of ``rec``.  They are
inlined into their callers (``JIT_INLINE``): the kernels pass a few flat
arrays, never tuples of arrays, because numba reference-counts every member
of a tuple at every inlined call (measured ~30x slower per element).
"""
import math

import numba as nb

from .config import JIT, JIT_INLINE
from . import layout as ly


@nb.njit(**JIT_INLINE)
def beam_point_motion(row, q, qd, i0, x_offset):
    """Position (cm), velocity (cm/s) and convective x acceleration (cm/s^2) of a beam point.

    In the beam's root frame (docs/model.md §4): ``row`` a shape-table row,
    ``i0`` the beam's first coordinate, ``x_offset`` the root along the
    frame's x axis.  Returns ``(rx, ry, vx, vy, kx, sb0, sb1)``, with
    Sigma b = (sb0, sb1) the foreshortening gradient (the convective y
    acceleration is 0).
    """
    w = q[i0]
    phi = q[i0 + 1]
    wd = qd[i0]
    phid = qd[i0 + 1]
    s00 = row[ly.T_S00]
    s01 = row[ly.T_S01]
    s11 = row[ly.T_S11]
    xi = row[ly.T_XI]
    n1 = row[ly.T_N1]
    n2 = row[ly.T_N2]
    sb0 = s00 * w + s01 * phi      # (Sigma b)_0
    sb1 = s01 * w + s11 * phi      # (Sigma b)_1
    rx = x_offset + row[ly.T_X] + xi * q[i0 + 2] - 0.5 * (w * sb0 + phi * sb1)
    ry = n1 * w + n2 * phi
    vx = -sb0 * wd - sb1 * phid + xi * qd[i0 + 2]
    vy = n1 * wd + n2 * phid
    kx = -(s00 * wd * wd + 2.0 * s01 * wd * phid + s11 * phid * phid)
    return rx, ry, vx, vy, kx, sb0, sb1


@nb.njit(**JIT_INLINE)
def beam_point_local(row, q, qd, i0, x_offset, rec, dst):
    """A beam point in the beam's root frame (docs/model.md §4) into ``rec[dst]``.

    ``row`` a shape-table row, ``i0`` the beam's first coordinate (W_A or
    W_B), ``x_offset`` the root's position along the frame's x axis (cm).
    Fills position (cm), velocity (cm/s), convective acceleration (cm/s^2)
    and the Jacobian d(rho)/dq; the angle row is left alone.
    """
    rx, ry, vx, vy, kx, sb0, sb1 = beam_point_motion(row, q, qd, i0, x_offset)
    r = rec[dst]
    r[ly.RX] = rx
    r[ly.RY] = ry
    r[ly.VX] = vx
    r[ly.VY] = vy
    r[ly.KX] = kx
    r[ly.KY] = 0.0
    for j in range(ly.N_DOF):
        r[ly.JX + j] = 0.0
        r[ly.JY + j] = 0.0
    r[ly.JX + i0] = -sb0
    r[ly.JX + i0 + 1] = -sb1
    r[ly.JX + i0 + 2] = row[ly.T_XI]
    r[ly.JY + i0] = row[ly.T_N1]
    r[ly.JY + i0 + 1] = row[ly.T_N2]


@nb.njit(**JIT_INLINE)
def attach(rec, frame, src, dst, rigid):
    """Carry point ``rec[src]`` of frame ``rec[frame]`` to global ``rec[dst]``.

    ``rigid`` True means the point is fixed in the frame: its Jacobian,
    velocity and convective part are then not read.  The angle row of dst is
    left alone.
    """
    f = rec[frame]
    p = rec[src]
    d = rec[dst]
    c = f[ly.COS]
    s = f[ly.SIN]
    ad = f[ly.RATE]
    rx = c * p[ly.RX] - s * p[ly.RY]          # R rho
    ry = s * p[ly.RX] + c * p[ly.RY]
    if rigid:
        lx = -ad * ad * p[ly.RX]
        ly_ = -ad * ad * p[ly.RY]
        for j in range(ly.N_DOF):             # J0 + (R S rho) a^T, R S rho = (-ry, rx)
            d[ly.JX + j] = f[ly.JX + j] - ry * f[ly.AA + j]
            d[ly.JY + j] = f[ly.JY + j] + rx * f[ly.AA + j]
    else:
        # rho''_conv + 2 alpha' S rho' - alpha'^2 rho, with S rho' = (-vy, vx)
        lx = p[ly.KX] - 2.0 * ad * p[ly.VY] - ad * ad * p[ly.RX]
        ly_ = p[ly.KY] + 2.0 * ad * p[ly.VX] - ad * ad * p[ly.RY]
        for j in range(ly.N_DOF):             # ... + R d(rho)/dq
            d[ly.JX + j] = f[ly.JX + j] - ry * f[ly.AA + j] + c * p[ly.JX + j] - s * p[ly.JY + j]
            d[ly.JY + j] = f[ly.JY + j] + rx * f[ly.AA + j] + s * p[ly.JX + j] + c * p[ly.JY + j]
    d[ly.RX] = f[ly.RX] + rx
    d[ly.RY] = f[ly.RY] + ry
    d[ly.KX] = f[ly.KX] + c * lx - s * ly_
    d[ly.KY] = f[ly.KY] + s * lx + c * ly_


#: Below this |angle| (rad) :func:`cos_sin` sums the series: its first terms left out are
#: below 2^-67 of the sums, and the sums within an ulp of libm's (tests/core/test_kinematics.py).
SMALL_ANGLE = 0.25


@nb.njit(**JIT_INLINE)
def cos_sin(angle):
    """(cos angle, sin angle): the Taylor series to angle^14 and angle^13 (Horner) where
    |angle| <= SMALL_ANGLE (the beams' slopes and the loose body's tilt), else libm's."""
    if abs(angle) > SMALL_ANGLE:
        return math.cos(angle), math.sin(angle)
    x2 = angle * angle
    c = 1.0 + x2 * (-1.0 / 2.0 + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 * (
        1.0 / 40320.0 + x2 * (-1.0 / 3628800.0 + x2 * (1.0 / 479001600.0 + x2 * (
            -1.0 / 87178291200.0)))))))
    s = angle + angle * x2 * (-1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (
        1.0 / 362880.0 + x2 * (-1.0 / 39916800.0 + x2 * (1.0 / 6227020800.0))))))
    return c, s


@nb.njit(**JIT_INLINE)
def _set_angle(rec, row, angle, rate):
    rec[row, ly.COS], rec[row, ly.SIN] = cos_sin(angle)
    rec[row, ly.RATE] = rate


@nb.njit(**JIT_INLINE)
def tip_row(P, which):
    """Row of the shape table holding special point ``which`` (an R_* index)."""
    return 2 * int(P[ly.P_N_GAUSS]) + which


@nb.njit(**JIT_INLINE)
def compute_frames(q, qd, P, tab, rec):
    """Fill the joint-frame and loose-frame records of ``rec``."""
    # Joint frame: origin at beam A's tip; beam A's root frame is global.
    beam_point_local(tab[tip_row(P, ly.R_TIP_A)], q, qd, ly.W_A, 0.0, rec, ly.REC_JOINT)
    _set_angle(rec, ly.REC_JOINT, q[ly.PHI_A], qd[ly.PHI_A])
    # Loose-body frame: origin d = (x_in + s, v) in the joint frame.
    p = rec[ly.REC_LOCAL]
    p[ly.RX] = P[ly.P_X_IN] + q[ly.S]
    p[ly.RY] = q[ly.V]
    p[ly.VX] = qd[ly.S]
    p[ly.VY] = qd[ly.V]
    p[ly.KX] = 0.0
    p[ly.KY] = 0.0
    for j in range(ly.N_DOF):
        p[ly.JX + j] = 0.0
        p[ly.JY + j] = 0.0
        rec[ly.REC_JOINT, ly.AA + j] = 0.0
    p[ly.JX + ly.S] = 1.0
    p[ly.JY + ly.V] = 1.0
    rec[ly.REC_JOINT, ly.AA + ly.PHI_A] = 1.0
    attach(rec, ly.REC_JOINT, ly.REC_LOCAL, ly.REC_LOOSE, False)
    _set_angle(rec, ly.REC_LOOSE, q[ly.PHI_A] + q[ly.PSI], qd[ly.PHI_A] + qd[ly.PSI])
    for j in range(ly.N_DOF):
        rec[ly.REC_LOOSE, ly.AA + j] = 0.0
    rec[ly.REC_LOOSE, ly.AA + ly.PHI_A] = 1.0
    rec[ly.REC_LOOSE, ly.AA + ly.PSI] = 1.0


@nb.njit(**JIT_INLINE)
def rigid_point(rec, frame, x, y, dst):
    """The point (x, y) (cm) fixed in ``frame``, carried to global ``rec[dst]``."""
    rec[ly.REC_LOCAL, ly.RX] = x
    rec[ly.REC_LOCAL, ly.RY] = y
    attach(rec, frame, ly.REC_LOCAL, dst, True)


@nb.njit(**JIT_INLINE)
def beam_b_point(row, q, qd, P, rec, dst):
    """A beam B point (a row of its shape table), global, into ``rec[dst]``."""
    beam_point_local(row, q, qd, ly.W_B, P[ly.P_L4], rec, ly.REC_LOCAL)
    attach(rec, ly.REC_LOOSE, ly.REC_LOCAL, dst, False)


@nb.njit(**JIT_INLINE)
def n_elements(P):
    """Number of mass elements: the Gauss points of both beams, three bodies."""
    return 2 * int(P[ly.P_N_GAUSS]) + 3


@nb.njit(**JIT)
def element(k, q, qd, P, tab, rec):
    """Kinematics of mass element ``k`` into ``rec[REC_POINT]``, angle row included.

    The frames must be current (:func:`compute_frames`).  Returns
    ``(mass (g), rotary inertia (g cm^2), angle (rad))``.  Order: beam A
    Gauss points, joint body CM, loose body CM, beam B Gauss points, tip mass.
    """
    ng = int(P[ly.P_N_GAUSS])
    pt = rec[ly.REC_POINT]
    dst = ly.REC_POINT
    if k < ng:                                     # beam A, angle w_A'(x)
        row = tab[k]
        beam_point_local(row, q, qd, ly.W_A, 0.0, rec, dst)
        mass = P[ly.P_MU_A] * row[ly.T_WEIGHT]
        rot = P[ly.P_RHOI_A] * row[ly.T_WEIGHT]
        da_w, da_phi, da_psi, da_wb, da_phib = row[ly.T_DN1], row[ly.T_DN2], 0.0, 0.0, 0.0
    elif k == ng:                                  # joint body CM, angle phi_A
        rigid_point(rec, ly.REC_JOINT, P[ly.P_C3], 0.0, dst)
        mass = P[ly.P_M3]
        rot = P[ly.P_I3]
        da_w, da_phi, da_psi, da_wb, da_phib = 0.0, 1.0, 0.0, 0.0, 0.0
    elif k == ng + 1:                              # loose body CM, angle phi_A + psi
        rigid_point(rec, ly.REC_LOOSE, P[ly.P_C4], 0.0, dst)
        mass = P[ly.P_M4]
        rot = P[ly.P_I4]
        da_w, da_phi, da_psi, da_wb, da_phib = 0.0, 1.0, 1.0, 0.0, 0.0
    elif k < 2 * ng + 2:                           # beam B, angle phi_A + psi + w_B'(x)
        row = tab[k - 2]
        beam_b_point(row, q, qd, P, rec, dst)
        mass = P[ly.P_MU_B] * row[ly.T_WEIGHT]
        rot = P[ly.P_RHOI_B] * row[ly.T_WEIGHT]
        da_w, da_phi, da_psi, da_wb, da_phib = 0.0, 1.0, 1.0, row[ly.T_DN1], row[ly.T_DN2]
    else:                                          # tip mass, angle phi_A + psi + phi_B
        beam_b_point(tab[tip_row(P, ly.R_TIP_B)], q, qd, P, rec, dst)
        mass = P[ly.P_M6]
        rot = P[ly.P_I6]
        da_w, da_phi, da_psi, da_wb, da_phib = 0.0, 1.0, 1.0, 0.0, 1.0
    for j in range(ly.N_DOF):
        pt[ly.AA + j] = 0.0
    pt[ly.AA + ly.W_A] = da_w
    pt[ly.AA + ly.PHI_A] = da_phi
    pt[ly.AA + ly.PSI] = da_psi
    pt[ly.AA + ly.W_B] = da_wb
    pt[ly.AA + ly.PHI_B] = da_phib
    angle = 0.0                                    # every angle is linear in q
    for j in range(ly.N_DOF):
        angle += pt[ly.AA + j] * q[j]
    return mass, rot, angle


@nb.njit(**JIT)
def element_kinematics(q, qd, P, tab, rec, r, J, kap, a, mass, rot, angle):
    """All mass elements at once, for tests and diagnostics (not a hot path).

    Fills r (n_el, 2), J (n_el, 2, 9), kap (n_el, 2), a (n_el, 9), mass,
    rot and angle (n_el,).
    """
    compute_frames(q, qd, P, tab, rec)
    for k in range(n_elements(P)):
        mass[k], rot[k], angle[k] = element(k, q, qd, P, tab, rec)
        pt = rec[ly.REC_POINT]
        r[k, 0] = pt[ly.RX]
        r[k, 1] = pt[ly.RY]
        kap[k, 0] = pt[ly.KX]
        kap[k, 1] = pt[ly.KY]
        for j in range(ly.N_DOF):
            J[k, 0, j] = pt[ly.JX + j]
            J[k, 1, j] = pt[ly.JY + j]
            a[k, j] = pt[ly.AA + j]
