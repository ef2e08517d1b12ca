"""Benchmarks of the model core (``make bench``); never part of pass/fail.

* one right-hand-side evaluation, timed inside a jitted loop of 10 000 calls
  (a Python call would time numba's argument unboxing, ~40 us, instead):
  the free-flight equations (9 DOF, joint locked) and the regime equations
  of :func:`~workbench.core.constrained.rhs_regime` in free flight, single
  contact and double contact, sticking and sliding;
* a 10 s free-flight run at dt = 5e-5 s (joint locked: without contact the
  loose body would fly through the plates), 200 000 RK4 steps.

The runs with contact and events are in test_bench_runs.py.
"""
import numpy as np
import pytest

from workbench.model import packing as mdl
from workbench.core import layout as ly
from workbench.model.drives import sine
from workbench.model.freeflight import integrate
from workbench.model.params import Parameters

from rhs_parts import RHS, RHS_REGIME, repeat

N_CALLS = 10_000


def _state():
    return np.concatenate([np.random.default_rng(0).normal(size=9) * 0.1, np.zeros(9)])


@pytest.mark.parametrize("fixed", [(), mdl.JOINT], ids=["9dof", "locked"])
def test_rhs_evaluation(benchmark, fixed):
    model, work = mdl.build(Parameters(), fixed=fixed), mdl.make_work()
    y, ydot = _state(), np.zeros(18)
    ex = sine(1.0, 20.0)
    repeat(RHS, 10, y, model, ex, work, ydot)
    benchmark.extra_info["calls_per_round"] = N_CALLS
    status = benchmark(repeat, RHS, N_CALLS, y, model, ex, work, ydot)
    assert status == 0


#: (contact set, stick): free flight; {1} and {1, 3} (the paper's code 13)
REGIMES = {"free": (0, False), "single-stick": (1, True), "single-slip": (1, False),
           "double-stick": (5, True), "double-slip": (5, False)}


@pytest.mark.parametrize("regime", list(REGIMES))
def test_rhs_regime_evaluation(benchmark, regime):
    """rhs_regime: the equations, the contact rows and their 1-3 multipliers (docs/model.md §7)."""
    model, work = mdl.build(Parameters()), mdl.make_work()
    set_index, stick = REGIMES[regime]
    work.rg[ly.RG_SET], work.rg[ly.RG_STICK], work.rg[ly.RG_SIGN] = set_index, float(stick), 1.0
    y, ydot = np.zeros(ly.N_AUG), np.zeros(ly.N_AUG)
    y[:ly.N_STATE] = _state()
    ex = sine(1.0, 20.0)
    repeat(RHS_REGIME, 10, y, model, ex, work, ydot)
    rows = 0 if set_index == 0 else (2 if set_index > 4 else 1) + int(stick)
    benchmark.extra_info.update({"calls_per_round": N_CALLS, "constraint_rows": rows})
    status = benchmark(repeat, RHS_REGIME, N_CALLS, y, model, ex, work, ydot)
    assert status == 0


def test_free_flight_10s(benchmark):
    model = mdl.build(Parameters(), fixed=mdl.JOINT)
    ex = sine(2.0, 20.0)
    integrate(model, mdl.state(), 0.01, 5e-5, 20, ex)     # compile / load cache
    tr = benchmark.pedantic(integrate, args=(model, mdl.state(), 10.0, 5e-5, 20, ex),
                            rounds=3, iterations=1)
    assert tr.status == 0 and len(tr.t) == 10001
