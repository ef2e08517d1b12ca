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

from .limits import ACCEL_RANGE_G, FORCE_RANGE_N, VALID_TIP_CM

#: Standard gravity (cm/s²) and a newton (dyn).
G_CM_S2 = 980.665
N_DYN = 1e5


def tip_peak_cm(run) -> float:
    """The tip's largest deflection (cm) from its static equilibrium over the run."""
    return float(np.nanmax(np.abs(run.signals.tip_y.to_numpy() - run.static_tip_y)))


def accel_peak_g(run) -> float:
    """The largest |acceleration| of accel1-3 (g) over the run: what saturates a sensor."""
    return float(max(np.abs(run.signals[c].to_numpy()).max()
                     for c in ("accel1", "accel2", "accel3"))) / G_CM_S2


def validity(run) -> dict:
    """The run's largest responses against the range the model is validated for (module
    docstring); ``run`` has ``signals``, ``static_tip_y`` and ``params``."""
    sig = run.signals
    tip = tip_peak_cm(run)
    slide = float(np.abs(sig.s.to_numpy()).max())
    force = float(np.abs(sig.force1.to_numpy()).max())
    out = {"tip_abs_max_cm": tip, "slide_abs_max_cm": slide, "accel_abs_max_g": accel_peak_g(run),
           "force1_abs_max_n": force / N_DYN}
    over = [name for name, value, limit in (
        ("tip", tip, VALID_TIP_CM), ("slot", slide, run.params.s_travel),
        ("accel", out["accel_abs_max_g"], ACCEL_RANGE_G),
        ("force", out["force1_abs_max_n"], FORCE_RANGE_N)) if value > limit]
    out["out_of_range"] = ",".join(over)
    return out
