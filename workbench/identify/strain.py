"""Strain-patch calibration (seed §4.4 "Strain sensor patch calibration", Eq. 3, Appendix C).

A cantilevered beam carrying a PVDF patch and a tip accelerometer is
deflected and released.  The tip acceleration, integrated twice by Euler's
method, gives the tip deflection delta_L(t); a tip-loaded cantilever's
static shape turns it into the surface strain at the patch (Eq. 3),

    eps = 3 c delta_L (L - x) / L^3,

and the scale factor is the multiplier that maps the patch voltage onto
that strain (the paper found 9e-5 and 1.77e-5 for patches 1 and 2).
"""
from __future__ import annotations

import numpy as np

from ..model.params import ParameterError, check_positive


def euler_double_integral(t: np.ndarray, accel: np.ndarray, detrend: bool = True) -> np.ndarray:
    """Displacement from acceleration by two forward-Euler integrations (cm from cm/s^2).

    Starts from rest at zero.  ``detrend`` removes the best-fit quadratic
    from the displacement: the drift that a constant offset of the
    accelerometer (and the unknown initial velocity) integrate into.
    """
    t = np.asarray(t, dtype=float)
    a = np.asarray(accel, dtype=float)
    if t.shape != a.shape or t.ndim != 1 or len(t) < 3:
        raise ParameterError(f"t and accel must be 1-D of the same length >= 3, got {t.shape}, {a.shape}")
    dt = np.diff(t)
    if not np.all(dt > 0):
        raise ParameterError("t must increase strictly")
    v = np.concatenate(([0.0], np.cumsum(a[:-1] * dt)))
    d = np.concatenate(([0.0], np.cumsum(v[:-1] * dt)))
    if detrend:
        d = d - np.polyval(np.polyfit(t - t[0], d, 2), t - t[0])
    return d


def cantilever_strain(tip_deflection, c: float, x: float, length: float):
    """Surface strain at x of a tip-loaded cantilever, Eq. 3 (-).

    ``tip_deflection`` delta_L (cm, scalar or array), ``c`` the distance
    from the neutral axis (cm), ``x`` the patch position from the clamp
    (cm, in [0, L]), ``length`` L (cm).
    """
    length = check_positive("length", length, "cm")
    c = check_positive("c", c, "cm")
    if not 0.0 <= x <= length:
        raise ParameterError(f"x = {x} cm is outside the allowed range [0, {length}] cm (the beam)")
    return 3.0 * c * np.asarray(tip_deflection, dtype=float) * (length - x) / length ** 3


def scale_factor(voltage: np.ndarray, strain: np.ndarray) -> float:
    """The multiplier k minimising |k V - eps|^2 (strain per volt), both about their means."""
    v = np.asarray(voltage, dtype=float)
    e = np.asarray(strain, dtype=float)
    if v.shape != e.shape:
        raise ParameterError(f"voltage and strain must have the same shape, got {v.shape}, {e.shape}")
    v = v - v.mean()
    e = e - e.mean()
    vv = float(v @ v)
    if vv == 0.0:
        raise ParameterError("voltage is constant: no scale factor can be fitted")
    return float(v @ e) / vv


def calibrate_patch(t, accel, voltage, *, c: float, x: float, length: float) -> float:
    """The patch's scale factor (strain per volt) from one release test (§4.4).

    ``t`` (s), tip ``accel`` (cm/s^2) and patch ``voltage`` (V) sampled
    together; ``c``, ``x``, ``length`` as in :func:`cantilever_strain`.
    """
    strain = cantilever_strain(euler_double_integral(t, accel), c, x, length)
    return scale_factor(voltage, strain)
