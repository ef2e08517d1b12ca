"""Contact geometry of the loose joint (docs/model.md §7), jit-compiled.

In the joint frame the plates' inner faces lie at y = +-H, H = h4/2 + gap/2,
and the lips at x_lip; D = x_lip - x_in.  Four contact points (seed Fig. 4):

    1  loose body's inner-end lower corner on the lower plate face
    2  loose body's inner-end upper corner on the upper plate face
    3  lower lip corner (x_lip, -H) on the loose body's lower face
    4  upper lip corner (x_lip, +H) on the loose body's upper face

Gaps (>= 0 open) and tangential coordinates (tau' is the slip velocity of
the loose body relative to the joint body along the contact, outward):

    g1 = gap/2 + v + (h4/2)(1 - cos psi)         tau1 = x_in + s + (h4/2) sin psi
    g2 = gap/2 - v + (h4/2)(1 - cos psi)         tau2 = x_in + s - (h4/2) sin psi
    g3 = (H + v) cos psi + (D - s) sin psi - h4/2
                                   tau3 = -[(D - s) cos psi - (H + v) sin psi]
    g4 = (H - v) cos psi - (D - s) sin psi - h4/2
                                   tau4 = -[(D - s) cos psi + (H - v) sin psi]

They depend on (s, v, psi) only.  :func:`fill_geometry` writes each value
with its hand-derived gradient and Hessian (tested against finite
differences in tests/core/test_contact.py) into the record ``cg`` (layout
``CG_*``).
"""

import numba as nb

from .config import JIT, JIT_INLINE
from . import layout as ly
from .kinematics import cos_sin


@nb.njit(**JIT_INLINE)
def _put(cg, row, val, ds, dv, dp, hss, hsv, hsp, hvv, hvp, hpp):
    r = cg[row]
    r[ly.CG_VAL] = val
    r[ly.CG_DS] = ds
    r[ly.CG_DV] = dv
    r[ly.CG_DPSI] = dp
    r[ly.CG_HSS] = hss
    r[ly.CG_HSV] = hsv
    r[ly.CG_HSP] = hsp
    r[ly.CG_HVV] = hvv
    r[ly.CG_HVP] = hvp
    r[ly.CG_HPP] = hpp


@nb.njit(**JIT)
def fill_geometry(q, P, cg):
    """Gaps g1..g4 and tangents tau1..tau4 with derivatives (cm, cm/rad, ...) into cg."""
    s = q[ly.S]
    v = q[ly.V]
    c, sn = cos_sin(q[ly.PSI])
    a = 0.5 * P[ly.P_H4]                      # h4 / 2
    half_gap = 0.5 * P[ly.P_GAP]
    H = a + half_gap
    Dms = P[ly.P_X_LIP] - P[ly.P_X_IN] - s    # D - s
    Hpv = H + v
    Hmv = H - v
    # points 1, 2: the inner-end corners against the plate faces
    _put(cg, ly.CG_G + 0, half_gap + v + a * (1.0 - c), 0.0, 1.0, a * sn,
         0.0, 0.0, 0.0, 0.0, 0.0, a * c)
    _put(cg, ly.CG_G + 1, half_gap - v + a * (1.0 - c), 0.0, -1.0, a * sn,
         0.0, 0.0, 0.0, 0.0, 0.0, a * c)
    _put(cg, ly.CG_T + 0, P[ly.P_X_IN] + s + a * sn, 1.0, 0.0, a * c,
         0.0, 0.0, 0.0, 0.0, 0.0, -a * sn)
    _put(cg, ly.CG_T + 1, P[ly.P_X_IN] + s - a * sn, 1.0, 0.0, -a * c,
         0.0, 0.0, 0.0, 0.0, 0.0, a * sn)
    # points 3, 4: the lip corners against the loose body's faces
    _put(cg, ly.CG_G + 2, Hpv * c + Dms * sn - a, -sn, c, -Hpv * sn + Dms * c,
         0.0, 0.0, -c, 0.0, -sn, -Hpv * c - Dms * sn)
    _put(cg, ly.CG_G + 3, Hmv * c - Dms * sn - a, sn, -c, -Hmv * sn - Dms * c,
         0.0, 0.0, c, 0.0, sn, -Hmv * c + Dms * sn)
    _put(cg, ly.CG_T + 2, -(Dms * c - Hpv * sn), c, sn, Dms * sn + Hpv * c,
         0.0, 0.0, -sn, 0.0, c, Dms * c - Hpv * sn)
    _put(cg, ly.CG_T + 3, -(Dms * c + Hmv * sn), c, sn, Dms * sn - Hmv * c,
         0.0, 0.0, -sn, 0.0, c, Dms * c + Hmv * sn)


@nb.njit(**JIT_INLINE)
def row_rate(cg, row, qd):
    """Rate of a geometry row, W q' (cm/s)."""
    r = cg[row]
    return r[ly.CG_DS] * qd[ly.S] + r[ly.CG_DV] * qd[ly.V] + r[ly.CG_DPSI] * qd[ly.PSI]


@nb.njit(**JIT_INLINE)
def row_convective(cg, row, qd):
    """Convective term W' q' = q'^T (d2 row / dq2) q' (cm/s^2)."""
    r = cg[row]
    sd = qd[ly.S]
    vd = qd[ly.V]
    pd = qd[ly.PSI]
    return (r[ly.CG_HSS] * sd * sd + r[ly.CG_HVV] * vd * vd + r[ly.CG_HPP] * pd * pd
            + 2.0 * (r[ly.CG_HSV] * sd * vd + r[ly.CG_HSP] * sd * pd + r[ly.CG_HVP] * vd * pd))


@nb.njit(**JIT_INLINE)
def row_to_dof(cg, row, scale, out):
    """out (9,) += scale * d(row)/dq, the row as a generalised-coordinate vector."""
    r = cg[row]
    out[ly.S] += scale * r[ly.CG_DS]
    out[ly.V] += scale * r[ly.CG_DV]
    out[ly.PSI] += scale * r[ly.CG_DPSI]


@nb.njit(**JIT_INLINE)
def regime_of(set_index, stick):
    """Regime number 0..16 of a contact set (0..8) and stick flag (docs/model.md §7)."""
    if set_index == 0:
        return 0
    return 2 * set_index - 1 if stick else 2 * set_index


@nb.njit(**JIT_INLINE)
def in_set(set_index, point):
    """Whether point (0-based) belongs to contact set ``set_index``."""
    return ly.SET_FIRST[set_index] == point or ly.SET_SECOND[set_index] == point


@nb.njit(**JIT_INLINE)
def set_of_pair(first, second):
    """Contact set index holding the points ``first`` and ``second`` (-1 for none).

    Returns -1 when the pair cannot touch together (1 with 2, 3 with 4).
    """
    for k in range(ly.N_SETS):
        a = ly.SET_FIRST[k]
        b = ly.SET_SECOND[k]
        if (a == first and b == second) or (a == second and b == first):
            return k
    return -1


@nb.njit(**JIT)
def eval_geometry(q, P, cg):
    """:func:`fill_geometry` as an entry point, for tests and Python callers."""
    fill_geometry(q, P, cg)
