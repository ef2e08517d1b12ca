"""One simulation run: the ``simulate`` entry point.

    run = simulate(Parameters(gap_mm=1.016), excitation.sine(2.0, 20.0, ramp_s=1.0), 10.0)
    run.signals      # DataFrame indexed by time: q, q', sensors, contacts, energies
    run.events       # DataFrame: time, kind, from/to regime, point, impulses, energy lost
    run.transitions  # (from, to) regime transition counts
    run.summary()    # the dict printed by ``workbench run --json``

The method's kernel (:mod:`workbench.model.methods`) runs in chunks of
CHUNK_S, so memory stays bounded, progress can be shown, a ``stop``
condition is asked between chunks, and a failure keeps every sample and
event computed before it (``run.status``, ``run.message``).  Units are CGS
(docs/model.md); ``run.units`` names them per column.  The result is
:class:`workbench.model.run_result.Run`; the settings' checks are in
:mod:`~workbench.model.run_settings`, the default step in
:mod:`~workbench.model.step_policy`, the start in
:mod:`~workbench.model.initial_state`.
"""
from __future__ import annotations

import os
import time

import numpy as np

from . import packing as mdl
from ..core import excitation as cx, exponential, layout as ly
from . import accuracy, antialias, kernel_loading
from .drives import none
from .initial_state import initial_state
from .methods import DEFAULT_LEVEL_MAX, FLOOR_LOG_ROWS, METHODS
from .params import ParameterError, Parameters
from .run_result import Run, assemble, control_summary, fixed_step_summary, record_so_far
from .run_settings import check_method, check_settings
from .statics import static_equilibrium
from .step_policy import eigenvalues, stepped_dt
from .tableaus import write_tableau

#: Simulated seconds per kernel call, and the event log's rows per call.
CHUNK_S = 1.0
LOG_ROWS = 8192


def simulate(params: Parameters, excitation: np.ndarray | None = None, duration: float = 1.0, *,
             dt: float | None = None, output_hz: float | None = None, initial="static",
             free_decay_cm: float | None = None, fixed=(), progress: bool = False,
             t0: float = 0.0, regime: int = 0, method: str | None = None,
             tol: float | None = None, level_max: int = DEFAULT_LEVEL_MAX,
             check_accuracy: bool = False, stop=None) -> Run:
    """Simulate ``duration`` seconds of the loose-joint beam (docs/model.md §3-9).

    ``excitation`` is an array from :mod:`workbench.model.drives` (default: none).
    ``t0`` (s) is the start time: the run covers [t0, t0 + duration] and the
    excitation is evaluated at those times (e.g. to continue from a state
    of an earlier run, given as ``initial`` with its ``regime``).
    ``method`` (:mod:`workbench.model.methods`): "dop853" (the default) or "dopri5"
    chooses the steps by an error estimate against the relative tolerance
    ``tol`` (default DEFAULT_TOL), from dt down to dt / 2^level_max; "rk4" takes
    fixed RK4 steps of dt, and is the default when ``dt`` is given without
    ``tol``.  ``dt`` (s) is the fixed step, or the controlled method's
    largest (and its output lattice); by default :func:`default_dt`.
    ``output_hz`` is the sample rate of the signals; 1 / (output_hz dt)
    must be a whole number.  By default limits.DEFAULT_OUTPUT_HZ, or for a hammer
    PULSE_SAMPLES samples a pulse (the next rate dividing 1 / dt).  ``fixed`` holds coordinates (tests, locked
    joint).  ``check_accuracy`` runs a companion at finer settings (a tenth of
    the tolerance and half the coarsest step, or a quarter of a fixed step) and adds the run's error measured
    against it to ``run.control`` (:mod:`workbench.model.accuracy`).  ``stop``: a
    callable given the record so far (a :class:`Run` of the samples whose filtered
    channels are final, so its values are those of the whole run's first part) after
    each simulated second; when it returns a reason (a string), the run ends there with
    status ``STOPPED`` and that reason as its message (the leveling search stops a run
    once a limit is exceeded).  Never raises on a failure of the integration: the run
    stops with a status code and keeps what it computed.
    """
    if not isinstance(params, Parameters):
        raise ParameterError(f"params must be workbench.model.params.Parameters, got {type(params).__name__}")
    ex = none() if excitation is None else np.asarray(excitation, dtype=float)
    if ex.shape != (cx.N_EXC,):
        raise ParameterError("excitation must come from workbench.model.drives (an array of "
                             f"{cx.N_EXC} values)")
    method, tol = check_method(method, tol, dt_given=dt is not None)
    kernel = METHODS[method].kernel
    kernel_loading.prepare_kernels(kernel)              # before the step's eigenvalues
    dt, decim, n_steps = check_settings(params, ex, duration, dt, output_hz, t0, strict=False)
    if free_decay_cm is not None and int(ex[cx.X_KIND]) != cx.EXC_NONE:
        raise ParameterError("free_decay_cm releases the structure without excitation; "
                             "leave excitation unset")
    model = mdl.build(params, fixed)
    model.P[ly.P_STEPPED_DT] = stepped_dt(params)
    write_tableau(model.P, METHODS[method].tableau)
    work = mdl.make_work()
    try:
        static = static_equilibrium(params, 0.0, fixed)     # the tip's reference position
    except ParameterError:
        static = None
    y, (set0, stick0), label = initial_state(params, initial, fixed, free_decay_cm, static, regime)
    work.rg[ly.RG_SET] = set0
    work.rg[ly.RG_STICK] = 1.0 if stick0 else 0.0
    work.rg[ly.RG_SIGN] = 1.0
    # the kernels sample every k base steps; the record keeps every m-th, its analog
    # channels low-pass filtered first (antialias)
    k = antialias.internal_decimation(decim, dt, np.abs(eigenvalues(params)).max() / (2 * np.pi))
    record = _Record(params, ex, dt, duration, t0, label,
                     float("nan") if static is None else static.tip_y, decim // k, k)
    controller, settings = _controller(METHODS[method].controlled, tol, level_max)
    compile_s = _load(kernel, (y, float(t0), (dt, 1, 0, int(k)), *settings, model, ex, work,
                               (np.empty(1), np.empty((1, ly.N_STATE)), np.empty((1, ly.N_SIG))),
                               np.empty((1, ly.N_LOG)), record.st, *controller))
    run = record.integrate(kernel, y, (model, ex, work), settings, controller, n_steps,
                           progress, stop)
    run.compile_s = compile_s
    run.method, run.tol = method, tol
    run.control = (control_summary(controller[0][0], controller[0][2], tol, dt, duration)
                   if controller else fixed_step_summary(dt, int(record.st[ly.ST_STEP])))
    if controller:
        opkey = controller[0][4]
        run.control.update(etd_operators=int(opkey[exponential.KEY_COUNT, 0]),
                           etd_steps=int(opkey[exponential.KEY_COUNT, 1]),
                           etd_fallbacks=int(opkey[exponential.KEY_FALL, 0]),
                           etd_fall_err=int(opkey[exponential.KEY_FALL, 1]),
                           etd_err_max=float(opkey[exponential.KEY_MODE, 1]),
                           etd_err_hist={i / 4: int(v) for i, v in
                                         enumerate(opkey[exponential.KEY_ARG:, 1]) if v},
                           etd_fall_arg={i: int(v) for i, v in
                                         enumerate(opkey[exponential.KEY_ARG:, 0]) if v})
    if check_accuracy and run.ok:
        finer = accuracy.companion_settings(METHODS[method].controlled, tol, dt)
        companion = simulate(params, excitation, duration, output_hz=1.0 / (decim * dt),
                             initial=initial, free_decay_cm=free_decay_cm, fixed=fixed, t0=t0,
                             regime=regime, method=method, level_max=level_max,
                             **{"dt": dt, "tol": tol, **finer})
        run.control.update(accuracy.measured(run, companion, finer))
    return run


def _controller(controlled: bool, tol, level_max) -> tuple[tuple, tuple]:
    """The controlled kernel's state ((ctl, scale, floor_log),) and its settings
    ((tol, level_max),); empty for a fixed step."""
    if not controlled:
        return (), ()
    ctl = np.zeros(ly.N_CTL)
    ctl[ly.CTL_H_MIN] = np.inf
    expo = exponential.new_arrays(os.environ.get("WORKBENCH_ETD", "0") == "1",
                                  float(os.environ.get("WORKBENCH_ETD_AGE", "0.01")))
    expo[1][exponential.KEY_MODE, 0] = float(os.environ.get("WORKBENCH_ETD_SAMPLES", "1"))
    expo[1][exponential.KEY_MODE, 2] = float(os.environ.get("WORKBENCH_ETD_TOLX", "1"))
    return ((ctl, np.zeros((ly.N_SCALE_ROWS, ly.N_STATE)), np.zeros((FLOOR_LOG_ROWS, ly.N_FLOOR)),
             *expo),), \
        ((tol, int(level_max)),)


def _load(kernel, args) -> float:
    """Compile or load the kernel for these arguments; the seconds, with those of the run's
    other kernels compiled on their first use (kernel_loading)."""
    clock = kernel_loading.first_use
    first_use = clock[0].take() if clock else 0.0       # the kernels before the loop's
    seconds = kernel_loading.compile_kernel(kernel, args)
    if clock:
        clock[0].take()                                 # in compile_kernel's seconds
    return (seconds + first_use
            + kernel_loading.compile_unreported.pop(kernel_loading.kernel_name(kernel), 0.0))


class _Record:
    """A run's record as its chunks come: samples, filtered channels, events, statistics."""

    def __init__(self, params, ex, dt, duration, t0, label, static_tip, m, k):
        self.head = (params, ex, dt, duration)
        self.tail = (static_tip, label, t0)
        self.m, self.k = m, k
        self.decimator = antialias.Decimator(m, 1.0 / (k * dt))
        self.t, self.y, self.s, self.analog, self.log = [], [], [], [], []
        self.n_internal = 0     # internal samples so far: output sample j is internal sample j m
        self.st = np.zeros(ly.N_ST)

    def push(self, out_t, out_y, out_sig, stored, log, n_log):
        keep = slice((-self.n_internal) % self.m, stored, self.m)
        self.t.append(out_t[keep])
        self.y.append(out_y[keep])
        self.s.append(out_sig[keep])
        self.analog.append(self.decimator.push(out_sig[:stored]))
        self.n_internal += stored
        self.log.append(log[:n_log].copy())

    def so_far(self) -> Run:
        return record_so_far(*self.head, self.t, self.y, self.s, self.analog, self.log, self.st,
                             *self.tail)

    def integrate(self, kernel, y, arrays, settings, controller, n_steps, progress, stop) -> Run:
        """Run the kernel in chunks of CHUNK_S over n_steps base steps from y (module
        docstring); the Run of the record."""
        params, ex, dt, duration = self.head
        model, ex, work = arrays
        chunk = max(self.m * self.k, (round(CHUNK_S / dt) // (self.m * self.k)) * self.m * self.k)
        bar = None
        if progress:
            from tqdm import tqdm
            bar = tqdm(total=n_steps, unit="step", desc="simulate", leave=False)
        t_wall, done, status, reason = time.perf_counter(), 0, ly.OK, ""
        while done < n_steps:
            n = min(chunk, n_steps - done)
            n_out = (done + n) // self.k - done // self.k + (1 if done == 0 else 0)
            out = (np.empty(n_out), np.empty((n_out, ly.N_STATE)), np.empty((n_out, ly.N_SIG)))
            log = np.empty((LOG_ROWS, ly.N_LOG))
            span = (dt, int(n), int(done), int(self.k))
            status, stored, n_log = kernel(y, self.tail[2] + done * dt, span, *settings, model,
                                           ex, work, out, log, self.st, *controller)
            self.push(*out, stored, log, n_log)
            new_done = done + n if status == ly.OK else (
                int(self.st[ly.ST_STEP]) if status == ly.LOG_FULL else done)
            if bar is not None:
                bar.update(new_done - done)
            y = work.stages[ly.STAGE_CUR].copy()
            if status not in (ly.OK, ly.LOG_FULL):
                break
            if status == ly.LOG_FULL and new_done == done:
                status = ly.ERR_EVENT_FLOOD
                break
            done, status = new_done, ly.OK
            if stop is not None and done < n_steps:
                reason = stop(self.so_far())
                if reason:
                    status = ly.STOPPED
                    break
        if bar is not None:
            bar.close()
        self.analog.append(self.decimator.finish())
        s = np.concatenate(self.s)
        s[:, antialias.ANALOG_COLUMNS] = np.concatenate(self.analog)
        run = assemble(params, ex, dt, duration, status, time.perf_counter() - t_wall, self.t,
                       self.y, [s], self.log, self.st, *self.tail)
        if status == ly.STOPPED:
            run.message = f"{ly.MESSAGES[status]}: {reason}"
        run.anti_alias = antialias.summary(self.m, 1.0 / (self.k * dt))
        return run
