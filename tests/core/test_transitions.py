"""Transitions in the model (workbench/core/transitions.py), the slot stop and the axial damping.

docs/model.md §5-§7: the end stop's force is minus the gradient of its potential;
the axial coordinates are damped at their own mode's zeta; Moreau-Jean steps
never add kinetic energy and leave no closed point approaching; the
projection onto a chosen regime holds a released point at contact; the
accumulations, inconsistent regimes and event floods of the runs that once failed
end in finished runs with every impact dissipative.
"""
import math

import numpy as np
import pytest

from workbench.model import drives
from workbench.model import packing as mdl
from workbench.core import layout as ly
from workbench.core.constrained import kinetic_energy, project
from workbench.core.contact import eval_geometry
from workbench.core.dynamics import cork_energy, cork_force, eval_inertia
from workbench.core.config import GAP_EPS, STEPPED_TIME_S
from workbench.core.hybrid import _stepped
from workbench.core.transitions import moreau_jean_step
from workbench.model.modes import linear_eigenvalues
from workbench.model.params import ParameterError, Parameters
from workbench.model.run_result import CONTACT_STAT_KEYS
from workbench.model.step_policy import default_dt, stepped_dt
from workbench.model.simulate import simulate


@pytest.mark.parametrize("cork", ["none", "linear", "cubic"])
def test_slot_stop_force_is_minus_the_gradient_of_its_energy(cork):
    P = mdl.pack(Parameters(cork=cork, cork_c=0.0))
    for s in (-1.3, -0.9, -0.2, 0.3, 0.8, 1.7):
        h = 1e-6
        grad = (cork_energy(s + h, P) - cork_energy(s - h, P)) / (2 * h)
        assert cork_force(s, 0.0, P) == pytest.approx(grad, rel=1e-7, abs=1e-3)
    # beyond the travel the stop adds k_stop per cm; inside it adds nothing
    p = Parameters(cork=cork, cork_c=0.0)
    unbounded = mdl.pack(p.replace(s_travel=float("inf")))
    assert cork_force(0.5, 0.0, P) == cork_force(0.5, 0.0, unbounded)
    extra = cork_force(1.0, 0.0, P) - cork_force(1.0, 0.0, unbounded)
    assert extra == pytest.approx(p.k_stop * (1.0 - p.s_travel), rel=1e-12)


def test_slot_travel_accepts_inf_and_refuses_nonsense():
    assert Parameters(s_travel=float("inf")).s_travel == float("inf")
    for bad in (0.0, -1.0, float("nan"), float("-inf")):
        with pytest.raises(ParameterError, match="s_travel"):
            Parameters(s_travel=bad)


@pytest.mark.parametrize("tip", [True, False])
def test_axial_coordinates_are_damped_at_their_own_zeta(tip):
    """c = 2 zeta sqrt(k m) with m = M(0)[u, u]; the axial modes' damping ratios stay near zeta."""
    p = Parameters(tip_mass=tip)
    model, work = mdl.build(p), mdl.make_work()
    zero = np.zeros(ly.N_DOF)
    eval_inertia(zero, zero, model, work)
    for beam, i in (("a", ly.U_A), ("b", ly.U_B)):
        assert p.axial_mass(beam) == pytest.approx(work.mat[ly.MAT_M][i, i], rel=1e-12)
        k = model.kc[ly.KC_K][i, i]
        assert model.kc[ly.KC_C][i, i] == pytest.approx(2 * (p.zeta_a if beam == "a" else p.zeta_b)
                                                        * np.sqrt(k * p.axial_mass(beam)))
    lam = linear_eigenvalues(p)
    fast = lam[np.abs(lam) > 2 * np.pi * 500.0]          # the axial modes (0.9-5.6 kHz)
    zeta = -fast.real / np.abs(fast)
    assert fast.size and np.all(zeta < 0.02) and np.all(zeta > 0.003)


def test_moreau_jean_step_is_plastic_and_dissipative():
    """One step of the fallback from a state whose corner 2 approaches the upper plate."""
    p = Parameters().replace(gap_mm=1.016)
    model, work = mdl.build(p), mdl.make_work()
    y = np.zeros(ly.N_AUG)
    y[ly.V] = p.gap / 2 - 1e-9                  # corner 2 just touching the upper plate
    y[ly.N_DOF + ly.V] = 20.0                   # approaching it at 20 cm/s
    y[ly.N_DOF + ly.S] = 5.0                    # and sliding
    work.stages[ly.STAGE_CUR] = y
    work.rg[:] = 0.0
    st = np.zeros(ly.N_ST)
    h = 1e-4
    status = moreau_jean_step(0.0, h, model, drives.none(), work, st)
    assert status == ly.OK
    after = work.stages[ly.STAGE_CUR]
    # the impulse stopped the approach of corner 2 (plastic) and removed energy
    assert after[ly.N_DOF + ly.V] <= 1e-9
    assert st[ly.ST_E_STEPPED] > 0 and st[ly.ST_N_STEPPED] == 1
    contact_set = int(work.rg[ly.RG_SET])                # {2}, or {2, 4}: it lies flat
    assert 1 in (ly.SET_FIRST[contact_set], ly.SET_SECOND[contact_set])
    eval_inertia(after[:ly.N_DOF], after[ly.N_DOF:ly.N_STATE], model, work)
    ke_after = kinetic_energy(after[ly.N_DOF:ly.N_STATE], work.mat)
    eval_inertia(y[:ly.N_DOF], y[ly.N_DOF:ly.N_STATE], model, work)
    assert ke_after < kinetic_energy(y[ly.N_DOF:ly.N_STATE], work.mat)


@pytest.mark.parametrize("tip_mass", [False, True])
def test_moreau_jean_episode_keeps_the_axial_modes_bounded(tip_mass):
    """An event flood's Moreau-Jean episode (STEPPED_TIME_S in kernel steps) in free flight.

    The scheme is explicit in the elastic forces, stable for omega h < 2:
    at the default step without the tip mass omega h = 2.2 for the axial
    mode, whose rate then grew from 1 to 3.7 cm/s in 11 steps.  Split into steps of at
    most stepped_dt, the axial rate must not grow (the mode is damped).
    """
    p = Parameters(cork="cubic", tip_mass=tip_mass).replace(gap_mm=1.016)
    model, work = mdl.build(p), mdl.make_work()
    dt = default_dt(p)
    steps = round(STEPPED_TIME_S / dt)      # 10 with the tip mass, 16 without

    def episode(limit):
        model.P[ly.P_STEPPED_DT] = limit
        y = work.stages[ly.STAGE_CUR]
        y[:] = 0.0
        y[ly.N_DOF + ly.U_A] = y[ly.N_DOF + ly.U_B] = 1.0     # axial rates (cm/s), free flight
        work.rg[:] = 0.0
        st = np.zeros(ly.N_ST)
        for k in range(steps):
            assert _stepped(k * dt, dt, model, drives.none(), work, st) == ly.OK
        return max(abs(y[ly.N_DOF + ly.U_A]), abs(y[ly.N_DOF + ly.U_B])), st[ly.ST_N_STEPPED]

    rate, n_steps = episode(stepped_dt(p))
    assert rate <= 1.0
    assert n_steps == steps * math.ceil(dt / stepped_dt(p)) >= 2 * steps
    if not tip_mass:                        # one step per kernel step: the mode grows
        assert episode(math.inf)[0] > 2.0


def hard_run(force_n, freq_hz, duration, **changes):
    p = Parameters(cork="cubic", tip_mass=True, **changes).replace(gap_mm=1.016)
    return simulate(p, drives.sine(force_n, freq_hz, ramp_s=1.0), duration)


@pytest.mark.parametrize("force_n, freq_hz", [(100.0, 45.0), (200.0, 50.0), (200.0, 30.0)])
def test_the_diagnosed_failures_finish(force_n, freq_hz):
    """Runs that once failed: accumulations 1 <-> 3, opening impacts, a cycling regime choice, a jam."""
    run = hard_run(force_n, freq_hz, 3.0)
    assert run.ok, run.message
    s = run.summary()
    for key in CONTACT_STAT_KEYS:
        assert key in s
    assert s["n_impacts"] > 100 and s["accumulations"] > 0
    impacts = run.events[run.events.kind == "impact"]
    assert (impacts.ke_lost >= -1e-12 * run.signals.e_kin.max()).all()
    # the slot holds s: within the travel plus what the stop allows under the friction
    over = max(abs(s["s_min_cm"]), abs(s["s_max_cm"])) - run.params.s_travel
    assert over < 1.0
    assert s["max_penetration_cm"] < 1e-6


@pytest.mark.parametrize("mu", [0.0, 1.0])
def test_friction_coefficients_at_the_ends_of_the_range_finish(mu):
    run = hard_run(200.0, 40.0, 2.0, mu_s=mu, mu_k=mu)
    assert run.ok, run.message
    impacts = run.events[run.events.kind == "impact"]
    assert (impacts.ke_lost >= -1e-12 * run.signals.e_kin.max()).all()


@pytest.mark.parametrize("drift_cm", [-5e-9, 5e-9])
def test_projection_of_a_chosen_regime_holds_a_released_point_at_contact(drift_cm):
    """A point released a little below contact (past its event, as at a located
    impact) is held at contact by the projection onto the remaining set that
    choose_regime makes (hold_open_below), not carried deeper."""
    p = Parameters()
    model, work = mdl.build(p), mdl.make_work()
    released, active = 0, 2                   # points 1 and 3; set {3} is set index 3
    q = np.zeros(ly.N_DOF)
    cg = np.zeros_like(work.cg)
    target = np.array([-1e-9, drift_cm])      # g_1 just past its event, g_3 drifted
    joint = [ly.V, ly.PSI]
    for _ in range(20):                       # Newton on (v, psi) for those two gaps
        eval_geometry(q, model.P, cg)
        rows = [ly.CG_G + released, ly.CG_G + active]
        res = cg[rows, ly.CG_VAL] - target
        if np.max(np.abs(res)) < 1e-14:
            break
        jac = cg[np.ix_(rows, [ly.CG_DV, ly.CG_DPSI])]
        q[joint] -= np.linalg.solve(jac, res)
    assert np.max(np.abs(res)) < 1e-14
    y = np.zeros(ly.N_AUG)
    y[:ly.N_DOF] = q
    y[ly.N_DOF + ly.V] = 1.0                  # any rates: the projection zeroes the active row's
    work.rg[:] = 0.0
    work.rg[ly.RG_SET] = active + 1
    work.rg[ly.RG_SIGN] = 1.0
    work.rg[ly.RG_ARM:ly.RG_ARM + ly.N_POINTS] = GAP_EPS
    project(y, model.P, model.free, work.cg, work.cw, work.rg, True)
    eval_geometry(y[:ly.N_DOF], model.P, cg)
    assert abs(cg[ly.CG_G + active, ly.CG_VAL]) < 1e-13
    assert abs(cg[ly.CG_G + released, ly.CG_VAL]) < 1e-13
