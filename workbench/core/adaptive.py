"""Error-controlled event-driven integration with an embedded pair, jit-compiled.

One step at a time (Hairer, Norsett & Wanner I, §II.4): each step of the
pair (:mod:`workbench.core.pair`) carries its own error estimate, and the
step is accepted when, over ``tol`` times its scale
(:mod:`workbench.core.error_scales`),

* every component of (q, q') of the estimate, and
* every event function of the regime (gaps, normal forces, stick margin,
  slip rate), as the difference between its value at the propagated and
  at the embedded solution,

is at most 1.  The next step follows from a PI controller on the estimate
(Hairer, Norsett & Wanner I, §IV.2, as in DOPRI5: exponents 0.7/p and
0.4/p); steps are at most the base step ``dt`` and at least
dt / 2^level_max, where a step is accepted whatever its estimate and
written to ``floor_log``.

Events are looked for in each accepted step (:func:`workbench.core.hybrid.locate`
on the dense output): a sign change between the step's ends, or an event
function negative at one of the step's stages or, for a gap turning within
the step, at its Hermite minimum, is checked on the dense output and
located there by Brent's method to EVENT_TIME_TOL; then one step of the
pair from the step's start to the event, moved on by short steps
(SHORT_STEP_S) to within EVENT_TIME_TOL of it, gives the state there, the event
is applied (:func:`workbench.core.hybrid.apply_event`) and the next step
starts from it with the step size kept.  When the pair's steps do not cross
the event by the step's end, the step is rejected and tried shorter.
Samples are the dense output at the output times.  An event flood
(FLOOD_EVENTS within FLOOD_WINDOW_S) hands STEPPED_TIME_S to Moreau-Jean
time-stepping.  Every decision depends on the state only, so a run is
deterministic.
"""
import math

import numba as nb
import numpy as np

from .config import (EVENT_TIME_SCALE_S, EVENT_TIME_TOL, JIT, JIT_INLINE, MAX_EVENTS_PER_STEP,
                     SHORT_STEP_S, STEP_REMAINDER_REL, STEPPED_TIME_S)
from . import layout as ly
from .constrained import rhs_regime
from .contact import regime_of
from .error_scales import event_scale, floors, grow_scales, state_scale, total_normal_force
from .event_functions import event_values_after_rhs
from .hybrid import (_bracket, _copy, _copy_ev, _immediate_impact, _stepped, _trial,
                     apply_event, begin, flooding, locate, passed_before, penetration, step_end,
                     store)
from .pair import dense, pair_step, prepare_dense, project_step_end

#: The PI controller (Hairer, Norsett & Wanner I, §IV.2; DOPRI5's defaults):
#: h_new = h SAFETY err^-(1/p - 0.75 BETA) err_prev^BETA, by a factor in
#: [FAC_MIN, FAC_MAX], and not above h right after a rejection; after a
#: rejection h SAFETY err^-1/p, at least FAC_MIN.
SAFETY = 0.9
BETA = 0.04
FAC_MIN = 0.2
FAC_MAX = 10.0
#: The PI controller's memory before the first step (Hairer's facold).
ERR_PREV_START = 1e-4
#: Rows of the event log the driver keeps free before a step; below this it
#: ends the call at the next base step (LOG_FULL).
LOG_RESERVE = 4 * (MAX_EVENTS_PER_STEP + 2)


@nb.njit(**JIT)
def step_error(tol, model, ex, work, scale, ctl, t):
    """The step's estimate over ``tol``: the new state at STAGE_NEXT, its events in EV_END.

    The embedded solution's (q, q'), y_new - err (STAGE_TRY), is evaluated in the same
    regime, its event functions into EV_TRY (its contact forces overwrite
    rg's).  Returns ``(status, estimate, component)``: the component of
    (q, q') (0..17) or the event function (N_STATE + e) with the largest ratio.
    """
    P, free = model.P, model.free
    stages, cg, rg, ev = work.stages, work.cg, work.rg, work.ev
    y_new = stages[ly.STAGE_NEXT]
    err = stages[ly.STAGE_ERR]
    worst = 0.0
    arg = 0
    for i in range(ly.N_STATE):
        r = abs(err[i]) / (tol * state_scale(i, y_new, scale))
        if r > worst:
            worst = r
            arg = i
    y_hat = stages[ly.STAGE_TRY]
    for i in range(ly.N_STATE):
        y_hat[i] = y_new[i] - err[i]
    if int(rg[ly.RG_SET]) > 0:
        status = rhs_regime(t, y_hat, model, ex, work, stages[ly.STAGE_KTRY])
        if status != ly.OK:
            return status, worst, arg
    event_values_after_rhs(y_hat, P, free, cg, rg, ev, ly.EV_TRY, ly.EV_RATE_TRY)
    for e in range(ly.N_EV):
        r = abs(ev[ly.EV_END, e] - ev[ly.EV_TRY, e]) / (tol * event_scale(e, P, scale, ctl))
        if r > worst:
            worst = r
            arg = ly.N_STATE + e
    return ly.OK, worst, arg


@nb.njit(**JIT_INLINE)
def _next_step(h, err, err_prev, order):
    """The PI controller's next step (s) after an accepted step of h with estimate err."""
    e = max(err, 1e-10)
    fac = SAFETY * e ** (-(1.0 / order - 0.75 * BETA)) * err_prev ** BETA
    return h * min(FAC_MAX, max(FAC_MIN, fac))


@nb.njit(**JIT)
def _record_step(t, h, err, arg, dt, stages, rg, scale, ctl, floor_log, set_before, stick_before):
    """Statistics of an accepted step (layout CTL_*) and, above the tolerance, its floor row."""
    ctl[ly.CTL_STEPS] += 1.0
    ctl[ly.CTL_INTERVALS] += 1.0
    ctl[ly.CTL_H_MIN] = min(ctl[ly.CTL_H_MIN], h)
    ctl[ly.CTL_H_MAX] = max(ctl[ly.CTL_H_MAX], h)
    level = int(math.floor(math.log2(dt / h) + 1e-9)) if h < dt else 0
    ctl[ly.CTL_LEVELS + min(max(level, 0), ly.N_CTL_LEVELS - 1)] += 1.0
    if err > ctl[ly.CTL_ERR_MAX]:
        ctl[ly.CTL_ERR_MAX] = err
        ctl[ly.CTL_T_ERR_MAX] = t
        ctl[ly.CTL_ARG_ERR_MAX] = arg
    y = stages[ly.STAGE_NEXT]
    q = 0.0
    for i in range(ly.N_DOF):
        q = max(q, abs(stages[ly.STAGE_ERR, i]) / state_scale(i, y, scale))
    ctl[ly.CTL_Q_SSQ] += q * q
    if err > 1.0:
        r = int(ctl[ly.CTL_N_FLOOR])
        if r < floor_log.shape[0]:
            floor_log[r, ly.FL_T0] = t
            floor_log[r, ly.FL_T1] = t + h
            floor_log[r, ly.FL_FROM] = regime_of(set_before, stick_before)
            floor_log[r, ly.FL_TO] = regime_of(int(rg[ly.RG_SET]), rg[ly.RG_STICK] != 0.0)
            floor_log[r, ly.FL_EVENTS] = 0.0
            floor_log[r, ly.FL_ERR] = err
            floor_log[r, ly.FL_STEPPED] = 0.0
        ctl[ly.CTL_N_FLOOR] += 1.0


@nb.njit(**JIT_INLINE)
def _event_time_error(e, span, ev, ev_err):
    """An event's time error (s): its function's estimate ev_err[e] over its mean rate from the
    step's start to the event, ``span`` (s) later (its state just past it in EV_HI)."""
    slope = abs(ev[ly.EV_START, e] - ev[ly.EV_HI, e]) / span
    if not slope > 0.0:
        return 0.0
    return ev_err[e] / slope


#: _to_event's status (internal, never a run's) when the pair's steps do not reach the event
#: the dense output located by the step's end (the two differ by the step's error): the step
#: is tried again a quarter as long, or at the smallest step taken whole with no event (the
#: run's account counts the step among the accepted, its retry among the rejected).
NOT_REACHED = -1
#: Steps of the pair to the event (Newton's method on its time) at most.
PAST_ITERS = 40
#: The dense output's slope at an event is taken over this fraction of the step.
SLOPE_FRACTION = 1e-3


@nb.njit(**JIT_INLINE)
def _short_step(t, d, model, ex, work, st):
    """A Heun step of d (s, either sign, |d| <= SHORT_STEP_S) from the pair's state at t
    (STAGE_BASE, its right-hand side in STAGE_KBASE) into STAGE_HI, projected onto the
    regime's constraints; its right-hand side in STAGE_KTRY and its forces in rg."""
    P, free = model.P, model.free
    stages, cg, cw, rg = work.stages, work.cg, work.cw, work.rg
    y0 = stages[ly.STAGE_BASE]
    k0 = stages[ly.STAGE_KBASE]
    y = stages[ly.STAGE_HI]
    k = stages[ly.STAGE_KTRY]
    yp = stages[ly.STAGE_TMP]
    for i in range(ly.N_AUG):
        yp[i] = y0[i] + d * k0[i]
    status = rhs_regime(t + d, yp, model, ex, work, k)
    if status != ly.OK:
        return status
    for i in range(ly.N_AUG):
        y[i] = y0[i] + 0.5 * d * (k0[i] + k[i])
    project_step_end(y, P, free, cg, cw, rg, st)
    return rhs_regime(t + d, y, model, ex, work, k)


@nb.njit(**JIT_INLINE)
def _pair_state_at(x, base, t, h, model, ex, work, st):
    """The pair's state at t + x h (s) into STAGE_HI, its events into EV_HI: a short step
    from the last step of the pair (at the fraction ``base`` of the step, in STAGE_BASE) when
    within SHORT_STEP_S of it, else a step of the pair from the step's start (then the new
    base).  Returns ``(status, base)``."""
    P, stages = model.P, work.stages
    if base >= 0.0 and abs(x - base) * h <= SHORT_STEP_S:
        status = _short_step(t + base * h, (x - base) * h, model, ex, work, st)
    else:
        status = pair_step(t, stages[ly.STAGE_CUR], x * h, model, ex, work, st,
                           stages[ly.STAGE_HI])
        if status == ly.OK:
            base = x
            _copy(stages, ly.STAGE_HI, ly.STAGE_BASE)
            _copy(stages, int(P[ly.P_RK_STAGES]) - 1, ly.STAGE_KBASE)
    if status == ly.OK:
        event_values_after_rhs(stages[ly.STAGE_HI], P, model.free, work.cg, work.rg, work.ev,
                               ly.EV_HI, ly.EV_RATE_TRY)
    return status, base


@nb.njit(**JIT)
def _step_past(e, theta, t, h, model, ex, work, st):
    """The state just past event e by steps of the pair from the step's start (into STAGE_HI).

    ``theta`` is where the dense output of the step (its stages intact)
    passes the event, its state in STAGE_HI and its events in EV_HI.  The
    step of the pair to theta may end before the event or past it by more
    than the event's own thresholds (the two approximations differ by the
    step's error): Newton's method on the event's time, with the dense
    output's slope there, safeguarded by bisection of the bracket the
    pair's steps have found (an event function may have a kink there: a
    double contact's stick margin), moves theta until the pair's state is
    past the event by about what the function changes in EVENT_TIME_TOL, or
    the bracket is EVENT_TIME_TOL wide (after PAST_ITERS tries, the state at
    the bracket's far end, past the event).  A move of at most SHORT_STEP_S from
    the last step of the pair is a short step from its state
    (:func:`_short_step`).  Returns ``(status, theta)``; the events at the
    state in EV_HI.  theta is -1 when the pair's states have not crossed the
    event by the step's end (the dense output's crossing is not the pair's).
    """
    stages, ev = work.stages, work.ev
    f_past = ev[ly.EV_HI, e]
    x = theta - SLOPE_FRACTION if theta > SLOPE_FRACTION else theta + SLOPE_FRACTION
    status = _trial(x, t, h, np.bool_(True), model, ex, work)
    if status != ly.OK:
        return status, theta
    slope = (ev[ly.EV_TRY, e] - f_past) / (x - theta)
    push = EVENT_TIME_TOL / h
    depth = max(-slope * push, 1e-300)
    lo, hi = 0.0, 2.0            # exact f >= 0 at lo (the step's start), < 0 at hi (if <= 1)
    x = theta
    base = -1.0                  # the fraction of the last step of the pair (STAGE_BASE)
    f = 0.0
    for _ in range(PAST_ITERS):
        if x >= 1.0:
            if ev[ly.EV_END, e] >= 0.0:
                return ly.OK, -1.0    # not crossed on the pair's states by the step's end
            _copy(stages, ly.STAGE_NEXT, ly.STAGE_HI)
            _copy_ev(ev, ly.EV_END, ly.EV_HI)
            return ly.OK, 1.0
        status, base = _pair_state_at(x, base, t, h, model, ex, work, st)
        if status != ly.OK:
            return status, x
        f = ev[ly.EV_HI, e]
        if f < 0.0:
            hi = x
            if f > -2.0 * depth or hi - lo <= push:
                return ly.OK, x
        else:
            lo = x
        nxt = x + (-depth - f) / slope if slope < 0.0 else -1.0
        if hi <= 1.0:
            if not lo < nxt < hi:
                nxt = 0.5 * (lo + hi)
        elif not nxt > lo:
            nxt = lo + 2.0 * (lo - theta) + push     # no bracket yet: step further out
        x = min(nxt, 1.0)
    if f >= 0.0:                 # out of iterations before the event: the bracket's far end
        if hi > 1.0:
            return ly.OK, -1.0
        status, base = _pair_state_at(hi, base, t, h, model, ex, work, st)
    return status, hi


@nb.njit(**JIT)
def _earlier_on_steps(e, theta, t, h, model, ex, work):
    """Another event passed on the way to event e's state (STAGE_HI, its events in EV_HI)?

    The pair's steps may reach e later than its dense output did, and pass
    an event the dense output had not reached by then: that event, located
    by Brent's method on the pair's steps from the step's start, comes
    first.  Returns ``(status, event, theta)``, the state past it in STAGE_HI.
    """
    ev = work.ev
    for _ in range(ly.N_EV):
        earlier = passed_before(e, ev)
        if earlier < 0:
            break
        status, theta = _bracket(earlier, ev[ly.EV_START, earlier], theta, ev[ly.EV_HI, earlier], t,
                                 h, np.bool_(False), model, ex, work)
        if status != ly.OK:
            return status, e, theta
        e = earlier
    return ly.OK, e, theta


@nb.njit(**JIT)
def _take_step(stages, ev, last):
    """An accepted step without an event: its end becomes the current state, its last stage
    the next step's first (first same as last), its event functions the next start's."""
    _copy(stages, ly.STAGE_NEXT, ly.STAGE_CUR)
    _copy(stages, last, ly.STAGE_K1)
    _copy_ev(ev, ly.EV_END, ly.EV_START)
    for p in range(ly.N_POINTS):
        ev[ly.EV_RATE_START, ly.EV_GAP + p] = ev[ly.EV_RATE_END, ly.EV_GAP + p]


@nb.njit(**JIT)
def _take_whole(t_end, model, ex, work):
    """A step at the smallest size whose located event the pair's steps do not reach: its
    end (STAGE_NEXT, at t_end, s) becomes the current state with no event; returns a status."""
    stages = work.stages
    _take_step(stages, work.ev, int(model.P[ly.P_RK_STAGES]) - 1)   # its first stage anew below
    return rhs_regime(t_end, stages[ly.STAGE_CUR], model, ex, work, stages[ly.STAGE_K1])


@nb.njit(**JIT)
def _bad_input(y0, span, tolerance, P, out, log):
    """Whether run_adaptive's arrays or settings are inconsistent (ERR_BAD_INPUT)."""
    dt, n_steps, step0, decim = span
    tol, level_max = tolerance
    need = (step0 + n_steps) // decim - step0 // decim + (1 if step0 == 0 else 0)
    return (y0.shape[0] != ly.N_AUG or decim < 1 or out[0].shape[0] < need
            or out[1].shape[0] < need or out[2].shape[0] < need
            or log.shape[0] < 2 * LOG_RESERVE or not tol > 0.0 or level_max < 0
            or P[ly.P_RK_DEGREE] < 1.0)


@nb.njit(**JIT)
def _rejected(status, err, arg, h, h_floor, order, ctl):
    """Count a rejected step of h (s) and return the step to try next (s): a quarter after
    a failure, else the controller's decrease, at least h_floor."""
    ctl[ly.CTL_REJECTED] += 1.0
    ctl[ly.CTL_WORK] += 1.0
    if arg >= ly.N_STATE:
        ctl[ly.CTL_REJECTED_EVENTS] += 1.0
    if status != ly.OK or not math.isfinite(err):
        h_new = 0.25 * h
    else:
        h_new = h * max(FAC_MIN, SAFETY * err ** (-1.0 / order))
    return max(h_new, h_floor)


@nb.njit(**JIT_INLINE)
def _noise_levels(tol, P, scale, ctl, ev):
    """The error each event function may carry, tol times its scale, into ev[EV_NOISE]."""
    for k in range(ly.N_EV):
        ev[ly.EV_NOISE, k] = tol * event_scale(k, P, scale, ctl)


@nb.njit(**JIT)
def _accepted(step, force, tol, before, model, work, control):
    """The account of an accepted step ``step`` = (t, h, err, arg, dt, e, theta): its
    statistics, the error scales grown by its state and total normal force (dyn), the
    event functions' noise levels, and the squared time error of its event e (if any);
    ``before`` is the regime's (set, stick) before the step."""
    t, h, err, arg, dt, e, theta = step
    P, stages, rg, ev = model.P, work.stages, work.rg, work.ev
    ctl, scale, floor_log = control
    ctl[ly.CTL_WORK] += 1.0
    _record_step(t, h, err, arg, dt, stages, rg, scale, ctl, floor_log, before[0], before[1])
    grow_scales(stages[ly.STAGE_NEXT], force, scale, ctl)
    _noise_levels(tol, P, scale, ctl, ev)
    if e >= 0:
        te = _event_time_error(e, theta * h, ev, stages[ly.STAGE_TMP])
        ctl[ly.CTL_T_SSQ] += te * te


@nb.njit(**JIT)
def _try_step(t, y, h_try, tol, h_floor, model, ex, work, st, scale, ctl):
    """A step of the pair of h_try (s) from (t, y) into STAGE_NEXT, its error estimate over
    the tolerance (q, q', the event functions, the time of the first event it locates) and
    that event.  Returns (status, err, arg of the largest estimate, the total normal force,
    the event e (-1: none), its fraction theta of the step)."""
    P, free = model.P, model.free
    stages, cg, rg, ev = work.stages, work.cg, work.rg, work.ev
    status = pair_step(t, y, h_try, model, ex, work, st, stages[ly.STAGE_NEXT])
    err = np.inf
    arg = -1
    force = 0.0
    if status == ly.OK:
        event_values_after_rhs(stages[ly.STAGE_NEXT], P, free, cg, rg, ev, ly.EV_END, ly.EV_RATE_END)
        force = total_normal_force(rg)
        status, err, arg = step_error(tol, model, ex, work, scale, ctl, t + h_try)
    e = -1
    theta = 2.0
    acceptable = err <= 1.0 or h_try <= h_floor * (1.0 + 1e-9)
    if status == ly.OK and acceptable and P[ly.P_RK_EXTRA] > 0.0:
        status = prepare_dense(t, y, h_try, model, ex, work)
    if status == ly.OK and acceptable:
        ev_err = stages[ly.STAGE_TMP]       # the event functions' estimates
        for k in range(ly.N_EV):
            ev_err[k] = abs(ev[ly.EV_END, k] - ev[ly.EV_TRY, k])
        status, e, theta = locate(t, h_try, np.bool_(True), model, ex, work)
        if status == ly.OK and e >= 0:
            te = _event_time_error(e, theta * h_try, ev, ev_err)
            r = te / (tol * EVENT_TIME_SCALE_S)
            if r > err:
                err = r
                arg = ly.N_STATE + ly.N_EV
    return status, err, arg, force, e, theta


@nb.njit(**JIT)
def _samples(t, t_end, h, whole, y, lattice, counts, model, ex, work, st, out):
    """Store the samples of the lattice (t0, step0, dt, decim, m_stop) in (t, t_end] from the
    dense output of the step of h (s) from (t, y) (its end from STAGE_NEXT when the step is
    ``whole``, not cut at an event).  ``counts`` is (stored, b_next); returns (status, stored,
    b_next)."""
    t0, step0, dt, decim, m_stop = lattice
    stored, b_next = counts
    P, stages = model.P, work.stages
    out_t, out_y, out_sig = out
    while b_next <= m_stop:
        t_sample = t0 + (b_next - step0) * dt
        if t_sample > t_end + STEP_REMAINDER_REL * dt:
            break
        x = (t_sample - t) / h
        y_s = stages[ly.STAGE_NEXT]
        if not (whole and x >= 1.0 - 1e-12):
            y_s = stages[ly.STAGE_HI]
            dense(min(x, 1.0), h, y, P, stages, y_s)
        status = store(stored, t_sample, y_s, model, ex, work, st, out_t, out_y, out_sig)
        if status != ly.OK:
            return status, stored, b_next
        stored += 1
        b_next += decim
    return ly.OK, stored, b_next


@nb.njit(**JIT)
def _to_event(e, theta, t, h, t_stop, y, model, ex, work, log, n_log, st):
    """After a step of h (s) from (t, y) in which event e was located at theta: one step of
    the pair from the step's start to just past it, then the event and any impact it sets
    off (Moreau-Jean time-stepping once they flood).  Returns (status, t, n_log);
    NOT_REACHED, nothing changed, when the pair's steps do not reach the event."""
    stages, rg, ev = work.stages, work.rg, work.ev
    status, theta = _step_past(e, theta, t, h, model, ex, work, st)
    if status == ly.OK and theta < 0.0:
        return NOT_REACHED, t, n_log
    if status == ly.OK:
        status, e, theta = _earlier_on_steps(e, theta, t, h, model, ex, work)
    if status != ly.OK:
        st[ly.ST_T] = t
        return status, t, n_log
    _copy(stages, ly.STAGE_HI, ly.STAGE_CUR)
    if theta < 1.0:
        t = t + theta * h
    else:
        t = t_stop if h == t_stop - t else t + h
    penetration(st, rg, ev, ly.EV_HI, t, 10)    # when the event is found
    n_step_events = 0
    while e >= 0:
        n_step_events += 1
        if flooding(st, t) or n_step_events > MAX_EVENTS_PER_STEP:
            st[ly.ST_STEPPED_UNTIL] = t + STEPPED_TIME_S
            return rhs_regime(t, y, model, ex, work, stages[ly.STAGE_K1]), t, n_log
        status = apply_event(e, t, model, ex, work, log, n_log, st)
        if status != ly.OK:
            st[ly.ST_T] = t
            return status, t, n_log
        n_log += 1
        e = _immediate_impact(ev)
    return ly.OK, t, n_log


@nb.njit(**JIT)
def _stepped_span(t, t_stop, y, lattice, counts, model, ex, work, st, out):
    """Moreau-Jean steps from t to the end of the flood's interval (ST_STEPPED_UNTIL), t_stop
    or the next sample of the lattice (t0, step0, dt, decim, m_stop), whichever comes first,
    and that sample.  ``counts`` is (stored, b_next); returns (status, t, stored, b_next)."""
    t0, step0, dt, decim, m_stop = lattice
    stored, b_next = counts
    out_t, out_y, out_sig = out
    t_sample = t0 + (b_next - step0) * dt
    t_next = min(st[ly.ST_STEPPED_UNTIL], t_stop)
    if b_next <= m_stop:
        t_next = min(t_next, t_sample)
    status = _stepped(t, t_next - t, model, ex, work, st)
    if status != ly.OK:
        st[ly.ST_T] = t
        return status, t, stored, b_next
    t = t_next
    if b_next <= m_stop and t >= t_sample - STEP_REMAINDER_REL * dt:
        status = store(stored, t_sample, y, model, ex, work, st, out_t, out_y, out_sig)
        if status != ly.OK:
            return status, t, stored, b_next
        stored += 1
        b_next += decim
    return ly.OK, t, stored, b_next


@nb.njit(**JIT)
def run_adaptive(y0, t0, span, tolerance, model, ex, work, out, log, st, control):
    """Integrate n_steps base steps dt (s) from (t0, y0) with steps chosen by the error.

    ``span`` (dt, n_steps, step0, decim) and the groups ``model``, ``work``, ``out`` as
    :func:`workbench.core.hybrid.run_hybrid` (samples here from the dense output);
    ``tolerance`` is (tol, level_max): steps of the pair in P against the relative
    tolerance tol > 0, between dt and dt / 2^level_max (module docstring); ``control``
    (ctl (N_CTL,), scale (N_SCALE_ROWS, N_STATE), floor_log (capacity, N_FLOOR)) carries
    the controller between calls (zeros, with CTL_H_MIN = inf, before the first).
    Returns ``(status, n_stored, n_log)``.
    """
    dt, n_steps, step0, decim = span
    tol, level_max = tolerance
    P = model.P
    stages, rg, ev = work.stages, work.rg, work.ev
    ctl, scale = control[0], control[1]
    if _bad_input(y0, span, tolerance, P, out, log):
        return ly.ERR_BAD_INPUT, 0, 0
    y = stages[ly.STAGE_CUR]
    for i in range(ly.N_AUG):
        y[i] = y0[i]
    status, stored, n_log = begin(t0, step0, model, ex, work, out[0], out[1], out[2], log, st)
    if status != ly.OK:
        return status, stored, n_log
    order = P[ly.P_RK_ORDER]
    last = int(P[ly.P_RK_STAGES]) - 1
    floors(P, scale)
    grow_scales(y, total_normal_force(rg), scale, ctl)
    _noise_levels(tol, P, scale, ctl, ev)
    h_floor = dt / (1 << level_max)
    h_max = max(P[ly.P_RK_STEP_FACTOR], 1.0) * dt
    h = ctl[ly.CTL_H_NEXT] if ctl[ly.CTL_H_NEXT] > 0.0 else dt
    err_prev = ctl[ly.CTL_ERR_PREV] if ctl[ly.CTL_ERR_PREV] > 0.0 else ERR_PREV_START
    t = t0
    rejected = full = False          # the last step tried was rejected; the log is nearly full
    m_stop = step0 + n_steps                 # the base step the call ends at
    b_next = (step0 // decim + 1) * decim    # the next sample's base step
    while True:
        t_stop = t0 + (m_stop - step0) * dt
        if t_stop - t <= STEP_REMAINDER_REL * dt:
            break
        if not full and n_log + LOG_RESERVE > log.shape[0]:
            full = True                      # end at the next base step
            m_stop = step0 + int(math.ceil((t - t0) / dt - 1e-9))
            continue
        if n_log + MAX_EVENTS_PER_STEP + 2 > log.shape[0]:
            st[ly.ST_T] = t
            return ly.ERR_EVENT_FLOOD, stored, n_log
        if st[ly.ST_STEPPED_UNTIL] > t + STEP_REMAINDER_REL * dt:
            # Moreau-Jean time-stepping after an event flood
            status, t, stored, b_next = _stepped_span(t, t_stop, y, (t0, step0, dt, decim, m_stop),
                                                      (stored, b_next), model, ex, work, st, out)
            if status != ly.OK:
                return status, stored, n_log
            continue
        h_try = min(h, h_max, t_stop - t)
        before = (int(rg[ly.RG_SET]), rg[ly.RG_STICK] != 0.0)     # the regime (set, stick)
        status, err, arg, force, e, theta = _try_step(t, y, h_try, tol, h_floor, model, ex, work,
                                                      st, scale, ctl)
        if (status != ly.OK or err > 1.0) and h_try > h_floor * (1.0 + 1e-9):
            h = _rejected(status, err, arg, h_try, h_floor, order, ctl)
            rejected = True
            continue
        if status != ly.OK:
            st[ly.ST_T] = t
            return status, stored, n_log
        _accepted((t, h_try, err, arg, dt, e, theta), force, tol, before, model, work, control)
        t_end = t + h_try if (e < 0 or theta >= 1.0) else t + theta * h_try
        if e < 0 and h_try == t_stop - t:
            t_end = t_stop
        # samples in (t, t_end]: the dense output of this step (or its end)
        status, stored, b_next = _samples(t, t_end, h_try, e < 0, y, (t0, step0, dt, decim, m_stop),
                                          (stored, b_next), model, ex, work, st, out)
        if status != ly.OK:
            return status, stored, n_log
        if e < 0:
            _take_step(stages, ev, last)
            t = t_end
        else:
            status, t, n_log = _to_event(e, theta, t, h_try, t_stop, y, model, ex, work, log,
                                         n_log, st)
            if status == NOT_REACHED and h_try > h_floor * (1.0 + 1e-9):
                h = _rejected(status, err, ly.N_STATE + e, h_try, h_floor, order, ctl)
                rejected = True
                continue
            if status == NOT_REACHED:
                status, t = _take_whole(t + h_try, model, ex, work), t + h_try
            if status != ly.OK:
                return status, stored, n_log
        if err <= 1.0:                       # no growth right after a rejection
            h = min(_next_step(h_try, err, err_prev, order), h_try if rejected else np.inf)
            err_prev = max(err, ERR_PREV_START)
        rejected = False
        h = max(h, h_floor)
        step_end(t, y, rg, ev, st)
    st[ly.ST_T] = t
    st[ly.ST_STEP] = m_stop
    ctl[ly.CTL_H_NEXT] = h
    ctl[ly.CTL_ERR_PREV] = err_prev
    return (ly.LOG_FULL if full else ly.OK), stored, n_log
