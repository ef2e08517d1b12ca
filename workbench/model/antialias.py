"""The DAQ's anti-alias filter: a record's analog channels low-pass filtered before they are
sampled at the output rate.

A data acquisition system filters every analog channel below half its sample rate
before it samples, so that nothing above that frequency folds into the record.  A run
does the same from samples of the solution.  The kernels sample the solution at an internal rate F = 1 / (k dt)
(:func:`internal_decimation`: the coarsest that is still above 2 f_model + f, with
f_model the linear model's fastest mode and f the output rate, so that none of the
model's modes folds into the record's band; with the default step k = 1, F = 10 kHz
with the tip mass and 16 kHz without).  The ANALOG channels (the rig's sensors and the
hammer's force gauge) then pass a linear-phase FIR low-pass filter and every m-th
sample is kept (m = F / f):

- passband to PASSBAND f, stopband from STOPBAND f (the Nyquist frequency f / 2),
  ATTENUATION_DB of attenuation there, a Kaiser window (``scipy.signal.kaiserord``
  and ``firwin``); the passband ripple is that of the window's, at most
  10^(-ATTENUATION_DB / 20) (1e-5, 9e-5 dB), and :func:`design` measures it;
- the filter is centred (an output sample at t weighs the internal samples t +- H dt
  symmetrically), so it has no delay: a DAQ's timestamps are corrected for its own
  filter's delay in the same way;
- a record is valid (flat within the ripple, nothing of the model's modes folded) from 0
  to PASSBAND f: 400 Hz at the default 1 kHz.  What the internal samples fold from above
  F / 2 stays: the accelerations, which jump at the events, differ from the same trajectory
  sampled at 4 F by up to 0.2-1.2 % of their range (docs/usage.md).

The edges: before the run's first sample each channel is held at its first value (the
rig at rest in its start state); after the last it is continued by point reflection
about its last value, x(T + s) = 2 x(T) - x(T - s), which keeps its value and slope.
Only the first and last H internal samples (H dt: 46 ms at the default 1 kHz without
the tip mass) are filtered across an edge.

The states (q, q'), the contact channels and the model's other signals (gaps, forces,
energies, the regime) are the solution itself, sampled every m-th internal sample.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from ..core import layout as ly

#: The record's analog channels, filtered before sampling (docs/usage.md "Records").
ANALOG = ("force1", "hammer", "strain1", "strain2", "accel1", "accel2", "accel3")
ANALOG_COLUMNS = tuple(ly.SIGNALS.index(c) for c in ANALOG)
#: Passband and stopband edges, fractions of the output rate.
PASSBAND = 0.4
STOPBAND = 0.5
ATTENUATION_DB = 100.0


@functools.lru_cache(maxsize=32)
def design(m: int, internal_hz: float) -> dict:
    """The FIR filter for decimating by ``m`` from ``internal_hz``: its taps (odd count,
    symmetric, unit DC gain) and what it does (edges in Hz, measured ripple and attenuation)."""
    from scipy import signal

    if m == 1:
        return {"taps": np.ones(1), "m": 1, "internal_hz": internal_hz, "passband_hz": None,
                "stopband_hz": None, "ripple_db": 0.0, "attenuation_db": None}
    out_hz = internal_hz / m
    width = (STOPBAND - PASSBAND) * out_hz / (internal_hz / 2.0)
    numtaps, beta = signal.kaiserord(ATTENUATION_DB, width)
    numtaps += 1 - numtaps % 2
    taps = signal.firwin(numtaps, 0.5 * (PASSBAND + STOPBAND) * out_hz, window=("kaiser", beta),
                         fs=internal_hz)
    taps /= taps.sum()
    f, h = signal.freqz(taps, worN=8192, fs=internal_hz)
    gain = np.abs(h)
    passband = f <= PASSBAND * out_hz
    stopband = f >= STOPBAND * out_hz
    return {"taps": taps, "m": m, "internal_hz": internal_hz,
            "passband_hz": PASSBAND * out_hz, "stopband_hz": STOPBAND * out_hz,
            "ripple_db": float(np.max(np.abs(20.0 * np.log10(gain[passband])))),
            "attenuation_db": float(-20.0 * np.log10(gain[stopband].max()))}


def internal_decimation(decim: int, dt: float, f_model_hz: float) -> int:
    """Base steps between the kernels' samples: the largest divisor k of ``decim`` (the
    base steps between output samples) with 1 / (k dt) >= 2 f_model_hz + the output rate."""
    out_hz = 1.0 / (decim * dt)
    need = 2.0 * f_model_hz + out_hz
    for k in range(decim, 0, -1):
        if decim % k == 0 and 1.0 / (k * dt) >= need * (1.0 - 1e-12):
            return k
    return 1


def summary(m: int, internal_hz: float) -> dict:
    """What the filter does, for Run.summary (no taps)."""
    d = design(m, internal_hz)
    return {"filter": "none (the output rate is the internal rate)" if m == 1 else
            f"FIR low-pass, Kaiser window, {len(d['taps'])} taps, linear phase, centred",
            "internal_hz": internal_hz, "passband_hz": d["passband_hz"],
            "stopband_hz": d["stopband_hz"], "ripple_db": d["ripple_db"],
            "attenuation_db": d["attenuation_db"],
            "valid_band_hz": [0.0, d["passband_hz"] if m > 1 else internal_hz / 2.0]}


class Decimator:
    """Filters and decimates the ANALOG columns of consecutive blocks of internal samples.

    ``push(block)`` takes the next internal samples (rows, the kernel's signal columns)
    and returns the filtered analog values of the output samples it completes (rows,
    len(ANALOG)); ``finish()`` returns the rest.  Output sample j is internal sample
    j m (the first internal sample is j = 0).
    """

    def __init__(self, m: int, internal_hz: float):
        self.m = m
        self.taps = design(m, internal_hz)["taps"]
        self.half = (len(self.taps) - 1) // 2
        self.buf = None          # internal samples not yet used up, from global index self.start
        self.start = 0
        self.next_out = 0        # global internal index of the next output sample

    def push(self, block: np.ndarray) -> np.ndarray:
        x = np.asarray(block, dtype=float)[:, ANALOG_COLUMNS]
        if self.buf is None:
            if not len(x):
                return np.empty((0, len(ANALOG)))
            self.buf = np.concatenate([np.repeat(x[:1], self.half, axis=0), x])
            self.start = -self.half
        else:
            self.buf = np.concatenate([self.buf, x])
        return self._emit()

    def finish(self) -> np.ndarray:
        if self.buf is None or self.half == 0:      # no filter: every sample already out
            return np.empty((0, len(ANALOG)))
        h = self.half
        last = self.buf[-1]
        n = len(self.buf)
        back = self.buf[max(0, n - 1 - h):n - 1][::-1]
        tail = np.concatenate([2.0 * last - back, np.repeat(last[None], h - len(back), axis=0)])
        end = self.start + n - 1                      # the last real internal sample
        self.buf = np.concatenate([self.buf, tail])
        return self._emit(last_index=end)

    def _emit(self, last_index: int | None = None) -> np.ndarray:
        from scipy import signal

        h, m = self.half, self.m
        available = self.start + len(self.buf) - 1 - h     # the last centre with its window
        if last_index is not None:
            available = min(available, last_index)
        if available < self.next_out:
            return np.empty((0, len(ANALOG)))
        first = self.next_out - h - self.start             # buffer row of the first window
        stop = available - h - self.start                  # ... of the last centre's window
        rows = self.buf[first:stop + 2 * h + 1]
        if h == 0:
            out = rows[::m].copy()
        else:
            out = signal.oaconvolve(rows, self.taps[:, None], mode="valid", axes=0)[::m]
        self.next_out += m * len(out)
        drop = self.next_out - h - self.start
        self.buf = self.buf[max(0, drop):]
        self.start += max(0, drop)
        return out


def expected_outputs(n_internal: int, m: int) -> int:
    """Output samples among n_internal internal samples (indices 0 .. n_internal - 1)."""
    return 0 if n_internal <= 0 else math.floor((n_internal - 1) / m) + 1
