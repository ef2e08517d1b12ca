"""The simulation that matches a record: its model parameters, excitation and length.

A record's settings come from its file (``WB_`` keys, :mod:`workbench.lab.files`)
and from the command line, which wins.  The keys are those of a study
(:mod:`workbench.study.definition`): ``drive`` (a kind of
:mod:`workbench.model.drives`: sine, chirp, free_decay, hammer_joint,
hammer_tip, none) with its settings (``freq_hz``, ``force_n``, ...), and any model parameter of
``workbench params`` (``gap_mm``, ``tip_mass``, ``cork``, ``e_b_gpa``, ...).
The duration and sample rate are the record's.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..model.params import ParameterError, Parameters, resolve_name
from ..model import drives

if TYPE_CHECKING:
    import pandas as pd


@dataclass(frozen=True)
class Setup:
    """One simulation: parameters, excitation settings (user units), length (s), rate (Hz),
    and its start ("static" or "paper", as :func:`~workbench.model.simulate.simulate`)."""

    params: Parameters
    excitation: dict
    duration: float
    output_hz: float
    initial: str = "static"

    def simulate(self, params: Parameters | None = None, excitation: dict | None = None):
        """Run it (optionally with other parameters or excitation settings)."""
        from ..model.simulate import simulate

        exc = excitation or self.excitation
        return simulate(params or self.params, drives.excitation_array(exc), self.duration,
                        output_hz=self.output_hz, initial=self.initial,
                        **drives.start_keywords(exc))


def settings_of(excitation: dict, params: Parameters) -> dict:
    """The settings to write with a simulated record (``WB_`` keys), which
    :func:`setup_from` reads back: the drive, its settings, and the model parameters
    that differ from the defaults (CGS names)."""
    return {**excitation, **params.changed()}


def setup_from(settings: dict, record: pd.DataFrame, base: Parameters | None = None) -> Setup:
    """The Setup of ``record`` from its settings (module docstring)."""
    settings = dict(settings)
    kind = settings.pop("drive", "none")
    t = record.index.to_numpy(dtype=float)
    rate = 1.0 / float(np.median(np.diff(t)))
    output_hz = float(round(rate))
    if abs(output_hz - rate) > 1e-6 * rate:
        raise ParameterError(f"the record's sample rate {rate} Hz is not a whole number of Hz")
    duration = round(float(t[-1] - t[0]) * output_hz) / output_hz
    given = {}
    for key in drives.get(kind, where="drive").keys:
        if key in settings:
            value = settings.pop(key)
            try:
                given[key] = float(value)
            except (TypeError, ValueError, OverflowError):
                raise ParameterError(f"{key} = {value!r} is not a number (WB_{key} in the file, "
                                     "or its option)") from None
    exc = drives.complete(kind, given, lambda key: f"a {kind} drive needs {key} (in the file as "
                          f"WB_{key}, or on the command line)", where="drive",
                          duration_s=duration)
    for key in [k for k in settings if k in drives.all_keys()]:
        raise ParameterError(f"{key} does not apply to a {kind} drive")
    for key in settings:
        resolve_name(key)                 # names the parameter if it is unknown
    params = (base or Parameters()).replace(**settings) if settings else (base or Parameters())
    drives.excitation_array(exc)          # validates the values
    return Setup(params, exc, duration, output_hz)
