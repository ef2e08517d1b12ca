"""What an exponential integrator's linear part costs compiled (not adopted).

    python benchmarks/unadopted/phi_cost.py tip|notip [--spans N] [--steps 16] [--repeat R]

docs/performance.md ("Beyond the explicit limit") counts the exponential route with scipy's
cost of a Jacobian with its phi functions (about 140 us).  This script measures that cost
compiled with numba, on the Jacobians of the spans ``exponential_windows.py`` takes from the
10 s sine (1.016 mm, 20 Hz, 200 N, cubic cork):

* the Jacobian of w = (y, t) by forward differences inside numba (19 ``rhs_regime`` calls);
* everything ETDRK4 (Cox & Matthews 2002) needs of Z = hJ: exp(Z/2), phi_1(Z/2), exp(Z),
  phi_1(Z), phi_2(Z), phi_3(Z), by Parlett-Reinsch balancing (powers of 2), a Taylor series
  of degree ``DEGREE`` once ||Z / 2^s||_1 <= THETA, and s squarings by
  phi_k(2A) = 2^-k [e^A phi_k(A) + sum_{j=1..k} phi_j(A) / (k - j)!]
  (Skaflestad & Wright, Appl. Numer. Math. 59 (2009), eq. 2.4); every array preallocated,
  the products by BLAS;
* for comparison, the eigendecomposition of Z and the inverse of its eigenvectors (the route
  by which phi of any multiple of Z, for a dense output, would cost O(n^2) a vector).

It checks the compiled phi functions against scipy (the exponential of an augmented matrix)
by the spans' ETDRK4 errors against scipy's DOP853 at rtol 1e-12 with either, and prints the
median time of each part (``--repeat`` calls on each span's Jacobian) and the squarings taken.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import numba as nb
import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).parent))
import exponential_windows as ew  # noqa: E402

from workbench.core import layout as ly  # noqa: E402
from workbench.core.constrained import rhs_regime  # noqa: E402
from workbench.model.drives import sine  # noqa: E402
from workbench.model.params import Parameters  # noqa: E402
from workbench.model.simulate import simulate  # noqa: E402

N = ly.N_STATE
NW = N + 1
THETA = 0.5
DEGREE = 13
#: 1 / j! for j = 0 .. DEGREE + 3
INV_FACT = np.array([1.0 / np.prod(np.arange(1.0, j + 1.0)) for j in range(DEGREE + 4)])


@nb.njit(cache=True)
def matmul(a, b, c):
    """c = a b for square C-contiguous matrices (BLAS dgemm: 0.43 us at 19 x 19, against
    1.9 us for loops in i-k-j order)."""
    np.dot(a, b, c)


@nb.njit(cache=True)
def balance(Z, d):
    """Parlett-Reinsch balancing in place: Z <- D^-1 Z D with d = diag(D), powers of 2."""
    n = Z.shape[0]
    for i in range(n):
        d[i] = 1.0
    for _ in range(20):
        done = True
        for i in range(n):
            c = 0.0
            r = 0.0
            for j in range(n):
                if j != i:
                    c += abs(Z[j, i])
                    r += abs(Z[i, j])
            if c == 0.0 or r == 0.0:
                continue
            f = 1.0
            s = c + r
            while c < r / 2.0:
                c *= 2.0
                r /= 2.0
                f *= 2.0
            while c >= r * 2.0:
                c /= 2.0
                r *= 2.0
                f /= 2.0
            if (c + r) < 0.95 * s:
                done = False
                d[i] *= f
                for j in range(n):
                    Z[i, j] /= f
                    Z[j, i] *= f
        if done:
            break


@nb.njit(cache=True)
def phi_set(Z, inv_fact, theta, out, work):
    """out[0..3] = phi_0..3(Z), out[4], out[5] = phi_0, phi_1(Z / 2); returns the squarings.

    work: (DEGREE + 8, n, n) scratch; Z is not changed."""
    n = Z.shape[0]
    degree = inv_fact.shape[0] - 4
    d = np.empty(n)          # n floats: the one allocation, outside any loop
    A = work[0]
    A[:, :] = Z
    balance(A, d)
    norm = 0.0
    for j in range(n):
        s = 0.0
        for i in range(n):
            s += abs(A[i, j])
        norm = max(norm, s)
    sq = 0
    while norm > theta:
        norm *= 0.5
        sq += 1
    sq = max(sq, 1)          # Z / 2 is taken on the way
    scale = 0.5 ** sq
    for i in range(n):
        for j in range(n):
            A[i, j] *= scale
    # powers A^1 .. A^degree in work[1 ..]
    P = work[1:degree + 1]
    P[0, :, :] = A
    for p in range(1, degree):
        matmul(P[p - 1], A, P[p])
    for k in range(4):
        phi = out[k]
        for i in range(n):
            for j in range(n):
                phi[i, j] = inv_fact[k] if i == j else 0.0
        for p in range(degree):
            c = inv_fact[p + 1 + k]
            for i in range(n):
                for j in range(n):
                    phi[i, j] += c * P[p, i, j]
    prod = work[degree + 1:degree + 5]
    for level in range(sq):
        if level == sq - 1:
            out[4, :, :] = out[0]
            out[5, :, :] = out[1]
        for k in range(4):
            matmul(out[0], out[k], prod[k])
        for i in range(n):
            for j in range(n):
                p0, p1, p2, p3 = out[0, i, j], out[1, i, j], out[2, i, j], out[3, i, j]
                out[0, i, j] = prod[0, i, j]
                out[1, i, j] = 0.5 * (prod[1, i, j] + p1)
                out[2, i, j] = 0.25 * (prod[2, i, j] + p1 + p2)
                out[3, i, j] = 0.125 * (prod[3, i, j] + 0.5 * p1 + p2 + p3)
    for k in range(6):       # undo the balancing: phi(Z) = D phi(D^-1 Z D) D^-1
        for i in range(n):
            for j in range(n):
                out[k, i, j] *= d[i] / d[j]
    return sq


@nb.njit(cache=True)
def fd_jacobian(t, y, h_fd, model, ex, work, buf, f0, f1, J):
    """J (19 x 19) of w = (y, t) -> (f(t, y), 1) by forward differences; returns a status."""
    for i in range(N):
        buf[i] = y[i]
    status = rhs_regime(t, buf, model, ex, work, f0)
    if status != ly.OK:
        return status
    for j in range(NW):
        d = h_fd * max(abs(y[j]) if j < N else abs(t), 1e-3)
        for i in range(N):
            buf[i] = y[i]
        tt = t
        if j < N:
            buf[j] += d
        else:
            tt += d
        status = rhs_regime(tt, buf, model, ex, work, f1)
        if status != ly.OK:
            return status
        for i in range(N):
            J[i, j] = (f1[i] - f0[i]) / d
        J[N, j] = 0.0
    return ly.OK


@nb.njit(cache=True)
def eigen(Z):
    """The eigendecomposition of Z (LAPACK dgeev through numba), and V^-1 (complex)."""
    lam, V = np.linalg.eig(Z.astype(np.complex128))
    return lam, V, np.linalg.inv(V)


def median_time(fn, repeat):
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts))


def compiled_phis(out, work):
    """Stand-ins for exponential_windows' phis and expm from phi_set (for the error check)."""
    def phis(Z, kmax):
        phi_set(np.ascontiguousarray(Z) * 2.0, INV_FACT, THETA, out, work)   # Z = (2Z) / 2
        if kmax == 1:
            return [out[5].copy()]
        phi_set(np.ascontiguousarray(Z), INV_FACT, THETA, out, work)
        return [out[k].copy() for k in range(1, kmax + 1)]

    def expm(Z):
        phi_set(np.ascontiguousarray(Z), INV_FACT, THETA, out, work)
        return out[0].copy()
    return phis, SimpleNamespace(expm=expm)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("case", choices=("tip", "notip"))
    ap.add_argument("--spans", type=int, default=8)
    ap.add_argument("--span-ms", type=float, default=2.0)
    ap.add_argument("--steps", type=int, default=16, help="ETDRK4 steps a span")
    ap.add_argument("--repeat", type=int, default=200)
    a = ap.parse_args()
    p = Parameters().replace(gap_mm=1.016, tip_mass=a.case == "tip", cork="cubic")
    ex = sine(200.0, 20.0, ramp_s=1.0)
    run = simulate(p, ex, 10.0)
    scale = ew.scales(run)
    T = a.span_ms * 1e-3
    h = T / a.steps
    chosen = ew.spans(run, a.spans, T)
    out = np.zeros((6, NW, NW))
    work = np.zeros((DEGREE + 8, NW, NW))
    J = np.zeros((NW, NW))
    buf, f0, f1 = np.zeros(ly.N_AUG), np.zeros(ly.N_AUG), np.zeros(ly.N_AUG)
    scipy_phis, scipy_sla = ew.phis, ew.sla
    rows = []
    for t0, y0, regime in chosen:
        f = ew.RegimeODE(p, ex, regime, y0)
        assert fd_jacobian(t0, y0, 1e-7, f.model, f.ex, f.work, buf, f0, f1, J) == ly.OK
        Z = h * J
        sq = phi_set(Z, INV_FACT, THETA, out, work)
        t_jac = median_time(lambda: fd_jacobian(t0, y0, 1e-7, f.model, f.ex, f.work, buf, f0,
                                                f1, J), a.repeat)
        t_phi = median_time(lambda: phi_set(Z, INV_FACT, THETA, out, work), a.repeat)
        t_eig = median_time(lambda: eigen(Z), a.repeat)
        ref = solve_ivp(f, (t0, t0 + T), y0, method="DOP853", rtol=1e-12,
                        atol=1e-14 * scale).y[:, -1]
        errs = []
        for phis, sla in ((scipy_phis, scipy_sla), compiled_phis(out, work)):
            ew.phis, ew.sla = phis, sla
            y = ew.etdrk4(f, t0, y0, T, a.steps, {"expm": 0})
            errs.append(np.max(np.abs(y - ref) / scale))
        ew.phis, ew.sla = scipy_phis, scipy_sla
        rows.append((regime, sq, t_jac * 1e6, t_phi * 1e6, errs[0], errs[1], t_eig * 1e6))
        print(f"regime {regime:2d}  squarings {sq:2d}  Jacobian {t_jac * 1e6:6.1f} us  "
              f"phi set {t_phi * 1e6:6.1f} us  eig {t_eig * 1e6:6.1f} us  "
              f"ETDRK4 error, scipy phi {errs[0]:.2e}, compiled {errs[1]:.2e}", flush=True)
    r = np.array(rows)
    med = np.median(r, axis=0)
    print(f"{a.case}: {len(rows)} spans, h = {h:.3g} s; medians: Jacobian {med[2]:.1f} us, "
          f"phi set {med[3]:.1f} us, eig {med[6]:.1f} us (squarings {med[1]:.0f}); "
          f"largest ETDRK4 error scipy {r[:, 4].max():.2e}, compiled {r[:, 5].max():.2e}")

if __name__ == "__main__":
    main()
