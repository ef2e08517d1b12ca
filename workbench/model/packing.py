"""Pack validated :class:`~workbench.model.params.Parameters` into kernel arrays.

The kernels see a few flat arrays whose layout is declared in
:mod:`workbench.core.layout`.  Python code carries them as two named tuples,
:class:`Model` (what is simulated) and :class:`Work` (scratch), and passes
them unpacked: ``eval_rhs(t, y, *model, ex, *work, ydot)``.  Build a model
once per parameter set; a sweep builds one per grid point and never
recompiles.

Holding coordinates fixed
-------------------------
``build(params, fixed=("s", "v", "psi"))`` holds the named coordinates at
their initial values: their equations are dropped and their accelerations
are zero.  Their initial velocities must be zero.  ``JOINT`` names the three
joint coordinates, so ``fixed=JOINT`` is the locked joint of docs/model.md.
"""
from __future__ import annotations

import functools
import math
from collections import namedtuple
from collections.abc import Iterable

import numpy as np

from ..core import layout as ly
from ..core.cork import FORMS as CORK_FORMS
from ..core.dynamics import fill_stiffness_damping
from ..core.inertia import fill_invariants
from ..core.shapes import fill_shape_row
from .params import ParameterError, Parameters
from .tableaus import RK4, write_tableau

#: The loose joint's coordinates; ``fixed=JOINT`` locks the joint.
JOINT = ("s", "v", "psi")

#: What the kernels simulate: ``P`` (N_PARAMS,) parameters, ``tab``
#: (2 n_gauss + N_PTS, N_TAB) shape table (beam A Gauss rows, beam B Gauss
#: rows, special points), ``kc`` (2, 9, 9) stiffness and damping, ``free``
#: (n_free,) int64 indices of the coordinates that move.
Model = namedtuple("Model", "P tab kc free")

#: Scratch of one thread of kernel calls: ``rec`` (N_RECS, N_REC) point
#: records, ``mat`` (2, 9, 9), ``vec`` (N_VEC, 9), ``stages`` (N_STAGES,
#: N_AUG), contact geometry ``cg`` (2 N_POINTS, N_CG), constraint work ``cw``
#: (N_CW, N_CW_COLS), regime record ``rg`` (N_RG,) and event values ``ev``
#: (N_EV_ROWS, N_EV).
Work = namedtuple("Work", "rec mat vec stages cg cw rg ev")


def coordinate_index(name: str | int) -> int:
    """Index of a coordinate given by name (``"phi_A"``) or index."""
    if isinstance(name, (int, np.integer)) and not isinstance(name, bool):
        if 0 <= name < ly.N_DOF:
            return int(name)
    elif name in ly.COORD_NAMES:
        return ly.COORD_NAMES.index(name)
    raise ParameterError(f"unknown coordinate {name!r}; valid: {', '.join(ly.COORD_NAMES)} "
                         f"or 0..{ly.N_DOF - 1}")


def pack(p: Parameters, tab: np.ndarray | None = None) -> np.ndarray:
    """The flat parameter array P (N_PARAMS,), CGS, in the declared layout; the beams'
    inertia invariants from the shape table ``tab`` (default :func:`shape_table` of p)."""
    P = np.zeros(ly.N_PARAMS)
    P[ly.P_L_A], P[ly.P_L_B] = p.l_a, p.l_b
    P[ly.P_MU_A], P[ly.P_MU_B] = p.mu_a, p.mu_b
    P[ly.P_RHOI_A], P[ly.P_RHOI_B] = p.rho_i_a, p.rho_i_b
    P[ly.P_EI_A], P[ly.P_EI_B] = p.e_a * p.inertia_a, p.e_b * p.inertia_b
    P[ly.P_EA_A], P[ly.P_EA_B] = p.e_a * p.area_a, p.e_b * p.area_b
    P[ly.P_BETA_A], P[ly.P_BETA_B] = p.damping_beta("a"), p.damping_beta("b")
    P[ly.P_C_AX_A], P[ly.P_C_AX_B] = p.axial_damping("a"), p.axial_damping("b")
    P[ly.P_S_TRAVEL], P[ly.P_K_STOP] = p.s_travel, p.k_stop
    P[ly.P_M3], P[ly.P_I3], P[ly.P_C3] = p.m3, p.i3, p.c3
    P[ly.P_X_IN], P[ly.P_X_LIP] = p.x_in, p.x_lip
    P[ly.P_M4], P[ly.P_I4], P[ly.P_L4], P[ly.P_C4] = p.m4, p.i4, p.l4, p.loose_cm
    P[ly.P_H4], P[ly.P_GAP] = p.h4, p.gap
    on = 1.0 if p.tip_mass else 0.0
    P[ly.P_M6], P[ly.P_I6] = on * p.m6, on * p.i6
    P[ly.P_MU_S], P[ly.P_MU_K] = p.mu_s, p.mu_k
    P[ly.P_GRAV] = p.g
    law = p.cork_law
    if law.form not in CORK_FORMS:
        raise ParameterError(f"cork = {p.cork!r} has the form {law.form!r}, which the kernels do "
                             f"not have; forms: {', '.join(CORK_FORMS)}")
    P[ly.P_CORK_FORM] = CORK_FORMS.index(law.form)
    P[ly.P_CORK_N], P[ly.P_CORK_K], P[ly.P_CORK_C] = law.n, law.k, law.c
    P[ly.P_K_V], P[ly.P_K_PSI] = p.k_v, p.k_psi
    P[ly.P_X_FORCE] = p.x_force
    P[ly.P_C_STRAIN] = p.c_strain
    P[ly.P_N_GAUSS] = p.n_gauss
    P[ly.P_X_ACCEL1], P[ly.P_X_ACCEL2] = p.x_accel1, p.x_accel2
    # needs the linear eigenvalues, which need this array: workbench.model.simulate sets it
    P[ly.P_STEPPED_DT] = math.inf
    write_tableau(P, RK4)       # the step method; a run's method may write another
    fill_invariants(P, shape_table(p) if tab is None else tab)
    return P


@functools.lru_cache(maxsize=None)
def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The n Gauss-Legendre nodes and weights on [-1, 1] (read-only arrays, computed once)."""
    nodes, weights = np.polynomial.legendre.leggauss(n)
    nodes.flags.writeable = False
    weights.flags.writeable = False
    return nodes, weights


def gauss_table(length: float, n: int) -> np.ndarray:
    """Shape-table rows (n, N_TAB) at the n Gauss-Legendre points of [0, length]."""
    nodes, weights = gauss_legendre(n)
    tab = np.zeros((n, ly.N_TAB))
    for i, (x, w) in enumerate(zip(nodes, weights)):
        fill_shape_row(0.5 * (x + 1.0), length, 0.5 * length * w, tab[i])
    return tab


def shape_table(p: Parameters) -> np.ndarray:
    """The shape table: beam A Gauss rows, beam B Gauss rows, special points."""
    pts = np.zeros((ly.N_PTS, ly.N_TAB))
    for row, x, length in ((ly.R_TIP_A, p.l_a, p.l_a), (ly.R_TIP_B, p.l_b, p.l_b),
                           (ly.R_FORCE1, p.x_force, p.l_a), (ly.R_STRAIN1, p.x_strain1, p.l_a),
                           (ly.R_STRAIN2, p.x_strain2, p.l_b), (ly.R_ACCEL3, p.x_accel3, p.l_b)):
        fill_shape_row(x / length, length, 0.0, pts[row])
    return np.vstack([gauss_table(p.l_a, p.n_gauss), gauss_table(p.l_b, p.n_gauss), pts])


def build(p: Parameters, fixed: Iterable[str | int] = ()) -> Model:
    """The kernel-side model of parameters ``p`` with ``fixed`` coordinates held: fresh
    arrays (a caller may write a method's tableau into P), copied from the parameters'
    arrays packed once (:func:`_packed`)."""
    if not isinstance(p, Parameters):
        raise ParameterError(f"expected workbench.model.params.Parameters, got {type(p).__name__}")
    held = {coordinate_index(c) for c in fixed}
    free = np.array([i for i in range(ly.N_DOF) if i not in held], dtype=np.int64)
    if free.size == 0:
        raise ParameterError("fixed holds every coordinate; at least one must move")
    P, tab, kc = (a.copy() for a in _packed(p))
    return Model(P=P, tab=tab, kc=kc, free=free)


@functools.lru_cache(maxsize=64)
def _packed(p: Parameters) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P, the shape table and K and C of ``p``, read-only: a run packs its parameters once
    for the run, its static start and its linear model (joint free and locked)."""
    tab = shape_table(p)
    P = pack(p, tab)
    kc = np.zeros((2, ly.N_DOF, ly.N_DOF))
    fill_stiffness_damping(P, kc)
    arrays = (P, tab, kc)
    for a in arrays:
        a.flags.writeable = False
    return arrays


def make_work() -> Work:
    """Fresh scratch arrays for one thread of kernel calls."""
    return Work(rec=np.zeros((ly.N_RECS, ly.N_REC)), mat=np.zeros((2, ly.N_DOF, ly.N_DOF)),
                vec=np.zeros((ly.N_VEC, ly.N_DOF)), stages=np.zeros((ly.N_STAGES, ly.N_AUG)),
                cg=np.zeros((2 * ly.N_POINTS, ly.N_CG)), cw=np.zeros((ly.N_CW, ly.N_CW_COLS)),
                rg=np.zeros(ly.N_RG), ev=np.zeros((ly.N_EV_ROWS, ly.N_EV)))


def state(q=None, qd=None) -> np.ndarray:
    """An 18-state vector from q and q' (each 9 values or a {name: value} dict)."""
    y = np.zeros(ly.N_STATE)
    for offset, part in ((0, q), (ly.N_DOF, qd)):
        if part is None:
            continue
        if isinstance(part, dict):
            for name, value in part.items():
                y[offset + coordinate_index(name)] = value
        else:
            arr = np.asarray(part, dtype=float)
            if arr.shape != (ly.N_DOF,):
                raise ParameterError(f"q and qd must have {ly.N_DOF} values, got shape {arr.shape}")
            y[offset:offset + ly.N_DOF] = arr
    if not np.all(np.isfinite(y)):
        raise ParameterError("the initial state has NaN or infinite values")
    return y
