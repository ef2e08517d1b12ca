"""Kernels of the axial hammer test (seed §4.3, Table 6).

The loose body, beam B and the tip mass slide as one mass m against the
cork (docs/model.md §6): m s'' = -k sign(s) |s|^n - c s', released at s = 0 with
the hammer's velocity v0.  The accelerometer on the tip reads s''.
Integrated by RK4 with ``substeps`` steps per record sample.
"""
import numba as nb
import numpy as np

from .config import JIT, JIT_INLINE, JIT_PARALLEL
from .cork import power_spring
from .layout import ERR_NAN, OK


@nb.njit(**JIT_INLINE)
def _accel(s, v, inv_m, n_exp, k, c):
    return -(power_spring(s, n_exp, k) + c * v) * inv_m


@nb.njit(**JIT_INLINE)
def _rk4(s, v, h, inv_m, n_exp, k, c):
    a1 = _accel(s, v, inv_m, n_exp, k, c)
    a2 = _accel(s + 0.5 * h * v, v + 0.5 * h * a1, inv_m, n_exp, k, c)
    v2 = v + 0.5 * h * a1
    a3 = _accel(s + 0.5 * h * v2, v + 0.5 * h * a2, inv_m, n_exp, k, c)
    v3 = v + 0.5 * h * a2
    a4 = _accel(s + h * v3, v + h * a3, inv_m, n_exp, k, c)
    v4 = v + h * a3
    s_new = s + h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4)
    v_new = v + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return s_new, v_new


@nb.njit(**JIT)
def hammer_response(mass, n_exp, k, c, v0, dt, substeps, out_accel):
    """Fill ``out_accel`` (cm/s^2) with s'' at t = 0, dt, 2 dt, ...; status code."""
    inv_m = 1.0 / mass
    h = dt / substeps
    s = 0.0
    v = v0
    out_accel[0] = _accel(s, v, inv_m, n_exp, k, c)
    for i in range(1, out_accel.shape[0]):
        for _ in range(substeps):
            s, v = _rk4(s, v, h, inv_m, n_exp, k, c)
        out_accel[i] = _accel(s, v, inv_m, n_exp, k, c)
        if not np.isfinite(out_accel[i]):
            return ERR_NAN
    return OK


@nb.njit(**JIT_PARALLEL)
def hammer_scores(mass, n_exp, v0s, ks, cs, dt, substeps, record, out_scores):
    """Sum of squared differences to ``record`` for every (v0, k, c) of the grid.

    ``out_scores`` (len(v0s), len(ks), len(cs)) is filled in parallel over the
    grid; a response that is not finite scores inf.  Returns a status code.
    """
    inv_m = 1.0 / mass
    h = dt / substeps
    n_k = ks.shape[0]
    n_c = cs.shape[0]
    n_all = v0s.shape[0] * n_k * n_c
    for flat in nb.prange(n_all):
        iv = flat // (n_k * n_c)
        ik = (flat // n_c) % n_k
        ic = flat % n_c
        k = ks[ik]
        c = cs[ic]
        s = 0.0
        v = v0s[iv]
        a = _accel(s, v, inv_m, n_exp, k, c)
        score = (a - record[0]) ** 2
        for i in range(1, record.shape[0]):
            for _ in range(substeps):
                s, v = _rk4(s, v, h, inv_m, n_exp, k, c)
            a = _accel(s, v, inv_m, n_exp, k, c)
            score += (a - record[i]) ** 2
        out_scores[iv, ik, ic] = score if np.isfinite(score) else np.inf
    return OK
