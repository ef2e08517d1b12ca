"""Accuracy against cost of two checkouts' integrators on the same windows.

    python benchmarks/accuracy_side_by_side.py windows /tmp/windows.json
    python benchmarks/accuracy_side_by_side.py measure /tmp/windows.json 2e-4 1e-4
    (cd /tmp/old && PYTHONPATH=/tmp/old python /path/to/accuracy_side_by_side.py \\
        measure /tmp/windows.json 1e-4 5e-5)

``windows`` runs each case whole at this checkout's default step, takes the
window of :func:`side_by_side.window_start` (a 0.25 s span from a state clear
of events) and the converged solution on it (CONVERGED_DT, and half of it
for its own error), and saves them.  ``measure`` runs every window from that
saved state at each given step, RUNS times, and prints one JSON line per
(case, step): the median wall per simulated second, the tip-height error
over the converged tip's range, the largest contact-share difference and
the events.  It uses only ``simulate``, so it runs in an older checkout too
(put that checkout first on PYTHONPATH): both are then measured against the
same converged solution, alternately, on the same machine.

``windows ... --starts 2,3.5`` takes a window after each of those times (s) of
every 10 s sine instead.

``measure ... --held u_A,u_B`` holds those coordinates at their values at the
window's start (their rates zeroed): a reduced model measured against the
converged full model.
"""
from __future__ import annotations

import json
import statistics
import sys
import time

import numpy as np

from workbench.model.excitation import chirp, sine
from workbench.model.params import Parameters
from workbench.model.simulate import simulate

SAMPLE_HZ = 1000.0
CONVERGED_DT = 3.125e-6
WINDOW_S = 0.25
RUNS = 3
MIN_WINDOW_EVENTS = 4


def cases() -> dict:
    """name -> (parameters, excitation, whole-run duration (s), window wanted from (s))."""
    base = Parameters().replace(gap_mm=1.016, cork="cubic")
    return {"sine tip": (base.replace(tip_mass=True), sine(20.0, 20.0, ramp_s=1.0), 10.0, 5.0),
            "sine no tip": (base.replace(tip_mass=False), sine(20.0, 20.0, ramp_s=1.0), 10.0, 5.0),
            "chirp tip": (base.replace(tip_mass=True), chirp(10.0, 5.0, 65.0, 240.0, ramp_s=1.0),
                          240.0, 120.0),
            # the default 200 N: the loose body rocks (docs/verification.md)
            "sine tip 200 N": (base.replace(tip_mass=True), sine(200.0, 20.0, ramp_s=1.0), 10.0, 5.0),
            "sine no tip 200 N": (base.replace(tip_mass=False), sine(200.0, 20.0, ramp_s=1.0), 10.0,
                                  5.0)}


COLUMNS = ["w_A", "phi_A", "u_A", "s", "v", "psi", "w_B", "phi_B", "u_B"]


def _window_start(run, after: float):
    sig = run.signals
    t = sig.index.to_numpy()
    events = run.events.t.to_numpy()
    cols = [*COLUMNS, *(c + "_dot" for c in COLUMNS)]
    for k in np.flatnonzero(t >= after - 1e-12):
        inside = ((events > t[k]) & (events < t[k] + WINDOW_S)).sum()
        if inside >= MIN_WINDOW_EVENTS and not (np.abs(events - t[k]) < 1e-3).any():
            return float(t[k]), sig[cols].iloc[k].to_numpy(), int(sig.regime.iloc[k])
    raise RuntimeError(f"no window after {after} s")


def window(params, ex, t0, y0, regime, dt, held=()):
    """One window at step dt; ``held`` coordinates are held at their start (rates zeroed)."""
    if held:
        y0 = np.array(y0, dtype=float)
        for name in held:
            y0[len(COLUMNS) + COLUMNS.index(name)] = 0.0
    start = time.perf_counter()
    run = simulate(params, ex, WINDOW_S, dt=dt, output_hz=SAMPLE_HZ, initial=y0, t0=t0,
                   regime=regime, fixed=held)
    wall = time.perf_counter() - start
    if not run.ok:
        raise RuntimeError(f"window at dt = {dt}: {run.message}")
    return wall, run.signals.tip_y.to_numpy(), run.contact_time_share(), len(run.events) - 1


def errors(tip, shares, ref_tip, ref_shares):
    """Tip error over the reference tip's range; largest share difference (keys as text)."""
    shares = {str(k): v for k, v in shares.items()}
    ref_shares = {str(k): v for k, v in ref_shares.items()}
    n = min(len(tip), len(ref_tip))
    tip_err = float(np.max(np.abs(tip[:n] - ref_tip[:n])) / np.ptp(ref_tip[:n]))
    codes = set(shares) | set(ref_shares)
    share_err = max(abs(shares.get(c, 0.0) - ref_shares.get(c, 0.0)) for c in codes)
    return tip_err, float(share_err)


def save_windows(path, starts=None):
    """Each case's window after its own start; with ``starts`` (s), one window after each of
    them for every 10 s sine (keys "case @start")."""
    out = {}
    for name, (params, ex, duration, after) in cases().items():
        if starts is not None and not name.startswith("sine"):
            continue
        run = simulate(params, ex, duration, output_hz=SAMPLE_HZ)
        for start in (after,) if starts is None else starts:
            t0, y0, regime = _window_start(run, start)
            _, tip, shares, n_events = window(params, ex, t0, y0, regime, CONVERGED_DT)
            _, tip2, shares2, _ = window(params, ex, t0, y0, regime, CONVERGED_DT / 2)
            own = errors(tip2, shares2, tip, shares)
            key = name if starts is None else f"{name} @{start:g}"
            out[key] = {"case": name, "t0": t0, "y0": y0.tolist(), "regime": regime,
                        "tip": tip.tolist(), "shares": {str(k): v for k, v in shares.items()},
                        "events": n_events, "converged_own_error": own}
            print(json.dumps({"case": key, "t0": t0, "converged_events": n_events,
                              "converged_own_error": own}), flush=True)
    with open(path, "w") as f:
        json.dump(out, f)


def measure(path, steps, held=()):
    with open(path) as f:
        saved = json.load(f)
    known = cases()
    for name, w in saved.items():
        params, ex, _, _ = known[w.get("case", name)]
        for dt in steps:
            walls = []
            try:
                for _ in range(RUNS):
                    wall, tip, shares, n_events = window(params, ex, w["t0"], np.array(w["y0"]),
                                                         w["regime"], dt, held)
                    walls.append(wall)
            except Exception as exc:          # an unstable or refused step: say so, go on
                print(json.dumps({"case": name, "dt": dt, "failed": str(exc)}), flush=True)
                continue
            tip_err, share_err = errors(tip, shares, np.array(w["tip"]), w["shares"])
            print(json.dumps({"case": name, "dt": dt, "held": list(held),
                              "wall_per_sim_s": statistics.median(walls) / WINDOW_S,
                              "tip_error_rel": tip_err, "share_error": share_err,
                              "events": n_events, "converged_events": w["events"]}), flush=True)


if __name__ == "__main__":
    if sys.argv[1] == "windows":
        starts = None
        if "--starts" in sys.argv:
            starts = [float(x) for x in sys.argv[sys.argv.index("--starts") + 1].split(",")]
        save_windows(sys.argv[2], starts)
    else:
        args = sys.argv[3:]
        held = tuple(args[args.index("--held") + 1].split(",")) if "--held" in args else ()
        measure(sys.argv[2], [float(a) for a in args if a[0].isdigit()], held)
