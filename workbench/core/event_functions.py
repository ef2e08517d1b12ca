"""The event functions of a regime (docs/model.md §7), jit-compiled.

Every event function goes from + to - when its event happens (layout ``EV_*``):

    open gap g_k + arm_k                    impact of point k (arm_k: GAP_EPS, or
                                            the depth at which a released point
                                            left, rg[RG_ARM + k])
    lambda_n,k + LAMBDA_EPS, active k       separation of point k (or, in a sticking
                                            double contact, the move of its
                                            tangential row to the other point)
    mu_s sum lambda_n - |lambda_t| + tol    stick -> slip (tol: FRICTION_REL_EPS)
    sigma tau' + RATE_EPS                   slip -> stick (or reversal)
"""
import numba as nb

from .config import JIT, JIT_INLINE, LAMBDA_EPS, RATE_EPS
from . import layout as ly
from .constrained import stick_margin, stick_tolerance, tangent_point
from .contact import fill_geometry, in_set, row_rate


@nb.njit(**JIT)
def event_values(y, P, free, cg, rg, ev, row, rate_row):
    """Event functions of the regime in rg at y into ev[row] (gap rates into ev[rate_row]).

    The contact forces in rg must be those of y (rhs_regime just ran).
    """
    fill_geometry(y, P, cg)
    _values(y, P, free, cg, rg, ev, row, rate_row)


@nb.njit(**JIT_INLINE)
def event_values_after_rhs(y, P, free, cg, rg, ev, row, rate_row):
    """:func:`event_values` right after ``rhs_regime`` at y: in contact, its geometry in cg
    is y's already (``constrained.add_contact_forces`` filled it) and is not computed again."""
    if int(rg[ly.RG_SET]) == 0:
        fill_geometry(y, P, cg)
    _values(y, P, free, cg, rg, ev, row, rate_row)


@nb.njit(**JIT_INLINE)
def _values(y, P, free, cg, rg, ev, row, rate_row):
    """The event functions at y with its geometry in cg."""
    qd = y[ly.N_DOF:ly.N_STATE]
    set_index = int(rg[ly.RG_SET])
    stick = rg[ly.RG_STICK] != 0.0
    double_stick = stick and ly.SET_SECOND[set_index] >= 0
    for p in range(ly.N_POINTS):
        if in_set(set_index, p):
            ev[row, ly.EV_GAP + p] = 1.0
            ev[rate_row, ly.EV_GAP + p] = 0.0
            # a sticking double contact watches its split of forces in EV_STICK
            ev[row, ly.EV_LAMBDA + p] = 1.0 if double_stick else rg[ly.RG_LN + p] + LAMBDA_EPS
        else:
            ev[row, ly.EV_GAP + p] = cg[ly.CG_G + p, ly.CG_VAL] + rg[ly.RG_ARM + p]
            ev[rate_row, ly.EV_GAP + p] = row_rate(cg, ly.CG_G + p, qd)
            ev[row, ly.EV_LAMBDA + p] = 1.0
    ev[row, ly.EV_STICK] = 1.0
    ev[row, ly.EV_SLIP] = 1.0
    if set_index > 0:
        if stick:
            ev[row, ly.EV_STICK] = stick_margin(P, free, cg, rg) + stick_tolerance(P, rg)
        else:
            rate = row_rate(cg, ly.CG_T + tangent_point(set_index), qd)
            ev[row, ly.EV_SLIP] = rg[ly.RG_SIGN] * rate + RATE_EPS
