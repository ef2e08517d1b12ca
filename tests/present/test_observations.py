"""The rules that measure the paper's observations, on synthetic signals with known content."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.present import observations as O


def _record(seconds=10.0, fs=1000.0, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * fs)) / fs
    return t, 1e-3 * rng.normal(size=t.size)          # white floor


def test_a_subharmonic_is_found_at_its_known_level_and_not_without_it():
    """A 20 Hz line with a 10 Hz subharmonic of a known amplitude over white noise: its level
    over the floor is the line's power over the noise's per-bin power (a sinusoid of amplitude
    a puts a^2/2 / (1.5 * bin) into a Hann-window Welch bin: ENBW 1.5 bins)."""
    t, noise = _record()
    fs, res = 1000.0, 0.5
    for a, present in ((3e-3, True), (0.0, False)):
        x = np.sin(2 * np.pi * 20 * t) + a * np.sin(2 * np.pi * 10 * t) + noise
        line = O.line_level(t, x, 10.0, res)
        assert line["present"] is present
        floor = (1e-3) ** 2 * 2 / fs                   # one-sided white PSD
        assert line["floor"] == pytest.approx(floor, rel=0.3)
        if present:
            expected = 10 * np.log10((a ** 2 / 2) / (1.5 * res) / floor)
            assert line["level_db"] == pytest.approx(expected, abs=1.5)
    assert O.line_level(t, np.sin(2 * np.pi * 20 * t) + noise, 20.0)["level_db"] > 60


def test_peaks_in_a_band_and_the_power_above_a_frequency():
    t, noise = _record()
    x = np.sin(2 * np.pi * 20 * t) + 0.05 * np.sin(2 * np.pi * 63 * t) + 0.1 * np.sin(2 * np.pi * 250 * t)
    peak = O.strongest_peak(t, x + noise, 45.0, 75.0)
    assert peak["f_hz"] == pytest.approx(63.0, abs=0.5) and peak["level_db"] > 20
    share = O.power_above(t, x, 200.0)
    assert share == pytest.approx(0.01 / (1 + 0.0025 + 0.01), rel=0.02)


def test_resonance_bands_are_found_at_their_known_times():
    """A 240 s record whose amplitude rises threefold in bursts centred at 50, 100 and 180 s
    (Gaussian, 4 s wide) on a slowly growing base: three bands, each within a window of its
    time, and none in the first 20 s skipped."""
    fs = 200.0
    t = np.arange(int(240 * fs)) / fs
    envelope = (1 + t / 240) * (1 + sum(2 * np.exp(-0.5 * ((t - c) / 4.0) ** 2)
                                        for c in (50.0, 100.0, 180.0, 10.0)))
    x = envelope * np.sin(2 * np.pi * (5 * t + 60 / 480 * t ** 2))
    bands = O.resonance_bands(t, x, skip_s=20.0)
    assert len(bands) == 3
    assert bands == pytest.approx([50.0, 100.0, 180.0], abs=O.BAND_WINDOW_S)
    assert len(O.resonance_bands(t, np.sin(2 * np.pi * 5 * t))) == 0


def test_the_verdicts_follow_their_rules():
    """A sine record with the drive line, a subharmonic, peaks at 62 and 104 Hz and nothing
    above 200 Hz, switching between 14 and 23 and never in 13; and a chirp record whose
    bands sit at two of the paper's three times."""
    t, noise = _record()
    tone = lambda f, a: a * np.sin(2 * np.pi * f * t)          # noqa: E731
    x = tone(20, 1.0) + tone(10, 0.01) + tone(62, 0.01) + tone(104, 0.01) + noise
    v = O.assess_sine(t, x, {14: 0.3, 23: 0.45, 13: 0.0}, 900.0)
    assert {k: verdict for k, (_, verdict) in v.items()} == {
        "drive_line": "reproduced", "subharmonic": "reproduced", "peaks_60_100": "reproduced",
        "above_200": "reproduced", "switch_14_23": "reproduced", "code_13": "not",
        "switch_rate": "no number"}
    assert "62.0 Hz" in v["peaks_60_100"][0] and "104.0 Hz" in v["peaks_60_100"][0]
    v = O.assess_sine(t, tone(20, 1.0) + tone(300, 0.5) + noise, {14: 0.5, 23: 0.1}, 10.0)
    assert v["subharmonic"][1] == "not" and v["above_200"][1] == "not"
    assert v["switch_14_23"][1] == "partly"
    fs = 200.0
    tc = np.arange(int(240 * fs)) / fs
    envelope = 1 + sum(2 * np.exp(-0.5 * ((tc - c) / 4.0) ** 2) for c in (50.0, 100.0))
    verdicts, bands = O.assess_chirp(tc, envelope * np.sin(2 * np.pi * 20 * tc), 20.0)
    words, verdict = verdicts["chirp_bands"]
    assert bands == pytest.approx([50 / 60, 100 / 60], abs=O.BAND_WINDOW_S / 60)
    assert verdict == "partly" and "2 of the paper's 3" in words
