"""The rules that measure the paper's §6 observations in a record, stated once.

Each rule takes a signal sampled uniformly (an alias-free record: a run's
signals or a lab file) and returns numbers; :data:`RULES` says each rule in
words for the report.

- :func:`line_level`: a spectral line's level over the spectrum's floor
  around it (dB).  The power spectrum is Welch's (Hann, half overlap,
  segments of ``resolution_hz``^-1 s); the line's power is the largest bin
  within one bin of its frequency; the floor is the median of the bins
  within +-FLOOR_BAND of the line's frequency (relative), leaving out
  +-FLOOR_GAP bins around the line.  A line is *present* when it stands
  LINE_MARGIN_DB above its floor.
- :func:`strongest_peak`: the strongest spectral peak in a band (Hz) and
  its level over the band's floor (median), for "peaks near 60 and
  100 Hz".
- :func:`power_above`: the share of the signal's power (about its mean)
  above a frequency (Hz), for "none of the information above 200 Hz".
- :func:`resonance_bands`: the times (s) of the bands of resonance of a
  swept run: the strain's power in sliding windows of BAND_WINDOW_S, in dB,
  against its running median over BAND_CONTEXT_S; a band is a run of
  windows BAND_MARGIN_DB or more above that median, and its time is the
  band's power-weighted centre.  Times before ``skip_s`` (the transient the
  paper says to ignore) are left out.
"""
from __future__ import annotations

import numpy as np
from scipy import ndimage

from ..study.metrics import psd

LINE_MARGIN_DB = 10.0
FLOOR_BAND = 0.5
FLOOR_GAP = 3
BAND_WINDOW_S = 2.0
BAND_CONTEXT_S = 60.0
BAND_MARGIN_DB = 3.0

RULES = {
    "line": f"a line is present when its Welch power (Hann, half overlap) stands "
            f"{LINE_MARGIN_DB:g} dB above the median of the bins within ±{FLOOR_BAND:.0%} of "
            f"its frequency (±{FLOOR_GAP} bins around it left out)",
    "peak": "the strongest Welch peak in the band, and its level over the band's median",
    "above": "the share of the power (about the mean) above the frequency, from the Welch spectrum",
    "bands": f"power in {BAND_WINDOW_S:g} s windows against its running median over "
             f"{BAND_CONTEXT_S:g} s; a band is a run of windows {BAND_MARGIN_DB:g} dB or more "
             "above it, at its power-weighted centre",
}


def _rate(t: np.ndarray) -> float:
    dt = np.diff(t)
    if len(t) < 16 or not np.allclose(dt, dt[0], rtol=1e-6):
        raise ValueError("the signal needs at least 16 uniform samples")
    return 1.0 / dt[0]


def spectrum(t, x, resolution_hz: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Welch's power spectral density of x about its mean (``metrics.psd``): Hz, PSD."""
    _rate(t)
    return psd(t, x, segment_s=1.0 / resolution_hz)


def line_level(t, x, f_hz: float, resolution_hz: float = 0.5) -> dict:
    """The line at ``f_hz``: its power, its level over the floor (dB), and present or not."""
    f, p = spectrum(t, x, resolution_hz)
    df = f[1] - f[0]
    k = int(round(f_hz / df))
    near = slice(max(0, k - 1), k + 2)
    power = float(p[near].max())
    band = (np.abs(f - f_hz) <= FLOOR_BAND * f_hz) & (np.abs(np.arange(len(f)) - k) > FLOOR_GAP)
    floor = float(np.median(p[band])) if band.any() else float("nan")
    level = 10.0 * np.log10(power / floor) if floor > 0 else float("inf")
    return {"f_hz": f_hz, "power": power, "floor": floor, "level_db": float(level),
            "present": bool(level >= LINE_MARGIN_DB)}


def strongest_peak(t, x, lo_hz: float, hi_hz: float, resolution_hz: float = 0.5) -> dict:
    """The strongest spectral peak within [lo_hz, hi_hz] and its level over the band (dB)."""
    f, p = spectrum(t, x, resolution_hz)
    band = (f >= lo_hz) & (f <= hi_hz)
    i = int(np.argmax(np.where(band, p, -np.inf)))
    floor = float(np.median(p[band]))
    return {"f_hz": float(f[i]), "level_db": float(10.0 * np.log10(p[i] / floor))}


def power_above(t, x, f_hz: float, resolution_hz: float = 0.5) -> float:
    """The share of x's power (about its mean) above ``f_hz``."""
    f, p = spectrum(t, x, resolution_hz)
    total = p[1:].sum()
    return float(p[f > f_hz].sum() / total) if total > 0 else 0.0


def resonance_bands(t, x, skip_s: float = 0.0) -> list[float]:
    """The times (s) of the bands of resonance of a swept record (module docstring)."""
    fs = _rate(t)
    n = int(round(BAND_WINDOW_S * fs))
    windows = len(x) // n
    if windows < 3:
        raise ValueError(f"the record holds {windows} windows of {BAND_WINDOW_S:g} s; need 3")
    chunks = np.asarray(x[:windows * n], dtype=float).reshape(windows, n)
    power = chunks.var(axis=1)
    centre = t[0] + (np.arange(windows) + 0.5) * BAND_WINDOW_S
    db = 10.0 * np.log10(np.maximum(power, 1e-300))
    context = max(3, int(round(BAND_CONTEXT_S / BAND_WINDOW_S)) | 1)
    baseline = ndimage.median_filter(db, size=context, mode="nearest")
    above = (db - baseline >= BAND_MARGIN_DB) & (centre >= t[0] + skip_s)
    labels, count = ndimage.label(above)
    return [float(np.average(centre[labels == i], weights=power[labels == i]))
            for i in range(1, count + 1)]
