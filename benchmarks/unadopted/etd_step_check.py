"""One ETDRK4 step (workbench/core/exponential.py) of 5e-5, 1e-4 and 2e-4 s from states of the
3 s sine without an event within 1 ms, against scipy DOP853 at rtol 1e-12: the end, the middle
(the continuous extension), the estimate and the last-stage estimate of RK4's kind, as the largest
error over the state's scale.

    python benchmarks/unadopted/etd_step_check.py tip|notip
"""
import sys
from pathlib import Path
sys.path.insert(0, str(Path(__file__).parent))
import numpy as np
from scipy.integrate import solve_ivp
import exponential_windows as ew
from workbench.core import layout as ly, exponential as xp
from workbench.model.drives import sine
from workbench.model.params import Parameters
from workbench.model.simulate import simulate
N = ly.N_STATE
case = sys.argv[1]
p = Parameters().replace(gap_mm=1.016, tip_mass=case == "tip", cork="cubic")
ex = sine(200.0, 20.0, ramp_s=1.0)
run = simulate(p, ex, 3.0)
scale = ew.scales(run)
for t0, y0, regime in ew.spans(run, 6, 1e-3, t_min=1.5):
    f = ew.RegimeODE(p, ex, regime, y0)
    y = np.zeros(ly.N_AUG); y[:N] = y0
    st = np.zeros(64)
    ops, opkey, sc = xp.new_arrays(True, 0.01)
    out = []
    for h in (5e-5, 1e-4, 2e-4):
        f.work.stages[ly.STAGE_K1, :] = 0
        f(t0, y0); f.work.stages[ly.STAGE_K1, :N] = f.out[:N]; f.work.stages[ly.STAGE_K1, N:] = f.out[N:]
        assert xp.operators(t0, y, h, f.model, f.ex, f.work, ops[0], sc) == ly.OK
        f(t0, y0); f.work.stages[ly.STAGE_K1, :] = f.out
        ynew = np.zeros(ly.N_AUG)
        s = xp.etd_step(t0, y, h, f.model, f.ex, f.work, st, ops[0], ynew, True)
        ref = solve_ivp(f, (t0, t0 + h), y0, method="DOP853", rtol=1e-12, atol=1e-14 * scale, dense_output=True)
        e_end = np.max(np.abs(ynew[:N] - ref.y[:, -1]) / scale)
        e_mid = np.max(np.abs(f.work.stages[xp.STAGE_MID, :N] - ref.sol(t0 + h / 2)) / scale)
        e_est = np.max(np.abs(f.work.stages[ly.STAGE_ERR, :N]) / scale)
        e_alt = np.max(np.abs(f.work.stages[xp.STAGE_ALT_ERR, :N]) / scale)
        out.append(f"h {h:.0e}: end {e_end:.1e} mid {e_mid:.1e} est {e_est:.1e} "
                   f"last-stage est {e_alt:.1e}")
    print(regime, " | ".join(out))
