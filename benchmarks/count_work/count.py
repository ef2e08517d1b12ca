"""Work counts of the 10 s sine benchmark (1.016 mm, 20 Hz, cubic cork): right-hand
sides per step, trial states and brackets of event location.

The kernel keeps no counters; ``counters.patch`` (next to this file) adds
them to the regime record rg.  Apply it in a worktree, never in the
checkout you work in (any edit of ``workbench/core`` recompiles every
kernel):

    git worktree add /tmp/count HEAD
    (cd /tmp/count && git apply benchmarks/count_work/counters.patch)
    PYTHONPATH=/tmp/count python benchmarks/count_work/count.py 200 [--no-tip]

Arguments: the drive amplitude (N); ``--no-tip`` takes the tip mass off.
"""
import sys
import time

from workbench.core import layout as ly
from workbench.model import excitation, packing
from workbench.model.params import Parameters
from workbench.model import simulate as S


def main(argv):
    force = float(argv[0])
    tip = "--no-tip" not in argv
    works = []
    make_work = packing.make_work

    def recorded():
        works.append(make_work())
        return works[-1]

    packing.make_work = recorded
    p = Parameters(cork="cubic", tip_mass=tip).replace(gap_mm=1.016)
    ex = excitation.sine(force, 20.0, ramp_s=1.0)
    S.simulate(p, ex, 0.2)                      # compile or load the cache
    works.clear()
    t = time.perf_counter()
    run = S.simulate(p, ex, 10.0)
    wall = time.perf_counter() - t
    rhs, trials, grazes, brackets, applied = works[-1].rg[ly.RG_CNT:ly.RG_CNT + 5]
    steps = round(10.0 / run.dt)
    print(f"{force:g} N, tip mass {'on' if tip else 'off'}: wall {wall:.2f} s, "
          f"{len(run.events)} events, {steps} steps")
    print(f"right-hand sides {rhs:.0f} ({rhs / steps:.2f} per step); trial states {trials:.0f} "
          f"in {brackets:.0f} brackets ({trials / max(brackets, 1):.1f} per bracket, the "
          f"grazing checks' included); "
          f"grazing checks with trials {grazes:.0f}; events applied {applied:.0f}")


if __name__ == "__main__":
    main(sys.argv[1:])
