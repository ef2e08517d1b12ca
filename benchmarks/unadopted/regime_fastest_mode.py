import numpy as np
from workbench.core import layout as ly
from workbench.core.constrained import rhs_regime
from workbench.model import drives, packing as mdl
from workbench.model.params import Parameters
from workbench.model.regimes import set_of, regime_of
from workbench.model.simulate import simulate
from workbench.model.methods import METHODS
from workbench.model.tableaus import write_tableau
p = Parameters().replace(gap_mm=1.016, tip_mass=True)
ex = drives.sine(200.0, 20.0, ramp_s=1.0)
run = simulate(p, ex, 5.1)
ev = run.events
print(ev.columns.tolist())
model = mdl.build(p); write_tableau(model.P, METHODS["dop853"].tableau)
work = mdl.make_work()
exa = run.excitation
t_all = run.t if hasattr(run, "t") else run.signals.index.to_numpy()
Y = run.states
sel = np.where((t_all > 5.0) & (t_all < 5.05))[0]
evt = ev.t.to_numpy(); to = ev.to_regime.to_numpy()
res = []
for i in sel[::5]:
    t = t_all[i]
    k = np.searchsorted(evt, t) - 1
    reg = int(to[k])
    s, stick, sign = set_of(reg), 0.0, 1.0
    # regime code -> set and stick flag
    from workbench.model import regimes as R
    work.rg[ly.RG_SET] = R.set_of(reg); work.rg[ly.RG_STICK] = 1.0 if R.is_stick(reg) else 0.0
    work.rg[ly.RG_SIGN] = 1.0
    y = np.zeros(ly.N_AUG); y[:ly.N_STATE] = Y[i]
    f0 = np.zeros(ly.N_AUG); hi = np.zeros(ly.N_AUG); lo = np.zeros(ly.N_AUG)
    J = np.zeros((18, 18))
    sc = np.maximum(np.abs(Y).max(0), 1e-6)
    for j in range(18):
        d = 1e-6 * sc[j]
        yp, ym = y.copy(), y.copy(); yp[j] += d; ym[j] -= d
        a = rhs_regime(t, yp, model, exa, work, hi); b = rhs_regime(t, ym, model, exa, work, lo)
        J[:, j] = (hi[:18] - lo[:18]) / (2 * d)
    lam = np.linalg.eigvals(J)
    big = lam[np.argmax(np.abs(lam))]
    res.append((t, reg, abs(big) / 2 / np.pi, big))
    print(f"t {t:.5f} regime {reg:3d} fastest |lam|/2pi {abs(big)/2/np.pi:8.1f} Hz  lam {big:.3e}")
