"""Accuracy against cost of the integration methods on 1 s runs across the operating range.

    python benchmarks/controlled_accuracy.py run /tmp/acc.json [--cases issue|range|all] [--tols 1e-4,1e-5]
    python benchmarks/controlled_accuracy.py table /tmp/acc.json

Each case runs 1 s from the static equilibrium with a 0.5 s soft start and
is measured over 0.5-1 s against RK4 at a 64th of the default step (the
converged solution, whose own error is its difference from a 32nd, printed
as ``ref_err``): the tip height's largest difference over the converged
tip's range, the largest difference of a contact code's time share (from
the event log, ``regimes.contact_shares_of``), and the events in the
window.  Methods: fixed RK4 at the default step, at a half, a quarter and
an eighth of it, and the default (controlled) method at each tolerance,
with its wall time, its steps (accepted and in all) and its own largest
error estimate.
``table`` prints the saved results as Markdown, and for each tolerance the
ratio to the measured error (the larger of the tip's and the shares') of
the run's global error estimate and of its difference from its companion
run (what ``check_accuracy`` measures, here in the window), over the cases whose converged solution is
converged (its own error below 1e-4 of the tip's range).
"""
from __future__ import annotations

import argparse
import json
import sys

import numpy as np
from joblib import Parallel, delayed

from workbench.model.drives import chirp, sine
from workbench.model.params import Parameters
from workbench.model.step_policy import default_dt
from workbench.model.simulate import simulate
from workbench.model.accuracy import companion_settings, difference

DURATION_S = 1.0
RAMP_S = 0.5
WINDOW = (0.5, 1.0)
CONVERGED_DIVISOR = 64
RK4_DIVISORS = (1, 2, 4, 8)


def issue_cases() -> dict:
    """The four cases of the accuracy question: the hardest rocking and the default case."""
    base = Parameters().replace(cork="cubic")
    return {
        "1.016 mm, no tip, 100 N, 55 Hz": (base.replace(gap_mm=1.016, tip_mass=False), sine(100.0, 55.0, ramp_s=RAMP_S)),
        "0.508 mm, no tip, 200 N, 50 Hz": (base.replace(gap_mm=0.508, tip_mass=False), sine(200.0, 50.0, ramp_s=RAMP_S)),
        "0.635 mm, tip, quadratic, 50 N, 45 Hz": (base.replace(gap_mm=0.635, tip_mass=True, cork="quadratic"),
                                                  sine(50.0, 45.0, ramp_s=RAMP_S)),
        "1.016 mm, tip, 200 N, 20 Hz": (base.replace(gap_mm=1.016, tip_mass=True), sine(200.0, 20.0, ramp_s=RAMP_S)),
    }


def range_cases() -> dict:
    """Across 10-55 Hz, 20-200 N, every gap, tip on and off, every cork law, and the chirp's top."""
    base = Parameters().replace(cork="cubic")
    out = {}
    corks = ("cubic", "linear", "quadratic", "static", "none")
    gaps = (0.508, 0.635, 0.762, 1.016)
    k = 0
    for freq in (10.0, 20.0, 30.0, 45.0, 55.0):
        for force in (20.0, 200.0):
            for tip in (True, False):
                gap = gaps[k % len(gaps)]
                cork = corks[k % len(corks)]
                k += 1
                name = f"{gap} mm, {'tip' if tip else 'no tip'}, {cork}, {force:g} N, {freq:g} Hz"
                out[name] = (base.replace(gap_mm=gap, tip_mass=tip, cork=cork),
                             sine(force, freq, ramp_s=RAMP_S))
    # the chirp's 45-65 Hz part: 5-65 Hz over 240 s is at 45 Hz after 160 s
    for tip in (True, False):
        out[f"1.016 mm, {'tip' if tip else 'no tip'}, chirp 45-65 Hz part"] = (
            base.replace(gap_mm=1.016, tip_mass=tip), chirp(200.0, 45.0, 65.0, 80.0, ramp_s=RAMP_S))
    return out


def compare(run, ref) -> dict:
    """The run's errors in the window against the converged run ``ref`` (accuracy.difference)."""
    d = difference(run, ref, *WINDOW)
    return {"tip_err": d["tip_error"], "share_err": d["share_error"], "events": d["events"],
            "events_ref": d["events_ref"], "event_err": d["event_error"]}


def measure(name, params, ex, tols):
    dt = default_dt(params, ex)
    ref = simulate(params, ex, DURATION_S, dt=dt / CONVERGED_DIVISOR)
    half_ref = simulate(params, ex, DURATION_S, dt=dt / (CONVERGED_DIVISOR // 2))
    rows = [{"case": name, "method": "reference", "ok": ref.ok,
             **{f"ref_{k}": v for k, v in compare(half_ref, ref).items()}}]
    for d in RK4_DIVISORS:
        run = simulate(params, ex, DURATION_S, dt=dt / d)
        rows.append({"case": name, "method": f"rk4 dt/{d}", "ok": run.ok, "wall_s": run.wall_s,
                     "steps": run.control["steps"], **compare(run, ref)})
    for tol in tols:
        run = simulate(params, ex, DURATION_S, tol=tol)
        c = run.control
        companion = simulate(params, ex, DURATION_S, **companion_settings(True, tol, dt))
        by_companion = max(compare(run, companion)[k] for k in ("tip_err", "share_err"))
        rows.append({"case": name, "method": f"controlled {tol:g}", "ok": run.ok,
                     "wall_s": run.wall_s, "steps": c["steps"], "steps_all": c["steps_all"],
                     "rejected": c["rejected"], "h_min": c["h_min"],
                     "error_est_max": c["error_est_max"], "global_error_est": c["global_error_est"],
                     "error_by_companion": by_companion,
                     "floor_count": c["floor_count"],
                     **compare(run, ref)})
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("what", choices=("run", "table"))
    ap.add_argument("file")
    ap.add_argument("--cases", choices=("issue", "range", "all"), default="issue")
    ap.add_argument("--tols", default="1e-4")
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args(argv)
    if args.what == "run":
        cases = {}
        if args.cases in ("issue", "all"):
            cases.update(issue_cases())
        if args.cases in ("range", "all"):
            cases.update(range_cases())
        tols = [float(x) for x in args.tols.split(",")]
        done = Parallel(n_jobs=args.jobs)(delayed(measure)(n, p, ex, tols)
                                          for n, (p, ex) in cases.items())
        rows = [r for part in done for r in part]
        with open(args.file, "w") as f:
            json.dump(rows, f, indent=1)
    rows = json.load(open(args.file))
    print("| case | method | tip err | share err | events (ref) | wall s | steps (all) | est | floor |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if r["method"] == "reference":
            print(f"| {r['case']} | reference (vs dt/32) | {r['ref_tip_err']:.1e} | "
                  f"{r['ref_share_err']:.1e} | {r['ref_events']} | | | | |")
            continue
        print(f"| {r['case']} | {r['method']} | {r['tip_err']:.1e} | {r['share_err']:.1e} | "
              f"{r['events']} ({r['events_ref']}) | {r.get('wall_s', 0):.2f} | {r['steps']} "
              f"({r.get('steps_all', r['steps'])}) | {r.get('error_est_max') or 0:.1e} | "
              f"{r.get('floor_count', '')} |")
    honesty(rows)
    return 0


def honesty(rows) -> None:
    """Each error measure over the measured error, per tolerance: range, median, outside 0.1-10.

    The measures: the global estimate, and the difference from the companion
    at a tenth of the tolerance (``check_accuracy``), both in the window."""
    converged = {r["case"] for r in rows if r["method"] == "reference" and r["ref_tip_err"] < 1e-4}
    ratios = {}
    for r in rows:
        measured = max(r.get("tip_err", 0.0), r.get("share_err", 0.0))
        if r["case"] not in converged or measured <= 0:
            continue
        for key in ("global_error_est", "error_by_companion"):
            if r.get(key) is not None:
                ratios.setdefault((key, r["method"]), []).append(r[key] / measured)
    print("\n| measure | method | cases | measure / error: min | median | max | outside 0.1-10 |")
    print("|---|---|---|---|---|---|---|")
    for (key, method), v in ratios.items():
        v = np.array(v)
        print(f"| {key} | {method} | {len(v)} | {v.min():.2f} | {np.median(v):.2f} | "
              f"{v.max():.2f} | {int(((v < 0.1) | (v > 10)).sum())} |")


if __name__ == "__main__":
    sys.exit(main())
