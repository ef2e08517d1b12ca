"""Whole runs at the default settings: RK4 at its default step against ARS(3,4,3) and the
axial coordinates held.

Run in a worktree with ``ars343.patch`` applied (docs/performance.md, "ARS(3,4,3) in the
kernel: whole runs"):

    PYTHONPATH=. python benchmarks/ars343/sine_speed.py tip 2.5e-4 2e-4
    PYTHONPATH=. python benchmarks/ars343/sine_speed.py notip 2.5e-4 2e-4 1.25e-4
    PYTHONPATH=. python benchmarks/ars343/sine_speed.py chirp 2.5e-4
    python benchmarks/ars343/sine_speed.py tip --held 5e-4      # no patch needed

``tip`` and ``notip`` are the 10 s sines of ``accuracy_side_by_side.cases``
at 200 N (1.016 mm, 20 Hz, cubic cork), ``chirp`` the 240 s chirp of
``make bench`` (5-65 Hz, 200 N, tip mass; one round, 500 Hz output).  RK4
at ``default_dt``, then ARS(3,4,3) at each given step (s), and with
``--held DT`` RK4 at DT with u_A and u_B held at their static values,
alternately, ROUNDS rounds in one process.  Prints the median wall of
each, simulated seconds per wall second, the ratio to RK4 and the events.
"""
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from accuracy_side_by_side import cases  # noqa: E402

from workbench.model.excitation import chirp  # noqa: E402
from workbench.model.simulate import simulate  # noqa: E402

ROUNDS = 3
HELD = ("u_A", "u_B")


def main(argv):
    which = argv[0]
    args = argv[1:]
    configs = [("rk4", None)]
    if "--held" in args:
        k = args.index("--held")
        configs.append(("held", float(args[k + 1])))
        del args[k:k + 2]
    configs += [("ars343", float(a)) for a in args]
    output_hz, rounds = 1000.0, ROUNDS
    if which == "chirp":
        p, _, _, _ = cases()["sine tip 200 N"]
        ex, duration, output_hz, rounds = chirp(200.0, 5.0, 65.0, 240.0, ramp_s=1.0), 240.0, 500.0, 1
    else:
        p, ex, duration, _ = cases()["sine tip 200 N" if which == "tip" else "sine no tip 200 N"]
    walls = {c: [] for c in configs}
    last = {}
    for _ in range(rounds):
        for method, dt in configs:
            extra = {"method": method} if method == "ars343" else {}
            run = simulate(p, ex, duration, dt=dt, output_hz=output_hz,
                           fixed=HELD if method == "held" else (), **extra)
            walls[(method, dt)].append(run.wall_s)
            last[(method, dt)] = run
    base = statistics.median(walls[configs[0]])
    for c in configs:
        w = statistics.median(walls[c])
        run = last[c]
        print(f"{which}, {c[0]} at {run.dt:.4g} s: status {run.status}, {len(run.log) - 1} events, "
              f"median wall {w:.3f} s ({duration / w:.1f} simulated s per s, x{base / w:.2f}); "
              f"walls {', '.join(f'{x:.3f}' for x in walls[c])}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
