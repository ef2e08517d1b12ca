"""Natural frequencies against an independent FE model and closed forms."""
import json
import math

import numpy as np
import pytest
import scipy.linalg
from fe_reference import cantilever_frequencies, locked_frequencies

from workbench.model import packing as mdl
from workbench.cli import main
from workbench.core import layout as ly
from workbench.core.dynamics import eval_inertia
from workbench.model.modes import natural_frequencies
from workbench.model.params import ParameterError, Parameters

BETA1_L = 1.875104    # first root of cos(bL) cosh(bL) = -1 (Blevins, Formulas for
                      # Natural Frequency and Mode Shape, Table 8-1)


def test_fe_reference_reproduces_the_uniform_cantilever():
    p = Parameters()
    f1 = cantilever_frequencies(p.l_a, p.e_a * p.inertia_a, p.mu_a)[0]
    exact = BETA1_L ** 2 / p.l_a ** 2 * math.sqrt(p.e_a * p.inertia_a / p.mu_a) / (2 * math.pi)
    assert f1 == pytest.approx(exact, rel=1e-6)


@pytest.mark.parametrize("tip", [True, False])
def test_locked_frequencies_match_a_fine_fe_model(tip):
    p = Parameters(tip_mass=tip)
    fe = locked_frequencies(p, n_el=40)
    model = natural_frequencies(p, "locked")
    bending = model[:3]   # the axial modes lie near 1 kHz and above
    assert bending[0] == pytest.approx(fe[0], rel=0.005)
    assert bending[1] == pytest.approx(fe[1], rel=0.005)
    assert bending[2] == pytest.approx(fe[2], rel=0.05)


def test_uniform_cantilever_limit():
    # Everything but beam A made negligible, joint and beam B held: the model
    # is one cubic Hermite cantilever, whose Rayleigh-Ritz frequency is the
    # closed form's from above, within 0.48 % (3.533 vs 3.516 sqrt(EI/mu L^4)).
    tiny = 1e-9
    p = Parameters(m3=tiny, i3=tiny, m4=tiny, i4=tiny, mu_b=tiny, rho_i_b=tiny, tip_mass=False,
                   rho_i_a=tiny)
    m = mdl.build(p, fixed=("s", "v", "psi", "w_B", "phi_B", "u_B"))
    work = mdl.make_work()
    eval_inertia(np.zeros(9), np.zeros(9), m, work)
    f = m.free
    lam = scipy.linalg.eigh(m.kc[ly.KC_K][np.ix_(f, f)], work.mat[ly.MAT_M][np.ix_(f, f)],
                            eigvals_only=True)
    beta1_l = (lam[0] * p.mu_a / (p.e_a * p.inertia_a)) ** 0.25 * p.l_a
    assert beta1_l > BETA1_L
    assert beta1_l == pytest.approx(BETA1_L, rel=0.0025)


def test_free_joint_has_the_rigid_modes_of_the_missing_stiffness():
    f_cubic = natural_frequencies(Parameters(cork="cubic"), "free")
    f_linear = natural_frequencies(Parameters(cork="linear"), "free")
    assert np.sum(f_cubic == 0.0) == 3       # s, v, psi unrestrained at s = 0
    assert np.sum(f_linear == 0.0) == 2      # v, psi
    assert np.all(np.diff(f_linear) >= 0)


def test_cli_modes_json(capsys):
    assert main(["modes", "--tip-mass", "off", "--joint", "locked", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    expected = natural_frequencies(Parameters(tip_mass=False), "locked", "static")
    assert out["frequencies_hz"] == pytest.approx(list(expected))
    assert out["frequencies_hz"] == sorted(out["frequencies_hz"])
    assert out["about"] == "static" and "static equilibrium" in out["linearised_about"]
    assert main(["modes", "--joint", "free", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["about"] == "undeformed"
    assert main(["modes", "--joint", "free", "--about", "static"]) == 2
    assert "--about static needs --joint locked" in capsys.readouterr().err


def test_cli_reports_bad_input(capsys):
    assert main(["modes", "--set", "gap_mm=9"]) == 2
    assert "gap_mm = 9 mm is outside the allowed range (0, 5] mm" in capsys.readouterr().err
    assert main(["modes", "--cork", "cubic", "--set", "m3=nan"]) == 2
    assert "m3 must be finite" in capsys.readouterr().err


def test_stiffness_proportional_damping_gives_its_closed_form_ratios():
    """With both beams' bending blocks at one beta (C_b = beta K_b) and no cork damper, the
    locked bending modes are classically damped: zeta_i = beta omega_i / 2 (Chopra, Dynamics
    of Structures, 4th ed., §11.4.1, stiffness-proportional damping)."""
    from workbench.model.modes import damping_ratios
    p = Parameters()
    beta = p.damping_beta("a")
    q = p.replace(zeta_b=p.zeta_b * beta / p.damping_beta("b"), cork_c=0.0)
    assert q.damping_beta("b") == pytest.approx(beta, rel=1e-12)
    f, zeta = damping_ratios(q, "locked")
    bending = f < 500.0       # the axial modes (about 1 kHz and above) have their own zeta
    assert bending.sum() == 4
    assert zeta[bending] == pytest.approx(beta * np.pi * f[bending], rel=1e-6)


def test_damping_ratios_rise_with_the_cork_damper_and_rigid_modes_have_none():
    from workbench.model.modes import damping_ratios
    f, zeta = damping_ratios(Parameters(cork="linear"), "free")
    f2, zeta2 = damping_ratios(Parameters(cork="linear", cork_c=2 * Parameters(cork="linear").cork_law.c), "free")
    assert np.array_equal(f, f2)
    assert np.isnan(zeta[f == 0.0]).all() and np.isfinite(zeta[f > 0.0]).all()
    cork_mode = int(np.nanargmax(zeta))          # the loose body on the cork's spring and damper
    assert zeta2[cork_mode] > 1.5 * zeta[cork_mode]
    assert np.all((zeta > 0.0) | np.isnan(zeta))


def test_cli_modes_prints_the_damping_ratios(capsys):
    assert main(["modes", "--tip-mass", "on", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["damping_ratios"]) == len(out["frequencies_hz"])
    assert out["damping_ratios"][1] == pytest.approx(0.00437, rel=1e-2)   # mode 2, 13.9 Hz


def test_about_the_static_equilibrium_without_gravity_is_the_undeformed_linearisation():
    """With g = 0 the static equilibrium is the undeformed state, and the tangent stiffness by
    central differences is the elastic one: the same frequencies to the differences' error."""
    from workbench.model.modes import linear_matrices, natural_frequencies
    p = Parameters(tip_mass=True).replace(g=0.0)
    M0, K0, _ = linear_matrices(p, "locked", "undeformed")
    Ms, Ks, _ = linear_matrices(p, "locked", "static")
    assert np.allclose(Ms, M0, rtol=1e-9, atol=0) and np.allclose(Ks, K0, rtol=1e-5, atol=1e-3)
    np.testing.assert_allclose(natural_frequencies(p, "locked", "static"),
                               natural_frequencies(p, "locked", "undeformed"), rtol=1e-6)


def test_gravity_lowers_the_bending_modes_about_the_static_equilibrium():
    """The beams hang under gravity: about the static equilibrium modes 2-3 sit 0.1-1 % below
    the unloaded linearisation (the shift the hammer FRFs show), the axial modes barely move."""
    from workbench.model.modes import natural_frequencies
    p = Parameters(tip_mass=True)
    static = natural_frequencies(p, "locked", "static")
    free = natural_frequencies(p, "locked", "undeformed")
    shift = static[1:3] / free[1:3] - 1.0
    assert np.all(shift < -1e-3) and np.all(shift > -1e-2)
    assert abs(static[-1] / free[-1] - 1.0) < 1e-3
    with pytest.raises(ParameterError, match="needs the joint locked"):
        natural_frequencies(p, "free", "static")
