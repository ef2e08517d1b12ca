"""Parameter identification: the paper's tables, the decrement, the cork
fit, the strain calibration and the PVDF contact detection."""
import math

import numpy as np
import pandas as pd
import pytest

from workbench.identify import (calibrate_patch, cantilever_strain, decrement_from_record,
                                detect_contacts, contact_code_series, euler_double_integral,
                                fit_cork, hammer_record, hooke_stiffness, log_decrement,
                                parallel_axis)
from workbench.identify import paper as P
from workbench.identify import tables as T
from workbench.model.params import ParameterError


def test_appendix_b_reproduced_to_the_printed_digits():
    """Every Td, zeta, omega_n, EI and E of Appendix B, and the §4.4 means."""
    table = T.appendix_b()
    assert len(table) == 6 * 5 + 2
    assert (table.agrees == "yes").all(), table[table.agrees != "yes"]


def test_tables_4_and_5_reproduced():
    for table in (T.table4(), T.table5()):
        computed = table[table.workbench != ""]
        assert len(computed) >= 3 and (computed.agrees == "yes").all(), computed


def test_log_decrement_named_fields_and_textbook_convention():
    # A decay x = exp(-zeta wn t) cos(wd t) sampled at its peaks: exact answers.
    zeta, wn = 0.02, 2 * math.pi * 3.0
    wd = wn * math.sqrt(1 - zeta ** 2)
    n = 10
    tn = (n - 1) * 2 * math.pi / wd
    d = log_decrement(1.0, math.exp(-zeta * wn * tn), 0.0, tn, n,
                      appendix_b_conventions=False, td_round_s=None, mu=4.0, length=30.0,
                      area_moment=0.0135)
    assert d.zeta == pytest.approx(zeta, rel=1e-12)
    assert d.omega_n == pytest.approx(wn, rel=1e-12)
    assert d.Td == pytest.approx(2 * math.pi / wd, rel=1e-12)
    assert d.EI == pytest.approx(11 / 140 * 4.0 * wn ** 2 * 30.0 ** 4, rel=1e-12)
    assert d.E == pytest.approx(d.EI / 0.0135)


def test_decrement_from_a_sampled_record():
    zeta, f = 0.01, 17.0
    wn = 2 * math.pi * f
    t = np.arange(0, 3.0, 1e-4)
    x = np.exp(-zeta * wn * t) * np.cos(wn * math.sqrt(1 - zeta ** 2) * t)
    d = decrement_from_record(t, x)
    assert d.zeta == pytest.approx(zeta, rel=2e-3)
    assert d.omega_n == pytest.approx(wn, rel=1e-5)


@pytest.mark.parametrize("args, name", [((0.1, 0.2, 0.0, 1.0, 5), "xn"), ((1.0, 0.5, 1.0, 0.5, 5), "tn"),
                                        ((1.0, 0.5, 0.0, 1.0, 1), "n"), ((-1.0, 0.5, 0.0, 1.0, 5), "x1")])
def test_log_decrement_refuses_bad_input(args, name):
    with pytest.raises(ParameterError, match=name):
        log_decrement(*args)


def test_parallel_axis_and_hooke():
    assert parallel_axis(10.0, 2.0, 3.0) == 28.0
    assert hooke_stiffness(3.0, 1.0, 0.5) == 6.0
    with pytest.raises(ParameterError, match="load_gap"):
        hooke_stiffness(3.0, 0.5, 1.0)


def test_strain_calibration_recovers_a_known_scale_factor():
    """A cantilever's first-mode release: tip acceleration -> Euler double integral
    -> Eq. 3 strain; the patch voltage is that strain / k (plus noise)."""
    L, x, c, k_true = 33.0, 13.4, 0.15875, 1.77e-5
    w, zeta = 2 * math.pi * 4.0, 0.01
    t = np.arange(0, 5.0, 1e-4)
    tip = 2.7 * np.exp(-zeta * w * t) * np.cos(w * t)
    accel = np.gradient(np.gradient(tip, t), t)
    rng = np.random.default_rng(0)
    volts = cantilever_strain(tip, c, x, L) / k_true + rng.normal(0, 0.5, t.shape)
    # the integral starts from rest at 0: it recovers tip up to the quadratic it removes
    d = euler_double_integral(t, accel)
    corr = np.corrcoef(d, tip - tip.mean())[0, 1]
    assert corr > 0.999
    assert calibrate_patch(t, accel, volts, c=c, x=x, length=L) == pytest.approx(k_true, rel=0.02)
    with pytest.raises(ParameterError, match="x = 40"):
        cantilever_strain(1.0, c, 40.0, L)


def test_cork_fit_recovers_a_linear_spring_from_a_noisy_record():
    law, k, c, v0 = "linear", 2.7e5, 1.1e4, 15.0
    t, a = hammer_record(law, k, c, v0, dt=2e-4, duration=0.3)
    rng = np.random.default_rng(1)
    noisy = a + rng.normal(0, 0.02 * np.abs(a).max(), a.shape)
    fit = fit_cork(t, noisy, law)
    for name, truth in (("k", k), ("c", c), ("v0", v0)):
        assert getattr(fit, name) == pytest.approx(truth, rel=0.02)
        lo, hi = fit.intervals[name]
        assert lo <= truth <= hi and hi / lo < 1.1


def test_cork_fit_says_when_a_cubic_stiffness_is_not_identifiable():
    """At hammer velocities the cubic spring force is ~1e-4 of the damping force:
    the fit must recover c and v0 and give k an interval that holds the truth."""
    law, k, c, v0 = "cubic", 1.0e4, 2.2e4, 15.0
    t, a = hammer_record(law, k, c, v0, dt=2e-4, duration=0.3)
    noisy = a + np.random.default_rng(2).normal(0, 0.02 * np.abs(a).max(), a.shape)
    fit = fit_cork(t, noisy, law)
    assert fit.c == pytest.approx(c, rel=0.03) and fit.v0 == pytest.approx(v0, rel=0.03)
    lo, hi = fit.intervals["k"]
    assert lo <= k <= hi and (lo == 0.0 or hi / lo > 100)


def _pulses(t, spec):
    """Four patch voltages with a half-sine pulse of height h on [t0, t1] per (patch, t0, t1, h)."""
    v = np.zeros((len(t), 4))
    for patch, t0, t1, h in spec:
        on = (t >= t0) & (t <= t1)
        v[on, patch - 1] += h * np.sin(np.pi * (t[on] - t0) / (t1 - t0))
    return v


def test_contact_detection_merges_patches_into_codes():
    t = np.arange(0, 1.0, 1e-4)
    v = _pulses(t, [(1, 0.10, 0.12, 1.0), (4, 0.1005, 0.12, 0.8),     # 14
                    (2, 0.30, 0.32, 1.0), (3, 0.301, 0.32, 1.2),      # 23
                    (3, 0.50, 0.52, 1.0),                             # 3
                    (1, 0.70, 0.72, 1.0), (2, 0.7002, 0.72, 0.9),     # 1 and 2: one end, keep 1
                    (4, 0.90, 0.92, 0.05)])                           # below threshold
    events = detect_contacts(t, v, threshold=0.2)
    assert events.code.tolist() == [14, 23, 3, 1]
    codes = contact_code_series(pd.DataFrame(v, columns=[f"contact{i}" for i in range(1, 5)]), 0.2)
    # per sample the stronger of 1 and 2 wins (2 near the end of its later pulse)
    assert set(np.unique(codes)) == {0, 1, 2, 3, 14, 23}
    assert codes[np.searchsorted(t, 0.31)] == 23 and codes[np.searchsorted(t, 0.705)] == 1
    assert codes[np.searchsorted(t, 0.91)] == 0


def test_paper_digit_comparison():
    assert P.same_digits(109.2976, "109.298") and not P.same_digits(109.2974, "109.298")
    assert P.same_digits(6.8621e9, "6.862e9") and P.format_like(4.5136e7, "4.52e7") == "4.51e7"
