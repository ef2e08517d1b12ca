"""Scalar results of one run over its steady-state window.

The window is the last ``window_s`` seconds of the run.  Per sensor channel
(force1, strain1, strain2, accel1-3) and for the tip displacement from its
static equilibrium (``tip``, cm):

    <ch>_rms    RMS about the window mean (the dynamic part; strains carry a
                static part under gravity)
    <ch>_peak   largest |x - mean| in the window
    <ch>_h0.5, <ch>_h1, <ch>_h2, <ch>_h3
                amplitudes of the harmonics f/2, f, 2f, 3f of the drive
                frequency f (sine runs), by a least-squares fit of the
                window to a constant and those four sinusoids

The subharmonic (sine runs): ``strain1_sub_db``, the strain1 line at half the
drive frequency over the spectrum's floor around it (dB; :func:`line_level`,
Welch segments of 1 / SUB_RESOLUTION_HZ s, or the window when shorter).

Contact statistics from the event log (exact times, not samples):
``share_<code>`` the fraction of the window in each contact code (0, 1, 2,
3, 4, 13, 14, 23, 24), ``stick_share`` the fraction in a sticking regime,
``impacts_per_s`` and ``switches_per_s`` (every event).  Energy dissipated
per forcing cycle (erg; per second without a drive frequency) by structural
damping, cork damping, friction and impacts: ``diss_<mechanism>``.

Bifurcation samples: ``tip_poincare`` lists the tip displacement (cm) once
per forcing period, at t = k / f within the window (the drive's phase 0),
interpolated by a cubic spline through the samples (sine runs only).

The validated range (over the whole run): the columns of
:func:`workbench.model.validity.validity`, with ``out_of_range`` naming the
limits a run exceeds.

Steady-state indicator (the first mode, ~2 Hz with zeta < 1 %, rings for
tens of seconds): ``steady_change`` = |RMS_last - RMS_previous| / RMS_last
of the tip displacement over the last two windows; ``steady`` is
``steady_change <= steady_tol``.
"""
from __future__ import annotations

import math

import numpy as np

from ..model import regimes
from ..model.regimes import contact_shares_of, regime_time_of
from .wear import WearConstants, wear_measures
from ..model.validity import validity
from ..model.run_result import CONTACT_STAT_KEYS

CHANNELS = ("force1", "strain1", "strain2", "accel1", "accel2", "accel3", "tip")
HARMONICS = (0.5, 1.0, 2.0, 3.0)
CONTACT_CODES = regimes.CONTACT_CODES
DISSIPATION = {"structural": "d_structural", "cork": "d_cork", "friction": "d_friction",
               "impact": "d_impact"}
#: The metrics shown in figures and tables: (title, CGS unit of the column; "" for a count or a
#: share).  ``workbench.present.units`` shows them in SI.
QUANTITIES = {
    "tip_rms": ("tip RMS", "cm"), "tip_h1": ("tip at f", "cm"),
    "strain1_rms": ("strain1 RMS", "strain"), "accel3_rms": ("accel3 RMS", "cm/s²"),
    "impacts_per_s": ("impacts per s", ""), "switches_per_s": ("switches per s", ""),
    "stick_share": ("stick share", ""), "share_0": ("free-flight share", ""),
    "force_n_used": ("drive force used", "N"),
}
#: Resolution (Hz) of the spectrum the subharmonic's level is read from.
SUB_RESOLUTION_HZ = 0.5
#: Default bound on the relative RMS change between the last two windows.
STEADY_TOL = 0.05


def psd(t: np.ndarray, x: np.ndarray, segment_s: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Power spectral density of x (unit^2/Hz) by Welch's method with ``segment_s``
    segments (Hann, half overlap, mean removed): frequencies (Hz) and PSD."""
    from scipy.signal import welch

    fs = 1.0 / float(np.median(np.diff(t)))
    return welch(np.asarray(x, dtype=float), fs=fs, nperseg=min(len(t), int(round(segment_s * fs))),
                 detrend="constant")


#: A spectral line (:func:`line_level`) is present this far (dB) above its floor: the median of
#: the bins within +-FLOOR_BAND of its frequency (relative), +-FLOOR_GAP bins around it left out.
LINE_MARGIN_DB = 10.0
FLOOR_BAND = 0.5
FLOOR_GAP = 3


def sample_rate(t: np.ndarray) -> float:
    """The sample rate (Hz) of uniform times t (s); ValueError when not uniform or too few."""
    dt = np.diff(t)
    if len(t) < 16 or not np.allclose(dt, dt[0], rtol=1e-6):
        raise ValueError("the signal needs at least 16 uniform samples")
    return 1.0 / dt[0]


def spectrum(t, x, resolution_hz: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Welch's power spectral density of x about its mean (:func:`psd`): Hz, PSD."""
    sample_rate(t)
    return psd(t, x, segment_s=1.0 / resolution_hz)


def line_level(t, x, f_hz: float, resolution_hz: float = 0.5) -> dict:
    """The line at ``f_hz``: its power, its level over the floor (dB), and present or not.

    The level is NaN (and the line not present) when the spectrum has no bins around the
    line to take a floor from: a record shorter than a few periods of ``f_hz``."""
    f, p = spectrum(t, x, resolution_hz)
    df = f[1] - f[0]
    k = int(round(f_hz / df))
    near = slice(max(0, k - 1), k + 2)
    power = float(p[near].max())
    band = (np.abs(f - f_hz) <= FLOOR_BAND * f_hz) & (np.abs(np.arange(len(f)) - k) > FLOOR_GAP)
    floor = float(np.median(p[band])) if band.any() else float("nan")
    # no floor to stand on (a record too short for bins around the line): no level
    level = (float("nan") if np.isnan(floor) else
             10.0 * np.log10(power / floor) if floor > 0 else float("inf"))
    return {"f_hz": f_hz, "power": power, "floor": floor, "level_db": float(level),
            "present": bool(level >= LINE_MARGIN_DB)}


def parabolic_vertex(a, b, c):
    """The vertex of the parabola through (-1, a), (0, b), (1, c): its offset from 0
    (in samples) and its height.  Scalars or arrays; a flat triple gives offset 0."""
    a, b, c = (np.asarray(v, dtype=float) for v in (a, b, c))
    den = a - 2.0 * b + c
    shift = np.where(den != 0.0, 0.5 * (a - c) / np.where(den != 0.0, den, 1.0), 0.0)
    return shift, b - 0.25 * (a - c) * shift


def spectral_peaks(f: np.ndarray, p: np.ndarray, n: int = 3, fmin: float = 1.0,
                   fmax: float = 250.0, min_prominence: float = 0.5,
                   min_relative: float = 1e-4) -> np.ndarray:
    """Frequencies (Hz) of the ``n`` most prominent PSD peaks in [fmin, fmax] standing
    ``min_prominence`` decades above their surroundings and within ``min_relative``
    of the highest (measurement noise makes many small ones), refined by a parabola
    through the peak bin and its neighbours; ascending."""
    from scipy.signal import find_peaks

    band = np.flatnonzero((f >= fmin) & (f <= fmax))
    if len(band) < 3:
        return np.array([])
    logp = np.log10(p[band] + 1e-300)
    idx, props = find_peaks(logp, prominence=min_prominence,
                            height=float(logp.max()) + np.log10(min_relative))
    idx = idx[np.argsort(-props["prominences"])][:n]
    shift, _ = parabolic_vertex(logp[idx - 1], logp[idx], logp[idx + 1])
    return np.sort(f[band][idx] + shift * (f[1] - f[0]))


def harmonic_amplitudes(t: np.ndarray, x: np.ndarray, f_hz: float) -> dict[float, float]:
    """Amplitudes of x at k f_hz (k in HARMONICS) by least squares with a constant term."""
    cols = [np.ones_like(t)]
    for k in HARMONICS:
        w = 2.0 * np.pi * k * f_hz
        cols += [np.cos(w * t), np.sin(w * t)]
    coef, *_ = np.linalg.lstsq(np.column_stack(cols), x, rcond=None)
    return {k: float(np.hypot(coef[1 + 2 * i], coef[2 + 2 * i])) for i, k in enumerate(HARMONICS)}


def once_per_period(t: np.ndarray, x: np.ndarray, f_hz: float) -> np.ndarray:
    """x at the times k / f_hz (k integer) inside [t[0], t[-1]], by a cubic spline."""
    k = np.arange(np.ceil(t[0] * f_hz - 1e-9), np.floor(t[-1] * f_hz + 1e-9) + 1)
    from scipy.interpolate import CubicSpline   # here: scipy.interpolate costs 0.5 s to import
    return CubicSpline(t, x)(k / f_hz)


def regime_time(events, t0: float, t1: float) -> dict[int, float]:
    """Time (s) spent in each regime within [t0, t1], from the event log."""
    return regime_time_of(events.t.to_numpy(), events.to_regime.to_numpy(), t0, t1)


def contact_shares(events, t0: float, t1: float) -> dict[str, float]:
    """Fraction of [t0, t1] spent in each contact code ("0", "1", ..., "23"), from an event log.

    ``events`` has columns t and to_regime (a run's events, or a reference's log).
    """
    return contact_shares_of(events.t.to_numpy(), events.to_regime.to_numpy(), t0, t1)


def point_metrics(run, window_s: float, drive_hz: float | None = None,
                  wear: WearConstants = WearConstants(), steady_tol: float = STEADY_TOL) -> dict:
    """The metrics of the module docstring for a finished :class:`~workbench.model.run_result.Run`,
    the wear measures (:mod:`workbench.study.wear`, with Archard's constants ``wear``) among them."""
    sig = run.signals
    t = sig.index.to_numpy()
    t_end = float(t[-1])
    t0 = t_end - window_s
    win = t >= t0 - 1e-12
    prev = (t >= t0 - window_s - 1e-12) & (t < t0 - 1e-12)
    out: dict = {}
    tip = (sig.tip_y - run.static_tip_y).to_numpy()
    data = {ch: (tip if ch == "tip" else sig[ch].to_numpy()) for ch in CHANNELS}
    for ch, x in data.items():
        xw = x[win]
        dev = xw - xw.mean()
        out[f"{ch}_rms"] = float(np.sqrt(np.mean(dev ** 2)))
        out[f"{ch}_peak"] = float(np.abs(dev).max())
        if drive_hz:
            for k, a in harmonic_amplitudes(t[win], xw, drive_hz).items():
                out[f"{ch}_h{k:g}"] = a
    if drive_hz:
        out["tip_poincare"] = once_per_period(t[win], tip[win], drive_hz).tolist()
        out["strain1_sub_db"] = line_level(t[win], data["strain1"][win], drive_hz / 2.0,
                                           max(SUB_RESOLUTION_HZ, 1.0 / window_s))["level_db"]
    rms_prev = float(np.std(tip[prev])) if prev.sum() > 1 else float("nan")
    rms_last = out["tip_rms"]
    change = abs(rms_last - rms_prev) / rms_last if rms_last > 0 else 0.0
    out["steady_change"] = float(change)
    out["steady"] = bool(change <= steady_tol)
    spent = regime_time(run.events, t0, t_end)
    total = sum(spent.values()) or 1.0
    for code in CONTACT_CODES:
        out[f"share_{code}"] = 0.0
    stick = 0.0
    for reg, dur in spent.items():
        out[f"share_{regimes.contact_code(reg)}"] += dur / total
        if regimes.is_stick(reg):
            stick += dur / total
    out["stick_share"] = stick
    ev = run.events[(run.events.t >= t0) & (run.events.kind != "start")]
    out["impacts_per_s"] = float((ev.kind == "impact").sum() / window_s)
    out["switches_per_s"] = float(len(ev) / window_s)
    cycles = window_s * drive_hz if drive_hz else window_s
    for name, col in DISSIPATION.items():
        x = sig[col].to_numpy()
        out[f"diss_{name}"] = float((x[-1] - x[win][0]) / cycles)
    out.update(wear_measures(run, t0, t_end, cycles, wear))
    out.update(validity(run))
    return out


def contact_checks(run) -> dict:
    """The contact logic's account of a run (docs/model.md §6-§7), for sweeps and the stress study.

    The run's contact statistics (accumulations, inconsistent states
    resolved, least-violated regimes, Moreau-Jean steps, with the energy
    each removed; the range of s), and:

    ``impact_ke_gain_rel``  the largest kinetic energy an impact added,
                            over the run's largest kinetic energy (0: none)
    ``stop_overtravel_cm``  how far |s| went past the slot travel (cm)
    ``stop_force_n``        the end stop's largest force k_stop * overtravel (N)
    ``friction_limit_n``    mu_s times the largest total normal force (N):
                            the most the plates' friction can push the slide
    ``slide_speed_cm_s``    the largest |s'| (cm/s)
    ``stop_allowance_cm``   the overtravel those allow: the stop, a spring
                            k_stop, meets the slide's mass m (the loose body,
                            beam B and the tip mass) at speed v while the
                            friction F pushes on; energy, k d^2 / 2 =
                            m v^2 / 2 + F d, gives d = F/k + sqrt((F/k)^2 +
                            m v^2 / k).  The cork's own spring, which pulls
                            the slide back, is left out (the bound is safe).

    Forces and speeds are read from the stored signals (the output rate).
    """
    p = run.params
    out = {key: run.stats[key] for key in CONTACT_STAT_KEYS}
    e_kin = float(run.signals.e_kin.max()) if len(run.signals) else 0.0
    impacts = run.events[run.events.kind == "impact"]
    gain = float(max(0.0, -impacts.ke_lost.min())) if len(impacts) else 0.0
    out["impact_ke_gain_rel"] = gain / e_kin if e_kin > 0 else gain
    s_abs = max(abs(out["s_min_cm"]), abs(out["s_max_cm"]))
    over = max(0.0, s_abs - p.s_travel)
    out["stop_overtravel_cm"] = over
    out["stop_force_n"] = p.k_stop * over / 1e5
    normal = run.signals[[f"lambda_n{k}" for k in range(1, 5)]].sum(axis=1)
    friction = float(p.mu_s * normal.max()) if len(normal) else 0.0
    out["friction_limit_n"] = friction / 1e5
    speed = float(run.signals.s_dot.abs().max()) if len(run.signals) else 0.0
    out["slide_speed_cm_s"] = speed
    mass = p.m4 + p.mu_b * p.l_b + (p.m6 if p.tip_mass else 0.0)
    if p.k_stop > 0.0:
        static = friction / p.k_stop
        out["stop_allowance_cm"] = static + math.sqrt(static ** 2 + mass * speed ** 2 / p.k_stop)
    else:
        out["stop_allowance_cm"] = math.inf
    return out
