"""The 10 s sine (1.016 mm, 20 Hz, 200 N, cubic cork) with ``lawson_locked.patch``'s step.

Run in a worktree with the patch applied (docs/performance.md, "Lawson
steps while the joint is locked"):

    PYTHONPATH=. python benchmarks/lawson_locked/sine_refresh.py tip     # or notip

Three alternating rounds of RK4 throughout and of Lawson steps while the
joint is locked with L recomputed every 1, 4 and 16 Lawson steps and once
per locked interval; prints the median wall, the ratio to RK4, and the
events, Lawson steps and operators of each.
"""
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from accuracy_side_by_side import cases  # noqa: E402

from workbench.model.simulate import simulate  # noqa: E402

p, ex, _, _ = cases()["sine tip 200 N" if sys.argv[1] == "tip" else "sine no tip 200 N"]
simulate(p, ex, 0.01)
configs = [("RK4", dict(lawson_locked=False))] + [
    (f"L every {m}", dict(lawson_refresh=m)) for m in (1, 4, 16)] + [
    ("L per interval", dict(lawson_refresh=1 << 30))]
walls = {name: [] for name, _ in configs}
info = {}
for _ in range(3):
    for name, kw in configs:
        run = simulate(p, ex, 10.0, **kw)
        walls[name].append(run.wall_s)
        info[name] = (run.status, len(run.log), run.stats["lawson_steps"],
                      run.stats["locked_operators"])
rk4 = statistics.median(walls["RK4"])
for name, _ in configs:
    wall = statistics.median(walls[name])
    status, events, lawson, ops = info[name]
    print(f"{name:15s} {wall:.3f} s ({10 / wall:5.1f} simulated s per s), x{rk4 / wall:.2f}; "
          f"status {status}, {events} events, {lawson} Lawson steps, {ops} operators")
