"""The sensor channels and energy record of one output sample (docs/model.md §9).

Called right after :func:`~workbench.core.constrained.rhs_regime` at the
sample's state, whose frames, mass matrix, contact forces and q'' it reads.

    strain1, strain2   surface strain -c w''(x) of beam A / beam B (-)
    accel1, accel2     acceleration along the joint / loose body's local y,
                       without gravity (piezoelectric sensors read no static g)
    accel3             beam B, along the local cross-section y
    tip_y              vertical position of beam B's tip (cm)

Accelerations are J q'' + kappa of the sensor point (cm/s^2).
"""

import numba as nb

from .config import JIT, JIT_INLINE
from . import layout as ly
from .constrained import kinetic_energy
from .contact import fill_geometry, regime_of
from .dynamics import cork_energy
from .kinematics import beam_b_point, cos_sin, rigid_point, tip_row


@nb.njit(**JIT_INLINE)
def _local_y_accel(rec, qdd, angle_cos, angle_sin):
    """Acceleration of rec[REC_POINT] along the direction (-sin a, cos a) (cm/s^2)."""
    pt = rec[ly.REC_POINT]
    ax = pt[ly.KX]
    ay = pt[ly.KY]
    for j in range(ly.N_DOF):
        ax += pt[ly.JX + j] * qdd[j]
        ay += pt[ly.JY + j] * qdd[j]
    return -angle_sin * ax + angle_cos * ay


@nb.njit(**JIT_INLINE)
def _strain(row, q, i0, c):
    """Surface strain -c w''(x) at a beam row (-)."""
    return -c * (row[ly.T_DDN1] * q[i0] + row[ly.T_DDN2] * q[i0 + 1])


@nb.njit(**JIT)
def fill_signals(y, ydot, P, tab, kc, rec, mat, vec, cg, rg, st, out):
    """One row of signals (layout SIG_*) of state y with right-hand side ydot."""
    q = y[:ly.N_DOF]
    qd = y[ly.N_DOF:ly.N_STATE]
    qdd = ydot[ly.N_DOF:ly.N_STATE]
    c = P[ly.P_C_STRAIN]
    out[ly.SIG_FORCE1] = vec[ly.VEC_AUX, ly.AUX_F_SHAKER]
    out[ly.SIG_HAMMER] = vec[ly.VEC_AUX, ly.AUX_F_HAMMER]
    out[ly.SIG_STRAIN1] = _strain(tab[tip_row(P, ly.R_STRAIN1)], q, ly.W_A, c)
    out[ly.SIG_STRAIN2] = _strain(tab[tip_row(P, ly.R_STRAIN2)], q, ly.W_B, c)
    joint = rec[ly.REC_JOINT]
    loose = rec[ly.REC_LOOSE]
    rigid_point(rec, ly.REC_JOINT, P[ly.P_X_ACCEL1], 0.0, ly.REC_POINT)
    out[ly.SIG_ACCEL1] = _local_y_accel(rec, qdd, joint[ly.COS], joint[ly.SIN])
    rigid_point(rec, ly.REC_LOOSE, P[ly.P_X_ACCEL2], 0.0, ly.REC_POINT)
    out[ly.SIG_ACCEL2] = _local_y_accel(rec, qdd, loose[ly.COS], loose[ly.SIN])
    row = tab[tip_row(P, ly.R_ACCEL3)]
    beam_b_point(row, q, qd, P, rec, ly.REC_POINT)
    angle = q[ly.PHI_A] + q[ly.PSI] + row[ly.T_DN1] * q[ly.W_B] + row[ly.T_DN2] * q[ly.PHI_B]
    ca, sa = cos_sin(angle)
    out[ly.SIG_ACCEL3] = _local_y_accel(rec, qdd, ca, sa)
    beam_b_point(tab[tip_row(P, ly.R_TIP_B)], q, qd, P, rec, ly.REC_POINT)
    out[ly.SIG_TIP_Y] = rec[ly.REC_POINT, ly.RY]
    fill_geometry(y, P, cg)
    for k in range(ly.N_POINTS):
        out[ly.SIG_GAP + k] = cg[ly.CG_G + k, ly.CG_VAL]
        out[ly.SIG_LN + k] = rg[ly.RG_LN + k]
    out[ly.SIG_LT] = rg[ly.RG_LT]
    out[ly.SIG_REGIME] = regime_of(int(rg[ly.RG_SET]), rg[ly.RG_STICK] != 0.0)
    K = kc[ly.KC_K]
    ela = 0.0
    for i in range(ly.N_DOF):
        for j in range(ly.N_DOF):
            ela += 0.5 * q[i] * K[i, j] * q[j]
    out[ly.SIG_E_KIN] = kinetic_energy(qd, mat)
    out[ly.SIG_E_ELA] = ela
    out[ly.SIG_E_GRAV] = rg[ly.RG_VGRAV]
    out[ly.SIG_E_CORK] = cork_energy(q[ly.S], P)
    out[ly.SIG_W_EXT] = y[ly.A_WORK]
    out[ly.SIG_D_STRUCT] = y[ly.A_DAMP]
    out[ly.SIG_D_CORK] = y[ly.A_CORK]
    out[ly.SIG_D_FRIC] = y[ly.A_FRIC]
    out[ly.SIG_D_IMPACT] = st[ly.ST_E_IMPACT]
    out[ly.SIG_W_CONSTR] = y[ly.A_CONSTR]
    for k in range(ly.N_POINTS):
        out[ly.SIG_D_FRIC_P + k] = y[ly.A_FRIC_P + k]
        out[ly.SIG_D_IMPACT_P + k] = st[ly.ST_E_IMPACT_P + k]
