import sys, numpy as np
from workbench.reference import HybridReference
from workbench.core import layout as ly
from workbench.model.params import Parameters
from workbench.model.simulate import simulate
H = 0.036
p = Parameters()
kernel = simulate(p, None, H, dt=1.25e-5, initial="paper")
ref = HybridReference(p).run(0.0, H, np.zeros(2 * ly.N_DOF), t_eval=kernel.signals.index.to_numpy())
rl = ref.log
for tol in [float(x) for x in sys.argv[1].split(",")]:
    run = simulate(p, None, H, initial="paper", tol=tol)
    ev = run.events[run.events.kind != "start"]
    same = len(ev) == len(rl) and all((k.kind, k.from_regime, k.to_regime, k.point) == (r["kind"], r["from_regime"], r["to_regime"], r["point"]) for k, r in zip(ev.itertuples(), rl))
    err = max(abs(k.t - r["t"]) for k, r in zip(ev.itertuples(), rl))
    print(f"tol {tol:g}: ok {run.ok} floor {run.control['floor_count']} events {len(ev)}/{len(rl)} same {same} worst dt {err:.2e} s", flush=True)
