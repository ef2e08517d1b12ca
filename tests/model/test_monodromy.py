"""The monodromy from the variational equations and saltation matrices (core/variational.py,
model/monodromy.py) against finite differences: of the regime's right-hand side (the state
Jacobian) and of the period map (the whole product, through each kind of event)."""
from __future__ import annotations


import numpy as np
import pytest

from workbench.core import layout as ly
from workbench.core import variational as vr
from workbench.core.constrained import rhs_regime
from workbench.model import drives
from workbench.model import packing as mdl
from workbench.model.methods import METHODS
from workbench.model.monodromy import make_var_work
from workbench.model.orbit import (CHECK_FACTOR, FINER_ABOVE, Shooter, multiplier_error,
                                   periodic_orbit, reduced_scales)
from workbench.model.params import Parameters
from workbench.model.regimes import regime_of, set_of, set_of_points
from workbench.model.tableaus import write_tableau


def _period_maps(force_n, freq_hz, periods):
    """The period map at the states a run passes at phase 0, from the guess (a closest
    return, ``Shooter.guess``) on for ``periods`` periods: (shooter, x, regime, manifold,
    record, scale) for each."""
    shooter = Shooter(Parameters(), drives.sine(force_n, freq_hz))
    x, regime = shooter.guess(shooter.ex)
    for _ in range(periods):
        manifold = shooter.manifold(x, regime)
        x = manifold.project(x)
        record, _, scale, _, end = shooter.residual(x, regime, shooter.ex)
        yield shooter, x, regime, manifold, record, scale
        x, regime = record.states[-1, :ly.N_STATE].copy(), end


def _period_map(force_n, freq_hz):
    """The period map at the guess's state, its run, scales and manifold."""
    return next(_period_maps(force_n, freq_hz, 1))


def _scaled(J, manifold, scale):
    d = reduced_scales(manifold, scale)
    return J * d[None, :] / d[:, None]


def _apart(a, b, manifold, scale):
    """The largest difference of two monodromies on the error scales over a's largest entry."""
    a, b = _scaled(a, manifold, scale), _scaled(b, manifold, scale)
    return np.abs(a - b).max() / np.abs(a).max()


@pytest.mark.parametrize("force_n, freq_hz, kinds, sticks", [
    # impacts, separations and slip reversals; the body never sticks
    (200.0, 45.0, {"impact", "separation", "slip-stick"}, False),
    # the paper's case: impacts, separations, stick -> slip and slip -> stick
    (200.0, 20.0, {"impact", "separation", "stick-slip", "slip-stick"}, True),
])
def test_the_variational_monodromy_is_the_period_maps_jacobian(force_n, freq_hz, kinds, sticks):
    """Through every event of a period (the kinds listed; the regimes it passes through
    stick or not as listed) the variational monodromy equals the central differences of
    the period map (1e-6 of the error scales) within 1e-3 of its largest entry on the error
    scales (measured 1.4e-4 at 45 Hz, 2.7e-4 at 20 Hz; differences of 1e-5 give 3.4e-3,
    their truncation through the events, and 1e-7 the noise of the run's tolerance).  It is
    compared on the first period, of the eight from the guess, with those events, where the
    map is differentiable at that step (the differences of twice the step agree within
    1e-3: near a grazing they differ by up to 0.8) and the variational monodromy is what
    the orbits take (within FINER_ABOVE of itself at CHECK_FACTOR times its tolerance;
    else they take another, `Shooter._checked`)."""
    compared = 0
    for shooter, x, regime, manifold, record, scale in _period_maps(force_n, freq_hz, 8):
        seen = {ly.EVENT_KINDS[int(k)] for k in record.log[1:, ly.LOG_KIND]}
        regimes = set(record.signal("regime").astype(int))
        if seen != kinds or any(r % 2 == 1 for r in regimes) != sticks:
            continue
        J, method = shooter.monodromy(manifold, x, regime, shooter.ex, record, scale)
        coarse, _ = shooter.monodromy(manifold, x, regime, shooter.ex, record, scale,
                                      factor=CHECK_FACTOR)
        fd = shooter.fd_monodromy(manifold, x, regime, shooter.ex, scale, 1e-6)
        fd2 = shooter.fd_monodromy(manifold, x, regime, shooter.ex, scale, 2e-6)
        if method != "variational" or _apart(J, coarse, manifold, scale) > FINER_ABOVE \
                or _apart(fd, fd2, manifold, scale) > 1e-3:
            continue
        assert _apart(J, fd, manifold, scale) <= 1e-3
        compared += 1
        break
    assert compared == 1, f"no period of the eight with {kinds} and a differentiable map"


@pytest.mark.parametrize("freq_hz", [20.0, 45.0])
def test_the_variational_monodromy_settles_on_every_period(freq_hz):
    """200 N at 20 Hz (impacts, separations, stick -> slip and slip -> stick) and at 45 Hz
    (rocking impacts, which grow the tangent vectors up to 6.5e4-fold in a period): on each
    of eight periods from the guess the variational monodromy runs through and is within
    FINER_ABOVE of itself at CHECK_FACTOR times its tolerance (measured at most 1.7e-4), so
    the orbits need no other.  Two things this needs: where the record's regime after an
    event is taken over the enumeration's, a slip from rest slips the consistent way (with
    the sign the stick regime had left, the fourth period's monodromy at 20 Hz was off by
    0.17 at the default tolerance and not at the others); and each tangent vector's error
    is measured against its size since the last event, not its start's (else the third
    period at 45 Hz took 19 250 steps for one span and fell to finite differences)."""
    for shooter, x, regime, manifold, record, scale in _period_maps(200.0, freq_hz, 8):
        J, method = shooter.monodromy(manifold, x, regime, shooter.ex, record, scale)
        coarse, _ = shooter.monodromy(manifold, x, regime, shooter.ex, record, scale,
                                      factor=CHECK_FACTOR)
        assert method == "variational", shooter.fallback
        assert _apart(J, coarse, manifold, scale) <= FINER_ABOVE


def test_a_stick_slip_orbits_multipliers_agree_with_finite_differences_within_their_error():
    """40 N at 30 Hz (2 impacts, 14 stick -> slip and 12 slip -> stick a period): at the
    variational orbit the variational multipliers, whose error estimate is below 1e-5, lie
    as near the finite differences' (steps 5e-7, 1e-6, 2e-6 of the scales) as those lie to
    each other (measured: 1.4e-3 from the nearest, the differences 3.6e-3 apart: their
    noise through the stick-slip events); only the variational ones decide the stability:
    with the finite differences' the orbit says its stability is undetermined rather than
    guess.  Friction holds the body (a neutral multiplier), so each method's Newton
    iterates may end on another orbit of the family: the two monodromies are compared at
    the variational one's orbit."""
    ex = drives.sine(40.0, 30.0)
    var = periodic_orbit(Parameters(), ex)
    fd = periodic_orbit(Parameters(), ex, monodromy="finite-difference")
    assert var.status == fd.status == "ok"
    assert var.monodromy_method == "variational" and var.multiplier_error < 1e-5
    assert var.events_per_period["stick-slip"] >= 10 and var.events_per_period["impact"] == 2
    shooter = Shooter(Parameters(), ex, monodromy="finite-difference")
    shooter.phase = var.phase
    manifold = shooter.manifold(var.state, var.regime)
    _, _, scale, _, _ = shooter.residual(var.state, var.regime, shooter.ex)
    at_var = [shooter.fd_monodromy(manifold, var.state, var.regime, shooter.ex, scale, d)
              for d in (5e-7, 1e-6, 2e-6)]
    spread = max(multiplier_error(a, b) for a in at_var for b in at_var)
    assert min(multiplier_error(var.monodromy, a) for a in at_var) <= spread
    assert var.stable is True and fd.stable is None
    assert "stability undetermined" in fd.message and fd.monodromy_method == "finite-difference"


def test_the_state_jacobian_equals_central_differences():
    """A = df/dy of the regime at the guess (phase 0) at 40 N, 30 Hz (points 2 and 3
    sticking), by the kernel's forward differences, against central differences of 1e-4 of
    the scales: within 1e-8 of the largest entry on the error scales (measured 3e-11)."""
    shooter, x, regime, manifold, record, scale = _period_map(40.0, 30.0)
    model = mdl.build(Parameters())
    write_tableau(model.P, METHODS["dop853"].tableau)
    work, vw = mdl.make_work(), make_var_work()
    assert regime == regime_of(set_of_points((1, 2)), True)
    work.rg[ly.RG_SET], work.rg[ly.RG_STICK], work.rg[ly.RG_SIGN] = set_of(regime), 1.0, 1.0
    vw.scale[:] = scale
    y = np.zeros(ly.N_AUG)
    y[:ly.N_STATE] = x
    f = np.zeros(ly.N_AUG)
    assert rhs_regime(0.0, y, model, shooter.ex, work, f) == ly.OK
    assert vr.state_jacobian(0.0, y, f, model, shooter.ex, work, vw) == ly.OK
    central = np.zeros((ly.N_STATE, ly.N_STATE))
    hi, lo = np.zeros(ly.N_AUG), np.zeros(ly.N_AUG)
    for j in range(ly.N_STATE):
        d = 1e-4 * scale[j]
        yp, ym = y.copy(), y.copy()
        yp[j] += d
        ym[j] -= d
        rhs_regime(0.0, yp, model, shooter.ex, work, hi)
        rhs_regime(0.0, ym, model, shooter.ex, work, lo)
        central[:, j] = (hi[:ly.N_STATE] - lo[:ly.N_STATE]) / (2 * d)
    on_scales = (vw.A - central) * scale[None, :] / scale[:, None]
    largest = np.abs(central * scale[None, :] / scale[:, None]).max()
    assert np.abs(on_scales).max() <= 1e-8 * largest


def _off_the_orbit(force_n: float, offset: float, periods: int):
    """The period-1 orbit at ``force_n`` N, 20 Hz (the paper's gap, tip mass and cork), its
    largest multiplier, a run of ``periods`` periods from it and one started ``offset`` of
    the error scales off it along that multiplier's (real part of its) Floquet vector."""
    p, ex = Parameters(), drives.sine(force_n, 20.0)
    orbit = periodic_orbit(p, ex)
    assert orbit.status == "ok", orbit.message
    mu, vec = np.linalg.eig(orbit.monodromy)
    k = int(np.argmax(np.abs(mu)))
    shooter = Shooter(p, ex)
    shooter.phase = orbit.phase
    manifold = shooter.manifold(orbit.state, orbit.regime)
    _, _, scale, _, _ = shooter.residual(orbit.state, orbit.regime, shooter.ex)
    v = np.real(vec[:, k])
    v /= np.max(np.abs(v) / reduced_scales(manifold, scale))
    base = shooter.run(orbit.state, orbit.regime, shooter.ex, periods)
    run = shooter.run(manifold.project(manifold.move(orbit.state, offset * v)), orbit.regime,
                      shooter.ex, periods)
    assert base.ok and run.ok
    return orbit, mu[k], base, run


def test_a_perturbation_along_the_leading_floquet_vector_decays_at_its_multiplier():
    """The paper's case, 200 N at 20 Hz: the orbit is stable, its slowest multiplier a pair
    of modulus 0.99958 at 0.61 rad a period (the 2 Hz bending mode).  Started 1e-5 of the
    error scales off the orbit along that pair's real vector, a run's tip departs from the
    orbit's by an envelope that shrinks by the multiplier's modulus a period: the envelope
    over each 10 periods, fitted over 100 periods, within 1e-4 of |mu| a period (measured
    0.999574 against 0.999582); an unperturbed run from the orbit keeps its amplitude."""
    periods = 100
    orbit, mu, base, run = _off_the_orbit(200.0, 1e-5, periods)
    assert orbit.stable is True
    tip = base.signal("tip_y")
    assert (tip.max() - tip.min()) / 2 == pytest.approx(orbit.tip_amplitude_cm, rel=1e-4)
    n = len(tip) // periods
    departure = np.abs(run.signal("tip_y") - tip)
    envelope = np.array([departure[i * n:(i + 10) * n].max() for i in range(0, periods, 10)])
    per_period = np.exp(np.polyfit(np.arange(len(envelope)) * 10.0, np.log(envelope), 1)[0])
    assert abs(per_period - abs(mu)) < 1e-4, (per_period, abs(mu))


def test_an_unstable_orbit_is_left_at_its_multiplier_along_its_floquet_vector():
    """83.7 N at 20 Hz (1.016 mm, tip mass, cubic cork): the period-1 orbit is unstable, its
    largest multiplier real and negative (-1.203, stick-slip and impacts every period).
    Started 1e-6 of the error scales off it along that multiplier's vector, a run's tip
    departs from the orbit's by an envelope that grows by |mu| a period (fitted over periods
    10-40, where the others have decayed: measured 1.2030 against 1.2030) and changes side
    every period (the multiplier's sign), while the departure stays small (below 1e-3 cm)."""
    periods = 40
    orbit, mu, base, run = _off_the_orbit(83.7, 1e-6, periods)
    assert orbit.stable is False and mu.real < -1.0 and abs(mu.imag) < 1e-9
    n = len(base.signal("tip_y")) // periods
    departure = (run.signal("tip_y") - base.signal("tip_y"))[:periods * n].reshape(periods, n)
    envelope = np.abs(departure).max(axis=1)
    assert envelope.max() < 1e-3
    later = np.arange(10, periods)
    per_period = np.exp(np.polyfit(later, np.log(envelope[later]), 1)[0])
    assert abs(per_period - abs(mu)) < 2e-3, (per_period, abs(mu))
    at_phase = departure[later, 0]
    assert np.all(np.sign(at_phase[1:]) == -np.sign(at_phase[:-1]))
