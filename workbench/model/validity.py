"""The range a run's response is validated for, and where a run leaves it.

Over the whole run: ``tip_abs_max_cm`` (the tip's largest deflection from its static
equilibrium), ``slide_abs_max_cm`` (the loose body's largest |s|), ``accel_abs_max_g``
(the largest |accel1-3|, in g), ``force1_abs_max_n``; ``out_of_range`` names the limits
the run exceeds, comma separated ("" within all): ``tip`` beyond VALID_TIP_CM (the
paper's 8.4 cm: the small-slope beam shapes were compared with the rig up to there),
``slot`` beyond the slot's travel s_travel (the end stop, an ASSUMPTION, carries the
body), ``accel`` and ``force`` beyond the sensors' ranges (ACCEL_RANGE_G, FORCE_RANGE_N:
a measured record would be clipped there).  Every run's summary, a sweep's rows and the
leveling search (:mod:`workbench.study.leveling`) read them here.
"""
from __future__ import annotations

import numpy as np

from .shown_units import SI

from ..core import layout as ly
from .limits import ACCEL_RANGE_G, FORCE_RANGE_N, VALID_TIP_CM

#: Standard gravity (cm/s²) and a newton (dyn).
G_CM_S2 = 980.665
N_DYN = 1e5


def _column(run, name: str) -> np.ndarray:
    """A run's samples of one signal (or the slide ``s``), from its arrays when it has them
    (no DataFrame built), else from its ``signals`` table."""
    if hasattr(run, "sensors"):
        return run.states[:, ly.S] if name == "s" else run.signal(name)
    return run.signals[name].to_numpy()


def tip_peak_cm(run) -> float:
    """The tip's largest deflection (cm) from its static equilibrium over the run."""
    return float(np.nanmax(np.abs(_column(run, "tip_y") - run.static_tip_y)))


def accel_peak_g(run) -> float:
    """The largest |acceleration| of accel1-3 (g) over the run: what saturates a sensor."""
    return float(max(np.abs(_column(run, c)).max()
                     for c in ("accel1", "accel2", "accel3"))) / G_CM_S2


#: Each limit of the validated range: its response's column, unit and name in words.  The words
#: give lengths in mm (SI as the field writes them, :data:`~workbench.model.shown_units.SI`).
RESPONSES = {"tip": ("tip_abs_max_cm", "cm", "tip deflection"),
             "slot": ("slide_abs_max_cm", "cm", "slide"),
             "accel": ("accel_abs_max_g", "g", "acceleration"),
             "force": ("force1_abs_max_n", "N", "force1")}


def validated_limits(params) -> dict[str, float]:
    """The validated range's limits (module docstring), in the units of RESPONSES."""
    return {"tip": VALID_TIP_CM, "slot": params.s_travel, "accel": ACCEL_RANGE_G,
            "force": FORCE_RANGE_N}


def validity(run) -> dict:
    """The run's largest responses against the range the model is validated for (module
    docstring); ``run`` has ``signals``, ``static_tip_y`` and ``params``."""
    out = {"tip_abs_max_cm": tip_peak_cm(run),
           "slide_abs_max_cm": float(np.abs(_column(run, "s")).max()),
           "accel_abs_max_g": accel_peak_g(run),
           "force1_abs_max_n": float(np.abs(_column(run, "force1")).max()) / N_DYN}
    limits = validated_limits(run.params)
    out["out_of_range"] = ",".join(name for name, (column, _, _) in RESPONSES.items()
                                   if out[column] > limits[name])
    return out


def exceeded_words(responses: dict, params) -> str:
    """Each limit ``responses`` (validity's columns) exceed, with value and limit, in words."""
    limits = validated_limits(params)
    words = []
    for k in filter(None, responses["out_of_range"].split(",")):
        column, unit, name = RESPONSES[k]
        shown, factor = SI[unit]
        words.append(f"{name} {responses[column] * factor:.3g} {shown} > "
                     f"{limits[k] * factor:.3g} {shown}")
    return "; ".join(words)
