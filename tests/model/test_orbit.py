"""Periodic orbits by shooting (model/orbit.py): the stuck joint against the linearised model,
a stick-slip orbit against a long run, and bad input."""
from __future__ import annotations

import json

import numpy as np
import pytest

from workbench import cli
from workbench.core import layout as ly
from workbench.model import drives
from workbench.model.modes import _state_matrix
from workbench.model.orbit import (MAX_STEP, SETTLE, Shooter, error_scales, lattice,
                                   periodic_orbit, reduced_scales)
from workbench.model import packing as mdl
from workbench.model.params import ParameterError, Parameters
from workbench.model.simulate import simulate


def test_the_stuck_joints_orbit_has_the_locked_models_multipliers():
    """0.5 N at 20 Hz: nothing opens or slips, so the orbit is a small oscillation about the
    static equilibrium with the loose body stuck on points 2 and 3: 13 reduced coordinates (7
    positions: the stuck position is free; 6 rates), the stuck position's multiplier 1 (the
    family friction holds), and the others exp(lambda T) of the model with the joint held
    where the contacts hold it, linearised about the static equilibrium (`workbench modes`'s
    linearisation), to 1e-4 relative; the axial mode's (2.6 kHz, |mu| = e^-7.7 = 4.5e-4) is
    at the finite differences' floor, 2e-4 absolute."""
    p = Parameters()
    orbit = periodic_orbit(p, drives.sine(0.5, 20.0))
    assert orbit.status == "ok" and orbit.residual <= 1e-7, orbit.message
    assert orbit.dimension == 13 and sum(orbit.events_per_period.values()) == 0
    assert abs(orbit.neutral - 1.0) < 1e-6 and orbit.stable and orbit.multiplier_error < 2e-4
    lam = np.linalg.eigvals(_state_matrix(p, "locked", "static", orbit.state[:ly.N_DOF]))
    expected = np.exp(lam / 20.0)
    mu = orbit.deciding()
    assert len(mu) == len(expected) == 12
    for m in mu:
        near = expected[np.argmin(np.abs(expected - m))]
        if abs(near) > 1e-2:
            assert abs(m - near) <= 1e-4 * abs(near), (m, near)
        else:
            assert abs(m - near) <= 2e-4, (m, near)
    # the slowest linear mode (about 2 Hz, decay rate zeta omega) sets the settling time
    slowest = lam[np.argmax(lam.real)]
    assert orbit.settle_s() == pytest.approx(np.log(SETTLE) / slowest.real, rel=1e-3)
    assert orbit.slowest_hz() == pytest.approx(abs(slowest.imag) / (2 * np.pi), rel=1e-3)


@pytest.fixture(scope="module")
def stick_slip_orbit():
    """40 N at 30 Hz: each period 2 impacts, a separation and 14-15 stick-slip cycles."""
    return periodic_orbit(Parameters(), drives.sine(40.0, 30.0))


def test_a_stick_slip_orbit_is_found_and_a_run_from_near_it_stays_on_it(stick_slip_orbit):
    """Newton (damped) from a 30-period run converges; a run of 60 periods started 1e-6 of the error
    scales off the orbit ends on it within 1e-5 of the scales, and its every period passes
    through the same events.  Its slowest multiplier (0.9997) is inside the unit circle by
    far more than the variational monodromy's error estimate (below 1e-5): stable."""
    orbit = stick_slip_orbit
    assert orbit.status == "ok" and orbit.stable is True, orbit.to_dict()
    assert orbit.monodromy_method == "variational" and orbit.multiplier_error < 1e-5
    assert orbit.events_per_period["impact"] == 2 and orbit.events_per_period["stick-slip"] > 10
    assert abs(orbit.deciding()).max() < 1.0 - 10 * orbit.multiplier_error
    assert orbit.neutral is not None
    p, f = Parameters(), 30.0
    model = mdl.build(p)
    dt, rate = lattice(p, drives.sine(40.0, f), 1.0 / f)
    start = orbit.state.copy()
    t0 = orbit.phase / f                                # the section's time
    record = simulate(p, drives.sine(40.0, f), 1.0 / f, initial=start, regime=orbit.regime,
                      tol=1e-9, dt=dt, output_hz=rate, t0=t0)
    scale = error_scales(model.P, record.states)
    start[ly.N_DOF + ly.W_B] += 1e-6 * scale[ly.N_DOF + ly.W_B]
    run = simulate(p, drives.sine(40.0, f), 60.0 / f, initial=start, regime=orbit.regime,
                   tol=1e-9, dt=dt, output_hz=rate, t0=t0)
    assert run.ok, run.message
    end = run.states[-1, :ly.N_STATE]
    assert np.max(np.abs(end - orbit.state) / scale) < 1e-5
    kinds = run.events.kind[run.events.kind != "start"]
    assert (kinds == "impact").sum() == 2 * 60


def test_the_orbit_command_prints_the_json_the_issue_names(capsys):
    assert cli.main(["orbit", "--freq-hz", "20", "--force-n", "0.5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("status", "period_s", "periods", "residual", "newton_iterations", "multipliers",
                "stable", "events_per_period", "contact_time_share", "tip_amplitude_cm",
                "wall_s", "grazing", "settle_s", "slowest_multiplier_hz"):
        assert key in out, key
    assert out["status"] == "ok" and out["period_s"] == pytest.approx(0.05)
    assert all(len(m) == 2 for m in out["multipliers"])
    moduli = [abs(complex(*m)) for m in out["multipliers"]]
    assert moduli == sorted(moduli, reverse=True)


def test_a_search_that_does_not_converge_says_so_and_reports_no_orbit():
    """One Newton step allowed from the rocking 200 N, 20 Hz state: the status says no fixed
    point was found, with the residual reached, and no stability is reported for the
    iterate."""
    orbit = periodic_orbit(Parameters(), drives.sine(200.0, 20.0), max_newton=1,
                           newton_tol=1e-30)
    assert orbit.status == "not converged" and orbit.stable is None
    assert np.isfinite(orbit.residual) and orbit.residual > 0


def test_a_newton_step_whose_period_map_fails_is_cut_not_fatal():
    """A Newton step far outside the orbit (a thousand error scales in every reduced
    coordinate: the loose body metres along its slot) makes the period map's run fail; the
    damped step is cut and halved, and what it returns is a state whose map runs (at 47 Hz,
    1.016 mm, 200 N such a step used to end the search with status "failed")."""
    shooter = Shooter(Parameters(), drives.sine(200.0, 20.0))
    x, regime = shooter.guess(shooter.ex)
    manifold = shooter.manifold(x, regime)
    x = manifold.project(x)
    _, _, scale, residual, _ = shooter.residual(x, regime, shooter.ex)
    wild = 1000.0 * reduced_scales(manifold, scale)
    with pytest.raises(ParameterError):
        shooter.residual(manifold.project(manifold.move(x, wild)), regime, shooter.ex)
    moved = shooter._damped(manifold, x, regime, shooter.ex, wild, residual, scale)
    assert np.max(np.abs(manifold.coordinates(moved - x)) / reduced_scales(manifold, scale)) \
        <= MAX_STEP * (1 + 1e-9)
    shooter.residual(moved, regime, shooter.ex)              # runs


def test_bad_input_is_refused_in_one_line(capsys):
    with pytest.raises(ParameterError, match="periods = 0: a whole number of drive periods"):
        periodic_orbit(Parameters(), drives.sine(1.0, 20.0), periods=0)
    with pytest.raises(ParameterError, match="needs a sine drive"):
        periodic_orbit(Parameters(), drives.chirp(1.0, 5.0, 60.0, 1.0))
    assert cli.main(["orbit", "--freq-hz", "20", "--periods", "0"]) == 2
    assert "--periods: 0 is outside the allowed range [1, 64]" in capsys.readouterr().err
