"""The default step against a quarter and an eighth of it at the top of the shaker grid.

    python benchmarks/chatter_grid.py          # 16 points, 3 steps each: about 5 minutes

The shaker study's points at 50 and 55 Hz (200 N, cubic cork, every gap,
the tip mass on and off; 10 s from the static equilibrium, 1 s ramp),
each at ``default_dt``, at a quarter and at an eighth of it.  Prints, for
the default step and the quarter step against the eighth: the largest
difference of the contact time shares over the last 2 s and the relative
difference of the tip's rms over them (the shaker study's window and its
metrics, ``metrics.point_metrics``), and the events of the whole run.
"""
from workbench.model.excitation import sine
from workbench.model.params import Parameters
from workbench.model.regimes import CONTACT_CODES
from workbench.model.simulate import default_dt, simulate
from workbench.study.metrics import point_metrics

DURATION_S = 10.0
WINDOW_S = 2.0
DIVISORS = (1, 4, 8)


def window_stats(run, freq_hz):
    """Contact time shares by contact code and the tip's rms (cm) over the study's window."""
    m = point_metrics(run, WINDOW_S, freq_hz)
    return {c: m[f"share_{c}"] for c in CONTACT_CODES}, m["tip_rms"]


def main():
    for tip in (False, True):
        for freq in (50.0, 55.0):
            for gap in (0.508, 0.635, 0.762, 1.016):
                p = Parameters().replace(gap_mm=gap, cork="cubic", tip_mass=tip)
                ex = sine(200.0, freq, ramp_s=1.0)
                dt = default_dt(p)
                runs = {k: simulate(p, ex, DURATION_S, dt=dt / k) for k in DIVISORS}
                ref_shares, ref_rms = window_stats(runs[DIVISORS[-1]], freq)
                parts = []
                for k in DIVISORS[:-1]:
                    shares, rms = window_stats(runs[k], freq)
                    diff = max(abs(shares[c] - ref_shares[c]) for c in CONTACT_CODES)
                    parts.append(f"dt/{k}: shares {diff:.1e}, tip rms {abs(rms - ref_rms) / ref_rms:.1e}, "
                                 f"{len(runs[k].log) - 1} events")
                print(f"tip mass {'on' if tip else 'off'}, {freq:g} Hz, {gap} mm (dt = {dt:.4g} s): "
                      + "; ".join(parts) + f"; dt/{DIVISORS[-1]}: {len(runs[DIVISORS[-1]].log) - 1} events",
                      flush=True)


if __name__ == "__main__":
    main()
