"""The Lawson step of ``lawson_locked.patch`` alone, on the chirp window's locked interval.

Run in a worktree with the patch applied (README of this folder, or
docs/performance.md "Lawson steps while the joint is locked"), after
``accuracy_side_by_side.py windows /tmp/windows.json``:

    PYTHONPATH=. python benchmarks/lawson_locked/harness.py /tmp/windows.json

Prints, for 20 ms from the start of the "chirp tip" window (regime 13, the
joint locked throughout):
- the largest error of q (cm) against RK4 at 1e-5 s, for Lawson steps with
  L frozen at the start, L recomputed every step, and RK4;
- how much L = df/dy changes along the interval;
- the cost of the operator (L by forward differences and its exponentials),
  of one Lawson step and of one RK4 step (each a Python call of a kernel,
  the call's overhead included).
"""
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from accuracy_side_by_side import cases  # noqa: E402

from workbench.core import layout as ly  # noqa: E402
from workbench.core.constrained import rhs_regime  # noqa: E402
from workbench.core.integrate import rk4_step  # noqa: E402
from workbench.core.lawson import lawson_step, locked_operator  # noqa: E402
from workbench.model import packing as mdl  # noqa: E402
from workbench.model.simulate import stepped_dt  # noqa: E402

T = 0.02

w = json.load(open(sys.argv[1]))["chirp tip"]
p, ex, _, _ = cases()[w["case"]]
model = mdl.build(p)
model.P[ly.P_STEPPED_DT] = stepped_dt(p)
P, tab, kc, free = model
rec, mat, vec, stages, cg, cw, rg, ev = mdl.make_work()
regime = w["regime"]
rg[ly.RG_SET] = (regime + 1) // 2
rg[ly.RG_STICK] = 1.0
rg[ly.RG_SIGN] = 1.0
t0 = w["t0"]
y0 = np.zeros(ly.N_AUG)
y0[:ly.N_STATE] = w["y0"]
lw = np.zeros((ly.N_LW, ly.N_STATE, ly.N_STATE))


def f(t, y, out):
    return rhs_regime(t, y, P, tab, kc, free, ex, rec, mat, vec, cg, cw, rg, out)


def operator(t, y, h):
    stages[ly.STAGE_CUR][:] = y
    f(t, y, stages[ly.STAGE_K1])
    assert locked_operator(t, h, P, tab, kc, free, ex, rec, mat, vec, stages, cg, cw, rg, lw) == 0


def run(T, n, method, refresh=False):
    y = y0.copy()
    h = T / n
    for i in range(n):
        t = t0 + i * h
        if method == "lawson" and (i == 0 or refresh):
            operator(t, y, h)
        f(t, y, stages[ly.STAGE_K1])
        y_new = np.empty(ly.N_AUG)
        if method == "rk4":
            status = rk4_step(t, y, h, P, tab, kc, free, ex, rec, mat, vec, stages, cg, cw, rg, y_new)
        else:
            status = lawson_step(t, y, h, P, tab, kc, free, ex, rec, mat, vec, stages, cg, cw, rg, ev,
                                 lw, y_new)
        assert status == 0
        y = y_new
    return y


print(f"regime {regime} from t = {t0} s, {T * 1e3:g} ms; largest error of q (cm)")
ref = run(T, round(T / 1e-5), "rk4")
for h in (2e-4, 1e-4, 5e-5):
    n = round(T / h)
    row = {"L frozen": run(T, n, "lawson"), "L every step": run(T, n, "lawson", True)}
    if h <= 1e-4:
        row["RK4"] = run(T, n, "rk4")
    print(f"  h {h:g} s: " + ", ".join(f"{k} {np.abs(v - ref)[:ly.N_DOF].max():.2e}"
                                      for k, v in row.items()))

print("change of L along the interval, relative to its largest entry")
Ls = {}
for dt in (0.0, 0.001, 0.005, 0.02):
    y = run(dt, round(dt / 1e-5), "rk4") if dt > 0 else y0.copy()
    operator(t0 + dt, y, 2e-4)
    Ls[dt] = lw[ly.LW_L].copy()
nd = ly.N_DOF
for dt in (0.001, 0.005, 0.02):
    d = Ls[dt] - Ls[0.0]
    print(f"  after {dt * 1e3:g} ms: dq''/dq {np.abs(d[nd:, :nd]).max() / np.abs(Ls[0.0][nd:, :nd]).max():.3f}, "
          f"dq''/dq' {np.abs(d[nd:, nd:]).max() / np.abs(Ls[0.0][nd:, nd:]).max():.3f}")

print("cost per call (us), three rounds of 2000 calls")
operator(t0, y0, 2e-4)
y_new = np.empty(ly.N_AUG)
for _ in range(3):
    start = time.perf_counter()
    for _ in range(2000):
        locked_operator(t0, 2e-4, P, tab, kc, free, ex, rec, mat, vec, stages, cg, cw, rg, lw)
    op = (time.perf_counter() - start) / 2000
    start = time.perf_counter()
    for _ in range(2000):
        lawson_step(t0, y0, 2e-4, P, tab, kc, free, ex, rec, mat, vec, stages, cg, cw, rg, ev, lw,
                    y_new)
    lawson = (time.perf_counter() - start) / 2000
    start = time.perf_counter()
    for _ in range(2000):
        rk4_step(t0, y0, 1e-4, P, tab, kc, free, ex, rec, mat, vec, stages, cg, cw, rg, y_new)
    rk4 = (time.perf_counter() - start) / 2000
    print(f"  operator {op * 1e6:.1f}, Lawson step of 2e-4 s {lawson * 1e6:.2f}, "
          f"RK4 step of 1e-4 s {rk4 * 1e6:.2f}")
