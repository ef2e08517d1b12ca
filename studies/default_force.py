"""How the default shaker amplitude is chosen.

The paper drove the shaker at 0.4-0.8 V and gives no force (docs/model.md §8).
The rule: the largest candidate force, within the range the stress study
validates (up to 200 N, studies/stress.toml), for which the tip stays below
the paper's 8.4 cm deflection (seed §5.3) across 10-55 Hz at the widest gap
(1.016 mm) with the tip mass: simulate each frequency for 10 s for each
candidate and keep the forces whose runs all finish with the tip's largest
displacement from the static equilibrium below the limit.  The response is
far from linear (below a few newtons the joint stays stuck in contact 23),
so candidates are tried rather than scaled.

    python studies/default_force.py --out results/default_force
"""
import argparse
import json
from pathlib import Path

from workbench.model import drives as excitation
from workbench.model.params import Parameters
from workbench.model.simulate import simulate

FREQS = [10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0, 55.0]


def peaks(force_n, duration, ramp):
    p = Parameters().replace(gap_mm=1.016, tip_mass=True, cork="cubic")
    out = {}
    for f in FREQS:
        run = simulate(p, excitation.sine(force_n, f, ramp_s=ramp), duration)
        s = run.summary()
        out[f] = {"tip_disp_peak_cm": s["tip_disp_peak_cm"], "status": s["status"],
                  "n_events": s["n_events"]}
        print(f"F = {force_n:g} N, {f:4.0f} Hz: tip peak {s['tip_disp_peak_cm']:.3f} cm, "
              f"{s['n_events']} events, {s['status']}", flush=True)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="results/default_force")
    ap.add_argument("--forces-n", type=float, nargs="+", default=[20.0, 50.0, 100.0, 150.0, 200.0])
    ap.add_argument("--duration", type=float, default=10.0)
    ap.add_argument("--ramp", type=float, default=1.0)
    ap.add_argument("--limit-cm", type=float, default=8.4)
    args = ap.parse_args()
    trials = {f: peaks(f, args.duration, args.ramp) for f in sorted(args.forces_n)}
    good = [f for f, res in trials.items()
            if all(v["status"] == "ok" and v["tip_disp_peak_cm"] < args.limit_cm
                   for v in res.values())]
    result = {"trials": trials, "chosen_force_n": max(good) if good else None,
              "limit_cm": args.limit_cm, "duration_s": args.duration, "ramp_s": args.ramp}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "default_force.json").write_text(json.dumps(result, indent=1))
    print(json.dumps({"chosen_force_n": result["chosen_force_n"]}))


if __name__ == "__main__":
    main()
