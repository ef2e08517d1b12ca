"""Where one right-hand side's time goes: its parts timed in jitted loops, in one process.

    python benchmarks/rhs_parts.py

Each part runs 100 000 times inside a compiled loop (a Python call would
time numba's argument unboxing instead), 7 rounds, median per call (µs):
the mass matrix, h and gravity (``assemble_inertia``), the applied forces,
the LDL^T factor of M, the whole free-flight ``rhs``, ``rhs_regime`` in
free flight, single and double contact, one RK4 step, and what a step adds
besides its right-hand sides: the projection onto the regime
(``project``) and the event functions (``event_values``).  The state is a
random one: the costs do not depend on it.
"""
import time

import numba as nb
import numpy as np

from workbench.model import packing as mdl
from workbench.core import layout as ly
from workbench.core.constrained import project, rhs_regime
from workbench.core.dynamics import add_applied_forces, assemble_inertia, factor_free, rhs
from workbench.core.event_functions import event_values
from workbench.core.integrate import rk_step
from workbench.model.drives import sine
from workbench.model.params import Parameters

PARTS = ("mass matrix, h, gravity", "applied forces", "factor of M (LDL^T)", "rhs (free flight)",
         "rhs_regime", "RK4 step", "projection", "event functions")
RHS, RHS_REGIME = 3, 4              # the indices of the whole right-hand sides in PARTS


# Not cached: numba's cache=True checks only this file's timestamp, so a
# cached loop would keep the machine code of kernels edited since
# (workbench/core/compiler/cache.py keys only the kernels of workbench.core).
@nb.njit
def repeat(which, n, y, model, ex, work, ydot):
    P, tab, kc, free = model
    rec, mat, vec, stages, cg, cw, rg, ev = work
    status = 0
    for i in range(n):
        y[0] += 1e-12                                   # defeat hoisting
        q = y[:ly.N_DOF]
        qd = y[ly.N_DOF:ly.N_STATE]
        if which == 0:
            assemble_inertia(q, qd, P, tab, rec, mat, vec)
        elif which == 1:
            add_applied_forces(1e-3 * i, q, qd, P, tab, kc, ex, rec, vec)
        elif which == 2:
            status |= factor_free(free, mat)
        elif which == RHS:
            status |= rhs(1e-3 * i, y, P, tab, kc, free, ex, rec, mat, vec, ydot)
        elif which == RHS_REGIME:
            status |= rhs_regime(1e-3 * i, y, model, ex, work, ydot)
        elif which == 6:
            project(y, P, free, cg, cw, rg, np.bool_(False))
        elif which == 7:
            event_values(y, P, free, cg, rg, ev, ly.EV_END, ly.EV_RATE_END)
        else:
            status |= rk_step(1e-3 * i, y, 1e-5, model, ex, work, stages[ly.STAGE_NEXT])
    return status


def main(rounds=7, calls=100_000):
    model, work = mdl.build(Parameters()), mdl.make_work()
    y = np.zeros(ly.N_AUG)
    y[:ly.N_STATE] = np.random.default_rng(0).normal(size=ly.N_STATE) * 0.01
    ydot, ex = np.zeros(ly.N_AUG), sine(1.0, 20.0)
    cases = [(w, (0, False)) for w in range(4)]
    cases += [(4, r) for r in ((0, False), (1, True), (1, False), (5, True), (5, False))]
    cases += [(w, r) for w in (5, 6, 7) for r in ((0, False), (1, True), (5, True))]
    for which, (set_index, stick) in cases:
        work.rg[:] = 0.0
        work.rg[ly.RG_SET], work.rg[ly.RG_STICK], work.rg[ly.RG_SIGN] = set_index, stick, 1.0
        repeat(which, 10, y.copy(), model, ex, work, ydot)
        times = []
        for _ in range(rounds):
            t0 = time.perf_counter()
            repeat(which, calls, y.copy(), model, ex, work, ydot)
            times.append((time.perf_counter() - t0) / calls * 1e6)
        regime = f" (set {set_index}, {'stick' if stick else 'slip'})" if which >= RHS_REGIME else ""
        print(f"{PARTS[which] + regime:40s} {np.median(times):6.2f} us")


if __name__ == "__main__":
    main()
