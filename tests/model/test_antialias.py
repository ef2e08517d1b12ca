"""The anti-alias filter (workbench/model/antialias.py): nothing folds, the passband is flat."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from workbench.core import layout as ly
from workbench.model import antialias
from workbench.model.drives import sine
from workbench.model.params import Parameters
from workbench.model.simulate import simulate


def _internal(t, *tones):
    """Signal rows (the kernel's columns) whose analog columns hold the sum of the tones."""
    x = sum(a * np.sin(2 * np.pi * f * t) for f, a in tones)
    rows = np.zeros((len(t), ly.N_SIG))
    rows[:, list(antialias.ANALOG_COLUMNS)] = x[:, None]
    return rows


def _decimate(rows, m, fs, chunks):
    d = antialias.Decimator(m, fs)
    parts = [d.push(part) for part in np.array_split(rows, chunks)]
    return np.concatenate([*parts, d.finish()])


def test_a_tone_above_nyquist_does_not_fold_and_the_passband_is_flat():
    """10 kHz internal, 1 kHz out: a 550 Hz tone would fold to 450 Hz; after the filter it is
    below its stated attenuation (100 dB), while a 100 Hz and a 390 Hz tone (in the passband,
    0-400 Hz) pass within the stated ripple, away from the record's ends."""
    fs, m = 10_000.0, 10
    t = np.arange(40_001) / fs
    f = antialias.design(m, fs)
    assert f["passband_hz"] == 400.0 and f["stopband_hz"] == 500.0
    assert f["ripple_db"] < 1e-4 and f["attenuation_db"] >= 100.0
    tol = 10 ** (f["ripple_db"] / 20) - 1 + 1e-9
    out = _decimate(_internal(t, (100.0, 1.0), (390.0, 0.5), (550.0, 1.0)), m, fs, 7)
    to = t[::m]
    assert out.shape == (len(to), len(antialias.ANALOG))
    exact = np.sin(2 * np.pi * 100 * to) + 0.5 * np.sin(2 * np.pi * 390 * to)
    inner = slice(len(f["taps"]) // m, -len(f["taps"]) // m)
    assert np.abs(out[inner, 0] - exact[inner]).max() < 1.5 * tol
    # what is left at 450 Hz, the 550 Hz tone's alias, by projection on the folded tone
    rest = out[inner, 0] - exact[inner]
    folded = np.exp(-2j * np.pi * 450 * to[inner])
    assert abs(2 * np.mean(rest * folded)) < 10 ** (-f["attenuation_db"] / 20)
    # without the filter the 550 Hz tone is at 450 Hz at full amplitude
    raw = np.sin(2 * np.pi * 550 * to[inner])
    assert abs(2 * np.mean(raw * folded)) == pytest.approx(1.0, rel=1e-3)


def test_decimating_in_blocks_is_decimating_at_once_and_the_ends_are_held():
    fs, m = 16_000.0, 16
    t = np.arange(9_601) / fs
    rows = _internal(t, (30.0, 1.0), (5.0, 2.0))
    whole = _decimate(rows, m, fs, 1)
    for chunks in (2, 5, 37):
        assert np.allclose(_decimate(rows, m, fs, chunks), whole, rtol=0, atol=1e-12)
    exact = np.sin(2 * np.pi * 30 * t[::m]) + 2 * np.sin(2 * np.pi * 5 * t[::m])
    assert abs(whole[-1, 0] - exact[-1]) < 1e-3          # the reflected end keeps the last value
    assert antialias.Decimator(1, fs).push(rows)[:, 0] == pytest.approx(rows[:, antialias.ANALOG_COLUMNS[0]])


def test_a_run_records_no_alias_of_its_harmonics():
    """A 55 Hz run (1.016 mm, tip mass, 200 N; fixed RK4 steps, so that both take one path)
    written at 1 kHz and at 10 kHz (the internal rate, no filter): the 1 kHz record's strain1 has less power at 450 Hz than the 10 kHz
    record shows there (the 550 Hz harmonic no longer folds onto it), and the two records
    agree at the common samples to the content above 400 Hz (the impacts': 0.5 % of the range
    when measured)."""
    p, ex = Parameters(tip_mass=True), sine(200.0, 55.0, ramp_s=0.2)
    low = simulate(p, ex, 1.0, method="rk4")
    high = simulate(p, ex, 1.0, output_hz=10_000.0, method="rk4")
    assert low.summary()["anti_alias"]["valid_band_hz"] == [0.0, 400.0]
    assert high.summary()["anti_alias"]["filter"].startswith("none")
    assert np.array_equal(low.states, high.states[::10])      # the solution itself is sampled
    a, b = low.signals.strain1.to_numpy(), high.signals.strain1.to_numpy()
    half = slice(len(a) // 2, None)
    f1, p1 = signal.periodogram(a[half], fs=1000.0, window="hann", scaling="spectrum")
    f2, p2 = signal.periodogram(b[len(b) // 2:], fs=10_000.0, window="hann", scaling="spectrum")
    at = lambda f, p, fq: p[np.abs(f - fq) <= 2.0].max()      # noqa: E731
    assert at(f1, p1, 450.0) < at(f2, p2, 450.0)
    assert np.abs(a - b[::10]).max() < 1e-2 * np.ptp(a)
