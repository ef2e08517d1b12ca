"""Convergence order of RK4 and ARS(3,4,3) with the joint locked (no contact, no events).

    PYTHONPATH=. python benchmarks/ars343/order.py      # in the patched worktree

The 20 N sine at 20 Hz (0.2 s ramp) for 0.2 s from rest, s, v and psi held
(tip mass, 1.016 mm, cubic cork), each method at 2e-4 ... 2.5e-5 s against
itself at 2e-6 s: the largest error of w_B (cm) and its ratio to the
error at twice the step (16 for order 4, 8 for order 3).
"""
import numpy as np

from workbench.model import packing as mdl
from workbench.model.excitation import sine
from workbench.model.params import Parameters
from workbench.model.simulate import simulate

STEPS = (2e-4, 1e-4, 5e-5, 2.5e-5)
REFERENCE_DT = 2e-6


def main():
    p = Parameters().replace(gap_mm=1.016, cork="cubic", tip_mass=True)
    ex = sine(20.0, 20.0, ramp_s=0.2)
    start = np.zeros(18)
    for method in ("rk4", "ars343"):
        def run(dt):
            return simulate(p, ex, 0.2, dt=dt, fixed=mdl.JOINT, method=method, initial=start)
        ref = run(REFERENCE_DT)
        prev = None
        for dt in STEPS:
            r = run(dt)
            if not r.ok:
                print(f"{method} at {dt:g} s: {r.message}")
                continue
            err = float(np.abs(r.states[:, 6] - ref.states[:, 6]).max())
            ratio = f", ratio {prev / err:.2f}" if prev else ""
            print(f"{method} at {dt:g} s: w_B error {err:.3e} cm{ratio}")
            prev = err


if __name__ == "__main__":
    main()
