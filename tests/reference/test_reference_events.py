"""The kernel against the slow reference with events (workbench/reference/events.py).

The paper's own method (seed §2.3): an adaptive solver per regime (LSODA,
rtol 1e-10), terminal events, restarts.  From the paper's start (undeformed, at rest, free
flight) with the tip mass, 36 ms cover impacts into free flight, into
sliding single and double contacts, a stick-slip cycle of contact {4},
separations.

The stick-slip cycle is driven by the beams' axial modes (1-2 kHz, damped
at zeta < 1 %, docs/model.md §5): event by event it needs a step that resolves
them.  The kernel runs at KERNEL_DT (|lambda| dt = 0.26 for the fastest
mode); at the default 1e-4 s (|lambda| dt = 2.05, where RK4 damps that
mode by 0.71 per step) it takes 17 of the reference's 34 events.
"""
import numpy as np
import pytest

from workbench.core.excitation import shaker_force
from workbench.model.drives import chirp, sine
from workbench.reference import HybridReference, shaker
from workbench.core import layout as ly
from workbench.model.params import Parameters
from workbench.model.simulate import simulate

HORIZON = 0.036
KERNEL_DT = 1.25e-5


@pytest.fixture(scope="module")
def both():
    p = Parameters()
    kernel = simulate(p, None, HORIZON, dt=KERNEL_DT, initial="paper")
    ref = HybridReference(p)
    run = ref.run(0.0, HORIZON, np.zeros(2 * ly.N_DOF), t_eval=kernel.signals.index.to_numpy())
    return kernel, run.log, run.y, run, ref


def test_event_times_agree_with_the_reference(both):
    kernel, ref_log = both[:2]
    ev = kernel.events[kernel.events.kind != "start"]
    kinds = {e["kind"] for e in ref_log}
    assert {"impact", "separation", "stick-slip", "slip-stick"} <= kinds
    assert len(ev) == len(ref_log) >= 30
    for k, r in zip(ev.itertuples(), ref_log):
        assert (k.kind, k.from_regime, k.to_regime, k.point) == \
               (r["kind"], r["from_regime"], r["to_regime"], r["point"])
        assert abs(k.t - r["t"]) < 1e-6, (k, r)
        assert k.ke_lost == pytest.approx(r["ke_lost"], rel=1e-5, abs=1e-9)


def test_the_default_tolerance_takes_the_references_events(both):
    """The default method at its default tolerance, not told the step: every event of the
    reference, in order, within 1e-6 s."""
    ref_log = both[1]
    run = simulate(Parameters(), None, HORIZON, initial="paper")
    assert run.ok and run.method == "dop853" and run.control["floor_count"] == 0
    ev = run.events[run.events.kind != "start"]
    assert len(ev) == len(ref_log)
    for k, r in zip(ev.itertuples(), ref_log):
        assert (k.kind, k.from_regime, k.to_regime, k.point) == \
               (r["kind"], r["from_regime"], r["to_regime"], r["point"])
        assert abs(k.t - r["t"]) < 1e-6, (k, r)


def test_end_state_agrees_with_the_reference(both):
    kernel, _, ref_end = both[:3]
    cols = list(ly.COORD_NAMES) + [c + "_dot" for c in ly.COORD_NAMES]
    end = kernel.signals[cols].iloc[-1].to_numpy()
    assert kernel.signals.index[-1] == pytest.approx(HORIZON)
    err = np.abs(end - ref_end)
    # positions to 1e-7 cm (rad), velocities to 5e-5 cm/s (the axial rates)
    assert err[:ly.N_DOF].max() < 1e-7, err
    assert err[ly.N_DOF:].max() < 5e-5, err


def test_sampled_tip_height_agrees_with_the_reference(both):
    kernel, _, _, run, ref = both
    assert run.t == pytest.approx(kernel.signals.index.to_numpy(), abs=1e-12)
    tip = np.array([ref.model.tip_y(y[:ly.N_DOF]) for y in run.samples])
    assert np.abs(tip - kernel.signals.tip_y.to_numpy()).max() < 1e-7
    assert run.nfev > 0


@pytest.mark.parametrize("ex", [sine(20.0, 35.0, ramp_s=0.5), chirp(10.0, 5.0, 65.0, 240.0, ramp_s=1.0)],
                         ids=["sine", "chirp"])
def test_reference_drive_agrees_with_the_kernels(ex):
    """The reference writes the shaker force out again; both read the same array."""
    force = shaker(ex)
    for t in (0.0, 0.13, 0.49, 0.77, 1.5, 120.25, 239.9):
        assert force(t) == pytest.approx(shaker_force(t, ex), rel=1e-12, abs=1e-9)


def test_a_failed_event_location_on_lsoda_is_redone_by_the_fallback_method(monkeypatch):
    """scipy's brentq on LSODA's dense output can find no sign change (FALLBACK_METHOD's
    docstring): that segment is integrated again by FALLBACK_METHOD, and the run goes on."""
    p = Parameters()
    kernel = simulate(p, None, 0.024, dt=KERNEL_DT, initial="paper")
    cols = list(ly.COORD_NAMES) + [c + "_dot" for c in ly.COORD_NAMES]
    y0 = kernel.signals[cols].iloc[-1].to_numpy()       # free flight, 1 ms before an impact
    # to 25.7 ms: the impact, stick-slip, slip-stick and stick-slip again
    plain = HybridReference(p).run(0.024, 0.0257, y0)
    segment = HybridReference._segment
    failed = []

    def fail_once(self, t, t1, y, reg, evs, asked, method):
        if method == "LSODA" and not failed:
            failed.append(t)
            raise ValueError("f(a) and f(b) must have different signs")
        return segment(self, t, t1, y, reg, evs, asked, method)

    monkeypatch.setattr(HybridReference, "_segment", fail_once)
    run = HybridReference(p).run(0.024, 0.0257, y0)
    assert plain.fallbacks == 0 and run.fallbacks == 1 and failed == [0.024]
    assert len(plain.log) >= 4
    assert [(e["kind"], e["to_regime"]) for e in run.log] == \
           [(e["kind"], e["to_regime"]) for e in plain.log]
    assert max(abs(a["t"] - b["t"]) for a, b in zip(run.log, plain.log)) < 1e-8
    assert np.abs(run.y - plain.y)[:ly.N_DOF].max() < 1e-8


def test_other_errors_of_a_segment_are_not_retried(monkeypatch):
    def broken(self, *args):
        raise ValueError("some other failure")

    monkeypatch.setattr(HybridReference, "_segment", broken)
    with pytest.raises(ValueError, match="some other failure"):
        HybridReference(Parameters()).run(0.0, 0.001, np.zeros(2 * ly.N_DOF))
