"""The Jacobian of the period map by the variational equations and saltation matrices.

Along a run of the period map (a record of :func:`workbench.model.simulate.simulate`, with its
event log), :func:`variational_monodromy` integrates the state again with the variational
equations of each regime between events (:func:`workbench.core.variational.variational_span`)
and multiplies in the saltation matrix of each event of the log
(:func:`workbench.core.variational.saltation`): impacts by Moreau's law, separations,
stick -> slip and slip -> stick, each with the jump the integrator applies.  Each event is
found again on this integration, its time corrected by Newton's method on its event
function (to EVENT_TIME_TOL) from the logged time; the regime after it is the one the
record's run chose (where the enumeration at this run's state, which differs from the
record's by the tolerances, chooses another, as it may at a separating force of
-LAMBDA_EPS: ``followed``).

The variational equations carry the images of given tangent vectors of the start's regime
(the orbit's reduced coordinates, :mod:`workbench.model.orbit`): M B, M = d y(t0 + T) /
d y(t0), each column staying on the constraints of the regime it is in.  Runs with
Moreau-Jean steps (an event flood) have no saltation matrices: MonodromyError.
"""
from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from ..core import layout as ly
from ..core import variational as vr
from ..core.config import EVENT_TIME_TOL, VAR_FD_REL
from ..core.constrained import rhs_regime
from ..core.hybrid import begin
from . import kernel_loading
from . import packing as mdl
from .methods import METHODS
from .regimes import is_stick, set_of
from .step_policy import stepped_dt
from .tableaus import write_tableau

#: Newton corrections of an event's time on the variational run, at most.
EVENT_NEWTON = 4
#: The method the variational equations are integrated with.
METHOD = "dop853"
#: Steps (accepted and rejected) the variational equations may take, per step of the
#: record's run (measured: 1.1 at 20 Hz, 1.4 at 45 Hz), and beyond that at least.
STEPS_PER_RUN_STEP = 10
MIN_STEPS = 2000


#: Scratch of the variational kernels (:mod:`workbench.core.variational`): stage matrices K,
#: the state Jacobian A, Phi's stage and next values, state buffers, the jump's regime records
#: and statistics, a log row, the error scales, each column's size, and ctl (CTL_*).
VarWork = namedtuple("VarWork", "K A phi_stage phi_new y_new y_fd f_fd f_minus f_plus y_plus "
                                "grad rg_minus rg_plus st st_plus log scale column ctl")


def make_var_work() -> VarWork:
    """Fresh scratch for one thread of variational kernel calls."""
    n = ly.N_STATE
    ctl = np.zeros(vr.N_CTL)
    ctl[vr.CTL_FD_REL], ctl[vr.CTL_MAX_STEPS] = VAR_FD_REL, np.inf
    return VarWork(K=np.zeros((ly.MAX_RK_STAGES, n, n)), A=np.zeros((n, n)),
                   phi_stage=np.zeros((n, n)), phi_new=np.zeros((n, n)),
                   y_new=np.zeros(ly.N_AUG), y_fd=np.zeros(ly.N_AUG), f_fd=np.zeros(ly.N_AUG),
                   f_minus=np.zeros(ly.N_AUG), f_plus=np.zeros(ly.N_AUG),
                   y_plus=np.zeros(ly.N_AUG), grad=np.zeros(n),
                   rg_minus=np.zeros(ly.N_RG), rg_plus=np.zeros(ly.N_RG), st=np.zeros(ly.N_ST),
                   st_plus=np.zeros(ly.N_ST), log=np.zeros((2, ly.N_LOG)), scale=np.ones(n),
                   column=np.ones(n), ctl=ctl)


class MonodromyError(RuntimeError):
    """The variational run could not follow the record (the message says where)."""


@dataclass
class Monodromy:
    """M B, M = dy(t0 + T)/dy(t0), B the tangent vectors it was asked for, and what its
    integration took."""

    matrix: np.ndarray       # N_STATE x n
    end: np.ndarray          # the variational run's state at t0 + T (N_STATE)
    steps: int
    rejected: int
    events: int
    kinds: dict              # events by kind through which saltation matrices were taken
    followed: int            # events whose regime after was taken from the record


def event_index(kind: int, point: int) -> int:
    """The event function (layout EV_*) of a log row's kind and point (1..4)."""
    if kind == ly.KIND_IMPACT:
        return ly.EV_GAP + point - 1
    if kind == ly.KIND_SEPARATION:
        return ly.EV_LAMBDA + point - 1
    if kind == ly.KIND_STICK_SLIP:
        return ly.EV_STICK
    if kind == ly.KIND_SLIP_STICK:
        return ly.EV_SLIP
    raise ValueError(f"no event function for log kind {kind}")


def _check(status: int, where: str) -> None:
    if status != ly.OK:
        raise MonodromyError(f"{where}: {ly.MESSAGES.get(status, status)}")


def variational_monodromy(params, ex: np.ndarray, x: np.ndarray, regime: int, t0: float,
                          period_s: float, log: np.ndarray, basis: np.ndarray,
                          scale: np.ndarray, tol: float, h0: float, fixed=(),
                          fd_rel: float = VAR_FD_REL, run_steps: int = 0) -> Monodromy:
    """M B over [t0, t0 + period_s] from (x, regime) along the record whose event log is
    ``log`` (rows LOG_*), B = ``basis`` (N_STATE x n) tangent vectors of the regime's
    constraints at x; ``scale`` the error scales (N_STATE), ``tol`` the variational run's
    tolerance on them, ``h0`` (s) its first step, ``fd_rel`` the state Jacobian's
    difference step on the scales; ``run_steps`` the record's steps (the variational
    equations may take STEPS_PER_RUN_STEP times as many, MIN_STEPS at least: far below
    the run's steps the Jacobian's noise, not the solution, sets them)."""
    kernel_loading.prepare_kernels(METHODS[METHOD].kernel)
    model = mdl.build(params, fixed)
    model.P[ly.P_STEPPED_DT] = stepped_dt(params)
    write_tableau(model.P, METHODS[METHOD].tableau)
    work, vw = mdl.make_work(), make_var_work()
    vw.scale[:] = scale
    vw.ctl[vr.CTL_H] = h0
    vw.ctl[vr.CTL_FD_REL] = fd_rel
    vw.ctl[vr.CTL_MAX_STEPS] = max(STEPS_PER_RUN_STEP * run_steps, MIN_STEPS)
    st = np.zeros(ly.N_ST)
    work.rg[ly.RG_SET] = set_of(regime)
    work.rg[ly.RG_STICK] = 1.0 if is_stick(regime) else 0.0
    work.rg[ly.RG_SIGN] = 1.0
    work.stages[ly.STAGE_CUR, :ly.N_STATE] = x[:ly.N_STATE]
    status, _, _ = begin(float(t0), np.int64(0), model, ex, work, np.empty(1),
                         np.empty((1, ly.N_STATE)), np.empty((1, ly.N_SIG)),
                         np.empty((1, ly.N_LOG)), st)
    _check(status, "the start")
    y = work.stages[ly.STAGE_CUR].copy()
    ncol = basis.shape[1]
    phi = np.zeros((ly.N_STATE, ly.N_STATE))
    phi[:, :ncol] = basis
    start_size = np.maximum(np.abs(basis / scale[:, None]).max(axis=0), 1e-300)
    vw.column[:ncol] = start_size
    t, kinds = float(t0), {}
    rows = [r for r in log if int(r[ly.LOG_KIND]) != ly.KIND_START]
    for n, row in enumerate(rows):
        kind, point = int(row[ly.LOG_KIND]), int(row[ly.LOG_POINT])
        e = event_index(kind, point)
        where = (f"event {n + 1} ({ly.EVENT_KINDS[kind]}, point {point}) at "
                 f"t = {row[ly.LOG_T]:.9f} s")
        _check(vr.variational_span(t, float(row[ly.LOG_T]), tol, y, phi, model, ex, work, vw),
               where)
        t = float(row[ly.LOG_T])
        for _ in range(EVENT_NEWTON):       # the event's time on this run
            _check(rhs_regime(t, y, model, ex, work, vw.f_minus), where)
            status, value, rate = vr.event_rate(e, t, y, vw.f_minus, model, ex, work, vw)
            _check(status, where)
            dt = -value / rate if rate != 0.0 else 0.0
            if abs(dt) <= EVENT_TIME_TOL:
                break
            _check(vr.variational_span(t, t + dt, tol, y, phi, model, ex, work, vw), where)
            t += dt
        _check(vr.saltation(e, t, y, st, np.int64(row[ly.LOG_TO]), model, ex, work, vw, phi,
                            np.int64(ncol)), where)
        y[:] = vw.y_plus
        st[:] = vw.st_plus
        # a column's error is measured against its size since the last event, at least its
        # start's (a column rocking impacts have grown 6.5e4-fold, at 45 Hz, 200 N, is
        # otherwise held to a tolerance 6.5e4 times tighter: 19 250 steps for one span)
        vw.column[:ncol] = np.maximum(start_size,
                                      np.abs(phi[:, :ncol] / scale[:, None]).max(axis=0))
        kinds[ly.EVENT_KINDS[kind]] = kinds.get(ly.EVENT_KINDS[kind], 0) + 1
    _check(vr.variational_span(t, t0 + period_s, tol, y, phi, model, ex, work, vw),
           "the last span")
    return Monodromy(phi[:, :ncol].copy(), y[:ly.N_STATE].copy(), int(vw.ctl[vr.CTL_STEPS]),
                     int(vw.ctl[vr.CTL_REJECTED]), len(rows), kinds,
                     int(vw.ctl[vr.CTL_FOLLOWED]))
