"""Fixed-step classical Runge-Kutta (RK4) integration, jit-compiled.

One step of size dt advances y by (k1 + 2 k2 + 2 k3 + k4) dt / 6; global
error O(dt^4).  The state is the augmented one (layout ``A_*``): (q, q')
and the running integrals of the energy account, so that the account has
the integrator's accuracy.  :func:`rk4_step` serves both the free-flight
integration here and the event-driven integration of
:mod:`workbench.core.hybrid`, which re-integrates partial steps with it.
Arguments follow :mod:`workbench.core.constrained`; ``stages``
(N_STAGES, N_AUG) is scratch.
"""
import math

import numba as nb

from .config import JIT
from . import layout as ly
from .constrained import rhs_regime

# Butcher tableau of classical RK4: stage times c, stage weights for the
# next stage's state, and the final weights b.
_C = (0.0, 0.5, 0.5, 1.0)
_A_NEXT = (0.5, 0.5, 1.0)
_B = (1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0)
#: The order of the step (global error O(dt^ORDER)).
ORDER = 4


@nb.njit(**JIT)
def rk4_step(t, y, dt, P, tab, kc, free, ex, rec, mat, vec, stages, cg, cw, rg, y_new):
    """One RK4 step from (t, y) into y_new (may not alias y) in the regime of rg.

    k1 = f(t, y) must already be in stages[STAGE_K1] (the caller evaluated
    it, e.g. for the events at the step's start).  Returns a status.
    """
    n = ly.N_AUG
    yt = stages[ly.STAGE_TMP]
    for i in range(n):
        stages[0, i] = stages[ly.STAGE_K1, i]
    for st in range(4):
        if st > 0:
            status = rhs_regime(t + _C[st] * dt, yt, P, tab, kc, free, ex, rec, mat, vec,
                                cg, cw, rg, stages[st])
            if status != ly.OK:
                return status
        if st < 3:
            h = _A_NEXT[st] * dt
            for i in range(n):
                yt[i] = y[i] + h * stages[st, i]
    for i in range(n):
        y_new[i] = y[i] + dt * (_B[0] * stages[0, i] + _B[1] * stages[1, i]
                                + _B[2] * stages[2, i] + _B[3] * stages[3, i])
        if not math.isfinite(y_new[i]):
            return ly.ERR_NAN
    return ly.OK


@nb.njit(**JIT)
def integrate_fixed(y0, t0, dt, n_steps, decim, P, tab, kc, free, ex, rec, mat, vec,
                    stages, cg, cw, rg, ev, out_t, out_y):
    """Integrate n_steps RK4 steps of size dt (s) from (t0, y0) in free flight.

    No contact: the loose body passes through the plates, so use it with the
    joint locked or held by springs (docs/model.md §7 contact is in
    :mod:`workbench.core.hybrid`).  y0 is (q, q') (18,).  Stores the initial
    state and every ``decim``-th state into ``out_t`` (n_out,) and ``out_y``
    (n_out, 18), n_out >= n_steps // decim + 1.  Returns ``(status,
    n_stored)``; on failure the rows stored so far are valid and the failing
    state is not stored.
    """
    n_out = out_t.shape[0]
    if (out_y.shape[0] != n_out or n_out < n_steps // decim + 1
            or y0.shape[0] != ly.N_STATE or decim < 1):
        return ly.ERR_BAD_INPUT, 0
    rg[ly.RG_SET] = 0.0
    y_cur = stages[ly.STAGE_CUR]
    y_next = stages[ly.STAGE_NEXT]
    for i in range(ly.N_AUG):
        y_cur[i] = y0[i] if i < ly.N_STATE else 0.0
    for i in range(ly.N_STATE):
        out_y[0, i] = y0[i]
    out_t[0] = t0
    stored = 1
    for step in range(1, n_steps + 1):
        t = t0 + (step - 1) * dt
        status = rhs_regime(t, y_cur, P, tab, kc, free, ex, rec, mat, vec, cg, cw, rg,
                            stages[ly.STAGE_K1])
        if status == ly.OK:
            status = rk4_step(t, y_cur, dt, P, tab, kc, free, ex, rec, mat, vec, stages, cg, cw,
                              rg, y_next)
        if status != ly.OK:
            return status, stored
        for i in range(ly.N_AUG):
            y_cur[i] = y_next[i]
        if step % decim == 0:
            out_t[stored] = t0 + step * dt
            for i in range(ly.N_STATE):
                out_y[stored, i] = y_cur[i]
            stored += 1
    return ly.OK, stored
