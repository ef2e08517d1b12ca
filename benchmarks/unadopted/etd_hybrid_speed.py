"""The hybrid exponential integrator's speed on the 10 s sines (experiment, not adopted).

    WORKBENCH_ETD=1 [WORKBENCH_ETD_TOLX=10] [WORKBENCH_ETD_AGE=0.01] [WORKBENCH_ETD_SAMPLES=1]
        python benchmarks/unadopted/etd_hybrid_speed.py tip|notip [duration_s]

Between events, on the internal sample lattice, ETDRK4 steps with the regime's Jacobian frozen
(workbench/core/exponential.py, run_adaptive's ``exp_on`` branch); every step with an event
candidate, or an estimate above WORKBENCH_ETD_TOLX times the tolerance, is taken again by the
pair.  WORKBENCH_ETD=0 runs the pair alone.  Prints the event loop's time (cProfile's count of
run_adaptive), the events, and the hybrid's counts: operators (Jacobian and phi functions)
taken, exponential steps kept, fallbacks to the pair (those for the estimate), the estimates'
histogram (log10 of the ratio, in quarters) of the fallbacks.
"""
import cProfile
import os
import pstats
import sys

from workbench.model.drives import sine
from workbench.model.params import Parameters
from workbench.model.simulate import simulate


def main():
    case = sys.argv[1]
    duration = float(sys.argv[2]) if len(sys.argv) > 2 else 10.0
    p = Parameters().replace(gap_mm=1.016, tip_mass=case == "tip", cork="cubic")
    ex = sine(200.0, 20.0, ramp_s=1.0)
    simulate(p, ex, 0.01)                       # compile or load, import the record's modules
    prof = cProfile.Profile()
    run = prof.runcall(simulate, p, ex, duration)
    loop = sum(v[3] for k, v in pstats.Stats(prof).stats.items() if k[2] == "run_adaptive")
    c = run.control
    keys = ("steps", "rejected", "etd_operators", "etd_steps", "etd_fallbacks", "etd_fall_err",
            "etd_err_hist")
    print(f"{case} ETD={os.environ.get('WORKBENCH_ETD', '0')} "
          f"TOLX={os.environ.get('WORKBENCH_ETD_TOLX', '1')}: event loop {loop:.2f} s, "
          f"ok {run.ok}, events {len(run.log)}", {k: c.get(k) for k in keys})


if __name__ == "__main__":
    main()
