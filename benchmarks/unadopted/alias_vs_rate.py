"""The record's analog channels against the internal sample rate, on one trajectory.

    python benchmarks/unadopted/alias_vs_rate.py tip|notip

Runs the 10 s sine (1.016 mm, 20 Hz, 200 N, cubic cork) at the default settings, then the
same trajectory sampled on a lattice 2 and 4 times finer (dt / 2^n with the largest step,
the smallest step and the first step unchanged, so the steps and events are the same: the
non-analog channels agree exactly), and prints each analog channel's largest difference
(of its range) against the 4x record.  At e01daef (branch exp/lazy-dense) the default internal
rate is f_model + f (5 and 8 kHz) instead of 2 f_model + f (10 and 16 kHz).
"""
import sys

import numpy as np

import workbench as wb
import workbench.model.simulate as S
from workbench.core import layout as ly
from workbench.model.antialias import ANALOG


def record(tip: bool, halvings: int):
    p = wb.Parameters().replace(gap_mm=1.016, tip_mass=tip, cork="cubic")
    ex = wb.sine(200.0, 20.0, ramp_s=1.0)
    if halvings == 0:
        return wb.simulate(p, ex, duration=10.0)
    dt0, f = (1e-4 if tip else 6.25e-5), 2 ** halvings
    write, controller, internal = S.write_tableau, S._controller, S.antialias.internal_decimation

    def write_scaled(P, tab):
        write(P, tab)
        P[ly.P_RK_STEP_FACTOR] *= f

    def first_step(controlled, tol, level_max):
        c, s = controller(controlled, tol, level_max)
        c[0][0][ly.CTL_H_NEXT] = dt0
        return c, s
    S.write_tableau, S._controller = write_scaled, first_step
    S.antialias.internal_decimation = lambda decim, dt, fm: 1
    try:
        return S.simulate(p, ex, duration=10.0, dt=dt0 / f, level_max=8 + halvings,
                          method="dop853")
    finally:
        S.write_tableau, S._controller, S.antialias.internal_decimation = (write, controller,
                                                                           internal)


def main():
    tip = sys.argv[1] == "tip"
    runs = {n: record(tip, n) for n in (0, 1, 2)}
    ref = runs[2].signals
    for n in (0, 1):
        print(f"internal {runs[n].anti_alias['internal_hz']:g} Hz against "
              f"{runs[2].anti_alias['internal_hz']:g} Hz")
        for c in ref.columns:
            x, y = ref[c].to_numpy(float), runs[n].signals[c].to_numpy(float)
            d = np.max(np.abs(x - y)[100:-100]) / (np.ptp(x) or 1.0)
            if c in ANALOG or d > 0:
                print(f"  {c:10s} {d:.1e}")


if __name__ == "__main__":
    main()
