"""The workbench against the paper's method, and accuracy against cost.

Run by ``make bench``; ``benchmarks/summarise.py`` turns the saved JSON into
the tables of docs/performance.md.  Everything here runs in one process,
side by side, so that the ratios share the machine's load of the moment.

* the 10 s sine run and the 240 s chirp, whole, at the default step;
* the reference (LSODA, restarts) on a 0.25 s window of each, started from
  the workbench's state there (benchmarks/side_by_side.py says why);
* accuracy against cost on the sine window: the tip height and the contact
  time shares against a converged run (RK4 at CONVERGED_DT), for several
  RK4 steps and several LSODA tolerances.
"""
import numpy as np
import pytest

from side_by_side import (CHIRP, CONVERGED_DT, SINE, full_run, kernel_window, reference_window,
                          window_start)
from workbench.model.simulate import default_dt

KERNEL_STEPS = (1.25e-4, 1e-4, 5e-5, 2.5e-5, 1.25e-5, 6.25e-6)
LSODA_RTOLS = (1e-4, 1e-6, 1e-8, 1e-10)
CASES = {"sine": SINE, "chirp": CHIRP}


@pytest.fixture(scope="module")
def whole_runs():
    """One whole run of each case (warms the cache), and its window's start."""
    out = {}
    for key, case in CASES.items():
        run = full_run(case)
        assert run.ok, run.message
        out[key] = (run, window_start(run, case))
    return out


@pytest.fixture(scope="module")
def converged(whole_runs):
    t0, y0, regime = whole_runs["sine"][1]
    fine = kernel_window(SINE, t0, y0, regime, CONVERGED_DT)
    finer = kernel_window(SINE, t0, y0, regime, CONVERGED_DT / 2)
    return fine, finer.errors(fine)


def _record(benchmark, window, converged=None, **extra):
    info = {"solver": window.solver, "setting": window.setting, "window_s": float(np.ptp(window.t)),
            "n_events": window.n_events, "nfev": window.nfev, **extra}
    if converged is not None:
        fine, own = converged
        info.update(window.errors(fine))
        info.update({f"converged_{k}": v for k, v in own.items()})
    benchmark.extra_info.update(info)


@pytest.mark.parametrize("key", list(CASES))
def test_whole_run(benchmark, whole_runs, key):
    case = CASES[key]
    run = benchmark.pedantic(full_run, args=(case,), rounds=3 if key == "sine" else 1,
                             iterations=1)
    benchmark.extra_info.update({"case": case.name, "simulated_s": run.simulated_s,
                                 "dt": run.dt, "n_events": len(run.events) - 1,
                                 "status": run.message})
    assert run.ok


@pytest.mark.parametrize("key", ["chirp"])
def test_reference_window(benchmark, whole_runs, key):
    """The paper's method at rtol 1e-8 on the chirp's window (the sine's is in the accuracy table)."""
    case = CASES[key]
    t0, y0, regime = whole_runs[key][1]
    window = benchmark.pedantic(reference_window, args=(case, t0, y0, regime, 1e-8), rounds=1,
                                iterations=1)
    diff = kernel_window(case, t0, y0, regime, default_dt(case.params)).errors(window)
    _record(benchmark, window, case=case.name, t0=t0,
            workbench_vs_reference_tip=diff["tip_error_rel"],
            workbench_vs_reference_share=diff["share_error"])
    assert window.n_events > 0


def _accuracy(benchmark, whole_runs, converged, solve, setting, rounds, **extra):
    """Time ``solve`` on the sine window at ``setting`` and record its errors."""
    t0, y0, regime = whole_runs["sine"][1]
    window = benchmark.pedantic(solve, args=(SINE, t0, y0, regime, setting), rounds=rounds,
                                iterations=1)
    _record(benchmark, window, converged, case=SINE.name, t0=t0, **extra)
    assert window.n_events > 0


@pytest.mark.parametrize("dt", KERNEL_STEPS)
def test_accuracy_kernel(benchmark, whole_runs, converged, dt):
    _accuracy(benchmark, whole_runs, converged, kernel_window, dt, 3,
              default=dt == default_dt(SINE.params))


@pytest.mark.parametrize("rtol", LSODA_RTOLS)
def test_accuracy_reference(benchmark, whole_runs, converged, rtol):
    _accuracy(benchmark, whole_runs, converged, reference_window, rtol, 1)
