"""A run's initial state: the static equilibrium, the paper's undeformed start, a given
state, or a free decay's deflected start."""
from __future__ import annotations

import numpy as np

from ..core import layout as ly
from .params import ParameterError, Parameters
from .regimes import is_stick, set_of
from .statics import static_equilibrium, tip_load_for_deflection


def initial_state(p: Parameters, initial="static", fixed=(), free_decay_cm: float | None = None,
                  static=None, regime: int = 0):
    """The augmented initial state (N_AUG,), its regime (set, stick) and a label.

    ``static`` is the gravity equilibrium if already solved (it is not
    solved again).

    ``initial``: "static" (equilibrium under gravity), "paper" (undeformed,
    at rest, loose body centred, free flight, seed §2.3) or an 18-vector
    (q, q') in the regime ``regime`` (0..16, default free flight; the
    kernel settles it, docs/model.md §7).  ``free_decay_cm`` deflects the tip
    statically by that much first (docs/model.md §8 free decay; implies the
    static start).
    """
    y = np.zeros(ly.N_AUG)
    if free_decay_cm is not None:
        _, eq = tip_load_for_deflection(p, free_decay_cm, fixed, base=static)
        y[:ly.N_DOF] = eq.q
        return y, (eq.contact_set, True), f"free decay from {free_decay_cm} cm"
    if isinstance(initial, str):
        if initial == "static":
            eq = static_equilibrium(p, 0.0, fixed) if static is None else static
            y[:ly.N_DOF] = eq.q
            return y, (eq.contact_set, True), "static"
        if initial == "paper":
            return y, (0, False), "paper"
        raise ParameterError(f"initial = {initial!r}: use 'static', 'paper' or an array of "
                             f"{ly.N_STATE} values (q, q')")
    arr = np.asarray(initial, dtype=float)
    if arr.shape != (ly.N_STATE,) or not np.all(np.isfinite(arr)):
        raise ParameterError(f"initial state must be {ly.N_STATE} finite values (q, q'), "
                             f"got shape {arr.shape}")
    if not (isinstance(regime, (int, np.integer)) and 0 <= regime <= 16):
        raise ParameterError(f"regime = {regime!r} is outside the allowed range 0..16")
    y[:ly.N_STATE] = arr
    return y, (set_of(int(regime)), is_stick(int(regime))), "given"
