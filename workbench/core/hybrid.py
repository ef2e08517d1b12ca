"""Event-driven integration of the 17-regime model (docs/model.md §7), jit-compiled.

Fixed steps of the step method (:func:`workbench.core.integrate.rk_step`,
the tableau in P) in the current regime (:func:`run_hybrid`,
:func:`advance`); after each step the events of the regime are evaluated
(:mod:`workbench.core.event_functions`: each goes from + to - when its
event happens).  The location and the transitions here serve the
controlled steps of :mod:`workbench.core.adaptive` too.

A sign change is bracketed by re-integrating the partial step from the
step's start (one step of theta dt), or on the dense output of the step
just taken, and located by Brent's method to EVENT_TIME_TOL.  A gap that dips below zero and back within one step
(grazing) is caught by the cubic Hermite interpolant of the gap over the
step: near its minimum the true gap is evaluated by re-integration and its
minimum followed by the secant method on the gap's rate (:func:`_graze`).  Several events in a
step are taken in time order: the earliest is applied, and the rest of the
step is integrated again in the new regime.

Transitions (:mod:`workbench.core.transitions`): an impact is a momentum
transfer by Moreau's impact law over every closed or closing point; after
every event the new regime is chosen by the acceleration-level
enumeration.  Impacts that recur within ACCUM_TIME_S, or close slower
than the gap's free acceleration makes in ACCUM_TIME_S, are an
accumulation: the impact set then takes every point within ACCUM_GAP_TOL,
so the micro-collisions end in the persistent contact.  A watched gap
that is already closed is an impact only while it approaches faster than
CLOSED_RATE.  More than FLOOD_EVENTS events within FLOOD_WINDOW_S (or
MAX_EVENTS_PER_STEP in one step) hand the rest of the step and the steps
covering STEPPED_TIME_S to Moreau-Jean time-stepping
(:func:`workbench.core.transitions.moreau_jean_step`, in sub-steps of at
most P[P_STEPPED_DT]).  Each event is
written to the log (layout ``LOG_*``); failures (NaN, a mass matrix that
is not positive definite) end the run with a status code, keeping the
samples and the log written so far.
"""
import math

import numba as nb
import numpy as np

from .config import (ACCUM_GAP_TOL, ACCUM_TIME_S, CLOSED_RATE, EVENT_TIME_TOL, FLOOD_EVENTS,
                     FLOOD_WINDOW_S, GAP_TOL, GRAZE_BRACKET, GRAZE_ITERS, GRAZE_MARGIN, JIT,
                     JIT_INLINE, MAX_EVENTS_PER_STEP, STEP_REMAINDER_REL, STEPPED_TIME_S)
from . import layout as ly
from .constrained import project, rhs_regime
from .contact import fill_geometry, in_set, regime_of, row_convective, row_rate
from .dynamics import rhs
from .integrate import rk_step
from .event_functions import event_values
from .pair import dense
from .sensors import fill_signals
from .transitions import book_losses, choose_regime, impact, moreau_jean_step


@nb.njit(**JIT_INLINE)
def _copy(stages, src, dst):
    for i in range(ly.N_AUG):
        stages[dst, i] = stages[src, i]


@nb.njit(**JIT_INLINE)
def _copy_ev(ev, src, dst):
    for i in range(ly.N_EV):
        ev[dst, i] = ev[src, i]


@nb.njit(**JIT_INLINE)
def _trial(theta, t, h, on_dense, model, ex, work):
    """State after theta * h from the step's start into STAGE_TRY, its events into EV_TRY.

    ``on_dense``: the state is the dense output of the step just taken (its
    stages intact, :func:`workbench.core.pair.dense`); else a step of theta h
    is integrated from the step's start.
    """
    P, free = model.P, model.free
    stages, cg, rg, ev = work.stages, work.cg, work.rg, work.ev
    y = stages[ly.STAGE_CUR]
    y_try = stages[ly.STAGE_TRY]
    status = ly.OK
    if on_dense:
        dense(theta, h, y, P, stages, y_try)
    else:
        status = rk_step(t, y, theta * h, model, ex, work, y_try)
    if status == ly.OK:
        status = rhs_regime(t + theta * h, y_try, model, ex, work, stages[ly.STAGE_KTRY])
    if status == ly.OK:
        event_values(y_try, P, free, cg, rg, ev, ly.EV_TRY, ly.EV_RATE_TRY)
    return status


@nb.njit(**JIT_INLINE)
def _hermite_min(f0, f1, m0, m1):
    """Minimum over theta in [0, 1] of the cubic Hermite interpolant; returns (theta, value).

    f0, f1 values and m0, m1 slopes (per unit theta) at the ends.
    """
    # p(x) = f0 h00 + m0 h10 + f1 h01 + m1 h11; p'(x) = a x^2 + b x + c
    a = 6.0 * f0 + 3.0 * m0 - 6.0 * f1 + 3.0 * m1
    b = -6.0 * f0 - 4.0 * m0 + 6.0 * f1 - 2.0 * m1
    c = m0
    best_x = 0.0
    best_v = f0
    if f1 < best_v:
        best_x = 1.0
        best_v = f1
    roots = (-1.0, -1.0)
    if abs(a) > 1e-300:
        disc = b * b - 4.0 * a * c
        if disc >= 0.0:
            sq = disc ** 0.5
            roots = ((-b - sq) / (2.0 * a), (-b + sq) / (2.0 * a))
    elif abs(b) > 1e-300:
        roots = (-c / b, -1.0)
    for x in roots:
        if 0.0 < x < 1.0:
            x2 = x * x
            x3 = x2 * x
            v = (f0 * (2.0 * x3 - 3.0 * x2 + 1.0) + m0 * (x3 - 2.0 * x2 + x)
                 + f1 * (-2.0 * x3 + 3.0 * x2) + m1 * (x3 - x2))
            if v < best_v:
                best_x = x
                best_v = v
    return best_x, best_v


@nb.njit(**JIT)
def _graze(e, t, h, f0, f1, m0, m1, before, model, ex, work):
    """Does gap event e dip below zero inside the step though it is positive at both ends?

    The gap turns within the step (slopes m0 < 0 < m1 per unit theta).  The
    cubic Hermite interpolant of the ends places its minimum, but misplaces
    it by up to ~(omega h)^4 / 384 of the motion when a fast (axial, kHz)
    oscillation rides on the gap.  So the true gap is evaluated (a step from
    the step's start) wherever the interpolant comes within GRAZE_MARGIN of
    the slopes of zero, and its minimum is followed by the secant method on
    its rate for up to GRAZE_ITERS trials.  Returns ``(status, theta)``:
    theta of a state below zero (in STAGE_HI, its events in EV_HI) before
    ``before``, or -1.
    """
    stages, ev = work.stages, work.ev
    x, v = _hermite_min(f0, f1, m0, m1)
    margin = GRAZE_MARGIN * (m1 - m0)
    if not v < margin:
        return ly.OK, -1.0
    lo_x, lo_r, hi_x, hi_r = 0.0, m0, 1.0, m1
    for _ in range(GRAZE_ITERS):
        if not (0.0 < x < before):
            return ly.OK, -1.0
        status = _trial(x, t, h, np.bool_(False), model, ex, work)
        if status != ly.OK:
            return status, -1.0
        f = ev[ly.EV_TRY, e]
        if f < 0.0:
            _copy(stages, ly.STAGE_TRY, ly.STAGE_HI)
            _copy_ev(ev, ly.EV_TRY, ly.EV_HI)
            return ly.OK, x
        if f >= margin:
            return ly.OK, -1.0
        r = h * ev[ly.EV_RATE_TRY, e]
        if r < 0.0:
            lo_x, lo_r = x, r
        else:
            hi_x, hi_r = x, r
        if hi_r - lo_r <= 0.0 or hi_x - lo_x <= GRAZE_BRACKET:
            return ly.OK, -1.0
        x = lo_x - lo_r * (hi_x - lo_x) / (hi_r - lo_r)
    return ly.OK, -1.0


@nb.njit(**JIT)
def _bracket(e, flo, hi, fhi, t, h, on_dense, model, ex, work):
    """Locate event e's sign change in (0, hi) by Brent's method, to EVENT_TIME_TOL.

    Brent's zeroin (R. P. Brent, Algorithms for Minimization without
    Derivatives, 1973, ch. 4): inverse quadratic interpolation through the
    last three trials, or the secant through two, falling back to bisection
    when they do not shrink the bracket fast enough.  Every step is at
    least half the tolerance, so the bracket closes once the interpolation
    has converged.  ``b`` is the latest trial and ``c`` the latest one on
    the other side of the change, so the latest state past it (f < 0) is
    always an end of the bracket.

    ``flo`` >= 0 is its value at the step's start, ``fhi`` < 0 at ``hi``,
    whose state is in STAGE_HI.  Trial states as :func:`_trial` (``on_dense``).  Returns ``(status, theta)``: the state just
    past the change (theta) is left in STAGE_HI, the events there in EV_HI.
    """
    stages, ev = work.stages, work.ev
    half_tol = 0.5 * EVENT_TIME_TOL / h
    a, fa = 0.0, flo
    b, fb = hi, fhi
    c, fc = a, fa
    d = b - a
    last = d
    for _ in range(200):
        if abs(fc) < abs(fb):
            a, fa = b, fb
            b, fb = c, fc
            c, fc = a, fa
        xm = 0.5 * (c - b)
        if abs(xm) <= half_tol:
            break
        if abs(last) >= half_tol and abs(fa) > abs(fb):
            s = fb / fa
            if a == c:
                p = 2.0 * xm * s
                q = 1.0 - s
            else:
                q = fa / fc
                r = fb / fc
                p = s * (2.0 * xm * q * (q - r) - (b - a) * (r - 1.0))
                q = (q - 1.0) * (r - 1.0) * (s - 1.0)
            if p > 0.0:
                q = -q
            else:
                p = -p
            if 2.0 * p < min(3.0 * xm * q - abs(half_tol * q), abs(last * q)):
                last = d
                d = p / q
            else:
                d = xm
                last = d
        else:
            d = xm
            last = d
        a, fa = b, fb
        if abs(d) > half_tol:
            b += d
        else:
            b += half_tol if xm > 0.0 else -half_tol
        status = _trial(b, t, h, on_dense, model, ex, work)
        if status != ly.OK:
            return status, hi
        fb = ev[ly.EV_TRY, e]
        if fb < 0.0:
            _copy(stages, ly.STAGE_TRY, ly.STAGE_HI)
            _copy_ev(ev, ly.EV_TRY, ly.EV_HI)
        if (fb < 0.0) == (fc < 0.0):
            c, fc = a, fa
            d = b - a
            last = d
    return ly.OK, (b if fb < 0.0 else c)


#: Where the dense output of a step is checked for an event whose function is
#: positive at both ends of the step (fractions of the step).
SCAN_POINTS = (0.2, 0.4, 0.5, 0.6, 0.8)


@nb.njit(**JIT)
def _scan(e, t, h, before, model, ex, work):
    """Is event e negative somewhere inside the step though positive at both ends? (dense output)

    Called when a sign check flagged it: e's smallest value over the step's
    stages is negative (ev[EV_MIN]), or e is a gap that turns within the
    step.  The dense output is evaluated at the SCAN_POINTS before ``before``
    and, for a turning gap, where its cubic Hermite interpolant of the ends
    is smallest.  Returns ``(status, theta)``: the first theta whose state
    is past the change by more than the function's error (ev[EV_NOISE]; in
    STAGE_HI, its events in EV_HI), or -1.
    """
    P = model.P
    stages, cg, rg, ev = work.stages, work.cg, work.rg, work.ev
    xs = SCAN_POINTS
    x_min = -1.0
    if e < ly.EV_GAP + ly.N_POINTS:
        m0 = h * ev[ly.EV_RATE_START, e]
        m1 = h * ev[ly.EV_RATE_END, e]
        if m0 < 0.0 and m1 > 0.0:
            x_min, _ = _hermite_min(ev[ly.EV_START, e], ev[ly.EV_END, e], m0, m1)
    is_gap = e < ly.EV_GAP + ly.N_POINTS
    for k in range(len(xs) + 1):
        x = x_min if k == 0 else xs[k - 1]
        if not (0.0 < x < before):
            continue
        if is_gap:
            # a gap is a function of q alone: the geometry of the dense state first
            dense(x, h, stages[ly.STAGE_CUR], P, stages, stages[ly.STAGE_TRY])
            fill_geometry(stages[ly.STAGE_TRY], P, cg)
            p = e - ly.EV_GAP
            if not cg[ly.CG_G + p, ly.CG_VAL] + rg[ly.RG_ARM + p] < -ev[ly.EV_NOISE, e]:
                continue
        status = _trial(x, t, h, np.bool_(True), model, ex, work)
        if status != ly.OK:
            return status, -1.0
        if ev[ly.EV_TRY, e] < -ev[ly.EV_NOISE, e]:
            _copy(stages, ly.STAGE_TRY, ly.STAGE_HI)
            _copy_ev(ev, ly.EV_TRY, ly.EV_HI)
            return ly.OK, x
    return ly.OK, -1.0


@nb.njit(**JIT_INLINE)
def passed_before(e, ev):
    """An event other than e positive at the step's start and negative at the state in EV_HI
    (-1 if none)."""
    for k in range(ly.N_EV):
        if k != e and ev[ly.EV_START, k] >= 0.0 and ev[ly.EV_HI, k] < 0.0:
            return k
    return -1


@nb.njit(**JIT)
def locate(t, h, on_dense, model, ex, work):
    """The earliest event in the step (t, t + h) from STAGE_CUR to STAGE_NEXT.

    ``on_dense``: trial states are the dense output of the step just taken,
    and an event positive at both ends is looked for by :func:`_scan`;
    else they are integrated from the step's start, and a grazing gap is
    looked for by :func:`_graze`.  Returns ``(status, event, theta)``:
    event -1 if none; else the state just past the event (within
    EVENT_TIME_TOL) is in STAGE_HI at t + theta h.
    """
    stages, ev = work.stages, work.ev
    best = -1
    best_theta = 2.0
    for e in range(ly.N_EV):
        f0 = ev[ly.EV_START, e]
        f1 = ev[ly.EV_END, e]
        if f0 < 0.0:
            continue
        hi = -1.0
        fhi = 0.0
        if f1 < 0.0:
            hi = 1.0
            fhi = f1
        elif on_dense:
            turning = (e < ly.EV_GAP + ly.N_POINTS and ev[ly.EV_RATE_START, e] < 0.0
                       and ev[ly.EV_RATE_END, e] > 0.0 and f0 < 1.0)
            if turning or ev[ly.EV_MIN, e] < -ev[ly.EV_NOISE, e]:
                status, x = _scan(e, t, h, best_theta, model, ex, work)
                if status != ly.OK:
                    return status, -1, 0.0
                if x >= 0.0:
                    hi = x
                    fhi = ev[ly.EV_HI, e]
        elif e < ly.EV_GAP + ly.N_POINTS and f0 < 1.0:
            # grazing: the gap's cubic Hermite interpolant over the step
            m0 = h * ev[ly.EV_RATE_START, e]
            m1 = h * ev[ly.EV_RATE_END, e]
            if m0 < 0.0 and m1 > 0.0:
                status, x = _graze(e, t, h, f0, f1, m0, m1, best_theta, model, ex, work)
                if status != ly.OK:
                    return status, -1, 0.0
                if x >= 0.0:
                    hi = x
                    fhi = ev[ly.EV_HI, e]
        if hi < 0.0:
            continue
        if best >= 0 and hi >= best_theta:
            # an earlier event is already known: does e change sign before it?
            if ev[ly.EV_HI, e] >= 0.0:
                continue
            hi = best_theta
            fhi = ev[ly.EV_HI, e]
        elif hi == 1.0:
            _copy(stages, ly.STAGE_NEXT, ly.STAGE_HI)
            _copy_ev(ev, ly.EV_END, ly.EV_HI)
        status, hi = _bracket(e, f0, hi, fhi, t, h, on_dense, model, ex, work)
        if status != ly.OK:
            return status, -1, 0.0
        best = e
        best_theta = hi
    # An event positive at both ends of the step may still be negative at the
    # earliest bracket found (a gap hovering at zero after a plastic impact,
    # turning more than once in the step): it happened earlier still.
    for _ in range(ly.N_EV):
        if best < 0:
            break
        earlier = passed_before(best, ev)
        if earlier < 0:
            break
        status, hi = _bracket(earlier, ev[ly.EV_START, earlier], best_theta, ev[ly.EV_HI, earlier],
                              t, h, on_dense, model, ex, work)
        if status != ly.OK:
            return status, -1, 0.0
        best = earlier
        best_theta = hi
    return ly.OK, best, best_theta


@nb.njit(**JIT_INLINE)
def penetration(st, rg, ev, row, t, where):
    """Keep the largest penetration depth (cm) of the open points' gaps in ev[row], its time
    and where it was found (``where`` + the point: 10 at an event, 20 at a step's end)."""
    for p in range(ly.N_POINTS):
        if not in_set(int(rg[ly.RG_SET]), p):
            depth = rg[ly.RG_ARM + p] - ev[row, ly.EV_GAP + p]
            if depth > st[ly.ST_MAX_PEN]:
                st[ly.ST_MAX_PEN] = depth
                st[ly.ST_T_MAX_PEN] = t
                st[ly.ST_PEN_WHERE] = where + p


@nb.njit(**JIT_INLINE)
def step_end(t, y, rg, ev, st):
    """A step's end at t (s): the open gaps' penetration, the slide's range, the time reached."""
    penetration(st, rg, ev, ly.EV_START, t, 20)
    st[ly.ST_S_MIN] = min(st[ly.ST_S_MIN], y[ly.S])
    st[ly.ST_S_MAX] = max(st[ly.ST_S_MAX], y[ly.S])
    st[ly.ST_T] = t


@nb.njit(**JIT_INLINE)
def _log(log, n_log, t, kind, reg_from, reg_to, point):
    """Start a log row (impulses and energy zero); returns the row index."""
    r = log[n_log]
    for j in range(ly.N_LOG):
        r[j] = 0.0
    r[ly.LOG_T] = t
    r[ly.LOG_KIND] = kind
    r[ly.LOG_FROM] = reg_from
    r[ly.LOG_TO] = reg_to
    r[ly.LOG_POINT] = point
    return n_log


@nb.njit(**JIT)
def _accumulating(t, y, point, P, cg, st, k1):
    """Whether an impact of ``point`` at t belongs to an accumulation (docs/model.md §7).

    Impacts recurring within ACCUM_TIME_S, or a closing rate below what the
    free gap acceleration makes in ACCUM_TIME_S.
    """
    if t - st[ly.ST_T_IMPACT] < ACCUM_TIME_S:
        return True
    fill_geometry(y, P, cg)
    qd = y[ly.N_DOF:ly.N_STATE]
    rate = row_rate(cg, ly.CG_G + point, qd)
    acc = row_rate(cg, ly.CG_G + point, k1[ly.N_DOF:ly.N_STATE]) + row_convective(
        cg, ly.CG_G + point, qd)
    return abs(rate) < ACCUM_TIME_S * abs(acc)


@nb.njit(**JIT)
def event_transition(e, t, model, ex, work, log, n_log, st):
    """The transition of event e at the state in STAGE_CUR (time t), before the new regime
    is chosen: the state projected onto the old regime, then the impact law (an impact,
    its log row n_log written) or the new contact set or stick flag in rg.

    Returns ``(status, kind, point, reg_from, gap_tol)``: the log's kind and point, the
    regime before, the gap tolerance the choice of the new regime takes.
    """
    P, tab, kc, free = model.P, model.tab, model.kc, model.free
    rec, mat, vec, stages = work.rec, work.mat, work.vec, work.stages
    cg, cw, rg = work.cg, work.cw, work.rg
    y = stages[ly.STAGE_CUR]
    k1 = stages[ly.STAGE_K1]
    set_index = int(rg[ly.RG_SET])
    reg_from = regime_of(set_index, rg[ly.RG_STICK] != 0.0)
    # The bracketed state is not projected: pull it onto the old regime first,
    # so that e.g. a sticking slip velocity is exactly 0 when slip begins.
    project(y, P, free, cg, cw, rg, np.bool_(False))
    status = rhs_regime(t, y, model, ex, work, k1)
    point = 0
    kind = ly.KIND_START
    gap_tol = GAP_TOL
    lost = 0.0
    if status != ly.OK:
        return status, kind, point, reg_from, gap_tol
    if e < ly.EV_GAP + ly.N_POINTS:
        p = e - ly.EV_GAP
        accumulating = _accumulating(t, y, p, P, cg, st, k1)
        close_within = 0.0
        if accumulating:
            gap_tol = ACCUM_GAP_TOL
            close_within = ACCUM_TIME_S
        free_acc = stages[ly.STAGE_TRY]
        status = rhs(t, y, P, tab, kc, free, ex, rec, mat, vec, free_acc)
        if status != ly.OK:
            return status, kind, point, reg_from, gap_tol
        status, n_pts, lost = impact(y, p, P, free, mat, cg, cw, rg, gap_tol,
                                     free_acc[ly.N_DOF:ly.N_STATE], close_within, np.float64(0.0))
        if status != ly.OK:
            return status, kind, point, reg_from, gap_tol
        row = log[_log(log, n_log, t, ly.KIND_IMPACT, reg_from, 0, p + 1)]
        for i in range(n_pts):
            q = int(cw[ly.CW_PTS, i])
            row[ly.LOG_P + q] = cw[ly.CW_P, 2 * i]
            row[ly.LOG_PT] += cw[ly.CW_P, 2 * i + 1]
            row[ly.LOG_DKE_P + q] = cw[ly.CW_LOSS, i]
        row[ly.LOG_DKE] = lost
        book_losses(st, cw, n_pts, lost)
        st[ly.ST_N_IMPACTS] += 1.0
        st[ly.ST_T_IMPACT] = t
        if accumulating:
            st[ly.ST_N_ACCUM] += 1.0
            st[ly.ST_E_ACCUM] += lost
        kind = ly.KIND_IMPACT
        point = p + 1
    elif e < ly.EV_LAMBDA + ly.N_POINTS:
        p = e - ly.EV_LAMBDA
        keep = ly.SET_FIRST[set_index] if ly.SET_FIRST[set_index] != p else ly.SET_SECOND[set_index]
        rg[ly.RG_SET] = 0.0 if keep < 0 else float(keep + 1)   # set {keep + 1}
        kind = ly.KIND_SEPARATION
        point = p + 1
    elif e == ly.EV_STICK:
        rg[ly.RG_STICK] = 0.0
        rg[ly.RG_SIGN] = -1.0 if rg[ly.RG_LT] > 0.0 else 1.0
        kind = ly.KIND_STICK_SLIP
        point = ly.SET_FIRST[set_index] + 1
    else:
        # the slip rate is zero at the event: the state just past it (its time located
        # to EVENT_TIME_TOL, where the rate may change by ~1e-5 cm/s) is put at rest
        rg[ly.RG_STICK] = 1.0
        project(y, P, free, cg, cw, rg, np.bool_(False))
        kind = ly.KIND_SLIP_STICK
        point = ly.SET_FIRST[set_index] + 1
    return ly.OK, kind, point, reg_from, gap_tol


@nb.njit(**JIT)
def apply_event(e, t, model, ex, work, log, n_log, st):
    """Apply event e at the state in STAGE_CUR (time t); leave k1 and the events there.

    Returns a status; the log row n_log is written.
    """
    P, free = model.P, model.free
    stages, cg, rg, ev = work.stages, work.cg, work.rg, work.ev
    y = stages[ly.STAGE_CUR]
    status, kind, point, reg_from, gap_tol = event_transition(e, t, model, ex, work, log,
                                                              n_log, st)
    if status != ly.OK:
        return status
    status = choose_regime(t, y, model, ex, work, stages[ly.STAGE_K1], st, gap_tol)
    if status != ly.OK:
        return status
    reg_to = regime_of(int(rg[ly.RG_SET]), rg[ly.RG_STICK] != 0.0)
    if kind == ly.KIND_IMPACT:
        log[n_log, ly.LOG_TO] = reg_to
    else:
        _log(log, n_log, t, kind, reg_from, reg_to, point)
    event_values(y, P, free, cg, rg, ev, ly.EV_START, ly.EV_RATE_START)
    st[ly.ST_N_EVENTS] += 1.0
    return ly.OK


@nb.njit(**JIT_INLINE)
def flooding(st, t):
    """Count an event at t; True when it is more than FLOOD_EVENTS within FLOOD_WINDOW_S."""
    if t - st[ly.ST_FLOOD_T0] > FLOOD_WINDOW_S:
        st[ly.ST_FLOOD_T0] = t
        st[ly.ST_FLOOD_N] = 0.0
    st[ly.ST_FLOOD_N] += 1.0
    return st[ly.ST_FLOOD_N] > FLOOD_EVENTS


@nb.njit(**JIT_INLINE)
def _immediate_impact(ev):
    """A watched gap already closed and closing faster than CLOSED_RATE (-1 if none)."""
    for p in range(ly.N_POINTS):
        if (ev[ly.EV_START, ly.EV_GAP + p] < 0.0
                and ev[ly.EV_RATE_START, ly.EV_GAP + p] < -CLOSED_RATE):
            return ly.EV_GAP + p
    return -1


@nb.njit(**JIT_INLINE)
def _stepped(t, h, model, ex, work, st):
    """Moreau-Jean steps over h from (t, STAGE_CUR), then the regime chosen at t + h.

    The scheme is explicit in the smooth forces (leapfrog-like, stable for
    omega h < 2): h is split into the fewest equal steps of at most
    P[P_STEPPED_DT], which the model's fastest linear mode sets
    (:func:`workbench.model.step_policy.stepped_dt`); the integration step
    itself may exceed it (classical RK4 is stable to omega h = 2.83).
    """
    P, free = model.P, model.free
    stages, cg, rg, ev = work.stages, work.cg, work.rg, work.ev
    n = 1
    if h > P[ly.P_STEPPED_DT]:
        n = int(math.ceil(h / P[ly.P_STEPPED_DT]))
    for k in range(n):
        status = moreau_jean_step(t + k * (h / n), h / n, model, ex, work, st)
        if status != ly.OK:
            return status
    status = choose_regime(t + h, stages[ly.STAGE_CUR], model, ex, work, stages[ly.STAGE_K1], st,
                           GAP_TOL)
    if status == ly.OK:
        event_values(stages[ly.STAGE_CUR], P, free, cg, rg, ev, ly.EV_START, ly.EV_RATE_START)
    return status


@nb.njit(**JIT)
def store(stored, t, y, model, ex, work, st, out_t, out_y, out_sig):
    """Sample ``stored``: the state y at t in the regime of rg, and its signals (rg's
    forces and STAGE_KTRY are overwritten)."""
    P, tab, kc = model.P, model.tab, model.kc
    rec, mat, vec, stages, cg, rg = work.rec, work.mat, work.vec, work.stages, work.cg, work.rg
    k = stages[ly.STAGE_KTRY]
    if stored % 10 == 0:
        status = rhs_regime(t, y, model, ex, work, k)
        if status != ly.OK:
            return status
    out_t[stored] = t
    for i in range(ly.N_STATE):
        out_y[stored, i] = y[i]
    fill_signals(y, k, P, tab, kc, rec, mat, vec, cg, rg, st, out_sig[stored])
    return ly.OK


@nb.njit(**JIT)
def begin(t, step0, model, ex, work, out_t, out_y, out_sig, log, st):
    """Start (or continue) a run at t from STAGE_CUR: the regime chosen, its events.

    On a run's first call (step0 == 0) the start is logged and stored too.
    Returns ``(status, n_stored, n_log)``.
    """
    P, free = model.P, model.free
    stages, cg, rg, ev = work.stages, work.cg, work.rg, work.ev
    y = stages[ly.STAGE_CUR]
    n_log = 0
    stored = np.int64(0)
    reg_start = regime_of(int(rg[ly.RG_SET]), rg[ly.RG_STICK] != 0.0)
    if step0 == 0:
        st[ly.ST_T_IMPACT] = -1e300
        st[ly.ST_FLOOD_T0] = -1e300
        st[ly.ST_S_MIN] = y[ly.S]
        st[ly.ST_S_MAX] = y[ly.S]
    status = choose_regime(t, y, model, ex, work, stages[ly.STAGE_K1], st, GAP_TOL)
    if status != ly.OK:
        return status, stored, n_log
    event_values(y, P, free, cg, rg, ev, ly.EV_START, ly.EV_RATE_START)
    if step0 == 0:
        _log(log, n_log, t, ly.KIND_START, reg_start,
             regime_of(int(rg[ly.RG_SET]), rg[ly.RG_STICK] != 0.0), 0)
        n_log += 1
        status = store(stored, t, y, model, ex, work, st, out_t, out_y, out_sig)
        if status != ly.OK:
            return status, stored, n_log
        stored += 1
    return ly.OK, stored, n_log


@nb.njit(**JIT)
def advance(t, t_end, dt, stepped_left, model, ex, work, log, n_log, st):
    """One step of the lattice, from (t, STAGE_CUR) to t_end, with its events.

    ``dt`` (s) is the lattice step; ``stepped_left`` the Moreau-Jean steps
    still to take after an event flood (those covering STEPPED_TIME_S).  The event log must have room for MAX_EVENTS_PER_STEP + 2 rows
    from n_log.  Returns ``(status, t, n_log, stepped_left)``; on success
    t == t_end and STAGE_CUR, STAGE_K1 and the events' start rows are at t.
    """
    P, free = model.P, model.free
    stages, cg, cw, rg, ev = work.stages, work.cg, work.cw, work.rg, work.ev
    y = stages[ly.STAGE_CUR]
    n_step_events = 0
    if stepped_left > 0:
        status = _stepped(t, t_end - t, model, ex, work, st)
        if status != ly.OK:
            st[ly.ST_T] = t
            return status, t, n_log, stepped_left
        stepped_left -= 1
        t = t_end
    while stepped_left == 0:
        h = t_end - t
        if h <= STEP_REMAINDER_REL * dt:
            break
        e = _immediate_impact(ev)
        if e < 0:
            status = rk_step(t, y, h, model, ex, work, stages[ly.STAGE_NEXT])
            if status == ly.OK:
                correction, drift = project(stages[ly.STAGE_NEXT], P, free, cg, cw, rg, np.bool_(False))
                st[ly.ST_MAX_CORRECTION] = max(st[ly.ST_MAX_CORRECTION], correction)
                st[ly.ST_MAX_DRIFT] = max(st[ly.ST_MAX_DRIFT], drift)
                status = rhs_regime(t_end, stages[ly.STAGE_NEXT], model, ex, work,
                                    stages[ly.STAGE_KNEXT])
            if status != ly.OK:
                return status, t, n_log, stepped_left
            event_values(stages[ly.STAGE_NEXT], P, free, cg, rg, ev, ly.EV_END, ly.EV_RATE_END)
            status, e, theta = locate(t, h, np.bool_(False), model, ex, work)
            if status != ly.OK:
                return status, t, n_log, stepped_left
            if e < 0:
                _copy(stages, ly.STAGE_NEXT, ly.STAGE_CUR)
                _copy(stages, ly.STAGE_KNEXT, ly.STAGE_K1)
                _copy_ev(ev, ly.EV_END, ly.EV_START)
                for p in range(ly.N_POINTS):
                    ev[ly.EV_RATE_START, ly.EV_GAP + p] = ev[ly.EV_RATE_END, ly.EV_GAP + p]
                t = t_end
                break
            _copy(stages, ly.STAGE_HI, ly.STAGE_CUR)
            t = t_end if theta >= 1.0 else t + theta * h
            penetration(st, rg, ev, ly.EV_HI, t, 10)    # when the event is found
        while e >= 0:
            n_step_events += 1
            if flooding(st, t) or n_step_events > MAX_EVENTS_PER_STEP:
                # an episode the event-driven logic cannot resolve: Moreau-Jean
                # time-stepping through the rest of this step and STEPPED_TIME_S more
                status = ly.OK
                if t_end - t > STEP_REMAINDER_REL * dt:
                    status = _stepped(t, t_end - t, model, ex, work, st)
                if status != ly.OK:
                    st[ly.ST_T] = t
                    return status, t, n_log, stepped_left
                t = t_end
                stepped_left = int(math.ceil(STEPPED_TIME_S / dt - 1e-9))
                break
            status = apply_event(e, t, model, ex, work, log, n_log, st)
            if status != ly.OK:
                st[ly.ST_T] = t
                return status, t, n_log, stepped_left
            n_log += 1
            e = _immediate_impact(ev)
    step_end(t, y, rg, ev, st)
    return ly.OK, t, n_log, stepped_left


@nb.njit(**JIT)
def run_hybrid(y0, t0, span, model, ex, work, out, log, st):
    """Integrate n_steps fixed steps of dt (s) from (t0, y0) with contact events.

    ``span`` is (dt, n_steps, step0, decim).  The arrays come in named groups:
    ``model`` (P, tab, kc, free) and
    ``work`` (rec, mat, vec, stages, cg, cw, rg, ev), as
    :mod:`workbench.model.packing` builds them; ``out`` (out_t, out_y,
    out_sig), the samples.
    y0 (N_AUG,) is the augmented state; rg holds the starting regime and,
    on return, the final one; STAGE_CUR holds the final state.  ``step0``
    counts the steps done by earlier calls (a run in chunks): a sample is
    stored after every step whose global number is a multiple of ``decim``,
    and the state at t0 only when step0 == 0.  The event log ``log``
    (capacity, N_LOG) must hold MAX_EVENTS_PER_STEP + 2 rows; when fewer
    remain the call returns LOG_FULL after a whole step, and the caller
    continues from STAGE_CUR with st[ST_STEP] steps done.  st accumulates
    the run statistics (layout ST_*).

    Returns ``(status, n_stored, n_log)``.
    """
    dt, n_steps, step0, decim = span
    P, tab, kc, free = model
    rec, mat, vec, stages, cg, cw, rg, ev = work
    out_t, out_y, out_sig = out
    n_out = out_t.shape[0]
    need = (step0 + n_steps) // decim - step0 // decim + (1 if step0 == 0 else 0)
    if (y0.shape[0] != ly.N_AUG or decim < 1 or n_out < need or out_y.shape[0] < need
            or out_sig.shape[0] < need or log.shape[0] < MAX_EVENTS_PER_STEP + 2):
        return ly.ERR_BAD_INPUT, 0, 0
    for i in range(ly.N_AUG):
        stages[ly.STAGE_CUR, i] = y0[i]
    status, stored, n_log = begin(t0, step0, model, ex, work, out_t, out_y, out_sig, log, st)
    if status != ly.OK:
        return status, stored, n_log
    t = t0
    stepped_left = np.int64(0)
    for step in range(1, n_steps + 1):
        if n_log + MAX_EVENTS_PER_STEP + 2 > log.shape[0]:
            return ly.LOG_FULL, stored, n_log
        status, t, n_log, stepped_left = advance(t, t0 + step * dt, dt, stepped_left, model, ex,
                                                 work, log, n_log, st)
        if status != ly.OK:
            return status, stored, n_log
        st[ly.ST_STEP] = step0 + step
        if (step0 + step) % decim == 0:
            status = store(stored, t, stages[ly.STAGE_CUR], model, ex, work, st, out_t, out_y,
                           out_sig)
            if status != ly.OK:
                return status, stored, n_log
            stored += 1
    return ly.OK, stored, n_log
