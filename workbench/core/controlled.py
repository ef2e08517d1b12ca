"""Error-controlled integration on the output lattice, jit-compiled.

The run is cut into control intervals of ``seg`` base steps dt (a divisor of
the output interval, so samples fall exactly on the output times).  Each
interval is integrated twice by the event-driven steps of
:func:`workbench.core.hybrid.advance`, from the same start: a coarse path of
``seg 2^k`` steps of dt / 2^k and a fine path of twice as many (step
doubling).  The fine path is accepted when

* both paths took the same sequence of events (kind, point, regime after),
  so no impact, separation or stick-slip cycle of one is missing in the
  other, and neither handed an event flood to Moreau-Jean time-stepping
  (first order, so Richardson's estimate would not hold: such an interval
  is refined down to the floor, where the flood is accepted and reported),
  and
* every component of (q, q') and every event function of the regime
  (gaps, normal forces, stick margin, slip rate) agrees between the two
  ends within ``tol`` times its scale: for a component of q or q' the
  largest |value| so far of it or of its PARTNER (the two components of
  one point's motion: a beam tip's deflection and elongation, the loose
  body's slide and offset), not below a floor from the model's clearance
  (:func:`_floors`); for a gap the clearance; for a normal force or the
  stick margin the largest total normal force so far (not below the loose
  body's weight); for a slip rate the loose body's velocity scale; and
  the time of every event, on the scale of the interval's length.

The estimate is Richardson's error of the fine path: the difference of the
two paths over 2^p - 1 (p the order of the tableau in P: 15 for RK4),
which is the fine path's own error where the motion is smooth; the largest
of these ratios over ``tol`` decides.  A rejected interval is redone one
level finer, the fine path becoming the coarse one; an accepted estimate
below COARSEN_MARGIN / 2^p lets the next interval try one level coarser.  At ``level_max`` (steps of
dt / 2^(level_max + 1)) the fine path is accepted whatever the estimate and
the interval is written to ``floor_log`` (time, regimes, events, estimate).
Every decision depends on the state only, so a run is deterministic.
"""
import numba as nb
import numpy as np

from .config import COARSEN_MARGIN, JIT, JIT_INLINE, MAX_EVENTS_PER_STEP, REF_RATE
from . import layout as ly
from .contact import regime_of
from .hybrid import _store, advance, begin

#: Returned for two paths whose event sequences differ (no estimate).
MISMATCH = 1e300


@nb.njit(**JIT_INLINE)
def _save(base, t, stepped_left, stages, rg, ev, st, snap):
    for i in range(ly.N_AUG):
        snap[base + ly.SNAP_Y, i] = stages[ly.STAGE_CUR, i]
        snap[base + ly.SNAP_K1, i] = stages[ly.STAGE_K1, i]
    for i in range(ly.N_EV):
        snap[base + ly.SNAP_EV, i] = ev[ly.EV_START, i]
        snap[base + ly.SNAP_EVR, i] = ev[ly.EV_RATE_START, i]
    for i in range(ly.N_RG):
        snap[base + ly.SNAP_RG, i] = rg[i]
    for i in range(ly.N_ST):
        snap[base + ly.SNAP_ST, i] = st[i]
    snap[base + ly.SNAP_MISC, 0] = t
    snap[base + ly.SNAP_MISC, 1] = stepped_left


@nb.njit(**JIT_INLINE)
def _restore(base, stages, rg, ev, st, snap):
    """Put snapshot ``base`` back; returns its (t, stepped_left)."""
    for i in range(ly.N_AUG):
        stages[ly.STAGE_CUR, i] = snap[base + ly.SNAP_Y, i]
        stages[ly.STAGE_K1, i] = snap[base + ly.SNAP_K1, i]
    for i in range(ly.N_EV):
        ev[ly.EV_START, i] = snap[base + ly.SNAP_EV, i]
        ev[ly.EV_RATE_START, i] = snap[base + ly.SNAP_EVR, i]
    for i in range(ly.N_RG):
        rg[i] = snap[base + ly.SNAP_RG, i]
    for i in range(ly.N_ST):
        st[i] = snap[base + ly.SNAP_ST, i]
    return snap[base + ly.SNAP_MISC, 0], int(snap[base + ly.SNAP_MISC, 1])


@nb.njit(**JIT_INLINE)
def _took_stepped(st, snap):
    """Did the path just taken (from snapshot SNAP_START) take Moreau-Jean steps?"""
    return st[ly.ST_N_STEPPED] != snap[ly.SNAP_START + ly.SNAP_ST, ly.ST_N_STEPPED]


@nb.njit(**JIT)
def _path(t0, m0, n, dt, lev, stepped_left, P, tab, kc, free, ex, rec, mat, vec, stages, cg, cw, rg,
          ev, log, n_log, st, sample, step0, decim, stored, out_t, out_y, out_sig):
    """n lattice steps h = dt / 2^lev (s), the j-th ending at t0 + (m0 + j) h.

    With ``sample`` true, the state at every lattice point that is a base step b
    (counted from the run's start: step0 at t0) with b % decim == 0 is stored
    (out index ``stored`` for the first such point after the path's start, and on).
    Returns ``(status, n_log, stepped_left)``; LOG_FULL when the log has no
    room for a step's events.
    """
    h = dt / (1 << lev)
    t = t0 + m0 * h
    b_start = step0 + (m0 >> lev)
    for j in range(1, n + 1):
        if n_log + MAX_EVENTS_PER_STEP + 2 > log.shape[0]:
            return ly.LOG_FULL, n_log, stepped_left
        status, t, n_log, stepped_left = advance(t, t0 + (m0 + j) * h, h, stepped_left, P, tab,
                                                 kc, free, ex, rec, mat, vec, stages, cg, cw, rg,
                                                 ev, log, n_log, st)
        if status != ly.OK:
            return status, n_log, stepped_left
        if sample and (m0 + j) % (1 << lev) == 0:
            b = step0 + ((m0 + j) >> lev)
            if b % decim == 0:
                status = _store(stored + b // decim - b_start // decim - 1, t, P, tab, kc, free,
                                ex, rec, mat, vec, stages, cg, cw, rg, st, out_t, out_y, out_sig)
                if status != ly.OK:
                    return status, n_log, stepped_left
    return ly.OK, n_log, stepped_left


#: The coordinate sharing a component's scale: a beam tip's deflection and
#: elongation, and the loose body's slide and offset, are the two
#: components of one point's motion (cm); an angle has a scale of its own.
PARTNER = (ly.U_A, ly.PHI_A, ly.W_A, ly.V, ly.S, ly.PSI, ly.U_B, ly.PHI_B, ly.W_B)


@nb.njit(**JIT)
def _floors(P, scale):
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
def _grow_scales(y, rg, scale, ctl):
    for i in range(ly.N_STATE):
        scale[ly.SCALE_PEAK, i] = max(scale[ly.SCALE_PEAK, i], abs(y[i]))
    total = 0.0
    for p in range(ly.N_POINTS):
        total += abs(rg[ly.RG_LN + p])
    ctl[ly.CTL_F_SCALE] = max(ctl[ly.CTL_F_SCALE], total)


@nb.njit(**JIT)
def interval_error(tol, span, a, n_coarse, b, n_fine, P, stages, ev, log, snap, scale, ctl):
    """The fine path's error estimate over ``tol``: fine path at STAGE_CUR, coarse in snap.

    The coarse path's events are log rows [a, a + n_coarse), the fine
    path's [b, b + n_fine); ``span`` (s) is the interval's length, the scale
    of the events' times.  Returns ``(estimate, component)``: the component
    of (q, q') (0..17), the event function (N_STATE + e) or the event times
    (N_STATE + N_EV) with the largest ratio; (MISMATCH, -1) when the event
    sequences differ.
    """
    if n_coarse != n_fine:
        return MISMATCH, -1
    err = 0.0
    arg = 0
    for i in range(n_fine):
        for col in (ly.LOG_KIND, ly.LOG_POINT, ly.LOG_TO):
            if log[a + i, col] != log[b + i, col]:
                return MISMATCH, -1
        r = abs(log[a + i, ly.LOG_T] - log[b + i, ly.LOG_T]) / (tol * span)
        if r > err:
            err = r
            arg = ly.N_STATE + ly.N_EV
    y = stages[ly.STAGE_CUR]
    c = ly.SNAP_COARSE
    for i in range(ly.N_STATE):
        j = PARTNER[i % ly.N_DOF] + (i // ly.N_DOF) * ly.N_DOF
        s = tol * max(scale[ly.SCALE_FLOOR, i], scale[ly.SCALE_PEAK, i], scale[ly.SCALE_PEAK, j],
                      abs(y[i]))
        r = abs(y[i] - snap[c + ly.SNAP_Y, i]) / s
        if r > err:
            err = r
            arg = i
    force = tol * max(ctl[ly.CTL_F_SCALE], P[ly.P_M4] * P[ly.P_GRAV])
    rate = tol * max(scale[ly.SCALE_FLOOR, ly.N_DOF + ly.S], scale[ly.SCALE_PEAK, ly.N_DOF + ly.S],
                     scale[ly.SCALE_PEAK, ly.N_DOF + ly.V])
    gap = tol * P[ly.P_GAP]
    for e in range(ly.N_EV):
        if e < ly.EV_GAP + ly.N_POINTS:
            s = gap
        elif e == ly.EV_SLIP:
            s = rate
        else:
            s = force
        r = abs(ev[ly.EV_START, e] - snap[c + ly.SNAP_EV, e]) / s
        if r > err:
            err = r
            arg = ly.N_STATE + e
    return err / (2.0 ** P[ly.P_RK_ORDER] - 1.0), arg     # Richardson's factor


@nb.njit(**JIT)
def accumulate_local(a, b, n, P, stages, log, snap, scale, ctl):
    """Add an accepted interval's local estimates to the run's sums of squares.

    The fine path is at STAGE_CUR and the coarse one in snap; the n events
    of both are log rows [a, a + n) and [b, b + n).  Adds the square of the
    largest relative error of a position (Richardson's estimate over the
    scale of :func:`interval_error`) to ctl[CTL_Q_SSQ], and the squares of
    the events' time errors (s) to ctl[CTL_T_SSQ].  Their roots estimate the
    run's global error as local errors of random sign would add up.
    """
    richardson = 2.0 ** P[ly.P_RK_ORDER] - 1.0
    y = stages[ly.STAGE_CUR]
    q = 0.0
    for i in range(ly.N_DOF):
        s = max(scale[ly.SCALE_FLOOR, i], scale[ly.SCALE_PEAK, i],
                scale[ly.SCALE_PEAK, PARTNER[i]], abs(y[i]))
        q = max(q, abs(y[i] - snap[ly.SNAP_COARSE + ly.SNAP_Y, i]) / s)
    q /= richardson
    ctl[ly.CTL_Q_SSQ] += q * q
    for i in range(n):
        e = abs(log[a + i, ly.LOG_T] - log[b + i, ly.LOG_T]) / richardson
        ctl[ly.CTL_T_SSQ] += e * e


@nb.njit(**JIT_INLINE)
def _move_rows(log, src, n, dst):
    if src != dst:
        for i in range(n):
            for j in range(ly.N_LOG):
                log[dst + i, j] = log[src + i, j]


@nb.njit(**JIT)
def run_controlled(y0, t0, dt, n_steps, step0, decim, seg, tol, level_max, P, tab, kc, free, ex,
                   rec, mat, vec, stages, cg, cw, rg, ev, out_t, out_y, out_sig, log, st, snap,
                   ctl, scale, floor_log):
    """Integrate n_steps base steps dt (s) from (t0, y0) with steps chosen by the error.

    As :func:`workbench.core.hybrid.run_hybrid` (chunks by ``step0``,
    samples every ``decim`` base steps, LOG_FULL after a whole interval),
    with control intervals of ``seg`` base steps (seg divides n_steps and
    step0; the samples inside an interval are those of its accepted fine
    path), each integrated at the level of ``ctl[CTL_LEVEL]``
    or finer, the fine paths' steps down to dt / 2^level_max (level_max >= 1;
    module docstring).  ``tol`` > 0 is the
    relative tolerance.  ``snap`` (N_SNAP, N_AUG) is scratch; ``ctl``
    (N_CTL,), ``scale`` (N_SCALE_ROWS, N_STATE) and ``floor_log``
    (capacity, N_FLOOR) carry the controller between calls (zeros, with
    CTL_H_MIN = inf, before the first).  A path that fails (a status other
    than OK) is an interval to redo finer; only the finest failing ends
    the run.  Returns ``(status, n_stored, n_log)``.
    """
    n_out = out_t.shape[0]
    need = (step0 + n_steps) // decim - step0 // decim + (1 if step0 == 0 else 0)
    if (y0.shape[0] != ly.N_AUG or decim < 1 or seg < 1
            or n_steps % seg != 0 or step0 % seg != 0 or n_out < need or out_y.shape[0] < need
            or out_sig.shape[0] < need or log.shape[0] < 4 * (MAX_EVENTS_PER_STEP + 2)
            or not tol > 0.0 or level_max < 1 or snap.shape[0] < ly.N_SNAP):
        return ly.ERR_BAD_INPUT, 0, 0
    for i in range(ly.N_AUG):
        stages[ly.STAGE_CUR, i] = y0[i]
    status, stored, n_log = begin(t0, step0, P, tab, kc, free, ex, rec, mat, vec, stages, cg, cw,
                                  rg, ev, out_t, out_y, out_sig, log, st)
    if status != ly.OK:
        return status, stored, n_log
    coarsen = COARSEN_MARGIN / 2.0 ** P[ly.P_RK_ORDER]
    _floors(P, scale)
    _grow_scales(stages[ly.STAGE_CUR], rg, scale, ctl)
    t = t0
    stepped_left = np.int64(0)
    for i in range(n_steps // seg):
        _save(ly.SNAP_START, t, stepped_left, stages, rg, ev, st, snap)
        k = int(ctl[ly.CTL_LEVEL])
        n = seg << k
        status, end_c, left_c = _path(t0, i * n, n, dt, k, stepped_left, P, tab, kc, free, ex,
                                      rec, mat, vec, stages, cg, cw, rg, ev, log, n_log, st,
                                      np.bool_(False), step0, decim, stored, out_t, out_y,
                                      out_sig)
        ctl[ly.CTL_WORK] += n
        if status == ly.LOG_FULL:
            _restore(ly.SNAP_START, stages, rg, ev, st, snap)
            return ly.LOG_FULL, stored, n_log
        coarse_ok = status == ly.OK and not _took_stepped(st, snap)
        if coarse_ok:
            _save(ly.SNAP_COARSE, t, left_c, stages, rg, ev, st, snap)
        while True:
            t, stepped_left = _restore(ly.SNAP_START, stages, rg, ev, st, snap)
            n = seg << (k + 1)
            h = dt / (1 << (k + 1))
            status, end_f, left_f = _path(t0, i * n, n, dt, k + 1, stepped_left, P, tab, kc, free,
                                          ex, rec, mat, vec, stages, cg, cw, rg, ev, log, end_c,
                                          st, np.bool_(True), step0, decim, stored, out_t, out_y,
                                          out_sig)
            ctl[ly.CTL_WORK] += n
            if status == ly.LOG_FULL:
                _restore(ly.SNAP_START, stages, rg, ev, st, snap)
                return ly.LOG_FULL, stored, n_log
            err, arg = MISMATCH, -1
            if status == ly.OK and coarse_ok and not _took_stepped(st, snap):
                err, arg = interval_error(tol, seg * dt, n_log, end_c - n_log, end_c,
                                          end_f - end_c, P, stages, ev, log, snap, scale, ctl)
                if err <= 1.0 or k + 1 >= level_max:
                    if err < MISMATCH:
                        accumulate_local(n_log, end_c, end_f - end_c, P, stages, log, snap,
                                         scale, ctl)
            _move_rows(log, end_c, end_f - end_c, n_log)
            end_f = n_log + end_f - end_c
            if err <= 1.0 or k + 1 >= level_max:
                break
            # redo finer: the fine path is the next pair's coarse one
            ctl[ly.CTL_REJECTED] += 1.0
            if arg < 0:
                ctl[ly.CTL_REJECTED_EVENTS] += 1.0
            coarse_ok = status == ly.OK and not _took_stepped(st, snap)
            if coarse_ok:
                _save(ly.SNAP_COARSE, t, left_f, stages, rg, ev, st, snap)
            end_c = end_f
            k += 1
        if status != ly.OK:
            return status, stored, n_log
        if err > 1.0:
            r = int(ctl[ly.CTL_N_FLOOR])
            if r < floor_log.shape[0]:
                floor_log[r, ly.FL_T0] = snap[ly.SNAP_START + ly.SNAP_MISC, 0]
                floor_log[r, ly.FL_T1] = t0 + (i + 1) * seg * dt
                floor_log[r, ly.FL_FROM] = regime_of(
                    int(snap[ly.SNAP_START + ly.SNAP_RG, ly.RG_SET]),
                    snap[ly.SNAP_START + ly.SNAP_RG, ly.RG_STICK] != 0.0)
                floor_log[r, ly.FL_TO] = regime_of(int(rg[ly.RG_SET]), rg[ly.RG_STICK] != 0.0)
                floor_log[r, ly.FL_EVENTS] = end_f - n_log
                floor_log[r, ly.FL_ERR] = -1.0 if err >= MISMATCH else err
                floor_log[r, ly.FL_STEPPED] = (st[ly.ST_N_STEPPED]
                                               - snap[ly.SNAP_START + ly.SNAP_ST, ly.ST_N_STEPPED])
            ctl[ly.CTL_N_FLOOR] += 1.0
        if err < MISMATCH and err > ctl[ly.CTL_ERR_MAX]:
            ctl[ly.CTL_ERR_MAX] = err
            ctl[ly.CTL_T_ERR_MAX] = snap[ly.SNAP_START + ly.SNAP_MISC, 0]
            ctl[ly.CTL_ARG_ERR_MAX] = arg
        ctl[ly.CTL_LEVELS + min(k + 1, ly.N_CTL_LEVELS - 1)] += 1.0
        ctl[ly.CTL_STEPS] += n
        ctl[ly.CTL_INTERVALS] += 1.0
        ctl[ly.CTL_H_MIN] = min(ctl[ly.CTL_H_MIN], h)
        ctl[ly.CTL_H_MAX] = max(ctl[ly.CTL_H_MAX], h)
        ctl[ly.CTL_LEVEL] = k - 1 if (err < coarsen and k > 0) else k
        n_log = end_f
        stepped_left = left_f
        t = t0 + (i + 1) * seg * dt
        _grow_scales(stages[ly.STAGE_CUR], rg, scale, ctl)
        st[ly.ST_STEP] = step0 + (i + 1) * seg
        # the accepted fine path stored the samples of the interval
        stored += (step0 + (i + 1) * seg) // decim - (step0 + i * seg) // decim
    return ly.OK, stored, n_log
