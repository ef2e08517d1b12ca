"""Wall time of the 10 s sine benchmark (1.016 mm, 20 Hz, tip mass, cubic cork) in this checkout.

Run it alternately in two checkouts to compare commits side by side, e.g.

    git worktree add /tmp/old 97d9386
    for i in 1 2 3; do
      (cd /tmp/old && PYTHONPATH=/tmp/old python benchmarks/sine_side_by_side.py 20 3)
      python benchmarks/sine_side_by_side.py 20 3
    done

Arguments: force (N), runs; ``--locked`` holds the joint (no contact events),
``--no-tip`` takes the tip mass off, ``--chirp`` runs the 240 s chirp of the
chirp study instead (5-65 Hz, output at 500 Hz).  The script imports the
checkout on PYTHONPATH, so this copy can time an older checkout too:

    (cd /tmp/old && PYTHONPATH=/tmp/old python /path/to/benchmarks/sine_side_by_side.py 200 1 --chirp)

Prints one JSON line: the wall times (s, simulation only), status, events.
"""
import json
import sys

from workbench.model import excitation, packing as model
from workbench.model.params import Parameters
from workbench.model.simulate import simulate


def main(argv):
    force, runs = float(argv[0]), int(argv[1])
    locked = "--locked" in argv
    tip = "--no-tip" not in argv
    kw = dict(fixed=model.JOINT, initial="paper") if locked else {}
    p = Parameters(cork="cubic", tip_mass=tip).replace(gap_mm=1.016)
    ex = excitation.sine(force, 20.0, ramp_s=1.0)
    duration = 10.0
    if "--chirp" in argv:
        ex = excitation.chirp(force, 5.0, 65.0, 240.0, ramp_s=1.0)
        duration, kw = 240.0, {**kw, "output_hz": 500.0}
    simulate(p, ex, 0.2, **kw)                      # compile / load the cache
    walls = []
    for _ in range(runs):
        run = simulate(p, ex, duration, **kw)
        walls.append(run.wall_s)
    print(json.dumps({"force_n": force, "locked": locked, "tip_mass": tip, "dt": run.dt,
                      "walls": walls, "status": run.status, "events": int(len(run.events))}))


if __name__ == "__main__":
    main(sys.argv[1:])
