"""The step method: one explicit Runge-Kutta step of the tableau in P, jit-compiled.

A step of size dt with s stages advances y by dt sum_i b_i k_i, where
k_i = f(t + c_i dt, y + dt sum_{j<i} a_ij k_j) (Butcher's tableau, read
from P at layout ``P_RK_*``; classical RK4 unless the method of the run
says otherwise, :mod:`workbench.model.tableaus`).  The state is the
augmented one (layout ``A_*``): (q, q') and the running integrals of the
energy account, so that the account has the integrator's accuracy.
:func:`rk_step` is the one step every integrator takes: the free-flight
integration here, and the event-driven integration of
:mod:`workbench.core.hybrid`, which re-integrates partial steps with it
(its interpolant for locating events) and which
:mod:`workbench.core.controlled` runs twice per interval for its error
estimate.  Arguments follow :mod:`workbench.core.constrained`; ``stages``
(N_STAGES, N_AUG) is scratch.
"""
import math

import numba as nb

from .config import JIT, JIT_INLINE
from . import layout as ly
from .constrained import rhs_regime


@nb.njit(**JIT_INLINE)
def stage_state(r, t, y, h, P, stages, yt):
    """Stage r's state y + h sum_{j<r} a_rj k_j (k_j in stages[j]) into yt; returns its time.

    Only (q, q') (N_STATE): no right-hand side reads the energy integrals,
    so yt's are left as they are.
    """
    row = ly.P_RK_A + ly.MAX_RK_STAGES * r
    for i in range(ly.N_STATE):
        yt[i] = 0.0
    for j in range(r):
        a = P[row + j]
        if a != 0.0:
            for i in range(ly.N_STATE):
                yt[i] += a * stages[j, i]
    for i in range(ly.N_STATE):
        yt[i] = y[i] + h * yt[i]
    return t + P[ly.P_RK_C + r] * h


@nb.njit(**JIT)
def rk_step(t, y, dt, model, ex, work, y_new):
    """One step of the tableau in P from (t, y) into y_new (may not alias y) in the regime of rg.

    k1 = f(t, y) must already be in stages[STAGE_K1] (the caller evaluated
    it, e.g. for the events at the step's start); k_i goes to stages[i - 1].
    Zero coefficients a_ij are skipped.  Returns a status.
    """
    P = model.P
    stages = work.stages
    n = ly.N_AUG
    s = int(P[ly.P_RK_STAGES])
    yt = stages[ly.STAGE_TMP]
    for i in range(n):
        stages[0, i] = stages[ly.STAGE_K1, i]
    for st in range(1, s):
        status = rhs_regime(stage_state(st, t, y, dt, P, stages, yt), yt, model, ex, work,
                            stages[st])
        if status != ly.OK:
            return status
    for i in range(n):
        acc = 0.0
        for j in range(s):
            acc += P[ly.P_RK_B + j] * stages[j, i]
        y_new[i] = y[i] + dt * acc
        if not math.isfinite(y_new[i]):
            return ly.ERR_NAN
    return ly.OK


@nb.njit(**JIT)
def integrate_fixed(y0, t0, dt, n_steps, decim, model, ex, work, out_t, out_y):
    """Integrate n_steps steps of size dt (s) from (t0, y0) in free flight.

    No contact: the loose body passes through the plates, so use it with the
    joint locked or held by springs (docs/model.md §7 contact is in
    :mod:`workbench.core.hybrid`).  y0 is (q, q') (18,).  Stores the initial
    state and every ``decim``-th state into ``out_t`` (n_out,) and ``out_y``
    (n_out, 18), n_out >= n_steps // decim + 1.  Returns ``(status,
    n_stored)``; on failure the rows stored so far are valid and the failing
    state is not stored.
    """
    stages, rg = work.stages, work.rg
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
        status = rhs_regime(t, y_cur, model, ex, work, stages[ly.STAGE_K1])
        if status == ly.OK:
            status = rk_step(t, y_cur, dt, model, ex, work, y_next)
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
