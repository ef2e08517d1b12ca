"""An embedded explicit Runge-Kutta pair: its step, error estimate and dense output, jit-compiled.

The pair's coefficients are data in the parameter array P (layout
``P_RK_*``; :mod:`workbench.model.tableaus` writes them): Butcher's
(c, A, b) of the propagated solution, the error weights e_i = b_i - bhat_i
of the embedded one, and the dense output's weights as polynomials in
theta.  The pairs taken here are FSAL (first same as last): the last stage
is f(t + h, y_new), which is the next step's first stage (b of the last
stage is 0 and its row of A is b).  Hairer, Norsett & Wanner, Solving
Ordinary Differential Equations I, 2nd ed., §II.4-6.

    pair_step   y_new = y + h sum_i b_i k_i, projected onto the regime's
                constraints; the last stage f(t + h, y_new); the error
                estimate h sum_i e_i k_i (STAGE_ERR)
    dense       y(t + theta h) = y + h sum_i k_i sum_j d_ij theta^(j+1)

A new pair of this kind is a tableau (:class:`workbench.model.tableaus.Pair`),
not a kernel.  Arguments follow :mod:`workbench.core.constrained`.
"""
import math

import numba as nb
import numpy as np

from .config import JIT, JIT_INLINE
from . import layout as ly
from .constrained import project, rhs_regime
from .event_functions import event_values_after_rhs
from .integrate import stage_state


@nb.njit(**JIT_INLINE)
def _stage_events_min(yt, P, free, cg, rg, ev):
    """Lower ev[EV_MIN] to the event functions at a stage's state (its rhs_regime just ran)."""
    event_values_after_rhs(yt, P, free, cg, rg, ev, ly.EV_TRY, ly.EV_RATE_TRY)
    for e in range(ly.N_EV):
        ev[ly.EV_MIN, e] = min(ev[ly.EV_MIN, e], ev[ly.EV_TRY, e])


@nb.njit(**JIT_INLINE)
def project_step_end(y, P, free, cg, cw, rg, st):
    """Project a step's end y onto the regime's constraints; the projection's size into st."""
    correction, drift = project(y, P, free, cg, cw, rg, np.bool_(False))
    st[ly.ST_MAX_CORRECTION] = max(st[ly.ST_MAX_CORRECTION], correction)
    st[ly.ST_MAX_DRIFT] = max(st[ly.ST_MAX_DRIFT], drift)


@nb.njit(**JIT)
def pair_step(t, y, h, model, ex, work, st, y_new):
    """One step of h (s) of the pair in P from (t, y) into y_new (may not alias y).

    k1 = f(t, y) must be in stages[STAGE_K1]; k_i goes to stages[i - 1], the
    last (f(t + h, y_new), its contact forces in rg) to stages[s - 1].  y_new
    is projected onto the regime's constraints before the last stage (the
    projection's size goes to st).  The error estimate h sum e_i k_i of
    (q, q') goes to stages[STAGE_ERR] (the energy integrals are not
    controlled), and each event function's smallest value over the
    inner stages' states to ev[EV_MIN] (the sign checks inside the step;
    EV_TRY is overwritten).
    Returns a status.
    """
    P, free = model.P, model.free
    stages, cg, cw, rg, ev = work.stages, work.cg, work.cw, work.rg, work.ev
    n = ly.N_AUG
    s = int(P[ly.P_RK_STAGES])
    yt = stages[ly.STAGE_TMP]
    for e in range(ly.N_EV):
        ev[ly.EV_MIN, e] = ev[ly.EV_START, e]
    for i in range(n):
        stages[0, i] = stages[ly.STAGE_K1, i]
    for r in range(1, s - 1):
        status = rhs_regime(stage_state(r, t, y, h, P, stages, yt), yt, model, ex, work, stages[r])
        if status != ly.OK:
            return status
        _stage_events_min(yt, P, free, cg, rg, ev)
    for i in range(n):
        acc = 0.0
        for j in range(s - 1):
            acc += P[ly.P_RK_B + j] * stages[j, i]
        y_new[i] = y[i] + h * acc
        if not math.isfinite(y_new[i]):
            return ly.ERR_NAN
    project_step_end(y_new, P, free, cg, cw, rg, st)
    status = rhs_regime(t + h, y_new, model, ex, work, stages[s - 1])
    if status != ly.OK:
        return status
    err = stages[ly.STAGE_ERR]
    second = P[ly.P_RK_E3] != 0.0
    for i in range(ly.N_STATE):
        acc = 0.0
        acc3 = 0.0
        for j in range(s):
            acc += P[ly.P_RK_E + j] * stages[j, i]
            if second:
                acc3 += P[ly.P_RK_E3 + j] * stages[j, i]
        err[i] = h * acc
        if second:
            # DOP853's estimate: e5^2 / sqrt(e5^2 + 0.01 e3^2), here per component (HNW I, §II.10)
            d = math.sqrt(acc * acc + 0.01 * acc3 * acc3)
            if d > 0.0:
                err[i] *= abs(acc) / d
    return ly.OK


@nb.njit(**JIT)
def prepare_dense(t, y, h, model, ex, work):
    """The stages the dense output needs beyond the step's own (P[P_RK_EXTRA] of them).

    Called after :func:`pair_step` from (t, y) with h, before :func:`dense`.
    Returns a status.
    """
    P = model.P
    stages = work.stages
    s = int(P[ly.P_RK_STAGES])
    yt = stages[ly.STAGE_TMP]
    for r in range(s, s + int(P[ly.P_RK_EXTRA])):
        status = rhs_regime(stage_state(r, t, y, h, P, stages, yt), yt, model, ex, work, stages[r])
        if status != ly.OK:
            return status
    return ly.OK


@nb.njit(**JIT)
def dense(theta, h, y, P, stages, out):
    """The dense output at t + theta h (0 <= theta <= 1) of the step from y just taken, into out.

    The stages k_i must be those of that step (rows 0 .. s - 1).
    """
    s = int(P[ly.P_RK_STAGES]) + int(P[ly.P_RK_EXTRA])
    degree = int(P[ly.P_RK_DEGREE])
    for i in range(ly.N_AUG):
        out[i] = y[i]
    for j in range(s):
        w = 0.0
        power = theta
        base = ly.P_RK_D + ly.MAX_DENSE_DEGREE * j
        for d in range(degree):
            w += P[base + d] * power
            power *= theta
        if w != 0.0:
            w *= h
            k = stages[j]
            for i in range(ly.N_AUG):
                out[i] += w * k[i]
