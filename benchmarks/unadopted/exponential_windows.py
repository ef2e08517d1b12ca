"""Exponential integrators against DOP853 on the smooth spans between events (not adopted).

    python benchmarks/unadopted/exponential_windows.py tip|notip [--spans N] [--span-ms T]
        [--steps 2,4,8,16,32] [--methods dop853,exprb43,etdrk4,etdrk4-K,etdrk4-agoD]

From the 10 s sine (1.016 mm, 20 Hz, 200 N, cubic cork, the default method) it takes N
spans of T ms that hold no event (each starting at an output sample, in the regime the
log gives there), and integrates each span's regime ODE (``rhs_regime``, no events, no
projection) with fixed steps of

* DOP853 (its 8th-order solution; 12 right-hand sides a step with first same as last);
* exprb43, the exponential Rosenbrock method of order 4 (Hochbruck, Ostermann &
  Schweitzer, SIAM J. Numer. Anal. 47 (2009), eq. 5.9), the Jacobian of the step's
  start by forward differences (19 right-hand sides) and phi_k(hJ) by the exponential of
  an augmented matrix, time as a 19th state;
* ETDRK4 (Cox & Matthews, J. Comput. Phys. 176 (2002)) with the Jacobian of the span's
  start frozen over the span (``etdrk4``) or taken again every K steps (``etdrk4-K``): 4
  right-hand sides a step, the Jacobian and phi functions once a span or every K steps;
  ``etdrk4-agoD``: the Jacobian frozen, taken D ms before the span's start at the state the
  run had then, where that state was in the span's regime (the spans without one are left
  out of that row).

Errors at the span's end against scipy's DOP853 at rtol 1e-12: the state's on the
workbench's scales (each component over the run's largest |value| of it or its partner,
as workbench.core.error_scales) and the contact forces over the run's largest total
normal force (the stick margin's scale).  Prints, for each method and step, the median
and largest error over the spans and the right-hand sides and matrix exponentials per
simulated ms.
"""
from __future__ import annotations

import argparse
import numpy as np
import scipy.linalg as sla
from scipy.integrate import solve_ivp
from scipy.integrate._ivp import dop853_coefficients as dc

from workbench.core import layout as ly
from workbench.core.constrained import rhs_regime
from workbench.core.contact import eval_geometry
from workbench.core.error_scales import PARTNER
from workbench.model import packing as mdl
from workbench.model.drives import sine
from workbench.model.params import Parameters
from workbench.model.simulate import simulate

N = ly.N_STATE


class RegimeODE:
    """y' = f(t, y) of one regime (rg fixed), counting its evaluations."""

    def __init__(self, params, ex, regime, y0):
        self.model = mdl.build(params)
        self.work = mdl.make_work()
        self.ex = ex
        rg = self.work.rg
        rg[ly.RG_SET] = 0 if regime == 0 else (regime + 1) // 2
        rg[ly.RG_STICK] = 1.0 if regime > 0 and regime % 2 == 1 else 0.0
        rg[ly.RG_SIGN] = 1.0
        if regime > 0 and regime % 2 == 0:          # slipping: sigma = sign of the slip rate
            cg = self.work.cg
            eval_geometry(y0[:ly.N_DOF], self.model.P, cg)
            p = ly.SET_FIRST[int(rg[ly.RG_SET])]
            r = cg[ly.CG_T + p]
            qd = y0[ly.N_DOF:]
            rate = r[ly.CG_DS] * qd[ly.S] + r[ly.CG_DV] * qd[ly.V] + r[ly.CG_DPSI] * qd[ly.PSI]
            rg[ly.RG_SIGN] = 1.0 if rate >= 0 else -1.0
        self.buf = np.zeros(ly.N_AUG)
        self.out = np.zeros(ly.N_AUG)
        self.calls = 0

    def __call__(self, t, y):
        self.calls += 1
        self.buf[:N] = y
        status = rhs_regime(float(t), self.buf, self.model, self.ex, self.work, self.out)
        if status != ly.OK:                 # a state far off (an unstable step): NaN
            return np.full(N, np.nan)
        return self.out[:N].copy()

    def forces(self, t, y):
        self(t, y)
        return self.work.rg[ly.RG_LN:ly.RG_LN + ly.N_POINTS].copy(), self.work.rg[ly.RG_LT]


def dop853(f, t0, y0, T, n):
    A, B, C = dc.A[:12, :12], dc.B, dc.C[:12]
    h = T / n
    y = y0.copy()
    k = np.zeros((12, N))
    k[0] = f(t0, y)
    for i in range(n):
        t = t0 + i * h
        for s in range(1, 12):
            k[s] = f(t + C[s] * h, y + h * (A[s, :s] @ k[:s]))
        y = y + h * (B @ k)
        k[0] = f(t + h, y)
    return y


def phis(Z, kmax):
    """phi_1..phi_kmax of the square matrix Z by one exponential of a block matrix."""
    n = Z.shape[0]
    big = np.zeros(((kmax + 1) * n, (kmax + 1) * n))
    big[:n, :n] = Z
    for k in range(kmax):
        big[k * n:(k + 1) * n, (k + 1) * n:(k + 2) * n] = np.eye(n)
    E = sla.expm(big)
    return [E[:n, (k + 1) * n:(k + 2) * n] for k in range(kmax)]


def jacobian(F, w, Fw):
    """Forward differences of the autonomous F at w (19 evaluations)."""
    n = w.shape[0]
    J = np.empty((n, n))
    for j in range(n):
        d = 1e-7 * max(abs(w[j]), 1e-3)
        v = w.copy()
        v[j] += d
        J[:, j] = (F(v) - Fw) / d
    return J


def exprb43(f, t0, y0, T, n, counts):
    """Hochbruck, Ostermann & Schweitzer (2009), exprb43, on w = (y, t)."""
    def F(w):
        return np.append(f(w[N], w[:N]), 1.0)
    h = T / n
    w = np.append(y0, t0)
    for _ in range(n):
        Fw = F(w)
        J = jacobian(F, w, Fw)
        counts["expm"] += 2
        p1h, = phis(0.5 * h * J, 1)
        p1, _, p3, p4 = phis(h * J, 4)

        def g(v):
            return F(v) - J @ v
        gw = Fw - J @ w
        U2 = w + 0.5 * h * (p1h @ Fw)
        D2 = g(U2) - gw
        U3 = w + h * (p1 @ Fw) + h * (p1 @ D2)
        D3 = g(U3) - gw
        w = w + h * (p1 @ Fw) + h * ((16 * p3 - 48 * p4) @ D2) + h * ((-2 * p3 + 12 * p4) @ D3)
    return w[:N]


def etdrk4(f, t0, y0, T, n, counts, refresh=0, w_jac=None):
    """Cox & Matthews ETDRK4 with L the Jacobian at the span's start, frozen (or taken again
    every ``refresh`` steps, or taken at the earlier state w_jac = (y, t) of the same regime);
    on w = (y, t)."""
    def F(w):
        return np.append(f(w[N], w[:N]), 1.0)
    h = T / n
    w = np.append(y0, t0)

    def operator(w):
        at = w if w_jac is None else w_jac
        L = jacobian(F, at, F(at))
        counts["expm"] += 2
        p1h, = phis(0.5 * h * L, 1)
        p1, p2, p3 = phis(h * L, 3)
        # Cox-Matthews in phi form (Hochbruck & Ostermann, Acta Numerica 2010, eq. 2.39)
        return (L, sla.expm(0.5 * h * L), sla.expm(h * L), p1h, p1 - 3 * p2 + 4 * p3,
                2 * p2 - 4 * p3, -p2 + 4 * p3)
    L, e2, e1, p1h, b1, b23, b4 = operator(w)

    def Nl(v):
        return F(v) - L @ v
    for i in range(n):
        if refresh and i and i % refresh == 0:
            L, e2, e1, p1h, b1, b23, b4 = operator(w)
        Nw = Nl(w)
        a = e2 @ w + 0.5 * h * (p1h @ Nw)
        Na = Nl(a)
        b = e2 @ w + 0.5 * h * (p1h @ Na)
        Nb = Nl(b)
        c = e2 @ a + 0.5 * h * (p1h @ (2 * Nb - Nw))
        Nc = Nl(c)
        w = e1 @ w + h * (b1 @ Nw + b23 @ (Na + Nb) + b4 @ Nc)
    return w[:N]


def spans(run, n_spans, span_s, t_min=2.0):
    """Up to n_spans (t0, y0, regime) at output samples with no event within span_s after."""
    log = run.log
    times = log[:, ly.LOG_T]
    out = []
    t = run.t
    rng = np.random.default_rng(0)
    for i in rng.permutation(np.nonzero(t > t_min)[0]):
        t0 = t[i]
        k = np.searchsorted(times, t0, side="right")
        if k == 0 or (k < len(times) and times[k] < t0 + span_s):
            continue
        if t0 - times[k - 1] < 1e-6:
            continue
        out.append((t0, run.states[i, :N].copy(), int(log[k - 1, ly.LOG_TO])))
        if len(out) == n_spans:
            break
    return out


def earlier_state(run, t0, regime, ago):
    """(y, t) of the output sample ``ago`` s before t0 if the run was in ``regime`` from there
    (no event between) or, failing that, in the same regime then; else None."""
    i = np.searchsorted(run.t, t0 - ago)
    if i >= len(run.t) or i == 0:
        return None
    t1 = run.t[i]
    times = run.log[:, ly.LOG_T]
    k = np.searchsorted(times, t1, side="right")
    if k == 0 or int(run.log[k - 1, ly.LOG_TO]) != regime or t1 - times[k - 1] < 1e-6:
        return None
    return np.append(run.states[i, :N], t1)


def scales(run):
    peak = np.abs(run.states[:, :N]).max(axis=0)
    s = np.empty(N)
    for i in range(N):
        j = PARTNER[i % ly.N_DOF] + (i // ly.N_DOF) * ly.N_DOF
        s[i] = max(peak[i], peak[j])
    return s


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("case", choices=("tip", "notip"))
    ap.add_argument("--spans", type=int, default=12)
    ap.add_argument("--span-ms", type=float, default=2.0)
    ap.add_argument("--steps", default="2,4,8,16,32", help="steps a span, comma-separated")
    ap.add_argument("--methods", default="dop853,exprb43,etdrk4",
                    help="dop853, exprb43, etdrk4 (L frozen over the span), etdrk4-K (L every K "
                         "steps), etdrk4-agoD (L of the regime D ms before)")
    a = ap.parse_args()
    p = Parameters().replace(gap_mm=1.016, tip_mass=a.case == "tip", cork="cubic")
    ex = sine(200.0, 20.0, ramp_s=1.0)
    run = simulate(p, ex, 10.0)
    scale = scales(run)
    lam = run.sensors[:, ly.SIGNALS.index("lambda_n1"):ly.SIGNALS.index("lambda_n4") + 1]
    f_scale = max(np.abs(lam).sum(axis=1).max(), p.m4 * 981.0)  # error_scales.event_scale
    T = a.span_ms * 1e-3
    chosen = spans(run, a.spans, T)
    regimes = [r for _, _, r in chosen]
    print(f"{a.case}: {len(chosen)} spans of {a.span_ms} ms, regimes {sorted(set(regimes))}")
    steps = [int(n) for n in a.steps.split(",")]
    table = {}
    for t0, y0, regime in chosen:
        f = RegimeODE(p, ex, regime, y0)
        ref = solve_ivp(f, (t0, t0 + T), y0, method="DOP853", rtol=1e-12, atol=1e-14 * scale).y[:, -1]
        lam_ref, lt_ref = f.forces(t0 + T, ref)
        for method in a.methods.split(","):
            earlier = None
            if method.startswith("etdrk4-ago"):
                earlier = earlier_state(run, t0, regime, float(method[10:]) * 1e-3)
            for n in steps:
                counts = {"expm": 0}
                f.calls = 0
                try:
                    if method == "dop853":
                        y = dop853(f, t0, y0, T, n)
                    elif method == "exprb43":
                        y = exprb43(f, t0, y0, T, n, counts)
                    elif method == "etdrk4":
                        y = etdrk4(f, t0, y0, T, n, counts)
                    elif method.startswith("etdrk4-ago"):   # L of the regime D ms before
                        if earlier is None:
                            continue
                        y = etdrk4(f, t0, y0, T, n, counts, 0, earlier)
                    else:                                   # etdrk4-K: L every K steps
                        y = etdrk4(f, t0, y0, T, n, counts, int(method.split("-")[1]))
                    calls = f.calls
                    lam, lt = f.forces(t0 + T, y)
                    err = np.max(np.abs(y - ref) / scale)
                    ferr = (np.abs(lam - lam_ref).max() + abs(lt - lt_ref)) / f_scale
                    if not np.isfinite(err + ferr):
                        err = ferr = np.inf
                except (RuntimeError, FloatingPointError, ValueError):   # unstable: no result
                    calls, err, ferr = f.calls, np.inf, np.inf
                table.setdefault((method, n), []).append((err, ferr, calls, counts["expm"]))
    print(f"{'method':12s} {'n':>3s} {'h (s)':>9s} {'state err med':>13s} {'max':>9s} {'force err med':>13s} "
          f"{'max':>9s} {'RHS/ms':>8s} {'expm/ms':>8s}")
    for (method, n), rows in table.items():
        e = np.array(rows)
        print(f"{method:12s} {len(rows):3d} {T / n:9.2e} {np.median(e[:, 0]):13.2e} {e[:, 0].max():9.2e} "
              f"{np.median(e[:, 1]):13.2e} {e[:, 1].max():9.2e} {e[:, 2].mean() / (T * 1e3):8.0f} "
              f"{e[:, 3].mean() / (T * 1e3):8.1f}")


if __name__ == "__main__":
    main()
