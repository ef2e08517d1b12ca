"""FRFs (workbench/lab/frf.py): H1, H2 and the coherence on cases with known answers."""
from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pytest
from scipy import signal

from workbench import cli
from workbench.lab.frf import frf, magnitude_phase
from workbench.lab.modal import MIN_DECAY_TIMES, chart, modes, unresolved_words
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
    found = modes(table, chart(table, ["accel1"], 5.0, 60.0))
    assert len(found) == 1 and found.f_hz[0] == pytest.approx(fn, rel=2e-3)
    assert found.zeta[0] == pytest.approx(zeta, rel=0.1) and found.zeta_resolved[0]
    # the record is CGS ((cm/s^2) per dyn); the files give the field's (m/s^2)/N and µε/N
    flat = magnitude_phase(table)
    assert np.allclose(flat["accel1_H1_abs [(m/s²)/N]"], table.accel1_H1.abs() * 1e5 / 100.0)
    strain = magnitude_phase(table.rename(columns=lambda c: c.replace("accel1", "strain1")))
    assert np.allclose(strain["strain1_H1_abs [µε/N]"], table.accel1_H1.abs() * 1e11)


def test_noise_on_the_response_lowers_the_coherence_and_separates_h1_from_h2():
    table = frf(_sdof_record(noise=1.0), ["accel1"], segment_s=10.0)
    f = table.index.to_numpy()
    off = (f > 40) & (f < 100)                     # away from the resonance: noise dominates
    assert table.accel1_coherence.to_numpy()[off].mean() < 0.5
    h1, h2 = np.abs(table.accel1_H1.to_numpy()[off]), np.abs(table.accel1_H2.to_numpy()[off])
    assert np.all(h2 >= h1 * (1 - 1e-12))           # |H1| <= |H2|, equal only at coherence 1


def test_the_locked_joint_driven_by_a_chirp_has_its_modes():
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
    expected = [m for m in natural_frequencies(p, "locked") if 5.0 < m < 60.0]
    assert len(expected) == 2                                    # 13.94 and 47.23 Hz
    found = modes(table, chart(table, ["accel3", "strain2"], 5.0, 60.0))
    assert len(found) == len(expected), found
    for f_found, mode in zip(found.f_hz, expected):
        assert abs(f_found - mode) <= resolution, (f_found, mode)
    for response in ("accel3", "strain2"):
        coherence = table[f"{response}_coherence"]
        assert coherence.iloc[np.argmin(np.abs(table.index - expected[1]))] > 0.99
        assert coherence.iloc[np.argmin(np.abs(table.index - expected[0]))] > 0.75


def test_a_record_it_cannot_use_is_refused_clearly():
    rec = _sdof_record(seconds=2.0)
    with pytest.raises(ParameterError, match="no force2 column"):
        frf(rec, ["accel1"], force="force2")
    with pytest.raises(ParameterError, match=r"response channel\(s\) \['strain9'\]"):
        frf(rec, ["strain9"])
    with pytest.raises(ParameterError, match="force1 column is zero"):
        frf(rec.assign(force1=0.0), ["accel1"])


def test_the_command_writes_the_table_the_modes_and_the_figures(tmp_path, capsys):
    path = tmp_path / "sdof.parquet"
    _sdof_record(seconds=60.0).to_parquet(path)
    code = cli.main(["frf", str(path), "--segment-s", "10", "--f-min", "5", "--f-max", "60",
                     "--out", str(tmp_path / "out")])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["resolution_hz"] == pytest.approx(0.1)
    assert [round(m["f_hz"]) for m in out["modes"]] == [20]
    assert out["modes"][0]["zeta"] == pytest.approx(0.02, rel=0.1)
    for name in ("frf.csv", "modes.csv", "modes.md", "frf.png", "stabilisation.png"):
        assert (tmp_path / "out" / name).exists()


def _hit_record(fn=20.0, zeta=0.005, fs=2000.0, seconds=5.0, t_hit=0.05, width=2e-3, offset=3.0):
    """A hammer hit (half-sine, peak 1) on a unit-mass oscillator at rest at ``offset``: the
    response x = offset + the convolution of the pulse with h(t) = exp(-zeta wn t) sin(wd t) / wd."""
    t = np.arange(int(seconds * fs)) / fs
    tau = t - t_hit
    f = np.where((tau >= 0) & (tau <= width), np.sin(np.pi * np.clip(tau, 0, width) / width), 0.0)
    wn = 2 * np.pi * fn
    system = signal.lti([1.0], [1.0, 2 * zeta * wn, wn ** 2])
    _, x, _ = signal.lsim(system, f, t)
    return pd.DataFrame({"hammer": f, "accel1": offset + x}, index=pd.Index(t, name="t"))


def test_the_impact_windows_give_the_mode_and_the_corrected_damping():
    """One hit on a 20 Hz oscillator of zeta 0.005, 5 s: the exponential window (to 1 % at the
    end: tau = 5 / ln 100 = 1.09 s) adds 1 / (tau wn) = 0.0073 to the damping ratio, and the
    correction (Fladung & Rost 1997: every pole shifted back by 1/tau) takes it off again;
    without it the ratio is 2.5 times too high.  The static offset before the hit does not
    enter the FRF."""
    rec = _hit_record()
    table = frf(rec, ["accel1"], force="hammer", window="impact")
    assert table.attrs["window"] == "impact" and table.attrs["averages"] == 1
    assert table.attrs["exp_tau_s"] == pytest.approx((5.0 - 0.05 - 2 / 2000) / np.log(100), rel=1e-3)
    found = modes(table, chart(table, ["accel1"], 5.0, 60.0))
    assert len(found) == 1 and found.f_hz[0] == pytest.approx(20.0, rel=1e-3)
    assert found.zeta[0] == pytest.approx(0.005, rel=0.05)
    raw = table.copy()
    raw.attrs.pop("exp_tau_s")
    assert modes(raw, chart(raw, ["accel1"], 5.0, 60.0)).zeta[0] > 2.0 * found.zeta[0]
    assert np.isnan(table.accel1_coherence).all()                  # one hit: no average
    f = table.index.to_numpy()
    wn, k = 2 * np.pi * 20.0, np.argmin(np.abs(f - 5.0))          # below the mode: 1 / wn^2
    assert abs(table.accel1_H1.iloc[k]) == pytest.approx(1 / (wn ** 2 - (2 * np.pi * f[k]) ** 2),
                                                          rel=0.05)


def test_the_rect_window_gives_the_unwindowed_h1():
    """`--window rect` over the whole record is X / F of the raw record (bar the static line),
    for a user who fits H1 their own way."""
    rec = _hit_record(seconds=2.0)
    table = frf(rec, ["accel1"], force="hammer", window="rect", segment_s=None, band_hz=1e9)
    raw = np.fft.rfft(rec.accel1.to_numpy()) / np.fft.rfft(rec.hammer.to_numpy())
    assert table.attrs["averages"] == 1 and len(table) == len(raw)
    below = (table.index > 0) & (table.index < 500.0)    # the 2 ms pulse's first zero: 750 Hz
    assert np.allclose(table.accel1_H1.to_numpy()[below], raw[below], rtol=1e-5, atol=0)


def test_the_default_window_follows_the_drive():
    from workbench.lab.frf import default_window
    assert [default_window(d) for d in ("hammer_tip", "hammer_joint", "chirp", "sine", None)] \
        == ["impact", "impact", "rect", "hann", "hann"]
    with pytest.raises(ParameterError, match="window = 'flattop'; allowed: hann, rect, impact"):
        frf(_sdof_record(seconds=2.0), ["accel1"], window="flattop")


def test_a_hammer_run_written_as_uff_gives_the_locked_modes(tmp_path, capsys):
    """The §5.4 hammer test, as README.md runs it: `workbench run --impulse joint --joint
    locked --out hit.uff` then `workbench frf hit.uff`: the record carries the hammer's force
    (node 11 at the joint body, +Y), the FRF takes it as the reference with the impact
    windows, and its modes (LSCF, 0-300 Hz) are the locked modes about the static equilibrium
    (1.97, 13.91, 46.97 and 159.75 Hz, `workbench modes`) and no others, with their damping
    ratios within 2 %, except the first's: 10 s are 0.09 of its decay times, and the command
    says it cannot measure it."""
    import pyuff

    from workbench.model.modes import damping_ratios
    hit = tmp_path / "hit.uff"
    assert cli.main(["run", "--impulse", "joint", "--joint", "locked", "--duration", "10",
                     "--out", str(hit), "--json"]) == 0
    run = json.loads(capsys.readouterr().out)
    assert run["n_events"] == 0                       # the joint is held
    sets = [s for s in pyuff.UFF(str(hit)).read_sets() if s["type"] == 58]
    hammer = next(s for s in sets if s["id1"].strip() == "Hammer")
    assert hammer["rsp_node"] == 11 and hammer["rsp_dir"] == 2
    assert max(hammer["data"]) == pytest.approx(100.0, rel=0.02)          # N, sampled 10 a pulse
    assert all(s["ref_node"] == 11 for s in sets)
    out = tmp_path / "frf"
    assert cli.main(["frf", str(hit), "--f-max", "300", "--out", str(out)]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["force"] == "hammer" and res["window"] == "impact"
    f, zeta = damping_ratios(Parameters(), "locked", "static")
    assert len(res["modes"]) == 4, res["modes"]
    for found, fn, zn in zip(res["modes"], f[:4], zeta[:4]):
        assert found["f_hz"] == pytest.approx(fn, rel=2e-3), (fn, found)
        if found["zeta_resolved"]:
            assert found["zeta"] == pytest.approx(zn, rel=0.02), (fn, zn, found)
    assert [m["zeta_resolved"] for m in res["modes"]] == [False, True, True, True]
    assert res["modes"][0]["zeta"] is None
    # the span's figure comes from the unresolved mode's estimated damping: about 0.09
    assert len(res["notes"]) == 1
    note = re.fullmatch(r"1\.97 Hz: the record spans (0\.\d+) of its decay times, fewer than "
                        f"{MIN_DECAY_TIMES:g}; too short to measure its damping ratio",
                        res["notes"][0])
    assert note, res["notes"]
    assert float(note.group(1)) == pytest.approx(0.094, rel=0.05)
    assert (out / "frf.uff").exists() and not list(tmp_path.glob(".frf.partial-*"))


def test_a_record_too_short_for_a_modes_damping_says_so():
    """One hit on a 20 Hz oscillator of zeta 0.002 (decay time 1/(zeta wn) = 4 s): in a 3 s
    record (0.75 decay times, fewer than MIN_DECAY_TIMES) the mode is found and its damping
    is not given; in 20 s (5 decay times) it is, within 5 %."""
    short = frf(_hit_record(zeta=0.002, seconds=3.0), ["accel1"], force="hammer",
                window="impact")
    found = modes(short, chart(short, ["accel1"], 5.0, 60.0, order=10))
    assert len(found) == 1 and found.f_hz[0] == pytest.approx(20.0, rel=1e-3)
    assert not found.zeta_resolved[0] and np.isnan(found.zeta[0])
    assert found.decay_times[0] == pytest.approx(0.75, rel=0.01)
    assert "too short to measure its damping ratio" in unresolved_words(found)[0]
    long = frf(_hit_record(zeta=0.002, seconds=20.0), ["accel1"], force="hammer",
               window="impact")
    found = modes(long, chart(long, ["accel1"], 5.0, 60.0, order=10))
    assert found.zeta_resolved[0] and found.zeta[0] == pytest.approx(0.002, rel=0.05)
    assert unresolved_words(found) == []


def test_the_frf_help_states_the_modal_fits_default_order(capsys):
    from workbench.lab.modal import ORDER
    assert cli.main(["frf", "--help"]) == 0
    assert f"(default {ORDER}, lab.modal.ORDER" in " ".join(capsys.readouterr().out.split())


def test_the_modal_fit_refuses_a_band_it_cannot_fit():
    table = frf(_sdof_record(seconds=20.0), ["accel1"], segment_s=2.0)      # 0.5 Hz lines
    with pytest.raises(ParameterError, match="f_min = 60 Hz: must be below f_max = 5 Hz"):
        chart(table, ["accel1"], 60.0, 5.0)
    with pytest.raises(ParameterError, match="the order 40 needs at least 160"):
        chart(table, ["accel1"], 5.0, 60.0, order=40)
    assert chart(table, ["accel1"], 5.0, 60.0).attrs["orders"] == 27    # 110 lines: order 27
    with pytest.raises(ParameterError, match=r"order = 1: allowed a whole number in \[2, 200\]"):
        chart(table, ["accel1"], 5.0, 60.0, order=1)


def test_a_failed_frf_leaves_no_folder(tmp_path, capsys):
    path = tmp_path / "quiet.parquet"
    _sdof_record(seconds=4.0).assign(force1=0.0).to_parquet(path)
    assert cli.main(["frf", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "force1 column is zero" in capsys.readouterr().err
    assert not (tmp_path / "out").exists() and list(tmp_path.iterdir()) == [path]


def test_the_frf_files_state_their_window_and_stop_at_the_valid_band(tmp_path, capsys):
    """A hammer record's FRFs: the exponential window's tau and the damping correction in the
    CSV's first line and in the UFF's own records (read back by pyuff), and no frequency past
    the record's valid band (0.4 of its sample rate)."""
    import pyuff
    from workbench import cli
    record = tmp_path / "hit.uff"
    assert cli.main(["run", "--impulse", "joint", "--joint", "locked", "--tip-mass", "on",
                     "--duration", "2", "--out", str(record), "--json"]) == 0
    capsys.readouterr()
    assert cli.main(["frf", str(record), "--out", str(tmp_path / "frf")]) == 0
    first = (tmp_path / "frf" / "frf.csv").read_text().splitlines()[0]
    assert first.startswith("# ") and "exponential window, tau = " in first and "subtract" in first
    sets = pyuff.UFF(str(tmp_path / "frf" / "frf.uff")).read_sets()
    frfs = [s for s in sets if s.get("type") == 58]
    assert frfs and all("exponential window, tau" in s["id2"] for s in frfs)
    rate = 1.0 / float(np.diff(cli_record_times(record))[0])
    assert max(float(np.max(s["x"])) for s in frfs) <= 0.4 * rate * (1 + 1e-9)


def cli_record_times(path):
    from workbench.lab import files
    return files.read(path).index.to_numpy()
