"""FRFs (workbench/experiments/frf.py): H1, H2 and the coherence on cases with known answers."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from scipy import signal

from workbench import cli
from workbench.experiments.frf import frf, peaks
from workbench.model import drives, packing as mdl
from workbench.model.modes import natural_frequencies
from workbench.model.params import ParameterError, Parameters
from workbench.model.simulate import simulate


def _sdof_record(fn=20.0, zeta=0.02, fs=500.0, seconds=200.0, noise=0.0, seed=0):
    """A mass-spring-damper (unit mass) driven by white noise: x'' + 2 zeta wn x' + wn^2 x = f."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * fs)) / fs
    f = rng.normal(size=t.size)
    wn = 2 * np.pi * fn
    system = signal.lti([1.0], [1.0, 2 * zeta * wn, wn ** 2])
    _, x, _ = signal.lsim(system, f, t)
    x = x + noise * np.std(x) * rng.normal(size=t.size)
    return pd.DataFrame({"force1": f, "accel1": x}, index=pd.Index(t, name="t"))


def test_h1_of_a_single_degree_of_freedom_matches_its_receptance():
    # Bendat & Piersol §6.1: H(f) = 1 / (wn^2 - w^2 + 2j zeta wn w) for unit mass
    fn, zeta = 20.0, 0.02
    table = frf(_sdof_record(fn, zeta), ["accel1"], segment_s=10.0)
    f = table.index.to_numpy()
    w, wn = 2 * np.pi * f, 2 * np.pi * fn
    exact = 1.0 / (wn ** 2 - w ** 2 + 2j * zeta * wn * w)
    band = (f > 5) & (f < 60)
    err = np.abs(table.accel1_H1.to_numpy()[band] - exact[band]) / np.abs(exact[band])
    assert np.median(err) < 0.03                   # Hann-window bias near the peak only
    assert table.accel1_coherence.to_numpy()[band].min() > 0.95
    top = peaks(table, "accel1", 5.0, 60.0)
    assert len(top) == 1 and top.f_hz[0] == pytest.approx(fn, abs=0.1)
    assert top.zeta_half_power[0] == pytest.approx(zeta, rel=0.25)
    # the record is CGS ((cm/s^2) per dyn); the peak is given in the field's (m/s^2)/N
    k = np.argmin(np.abs(f - top.f_hz[0]))
    assert top.unit[0] == "(m/s²)/N"
    assert top.magnitude[0] == pytest.approx(abs(table.accel1_H1.iloc[k]) * 1e5 / 100.0)
    strain = peaks(table.rename(columns=lambda c: c.replace("accel1", "strain1")), "strain1",
                   5.0, 60.0)
    assert strain.unit[0] == "µε/N"
    assert strain.magnitude[0] == pytest.approx(abs(table.accel1_H1.iloc[k]) * 1e11)


def test_noise_on_the_response_lowers_the_coherence_and_separates_h1_from_h2():
    table = frf(_sdof_record(noise=1.0), ["accel1"], segment_s=10.0)
    f = table.index.to_numpy()
    off = (f > 40) & (f < 100)                     # away from the resonance: noise dominates
    assert table.accel1_coherence.to_numpy()[off].mean() < 0.5
    h1, h2 = np.abs(table.accel1_H1.to_numpy()[off]), np.abs(table.accel1_H2.to_numpy()[off])
    assert np.all(h2 >= h1 * (1 - 1e-12))           # |H1| <= |H2|, equal only at coherence 1


def test_the_locked_joint_driven_by_a_chirp_has_its_modes_as_peaks():
    """The joint locked and gravity off: the linear model about its undeformed state, whose
    modes `workbench modes` computes.  A 5-60 Hz chirp over 60 s, 10 s segments (0.1 Hz).
    The coherence is near 1 at the 47 Hz mode; at the 14 Hz mode (zeta ~ 1 %) the ring-down
    of one segment's resonance runs on into segments whose force has left that frequency,
    which a single sweep cannot avoid: there it is 0.8."""
    p = Parameters(tip_mass=True).replace(g=0.0)
    run = simulate(p, drives.chirp(2.0, 5.0, 60.0, 60.0), 60.0, fixed=mdl.JOINT, initial="paper",
                   output_hz=500.0)
    assert run.ok, run.message
    table = frf(run.signals, ["accel3", "strain2"], segment_s=10.0)
    resolution = table.index[1]
    modes = [m for m in natural_frequencies(p, "locked") if 5.0 < m < 60.0]
    assert len(modes) == 2                                       # 13.94 and 47.23 Hz
    for response in ("accel3", "strain2"):
        top = peaks(table, response, 5.0, 60.0)
        assert len(top) == len(modes), top
        for found, mode in zip(top.f_hz, modes):
            assert abs(found - mode) <= resolution, (response, found, mode)
        assert top.coherence.iloc[1] > 0.99 and top.coherence.iloc[0] > 0.75


def test_a_record_it_cannot_use_is_refused_clearly():
    rec = _sdof_record(seconds=2.0)
    with pytest.raises(ParameterError, match="no force2 column"):
        frf(rec, ["accel1"], force="force2")
    with pytest.raises(ParameterError, match=r"response channel\(s\) \['strain9'\]"):
        frf(rec, ["strain9"])
    with pytest.raises(ParameterError, match="force1 column is zero"):
        frf(rec.assign(force1=0.0), ["accel1"])


def test_the_command_writes_the_table_the_peaks_and_the_figure(tmp_path, capsys):
    path = tmp_path / "sdof.parquet"
    _sdof_record(seconds=60.0).to_parquet(path)
    code = cli.main(["frf", str(path), "--segment-s", "10", "--f-min", "5", "--f-max", "60",
                     "--out", str(tmp_path / "out")])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["resolution_hz"] == pytest.approx(0.1)
    assert [round(p["f_hz"]) for p in out["peaks"]] == [20]
    for name in ("frf.csv", "peaks.csv", "peaks.md", "frf.png"):
        assert (tmp_path / "out" / name).exists()
