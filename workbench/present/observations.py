"""The paper's §6 observations as data, and the rules that measure them in a record.

:data:`OBSERVATIONS` lists each observation with its section, figures and
the paper's claim in our words; :func:`assess_sine` and :func:`assess_chirp`
measure them in a run and give each a verdict ("reproduced", "partly",
"not", or "no number" where the paper gives nothing to compare with).

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

from ..study.metrics import (FLOOR_BAND, FLOOR_GAP, LINE_MARGIN_DB, line_level,  # noqa: F401
                             sample_rate, spectrum)

BAND_WINDOW_S = 2.0
BAND_CONTEXT_S = 60.0
BAND_MARGIN_DB = 3.0
#: The paper's drive line, subharmonic and higher peaks (§6, Fig. 7-8), the share above which a
#: band "has information", the bands of its chirp (Fig. 11-12, minutes) and how near a band must be.
DRIVE_HZ = 20.0
SUBHARMONIC_HZ = 10.0
PEAK_BANDS_HZ = ((45.0, 75.0), (80.0, 120.0))
HIGH_HZ = 200.0
HIGH_SHARE = 0.01
PAPER_BANDS_MIN = (0.83, 1.667, 3.0)
BAND_MATCH_MIN = 0.25
#: The paper's cases: the 20 Hz sine of Fig. 6-10 (10 s, measured after 2 s) and the 5-65 Hz
#: chirp of Fig. 11-12 (240 s, its first 20 s transient, §6), both with a 1 s soft start.
SINE_S, SINE_SKIP_S = 10.0, 2.0
CHIRP_F0_HZ, CHIRP_F1_HZ, CHIRP_S, CHIRP_SKIP_S = 5.0, 65.0, 240.0, 20.0
RAMP_S = 1.0
#: A contact code "dominates" above this share; a code "appears" above the second.
DOMINANT_SHARE = 0.2
APPEARS_SHARE = 0.01


RULES = {
    "verdicts": f"a code dominates above a share of {DOMINANT_SHARE:g} (14 and 23 both: "
                f"reproduced) and appears above {APPEARS_SHARE:g}; the peaks near 60 and 100 Hz "
                f"are the strongest in {PEAK_BANDS_HZ[0][0]:g}-{PEAK_BANDS_HZ[0][1]:g} and "
                f"{PEAK_BANDS_HZ[1][0]:g}-{PEAK_BANDS_HZ[1][1]:g} Hz, each found at the line margin; "
                f"'no information above 200 Hz' is less than {HIGH_SHARE:.0%} of the power there; "
                f"a paper band is matched by a band within {BAND_MATCH_MIN:g} min",
    "line": f"a line is present when its Welch power (Hann, half overlap) stands "
            f"{LINE_MARGIN_DB:g} dB above the median of the bins within ±{FLOOR_BAND:.0%} of "
            f"its frequency (±{FLOOR_GAP} bins around it left out)",
    "peak": "the strongest Welch peak in the band, and its level over the band's median",
    "above": "the share of the power (about the mean) above the frequency, from the Welch spectrum",
    "bands": f"power in {BAND_WINDOW_S:g} s windows against its running median over "
             f"{BAND_CONTEXT_S:g} s; a band is a run of windows {BAND_MARGIN_DB:g} dB or more "
             "above it, at its power-weighted centre",
}


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
    fs = sample_rate(t)
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


# --- the observations ----------------------------------------------------------------------

#: (id, figures, the paper's claim in our words); every one is of §6.
_CLAIMS = (
    ("drive_line", "Fig. 6-8",
     "the driving frequency (20 Hz) stands out in the strain and dominates the time history"),
    ("subharmonic", "Fig. 7-8",
     "a subharmonic at 10 Hz in the strain spectrum, in experiment and simulation"),
    ("peaks_60_100", "Fig. 7-8",
     "higher peaks near 60 and 100 Hz (the simulation's a little higher than the experiment's)"),
    ("above_200", "Fig. 8",
     "none of the information above 200 Hz is present in the paper's simulation"),
    ("switch_14_23", "Fig. 9",
     "the simulation switches mostly between contact at 1 and 4 and at 2 and 3"),
    ("code_13", "Fig. 10", "the experiment also shows contact at 1 and 3"),
    ("switch_rate", "Fig. 9-10",
     "the switching rates of simulation and experiment differ (no numbers given)"),
    ("chirp_bands", "Fig. 11-12",
     "bands of resonance near 0.83, 1.67 and 3 minutes of the 5-65 Hz, 4-minute chirp"),
)
OBSERVATIONS = tuple({"id": i, "section": "§6", "figures": f, "claim": c} for i, f, c in _CLAIMS)


def _verdict(ok: bool) -> str:
    return "reproduced" if ok else "not"


def assess_sine(t, strain1, shares: dict, switches_per_s: float) -> dict:
    """The observations of a 20 Hz sine run: {id: (measure in words, verdict)}."""
    drive = line_level(t, strain1, DRIVE_HZ)
    sub = line_level(t, strain1, SUBHARMONIC_HZ)
    peaks = [strongest_peak(t, strain1, lo, hi) for lo, hi in PEAK_BANDS_HZ]
    found = [p for p in peaks if p["level_db"] >= LINE_MARGIN_DB]
    high = power_above(t, strain1, HIGH_HZ)
    s14, s23, s13 = (shares.get(c, 0.0) for c in (14, 23, 13))
    both = s14 >= DOMINANT_SHARE and s23 >= DOMINANT_SHARE
    return {
        "drive_line": (f"20 Hz line {drive['level_db']:.1f} dB over its floor", _verdict(drive["present"])),
        "subharmonic": (f"10 Hz line {sub['level_db']:.1f} dB over its floor", _verdict(sub["present"])),
        "peaks_60_100": ("; ".join(f"{p['f_hz']:.1f} Hz at {p['level_db']:.1f} dB" for p in peaks),
                         "reproduced" if len(found) == 2 else ("partly" if found else "not")),
        "above_200": (f"{high:.2%} of the strain's power above 200 Hz", _verdict(high < HIGH_SHARE)),
        "switch_14_23": (f"shares 14: {s14:.2f}, 23: {s23:.2f}",
                         "reproduced" if both else ("partly" if max(s14, s23) >= DOMINANT_SHARE else "not")),
        "code_13": (f"share 13: {s13:.3f}", _verdict(s13 >= APPEARS_SHARE)),
        "switch_rate": (f"{switches_per_s:.0f} switches per s", "no number"),
    }


def assess_chirp(t, strain1, skip_s: float) -> dict:
    """The chirp's bands: {"chirp_bands": (measure in words, verdict)} and the band times (min)."""
    bands = [b / 60.0 for b in resonance_bands(t, strain1, skip_s)]
    matched = [p for p in PAPER_BANDS_MIN if any(abs(b - p) <= BAND_MATCH_MIN for b in bands)]
    verdict = ("reproduced" if len(matched) == len(PAPER_BANDS_MIN)
               else "partly" if matched else "not")
    words = (f"bands at {', '.join(f'{b:.2f}' for b in bands) or 'none'} min; "
             f"{len(matched)} of the paper's 3 within {BAND_MATCH_MIN:g} min")
    return {"chirp_bands": (words, verdict)}, bands
