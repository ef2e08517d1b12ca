"""Whole runs at the default settings, and accuracy against cost on windows of them.

Run by ``make bench``; ``benchmarks/summarise.py`` turns the saved JSON into
the tables of docs/performance.md and the targets table of the README.
Everything here runs in one process, side by side, so that the ratios share
the machine's load of the moment.

* the 10 s sine with and without the tip mass, and the 240 s chirp, whole,
  at the default settings (the controlled method), and the sines at fixed
  RK4 steps of the default step beside them (benchmarks/cases.py
  holds the cases);
* accuracy against cost on a 0.25 s window of each sine: the tip height and
  the contact time shares against a converged run (RK4 at CONVERGED_DT),
  for the kernel at fixed steps (the default and smaller), the controlled
  method at several tolerances, and the kernel's own compiled model under
  scipy's LSODA with events and restarts (what a user would build instead)
  at several tolerances.
"""
import pytest

from cases import (CASES, CONVERGED_DT, controlled_window, fixed_run, full_run,
                          kernel_window, lsoda_window, window_start)
from workbench.model.limits import DEFAULT_TOL
from workbench.model.step_policy import default_dt
from workbench.model.simulate import simulate

#: The kernel's steps on the windows, as fractions of the case's default step.
STEP_FRACTIONS = (1.0, 0.5, 0.25, 0.125)
LSODA_RTOLS = (1e-2, 1e-3, 1e-4, 1e-6)
#: The controlled method's tolerances on the windows (the default among them).
TOLS = (1e-4, DEFAULT_TOL, 1e-6)
WINDOW_CASES = ("sine-tip", "sine-no-tip")
WHOLE_ROUNDS = {"sine-tip": 5, "sine-no-tip": 5, "chirp": 1}


@pytest.fixture(scope="module")
def windows():
    """Each sine's window (start, state, regime) and its converged solution."""
    out = {}
    for key in WINDOW_CASES:
        case = CASES[key]
        run = full_run(case)                      # also loads the cache
        assert run.ok, run.message
        t0, y0, regime = window_start(run, case)
        fine = kernel_window(case, t0, y0, regime, CONVERGED_DT)
        finer = kernel_window(case, t0, y0, regime, CONVERGED_DT / 2)
        out[key] = (t0, y0, regime, fine, finer.errors(fine))
    return out


@pytest.mark.parametrize("key", list(WHOLE_ROUNDS))
def test_whole_run(benchmark, key):
    case = CASES[key]
    simulate(case.params, case.excitation, 0.01)          # load the cache
    run = benchmark.pedantic(full_run, args=(case,), rounds=WHOLE_ROUNDS[key], iterations=1)
    benchmark.extra_info.update({"case": case.name, "simulated_s": run.simulated_s,
                                 "dt": run.dt, "n_events": len(run.events) - 1,
                                 "tip_mass": case.tip_mass, "force_n": case.force_n,
                                 "status": run.message})
    assert run.ok


@pytest.mark.parametrize("key", ["sine-tip", "sine-no-tip"])
def test_whole_run_fixed_step(benchmark, key):
    """The same sines at fixed RK4 steps of the default step, beside the controlled runs."""
    case = CASES[key]
    run = benchmark.pedantic(fixed_run, args=(case,), rounds=WHOLE_ROUNDS[key], iterations=1)
    benchmark.extra_info.update({"case": case.name, "simulated_s": run.simulated_s,
                                 "dt": run.dt, "n_events": len(run.events) - 1,
                                 "method": "rk4", "status": run.message})
    assert run.ok


def _accuracy(benchmark, windows, key, solve, setting, rounds, **extra):
    """Time ``solve`` on the case's window at ``setting`` and record its errors."""
    case = CASES[key]
    t0, y0, regime, fine, own = windows[key]
    window = benchmark.pedantic(solve, args=(case, t0, y0, regime, setting), rounds=rounds,
                                iterations=1)
    benchmark.extra_info.update({
        "case": case.name, "t0": t0, "solver": window.solver, "setting": window.setting,
        "window_s": float(case.window_s), "n_events": window.n_events, "nfev": window.nfev,
        "converged_events": fine.n_events, **window.errors(fine),
        **{f"converged_{k}": v for k, v in own.items()}, **extra})
    assert window.n_events > 0


@pytest.mark.parametrize("fraction", STEP_FRACTIONS)
@pytest.mark.parametrize("key", WINDOW_CASES)
def test_accuracy_kernel(benchmark, windows, key, fraction):
    dt = default_dt(CASES[key].params) * fraction
    _accuracy(benchmark, windows, key, kernel_window, dt, 3, default=fraction == 1.0)


@pytest.mark.parametrize("tol", TOLS)
@pytest.mark.parametrize("key", WINDOW_CASES)
def test_accuracy_controlled(benchmark, windows, key, tol):
    _accuracy(benchmark, windows, key, controlled_window, tol, 3, default=tol == DEFAULT_TOL)


@pytest.mark.parametrize("rtol", LSODA_RTOLS)
@pytest.mark.parametrize("key", WINDOW_CASES)
def test_accuracy_lsoda(benchmark, windows, key, rtol):
    _accuracy(benchmark, windows, key, lsoda_window, rtol, 1)
