"""Whole 10 s sines at the default settings: RK4 at its default step against ARS(3,4,3).

Run in a worktree with ``ars343.patch`` applied (docs/performance.md, "ARS(3,4,3) in the
kernel: whole runs"):

    PYTHONPATH=. python benchmarks/ars343/sine_speed.py tip 2.5e-4 2e-4
    PYTHONPATH=. python benchmarks/ars343/sine_speed.py notip 2.5e-4 2e-4 1.25e-4

The 10 s sine (1.016 mm, 20 Hz, 200 N, cubic cork, 1 s ramp), with or without
the tip mass; RK4 at ``default_dt`` and ARS(3,4,3) at each given step (s),
alternately, ROUNDS rounds in one process.  Prints the median wall of each,
simulated seconds per wall second, the ratio to RK4 and the events.
"""
import statistics
import sys

from workbench.model.excitation import sine
from workbench.model.params import Parameters
from workbench.model.simulate import simulate

ROUNDS = 3


def main(argv):
    tip = argv[0] == "tip"
    p = Parameters().replace(gap_mm=1.016, cork="cubic", tip_mass=tip)
    ex = sine(200.0, 20.0, ramp_s=1.0)
    configs = [("rk4", None)] + [("ars343", float(a)) for a in argv[1:]]
    walls = {c: [] for c in configs}
    last = {}
    for _ in range(ROUNDS):
        for method, dt in configs:
            run = simulate(p, ex, 10.0, method=method, dt=dt)
            walls[(method, dt)].append(run.wall_s)
            last[(method, dt)] = run
    base = statistics.median(walls[configs[0]])
    for c in configs:
        w = statistics.median(walls[c])
        run = last[c]
        print(f"{'tip mass' if tip else 'no tip mass'}, {c[0]} at {run.dt:.4g} s: status "
              f"{run.status}, {len(run.log) - 1} events, median wall {w:.3f} s "
              f"({10.0 / w:.1f} simulated s per s, x{base / w:.2f}); walls "
              f"{', '.join(f'{x:.3f}' for x in walls[c])}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
