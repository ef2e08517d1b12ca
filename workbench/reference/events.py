"""The paper's method: the contact model (docs/model.md §7) by an adaptive solver with restarts.

Seed §2.3: integrate one regime with an adaptive solver (LSODA, as the
paper did, or any other method of scipy's solve_ivp) until a terminal
event, apply the transition, restart.  Slow, and coded independently of
the kernels, so that the tests check the kernels against it and the
benchmarks measure the kernels against it (benchmarks/):

* gaps and tangential coordinates are the formulas of docs/model.md §7 evaluated
  on the jets of :mod:`workbench.reference.equations` (no hand-derived
  gradient or Hessian);
* each regime is solved as the dense KKT system
  [[M, -B^T], [A, 0]] [q'', lambda] = [Q - h, -A' q'] by numpy.linalg.solve;
* events are scipy's terminal events, located on the dense output.

The transition *rules* are those of docs/model.md §7 and the kernel's: the same
impact law (:func:`workbench.core.impact_law.eval_impact`, on Delassus
matrices built here from the jets), the same enumeration of regimes in the
same order with the same tolerances, per-point friction when slipping and
the split-feasibility margin of a sticking double contact (computed here
with numpy); the event thresholds are the kernel's (GAP_EPS, LAMBDA_EPS,
the stick margin's round-off band, RATE_EPS), so that the regime chosen
after an event is the kernel's.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import null_space

from ..core.config import (CLOSED_RATE, FRICTION_REL_EPS, GAP_EPS, GAP_TOL, LAMBDA_EPS, RATE_EPS,
                           REGIME_REL_TOL, REST_RATE)
from ..core.impact_law import NOT_FOUND, OPEN, SLIP_POS, STICK, eval_impact
from ..model.regimes import SETS, regime_of, set_of_points
from .equations import N, Jet, Reference, jcos, jsin



def _incompatible(points):
    """1 with 2, or 3 with 4: the pairs that cannot touch together."""
    return set(points) in ({0, 1}, {2, 3})


def _compatible(points, k):
    return len(points) == 0 or (len(points) == 1 and not _incompatible([points[0], k]))


@dataclass(frozen=True)
class Regime:
    set_index: int = 0
    stick: bool = False
    sign: float = 0.0      # slip direction sigma of tau'

    @property
    def number(self):
        """Regime number 0..16: 2k - 1 stick, 2k slip (docs/model.md §7)."""
        return regime_of(self.set_index, self.stick)

    @property
    def points(self):
        return SETS[self.set_index]

    @property
    def tangent(self):
        """The point whose tangential row a sticking regime holds: the set's first."""
        return self.points[0]


def set_number(points):
    return set_of_points(points)


@dataclass
class ReferenceRun:
    """What :meth:`HybridReference.run` returns.

    ``log`` the events (dicts: t, kind, from_regime, to_regime, point,
    ke_lost), ``y`` the final state, ``t`` and ``samples`` (n, 18) the
    states at the requested sample times reached, ``nfev`` the solver's
    right-hand-side evaluations, ``regime`` the final regime,
    ``fallbacks`` the segments integrated by FALLBACK_METHOD instead.
    """

    log: list
    y: np.ndarray
    t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    samples: np.ndarray = field(default_factory=lambda: np.zeros((0, 2 * N)))
    nfev: int = 0
    regime: Regime = Regime()
    fallbacks: int = 0


#: The method of a segment whose event location failed on LSODA's dense output.
#: solve_ivp brackets an event between the solver's states at a step's ends,
#: then solves for it on the dense output; LSODA's interpolant need not pass
#: through the state at the step's start, so an event value near zero there
#: (a restart just after a transition) can take the other sign, and brentq
#: stops with "f(a) and f(b) must have different signs".  DOP853's dense
#: output is y_old plus terms that vanish at the step's start, so that cannot
#: happen; it is explicit, so it needs no Jacobian by differences of this slow
#: right-hand side (Radau's collocation polynomial would pass through y_old
#: too).  The fallback keeps a run going; it does not make it fast: on the
#: 0.25 s window of the 200 N sine with the tip mass at rtol 1e-3, neither
#: DOP853 nor Radau as the fallback finished within 25 minutes.
FALLBACK_METHOD = "DOP853"


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
        self._contact_cache = (None, None)

    # ---- geometry (docs/model.md §7, the formulas as written) -------------------------
    def contact(self, q, qd):
        """Jets of g1..g4 and tau1..tau4; the last state's kept (a regime's
        event functions ask for the same state's gaps up to four times)."""
        key = (q.tobytes(), qd.tobytes())
        if self._contact_cache[0] != key:
            self._contact_cache = (key, self._contact(q, qd))
        return self._contact_cache[1]

    def _contact(self, q, qd):
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
            B.append(g[k].g[0] + friction * tau[k].g[0])       # each point its own friction
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
        """How far a sticking regime is inside the friction cone (dyn), as docs/model.md §7 reads.

        One point: mu_s lambda_n - |lambda_t|.  Two points: the width of the
        interval of splits alpha (along the unit null vector of the rows n1,
        t1, n2, t2) that keep lambda_n,k >= 0 and |lambda_t,k| <= mu_s
        lambda_n,k at both points.  When the rows on the free joint
        coordinates span less than three dimensions, mu_s sum lambda_n -
        |lambda_t|.
        """
        _, lam_n, lam_t = self.solve(t, y, reg)
        mu = self.p.mu_s
        if len(reg.points) == 1:
            return mu * lam_n.sum() - abs(lam_t)
        k1, k2 = reg.points
        g, tau = self.contact(y[:N], y[N:])
        joint = [k for k in (3, 4, 5) if k in self.free]
        rows = np.array([g[k1].g[0], tau[k1].g[0], g[k2].g[0], tau[k2].g[0]])[:, joint]
        if np.linalg.matrix_rank(rows, tol=1e-9 * np.abs(rows).max()) < 3:
            return mu * lam_n.sum() - abs(lam_t)              # the points' rows coincide
        d = null_space(rows.T)[:, 0]
        d /= np.abs(d).max()
        x0 = np.array([lam_n[k1], lam_t, lam_n[k2], 0.0])
        # conditions C (x0 + alpha d) >= 0: an interval of alpha
        C = np.array([[1, 0, 0, 0], [mu, -1, 0, 0], [mu, 1, 0, 0],
                      [0, 0, 1, 0], [0, 0, mu, -1], [0, 0, mu, 1]], dtype=float)
        c, dd = C @ x0, C @ d
        fixed = dd == 0.0
        if np.any(c[fixed] < 0.0):
            return float(c[fixed].min())
        lo = np.max(-c[dd > 0] / dd[dd > 0], initial=-np.inf)
        hi = np.min(-c[dd < 0] / dd[dd < 0], initial=np.inf)
        return float(min(hi - lo, 1e300))

    def slip_rate(self, y, reg):
        _, tau = self.contact(y[:N], y[N:])
        return tau[reg.tangent].d1[0]

    def events(self, reg, y):
        """Terminal event functions of a regime at state y (each goes + -> - when it happens).

        With the kernel's thresholds (workbench/config.py): an impact at g <
        -GAP_EPS, or below the depth at which a point left if it left
        closed; a separation at lambda_n < -LAMBDA_EPS; stick -> slip past
        the round-off band of the margin; slip -> stick at sigma tau' <
        -RATE_EPS.
        """
        evs = []

        def add(fun, kind, point):
            fun.terminal, fun.direction = True, -1
            fun.kind, fun.point = kind, point
            evs.append(fun)

        g0, _ = self.contact(y[:N], y[N:])
        double_stick = reg.stick and len(reg.points) == 2
        for k in range(4):
            if k in reg.points:
                if not double_stick:         # a sticking pair watches its split in the margin
                    add(lambda t, y, k=k: self.solve(t, y, reg)[1][k] + LAMBDA_EPS,
                        "separation", k)
            else:
                arm = GAP_EPS - min(g0[k].v[0], 0.0)
                add(lambda t, y, k=k, arm=arm: self.contact(y[:N], y[N:])[0][k].v[0] + arm,
                    "impact", k)
        if reg.set_index and reg.stick:
            add(lambda t, y: self.margin(t, y, reg) + self.stick_tolerance(t, y, reg),
                "stick-slip", reg.points[0])
        elif reg.set_index:
            add(lambda t, y: reg.sign * self.slip_rate(y, reg) + RATE_EPS, "slip-stick",
                reg.points[0])
        return evs

    # ---- transitions (docs/model.md §7) -------------------------------------------------
    def closed_points(self, g, point, reg, gap_tol, rate_tol):
        """The event point, the regime's points, then the nearest open points within gap_tol.

        rate_tol < 0 takes any normal rate; otherwise only points at rest.
        """
        pts = [] if point is None else [point]
        pts += [k for k in reg.points if k not in pts and _compatible(pts, k)]
        for _ in range(2):
            near = [k for k in range(4) if k not in pts and g[k].v[0] <= gap_tol
                    and _compatible(pts, k) and (rate_tol < 0 or abs(g[k].d1[0]) <= rate_tol)]
            if near:
                pts.append(min(near, key=lambda k: g[k].v[0]))
        return pts[:2]

    def impact(self, t, y, point, reg, gap_tol=GAP_TOL):
        """Moreau's impact law over the impact set (the kernel's law, workbench.core.impact_law).

        Returns (y+, regime read from the solution, kinetic energy lost).
        """
        q, qd = y[:N], y[N:]
        M, _ = self.model.generalized(t, q, qd)
        f = self.free
        g, tau = self.contact(q, qd)
        pts = self.closed_points(g, point, reg, gap_tol, -1.0)
        if not pts:
            return y, reg, 0.0
        W = np.array([row for k in pts for row in (g[k].g[0], tau[k].g[0])])
        X = np.zeros((N, len(W)))
        X[f] = np.linalg.solve(M[np.ix_(f, f)], W[:, f].T)
        source, P, modes = eval_impact(W @ X, W @ qd, np.full(len(pts), self.p.mu_k), len(pts))
        if source == NOT_FOUND:
            raise RuntimeError(f"the impact law found no solution at t = {t}")
        qd_plus = qd + X @ P
        closed = [(k, mode) for k, mode in zip(pts, modes) if mode != OPEN]
        new = Regime()
        if closed:
            stick = all(mode == STICK for _, mode in closed)
            slips = [mode for _, mode in closed if mode != STICK]
            sign = 1.0 if not slips or slips[0] == SLIP_POS else -1.0
            new = Regime(set_number([k for k, _ in closed]), stick, sign)
            if not stick:
                rate = tau[new.tangent].g[0] @ qd_plus
                if abs(rate) > REST_RATE:
                    new = replace(new, sign=float(np.sign(rate)))
        ke = 0.5 * qd @ M @ qd - 0.5 * qd_plus @ M @ qd_plus
        return np.concatenate([q, qd_plus]), new, ke

    def stick_tolerance(self, t, y, reg):
        """Round-off band of the stick margin (dyn), as the kernel's."""
        _, lam_n, _ = self.solve(t, y, reg)
        return FRICTION_REL_EPS * self.p.mu_s * np.abs(lam_n).sum() + LAMBDA_EPS

    def violation(self, t, y, reg, pts, slip_from_rest):
        """How far a regime is from consistent (<= 0: consistent), as the kernel measures it."""
        q, qd = y[:N], y[N:]
        ydot, lam_n, lam_t = self.solve(t, y, reg)
        qdd = ydot[N:]
        g, tau = self.contact(q, qd)
        f_scale = max(LAMBDA_EPS, np.abs(lam_n).max(), abs(lam_t))
        acc = {k: g[k].g[0] @ qdd + g[k].d2[0] for k in pts}
        a_scale = max([1e-9] + [abs(a) for a in acc.values()])
        worst = -1.0
        double_stick = reg.stick and len(reg.points) == 2
        for k in pts:
            if k in reg.points and double_stick:
                continue                              # the split is in the margin
            worst = max(worst, -(lam_n[k] + LAMBDA_EPS) / f_scale if k in reg.points
                        else -acc[k] / a_scale)
        if reg.set_index and reg.stick:
            tol = self.stick_tolerance(t, y, reg)
            worst = max(worst, -(self.margin(t, y, reg) + 0.5 * tol) / f_scale)
        elif reg.set_index and slip_from_rest:
            T = tau[reg.points[0]]
            at = T.g[0] @ qdd + T.d2[0]
            worst = max(worst, -reg.sign * at / max(a_scale, abs(at)))
        return worst - REGIME_REL_TOL

    def candidates(self, y, proposal, pts):
        """(regime, slip from rest) in the kernel's order: the proposal, then subsets largest first."""
        q, qd = y[:N], y[N:]
        _, tau = self.contact(q, qd)
        out = []
        if all(k in pts for k in proposal.points):
            reg = proposal
            if reg.set_index:
                rate = tau[reg.points[0]].d1[0]
                rest = abs(rate) <= REST_RATE
                if not reg.stick and not rest:
                    reg = replace(reg, sign=float(np.sign(rate)))
                if not (reg.stick and not rest):
                    out.append((reg, not reg.stick and rest))
            else:
                out.append((reg, False))
        m = len(pts)
        for mask in range((1 << m) - 1, -1, -1):
            chosen = [pts[i] for i in range(m) if mask & (1 << i)]
            if not chosen:
                out.append((Regime(), False))
                continue
            if len(chosen) == 2 and _incompatible(chosen):
                continue
            k = set_number(chosen)
            rate = tau[SETS[k][0]].d1[0]
            rest = abs(rate) <= REST_RATE
            if rest:
                out += [(Regime(k, True, 1.0), False), (Regime(k, False, 1.0), True),
                        (Regime(k, False, -1.0), True)]
            else:
                out.append((Regime(k, False, float(np.sign(rate))), False))
        return out

    def choose(self, t, y, proposal, gap_tol=GAP_TOL):
        """The regime at y by the acceleration-level enumeration (the kernel's choose_regime).

        No consistent regime: the impact law at zero approach, then again;
        then the least violated.  Returns (y, regime, kinetic energy lost).
        """
        lost = 0.0
        reg = proposal
        for attempt in range(2):
            g, _ = self.contact(y[:N], y[N:])
            pts = self.closed_points(g, None, reg, gap_tol, CLOSED_RATE)
            scored = []
            for cand, from_rest in self.candidates(y, reg, pts):
                v = self.violation(t, y, cand, pts, from_rest)
                if v <= 0.0:
                    return y, cand, lost
                scored.append((v, len(scored), cand))
            reg = min(scored)[2]
            if attempt == 1 or not pts:
                break
            y, reg, ke = self.impact(t, y, None, reg, gap_tol)
            lost += ke
        return y, reg, lost

    def transition(self, t, y, ev, reg):
        """Apply event ``ev``; returns (y, new regime, log row)."""
        ke_lost = 0.0
        if ev.kind == "impact":
            y, new, ke_lost = self.impact(t, y, ev.point, reg)
        elif ev.kind == "separation":
            keep = [k for k in reg.points if k != ev.point]
            new = Regime(set_number(keep), reg.stick, reg.sign) if keep else Regime()
        elif ev.kind == "stick-slip":
            _, _, lam_t = self.solve(t, y, reg)
            new = Regime(reg.set_index, False, -float(np.sign(lam_t)))
        else:
            new = replace(reg, stick=True)
        y, chosen, lost = self.choose(t, y, new)
        return y, chosen, dict(t=t, kind=ev.kind, from_regime=reg.number,
                               to_regime=chosen.number, point=ev.point + 1,
                               ke_lost=ke_lost + lost)

    # ---- the run ---------------------------------------------------------------------
    def run(self, t0, t1, y0, reg=Regime(), max_events=100, t_eval=None):
        """Integrate from (t0, y0) in regime ``reg`` to t1 (s); returns a :class:`ReferenceRun`.

        Stops after ``max_events`` events (the run's end time is then that of
        the last event).  ``t_eval`` (increasing times in [t0, t1]) asks for
        the states at those times.
        """
        t, y = t0, np.array(y0, dtype=float)
        y, reg, _ = self.choose(t, y, reg)
        log = []
        want = np.zeros(0) if t_eval is None else np.asarray(t_eval, dtype=float)
        want = want[(want >= t0) & (want <= t1 + 1e-12 * max(1.0, abs(t1)))]
        at_end = bool(want.size) and abs(want[-1] - t1) <= 1e-12 * max(1.0, abs(t1))
        if at_end:
            want = want[:-1]
        times, samples, nfev, fallbacks = [], [], 0, 0
        if want.size and want[0] == t0:
            times.append(t0)
            samples.append(y.copy())
        while t < t1 and len(log) < max_events:
            evs = self.events(reg, y)
            asked = want[want > t]
            try:
                sol = self._segment(t, t1, y, reg, evs, asked, self.method)
            except ValueError as exc:
                if self.method != "LSODA" or "different signs" not in str(exc):
                    raise
                sol = self._segment(t, t1, y, reg, evs, asked, FALLBACK_METHOD)
                fallbacks += 1
            nfev += sol.nfev
            if not sol.success:
                raise RuntimeError(sol.message)
            for tt, yy in zip(np.atleast_1d(sol.t), np.reshape(sol.y, (2 * N, -1)).T):
                if tt < t1 or at_end:
                    times.append(tt)
                    samples.append(yy)
            if sol.status == 0:
                return self._result(log, sol.y[:, -1], times, samples, nfev, reg, fallbacks)
            hits = [(te[0], k) for k, te in enumerate(sol.t_events) if len(te)]
            t, k = min(hits)
            y = sol.y_events[k][0]
            y, reg, row = self.transition(t, y, evs[k], reg)
            log.append(row)
        return self._result(log, y, times, samples, nfev, reg, fallbacks)

    def _segment(self, t, t1, y, reg, evs, asked, method):
        """solve_ivp in regime ``reg`` from (t, y) to t1 or its first event."""
        return solve_ivp(lambda tt, yy, r=reg: self.solve(tt, yy, r)[0], (t, t1), y,
                         method=method, rtol=self.rtol, atol=self.atol, events=evs,
                         t_eval=np.append(asked, t1))

    @staticmethod
    def _result(log, y, times, samples, nfev, reg, fallbacks):
        return ReferenceRun(log=log, y=np.asarray(y), t=np.array(times),
                            samples=np.array(samples).reshape(-1, 2 * N), nfev=nfev, regime=reg,
                            fallbacks=fallbacks)
