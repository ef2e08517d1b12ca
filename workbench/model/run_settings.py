"""A run's settings checked before it starts: the method and its tolerance, the step, the
output rate and the duration against what the drive needs (one-line errors naming the
option as the user wrote it)."""
from __future__ import annotations

import math

import numpy as np

from . import drives
from .limits import DEFAULT_TOL, MAX_DT, MAX_DURATION_S, MIN_DT, TOL_RANGE
from .methods import DEFAULT_METHOD, METHODS
from .params import ParameterError, Parameters, check_positive
from .step_policy import default_dt, stability_limit


def check_settings(params: Parameters, ex: np.ndarray, duration: float, dt: float | None,
                   output_hz: float | None, t0: float = 0.0, names: dict | None = None,
                   strict: bool = True) -> tuple[float, int, int]:
    """Check a run's settings against what its step can resolve; return (dt, decim, n_steps).

    The step (given or :func:`default_dt`) must resolve the drive (its
    :class:`~workbench.model.drives.Drive`'s check: STEPS_PER_PERIOD steps per
    period of a sine or a chirp's highest frequency, MIN_PULSE_STEPS per hammer
    pulse) and divide the output interval and the duration.  ``strict`` (the
    command line and studies) adds: the step RK4-stable for the model
    (:func:`stability_limit`), a hammer hit and a soft-start ramp ending within
    the run.  The Python API (:func:`simulate`) is not strict: a short look at a
    run's start, or a deliberately unstable step in a test, stays possible.
    ``names`` maps the setting names (duration, dt, output_hz, and the drive's
    settings) to the names the user wrote (an option, a study key), for the
    messages.
    Raises ParameterError.
    """
    names = names or {}

    def name(key):
        return names.get(key, key)

    duration = check_positive(name("duration"), duration, "s")
    if duration > MAX_DURATION_S:
        raise ParameterError(f"{name('duration')} = {duration:g} s is outside the allowed range "
                             f"(0, {MAX_DURATION_S:g}] s")
    t0 = check_positive("t0", t0, "s", allow_zero=True)
    given = dt is not None
    if given:
        dt = check_positive(name("dt"), dt, "s")
        if not MIN_DT <= dt <= MAX_DT:
            raise ParameterError(f"{name('dt')} = {dt:g} s is outside the allowed range "
                                 f"[{MIN_DT:g}, {MAX_DT:g}] s")
        if strict:
            limit = stability_limit(params)
            if dt > limit:
                raise ParameterError(
                    f"{name('dt')} = {dt:g} s is above this model's RK4 stability limit "
                    f"{limit:.3g} s (its fastest linear mode); give at most that, or leave it out "
                    f"for the default {default_dt(params, ex):g} s")
    else:
        dt = default_dt(params, ex)
    drive = drives.of_array(ex)
    if output_hz is None:           # the drive's rate at least, dividing 1/dt
        output_hz = 1.0 / (dt * max(1, math.floor(1.0 / (dt * drive.output_hz(ex)) + 1e-9)))
    output_hz = check_positive(name("output_hz"), output_hz, "Hz")
    decim = round(1.0 / (output_hz * dt)) if output_hz * dt > 1e-12 else 0
    if decim < 1 or abs(decim * dt * output_hz - 1.0) > 1e-9:
        raise ParameterError(f"{name('output_hz')} = {output_hz:g} Hz must divide 1/dt = "
                             f"{1 / dt:g} Hz into whole steps (dt = {dt:g} s)")
    n_steps = round(duration / dt)
    if abs(n_steps * dt - duration) > 1e-9 * duration:
        raise ParameterError(f"{name('duration')} = {duration:g} s is not a whole number of "
                             f"steps dt = {dt:g} s")
    drive.check(ex, drives.Step(dt, t0 + duration, strict, name, 1.0 / (decim * dt)))
    return dt, decim, n_steps


def check_method(method: str | None, tol: float | None, dt_given: bool = False,
                 names: dict | None = None) -> tuple[str, float | None]:
    """The method and its tolerance (None for a fixed step); ParameterError on bad input.

    Without a method, "rk4" when a step was given without a tolerance,
    else DEFAULT_METHOD.  ``names`` maps "method" and "tol" to the names
    the user wrote.
    """
    names = names or {}
    if method is None:
        method = "rk4" if dt_given and tol is None else DEFAULT_METHOD
    if not isinstance(method, str) or method not in METHODS:
        raise ParameterError(f"{names.get('method', 'method')} = {method!r} is not a method; "
                             f"use one of {', '.join(sorted(METHODS))}")
    if not METHODS[method].controlled:
        if tol is not None:
            raise ParameterError(f"{names.get('tol', 'tol')} = {tol:g} is for the controlled "
                                 f"method; {method!r} takes fixed steps (give dt instead)")
        return method, None
    tol = DEFAULT_TOL if tol is None else check_positive(names.get("tol", "tol"), tol, "")
    if not TOL_RANGE[0] <= tol <= TOL_RANGE[1]:
        raise ParameterError(f"{names.get('tol', 'tol')} = {tol:g} is outside the allowed range "
                             f"[{TOL_RANGE[0]:g}, {TOL_RANGE[1]:g}]")
    return method, float(tol)
