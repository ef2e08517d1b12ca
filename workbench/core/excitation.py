"""Shaker force F(t) at force1 (docs/model.md §8), jit-compiled.

    sine:   F = F0 sin(2 pi f t)
    chirp:  F = F0 sin(2 pi (f0 t + (f1 - f0) t^2 / (2 T)))

Both multiplied by a soft-start ramp 1/2 (1 - cos(pi t / t_ramp)) while
t < t_ramp, so the lightly damped first mode is not kicked by a sudden start.

Hammer pulses (docs/model.md §8, seed §4.3 and §5.4) are half-sines
F = F0 sin(pi (t - t_hit) / width) for t_hit <= t <= t_hit + width.
"""
import math

import numba as nb

from .config import JIT_INLINE
from . import layout as ly


@nb.njit(**JIT_INLINE)
def ramp(t, t_ramp):
    """Soft-start factor in [0, 1] (-)."""
    if t_ramp <= 0.0 or t >= t_ramp:
        return 1.0
    if t <= 0.0:
        return 0.0
    return 0.5 * (1.0 - math.cos(math.pi * t / t_ramp))


@nb.njit(**JIT_INLINE)
def shaker_force(t, ex):
    """Vertical shaker force (dyn) at time t (s) for the excitation array ex."""
    kind = int(ex[ly.X_KIND])
    if kind == ly.EXC_SINE:
        phase = ex[ly.X_FREQ] * t
    elif kind == ly.EXC_CHIRP:
        f0 = ex[ly.X_F0]
        phase = f0 * t + (ex[ly.X_F1] - f0) * t * t / (2.0 * ex[ly.X_T_SWEEP])
    else:
        return 0.0
    return ex[ly.X_AMP] * ramp(t, ex[ly.X_RAMP]) * math.sin(2.0 * math.pi * phase)


@nb.njit(**JIT_INLINE)
def hammer_force(t, ex):
    """Hammer pulse force (dyn) at time t (s); 0 unless ex is a hammer excitation."""
    kind = int(ex[ly.X_KIND])
    if kind != ly.EXC_HAMMER_JOINT and kind != ly.EXC_HAMMER_TIP:
        return 0.0
    tau = t - ex[ly.X_T_HIT]
    width = ex[ly.X_WIDTH]
    if tau < 0.0 or tau > width:
        return 0.0
    return ex[ly.X_AMP] * math.sin(math.pi * tau / width)
