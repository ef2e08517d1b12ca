"""The benchmark cases of ``make bench`` and the solvers compared on them.

The cases are the targets' runs at the default settings (1.016 mm gap,
20 Hz, 200 N, cubic cork): the 10 s sine with and without the tip mass, and
the 240 s chirp (5-65 Hz, tip mass).  Accuracy against cost is measured on
a 0.25 s *window* of each sine, a span that starts from the state and
regime the kernel reached there, clear of events, so that slow solvers can
be run on it:

* :func:`kernel_window`: the kernel (RK4, events bracketed) at a given step;
* :func:`lsoda_window`: what a user would build instead, the kernel's own
  compiled model under scipy's LSODA with events and restarts
  (``lsoda_side_by_side.CompiledLSODA``);
* :func:`jet_window`: the slow NumPy reference of the same equations
  (:mod:`workbench.reference`, LSODA, the paper's method).

Errors are against a converged kernel run on the same window (RK4 at
CONVERGED_DT, its own error against half that step reported beside it).
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from lsoda_side_by_side import CompiledLSODA
from workbench.core import layout as ly
from workbench.model.drives import DEFAULT_FORCE_N, chirp, sine
from workbench.model.params import Parameters
from workbench.model.regimes import is_stick, set_of
from workbench.model.simulate import simulate
from workbench.reference import HybridReference, Regime, shaker
from workbench.study.metrics import contact_shares

#: Sample rate of the windows' tip height (Hz).
SAMPLE_HZ = 1000.0
#: Step of the converged kernel run (s); its own error is reported next to it.
CONVERGED_DT = 3.125e-6


@dataclass(frozen=True)
class Case:
    """A benchmark run: 1.016 mm gap, cubic cork, the default force."""

    name: str
    duration_s: float
    tip_mass: bool = True
    chirp: bool = False
    force_n: float = DEFAULT_FORCE_N
    window_at_s: float = 5.0   # the window starts at the first sample clear of events after this
    window_s: float = 0.25

    @property
    def params(self) -> Parameters:
        return Parameters().replace(gap_mm=1.016, tip_mass=self.tip_mass, cork="cubic")

    @property
    def excitation(self) -> np.ndarray:
        if self.chirp:        # seed §5.5: 5 -> 65 Hz over four minutes
            return chirp(self.force_n, 5.0, 65.0, self.duration_s, ramp_s=1.0)
        return sine(self.force_n, 20.0, ramp_s=1.0)


SINE_TIP = Case("sine 10 s, tip mass", 10.0)
SINE_NO_TIP = Case("sine 10 s, no tip mass", 10.0, tip_mass=False)
CHIRP = Case("chirp 240 s, tip mass", 240.0, chirp=True)
CASES = {"sine-tip": SINE_TIP, "sine-no-tip": SINE_NO_TIP, "chirp": CHIRP}


def full_run(case: Case, dt: float | None = None):
    """The whole run at the default (or given) step, with the signals at SAMPLE_HZ."""
    return simulate(case.params, case.excitation, case.duration_s, dt=dt, output_hz=SAMPLE_HZ)


def fixed_run(case: Case):
    """The whole run at fixed RK4 steps of the default step (the method before the controlled one)."""
    return simulate(case.params, case.excitation, case.duration_s, method="rk4",
                    output_hz=SAMPLE_HZ)


#: A window must hold at least this many of the kernel's events.
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
    shares: dict               # contact code (text) -> fraction of the window
    n_events: int
    nfev: int = 0

    def errors(self, converged: "Window") -> dict:
        """Tip-height error relative to the converged tip's range (at the samples both
        hold), and the largest contact-share difference (fraction of the window)."""
        mine = np.rint(self.t * SAMPLE_HZ).astype(np.int64)
        theirs = np.rint(converged.t * SAMPLE_HZ).astype(np.int64)
        _, i, j = np.intersect1d(mine, theirs, return_indices=True)
        if len(i) < 2:
            raise RuntimeError(f"{self.solver} and the converged run share no samples")
        span = np.ptp(converged.tip_y[j])
        tip = float(np.max(np.abs(self.tip_y[i] - converged.tip_y[j])) / span)
        codes = set(self.shares) | set(converged.shares)
        share = max(abs(self.shares.get(c, 0.0) - converged.shares.get(c, 0.0)) for c in codes)
        return {"tip_error_rel": tip, "share_error": float(share)}


def _samples(case: Case, t0: float) -> np.ndarray:
    return t0 + np.arange(round(case.window_s * SAMPLE_HZ) + 1) / SAMPLE_HZ


def kernel_window(case: Case, t0: float, y0: np.ndarray, regime: int, dt: float | None,
                  tol: float | None = None) -> Window:
    """The kernel over the window from (t0, y0) in ``regime``: fixed RK4 steps of dt, or the
    controlled method at ``tol``."""
    start = time.perf_counter()
    run = simulate(case.params, case.excitation, case.window_s, dt=dt, tol=tol,
                   output_hz=SAMPLE_HZ, initial=y0, t0=t0, regime=regime)
    wall = time.perf_counter() - start
    setting = dt if tol is None else tol
    if not run.ok:
        raise RuntimeError(f"kernel window at {run.method} {setting}: {run.message}")
    solver = "workbench RK4" if tol is None else "workbench controlled"
    return Window(solver, setting, wall, run.signals.index.to_numpy(),
                  run.signals.tip_y.to_numpy(), run.contact_time_share(), len(run.events) - 1)


def controlled_window(case: Case, t0: float, y0: np.ndarray, regime: int, tol: float) -> Window:
    """The kernel's controlled method over the window at ``tol``."""
    return kernel_window(case, t0, y0, regime, None, tol)


def lsoda_window(case: Case, t0: float, y0: np.ndarray, regime: int, rtol: float) -> Window:
    """The kernel's compiled model under scipy's LSODA (events, restarts) over the window."""
    solver = CompiledLSODA(case.params, case.excitation)
    start = time.perf_counter()
    t, tip, shares, n_events = solver.run(t0, t0 + case.window_s, y0, regime, rtol,
                                          _samples(case, t0)[1:])
    wall = time.perf_counter() - start
    return Window("compiled model, LSODA", rtol, wall, t, tip,
                  {str(k): v for k, v in shares.items()}, n_events, solver.nfev)


def jet_window(case: Case, t0: float, y0: np.ndarray, regime: int, rtol: float) -> Window:
    """The NumPy reference under LSODA (the paper's method) over the window: atol = rtol / 100."""
    ref = HybridReference(case.params, excitation=shaker(case.excitation), rtol=rtol,
                          atol=rtol * 1e-2, method="LSODA")
    start = time.perf_counter()
    out = ref.run(t0, t0 + case.window_s, y0, Regime(set_of(regime), is_stick(regime)),
                  max_events=10**6, t_eval=_samples(case, t0))
    wall = time.perf_counter() - start
    tip = np.array([ref.model.tip_y(y[:ly.N_DOF]) for y in out.samples])
    events = {"t": [t0] + [e["t"] for e in out.log],
              "to_regime": [regime] + [e["to_regime"] for e in out.log]}
    shares = contact_shares(pd.DataFrame(events), t0, t0 + case.window_s)
    return Window("NumPy reference, LSODA", rtol, wall, np.asarray(out.t), tip, shares,
                  len(out.log), out.nfev)
