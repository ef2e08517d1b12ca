"""The scales on which the step's error is measured, jit-compiled.

A component of (q, q') is measured on the largest |value| so far of it or
of its PARTNER (the two components of one point's motion: a beam tip's
deflection and elongation, the loose body's slide and offset), not below a
floor from the model's clearance (:func:`floors`); a gap on the clearance;
a normal force or the stick margin on the largest total normal force so far
(not below the loose body's weight); a slip rate on the loose body's
velocity scale.
"""
import numba as nb

import os
from .config import JIT, JIT_INLINE, REF_RATE
#: Experiment: the forces' error scales times FORCE_MULT (environment; a compile-time
#: constant, so give each value its own WORKBENCH_CACHE_ROOT).
FORCE_MULT = float(os.environ.get('FORCE_MULT', '1'))
from . import layout as ly

#: The coordinate sharing a component's scale: a beam tip's deflection and
#: elongation, and the loose body's slide and offset, are the two
#: components of one point's motion (cm); an angle has a scale of its own.
PARTNER = (ly.U_A, ly.PHI_A, ly.W_A, ly.V, ly.S, ly.PSI, ly.U_B, ly.PHI_B, ly.W_B)


@nb.njit(**JIT)
def floors(P, scale):
    """The smallest error scale of each component of (q, q') (cm, rad, and per s)."""
    c = P[ly.P_GAP]
    for i in range(ly.N_DOF):
        scale[ly.SCALE_FLOOR, i] = c
    scale[ly.SCALE_FLOOR, ly.PHI_A] = c / P[ly.P_L_A]
    scale[ly.SCALE_FLOOR, ly.PHI_B] = c / P[ly.P_L_B]
    scale[ly.SCALE_FLOOR, ly.PSI] = c / P[ly.P_L4]
    for i in range(ly.N_DOF):
        scale[ly.SCALE_FLOOR, ly.N_DOF + i] = REF_RATE * scale[ly.SCALE_FLOOR, i]


@nb.njit(**JIT_INLINE)
def grow_scales(y, total_force, scale, ctl):
    """Raise the peaks by the state y and the total normal force (dyn) at it."""
    for i in range(ly.N_STATE):
        scale[ly.SCALE_PEAK, i] = max(scale[ly.SCALE_PEAK, i], abs(y[i]))
    ctl[ly.CTL_F_SCALE] = max(ctl[ly.CTL_F_SCALE], total_force)


@nb.njit(**JIT_INLINE)
def total_normal_force(rg):
    """Sum of |lambda_n| over the points (dyn) of the last right-hand side."""
    total = 0.0
    for p in range(ly.N_POINTS):
        total += abs(rg[ly.RG_LN + p])
    return total


@nb.njit(**JIT_INLINE)
def state_scale(i, y, scale):
    """The error scale of component i of (q, q') at y (its unit)."""
    j = PARTNER[i % ly.N_DOF] + (i // ly.N_DOF) * ly.N_DOF
    return max(scale[ly.SCALE_FLOOR, i], scale[ly.SCALE_PEAK, i], scale[ly.SCALE_PEAK, j],
               abs(y[i]))


@nb.njit(**JIT_INLINE)
def event_scale(e, P, scale, ctl):
    """The error scale of event function e: cm for a gap, cm/s for a slip rate, dyn for a force."""
    if e < ly.EV_GAP + ly.N_POINTS:
        return P[ly.P_GAP]
    if e == ly.EV_SLIP:
        return max(scale[ly.SCALE_FLOOR, ly.N_DOF + ly.S], scale[ly.SCALE_PEAK, ly.N_DOF + ly.S],
                   scale[ly.SCALE_PEAK, ly.N_DOF + ly.V])
    return FORCE_MULT * max(ctl[ly.CTL_F_SCALE], P[ly.P_M4] * P[ly.P_GRAV])
