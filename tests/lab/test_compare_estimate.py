"""Comparison with experiments and the parameter estimator, end to end
through a simulated record written as a LabVIEW file."""
import json

import numpy as np
import pandas as pd
import pytest

from workbench.lab import files as F
from workbench.cli import main
from workbench.lab.estimate import estimate
from workbench.lab.matching import setup_from
from workbench.model.params import ParameterError

HIDDEN = {"e_b": 6.0e11, "force_n": 14.0}
SETTINGS = {"drive": "sine", "freq_hz": 25.0, "ramp_s": 0.5, "gap_mm": 1.016}


def _time_base(duration, rate=1000.0):
    t = np.arange(0.0, duration + 0.5 / rate, 1.0 / rate)
    return pd.DataFrame(index=pd.Index(t, name="t"))


@pytest.fixture(scope="module")
def synthetic_lvm(tmp_path_factory):
    """A 1.5 s, 25 Hz shaker record simulated with hidden E_B and force, 2 % noise on
    every signal channel, written as .lvm with its settings but not the hidden values."""
    setup = setup_from({**SETTINGS, "force_n": HIDDEN["force_n"], "e_b": HIDDEN["e_b"]},
                       _time_base(1.5))
    run = setup.simulate()
    assert run.ok
    rec = F.record_from_run(run)
    rng = np.random.default_rng(0)
    for ch in rec.columns:
        if not ch.startswith("contact"):
            rec[ch] += rng.normal(0.0, 0.02 * rec[ch].std(), len(rec))
    path = tmp_path_factory.mktemp("exp") / "synthetic.lvm"
    return F.write(path, rec, {**SETTINGS, "force_n": 20.0})


def test_estimator_recovers_hidden_parameters_from_an_lvm(synthetic_lvm):
    record = F.read(synthetic_lvm)
    setup = setup_from(record.attrs["meta"], record)
    assert setup.params.e_b == 7.0e11          # the file does not give the hidden values away
    fit = estimate([(record, setup)], {"e_b": 7.0e11, "force_n": 20.0}, skip_s=0.5, jobs=2)
    assert fit.success
    for name, truth in HIDDEN.items():
        assert fit.values[name] == pytest.approx(truth, rel=0.02), fit.table(HIDDEN)


def test_estimator_refuses_what_it_cannot_fit(synthetic_lvm):
    record = F.read(synthetic_lvm)
    setup = setup_from(record.attrs["meta"], record)
    with pytest.raises(ParameterError, match="cannot fit"):
        estimate([(record, setup)], {"gap": 0.1})
    with pytest.raises(ParameterError, match="start e_b"):
        estimate([(record, setup)], {"e_b": 1.0})


def test_compare_cli_writes_the_four_comparisons(synthetic_lvm, tmp_path, capsys):
    out = tmp_path / "cmp"
    code = main(["compare", str(synthetic_lvm), "--force-n", "14", "--set", "e_b=6e11",
                 "--skip-s", "0.5", "--out", str(out)])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    for name in ("time_history", "spectra", "switching"):
        assert (out / f"{name}.png").exists() and (out / f"{name}.pdf").exists()
    signals = pd.read_csv(out / "differences_signals.csv").set_index("channel")
    # the same model and parameters: only the 2 % noise differs
    assert signals.rms_error_rel.max() < 0.05, signals
    assert signals.rms_ratio.between(0.99, 1.01).all()
    peaks = pd.read_csv(out / "differences_peaks.csv")
    assert len(peaks) >= 6 and np.all(np.abs(peaks.shift_hz) < 1.0), peaks
    contacts = pd.read_csv(out / "differences_contacts.csv")
    assert np.all(np.abs(contacts.difference) < 1e-9)
    assert summary["simulation_status"] == 0
    text = (out / "differences.md").read_text()
    assert all(f"## {name}" in text for name in ("signals", "peaks", "contacts", "figures"))


def test_compare_with_other_parameters_shows_the_difference(synthetic_lvm, tmp_path, capsys):
    out = tmp_path / "cmp"
    assert main(["compare", str(synthetic_lvm), "--skip-s", "0.5", "--out", str(out)]) == 0
    signals = pd.read_csv(out / "differences_signals.csv").set_index("channel")
    assert signals.loc["force1", "rms_ratio"] == pytest.approx(20.0 / 14.0, rel=0.01)


def test_matching_setup_refuses_bad_settings():
    base = _time_base(0.1)
    with pytest.raises(ParameterError, match="drive = 'wobble'"):
        setup_from({"drive": "wobble"}, base)
    with pytest.raises(ParameterError, match="needs freq_hz"):
        setup_from({"drive": "sine"}, base)
    with pytest.raises(ParameterError, match="freq_hz does not apply"):
        setup_from({"drive": "chirp", "f0_hz": 5, "f1_hz": 65, "sweep_s": 1, "freq_hz": 3}, base)
    with pytest.raises(ParameterError, match="gap"):
        setup_from({"gap_mm": 9.0}, base)


def test_compare_of_a_chirp_draws_both_spectrograms_and_the_frfs(tmp_path):
    settings = {"drive": "chirp", "f0_hz": 5.0, "f1_hz": 65.0, "sweep_s": 2.0, "ramp_s": 0.2}
    setup = setup_from(settings, _time_base(2.0))
    run = setup.simulate()
    path = F.write(tmp_path / "chirp.txt", F.record_from_run(run), settings)
    out = tmp_path / "cmp"
    assert main(["compare", str(path), "--out", str(out)]) == 0
    for name in ("spectrogram_record", "spectrogram_simulation", "switching", "frf"):
        assert (out / f"{name}.png").exists()
    signals = pd.read_csv(out / "differences_signals.csv")
    assert signals.rms_error_rel.max() < 1e-6      # the same model, no noise
    modes = pd.read_csv(out / "differences_frf_modes.csv")
    assert set(modes.source) == {"record", "simulation"} and modes.f_hz.between(5, 65).all()
    by_source = [modes[modes.source == s].drop(columns="source").reset_index(drop=True)
                 for s in ("record", "simulation")]
    pd.testing.assert_frame_equal(*by_source, rtol=1e-5)    # the same model: the same modes
