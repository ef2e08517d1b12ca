"""The default step against a quarter and an eighth of it at the top of the shaker grid.

    python benchmarks/chatter_grid.py          # 16 points, 3 steps each: about 5 minutes

The shaker study's points at 50 and 55 Hz (200 N, cubic cork, every gap,
the tip mass on and off; 10 s from the static equilibrium, 1 s ramp),
each at ``default_dt``, at a quarter and at an eighth of it.  Prints, for
the default step and the quarter step against the eighth: the largest
difference of the contact time shares over the last 2 s (the study's
window; from the 1 kHz samples, so to 5e-4), the relative difference of
the tip height's rms over them, and the events of the whole run.
"""
import numpy as np

from workbench.model.excitation import sine
from workbench.model.params import Parameters
from workbench.model.simulate import default_dt, simulate

DURATION_S = 10.0
WINDOW_FROM_S = 8.0
DIVISORS = (1, 4, 8)


def window_stats(run):
    """Contact time shares (by contact code, from the samples) and the tip's rms (cm)."""
    sig = run.signals
    w = sig[sig.index >= WINDOW_FROM_S]
    return w["contact_code"].value_counts(normalize=True).to_dict(), float(np.std(w["tip_y"]))


def main():
    for tip in (False, True):
        for freq in (50.0, 55.0):
            for gap in (0.508, 0.635, 0.762, 1.016):
                p = Parameters().replace(gap_mm=gap, cork="cubic", tip_mass=tip)
                ex = sine(200.0, freq, ramp_s=1.0)
                dt = default_dt(p)
                runs = {k: simulate(p, ex, DURATION_S, dt=dt / k) for k in DIVISORS}
                ref_shares, ref_rms = window_stats(runs[DIVISORS[-1]])
                parts = []
                for k in DIVISORS[:-1]:
                    shares, rms = window_stats(runs[k])
                    codes = set(shares) | set(ref_shares)
                    diff = max(abs(shares.get(c, 0.0) - ref_shares.get(c, 0.0)) for c in codes)
                    parts.append(f"dt/{k}: shares {diff:.1e}, tip rms {abs(rms - ref_rms) / ref_rms:.1e}, "
                                 f"{len(runs[k].log) - 1} events")
                print(f"tip mass {'on' if tip else 'off'}, {freq:g} Hz, {gap} mm (dt = {dt:.4g} s): "
                      + "; ".join(parts) + f"; dt/{DIVISORS[-1]}: {len(runs[DIVISORS[-1]].log) - 1} events",
                      flush=True)


if __name__ == "__main__":
    main()
