"""The paper's method: the contact model (MODEL.md §7) by an adaptive solver with restarts.

Seed §2.3: integrate one regime with an adaptive solver (LSODA, as the
paper did, or any other method of scipy's solve_ivp) until a terminal
event, apply the transition, restart.  Slow, and coded independently of
the kernels, so that the tests check the kernels against it and the
benchmarks measure the kernels against it (benchmarks/, issue 6):

* gaps and tangential coordinates are the formulas of MODEL.md §7 evaluated
  on the jets of :mod:`workbench.reference.equations` (no hand-derived
  gradient or Hessian);
* each regime is solved as the dense KKT system
  [[M, -B^T], [A, 0]] [q'', lambda] = [Q - h, -A' q'] by numpy.linalg.solve;
* events are scipy's terminal events, located on the dense output.

The transition *rules* are those of MODEL.md §7 with the workbench's
documented choices (README "Deviations"): the candidate order of an impact,
the shared tangential row of a double contact, and a sticking double
contact moving its tangential row to the point that stays before the other
separates.  The kernel's small thresholds (GAP_EPS, LAMBDA_EPS, ...) shift
event times by far less than the 1e-6 s the comparison allows.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.integrate import solve_ivp

from .equations import N, Jet, Reference, jcos, jsin

#: Contact sets (0-based points) in the order of MODEL.md §7; index = set number.
SETS = ((), (0,), (1,), (2,), (3,), (0, 2), (0, 3), (1, 2), (1, 3))
#: Impact candidates: double contacts first (MODEL.md §7 "enumerate").
IMPACT_ORDER = (5, 6, 7, 8, 1, 2, 3, 4)
CLOSED = 1e-9          # cm: a gap this small may join an impact


@dataclass(frozen=True)
class Regime:
    set_index: int = 0
    stick: bool = False
    sign: float = 0.0      # slip direction sigma of tau'
    tpt: int = 0           # which point of a double contact holds the tangential row

    @property
    def number(self):
        """Regime number 0..16: 2k - 1 stick, 2k slip (MODEL.md §7)."""
        k = self.set_index
        return 0 if k == 0 else (2 * k - 1 if self.stick else 2 * k)

    @property
    def points(self):
        return SETS[self.set_index]

    @property
    def tangent(self):
        pts = self.points
        return pts[1] if (self.tpt == 1 and len(pts) == 2) else pts[0]


def set_number(points):
    return SETS.index(tuple(sorted(points)))


@dataclass
class ReferenceRun:
    """What :meth:`HybridReference.run` returns.

    ``log`` the events (dicts: t, kind, from_regime, to_regime, point,
    ke_lost), ``y`` the final state, ``t`` and ``samples`` (n, 18) the
    states at the requested sample times reached, ``nfev`` the solver's
    right-hand-side evaluations, ``regime`` the final regime.
    """

    log: list
    y: np.ndarray
    t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    samples: np.ndarray = field(default_factory=lambda: np.zeros((0, 2 * N)))
    nfev: int = 0
    regime: Regime = Regime()


class HybridReference:
    """Events and transitions of the loose joint, by solve_ivp with restarts.

    ``method`` is a solve_ivp method ("LSODA", the paper's, or "DOP853",
    "Radau", ...) with tolerances ``rtol`` and ``atol`` (per state entry,
    cm, rad and their rates).  ``excitation`` is F(t) (dyn) at force1.
    The defaults are the tightest at which LSODA runs the tests' case
    (at rtol 1e-11 it misplaces an impact so that no candidate is
    consistent).
    """

    def __init__(self, p, free=range(N), excitation=None, rtol=1e-10, atol=1e-12,
                 method="LSODA"):
        self.p = p
        self.model = Reference(p, free, excitation)
        self.free = self.model.free
        self.rtol, self.atol, self.method = rtol, atol, method
        self._cache = (None, None)

    # ---- geometry (MODEL.md §7, the formulas as written) -------------------------
    def contact(self, q, qd):
        """Jets of g1..g4 and tau1..tau4."""
        p = self.p
        s, v, psi = (Jet.coord(q, qd, k) for k in (3, 4, 5))
        c, sn = jcos(psi), jsin(psi)
        a = 0.5 * p.h4
        H = a + 0.5 * p.gap
        D = p.x_lip - p.x_in
        g = [0.5 * p.gap + v + a * (1.0 - c),
             0.5 * p.gap - v + a * (1.0 - c),
             (H + v) * c + (D - s) * sn - a,
             (H - v) * c - (D - s) * sn - a]
        tau = [p.x_in + s + a * sn,
               p.x_in + s - a * sn,
               -((D - s) * c - (H + v) * sn),
               -((D - s) * c + (H - v) * sn)]
        return g, tau

    def rows(self, q, qd, reg):
        """Rows A, force directions B and convective terms A' q' of a regime."""
        g, tau = self.contact(q, qd)
        A, B, conv = [], [], []
        if not reg.points:
            return np.zeros((0, N)), np.zeros((0, N)), np.zeros(0), g, tau
        T = tau[reg.tangent]
        friction = 0.0 if reg.stick else -self.p.mu_k * reg.sign
        for k in reg.points:
            A.append(g[k].g[0])
            B.append(g[k].g[0] + friction * T.g[0])
            conv.append(g[k].d2[0])
        if reg.stick:
            A.append(T.g[0])
            B.append(T.g[0])
            conv.append(T.d2[0])
        return np.array(A).reshape(-1, N), np.array(B).reshape(-1, N), np.array(conv), g, tau

    # ---- the equations of one regime -----------------------------------------------
    def _kkt_solve(self, M, A, B, top, bottom):
        """Solve [[M, -B^T], [A, 0]] (x, lambda) = (top, bottom) on the free coordinates."""
        f = self.free
        n, m = len(f), len(A)
        K = np.zeros((n + m, n + m))
        K[:n, :n] = M[np.ix_(f, f)]
        K[:n, n:] = -B[:, f].T
        K[n:, :n] = A[:, f]
        return np.linalg.solve(K, np.concatenate([top, bottom]))

    def solve(self, t, y, reg):
        """(y', lambda_n (4,), lambda_t) of the regime at (t, y); cached for the events."""
        key = (t, y.tobytes(), reg)
        if self._cache[0] == key:
            return self._cache[1]
        q, qd = y[:N], y[N:]
        M, F = self.model.generalized(t, q, qd)
        f = self.free
        A, B, conv, _, _ = self.rows(q, qd, reg)
        n = len(f)
        x = self._kkt_solve(M, A, B, F[f], -conv)
        qdd = np.zeros(N)
        qdd[f] = x[:n]
        lam = x[n:]
        lam_n = np.zeros(4)
        for r, k in enumerate(reg.points):
            lam_n[k] = lam[r]
        lam_t = lam[-1] if reg.stick else 0.0
        out = (np.concatenate([qd, qdd]), lam_n, lam_t)
        self._cache = (key, out)
        return out

    def margin(self, t, y, reg):
        """mu_s sum lambda_n - |lambda_t| (dyn)."""
        _, lam_n, lam_t = self.solve(t, y, reg)
        return self.p.mu_s * lam_n.sum() - abs(lam_t)

    def slip_rate(self, y, reg):
        _, tau = self.contact(y[:N], y[N:])
        return tau[reg.tangent].d1[0]

    def events(self, reg):
        """Terminal event functions of a regime (each goes + -> - when it happens)."""
        evs = []

        def add(fun, kind, point):
            fun.terminal, fun.direction = True, -1
            fun.kind, fun.point = kind, point
            evs.append(fun)

        for k in range(4):
            if k in reg.points:
                add(lambda t, y, k=k: self.solve(t, y, reg)[1][k], "separation", k)
            else:
                add(lambda t, y, k=k: self.contact(y[:N], y[N:])[0][k].v[0], "impact", k)
        if reg.set_index and reg.stick:
            add(lambda t, y: self.margin(t, y, reg), "stick-slip", reg.points[0])
        elif reg.set_index:
            add(lambda t, y: reg.sign * self.slip_rate(y, reg), "slip-stick", reg.points[0])
        return evs

    # ---- transitions (MODEL.md §7) -------------------------------------------------
    def impact(self, t, y, point, reg):
        """Momentum transfer: the first consistent candidate; returns (y+, regime, ke lost)."""
        q, qd = y[:N], y[N:]
        M, _ = self.model.generalized(t, q, qd)
        f = self.free
        g, tau = self.contact(q, qd)
        ke = 0.5 * qd @ M @ qd
        tol = 1e-9 * abs(g[point].d1[0]) + 1e-10
        for cand in IMPACT_ORDER:
            pts = SETS[cand]
            if point not in pts or any(k != point and k not in reg.points and g[k].v[0] > CLOSED
                                       for k in pts):
                continue
            rate = tau[pts[0]].d1[0]
            for stick in (True, False):
                if not stick and rate == 0.0:
                    continue
                r = Regime(cand, stick, 0.0 if stick else float(np.sign(rate)))
                A, B, _, _, _ = self.rows(q, qd, r)
                n = len(f)
                x = self._kkt_solve(M, A, B, np.zeros(n), -A @ qd)
                qd_plus = qd.copy()
                qd_plus[f] += x[:n]
                P = x[n:]
                Pn = P[:len(pts)]
                ok = (Pn >= -1e-12 * np.abs(P).max()).all()
                if stick:
                    ok &= abs(P[-1]) <= self.p.mu_s * Pn.sum() * (1 + 1e-12)
                else:
                    ok &= r.sign * (tau[pts[0]].g[0] @ qd_plus) >= -tol
                for k in range(4):
                    if k not in pts and g[k].v[0] <= CLOSED:
                        ok &= g[k].g[0] @ qd_plus >= -tol
                ke_plus = 0.5 * qd_plus @ M @ qd_plus
                ok &= ke_plus <= ke * (1 + 1e-12)
                if ok:
                    return np.concatenate([q, qd_plus]), r, ke - ke_plus
        raise RuntimeError(f"no consistent impact candidate at t = {t}")

    def settle(self, t, y, reg):
        """The consistent regime at y without a velocity jump (as MODEL.md §7 reads)."""
        for _ in range(12):
            if reg.set_index == 0:
                return reg
            if not reg.stick:
                rate = self.slip_rate(y, reg)
                if abs(rate) > 1e-10:
                    reg = replace(reg, sign=float(np.sign(rate)))
            _, lam_n, lam_t = self.solve(t, y, reg)
            worst = min(reg.points, key=lambda k: lam_n[k])
            if lam_n[worst] < -1e-6:
                reg = self.drop(reg, worst)
                continue
            if reg.stick and self.margin(t, y, reg) < 0.0:
                reg = Regime(reg.set_index, False, -float(np.sign(lam_t)), reg.tpt)
                continue
            return reg
        raise RuntimeError(f"no consistent regime at t = {t}")

    @staticmethod
    def drop(reg, point):
        """Separation of ``point``; a sticking double contact first moves its row off it."""
        keep = [k for k in reg.points if k != point]
        if keep and reg.stick and reg.tangent == point:
            return replace(reg, tpt=1 - reg.tpt)
        return Regime(set_number(keep), reg.stick, reg.sign) if keep else Regime()

    def transition(self, t, y, ev, reg):
        """Apply event ``ev``; returns (y, new regime, log row)."""
        ke_lost = 0.0
        if ev.kind == "impact":
            y, new, ke_lost = self.impact(t, y, ev.point, reg)
        elif ev.kind == "separation":
            new = self.drop(reg, ev.point)
        elif ev.kind == "stick-slip":
            _, _, lam_t = self.solve(t, y, reg)
            new = Regime(reg.set_index, False, -float(np.sign(lam_t)), reg.tpt)
        else:
            new = replace(reg, stick=True)
        settled = self.settle(t, y, new)
        if (ev.kind == "slip-stick" and settled.set_index == reg.set_index
                and not settled.stick and settled.sign == reg.sign):
            settled = replace(settled, stick=True)     # at the friction limit: stick
        return y, settled, dict(t=t, kind=ev.kind, from_regime=reg.number,
                                to_regime=settled.number, point=ev.point + 1, ke_lost=ke_lost)

    # ---- the run ---------------------------------------------------------------------
    def run(self, t0, t1, y0, reg=Regime(), max_events=100, t_eval=None):
        """Integrate from (t0, y0) in regime ``reg`` to t1 (s); returns a :class:`ReferenceRun`.

        Stops after ``max_events`` events (the run's end time is then that of
        the last event).  ``t_eval`` (increasing times in [t0, t1]) asks for
        the states at those times.
        """
        t, y = t0, np.array(y0, dtype=float)
        reg = self.settle(t, y, reg)
        log = []
        want = np.zeros(0) if t_eval is None else np.asarray(t_eval, dtype=float)
        want = want[(want >= t0) & (want <= t1 + 1e-12 * max(1.0, abs(t1)))]
        at_end = bool(want.size) and abs(want[-1] - t1) <= 1e-12 * max(1.0, abs(t1))
        if at_end:
            want = want[:-1]
        times, samples, nfev = [], [], 0
        if want.size and want[0] == t0:
            times.append(t0)
            samples.append(y.copy())
        while t < t1 and len(log) < max_events:
            evs = self.events(reg)
            asked = want[want > t]
            sol = solve_ivp(lambda tt, yy, r=reg: self.solve(tt, yy, r)[0], (t, t1), y,
                            method=self.method, rtol=self.rtol, atol=self.atol, events=evs,
                            t_eval=np.append(asked, t1))
            nfev += sol.nfev
            if not sol.success:
                raise RuntimeError(sol.message)
            for tt, yy in zip(np.atleast_1d(sol.t), np.reshape(sol.y, (2 * N, -1)).T):
                if tt < t1 or at_end:
                    times.append(tt)
                    samples.append(yy)
            if sol.status == 0:
                return self._result(log, sol.y[:, -1], times, samples, nfev, reg)
            hits = [(te[0], k) for k, te in enumerate(sol.t_events) if len(te)]
            t, k = min(hits)
            y = sol.y_events[k][0]
            y, reg, row = self.transition(t, y, evs[k], reg)
            log.append(row)
        return self._result(log, y, times, samples, nfev, reg)

    @staticmethod
    def _result(log, y, times, samples, nfev, reg):
        return ReferenceRun(log=log, y=np.asarray(y), t=np.array(times),
                            samples=np.array(samples).reshape(-1, 2 * N), nfev=nfev, regime=reg)
