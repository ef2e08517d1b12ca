"""Measurements quoted in docs/verification.md: step convergence through events, energy balance,
penetration and drift, and the 10 s benchmark run.  python studies/convergence_checks.py"""
import numpy as np
from workbench.model.params import Parameters
from workbench.model.simulate import simulate
from workbench.model.drives import sine, DEFAULT_FORCE_N
p = Parameters()
runs = {dt: simulate(p, None, 0.1, dt=dt, initial="paper") for dt in (5e-5, 2.5e-5, 1.25e-5, 6.25e-6, 5e-6)}
print("events", {dt: len(r.events) for dt, r in runs.items()})
ref = runs[1.25e-5]
for col in ("w_B", "s", "v", "psi", "w_B_dot", "s_dot", "v_dot", "psi_dot"):
    e = [np.abs(runs[dt].signals[col] - ref.signals[col]).max() for dt in (5e-5, 2.5e-5)]
    print(col, e, "ratio", e[0] / e[1])
print("event t diff", np.abs(runs[5e-5].events.t.to_numpy() - ref.events.t.to_numpy()).max())
for dt, r in runs.items():
    s = r.summary(); print(dt, "balance", s["energy_balance_rel"], "pen", s["max_penetration_cm"], "drift", s["max_drift_cm"])
for tip in (True, False):
    s = simulate(Parameters(tip_mass=tip), None, 1.0, initial="paper").summary()
    print("paper 1 s tip", tip, "pen", s["max_penetration_cm"], "drift", s["max_drift_cm"], "dt", s["dt"])
s = simulate(p.replace(gap_mm=1.016), sine(DEFAULT_FORCE_N, 20.0, ramp_s=1.0), 10.0).summary()
print("10 s run", {k: s[k] for k in ("n_events", "n_impacts", "energy_balance_rel", "max_penetration_cm", "max_drift_cm", "wall_s")})

# The kernel at the default step against the slow reference with events (workbench/reference/events.py)
from workbench.reference import HybridReference  # noqa: E402
from workbench.core import layout as ly  # noqa: E402
k = simulate(p, None, 0.036, initial="paper")
ref_run = HybridReference(p).run(0.0, 0.036, np.zeros(ly.N_STATE))
log, yend = ref_run.log, ref_run.y
ev = k.events[k.events.kind != "start"]
print("reference: events", len(ev), len(log), "max |dt|", max(abs(a - b["t"]) for a, b in zip(ev.t, log)))
cols = list(ly.COORD_NAMES) + [c + "_dot" for c in ly.COORD_NAMES]
e = np.abs(k.signals[cols].iloc[-1].to_numpy() - yend)
print("reference: end state |dq|", e[:ly.N_DOF].max(), "|dq'|", e[ly.N_DOF:].max())
