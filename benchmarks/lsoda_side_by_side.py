"""The kernel against its own compiled model under scipy's LSODA with events and restarts.

What a user would build instead of the fixed-step event-driven kernel: an
adaptive stiff solver (scipy's ``solve_ivp(method="LSODA")``) integrating one
regime with the workbench's compiled right-hand side (``rhs_regime``),
stopped by the kernel's compiled event functions (``event_values``;
terminal, + to -), the transition applied by the kernel's own
``apply_event`` (projection, Moreau's impact law, regime choice) and a
restart.  Same model, same transitions: only the integration differs.
``make bench`` measures its accuracy against cost on the windows of
``cases.py``; by hand, its speed on a whole run:

    python benchmarks/lsoda_side_by_side.py speed 1e-3 [--no-tip] [--force 200] [--rounds 3]

``speed`` runs the 10 s sine (1.016 mm, 20 Hz, cubic cork, from the static equilibrium)
alternately with the kernel's ``simulate`` (its default step) and with
LSODA at that rtol, and prints both walls (medians) and their ratio.
"""
from __future__ import annotations

import json
import statistics
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

from workbench.core import layout as ly
from workbench.core.config import (EVENT_TIME_TOL, FLOOD_EVENTS, FLOOD_WINDOW_S, GAP_TOL,
                                   STEPPED_TIME_S)
from workbench.core.constrained import rhs_regime
from workbench.core.event_functions import event_values
from workbench.core.hybrid import _immediate_impact, _stepped, apply_event
from workbench.core.sensors import fill_signals
from workbench.core.transitions import choose_regime
from workbench.model import packing as mdl
from workbench.model.drives import sine
from workbench.model.params import Parameters
from workbench.model.regimes import contact_code, is_stick, regime_of, set_of
from workbench.model.step_policy import default_dt, stepped_dt
from workbench.model.simulate import simulate

#: atol of every state component = ATOL_REL * rtol (cm, rad, cm/s, rad/s):
#: the axial coordinates move by ~1e-6 cm.
ATOL_REL = 1e-6
SAMPLE_HZ = 1000.0


class CompiledLSODA:
    """The kernel's compiled regime equations, events and transitions under solve_ivp."""

    def __init__(self, params: Parameters, ex: np.ndarray, method: str = "LSODA"):
        self.model = mdl.build(params)
        self.model.P[ly.P_STEPPED_DT] = stepped_dt(params)     # as simulate sets it
        self.work = mdl.make_work()
        self.ex = ex
        self.method = method
        # the Moreau-Jean episode after a flood steps at the kernel's base step
        self.dt_rule = default_dt(params, ex)
        self.y = np.zeros(ly.N_AUG)
        self.ydot = np.zeros(ly.N_AUG)
        self.sig = np.zeros(ly.N_SIG)
        self.st = np.zeros(ly.N_ST)
        self.log = np.zeros((4, ly.N_LOG))
        self.key = None
        self.nfev = 0
        self.events = []
        for e in range(ly.N_EV):
            fun = (lambda t, y, e=e: self._event(t, y, e))
            fun.terminal = True
            fun.direction = -1.0
            self.events.append(fun)

    def _regime_args(self):
        w = self.work
        return (self.model, self.ex, w)

    def _eval(self, t, y):
        key = (t, y.tobytes())
        if key != self.key:
            self.y[:ly.N_STATE] = y
            status = rhs_regime(t, self.y, *self._regime_args(), self.ydot)
            if status != ly.OK:
                raise RuntimeError(f"rhs_regime status {status} at t = {t}")
            w = self.work
            event_values(self.y, self.model.P, self.model.free, w.cg, w.rg, w.ev, ly.EV_TRY,
                         ly.EV_RATE_TRY)
            self.key = key
            self.nfev += 1

    def _rhs(self, t, y):
        self._eval(t, y)
        return self.ydot[:ly.N_STATE].copy()

    def _event(self, t, y, e):
        self._eval(t, y)
        return self.work.ev[ly.EV_TRY, e]

    def _tip(self, t, y):
        self._eval(t, y)
        w = self.work
        fill_signals(self.y, self.ydot, self.model.P, self.model.tab, self.model.kc, w.rec, w.mat,
                     w.vec, w.cg, w.rg, self.st, self.sig)
        return self.sig[ly.SIG_TIP_Y]

    def _transition(self, e, t, y):
        """Apply event e at (t, y) with the kernel's apply_event; returns the new state."""
        w = self.work
        cur = w.stages[ly.STAGE_CUR]
        cur[:] = 0.0
        cur[:ly.N_STATE] = y
        while e >= 0:
            status = apply_event(e, t, self.model, self.ex, w, self.log, 0, self.st)
            if status != ly.OK:
                raise RuntimeError(f"apply_event status {status} at t = {t}")
            e = _immediate_impact(w.ev)
        self.key = None
        return cur[:ly.N_STATE].copy()

    def _stepped_episode(self, t, t1, y, sample_times, times, tips, shares):
        """The kernel's answer to an event flood: Moreau-Jean steps of the kernel's base step
        over STEPPED_TIME_S; the tip at the samples inside is interpolated linearly.
        Returns the time and state after it.
        """
        w = self.work
        cur = w.stages[ly.STAGE_CUR]
        t_stop = min(t + STEPPED_TIME_S, t1)
        while True:
            h = min(self.dt_rule, t_stop - t)
            if h <= 1e-12:
                break
            reg = regime_of(int(w.rg[ly.RG_SET]), w.rg[ly.RG_STICK] != 0.0)
            tip_a = self._tip(t, y)
            cur[:] = 0.0
            cur[:ly.N_STATE] = y
            status = _stepped(t, h, self.model, self.ex, w, self.st)
            if status != ly.OK:
                raise RuntimeError(f"Moreau-Jean step status {status} at t = {t}")
            y = cur[:ly.N_STATE].copy()
            self.key = None
            tip_b = self._tip(t + h, y)
            for ts in sample_times[(sample_times > t) & (sample_times <= t + h)]:
                times.append(ts)
                tips.append(tip_a + (tip_b - tip_a) * (ts - t) / h)
            shares[reg] = shares.get(reg, 0.0) + h
            t += h
        return t, y

    def run(self, t0, t1, y0, regime, rtol, sample_times):
        """Integrate from (t0, y0) in ``regime`` to t1; the tip height at sample_times.

        Returns (sample times, tip heights (cm), contact-time shares by
        contact code, events).  More than FLOOD_EVENTS events within
        FLOOD_WINDOW_S are handed to the kernel's Moreau-Jean steps, as the
        kernel does.
        """
        w = self.work
        w.rg[:] = 0.0
        w.rg[ly.RG_SET] = set_of(int(regime))
        w.rg[ly.RG_STICK] = 1.0 if is_stick(int(regime)) else 0.0
        w.rg[ly.RG_SIGN] = 1.0
        self.st[:] = 0.0
        self.st[ly.ST_T_IMPACT] = -1e300
        self.st[ly.ST_FLOOD_T0] = -1e300
        self.y[:] = 0.0
        self.y[:ly.N_STATE] = y0
        status = choose_regime(t0, self.y, self.model, self.ex, w, w.stages[ly.STAGE_K1], self.st, GAP_TOL)
        if status != ly.OK:
            raise RuntimeError(f"choose_regime status {status}")
        t, y = t0, self.y[:ly.N_STATE].copy()
        tips, times, shares = [], [], {}
        n_events, recent = 0, []
        while t1 - t > 1e-12:
            reg = regime_of(int(w.rg[ly.RG_SET]), w.rg[ly.RG_STICK] != 0.0)
            inside = sample_times[(sample_times > t) & (sample_times <= t1)]
            try:
                sol = solve_ivp(self._rhs, (t, t1), y, method=self.method, rtol=rtol,
                                atol=ATOL_REL * rtol, events=self.events, t_eval=inside,
                                dense_output=True)
            except ValueError as exc:           # e.g. LSODA returned a step of zero length
                raise RuntimeError(f"solve_ivp at t = {t}: {exc}") from exc
            if sol.status < 0:
                raise RuntimeError(sol.message)
            for k, tk in enumerate(sol.t):
                times.append(tk)
                tips.append(self._tip(tk, sol.y[:, k]))
            fired = [e for e in range(ly.N_EV) if len(sol.t_events[e])]
            t_end = sol.t_events[fired[0]][0] if fired else t1
            shares[reg] = shares.get(reg, 0.0) + (t_end - t)
            if not fired:
                break
            e = min(fired, key=lambda k: sol.t_events[k][0])
            t_e = sol.t_events[e][0]
            # the state just past the event (the kernel's brackets end there too)
            for k in range(1, 40):
                t_past = min(t_e + k * EVENT_TIME_TOL, t1)
                y_past = sol.sol(t_past)
                if self._event(t_past, y_past, e) < 0.0 or t_past >= t1:
                    break
            y = self._transition(e, t_past, y_past)
            t = t_past
            n_events += 1
            recent = [r for r in recent if t - r <= FLOOD_WINDOW_S] + [t]
            if len(recent) > FLOOD_EVENTS:
                t, y = self._stepped_episode(t, t1, y, sample_times, times, tips, shares)
                recent = []
        total = sum(shares.values())
        by_code = {}
        for reg, span in shares.items():
            code = int(contact_code(reg))
            by_code[code] = by_code.get(code, 0.0) + span / total
        return np.array(times), np.array(tips), by_code, n_events


def speed(rtol, tip_mass=True, force=200.0, rounds=3, duration=10.0):
    p = Parameters(cork="cubic", tip_mass=tip_mass).replace(gap_mm=1.016)
    ex = sine(force, 20.0, ramp_s=1.0)
    simulate(p, ex, 0.2)                                     # load the kernels
    first = simulate(p, ex, duration)
    y0 = first.signals.iloc[0][[c for c in first.signals.columns][:ly.N_STATE]].to_numpy(float)
    regime = int(first.signals.regime.iloc[0])
    samples = np.arange(1, round(duration * SAMPLE_HZ) + 1) / SAMPLE_HZ
    kernel, lsoda, events = [], [], None
    for _ in range(rounds):
        start = time.perf_counter()
        run = simulate(p, ex, duration)
        kernel.append(time.perf_counter() - start)
        solver = CompiledLSODA(p, ex)
        start = time.perf_counter()
        _, _, _, events = solver.run(0.0, duration, y0, regime, rtol, samples)
        lsoda.append(time.perf_counter() - start)
    print(json.dumps({"tip_mass": tip_mass, "force_n": force, "rtol": rtol,
                      "kernel_walls": kernel, "lsoda_walls": lsoda,
                      "kernel_events": int(len(run.events) - 1), "lsoda_events": events,
                      "lsoda_nfev": solver.nfev,
                      "ratio_of_medians": statistics.median(lsoda) / statistics.median(kernel)}),
          flush=True)


if __name__ == "__main__":
    args = sys.argv[2:]
    opt = {a: args[i + 1] for i, a in enumerate(args) if a in ("--force", "--rounds")}
    speed(float(args[0]), tip_mass="--no-tip" not in args,
          force=float(opt.get("--force", 200.0)), rounds=int(opt.get("--rounds", 3)))
