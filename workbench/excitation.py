"""Excitations at the user boundary (MODEL.md §8), converted once to CGS.

Forces are given in newtons (1 N = 1e5 dyn) and frequencies in Hz; the
result is the kernel's excitation array (layout ``X_*``).
"""
from __future__ import annotations

import math

import numpy as np

from .core import layout as ly
from .params import ParameterError

#: dyn per newton
DYN_PER_N = 1.0e5


def _positive(name, value, unit, allow_zero=False):
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if not ok or value < 0 or (value == 0 and not allow_zero):
        allowed = "[0, inf)" if allow_zero else "(0, inf)"
        raise ParameterError(f"{name} = {value!r} {unit} is outside the allowed range {allowed} {unit}")
    return float(value)


def none() -> np.ndarray:
    """No shaker force."""
    return np.zeros(ly.N_EXC)


def sine(force_n: float, freq_hz: float, ramp_s: float = 0.0) -> np.ndarray:
    """F = F0 sin(2 pi f t) at force1, with an optional soft-start ramp (s)."""
    ex = none()
    ex[ly.X_KIND] = ly.EXC_SINE
    ex[ly.X_AMP] = _positive("force_n", force_n, "N", allow_zero=True) * DYN_PER_N
    ex[ly.X_FREQ] = _positive("freq_hz", freq_hz, "Hz")
    ex[ly.X_RAMP] = _positive("ramp_s", ramp_s, "s", allow_zero=True)
    return ex


def chirp(force_n: float, f0_hz: float, f1_hz: float, sweep_s: float,
          ramp_s: float = 0.0) -> np.ndarray:
    """Linear chirp f0 -> f1 over sweep_s seconds (seed §5.5: 5 -> 65 Hz, 240 s)."""
    ex = none()
    ex[ly.X_KIND] = ly.EXC_CHIRP
    ex[ly.X_AMP] = _positive("force_n", force_n, "N", allow_zero=True) * DYN_PER_N
    ex[ly.X_F0] = _positive("f0_hz", f0_hz, "Hz")
    ex[ly.X_F1] = _positive("f1_hz", f1_hz, "Hz")
    ex[ly.X_T_SWEEP] = _positive("sweep_s", sweep_s, "s")
    ex[ly.X_RAMP] = _positive("ramp_s", ramp_s, "s", allow_zero=True)
    return ex
