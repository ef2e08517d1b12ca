"""One simulation run: the ``simulate`` entry point and the :class:`Run` it returns.

    run = simulate(Parameters(gap_mm=1.016), excitation.sine(2.0, 20.0, ramp_s=1.0), 10.0)
    run.signals      # DataFrame indexed by time: q, q', sensors, contacts, energies
    run.events       # DataFrame: time, kind, from/to regime, point, impulses, energy lost
    run.transitions  # (from, to) regime transition counts
    run.summary()    # the dict printed by ``workbench run --json``

The kernel (:func:`workbench.core.hybrid.run_hybrid`) runs in chunks, so
memory stays bounded, progress can be shown, and a failure keeps every
sample and event computed before it (``run.status``, ``run.message``).
Units are CGS (docs/model.md); ``run.units`` names them per column.
"""
from __future__ import annotations

import functools
import math
import sys
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numba.core import event as numba_event

from . import packing as mdl
from ..core import excitation as cx, layout as ly
from . import accuracy, antialias, drives
from .drives import none
from .tableaus import write_tableau
from .methods import DEFAULT_LEVEL_MAX, DEFAULT_METHOD, FLOOR_LOG_ROWS, METHODS
from .limits import DEFAULT_TOL, MAX_DT, MAX_DURATION_S, MIN_DT, STABILITY_MARGIN, TOL_RANGE
from .params import ParameterError, Parameters, check_positive
from .regimes import contact_code, contact_shares_of, in_contact, is_stick, set_of
from .statics import static_equilibrium, tip_load_for_deflection

if TYPE_CHECKING:
    import pandas as pd

#: Steps :func:`default_dt` chooses from (s): 1 ms / n for n = 10 ... 200, so that each
#: divides 1 ms (every output rate that divides 1 kHz, and every whole number of ms).
NICE_STEPS = tuple(1e-3 / n for n in range(10, 201))
#: The largest default step (s): on the benchmark windows at 1e-4 s the tip
#: height is within 2.6e-5 of its range and the contact time shares within
#: 5e-6 of a converged run (docs/performance.md).
MAX_DEFAULT_DT = 1e-4


def rk4_amplification(z: np.ndarray) -> np.ndarray:
    """|R(z)| of classical RK4, R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24 (z = lambda dt)."""
    z = np.asarray(z, dtype=complex)
    return np.abs(1.0 + z * (1.0 + z / 2.0 * (1.0 + z / 3.0 * (1.0 + z / 4.0))))


def default_dt(p: Parameters, excitation: np.ndarray | None = None) -> float:
    """The largest step of NICE_STEPS (at most MAX_DEFAULT_DT) at which RK4 is stable.

    Stable: |R(STABILITY_MARGIN lambda dt)| <= 1 for every eigenvalue lambda
    of :func:`workbench.model.modes.linear_eigenvalues`.  With the tip mass this
    is 1e-4 s (MAX_DEFAULT_DT; the fastest mode is -246 +- 2.05e4 j 1/s); without
    it 6.25e-5 s (1 ms / 16; -321 +- 3.54e4 j 1/s): the beams' lightly damped axial
    modes, near the imaginary axis where RK4 is stable to |lambda dt| = 2.83.  The
    drive may bound it (a hammer pulse gets at least PULSE_STEPS steps).
    """
    lam = STABILITY_MARGIN * _eigenvalues(p)
    limit = MAX_DEFAULT_DT
    if excitation is not None:
        limit = min(limit, drives.of_array(excitation).dt_max(excitation))
    for dt in NICE_STEPS:
        if dt <= limit * (1.0 + 1e-12) and np.all(rk4_amplification(lam * dt) <= 1.0):
            return dt
    return NICE_STEPS[-1]


def _eigenvalues(p: Parameters) -> np.ndarray:
    from .modes import linear_eigenvalues  # scipy.linalg: imported when first needed
    return linear_eigenvalues(p)


def stability_limit(p: Parameters) -> float:
    """The largest step (s) at which RK4 is stable for the linear model's eigenvalues.

    No margin (:func:`default_dt` keeps STABILITY_MARGIN below it): a step
    above this grows the fastest mode without bound.
    """
    lam = _eigenvalues(p)
    lo, hi = 0.0, 3.0 / float(np.abs(lam).max())
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if np.all(rk4_amplification(lam * mid) <= 1.0):
            lo = mid
        else:
            hi = mid
    return lo


def stepped_dt(p: Parameters) -> float:
    """The largest Moreau-Jean step (s) of the event-flood fallback (docs/model.md §7).

    The Moreau-Jean scheme (theta = 1/2) is explicit in the smooth forces,
    like leapfrog: stable for omega h < 2.  With STABILITY_MARGIN on the
    fastest linear mode: 7.8e-5 s with the tip mass (omega = 2.05e4 1/s),
    4.5e-5 s without (3.54e4 1/s), below RK4's default steps (1e-4, 6.25e-5 s).
    """
    return 2.0 / (STABILITY_MARGIN * float(np.abs(_eigenvalues(p)).max()))


def check_settings(params: Parameters, ex: np.ndarray, duration: float, dt: float | None,
                   output_hz: float | None, t0: float = 0.0, names: dict | None = None,
                   strict: bool = True) -> tuple[float, int, int]:
    """Check a run's settings against what its step can resolve; return (dt, decim, n_steps).

    The step (given or :func:`default_dt`) must resolve the drive (its
    :class:`~workbench.model.drives.Drive`'s check: STEPS_PER_PERIOD steps per
    period of a sine or a chirp's highest frequency, MIN_PULSE_STEPS per hammer
    pulse) and divide the output interval and the duration.  ``strict`` (the
    command line and studies) adds: the step RK4-stable for the model
    (:func:`stability_limit`), a hammer hit and a soft-start ramp ending within
    the run.  The Python API (:func:`simulate`) is not strict: a short look at a
    run's start, or a deliberately unstable step in a test, stays possible.
    ``names`` maps the setting names (duration, dt, output_hz, and the drive's
    settings) to the names the user wrote (an option, a study key), for the
    messages.
    Raises ParameterError.
    """
    names = names or {}

    def name(key):
        return names.get(key, key)

    duration = check_positive(name("duration"), duration, "s")
    if duration > MAX_DURATION_S:
        raise ParameterError(f"{name('duration')} = {duration:g} s is outside the allowed range "
                             f"(0, {MAX_DURATION_S:g}] s")
    t0 = check_positive("t0", t0, "s", allow_zero=True)
    given = dt is not None
    if given:
        dt = check_positive(name("dt"), dt, "s")
        if not MIN_DT <= dt <= MAX_DT:
            raise ParameterError(f"{name('dt')} = {dt:g} s is outside the allowed range "
                                 f"[{MIN_DT:g}, {MAX_DT:g}] s")
        if strict:
            limit = stability_limit(params)
            if dt > limit:
                raise ParameterError(
                    f"{name('dt')} = {dt:g} s is above this model's RK4 stability limit "
                    f"{limit:.3g} s (its fastest linear mode); give at most that, or leave it out "
                    f"for the default {default_dt(params, ex):g} s")
    else:
        dt = default_dt(params, ex)
    drive = drives.of_array(ex)
    if output_hz is None:           # the drive's rate at least, dividing 1/dt
        output_hz = 1.0 / (dt * max(1, math.floor(1.0 / (dt * drive.output_hz(ex)) + 1e-9)))
    output_hz = check_positive(name("output_hz"), output_hz, "Hz")
    decim = round(1.0 / (output_hz * dt)) if output_hz * dt > 1e-12 else 0
    if decim < 1 or abs(decim * dt * output_hz - 1.0) > 1e-9:
        raise ParameterError(f"{name('output_hz')} = {output_hz:g} Hz must divide 1/dt = "
                             f"{1 / dt:g} Hz into whole steps (dt = {dt:g} s)")
    n_steps = round(duration / dt)
    if abs(n_steps * dt - duration) > 1e-9 * duration:
        raise ParameterError(f"{name('duration')} = {duration:g} s is not a whole number of "
                             f"steps dt = {dt:g} s")
    drive.check(ex, drives.Step(dt, t0 + duration, strict, name, 1.0 / (decim * dt)))
    return dt, decim, n_steps


#: The smallest energy scale (erg) of :meth:`Run.energy_balance_rel`.
ENERGY_SCALE_FLOOR_ERG = 1.0

#: Run statistics of the contact logic reported by :meth:`Run.summary` (docs/model.md §7).
CONTACT_STAT_KEYS = ("accumulations", "accumulation_energy_lost_erg", "inconsistent_resolved",
                     "inconsistent_energy_lost_erg", "least_violated", "stepped_steps",
                     "stepped_energy_lost_erg", "s_min_cm", "s_max_cm")

_CHUNK_S = 1.0
_LOG_ROWS = 8192
#: Intervals accepted at the finest level listed in :meth:`Run.summary` (all are in ``control``).
SUMMARY_FLOOR_ROWS = 20

Q_COLUMNS = list(ly.COORD_NAMES)
QD_COLUMNS = [f"{n}_dot" for n in ly.COORD_NAMES]
ENERGY_COLUMNS = ["e_kin", "e_elastic", "e_gravity", "e_cork", "w_excitation", "d_structural",
                  "d_cork", "d_friction", "d_impact", "w_constraint"]


def energy_account(columns) -> tuple:
    """The total mechanical energy E and the balance residual (erg) of the energy columns.

    ``columns`` maps the names of ENERGY_COLUMNS to NumPy arrays:
    residual = E - E(0) - W_excitation + D_structural + D_cork + D_friction + D_impact.
    """
    c = columns
    total = c["e_kin"] + c["e_elastic"] + c["e_gravity"] + c["e_cork"]
    residual = (total - total[0] - c["w_excitation"] + c["d_structural"] + c["d_cork"]
                + c["d_friction"] + c["d_impact"])
    return total, residual


@dataclass
class Run:
    """The result of :func:`simulate`.

    The samples and the event log are kept as the kernel wrote them
    (``t``, ``states``, ``sensors``, ``log``); :attr:`signals` and
    :attr:`events` are DataFrames of them, built on first use (pandas is
    not imported until then, so a run whose summary is all that is wanted
    does not pay for it).
    """

    params: Parameters
    excitation: np.ndarray
    dt: float
    duration: float
    status: int
    message: str
    wall_s: float
    t: np.ndarray               # sample times (s), (n,)
    states: np.ndarray          # (q, q') at the samples, (n, 18), CGS
    sensors: np.ndarray         # the kernel's signals (layout SIGNALS), (n, N_SIG)
    log: np.ndarray             # the event log (layout LOG_*), (n_events, N_LOG)
    stats: dict
    static_tip_y: float
    initial: str
    units: dict = field(default_factory=dict)
    t0: float = 0.0
    compile_s: float = 0.0      # compiling or loading the kernel (not in wall_s)
    method: str = "rk4"
    tol: float | None = None    # the controlled method's relative tolerance
    control: dict = field(default_factory=dict)   # steps, rejections, error estimate (summary())
    anti_alias: dict = field(default_factory=dict)  # the analog channels' filter (antialias.summary)

    @property
    def ok(self) -> bool:
        return self.status == ly.OK

    @property
    def stopped(self) -> bool:
        """Ended early by the ``stop`` condition given to :func:`simulate`."""
        return self.status == ly.STOPPED

    @property
    def t_end(self) -> float:
        """The time reached (s): t0 + duration unless the run stopped early."""
        return float(self.stats["t_reached"])

    @property
    def simulated_s(self) -> float:
        """Simulated seconds: the time reached minus the start time t0."""
        return self.t_end - self.t0

    @functools.cached_property
    def signals(self) -> pd.DataFrame:
        """DataFrame indexed by time t (s): q, q', the signals of SIGNALS, contact flags."""
        import pandas as pd
        df = pd.DataFrame(self.states, columns=Q_COLUMNS + QD_COLUMNS)
        for j, name in enumerate(ly.SIGNALS):
            df[name] = self.sensors[:, j]
        df["regime"] = df["regime"].astype(np.int16)
        regimes = df["regime"].to_numpy()
        for k in range(ly.N_POINTS):
            df[f"contact{k + 1}"] = in_contact(k, regimes)
        df["contact_code"] = contact_code(regimes).astype(np.int16)
        df.index = pd.Index(self.t, name="t")
        return df

    @functools.cached_property
    def events(self) -> pd.DataFrame:
        """DataFrame of the event log: time, kind, from/to regime, point, impulses, energy lost."""
        import pandas as pd
        logs = self.log
        return pd.DataFrame({
            "t": logs[:, ly.LOG_T],
            "kind": pd.Categorical([ly.EVENT_KINDS[int(k)] for k in logs[:, ly.LOG_KIND]],
                                   categories=ly.EVENT_KINDS),
            "from_regime": logs[:, ly.LOG_FROM].astype(np.int16),
            "to_regime": logs[:, ly.LOG_TO].astype(np.int16),
            "point": logs[:, ly.LOG_POINT].astype(np.int8),
            **{f"impulse_n{k + 1}": logs[:, ly.LOG_P + k] for k in range(ly.N_POINTS)},
            "impulse_t": logs[:, ly.LOG_PT],
            "ke_lost": logs[:, ly.LOG_DKE],
        })

    @property
    def transitions(self) -> pd.DataFrame:
        """Counts of (from_regime, to_regime) over the events, starting event excluded."""
        ev = self.events[self.events.kind != "start"]
        return (ev.groupby(["from_regime", "to_regime"]).size().rename("count").reset_index())

    @property
    def energy(self) -> pd.DataFrame:
        """The energy account (erg) with the total E and the balance residual (:func:`energy_account`)."""
        e = self.signals[ENERGY_COLUMNS].copy()
        e["total"], e["residual"] = energy_account(
            {name: e[name].to_numpy() for name in ENERGY_COLUMNS})
        return e

    def signal(self, name: str) -> np.ndarray:
        """The samples of one signal of SIGNALS (its unit there), without building ``signals``."""
        return self.sensors[:, ly.SIGNALS.index(name)]

    def energy_balance_rel(self) -> float:
        """Largest |residual| over the run's energy scale (docs/model.md §9).

        The scale is the throughput |W_excitation| + dissipations at the end,
        plus the largest kinetic energy and the largest change of the
        mechanical energy E from E(0) (so that a free decay, whose throughput
        starts at zero, reads sensibly from its first sample), floored at
        ENERGY_SCALE_FLOOR_ERG: a run that stays at rest divides its
        round-off residual by 1 erg, not by a near-zero throughput.
        """
        c = {name: self.signal(name) for name in ENERGY_COLUMNS}
        total, residual = energy_account(c)
        last = {name: float(x[-1]) for name, x in c.items()}
        scale = (abs(last["w_excitation"]) + last["d_structural"] + last["d_cork"]
                 + last["d_friction"] + last["d_impact"] + float(c["e_kin"].max())
                 + float(np.abs(total - total[0]).max()))
        return float(np.abs(residual).max() / max(scale, ENERGY_SCALE_FLOOR_ERG))

    def contact_time_share(self) -> dict[str, float]:
        """Fraction of the simulated time spent in each contact code (from the event log)."""
        return contact_shares_of(self.log[:, ly.LOG_T], self.log[:, ly.LOG_TO],
                                 float(self.log[0, ly.LOG_T]), self.t_end)

    def summary(self) -> dict:
        """Scalar results of the run (the ``workbench run --json`` object)."""
        kinds = self.log[:, ly.LOG_KIND]
        visited = (set(int(r) for r in self.log[:, ly.LOG_TO])
                   | set(int(r) for r in self.signal("regime")))
        tip = self.signal("tip_y") - self.static_tip_y
        return {
            "status": "ok" if self.ok else "failed",
            "status_code": self.status,
            "message": self.message,
            "simulated_s": self.simulated_s,
            "wall_s": self.wall_s,
            "compile_s": self.compile_s,
            "dt": self.dt,
            "method": self.method,
            "tol": self.tol,
            **{key: value for key, value in self.control.items() if key != "floor_intervals"},
            "floor_intervals": self.control.get("floor_intervals", [])[:SUMMARY_FLOOR_ROWS],
            "anti_alias": self.anti_alias,
            "initial": self.initial,
            "n_events": int((kinds != ly.KIND_START).sum()),
            "n_impacts": int((kinds == ly.KIND_IMPACT).sum()),
            "regimes_visited": sorted(visited),
            "contact_time_share": self.contact_time_share(),
            "max_penetration_cm": float(self.stats["max_penetration_cm"]),
            "max_drift_cm": float(self.stats["max_drift_cm"]),
            "max_correction_cm": float(self.stats["max_correction_cm"]),
            "t_max_penetration": float(self.stats["t_max_penetration"]),
            "energy_balance_rel": self.energy_balance_rel(),
            "impact_energy_lost_erg": float(self.stats["impact_energy_lost_erg"]),
            **{key: self.stats[key] for key in CONTACT_STAT_KEYS},
            "strain1_rms": float(np.std(self.signal("strain1"))),
            "strain2_rms": float(np.std(self.signal("strain2"))),
            "tip_disp_peak_cm": float(np.abs(tip).max()),
        }

    def to_parquet(self, path) -> None:
        """Signals to ``path``; events to the same name with ``.events.parquet``."""
        path = str(path)
        self.signals.to_parquet(path)
        stem = path[:-len(".parquet")] if path.endswith(".parquet") else path
        self.events.to_parquet(stem + ".events.parquet")


def initial_state(p: Parameters, initial="static", fixed=(), free_decay_cm: float | None = None,
                  static=None, regime: int = 0):
    """The augmented initial state (N_AUG,), its regime (set, stick) and a label.

    ``static`` is the gravity equilibrium if already solved (it is not
    solved again).

    ``initial``: "static" (equilibrium under gravity), "paper" (undeformed,
    at rest, loose body centred, free flight, seed §2.3) or an 18-vector
    (q, q') in the regime ``regime`` (0..16, default free flight; the
    kernel settles it, docs/model.md §7).  ``free_decay_cm`` deflects the tip
    statically by that much first (docs/model.md §8 free decay; implies the
    static start).
    """
    y = np.zeros(ly.N_AUG)
    if free_decay_cm is not None:
        _, eq = tip_load_for_deflection(p, free_decay_cm, fixed, base=static)
        y[:ly.N_DOF] = eq.q
        return y, (eq.contact_set, True), f"free decay from {free_decay_cm} cm"
    if isinstance(initial, str):
        if initial == "static":
            eq = static_equilibrium(p, 0.0, fixed) if static is None else static
            y[:ly.N_DOF] = eq.q
            return y, (eq.contact_set, True), "static"
        if initial == "paper":
            return y, (0, False), "paper"
        raise ParameterError(f"initial = {initial!r}: use 'static', 'paper' or an array of "
                             f"{ly.N_STATE} values (q, q')")
    arr = np.asarray(initial, dtype=float)
    if arr.shape != (ly.N_STATE,) or not np.all(np.isfinite(arr)):
        raise ParameterError(f"initial state must be {ly.N_STATE} finite values (q, q'), "
                             f"got shape {arr.shape}")
    if not (isinstance(regime, (int, np.integer)) and 0 <= regime <= 16):
        raise ParameterError(f"regime = {regime!r} is outside the allowed range 0..16")
    y[:ly.N_STATE] = arr
    return y, (set_of(int(regime)), is_stick(int(regime))), "given"


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
    dt_given = dt is not None
    if ex.shape != (cx.N_EXC,):
        raise ParameterError("excitation must come from workbench.model.drives (an array of "
                             f"{cx.N_EXC} values)")
    method, tol = check_method(method, tol, dt_given=dt_given)
    kernel = METHODS[method].kernel
    prepare_kernels(kernel)                             # before the step's eigenvalues
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
    static_tip = float("nan") if static is None else static.tip_y
    work.rg[ly.RG_SET] = set0
    work.rg[ly.RG_STICK] = 1.0 if stick0 else 0.0
    work.rg[ly.RG_SIGN] = 1.0
    st = np.zeros(ly.N_ST)
    chunk = max(decim, (round(_CHUNK_S / dt) // decim) * decim)
    # the kernels sample every k base steps; the record keeps every m-th, its analog
    # channels low-pass filtered first (antialias)
    k = antialias.internal_decimation(decim, dt, np.abs(_eigenvalues(params)).max() / (2 * np.pi))
    m = decim // k
    decimator = antialias.Decimator(m, 1.0 / (k * dt))
    if METHODS[method].controlled:
        ctl = np.zeros(ly.N_CTL)
        ctl[ly.CTL_H_MIN] = np.inf
        controller = (ctl, np.zeros((ly.N_SCALE_ROWS, ly.N_STATE)),
                      np.zeros((FLOOR_LOG_ROWS, ly.N_FLOOR)))
        settings = (tol, int(level_max))
    else:
        controller, settings = (), ()
    parts_t, parts_y, parts_s, parts_log = [], [], [], []
    done = 0
    status = ly.OK
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=n_steps, unit="step", desc="simulate", leave=False)
    first_use = _first_use[0].take() if _first_use else 0.0     # the kernels before the loop's
    control = (controller,) if controller else ()
    compile_s = compile_kernel(kernel, (y, float(t0), dt, 1, 0, k, *settings, model, ex, work,
                                        (np.empty(1), np.empty((1, ly.N_STATE)),
                                         np.empty((1, ly.N_SIG))), np.empty((1, ly.N_LOG)), st,
                                        *control))
    if _first_use:
        _first_use[0].take()                                # in compile_kernel's seconds
    compile_s += first_use + _compile_unreported.pop(_kernel_name(kernel), 0.0)
    t_wall = time.perf_counter()
    parts_analog = []
    n_internal = 0          # internal samples so far: output sample j is internal sample j m
    while done < n_steps:
        n = min(chunk, n_steps - done)
        n_out = (done + n) // k - done // k + (1 if done == 0 else 0)
        out_t = np.empty(n_out)
        out_y = np.empty((n_out, ly.N_STATE))
        out_sig = np.empty((n_out, ly.N_SIG))
        log = np.empty((_LOG_ROWS, ly.N_LOG))
        status, stored, n_log = kernel(y, t0 + done * dt, dt, n, done, k, *settings, model, ex,
                                       work, (out_t, out_y, out_sig), log, st, *control)
        keep = slice((-n_internal) % m, stored, m)
        parts_t.append(out_t[keep])
        parts_y.append(out_y[keep])
        parts_s.append(out_sig[keep])
        parts_analog.append(decimator.push(out_sig[:stored]))
        n_internal += stored
        parts_log.append(log[:n_log].copy())
        new_done = int(st[ly.ST_STEP]) if status in (ly.OK, ly.LOG_FULL) else done
        if status == ly.OK:
            new_done = done + n
        if bar is not None:
            bar.update(new_done - done)
        y = work.stages[ly.STAGE_CUR].copy()
        if status not in (ly.OK, ly.LOG_FULL):
            break
        if status == ly.LOG_FULL and new_done == done:
            status = ly.ERR_EVENT_FLOOD
            break
        done = new_done
        status = ly.OK
        if stop is not None and done < n_steps:
            reason = stop(_record_so_far(params, ex, dt, duration, parts_t, parts_y, parts_s,
                                         parts_analog, parts_log, st, static_tip, label, t0))
            if reason:
                status = ly.STOPPED
                break
    parts_analog.append(decimator.finish())
    parts_s = [np.concatenate(parts_s)]
    parts_s[0][:, antialias.ANALOG_COLUMNS] = np.concatenate(parts_analog)
    wall = time.perf_counter() - t_wall
    if bar is not None:
        bar.close()
    run = _assemble(params, ex, dt, duration, status, wall, parts_t, parts_y, parts_s, parts_log,
                    st, static_tip, label, t0)
    if status == ly.STOPPED:
        run.message = f"{ly.MESSAGES[status]}: {reason}"
    run.compile_s = compile_s
    run.anti_alias = antialias.summary(m, 1.0 / (k * dt))
    run.method = method
    run.tol = tol
    run.control = (control_summary(controller[0], controller[2], tol, dt, duration) if controller
                   else fixed_step_summary(dt, int(st[ly.ST_STEP])))
    if check_accuracy and run.ok:
        finer = accuracy.companion_settings(METHODS[method].controlled, tol, dt)
        companion = simulate(params, excitation, duration, output_hz=1.0 / (decim * dt),
                             initial=initial, free_decay_cm=free_decay_cm, fixed=fixed, t0=t0,
                             regime=regime, method=method, level_max=level_max,
                             **{"dt": dt, "tol": tol, **finer})
        run.control.update(accuracy.measured(run, companion, finer))
    return run


def check_method(method: str | None, tol: float | None, dt_given: bool = False,
                 names: dict | None = None) -> tuple[str, float | None]:
    """The method and its tolerance (None for a fixed step); ParameterError on bad input.

    Without a method, "rk4" when a step was given without a tolerance,
    else DEFAULT_METHOD.  ``names`` maps "method" and "tol" to the names
    the user wrote.
    """
    names = names or {}
    if method is None:
        method = "rk4" if dt_given and tol is None else DEFAULT_METHOD
    if not isinstance(method, str) or method not in METHODS:
        raise ParameterError(f"{names.get('method', 'method')} = {method!r} is not a method; "
                             f"use one of {', '.join(sorted(METHODS))}")
    if not METHODS[method].controlled:
        if tol is not None:
            raise ParameterError(f"{names.get('tol', 'tol')} = {tol:g} is for the controlled "
                                 f"method; {method!r} takes fixed steps (give dt instead)")
        return method, None
    tol = DEFAULT_TOL if tol is None else check_positive(names.get("tol", "tol"), tol, "")
    if not TOL_RANGE[0] <= tol <= TOL_RANGE[1]:
        raise ParameterError(f"{names.get('tol', 'tol')} = {tol:g} is outside the allowed range "
                             f"[{TOL_RANGE[0]:g}, {TOL_RANGE[1]:g}]")
    return method, float(tol)


def control_summary(ctl: np.ndarray, floor_log: np.ndarray, tol: float, dt: float,
                    duration: float) -> dict:
    """The controlled run's steps, rejections and error estimates (Run.summary keys).

    ``intervals_by_step`` counts the steps accepted in each band
    (dt / 2^(j+1), dt / 2^j] (s; base step dt, steps above dt in the
    first).  Besides the largest local
    estimate, the run's global error is estimated as the root sum of
    squares of the accepted steps' local estimates (local errors of
    random sign): ``q_error_rss`` for the positions (relative to their
    scales, as the tip's error relative to its range) and
    ``share_error_rss`` for the contact codes' time shares (the events'
    time errors over the run's ``duration`` (s)); ``global_error_est`` is
    the larger (docs/model.md, "How far to trust it").
    """
    n_floor = int(ctl[ly.CTL_N_FLOOR])
    floors = [{"t0": float(r[ly.FL_T0]), "t1": float(r[ly.FL_T1]),
               "from_regime": int(r[ly.FL_FROM]), "to_regime": int(r[ly.FL_TO]),
               "events": int(r[ly.FL_EVENTS]),
               "error_over_tol": None if r[ly.FL_ERR] < 0 else float(r[ly.FL_ERR]),
               "moreau_jean_steps": int(r[ly.FL_STEPPED])}
              for r in floor_log[:min(n_floor, len(floor_log))]]
    done = ctl[ly.CTL_INTERVALS] > 0
    names = [*Q_COLUMNS, *QD_COLUMNS, *ly.EV_NAMES, "event_time"]
    arg = int(ctl[ly.CTL_ARG_ERR_MAX])
    q_rss = float(np.sqrt(ctl[ly.CTL_Q_SSQ]))
    share_rss = float(np.sqrt(ctl[ly.CTL_T_SSQ])) / duration if duration > 0 else 0.0
    per_level = ctl[ly.CTL_LEVELS:ly.CTL_LEVELS + ly.N_CTL_LEVELS]
    levels = {f"{dt / 2 ** j:.4g}": int(n) for j, n in enumerate(per_level) if n > 0}
    return {"steps": int(ctl[ly.CTL_STEPS]), "steps_all": int(ctl[ly.CTL_WORK]),
            "intervals": int(ctl[ly.CTL_INTERVALS]), "rejected": int(ctl[ly.CTL_REJECTED]),
            "h_min": float(ctl[ly.CTL_H_MIN]) if done else None,
            "h_max": float(ctl[ly.CTL_H_MAX]) if done else None,
            "error_est_max": float(ctl[ly.CTL_ERR_MAX] * tol),
            "error_over_tol_max": float(ctl[ly.CTL_ERR_MAX]),
            "t_error_max": float(ctl[ly.CTL_T_ERR_MAX]),
            "error_max_in": names[arg] if done else None,
            "rejected_by_events": int(ctl[ly.CTL_REJECTED_EVENTS]),
            "intervals_by_step": levels,
            "global_error_est": max(q_rss, share_rss), "q_error_rss": q_rss,
            "share_error_rss": share_rss,
            "floor_count": n_floor, "floor_intervals": floors}


def fixed_step_summary(dt: float, steps: int) -> dict:
    """The summary keys of a fixed-step run: its steps, and no error estimate."""
    return {"steps": steps, "steps_all": steps, "intervals": steps, "rejected": 0,
            "h_min": dt, "h_max": dt, "error_est_max": None, "error_over_tol_max": None,
            "t_error_max": None, "error_max_in": None, "rejected_by_events": 0,
            "global_error_est": None, "q_error_rss": None, "share_error_rss": None,
            "intervals_by_step": {f"{dt:.4g}": steps}, "floor_count": 0, "floor_intervals": []}


#: What the first compile of a run's kernels takes on this 2-core machine, from
#: an idle hour to a busy one (docs/performance.md "Compile time"), for the message.
COMPILE_NOTE = "15-45 s on 2 cores"

#: The kernels a run uses besides its method's event loop: the model's shape
#: table and stiffness (packing), the linear model's eigenvalues (the default
#: step) and the static start.
_RUN_KERNELS = ("shapes.fill_shape_row", "dynamics.fill_stiffness_damping",
                "dynamics.eval_inertia", "cork.cork_stiffness", "equilibrium.static_state",
                "equilibrium.newton_set")
_prepared: set = set()
#: Seconds compiled for a run kernel not yet reported in a run's ``compile_s``.
_compile_unreported: dict = {}


class FirstUseClock(numba_event.Listener):
    """Seconds numba spends compiling kernels on their first use in this process,
    counted from numba's ``numba:compile`` events (a caller's compile includes
    its callees': nested compiles count once), until :meth:`take` reads them.

    With ``WORKBENCH_COMPILE_JOBS=0`` a run's kernels compile on first use,
    the static start's and the step's eigenvalues' before the event loop's,
    so a run's ``compile_s`` adds what this clock counted before it.
    """

    def __init__(self):
        self.depth, self.started, self.seconds = 0, 0.0, 0.0

    def on_start(self, event):
        if self.depth == 0:
            self.started = time.perf_counter()
        self.depth += 1

    def on_end(self, event):
        self.depth -= 1
        if self.depth == 0:
            self.seconds += time.perf_counter() - self.started

    def take(self) -> float:
        """The seconds counted since the last call (s)."""
        seconds, self.seconds = self.seconds, 0.0
        return seconds

    def register(self) -> "FirstUseClock":
        """Start counting."""
        numba_event.register("numba:compile", self)
        return self

    def unregister(self) -> None:
        numba_event.unregister("numba:compile", self)


#: Counts first-use compiles once a process runs with ``WORKBENCH_COMPILE_JOBS=0``.
_first_use: list = []


def _kernel_name(kernel) -> str:
    function = getattr(kernel, "py_func", kernel)      # plain Python under NUMBA_DISABLE_JIT
    return f"{function.__module__.rsplit('.', 1)[-1]}.{function.__name__}"


def prepare_kernels(kernel) -> None:
    """Before a process's first run of ``kernel``: when numba's cache lacks any of
    the run's kernels, compile them in parallel on the usable cores
    (:mod:`~workbench.model.compile_plan`), saying so on stderr first.  The
    first run of ``kernel`` reports the seconds in its ``compile_s``.
    """
    if not hasattr(kernel, "signatures") or _kernel_name(kernel) in _prepared:
        return                                      # NUMBA_DISABLE_JIT, or done
    from . import compile_plan
    from ..core._cache import CACHE_DIR
    _prepared.add(_kernel_name(kernel))
    roots = (_kernel_name(kernel), *_RUN_KERNELS)
    jobs = compile_plan.jobs_from_environment()
    if jobs == 0:
        if not _first_use:
            _first_use.append(FirstUseClock().register())
        return
    if not compile_plan.missing(compile_plan.closure(compile_plan.load_plan(), roots)):
        return
    print(f"workbench: compiling the numba kernels ({COMPILE_NOTE}; once, then cached in "
          f"{CACHE_DIR})", file=sys.stderr, flush=True)
    t = time.perf_counter()
    compile_plan.compile_parallel(roots, jobs)
    _compile_unreported[_kernel_name(kernel)] = time.perf_counter() - t


def compile_kernel(kernel, args) -> float:
    """Compile a run kernel for these arguments' types, or load it from numba's cache.

    Returns the seconds spent (0 when already in this process).
    """
    import numba
    if not hasattr(kernel, "signatures") or kernel.signatures:   # NUMBA_DISABLE_JIT: plain Python
        return 0.0
    t = time.perf_counter()
    kernel.compile(tuple(numba.typeof(a) for a in args))
    return time.perf_counter() - t


def _record_so_far(params, ex, dt, duration, parts_t, parts_y, parts_s, parts_analog, parts_log,
                   st, static_tip, label, t0) -> Run:
    """The samples so far whose filtered channels are final, as a Run (status OK)."""
    analog = np.concatenate(parts_analog)
    n = len(analog)
    sig = np.concatenate(parts_s)[:n]
    sig[:, antialias.ANALOG_COLUMNS] = analog
    return _assemble(params, ex, dt, duration, ly.OK, 0.0, [np.concatenate(parts_t)[:n]],
                     [np.concatenate(parts_y)[:n]], [sig], parts_log, st, static_tip, label, t0)


def _assemble(params, ex, dt, duration, status, wall, parts_t, parts_y, parts_s, parts_log, st,
              static_tip, label, t0) -> Run:
    t = np.concatenate(parts_t)
    ys = np.concatenate(parts_y)
    sig = np.concatenate(parts_s)
    logs = np.concatenate(parts_log) if parts_log else np.empty((0, ly.N_LOG))
    units = {n: u for n, u in zip(ly.COORD_NAMES, ly.COORD_UNITS)}
    units.update({f"{n}_dot": f"{u}/s" for n, u in zip(ly.COORD_NAMES, ly.COORD_UNITS)})
    units.update(dict(zip(ly.SIGNALS, ly.SIGNAL_UNITS)))
    units.update({"t": "s", "impulse_t": "dyn s", "ke_lost": "erg"})
    stats = {"max_penetration_cm": max(0.0, st[ly.ST_MAX_PEN]), "max_drift_cm": st[ly.ST_MAX_DRIFT],
             "max_correction_cm": st[ly.ST_MAX_CORRECTION],
             "t_max_penetration": st[ly.ST_T_MAX_PEN],
             "max_penetration_where": int(st[ly.ST_PEN_WHERE]),
             "impact_energy_lost_erg": st[ly.ST_E_IMPACT], "t_reached": st[ly.ST_T],
             "steps": int(st[ly.ST_STEP]),
             "accumulations": int(st[ly.ST_N_ACCUM]),
             "accumulation_energy_lost_erg": st[ly.ST_E_ACCUM],
             "inconsistent_resolved": int(st[ly.ST_N_INCONSISTENT]),
             "inconsistent_energy_lost_erg": st[ly.ST_E_INCONSISTENT],
             "least_violated": int(st[ly.ST_N_UNRESOLVED]),
             "stepped_steps": int(st[ly.ST_N_STEPPED]),
             "stepped_energy_lost_erg": st[ly.ST_E_STEPPED],
             "s_min_cm": st[ly.ST_S_MIN], "s_max_cm": st[ly.ST_S_MAX]}
    return Run(params=params, excitation=ex, dt=dt, duration=duration, status=int(status),
               message=ly.MESSAGES[int(status)], wall_s=wall, t=t, states=ys, sensors=sig, log=logs,
               stats=stats, static_tip_y=static_tip, initial=label, units=units, t0=t0)
