"""Time a run spends in each regime, and in that regime's intervals longer than a few ms.

    python benchmarks/regime_time.py [force_n]

The 10 s sine (1.016 mm, 20 Hz, cubic cork; 200 N unless given), with and
without the tip mass, at the default step: the time between consecutive
events, summed by the regime entered (docs/performance.md, "The axial
modes integrated exactly").
"""
import sys

import numpy as np

from workbench.model.excitation import sine
from workbench.model.params import Parameters
from workbench.model.simulate import simulate

DURATION_S = 10.0
LONGER_THAN_S = (1e-3, 5e-3, 2e-2)


def main(force_n: float) -> None:
    for tip in (True, False):
        params = Parameters().replace(gap_mm=1.016, cork="cubic", tip_mass=tip)
        run = simulate(params, sine(force_n, 20.0, ramp_s=1.0), DURATION_S)
        events = run.events
        regimes = events.to_regime.to_numpy().astype(int)
        spans = np.diff(np.r_[events.t.to_numpy(), DURATION_S])
        print(f"tip mass {tip}: {len(events)} events")
        for r in sorted(set(regimes.tolist())):
            mine = regimes == r
            longer = "  ".join(f"> {lim:g} s: {spans[mine & (spans > lim)].sum():.2f}"
                               for lim in LONGER_THAN_S)
            print(f"  regime {r:2d}: {spans[mine].sum():6.3f} s   {longer}")


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 200.0)
