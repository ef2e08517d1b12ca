"""Whole runs at the default settings: the default method beside fixed RK4, side by side.

    python benchmarks/controlled_speed.py [--rounds 3] [--chirp]

The 10 s sines (1.016 mm, 20 Hz, 200 N, cubic cork, 1 s ramp) with and
without the tip mass, each run in turn by the default method at its
default tolerance and by fixed RK4 at the default step and at a quarter of
it, ROUNDS times alternately; prints the median wall, simulated seconds per
wall second, events, the controlled run's steps (accepted and in all) and
its accepted intervals per step.  ``--chirp`` adds the 240 s chirp (5-65 Hz,
tip mass) once per method.
"""
from __future__ import annotations

import argparse
import statistics

from workbench.model.drives import chirp, sine
from workbench.model.params import Parameters
from workbench.model.step_policy import default_dt
from workbench.model.simulate import simulate


def cases(with_chirp: bool) -> dict:
    base = Parameters().replace(gap_mm=1.016, cork="cubic")
    out = {"sine tip": (base.replace(tip_mass=True), sine(200.0, 20.0, ramp_s=1.0), 10.0),
           "sine no tip": (base.replace(tip_mass=False), sine(200.0, 20.0, ramp_s=1.0), 10.0)}
    if with_chirp:
        out["chirp tip"] = (base.replace(tip_mass=True), chirp(200.0, 5.0, 65.0, 240.0, ramp_s=1.0),
                            240.0)
    return out


def methods(p, ex) -> dict:
    dt = default_dt(p, ex)
    return {"default": {}, "rk4 dt": {"dt": dt}, "rk4 dt/4": {"dt": dt / 4}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--chirp", action="store_true")
    args = ap.parse_args(argv)
    for name, (p, ex, duration) in cases(args.chirp).items():
        simulate(p, ex, 0.01)                                     # load the kernels
        simulate(p, ex, 0.01, method="rk4")
        rounds = 1 if duration > 10 else args.rounds
        walls: dict = {m: [] for m in methods(p, ex)}
        last = {}
        for _ in range(rounds):
            for m, kw in methods(p, ex).items():
                run = simulate(p, ex, duration, output_hz=500.0 if duration > 10 else 1000.0, **kw)
                assert run.ok, run.message
                walls[m].append(run.wall_s)
                last[m] = run
        for m, w in walls.items():
            run, wall = last[m], statistics.median(w)
            c = run.control
            print(f"{name:12s} {m:11s} wall {wall:7.2f} s  {duration / wall:6.1f} sim s/s  "
                  f"events {len(run.events) - 1:6d}  steps {c['steps']} ({c['steps_all']})  "
                  f"by step {c['intervals_by_step']}  est {c['error_est_max']}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
