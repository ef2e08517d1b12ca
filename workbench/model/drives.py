"""The drives a run can have, in one registry.

A drive is named by its kind (``sine``, ``chirp``, ...) and set by a few
settings in user units (``force_n``, ``freq_hz``, ...): the keys of a
study's ``[excitation]`` table, of an experiment file's ``WB_`` settings,
and of ``workbench compare``'s options.  Each :class:`Drive` says which
settings it takes, how they build the kernel's excitation array
(:mod:`workbench.model.excitation`), and, for a drive that is a start
rather than a force (a free decay), the keywords of
:func:`workbench.model.simulate.simulate` that set the start.  Studies,
matching and reports read this registry; adding a drive is one
:func:`register` call (and a builder in :mod:`workbench.model.excitation`
if the kernels need a new kind of force).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from . import excitation as X
from .params import ParameterError

#: Defaults of the settings a drive may leave out (user units).
#: A hammer hits 10 ms into the record, as a lab's pretrigger keeps the record's start quiet.
DEFAULTS = {"force_n": X.DEFAULT_FORCE_N, "ramp_s": 0.0, "width_s": 1e-3, "t_hit_s": 0.01,
            "deflection_cm": 8.4}
#: The unit of every setting.
UNITS = {"force_n": "N", "freq_hz": "Hz", "f0_hz": "Hz", "f1_hz": "Hz", "sweep_s": "s",
         "ramp_s": "s", "width_s": "s", "t_hit_s": "s", "deflection_cm": "cm"}


@dataclass(frozen=True)
class Drive:
    """One kind of drive (module docstring)."""

    kind: str
    keys: tuple[str, ...]                          # its settings, in order
    build: Callable[[dict], np.ndarray]            # settings -> the kernel's excitation array
    ramped: bool = False                           # a soft start (ramp_s), dropped inside a stepped chain
    frequency_key: str | None = None               # the setting that is the forcing frequency
    swept: bool = False                            # the frequency sweeps over the run (chirp figures)
    start: Callable[[dict], dict] = field(default=lambda settings: {})   # simulate() keywords


DRIVES: dict[str, Drive] = {}


def register(drive: Drive) -> Drive:
    """Add (or replace) a drive; every key needs a unit in UNITS."""
    unknown = [k for k in drive.keys if k not in UNITS]
    if unknown:
        raise ValueError(f"drive {drive.kind!r}: settings without a unit in UNITS: {unknown}")
    DRIVES[drive.kind] = drive
    return drive


def get(kind: str, where: str = "kind") -> Drive:
    """The drive of that kind, or a ParameterError naming ``where`` and the kinds allowed."""
    if kind not in DRIVES:
        raise ParameterError(f"{where} = {kind!r}; allowed: {', '.join(sorted(DRIVES))}")
    return DRIVES[kind]


def complete(kind: str, given: dict, needs: Callable[[str], str], where: str = "kind") -> dict:
    """The settings {"kind": kind, key: value} of a drive: each key's value given, else its
    default; a key with neither raises a ParameterError saying ``needs(key)`` (how to give
    it, in the caller's words)."""
    drive = get(kind, where)
    settings = {"kind": drive.kind}
    for key in drive.keys:
        if key in given:
            settings[key] = given[key]
        elif key in DEFAULTS:
            settings[key] = DEFAULTS[key]
        else:
            raise ParameterError(needs(key))
    return settings


def all_keys() -> list[str]:
    """Every setting of every drive."""
    return sorted({k for d in DRIVES.values() for k in d.keys})


def excitation_array(settings: dict, first_in_chain: bool = True) -> np.ndarray:
    """The kernel's excitation array of {"kind": ..., key: value} (every key of the kind
    present, user units); a ramped drive not first in a stepped chain has no soft start."""
    e = dict(settings)
    drive = get(e.pop("kind"))
    if drive.ramped and not first_in_chain:
        e["ramp_s"] = 0.0
    return drive.build(e)


def start_keywords(settings: dict) -> dict:
    """The keywords of :func:`~workbench.model.simulate.simulate` that set the drive's start."""
    return get(settings["kind"]).start(settings)


def band_hz(settings: dict) -> tuple[float, float] | None:
    """The frequency band (Hz) a swept drive covers, else None."""
    if not get(settings["kind"]).swept:
        return None
    return tuple(sorted((settings["f0_hz"], settings["f1_hz"])))


def drive_hz(settings: dict) -> float | None:
    """The forcing frequency (Hz) of a drive that has one, else None."""
    key = get(settings["kind"]).frequency_key
    return settings.get(key) if key else None


register(Drive("none", (), lambda e: X.none()))
register(Drive("sine", ("force_n", "freq_hz", "ramp_s"),
               lambda e: X.sine(e["force_n"], e["freq_hz"], e["ramp_s"]),
               ramped=True, frequency_key="freq_hz"))
register(Drive("chirp", ("force_n", "f0_hz", "f1_hz", "sweep_s", "ramp_s"),
               lambda e: X.chirp(e["force_n"], e["f0_hz"], e["f1_hz"], e["sweep_s"], e["ramp_s"]),
               ramped=True, swept=True))
register(Drive("free_decay", ("deflection_cm",), lambda e: X.none(),
               start=lambda e: {"free_decay_cm": e["deflection_cm"]}))
register(Drive("hammer_joint", ("force_n", "width_s", "t_hit_s"),
               lambda e: X.hammer_joint(e["force_n"], e["width_s"], e["t_hit_s"])))
register(Drive("hammer_tip", ("force_n", "width_s", "t_hit_s"),
               lambda e: X.hammer_tip(e["force_n"], e["width_s"], e["t_hit_s"])))
