"""Wall time of the 10 s sine (1.016 mm, cubic cork, 200 N, 20 Hz) at given steps,
alternating in one process so that the machine's noise falls on every step alike.

    python benchmarks/step_side_by_side.py --no-tip 5e-5 6.25e-5

Prints, per step, the median and the least wall time (s) of REPS runs.
"""
from __future__ import annotations

import statistics
import sys
import time

from workbench.model import excitation as X
from workbench.model.params import Parameters
from workbench.model.simulate import simulate

REPS = 7


def main(argv: list[str]) -> None:
    tip = "--no-tip" not in argv
    steps = [float(a) for a in argv if not a.startswith("--")]
    p = Parameters().replace(gap_mm=1.016, cork="cubic", tip_mass=tip)
    ex = X.sine(200.0, 20.0, ramp_s=1.0)
    simulate(p, ex, 0.1)                              # load the compiled kernels
    walls = {dt: [] for dt in steps}
    for _ in range(REPS):
        for dt in steps:
            start = time.perf_counter()
            run = simulate(p, ex, 10.0, dt=dt)
            walls[dt].append(time.perf_counter() - start)
            if not run.ok:
                raise SystemExit(f"dt = {dt}: {run.message}")
    for dt in steps:
        print(f"tip mass {'on' if tip else 'off'}, dt {dt:g} s: median {statistics.median(walls[dt]):.3f} s, "
              f"least {min(walls[dt]):.3f} s over {REPS} runs")


if __name__ == "__main__":
    main(sys.argv[1:])
