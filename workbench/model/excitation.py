"""Excitations at the user boundary (docs/model.md §8), converted once to CGS.

Forces are given in newtons (1 N = 1e5 dyn) and frequencies in Hz; the
result is the kernel's excitation array (layout ``X_*``).
"""
from __future__ import annotations

import math

import numpy as np

from ..core import layout as ly
from .params import ParameterError, check_positive

#: dyn per newton
DYN_PER_N = 1.0e5

#: Default shaker amplitude (N): the tip stays below the paper's 8.4 cm
#: deflection across 10-55 Hz at the widest gap with the tip mass (chosen by
#: studies/default_force.py; see docs/usage.md, "Default shaker amplitude").
DEFAULT_FORCE_N = 200.0
#: Default hammer peak (N).
DEFAULT_HAMMER_N = 100.0


def none() -> np.ndarray:
    """No shaker force."""
    return np.zeros(ly.N_EXC)


def sine(force_n: float, freq_hz: float, ramp_s: float = 0.0) -> np.ndarray:
    """F = F0 sin(2 pi f t) at force1, with an optional soft-start ramp (s)."""
    ex = none()
    ex[ly.X_KIND] = ly.EXC_SINE
    ex[ly.X_AMP] = check_positive("force_n", force_n, "N", allow_zero=True) * DYN_PER_N
    ex[ly.X_FREQ] = check_positive("freq_hz", freq_hz, "Hz")
    ex[ly.X_RAMP] = check_positive("ramp_s", ramp_s, "s", allow_zero=True)
    return ex


def chirp(force_n: float, f0_hz: float, f1_hz: float, sweep_s: float,
          ramp_s: float = 0.0) -> np.ndarray:
    """Linear chirp f0 -> f1 over sweep_s seconds (seed §5.5: 5 -> 65 Hz, 240 s)."""
    ex = none()
    ex[ly.X_KIND] = ly.EXC_CHIRP
    ex[ly.X_AMP] = check_positive("force_n", force_n, "N", allow_zero=True) * DYN_PER_N
    ex[ly.X_F0] = check_positive("f0_hz", f0_hz, "Hz")
    ex[ly.X_F1] = check_positive("f1_hz", f1_hz, "Hz")
    ex[ly.X_T_SWEEP] = check_positive("sweep_s", sweep_s, "s")
    ex[ly.X_RAMP] = check_positive("ramp_s", ramp_s, "s", allow_zero=True)
    return ex


def _hammer(kind, force_n, width_s, t_hit_s):
    ex = none()
    ex[ly.X_KIND] = kind
    if not (isinstance(force_n, (int, float)) and math.isfinite(force_n)):
        raise ParameterError(f"force_n = {force_n!r} N must be a finite number (sign = direction)")
    ex[ly.X_AMP] = float(force_n) * DYN_PER_N
    ex[ly.X_WIDTH] = check_positive("width_s", width_s, "s")
    ex[ly.X_T_HIT] = check_positive("t_hit_s", t_hit_s, "s", allow_zero=True)
    return ex


def hammer_joint(force_n: float, width_s: float = 1e-3, t_hit_s: float = 0.0) -> np.ndarray:
    """Half-sine hammer pulse, vertical (+ up), at the joint body's base (seed §5.4).

    Peak ``force_n`` N, duration ``width_s`` s, starting at ``t_hit_s`` s.
    """
    return _hammer(ly.EXC_HAMMER_JOINT, force_n, width_s, t_hit_s)


def hammer_tip(force_n: float, width_s: float = 1e-3, t_hit_s: float = 0.0) -> np.ndarray:
    """Half-sine hammer pulse along beam B's axis at its tip (+ outward; seed §4.3 cork test)."""
    return _hammer(ly.EXC_HAMMER_TIP, force_n, width_s, t_hit_s)
