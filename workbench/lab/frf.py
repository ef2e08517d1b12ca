"""Frequency-response functions as the field defines them: H1, H2 and the coherence.

For a force f and a response x sampled together (a record, measured or
simulated), with Welch's averaged cross- and auto-spectra over segments
(Bendat & Piersol, Random Data, 4th ed., §9.1):

    H1 = G_fx / G_ff          (least noise on the response)
    H2 = G_xx / G_xf          (least noise on the force)
    gamma^2 = |G_fx|^2 / (G_ff G_xx) = H1 / H2

A chirp, a sine sweep or a train of hammer hits fills the segments with
force over the band; the coherence says where the record's response is
linear in the force (near 1) and where it is not (the joint's impacts,
noise).  Spectra come from scipy.signal's ``csd`` and ``welch`` (Hann
window, half-overlapping segments): pyFRF averages separate records given
one at a time, while a single long record, the workbench's and the lab's
usual case, is averaged by segmenting it, which Welch's method does.

The window (:data:`WINDOWS`) is the modal engineer's choice per kind of test
(:func:`default_window`):

- ``hann``: Welch's half-overlapping Hann segments, for a stationary drive
  (a sine, noise);
- ``rect``: rectangular segments, by default one the record's length, for a
  transient that starts and ends inside the record (a chirp or a burst):
  a taper would weight the modes the sweep crosses early or late and bias
  their damping;
- ``impact``: one hit, the field's impact-test windows (Ewins, Modal Testing,
  2nd ed., §3.10; Fladung & Rost, "Application and correction of the
  exponential window for frequency response functions", Mech. Syst. Signal
  Process. 11(1), 1997): a force window that keeps the pulse (from
  FORCE_WINDOW_MARGIN samples before the force first exceeds
  FORCE_LEVEL of its peak to as many after it last does) and zeroes the
  rest, and an exponential window exp(-(t - t_hit) / tau) on the response
  from the hit, tau such that it has fallen to EXP_END at the record's end.
  The response's level before the hit (a static offset) is removed first.
  The exponential window adds 1 / tau to every mode's decay rate (Fladung &
  Rost, eq. 9), which :mod:`workbench.lab.modal` takes back from the poles it
  fits; one hit has no coherence (NaN).

Modal parameters (natural frequencies, damping ratios) are read from these
tables by :mod:`workbench.lab.modal` (LSCF and a stabilisation chart).
"""
from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import signal

from ..model.antialias import PASSBAND
from ..model.params import ParameterError
from .channels import kind

#: Default segment length (s) of the Hann window: 0.5 Hz resolution, enough to separate the modes.
DEFAULT_SEGMENT_S = 2.0
WINDOWS = ("hann", "rect", "impact")
#: The impact windows (module docstring): the force's threshold (of its peak), the samples kept
#: on either side of the pulse, and the exponential window's value at the record's end.
FORCE_LEVEL = 0.01
FORCE_WINDOW_MARGIN = 2
EXP_END = 0.01
#: The field's unit of an FRF's magnitude, by the response's kind, and its factor from the
#: record's CGS ratio (strain per dyn, (cm/s^2) per dyn): 1 N = 1e5 dyn, 1 = 1e6 microstrain,
#: 1 m/s^2 = 100 cm/s^2.
FIELD_UNITS = {"strain": ("µε/N", 1e6 * 1e5), "accel": ("(m/s²)/N", 1e5 / 100.0)}



def field_unit(response: str) -> tuple[str, float]:
    """(unit, factor from CGS) of the FRF magnitude of a response channel (strain or accel)."""
    return FIELD_UNITS[kind(response)]


def default_window(drive: str | None) -> str:
    """The window a modal engineer picks for a record of that drive (module docstring)."""
    if str(drive).startswith("hammer"):
        return "impact"
    return "rect" if drive == "chirp" else "hann"


def frf(record: pd.DataFrame, responses=None, force: str = "force1",
        segment_s: float | None = DEFAULT_SEGMENT_S, skip_s: float = 0.0,
        window: str = "hann", band_hz: float | None = None) -> pd.DataFrame:
    """H1, H2 and the coherence of each response channel against the force.

    ``record`` is indexed by time (s) with the force column (N or dyn: the
    FRF carries the ratio of the units) and the responses (default: every
    accel and strain column).  ``window`` is one of WINDOWS (module
    docstring); ``segment_s`` the Welch segment of ``hann`` and ``rect``
    (None: the whole record after ``skip_s``; ``impact`` takes the whole
    record).  Returns a DataFrame indexed by frequency (Hz) with, per
    response r, the columns ``r_H1``, ``r_H2`` (complex) and
    ``r_coherence``; ``attrs`` holds the window and, for ``impact``, the
    exponential window's ``exp_tau_s`` (s) that the modal fit corrects the
    damping for.  The frequencies stop at ``band_hz``, by default the record's valid band,
    PASSBAND of its sample rate (an anti-aliased record's, as the workbench writes them and
    a DAQ records them).  Raises ParameterError on a record it cannot use.
    """
    if window not in WINDOWS:
        raise ParameterError(f"window = {window!r}; allowed: {', '.join(WINDOWS)}")
    try:
        t = record.index.to_numpy(dtype=float)
    except (TypeError, ValueError):
        raise ParameterError("the record's index must be its time (s)") from None
    if force not in record:
        raise ParameterError(f"the record has no {force} column (its columns: "
                             f"{', '.join(map(str, record.columns))})")
    if responses is None:
        responses = [c for c in record.columns if str(c).startswith(("accel", "strain"))]
    missing = [r for r in responses if r not in record]
    if missing or not responses:
        raise ParameterError(f"response channel(s) {missing or '(none)'} not in the record")
    keep = t >= t[0] + skip_s - 1e-12
    t = t[keep]
    if len(t) < 16:
        raise ParameterError(f"the record has {len(t)} samples after skip_s = {skip_s:g} s; "
                             "need at least 16")
    dt = np.diff(t)
    if not (np.all(np.isfinite(t)) and dt[0] > 0 and np.allclose(dt, dt[0], rtol=1e-6)):
        raise ParameterError("the record's time base is not uniform and increasing")
    for c in [force, *responses]:
        if not np.all(np.isfinite(record[c].to_numpy(dtype=float)[keep])):
            raise ParameterError(f"the {c} column has values that are not finite")
    fs = 1.0 / dt[0]
    band_hz = PASSBAND * fs if band_hz is None else band_hz
    if segment_s is None or window == "impact":
        segment_s = len(t) / fs
    if not 0.0 < segment_s <= len(t) / fs * (1 + 1e-9):
        raise ParameterError(f"segment_s = {segment_s:g} s: allowed (0, {len(t) / fs:g}] s, the "
                             "record's length after skip_s")
    nperseg = min(len(t), max(16, int(round(segment_s * fs))))
    f_in = record[force].to_numpy(dtype=float)[keep]
    if not np.any(f_in):
        raise ParameterError(f"the {force} column is zero: no force to refer the response to")
    if window == "impact":
        table = _impact_frf(t, f_in, {r: record[r].to_numpy(dtype=float)[keep] for r in responses})
        return _within(table, band_hz)
    taper = "hann" if window == "hann" else "boxcar"
    kw = dict(fs=fs, window=taper, nperseg=nperseg, noverlap=nperseg // 2 if window == "hann" else 0,
              detrend="constant")
    freq, g_ff = signal.welch(f_in, **kw)
    out = {}
    for r in responses:
        x = record[r].to_numpy(dtype=float)[keep]
        _, g_fx = signal.csd(f_in, x, **kw)           # E[F* X]
        _, g_xx = signal.welch(x, **kw)
        with np.errstate(divide="ignore", invalid="ignore"):
            h1 = g_fx / g_ff
            h2 = g_xx / np.conj(g_fx)
            coh = np.abs(g_fx) ** 2 / (g_ff * g_xx)
        out[f"{r}_H1"] = h1
        out[f"{r}_H2"] = h2
        out[f"{r}_coherence"] = np.clip(np.nan_to_num(coh.real), 0.0, 1.0)
    table = pd.DataFrame(out, index=pd.Index(freq, name="f_hz"))
    table.attrs.update(window=window, averages=1 + max(0, (len(t) - nperseg) // (nperseg - kw["noverlap"])),
                       segment_s=nperseg / fs)
    return _within(table, band_hz)


def _within(table: pd.DataFrame, band_hz: float) -> pd.DataFrame:
    """The rows up to band_hz (Hz), the band kept in ``attrs["band_hz"]``."""
    out = table[table.index <= band_hz * (1 + 1e-12)]
    out.attrs.update(table.attrs, band_hz=float(band_hz))
    return out


def window_words(table: pd.DataFrame) -> str:
    """The window an FRF table was estimated with and the damping correction it needs, in
    one line (for the files' headers)."""
    a = table.attrs
    if a.get("window") == "impact":
        return (f"force window on the hit and exponential window, tau = {a['exp_tau_s']:.6g} s "
                f"(a fitted damping ratio reads 1/(2 pi f tau) too high: subtract it; the "
                f"modes are corrected)")
    shape = "Hann" if a.get("window") == "hann" else "rectangular (none)"
    return (f"{shape} window, {a.get('averages', 1)} average(s) of {a.get('segment_s', 0):.6g} s "
            f"segments{', half overlap' if a.get('window') == 'hann' else ''}; no damping "
            "correction")


def impact_windows(t: np.ndarray, force: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, int]:
    """The force window, the exponential window, tau (s) and the hit's first sample of one hit
    (module docstring)."""
    peak = np.max(np.abs(force))
    above = np.flatnonzero(np.abs(force) > FORCE_LEVEL * peak)
    first = max(0, above[0] - FORCE_WINDOW_MARGIN)
    last = min(len(t) - 1, above[-1] + FORCE_WINDOW_MARGIN)
    w_force = np.zeros(len(t))
    w_force[first:last + 1] = 1.0
    tau = (t[-1] - t[first]) / np.log(1.0 / EXP_END)
    w_exp = np.exp(-np.clip(t - t[first], 0.0, None) / tau)
    return w_force, w_exp, float(tau), int(first)


def _impact_frf(t, force, responses: dict) -> pd.DataFrame:
    """H1 = X / F of one hit with the impact windows (module docstring)."""
    w_force, w_exp, tau, first = impact_windows(t, force)
    n = len(t)
    freq = np.fft.rfftfreq(n, t[1] - t[0])
    F = np.fft.rfft(force * w_force)
    out = {}
    for r, x in responses.items():
        offset = x[:first].mean() if first > 0 else x[0]
        X = np.fft.rfft((x - offset) * w_exp)
        with np.errstate(divide="ignore", invalid="ignore"):
            h = X / F
        out[f"{r}_H1"] = h
        out[f"{r}_H2"] = h
        out[f"{r}_coherence"] = np.full(len(freq), np.nan)
    table = pd.DataFrame(out, index=pd.Index(freq, name="f_hz"))
    table.attrs.update(window="impact", averages=1, exp_tau_s=tau, segment_s=n * (t[1] - t[0]))
    return table


def responses_of(table: pd.DataFrame) -> list[str]:
    """The response channels of an FRF table."""
    return sorted({c.rsplit("_", 1)[0] for c in table.columns})


def magnitude_phase(table: pd.DataFrame) -> pd.DataFrame:
    """An FRF table in real columns: |H1|, |H2| in the field's units (the unit in the
    column's name: ``strain1_H1_abs [µε/N]``), their phases (deg) and the coherence."""
    flat = pd.DataFrame(index=table.index)
    for r in responses_of(table):
        unit, scale = field_unit(r)
        for est in ("H1", "H2"):
            flat[f"{r}_{est}_abs [{unit}]"] = table[f"{r}_{est}"].abs() * scale
            flat[f"{r}_{est}_phase_deg"] = np.degrees(np.angle(table[f"{r}_{est}"]))
        flat[f"{r}_coherence"] = table[f"{r}_coherence"]
    return flat
