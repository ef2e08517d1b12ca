"""The variational equations of a regime and the saltation matrix of an event, jit-compiled.

Along a solution in one regime (docs/model.md §7) a perturbation of the state y = (q, q')
obeys dPhi/dt = A(t) Phi, A = df/dy of the regime's right-hand side
(:func:`workbench.core.constrained.rhs_regime`).  The model has no analytic Jacobian: A
is taken by forward differences of f, a step of VAR_FD_REL (or ctl[CTL_FD_REL]) of each
component's error scale (the kinematic rows, dq'/dy, exactly; a held coordinate's rows
and columns are 0).  :func:`variational_span` integrates (y, Phi) together with the pair
in P (the run's method): stage r's Phi_r = Phi + h sum_j a_rj K_j and
K_r = A(t_r, y_r) Phi_r, so that Phi is the Jacobian of the method's own step; the step is
controlled on both error estimates (y on its error scales, Phi_ik on scale_i times column
k's size vw.column[k], the caller's), and y is projected onto the regime's constraints after
each step, as the run's steps are (:func:`workbench.core.pair.pair_step`).

At an event at time t_e, with event function h(t, y) (:mod:`workbench.core.event_functions`)
and jump y+ = G(y-) (:func:`workbench.core.hybrid.apply_event`: the projection onto the
old regime, the impact law, the new regime's choice and projection), a perturbation passes
through the saltation matrix

    S = G_y + (f+ - G_y f-) grad h^T / (dh/dt)

f- the old regime's right-hand side at y-, f+ the new one's at y+, and dh/dt = h_t + grad h
. f- the event function's rate along the old flow (Leine & Nijmeijer, *Dynamics and
Bifurcations of Non-Smooth Mechanical Systems*, LNACM 18, Springer 2004, §3.5; Müller,
Chaos, Solitons & Fractals 5(9), 1995).  S is applied to the columns of Phi, each a
tangent vector of the regime's constraints: G_y and grad h along each by central
differences (JUMP_FD_REL of the error scales), dh/dt along f- over EVENT_DT_FD_S; G with
the regime after the event held (:func:`forced_jump`: a perturbed state meets the same
transition).  Where the enumeration's choice differs from the jump with that regime held
(an impulse resolved an inconsistent state) the jump is not differentiable
(ERR_JUMP_AMBIGUOUS); an event met tangentially has no saltation matrix
(ERR_EVENT_TANGENT).

The scratch is a ``VarWork`` record (:func:`workbench.model.monodromy.make_var_work`):
``scale`` its error scales (N_STATE), ``column`` each column's size on them, ``ctl`` the
step and counts (CTL_*).
"""
import math
import numba as nb
import numpy as np

from .config import (EVENT_DT_FD_S, JIT, JIT_INLINE, JUMP_FD_REL, RATE_EPS, VAR_H_MAX_S,
                     VAR_H_MIN_S)
from . import layout as ly
from .constrained import project, rhs_regime, tangent_point
from .contact import fill_geometry, regime_of, row_convective, row_rate
from .event_functions import event_values
from .hybrid import apply_event, event_transition
from .integrate import stage_state
from .transitions import arm_gaps

#: ctl entries: the step (s), steps accepted, steps rejected, events whose regime after was
#: the target's, not the enumeration's (:func:`saltation`), the state Jacobian's
#: forward-difference step relative to the error scales (default VAR_FD_REL), and the steps
#: (accepted and rejected) allowed in all (ERR_VAR_STEPS beyond).
CTL_H, CTL_STEPS, CTL_REJECTED, CTL_FOLLOWED, CTL_FD_REL, CTL_MAX_STEPS = 0, 1, 2, 3, 4, 5
N_CTL = 6
N = ly.N_STATE


@nb.njit(**JIT)
def state_jacobian(t, y, f, model, ex, work, vw):
    """A = df/dy (N_STATE x N_STATE) of the regime in rg at (t, y) into vw.A, f = f(t, y)
    given; forward differences of vw.ctl[CTL_FD_REL] of vw.scale.  Returns a status."""
    A, y_fd, f_fd, scale = vw.A, vw.y_fd, vw.f_fd, vw.scale
    rel = vw.ctl[CTL_FD_REL]
    free = model.free
    for i in range(N):
        for j in range(N):
            A[i, j] = 0.0
    for i in range(ly.N_AUG):
        y_fd[i] = y[i]
    for k in range(2 * free.shape[0]):        # the free coordinates' positions, then rates
        j = free[k] if k < free.shape[0] else ly.N_DOF + free[k - free.shape[0]]
        d = rel * scale[j]
        y_fd[j] = y[j] + d
        status = rhs_regime(t, y_fd, model, ex, work, f_fd)
        y_fd[j] = y[j]
        if status != ly.OK:
            return status
        for i in range(ly.N_DOF, N):
            A[i, j] = (f_fd[i] - f[i]) / d
    for k in range(free.shape[0]):
        A[free[k], ly.N_DOF + free[k]] = 1.0
    return ly.OK


@nb.njit(**JIT_INLINE)
def _product(A, B, out):
    """out = A B (N_STATE square)."""
    for i in range(N):
        for k in range(N):
            acc = 0.0
            for j in range(N):
                acc += A[i, j] * B[j, k]
            out[i, k] = acc


@nb.njit(**JIT_INLINE)
def _combine(P, row, r, h, Phi, K, out):
    """out = Phi + h sum_{j<r} P[row + j] K_j."""
    for i in range(N):
        for k in range(N):
            out[i, k] = Phi[i, k]
    for j in range(r):
        a = P[row + j]
        if a != 0.0:
            for i in range(N):
                for k in range(N):
                    out[i, k] += h * a * K[j, i, k]


@nb.njit(**JIT_INLINE)
def _estimate(acc, acc3, second, h):
    """The error estimate of one component (DOP853's combination where it has two)."""
    if second:
        d = math.sqrt(acc * acc + 0.01 * acc3 * acc3)
        if d > 0.0:
            return h * acc * abs(acc) / d
    return h * acc


@nb.njit(**JIT)
def variational_step(t, y, Phi, h, model, ex, work, vw):
    """One step of h of (y, Phi) with the pair in P into vw.y_new and vw.phi_new.

    The first stage (k_1 in stages[0], K_1 in vw.K[0]) must be that of (t, y, Phi); the
    last (FSAL) is left in stages[s - 1] and vw.K[s - 1].  Returns (status, the error
    estimate's largest ratio to the scales: y_i over scale_i, Phi_ik over scale_i times
    the column's size vw.column[k])."""
    P, free = model.P, model.free
    stages, cg, cw, rg = work.stages, work.cg, work.cw, work.rg
    K, A, phi_stage, phi_new, y_new = vw.K, vw.A, vw.phi_stage, vw.phi_new, vw.y_new
    scale, column = vw.scale, vw.column
    s = int(P[ly.P_RK_STAGES])
    yt = stages[ly.STAGE_TMP]
    for r in range(1, s - 1):
        tr = stage_state(r, t, y, h, P, stages, yt)
        status = rhs_regime(tr, yt, model, ex, work, stages[r])
        if status != ly.OK:
            return status, np.inf
        status = state_jacobian(tr, yt, stages[r], model, ex, work, vw)
        if status != ly.OK:
            return status, np.inf
        _combine(P, ly.P_RK_A + ly.MAX_RK_STAGES * r, r, h, Phi, K, phi_stage)
        _product(A, phi_stage, K[r])
    for i in range(ly.N_AUG):
        acc = 0.0
        for j in range(s - 1):
            acc += P[ly.P_RK_B + j] * stages[j, i]
        y_new[i] = y[i] + h * acc
        if not math.isfinite(y_new[i]):
            return ly.ERR_NAN, np.inf
    _combine(P, ly.P_RK_B, s - 1, h, Phi, K, phi_new)
    project(y_new, P, free, cg, cw, rg, np.bool_(False))
    status = rhs_regime(t + h, y_new, model, ex, work, stages[s - 1])
    if status != ly.OK:
        return status, np.inf
    status = state_jacobian(t + h, y_new, stages[s - 1], model, ex, work, vw)
    if status != ly.OK:
        return status, np.inf
    _product(A, phi_new, K[s - 1])
    second = P[ly.P_RK_E3] != 0.0
    err = 0.0
    for i in range(N):
        acc = 0.0
        acc3 = 0.0
        for j in range(s):
            acc += P[ly.P_RK_E + j] * stages[j, i]
            acc3 += P[ly.P_RK_E3 + j] * stages[j, i]
        err = max(err, abs(_estimate(acc, acc3, second, h)) / scale[i])
    for i in range(N):
        for k in range(N):
            acc = 0.0
            acc3 = 0.0
            for j in range(s):
                acc += P[ly.P_RK_E + j] * K[j, i, k]
                acc3 += P[ly.P_RK_E3 + j] * K[j, i, k]
            err = max(err, abs(_estimate(acc, acc3, second, h)) / (scale[i] * column[k]))
    if not math.isfinite(err):
        return ly.ERR_NAN, np.inf
    return ly.OK, err


@nb.njit(**JIT)
def variational_span(t, t_end, tol, y, Phi, model, ex, work, vw):
    """(y, Phi) from t to t_end (either direction) in the regime of rg, in place.

    Steps of the pair in P controlled to ``tol`` (the error estimate's largest ratio to
    the scales, :func:`variational_step`), starting from vw.ctl[CTL_H] and leaving the
    last full step there; ERR_VAR_STEPS below VAR_H_MIN_S or past vw.ctl[CTL_MAX_STEPS].
    Returns a status."""
    P, stages, K, ctl = model.P, work.stages, vw.K, vw.ctl
    s = int(P[ly.P_RK_STAGES])
    if t_end == t:
        return ly.OK
    status = rhs_regime(t, y, model, ex, work, stages[0])
    if status != ly.OK:
        return status
    status = state_jacobian(t, y, stages[0], model, ex, work, vw)
    if status != ly.OK:
        return status
    _product(vw.A, Phi, K[0])
    sign = 1.0 if t_end > t else -1.0
    exponent = -1.0 / P[ly.P_RK_ORDER]
    h = min(max(ctl[CTL_H], VAR_H_MIN_S), VAR_H_MAX_S)
    while sign * (t_end - t) > 0.0:
        left = abs(t_end - t)
        short = left <= h
        h_try = left if short else h
        status, err = variational_step(t, y, Phi, sign * h_try, model, ex, work, vw)
        if status != ly.OK:
            return status
        ratio = err / tol
        if ratio <= 1.0:
            t = t_end if short else t + sign * h_try
            for i in range(ly.N_AUG):
                y[i] = vw.y_new[i]
                stages[0, i] = stages[s - 1, i]
            for i in range(N):
                for k in range(N):
                    Phi[i, k] = vw.phi_new[i, k]
                    K[0, i, k] = K[s - 1, i, k]
            ctl[CTL_STEPS] += 1.0
            if short:       # the last piece of the span: its length says nothing of h
                break
        else:
            ctl[CTL_REJECTED] += 1.0
        factor = 5.0 if ratio == 0.0 else min(5.0, max(0.2, 0.9 * ratio ** exponent))
        h = min(h_try * factor, VAR_H_MAX_S)
        if h < VAR_H_MIN_S or ctl[CTL_STEPS] + ctl[CTL_REJECTED] > ctl[CTL_MAX_STEPS]:
            return ly.ERR_VAR_STEPS
    ctl[CTL_H] = h
    return ly.OK


@nb.njit(**JIT)
def event_function(e, t, y, model, ex, work, f):
    """(status, h_e(t, y)): event function e of the regime in rg (f gets f(t, y))."""
    status = rhs_regime(t, y, model, ex, work, f)
    event_values(y, model.P, model.free, work.cg, work.rg, work.ev, ly.EV_TRY, ly.EV_RATE_TRY)
    return status, work.ev[ly.EV_TRY, e]


@nb.njit(**JIT)
def _difference(e, t, y, v, d, dt, model, ex, work, vw):
    """(status, (h_e(t + dt, y + d v) - h_e(t - dt, y - d v)) / 2)."""
    y_fd = vw.y_fd
    for i in range(N):
        y_fd[i] = y[i] + d * v[i]
    status, hi = event_function(e, t + dt, y_fd, model, ex, work, vw.f_fd)
    for i in range(N):
        y_fd[i] = y[i] - d * v[i]
    status2, lo = event_function(e, t - dt, y_fd, model, ex, work, vw.f_fd)
    for i in range(N):
        y_fd[i] = y[i]
    if status != ly.OK or status2 != ly.OK:
        return ly.ERR_NAN, 0.0
    return ly.OK, 0.5 * (hi - lo)


@nb.njit(**JIT)
def event_rate(e, t, y, f, model, ex, work, vw):
    """(status, h_e(t, y), dh_e/dt along f): the event function and its total rate
    along the flow f (central differences over EVENT_DT_FD_S)."""
    status, value = event_function(e, t, y, model, ex, work, vw.f_fd)
    status2, half = _difference(e, t, y, f, EVENT_DT_FD_S, EVENT_DT_FD_S, model, ex, work, vw)
    if status != ly.OK or status2 != ly.OK:
        return ly.ERR_NAN, value, 0.0
    return ly.OK, value, half / EVENT_DT_FD_S


@nb.njit(**JIT_INLINE)
def _copy(src, dst):
    for i in range(len(src)):
        dst[i] = src[i]


@nb.njit(**JIT)
def jump(e, t, y_minus, rg_minus, st_minus, model, ex, work, vw, y_plus):
    """G(y-): event e at t applied to y- in the regime rg_minus, the run's statistics
    st_minus (the impact law's accumulation rule reads them) into vw.st; y+ into y_plus,
    its regime into work.rg.  Returns a status."""
    _copy(rg_minus, work.rg)
    _copy(st_minus, vw.st)
    cur = work.stages[ly.STAGE_CUR]
    _copy(y_minus, cur)
    status = apply_event(e, t, model, ex, work, vw.log, np.int64(0), vw.st)
    _copy(cur, y_plus)
    return status


@nb.njit(**JIT)
def forced_jump(e, t, y_minus, rg_minus, st_minus, rg_plus, model, ex, work, vw, y_plus):
    """G(y-) with the outcome of rg_plus: event e's transition
    (:func:`workbench.core.hybrid.event_transition`), then the state projected onto the
    regime of rg_plus, whatever regime the enumeration would choose there (a perturbed
    state meets the same transition).  Returns a status."""
    P, free, cg, cw, rg = model.P, model.free, work.cg, work.cw, work.rg
    _copy(rg_minus, rg)
    _copy(st_minus, vw.st)
    cur = work.stages[ly.STAGE_CUR]
    _copy(y_minus, cur)
    status, kind, point, reg_from, gap_tol = event_transition(e, t, model, ex, work, vw.log,
                                                              np.int64(0), vw.st)
    if status != ly.OK:
        return status
    rg[ly.RG_SET] = rg_plus[ly.RG_SET]
    rg[ly.RG_STICK] = rg_plus[ly.RG_STICK]
    rg[ly.RG_SIGN] = rg_plus[ly.RG_SIGN]
    project(cur, P, free, cg, cw, rg, np.bool_(True))
    arm_gaps(cur, P, cg, rg)
    _copy(cur, y_plus)
    return ly.OK


@nb.njit(**JIT)
def _slip_sign(t, y, set_index, model, ex, work, f):
    """(status, sign): the slip direction (+1 or -1) of a contact set's tangent point at y,
    the sign of its tangential rate, or where that is below RATE_EPS (slip from rest) the
    consistent one: the direction in which its tangential acceleration points when it slips
    that way (the friction force against it), of the two the larger (at a stick -> slip
    event, against the sticking force, as the event applies it).  Leaves work.rg slipping
    in set_index; f is scratch."""
    P, cg, rg = model.P, work.cg, work.rg
    g = ly.CG_T + tangent_point(set_index)
    fill_geometry(y, P, cg)
    rate = row_rate(cg, g, y[ly.N_DOF:ly.N_STATE])
    rg[ly.RG_SET] = float(set_index)
    rg[ly.RG_STICK] = 0.0
    if abs(rate) > RATE_EPS:
        return ly.OK, (1.0 if rate > 0.0 else -1.0)
    best, best_sign = -np.inf, 1.0
    for sign in (1.0, -1.0):
        rg[ly.RG_SIGN] = sign
        status = rhs_regime(t, y, model, ex, work, f)
        if status != ly.OK:
            return status, sign
        at = row_rate(cg, g, f[ly.N_DOF:ly.N_STATE]) + row_convective(cg, g,
                                                                      y[ly.N_DOF:ly.N_STATE])
        if sign * at > best:
            best, best_sign = sign * at, sign
    return ly.OK, best_sign


@nb.njit(**JIT)
def _directional(e, t, y, v, d, model, ex, work, vw):
    """(status, dh_e/dy . v) by central differences of d along v."""
    status, half = _difference(e, t, y, v, d, 0.0, model, ex, work, vw)
    return status, half / d


@nb.njit(**JIT)
def saltation(e, t, y_minus, st_minus, target, model, ex, work, vw, Phi, ncol):
    """Phi[:, :ncol] <- S Phi[:, :ncol], S the saltation matrix (module docstring) of event e
    at (t, y-) in the regime of work.rg, the statistics st_minus, into the regime the
    enumeration chooses, or the regime ``target`` (>= 0) where it chooses another (counted
    in vw.ctl[CTL_FOLLOWED]).  Leaves y+ in vw.y_plus, its regime in work.rg and
    vw.rg_plus, the statistics after in vw.st_plus.  Returns a status.

    Each column v of Phi (a tangent vector of the old regime's constraints) goes to
    S v = G_y u + f+ (g . v) / h', u = v - f- (g . v) / h' (g = grad h, h' = dh/dt): G is
    differenced along the event surface, where a perturbed state meets it (at
    t - (g . v) / h' per unit), and on the constraints: off the surface the jump's outcome
    is not the event's (a state short of the friction limit still sticks), off the
    constraints not smooth (a released point's gap held at 0 only from below)."""
    rg, scale = work.rg, vw.scale
    y_fd, y_a, f_minus, f_plus, col = vw.y_fd, vw.y_new, vw.f_minus, vw.f_plus, vw.grad
    _copy(rg, vw.rg_minus)
    status = rhs_regime(t, y_minus, model, ex, work, f_minus)
    if status != ly.OK:
        return status
    status, value, rate = event_rate(e, t, y_minus, f_minus, model, ex, work, vw)
    if status != ly.OK:
        return status
    size = 0.0
    for i in range(N):
        size = max(size, abs(f_minus[i]) / scale[i])
    status, along = _directional(e, t, y_minus, f_minus, JUMP_FD_REL / size, model, ex, work,
                                 vw)
    if status != ly.OK:
        return status
    if not abs(rate) > 1e-9 * abs(along):
        return ly.ERR_EVENT_TANGENT
    status = jump(e, t, y_minus, vw.rg_minus, st_minus, model, ex, work, vw, vw.y_plus)
    if status != ly.OK:
        return status
    if target >= 0 and regime_in(rg) != target:
        # the enumeration is on a boundary here (a separating force at -LAMBDA_EPS): take
        # the record's regime, slipping the consistent way (_slip_sign)
        rg[ly.RG_SET] = float((target + 1) // 2)
        rg[ly.RG_STICK] = 1.0 if target % 2 == 1 else 0.0
        if target > 0 and target % 2 == 0:
            status, sign = _slip_sign(t, y_minus, int(rg[ly.RG_SET]), model, ex, work,
                                      f_plus)
            if status != ly.OK:
                return status
            rg[ly.RG_SIGN] = sign
        _copy(rg, vw.rg_plus)
        status = forced_jump(e, t, y_minus, vw.rg_minus, st_minus, vw.rg_plus, model, ex,
                             work, vw, vw.y_plus)
        if status != ly.OK:
            return status
        vw.ctl[CTL_FOLLOWED] += 1.0
    _copy(rg, vw.rg_plus)
    _copy(vw.st, vw.st_plus)
    status = rhs_regime(t, vw.y_plus, model, ex, work, f_plus)
    if status != ly.OK:
        return status
    # the forced jump is the jump where the enumeration chose (no impulse resolved an
    # inconsistent state on the way)
    status = forced_jump(e, t, y_minus, vw.rg_minus, st_minus, vw.rg_plus, model, ex, work,
                         vw, y_a)
    if status != ly.OK:
        return status
    for i in range(N):
        if abs(y_a[i] - vw.y_plus[i]) > JUMP_FD_REL * JUMP_FD_REL * scale[i]:
            return ly.ERR_JUMP_AMBIGUOUS
    for k in range(ncol):
        size = 0.0
        for i in range(N):
            col[i] = Phi[i, k]
            size = max(size, abs(col[i]) / scale[i])
        if size == 0.0:
            continue
        d = JUMP_FD_REL / size
        _copy(vw.rg_minus, rg)           # the event function is the old regime's
        status, slope = _directional(e, t, y_minus, col, d, model, ex, work, vw)
        if status != ly.OK:
            return status
        shift = -slope / rate            # the event's time shift per unit along v (s)
        for side in range(2):
            sd = d if side == 0 else -d
            for i in range(N):
                y_fd[i] = y_minus[i] + sd * (col[i] + shift * f_minus[i])
            status = forced_jump(e, t + sd * shift, y_fd, vw.rg_minus, st_minus, vw.rg_plus,
                                 model, ex, work, vw, y_a)
            if status != ly.OK:
                return status
            for i in range(N):
                if side == 0:
                    Phi[i, k] = y_a[i]
                else:
                    Phi[i, k] = (Phi[i, k] - y_a[i]) / (2.0 * d) - f_plus[i] * shift
    for i in range(N):
        y_fd[i] = y_minus[i]
    _copy(vw.rg_plus, rg)
    return ly.OK


@nb.njit(**JIT)
def regime_in(rg):
    """The regime number (0..16) of rg."""
    return regime_of(int(rg[ly.RG_SET]), rg[ly.RG_STICK] != 0.0)
