"""The excitation array and the forces it describes (docs/model.md §8), jit-compiled.

The array ``ex`` (N_EXC,) holds a force shape's code (X_KIND, one of EXC_*)
and its settings in CGS; :mod:`workbench.model.drives` builds it from a
drive's settings in user units and checks them.  A new force shape is a
code and its slots here, a branch of :func:`shaker_force` (or
:func:`hammer_force`), and a drive in that registry.

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

# --- the excitation array ex ---------------------------------------------------
X_KIND = 0       # one of EXC_* below
X_AMP = 1        # force amplitude F0 (dyn)
X_FREQ = 2       # sine frequency (Hz)
X_F0 = 3         # chirp start frequency (Hz)
X_F1 = 4         # chirp end frequency (Hz)
X_T_SWEEP = 5    # chirp duration (s)
X_RAMP = 6       # soft-start ramp duration (s); 0 for none
X_T_HIT = 7      # hammer: start of the half-sine pulse (s)
X_WIDTH = 8      # hammer: pulse duration (s)
N_EXC = 9

EXC_NONE = 0
EXC_SINE = 1          # shaker at force1
EXC_CHIRP = 2         # shaker at force1
EXC_HAMMER_JOINT = 3  # vertical half-sine pulse at the joint body's base (docs/model.md §8)
EXC_HAMMER_TIP = 4    # half-sine pulse along beam B's axis at its tip (§4.3)


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
    """Vertical shaker force (dyn) at force1 at time t (s) for the excitation array ex."""
    kind = int(ex[X_KIND])
    if kind == EXC_SINE:
        phase = ex[X_FREQ] * t
    elif kind == EXC_CHIRP:
        f0 = ex[X_F0]
        phase = f0 * t + (ex[X_F1] - f0) * t * t / (2.0 * ex[X_T_SWEEP])
    else:
        return 0.0
    return ex[X_AMP] * ramp(t, ex[X_RAMP]) * math.sin(2.0 * math.pi * phase)


@nb.njit(**JIT_INLINE)
def hammer_force(t, ex):
    """Hammer pulse force (dyn) at time t (s); 0 unless ex is a hammer excitation."""
    kind = int(ex[X_KIND])
    if kind != EXC_HAMMER_JOINT and kind != EXC_HAMMER_TIP:
        return 0.0
    tau = t - ex[X_T_HIT]
    width = ex[X_WIDTH]
    if tau < 0.0 or tau > width:
        return 0.0
    return ex[X_AMP] * math.sin(math.pi * tau / width)
