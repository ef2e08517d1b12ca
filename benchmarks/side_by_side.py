"""The workbench against the paper's method on the same windows of the same runs.

The reference (:mod:`workbench.reference`: the same equations in NumPy,
LSODA, restarts at every event) costs milliseconds per right-hand side, so
it cannot cover the whole 10 s sine run (about 45 minutes) or the 240 s
chirp in a benchmark.  It is run on *windows* of them: a short span that
starts from the state and regime the workbench reached at that time, clear
of events.  The workbench's own cost is that of the whole run,
per simulated second; the ratio compares seconds of wall time per
simulated second.  The kernel's accuracy is measured on the same windows
(:func:`kernel_window`), against a converged kernel run at a tiny step.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from workbench.core import layout as ly
from workbench.model.excitation import chirp, sine
from workbench.study.metrics import contact_shares
from workbench.model.params import Parameters
from workbench.model.regimes import is_stick, set_of
from workbench.reference import HybridReference, Regime, shaker
from workbench.model.simulate import simulate

#: Sample rate of the windows' tip height (Hz).
SAMPLE_HZ = 1000.0
#: Step of the converged kernel run (s); its own error is reported next to it.
CONVERGED_DT = 3.125e-6


@dataclass(frozen=True)
class Case:
    """A benchmark run: 1.016 mm gap, tip mass, cubic cork."""

    name: str
    force_n: float
    duration_s: float
    window_at_s: float         # the window starts at the first free-flight sample after this
    window_s: float
    chirp: bool = False

    @property
    def params(self) -> Parameters:
        return Parameters().replace(gap_mm=1.016, tip_mass=True, cork="cubic")

    @property
    def excitation(self) -> np.ndarray:
        if self.chirp:        # seed §5.5: 5 -> 65 Hz over four minutes
            return chirp(self.force_n, 5.0, 65.0, self.duration_s, ramp_s=1.0)
        return sine(self.force_n, 20.0, ramp_s=1.0)


#: The benchmark run: 20 N, 20 Hz, 10 s.
SINE = Case("sine 10 s", 20.0, 10.0, window_at_s=5.0, window_s=0.25)
#: The chirp: 10 N, 5-65 Hz over 240 s (seed §5.5).
CHIRP = Case("chirp 240 s", 10.0, 240.0, window_at_s=120.0, window_s=0.25, chirp=True)


def full_run(case: Case, dt: float | None = None):
    """The whole run at the default (or given) step, with the signals at SAMPLE_HZ."""
    return simulate(case.params, case.excitation, case.duration_s, dt=dt, output_hz=SAMPLE_HZ)


#: A window must hold at least this many of the workbench's events.
MIN_WINDOW_EVENTS = 4


def window_start(run, case: Case) -> tuple[float, np.ndarray, int]:
    """(t, state, regime) at the first sample at or after window_at_s with no event
    within 1 ms and at least MIN_WINDOW_EVENTS events in the window that follows."""
    sig = run.signals
    t = sig.index.to_numpy()
    events = run.events.t.to_numpy()
    cols = [*ly.COORD_NAMES, *(c + "_dot" for c in ly.COORD_NAMES)]
    for k in np.flatnonzero(t >= case.window_at_s - 1e-12):
        inside = ((events > t[k]) & (events < t[k] + case.window_s)).sum()
        if inside >= MIN_WINDOW_EVENTS and not (np.abs(events - t[k]) < 1e-3).any():
            return float(t[k]), sig[cols].iloc[k].to_numpy(), int(sig.regime.iloc[k])
    raise RuntimeError(f"no sample clear of events, with events after it, after "
                       f"{case.window_at_s} s in {case.name}")


@dataclass
class Window:
    """One solver's result on a window: tip height at the samples, contact shares, cost."""

    solver: str
    setting: float             # dt (s) or rtol
    wall_s: float
    t: np.ndarray
    tip_y: np.ndarray
    shares: dict
    n_events: int
    nfev: int = 0

    def errors(self, converged: "Window") -> dict:
        """Tip-height error relative to the converged tip's range, and the largest
        contact-share difference (fraction of the window's time)."""
        n = min(len(self.tip_y), len(converged.tip_y))
        span = np.ptp(converged.tip_y[:n])
        tip = float(np.max(np.abs(self.tip_y[:n] - converged.tip_y[:n])) / span)
        codes = set(self.shares) | set(converged.shares)
        share = max(abs(self.shares.get(c, 0.0) - converged.shares.get(c, 0.0)) for c in codes)
        return {"tip_error_rel": tip, "share_error": float(share)}


def kernel_window(case: Case, t0: float, y0: np.ndarray, regime: int, dt: float) -> Window:
    """The workbench over the window from (t0, y0) in ``regime`` at step dt."""
    start = time.perf_counter()
    run = simulate(case.params, case.excitation, case.window_s, dt=dt, output_hz=SAMPLE_HZ,
                   initial=y0, t0=t0, regime=regime)
    wall = time.perf_counter() - start
    if not run.ok:
        raise RuntimeError(f"kernel window at dt = {dt}: {run.message}")
    return Window("workbench RK4", dt, wall, run.signals.index.to_numpy(),
                  run.signals.tip_y.to_numpy(), run.contact_time_share(), len(run.events) - 1)


def reference_window(case: Case, t0: float, y0: np.ndarray, regime: int, rtol: float,
                     method: str = "LSODA") -> Window:
    """The paper's method over the window from (t0, y0) in ``regime``: atol = rtol / 100."""
    ref = HybridReference(case.params, excitation=shaker(case.excitation), rtol=rtol,
                          atol=rtol * 1e-2, method=method)
    n = round(case.window_s * SAMPLE_HZ)
    t_eval = t0 + np.arange(n + 1) / SAMPLE_HZ
    start = time.perf_counter()
    start_regime = Regime(set_of(regime), is_stick(regime))
    out = ref.run(t0, t0 + case.window_s, y0, start_regime, max_events=10**6, t_eval=t_eval)
    wall = time.perf_counter() - start
    tip = np.array([ref.model.tip_y(y[:ly.N_DOF]) for y in out.samples])
    events = {"t": [t0] + [e["t"] for e in out.log],
              "to_regime": [regime] + [e["to_regime"] for e in out.log]}
    shares = contact_shares(pd.DataFrame(events), t0, t0 + case.window_s)
    return Window(f"reference {method}", rtol, wall, out.t, tip, shares, len(out.log), out.nfev)
