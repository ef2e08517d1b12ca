"""The paper's observations as the estimator's targets: each residual is 0 exactly where the
observation's rule holds and grows with the miss; the search finds a set where they hold."""
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from workbench.core import layout as ly
from workbench.lab.estimate import fit
from workbench.lab.matching import Setup
from workbench.present.observed import (SEARCH_MARGIN, SineObservations, band_misses,
                                            misses, residual)
from workbench.model.params import Parameters
from workbench.model.regimes import regime_of, set_of_points
from workbench.present import observations as O


def test_band_misses_are_zero_within_the_match_and_grow_beyond():
    assert np.all(band_misses([0.9, 1.5, 3.1], 4.0) < 0.0)
    assert band_misses([O.PAPER_BANDS_MIN[0] + O.BAND_MATCH_MIN], 4.0)[0] == pytest.approx(0.0, abs=1e-12)
    # one band at 0.33 min: 0.5, 1.337 and 2.67 min from the paper's, less the 0.25 matched
    expected = [(abs(0.33 - b) - O.BAND_MATCH_MIN) / O.BAND_MATCH_MIN for b in O.PAPER_BANDS_MIN]
    assert band_misses([0.33], 4.0) == pytest.approx(expected)
    assert band_misses([], 4.0) == pytest.approx([(4.0 - O.BAND_MATCH_MIN) / O.BAND_MATCH_MIN] * 3)


def _sine_run(sub_amplitude: float, share_14: float):
    """A stand-in run of 10 s: strain1 a 20 Hz line, a 10 Hz line of ``sub_amplitude`` and a
    weak noise floor; the joint in contact 14 for ``share_14`` of each second, else 23."""
    rng = np.random.default_rng(1)
    t = np.arange(0.0, 10.0 + 5e-4, 1e-3)
    strain1 = (np.sin(2 * np.pi * 20.0 * t) + sub_amplitude * np.sin(2 * np.pi * 10.0 * t)
               + 1e-4 * rng.standard_normal(len(t)))
    r14 = regime_of(set_of_points((0, 3)), True)
    r23 = regime_of(set_of_points((1, 2)), True)
    log = np.zeros((20, ly.N_LOG))
    log[0::2, ly.LOG_T] = np.arange(10.0)
    log[0::2, ly.LOG_TO] = r14
    log[1::2, ly.LOG_T] = np.arange(10.0) + share_14
    log[1::2, ly.LOG_TO] = r23
    signals = pd.DataFrame({"strain1": strain1}, index=pd.Index(t, name="t"))
    return SimpleNamespace(signals=signals, log=log)


def test_sine_observations_hold_with_the_subharmonic_and_both_codes():
    target = SineObservations(setup=None)
    holds = _sine_run(sub_amplitude=1e-2, share_14=0.4)
    m = target.measures(holds)
    assert m["share_14"] == pytest.approx(0.4, abs=1e-9)
    assert m["share_23"] == pytest.approx(0.6, abs=1e-9)
    assert m["sub_db"] > 40.0
    assert np.array_equal(target.residuals(holds), np.zeros(3))
    # no subharmonic and 14 only a tenth of the time: both miss, by their rules' scales
    misses_ = target.residuals(_sine_run(sub_amplitude=0.0, share_14=0.1))
    assert misses_[0] == pytest.approx((O.DOMINANT_SHARE - 0.1) / O.DOMINANT_SHARE + SEARCH_MARGIN,
                                       abs=1e-6)
    assert misses_[1] == 0.0
    assert 0.5 < misses_[2] <= 2.0          # a floor-level line: about 10 dB short of the margin
    # a share just at the rule's threshold holds, but the search's residual is still above 0
    assert residual(0.0) == SEARCH_MARGIN and residual(-2 * SEARCH_MARGIN) == 0.0


@dataclass(frozen=True)
class _ModulusAtMost:
    """A target that holds where the run's E_B is at most ``limit`` (dyn/cm²)."""

    setup: Setup
    limit: float

    @property
    def labels(self):
        return ["E_B at most the limit"]

    def residuals(self, run):
        return residual([np.log(run.params.e_b / self.limit)])


def test_fit_searches_until_every_target_holds():
    setup = Setup(Parameters(), {"drive": "none"}, 0.02, 1000.0)
    result = fit([_ModulusAtMost(setup, 5.5e11)], {"e_b": 7.0e11},
                 bounds={"e_b": (4.6e11, 7.1e11)}, jobs=1)
    assert result.success
    assert 4.6e11 <= result.values["e_b"] <= 5.5e11
    assert misses(result) == []
    assert result.labels == ["E_B at most the limit"]
    # unreachable within the bounds: the search ends at the bound, and says what misses
    result = fit([_ModulusAtMost(setup, 4.0e11)], {"e_b": 7.0e11},
                 bounds={"e_b": (4.6e11, 7.1e11)}, jobs=1)
    assert result.values["e_b"] == pytest.approx(4.6e11, rel=1e-3)
    assert [label for label, _ in misses(result)] == ["E_B at most the limit"]
