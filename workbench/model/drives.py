"""The drives a run can have, in one registry, with the excitation arrays they build.

A drive is named (``sine``, ``chirp``, ...) and set by a few
settings in user units (``force_n``, ``freq_hz``, ...): the keys of a
study's ``[excitation]`` table, of an experiment file's ``WB_`` settings,
and of ``workbench compare``'s options.  Each :class:`Drive` says which
settings it takes, how they build the kernel's excitation array
(:mod:`workbench.core.excitation`: forces converted once to CGS, 1 N =
1e5 dyn), what a run's step must resolve of it, and, for a drive that is
a start rather than a force (a free decay), the keywords of
:func:`workbench.model.simulate.simulate` that set the start.  Studies,
matching, the command line and reports read this registry.  A drive of an
existing force shape is one :func:`register` call; a new force shape adds
its code and force to :mod:`workbench.core.excitation` as well.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..core import excitation as cx
from .limits import (DEFAULT_OUTPUT_HZ, FREE_DECAY_MAX_CM, MIN_PULSE_SAMPLES, MIN_PULSE_STEPS,
                     PULSE_SAMPLES, PULSE_STEPS, STEPS_PER_PERIOD)
from .params import ParameterError, check_positive

#: dyn per newton
DYN_PER_N = 1.0e5
#: Default shaker amplitude (N): the tip stays below the paper's 8.4 cm
#: deflection across 10-55 Hz at the widest gap with the tip mass (chosen by
#: studies/default_force.py; see docs/usage.md, "Default shaker amplitude").
DEFAULT_FORCE_N = 200.0
#: Default hammer peak (N).
DEFAULT_HAMMER_N = 100.0

#: Defaults of the settings a drive may leave out (user units; a drive may have its
#: own, :meth:`Drive.default`).  A hammer hits 10 ms into the record, as a lab's pretrigger
#: keeps the record's start quiet; a shaker starts softly over 1 s (at most half the run).
DEFAULTS = {"force_n": DEFAULT_FORCE_N, "ramp_s": 1.0, "width_s": 1e-3, "t_hit_s": 0.01,
            "deflection_cm": 8.4}
#: The unit of every setting.
UNITS = {"force_n": "N", "freq_hz": "Hz", "f0_hz": "Hz", "f1_hz": "Hz", "sweep_s": "s",
         "ramp_s": "s", "width_s": "s", "t_hit_s": "s", "deflection_cm": "cm"}


# --- the excitation arrays (the public builders) -------------------------------

def none() -> np.ndarray:
    """No force."""
    return np.zeros(cx.N_EXC)


def _amplitude(force_n) -> float:
    return check_positive("force_n", force_n, "N", allow_zero=True) * DYN_PER_N


def sine(force_n: float, freq_hz: float, ramp_s: float = 0.0) -> np.ndarray:
    """F = F0 sin(2 pi f t) at force1, with an optional soft-start ramp (s)."""
    ex = none()
    ex[cx.X_KIND] = cx.EXC_SINE
    ex[cx.X_AMP] = _amplitude(force_n)
    ex[cx.X_FREQ] = check_positive("freq_hz", freq_hz, "Hz")
    ex[cx.X_RAMP] = check_positive("ramp_s", ramp_s, "s", allow_zero=True)
    return ex


def chirp(force_n: float, f0_hz: float, f1_hz: float, sweep_s: float,
          ramp_s: float = 0.0) -> np.ndarray:
    """Linear chirp f0 -> f1 over sweep_s seconds (seed §5.5: 5 -> 65 Hz, 240 s)."""
    ex = none()
    ex[cx.X_KIND] = cx.EXC_CHIRP
    ex[cx.X_AMP] = _amplitude(force_n)
    ex[cx.X_F0] = check_positive("f0_hz", f0_hz, "Hz")
    ex[cx.X_F1] = check_positive("f1_hz", f1_hz, "Hz")
    ex[cx.X_T_SWEEP] = check_positive("sweep_s", sweep_s, "s")
    ex[cx.X_RAMP] = check_positive("ramp_s", ramp_s, "s", allow_zero=True)
    return ex


def _hammer(code, force_n, width_s, t_hit_s):
    ex = none()
    ex[cx.X_KIND] = code
    if not (isinstance(force_n, (int, float)) and math.isfinite(force_n)):
        raise ParameterError(f"force_n = {force_n!r} N must be a finite number (sign = direction)")
    ex[cx.X_AMP] = float(force_n) * DYN_PER_N
    ex[cx.X_WIDTH] = check_positive("width_s", width_s, "s")
    ex[cx.X_T_HIT] = check_positive("t_hit_s", t_hit_s, "s", allow_zero=True)
    return ex


def hammer_joint(force_n: float, width_s: float = 1e-3, t_hit_s: float = 0.0) -> np.ndarray:
    """Half-sine hammer pulse, vertical (+ up), at the joint body's base (seed §5.4).

    Peak ``force_n`` N, duration ``width_s`` s, starting at ``t_hit_s`` s.
    """
    return _hammer(cx.EXC_HAMMER_JOINT, force_n, width_s, t_hit_s)


def hammer_tip(force_n: float, width_s: float = 1e-3, t_hit_s: float = 0.0) -> np.ndarray:
    """Half-sine hammer pulse along beam B's axis at its tip (+ outward; seed §4.3 cork test)."""
    return _hammer(cx.EXC_HAMMER_TIP, force_n, width_s, t_hit_s)


# --- what a run's step must resolve ---------------------------------------------

@dataclass(frozen=True)
class Step:
    """A run's step and span, for a drive's check: ``dt`` (s), the run's ``end`` (s),
    ``strict`` (the command line and studies, :func:`~workbench.model.run_settings.check_settings`),
    ``name`` (a setting's name as the user wrote it) and the signals' ``output_hz``."""

    dt: float
    end: float
    strict: bool
    name: Callable[[str], str]
    output_hz: float = math.inf

    @property
    def f_max(self) -> float:
        """The highest drive frequency (Hz) the step resolves: STEPS_PER_PERIOD steps a period."""
        return 1.0 / (STEPS_PER_PERIOD * self.dt)


def _check_frequency(ex, step, key, slot):
    if ex[slot] > step.f_max:
        raise ParameterError(f"{step.name(key)} = {ex[slot]:g} Hz is above what the step "
                             f"dt = {step.dt:g} s resolves ({STEPS_PER_PERIOD} steps per "
                             f"period: at most {step.f_max:g} Hz)")


def _check_ramp(ex, step):
    if step.strict and ex[cx.X_RAMP] > step.end:
        raise ParameterError(f"{step.name('ramp_s')} = {ex[cx.X_RAMP]:g} s: the soft start "
                             f"would end after the run ({step.end:g} s)")


def _check_sine(ex, step):
    _check_frequency(ex, step, "freq_hz", cx.X_FREQ)
    _check_ramp(ex, step)


def _check_chirp(ex, step):
    _check_frequency(ex, step, "f0_hz", cx.X_F0)
    _check_frequency(ex, step, "f1_hz", cx.X_F1)
    _check_ramp(ex, step)


def _check_pulse(ex, step):
    width = ex[cx.X_WIDTH]
    if width < MIN_PULSE_STEPS * step.dt * (1.0 - 1e-9):
        raise ParameterError(f"{step.name('width_s')} = {width:g} s is shorter than "
                             f"{MIN_PULSE_STEPS} steps dt = {step.dt:g} s: the step cannot "
                             "resolve the pulse (give a smaller dt or leave it out)")
    if width * step.output_hz < MIN_PULSE_SAMPLES * (1.0 - 1e-9):
        raise ParameterError(f"{step.name('output_hz')} = {step.output_hz:g} Hz samples the "
                             f"hammer pulse of {width:g} s {width * step.output_hz:.3g} times; "
                             f"at least {MIN_PULSE_SAMPLES} (give at least "
                             f"{MIN_PULSE_SAMPLES / width:g} Hz, or leave it out for "
                             f"{PULSE_SAMPLES} a pulse)")
    if step.strict and ex[cx.X_T_HIT] + width > step.end:
        raise ParameterError(f"{step.name('t_hit_s')} = {ex[cx.X_T_HIT]:g} s: the pulse of "
                             f"{width:g} s would end after the run ({step.end:g} s)")


def _pulse_dt(ex) -> float:
    return ex[cx.X_WIDTH] / PULSE_STEPS


def _pulse_hz(ex) -> float:
    return max(DEFAULT_OUTPUT_HZ, PULSE_SAMPLES / ex[cx.X_WIDTH])


def _release(settings, name) -> dict:
    """A free decay's start: the tip's static deflection (cm), within FREE_DECAY_MAX_CM."""
    x = settings["deflection_cm"]
    if (isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x)
            or abs(x) > FREE_DECAY_MAX_CM):
        raise ParameterError(f"{name('deflection_cm')} = {x!r} cm is outside the allowed range "
                             f"[-{FREE_DECAY_MAX_CM:g}, {FREE_DECAY_MAX_CM:g}] cm")
    return {"free_decay_cm": float(x)}


# --- the registry ------------------------------------------------------------------

@dataclass(frozen=True)
class Drive:
    """One kind of drive (module docstring)."""

    name: str
    keys: tuple[str, ...]                          # its settings, in order
    build: Callable[[dict], np.ndarray]            # settings -> the kernel's excitation array
    code: int = cx.EXC_NONE                        # the array's force shape (core.excitation)
    check: Callable[[np.ndarray, Step], None] = field(default=lambda ex, step: None)
    dt_max: Callable[[np.ndarray], float] = field(default=lambda ex: math.inf)  # default step's bound (s)
    output_hz: Callable[[np.ndarray], float] = field(default=lambda ex: DEFAULT_OUTPUT_HZ)  # default rate (Hz), at least
    ramped: bool = False                           # a soft start (ramp_s), dropped inside a stepped chain
    frequency_key: str | None = None               # the setting that is the forcing frequency
    swept: bool = False                            # the frequency sweeps over the run (chirp figures)
    start: Callable[[dict, Callable], dict] = field(default=lambda settings, name: {})  # simulate() keywords
    defaults: dict = field(default_factory=dict)   # its own defaults, before DEFAULTS

    def default(self, key: str, duration_s: float | None = None):
        """The default of a setting (its own, else DEFAULTS; None if it has none); the soft
        start ``ramp_s`` at most half of a run of ``duration_s`` seconds."""
        value = self.defaults.get(key, DEFAULTS.get(key))
        if key == "ramp_s" and value is not None and duration_s is not None:
            value = min(value, 0.5 * duration_s)
        return value


DRIVES: dict[str, Drive] = {}


def register(drive: Drive) -> Drive:
    """Add (or replace) a drive; every key needs a unit in UNITS."""
    unknown = [k for k in drive.keys if k not in UNITS]
    if unknown:
        raise ValueError(f"drive {drive.name!r}: settings without a unit in UNITS: {unknown}")
    DRIVES[drive.name] = drive
    return drive


def get(name: str, where: str = "drive") -> Drive:
    """The drive of that name, or a ParameterError naming ``where`` and the drives allowed."""
    if name not in DRIVES:
        raise ParameterError(f"{where} = {name!r}; allowed: {', '.join(sorted(DRIVES))}")
    return DRIVES[name]


def of_array(ex: np.ndarray) -> Drive:
    """The (first registered) drive whose force shape an excitation array has."""
    code = int(ex[cx.X_KIND])
    for drive in DRIVES.values():
        if drive.code == code:
            return drive
    raise ParameterError(f"the excitation array's force shape {code} is no registered drive's")


def complete(name: str, given: dict, needs: Callable[[str], str], where: str = "drive",
             duration_s: float | None = None) -> dict:
    """The settings {"drive": name, key: value} of a drive: each key's value given, else its
    default (:meth:`Drive.default` for a run of ``duration_s``); a key with neither raises a
    ParameterError saying ``needs(key)`` (how to give it, in the caller's words)."""
    drive = get(name, where)
    settings = {"drive": drive.name}
    for key in drive.keys:
        value = given[key] if key in given else drive.default(key, duration_s)
        if value is None:
            raise ParameterError(needs(key))
        settings[key] = value
    return settings


def all_keys() -> list[str]:
    """Every setting of every drive."""
    return sorted({k for d in DRIVES.values() for k in d.keys})


def excitation_array(settings: dict, first_in_chain: bool = True) -> np.ndarray:
    """The kernel's excitation array of {"drive": ..., key: value} (every key of the drive
    present, user units); a ramped drive not first in a stepped chain has no soft start."""
    e = dict(settings)
    drive = get(e.pop("drive"))
    if drive.ramped and not first_in_chain:
        e["ramp_s"] = 0.0
    return drive.build(e)


def start_keywords(settings: dict, names: dict | None = None) -> dict:
    """The keywords of :func:`~workbench.model.simulate.simulate` that set the drive's start,
    checked (a ParameterError names a setting as ``names`` maps it: an option, a study key)."""
    names = names or {}
    return get(settings["drive"]).start(settings, lambda key: names.get(key, key))


def band_hz(settings: dict) -> tuple[float, float] | None:
    """The frequency band (Hz) a swept drive covers, else None."""
    if not get(settings["drive"]).swept:
        return None
    return tuple(sorted((settings["f0_hz"], settings["f1_hz"])))


def drive_hz(settings: dict) -> float | None:
    """The forcing frequency (Hz) of a drive that has one, else None."""
    key = get(settings["drive"]).frequency_key
    return settings.get(key) if key else None


register(Drive("none", (), lambda e: none()))
register(Drive("sine", ("force_n", "freq_hz", "ramp_s"), lambda e: sine(**e),
               code=cx.EXC_SINE, check=_check_sine, ramped=True, frequency_key="freq_hz"))
register(Drive("chirp", ("force_n", "f0_hz", "f1_hz", "sweep_s", "ramp_s"), lambda e: chirp(**e),
               code=cx.EXC_CHIRP, check=_check_chirp, ramped=True, swept=True))
register(Drive("free_decay", ("deflection_cm",), lambda e: none(),
               start=_release))
register(Drive("hammer_joint", ("force_n", "width_s", "t_hit_s"), lambda e: hammer_joint(**e),
               code=cx.EXC_HAMMER_JOINT, check=_check_pulse, dt_max=_pulse_dt, output_hz=_pulse_hz,
               defaults={"force_n": DEFAULT_HAMMER_N}))
register(Drive("hammer_tip", ("force_n", "width_s", "t_hit_s"), lambda e: hammer_tip(**e),
               code=cx.EXC_HAMMER_TIP, check=_check_pulse, dt_max=_pulse_dt, output_hz=_pulse_hz,
               defaults={"force_n": DEFAULT_HAMMER_N}))
