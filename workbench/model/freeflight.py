"""Free-flight integration from Python: validate, allocate, call the kernel.

Contact is not modelled here: the loose body moves freely through
the plates, so use it with the joint locked or held by springs, or for
short checks.  Returns the decimated trajectory and the kernel's status.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import packing as mdl
from ..core import layout as ly
from ..core.integrate import integrate_fixed
from .drives import none
from .params import ParameterError


@dataclass
class Trajectory:
    """A decimated trajectory: t (n,) in s, y (n, 18) = (q, q'), status and message."""

    t: np.ndarray
    y: np.ndarray
    status: int
    message: str

    @property
    def q(self) -> np.ndarray:
        return self.y[:, :ly.N_DOF]

    @property
    def qd(self) -> np.ndarray:
        return self.y[:, ly.N_DOF:]


def integrate(model: mdl.Model, y0: np.ndarray, duration: float, dt: float,
              decim: int = 1, ex: np.ndarray | None = None,
              work: mdl.Work | None = None) -> Trajectory:
    """Integrate ``duration`` seconds with RK4 steps of ``dt`` seconds.

    ``duration`` must be a whole number of steps (to 1e-9 relative).
    Coordinates held fixed by the model must start with zero velocity.
    """
    for name, value in (("duration", duration), ("dt", dt)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ParameterError(f"{name} = {value!r} s is outside the allowed range (0, inf) s")
    if not (isinstance(decim, (int, np.integer)) and decim >= 1):
        raise ParameterError(f"decim = {decim!r} must be an integer >= 1")
    n_steps = round(duration / dt)
    if abs(n_steps * dt - duration) > 1e-9 * duration:
        raise ParameterError(f"duration = {duration} s is not a whole number of steps dt = {dt} s")
    y0 = np.asarray(y0, dtype=float)
    if y0.shape != (ly.N_STATE,) or not np.all(np.isfinite(y0)):
        raise ParameterError(f"y0 must be {ly.N_STATE} finite values, got shape {y0.shape}")
    held = np.setdiff1d(np.arange(ly.N_DOF), model.free)
    if np.any(y0[ly.N_DOF + held] != 0.0):
        raise ParameterError("coordinates held fixed must start with zero velocity: "
                             + ", ".join(ly.COORD_NAMES[i] for i in held))
    ex = none() if ex is None else ex
    work = mdl.make_work() if work is None else work
    n_out = n_steps // decim + 1
    out_t = np.empty(n_out)
    out_y = np.empty((n_out, ly.N_STATE))
    status, stored = integrate_fixed(y0, 0.0, dt, n_steps, decim, model, ex, work, out_t, out_y)
    return Trajectory(out_t[:stored], out_y[:stored], int(status), ly.MESSAGES[int(status)])
