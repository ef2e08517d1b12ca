"""Metrics of one run (workbench.study.metrics) on signals with known answers."""
import numpy as np
import pandas as pd
import pytest

from workbench.study.metrics import (contact_shares, harmonic_amplitudes, once_per_period,
                                     regime_time)


def test_harmonic_amplitudes_recover_a_known_mixture():
    t = np.arange(0.0, 2.0, 1e-3)
    f = 17.0
    x = (0.3 + 1.5 * np.sin(2 * np.pi * f * t + 0.4) + 0.2 * np.cos(np.pi * f * t)
         + 0.05 * np.sin(6 * np.pi * f * t - 1.0))
    amp = harmonic_amplitudes(t, x, f)
    assert amp[1.0] == pytest.approx(1.5, rel=1e-9)
    assert amp[0.5] == pytest.approx(0.2, rel=1e-9)
    assert amp[3.0] == pytest.approx(0.05, rel=1e-8)
    assert amp[2.0] < 1e-10


def test_once_per_period_samples_the_drive_phase():
    f = 23.0
    t = np.arange(1.0, 3.0, 1e-3)                  # 1 ms samples, period 43.5 ms: off the grid
    x = 2.0 * np.cos(2 * np.pi * f * t) + 0.1
    y = once_per_period(t, x, f)
    assert len(y) == len(np.arange(np.ceil(f * 1.0), np.floor(f * t[-1]) + 1))
    assert np.allclose(y, 2.1, atol=1e-6)          # cubic spline error (w h)^4 / 384 ~ 5e-7


def test_regime_time_splits_the_window_by_the_event_log():
    events = pd.DataFrame({"t": [0.0, 0.5, 1.2, 1.9], "to_regime": [0, 5, 6, 0]})
    spent = regime_time(events, 1.0, 2.0)
    assert spent == pytest.approx({5: 0.2, 6: 0.7, 0: 0.1})
    assert sum(spent.values()) == pytest.approx(1.0)


def test_contact_shares_group_regimes_by_the_papers_code():
    # regimes 9 and 10 are contact set 5 = {1, 3} sticking and sliding: code 13
    events = pd.DataFrame({"t": [0.0, 1.0, 3.0, 3.5], "to_regime": [0, 1, 9, 10]})
    shares = contact_shares(events, 0.0, 4.0)
    assert shares == pytest.approx({"0": 0.25, "1": 0.5, "13": 0.25})
