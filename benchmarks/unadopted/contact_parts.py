"""The contact forces' parts timed in jitted loops (medians of 7 x 100 000 calls, µs):
fill_geometry, one solve with M's factor, add_contact_forces and rhs_regime, for a single slip
(set 1), a single stick and a double slip (set 5).

    python benchmarks/unadopted/contact_parts.py
"""
import time, numba as nb, numpy as np
from workbench.model import packing as mdl
from workbench.core import layout as ly
from workbench.core.contact import fill_geometry
from workbench.core.dynamics import solve_factored, factor_free, assemble_inertia
from workbench.core.constrained import add_contact_forces, rhs_regime
from workbench.model.drives import sine
from workbench.model.params import Parameters

@nb.njit
def repeat(which, n, y, model, ex, work, ydot, x):
    P, tab, kc, free = model
    rec, mat, vec, stages, cg, cw, rg, ev = work
    for i in range(n):
        y[0] += 1e-12
        if which == 0:
            fill_geometry(y, P, cg)
        elif which == 1:
            x[0] += 1e-12
            solve_factored(free, mat, x, ydot[:9])
        elif which == 2:
            add_contact_forces(y, P, free, mat, cg, cw, rg, ydot)
        else:
            rhs_regime(1e-3*i, y, model, ex, work, ydot)
    return 0

model, work = mdl.build(Parameters()), mdl.make_work()
y = np.zeros(ly.N_AUG); y[:ly.N_STATE] = np.random.default_rng(0).normal(size=ly.N_STATE) * 0.01
ydot, ex = np.zeros(ly.N_AUG), sine(1.0, 20.0)
x = np.ones(9)
for which in (0,1,2,3):
  for set_index, stick in ((1, False),(1,True),(5,False)):
    work.rg[:] = 0.0
    work.rg[ly.RG_SET], work.rg[ly.RG_STICK], work.rg[ly.RG_SIGN] = set_index, stick, 1.0
    rhs_regime(0.0, y, model, ex, work, ydot)
    repeat(which, 10, y.copy(), model, ex, work, ydot, x)
    ts=[]
    for _ in range(7):
        t0=time.perf_counter(); repeat(which, 100000, y.copy(), model, ex, work, ydot, x); ts.append((time.perf_counter()-t0)*10)
    print(which, set_index, stick, f"{np.median(ts):.3f} us")
