"""A response-limited drive: the force of each point set so that the tip stays within a level.

The paper's operator set the shaker's amplitude trial by trial "so as to not saturate the
sensors" (seed §5.2), and a vibration controller limits a response the same way.  A study
with ``tip_limit_cm`` in [study] does it by a stated rule, for drives with a force
(``force_n``: sine, chirp, hammers):

1. run the point at its force F (the study's ``force_n``, the most it may use);
2. if the tip's largest deflection from its static equilibrium over the run, A, is within
   the level L, keep the run;
3. else run again at F * LEVEL_MARGIN * L / A (the response is nearly proportional to the
   force between changes of contact), at most LEVEL_RUNS runs in all; the last run is kept,
   and ``level_met`` says whether it met the level.

The point's row keeps ``force_n_used`` (N), ``level_runs`` and ``level_met``.  The same
rule limits any other peak (``metrics.accel_peak_g``: the accelerometers' range, as the paper's
operator kept the sensors from saturating).
"""
from __future__ import annotations

from typing import Callable

from .metrics import tip_peak_cm

#: The runs a point may take to meet its level, and the margin below the level aimed at.
LEVEL_RUNS = 5
LEVEL_MARGIN = 0.97


def limited_run(simulate_at: Callable[[float], object], force_n: float, limit: float,
                peak: Callable[[object], float] = tip_peak_cm):
    """The run (``simulate_at(force)``) whose ``peak`` (default the tip's, cm) stays within
    ``limit`` by the rule of the module docstring, starting from ``force_n``.  Returns (run,
    force used, runs, met)."""
    force = force_n
    for runs in range(1, LEVEL_RUNS + 1):
        run = simulate_at(force)
        if not run.ok:
            return run, force, runs, False
        value = peak(run)
        if value <= limit:
            return run, force, runs, True
        if runs < LEVEL_RUNS:
            force = force * LEVEL_MARGIN * limit / value
    return run, force, LEVEL_RUNS, False
