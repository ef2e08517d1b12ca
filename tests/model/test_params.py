"""Parameters: every docs/model.md number with its source, validation, units, TOML."""
import math

import pytest

import numpy as np

from workbench.model.params import CORK_MODELS, FIELDS, ParameterError, Parameters, describe


def test_defaults_are_the_model_md_values():
    p = Parameters()
    # docs/model.md §2 (Tables 3, 4, Appendix B) and §6 (Table 6)
    assert (p.rho, p.mu_a, p.rho_i_a, p.m3, p.i3, p.m4, p.i4, p.m6, p.i6) == (
        2.5065, 4.0428, 0.03396, 313.81, 6973.4, 123.33, 1398.6, 158.9, 301.55)
    assert p.cork_law == (3.0, 1.0e4, 1.7e4, "power")
    assert Parameters(cork="static").cork_law[1] == pytest.approx((4.19e7 + 2.23e7 + 7.13e7) / 3, rel=1e-3)


def test_derived_section_matches_the_bar():
    p = Parameters()
    # I = b h^3 / 12 for a 2 in x 1/8 in bar (docs/model.md §2)
    assert p.inertia_a == pytest.approx(5.08 * 0.3175 ** 3 / 12, rel=1e-3)
    assert p.area_a == pytest.approx(1.6129, rel=1e-4)


def test_beam_length_assumption_reproduces_appendix_b():
    # EI = 11 mu wn^2 L^4 / 140 with Appendix B's beam 1 trial 1: EI = 6.862e9, wn = 109.298
    p = Parameters()
    ei = 11 * p.mu_a * 109.298 ** 2 * p.l_a ** 4 / 140
    assert ei == pytest.approx(6.862e9, rel=1e-3)


def test_every_assumption_is_flagged():
    flagged = {row["name"] for row in describe() if row["assumption"]}
    assert {"l_a", "l_b", "l4", "c4", "h4", "gap", "mu_s", "mu_k"} <= flagged
    assert all(row["source"] for row in describe())
    assert len(describe()) == len(FIELDS)


@pytest.mark.parametrize("name, value, words", [
    ("m3", 0.0, ["m3", "0", "(0, inf)"]),
    ("m6", -5.0, ["m6", "-5", "g"]),
    ("l_a", 0.0, ["l_a", "cm"]),
    ("mu_b", -1.0, ["mu_b"]),
    ("gap", 0.6, ["gap", "0.6", "(0, 0.5]"]),
    ("gap", 0.0, ["gap", "(0, 0.5]"]),
    ("zeta_a", 1.0, ["zeta_a", "[0, 1)"]),
    ("e_b", math.nan, ["e_b", "finite", "nan"]),
    ("i4", math.inf, ["i4", "finite"]),
    ("x_force", 40.0, ["x_force", "beam A"]),
    ("mu_k", 0.5, ["mu_k", "mu_s"]),
])
def test_bad_values_name_parameter_value_and_range(name, value, words):
    with pytest.raises(ParameterError) as err:
        Parameters(**{name: value})
    for w in words:
        assert w in str(err.value)


def test_gap_in_mm_is_checked_in_mm():
    assert Parameters().replace(gap_mm=0.762).gap == pytest.approx(0.0762)
    with pytest.raises(ParameterError, match=r"gap_mm = 5.5 mm .*\(0, 5\] mm"):
        Parameters().replace(gap_mm=5.5)
    with pytest.raises(ParameterError, match="gap_mm"):
        Parameters().replace(gap_mm=math.nan)
    assert Parameters().replace(gap_mm=5.0).gap == pytest.approx(0.5)


def test_unknown_cork_lists_the_valid_ones():
    with pytest.raises(ParameterError) as err:
        Parameters(cork="rubber")
    for model in CORK_MODELS:
        assert model in str(err.value)


def test_unknown_name_suggests_close_ones():
    with pytest.raises(ParameterError, match="gap_mm"):
        Parameters.from_user({"gap_m": 1.0})


def test_type_errors():
    with pytest.raises(ParameterError, match="tip_mass"):
        Parameters(tip_mass="yes")
    with pytest.raises(ParameterError, match="m3 must be a number"):
        Parameters(m3="heavy")
    with pytest.raises(ParameterError, match="n_gauss"):
        Parameters(n_gauss=4)


def test_e_in_gpa_and_overrides():
    p = Parameters().replace(e_a_gpa=50.48, cork="linear", cork_k=4.83e5)
    assert p.e_a == pytest.approx(5.048e11)
    assert p.cork_law == (1.0, 4.83e5, 1.7e4, "power")


def test_toml_round_trip_and_errors(tmp_path):
    f = tmp_path / "rig.toml"
    f.write_text('[model]\ngap_mm = 0.508\ntip_mass = false\ncork = "quadratic"\n')
    p = Parameters.from_toml(f)
    assert (p.gap, p.tip_mass, p.cork_law[0]) == (pytest.approx(0.0508), False, 2.0)
    flat = tmp_path / "flat.toml"
    flat.write_text("m3 = 300.0\n")
    assert Parameters.from_toml(flat).m3 == 300.0
    bad = tmp_path / "bad.toml"
    bad.write_text("[model]\nm4 = -2.0\n")
    with pytest.raises(ParameterError, match=r"bad.toml: m4 = -2.0"):
        Parameters.from_toml(bad)
    broken = tmp_path / "broken.toml"
    broken.write_text("gap_mm = = 1\n")
    with pytest.raises(ParameterError, match="not valid TOML"):
        Parameters.from_toml(broken)
    with pytest.raises(ParameterError, match="cannot read"):
        Parameters.from_toml(tmp_path / "missing.toml")


def test_a_run_packs_its_parameters_once(monkeypatch):
    """simulate, its static start and its linear model (the default step, the anti-alias
    filter) share one packing of the parameters; each gets arrays of its own."""
    from workbench.model import packing
    from workbench.model.drives import sine
    from workbench.model.simulate import simulate
    calls = []
    real = packing.pack

    def counting(p, *rest):
        calls.append(p)
        return real(p, *rest)
    monkeypatch.setattr(packing, "pack", counting)
    p = Parameters().replace(gap_mm=0.9137, tip_mass=False)      # packed nowhere else
    simulate(p, sine(20.0, 20.0, ramp_s=0.01), 0.02)
    assert calls == [p]
    a, b = packing.build(p), packing.build(p)
    assert a.P is not b.P and np.array_equal(a.P, b.P) and a.P.flags.writeable
