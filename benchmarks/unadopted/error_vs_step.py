"""Diagnostic (not in make bench): the step estimate over the tolerance (3e-5) against the step, from
states of the 10 s sine (1.016 mm, 20 Hz, 200 N, tip mass) at 5.0-5.05 s, each step from the same state."""
import numpy as np
from workbench.core import layout as ly
from workbench.core.constrained import rhs_regime
from workbench.core.adaptive import step_error
from workbench.core.pair import pair_step
from workbench.core.event_functions import event_values_after_rhs
from workbench.core.error_scales import floors
from workbench.model import drives, packing as mdl, regimes as R
from workbench.model.params import Parameters
from workbench.model.simulate import simulate
from workbench.model.methods import METHODS
from workbench.model.tableaus import write_tableau
p = Parameters().replace(gap_mm=1.016, tip_mass=True)
ex = drives.sine(200.0, 20.0, ramp_s=1.0)
run = simulate(p, ex, 5.1)
ev = run.events
model = mdl.build(p); write_tableau(model.P, METHODS["dop853"].tableau)
work = mdl.make_work()
exa = run.excitation
t_all = run.t; Y = run.states
scale = np.zeros((ly.N_SCALE_ROWS, ly.N_STATE)); floors(model.P, scale)
scale[ly.SCALE_PEAK] = np.abs(Y).max(0)
ctl = np.zeros(ly.N_CTL); ctl[ly.CTL_F_SCALE] = 1.6e7
st = np.zeros(ly.N_ST)
names = [f"y{i}" for i in range(18)] + [f"gap{k}" for k in range(4)] + [f"lam{k}" for k in range(4)] + ["stick", "slip", "evtime"]
evt = ev.t.to_numpy(); to = ev.to_regime.to_numpy()
sel = np.where((t_all > 5.0) & (t_all < 5.05))[0]
hs = [4e-5, 6e-5, 8e-5, 9e-5, 1e-4, 1.1e-4, 1.2e-4, 1.4e-4, 1.7e-4, 2e-4]
for i in sel[::7]:
    t = t_all[i]; k = np.searchsorted(evt, t) - 1; reg = int(to[k])
    if k + 1 < len(evt) and evt[k + 1] - t < 2.5e-4: continue
    work.rg[ly.RG_SET] = R.set_of(reg); work.rg[ly.RG_STICK] = 1.0 if R.is_stick(reg) else 0.0; work.rg[ly.RG_SIGN] = 1.0
    y = np.zeros(ly.N_AUG); y[:ly.N_STATE] = Y[i]
    row = []
    for h in hs:
        rhs_regime(t, y, model, exa, work, work.stages[ly.STAGE_K1])
        s = pair_step(t, y, h, model, exa, work, st, work.stages[ly.STAGE_NEXT])
        event_values_after_rhs(work.stages[ly.STAGE_NEXT], model.P, model.free, work.cg, work.rg, work.ev, ly.EV_END, ly.EV_RATE_END)
        s2, err, arg = step_error(3e-5, model, exa, work, scale, ctl, t + h)
        row.append(f"{err:8.1e}{names[arg][:5]:>6s}")
    print(f"t {t:.4f} reg {reg:2d} " + " ".join(row), flush=True)
print("h:", hs)
