"""One registry per concept: drives (workbench/model/drives.py) and regimes (workbench/model/regimes.py).

A drive added by one ``register`` call is a study's excitation kind, a
record's ``WB_drive``, and has its forcing frequency in the metrics, with
no other file touched.  The regime vocabulary agrees with the kernels' own
numbering and with the slow reference's.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from workbench.core import excitation as cx
from workbench.core.contact import regime_of as kernel_regime_of
from workbench.lab.matching import setup_from
from workbench.model import drives, regimes
from workbench.model.params import ParameterError
from workbench.reference.events import Regime
from workbench.study import definition as S


@pytest.fixture
def sine_rms(monkeypatch):
    """An example drive: a sine given by its RMS force (N), in one call."""
    monkeypatch.setattr(drives, "DRIVES", dict(drives.DRIVES))
    return drives.register(drives.Drive(
        "sine_rms", ("force_n", "freq_hz", "ramp_s"),
        lambda e: drives.sine(e["force_n"] * np.sqrt(2.0), e["freq_hz"], e["ramp_s"]),
        ramped=True, frequency_key="freq_hz"))


STUDY = """
[study]
name = "rms"
duration_s = 0.2
window_s = 0.1

[excitation]
drive = "sine_rms"
force_n = 10.0

[axes]
freq_hz = [20.0, 30.0]
"""


def test_a_registered_drive_is_a_study_excitation_and_a_record_drive(sine_rms, tmp_path):
    path = tmp_path / "rms.toml"
    path.write_text(STUDY)
    study = S.load(path)
    points = study.points
    assert [p.drive_hz for p in points] == [20.0, 30.0]
    ex = points[0].excitation_array()
    assert ex[cx.X_AMP] == pytest.approx(10.0 * np.sqrt(2.0) * drives.DYN_PER_N)
    assert points[0].start_keywords == {}
    # a record that says WB_drive = sine_rms is matched by the same drive
    record = pd.DataFrame({"force1": np.zeros(101)}, index=pd.Index(np.arange(101) * 1e-3, name="t"))
    setup = setup_from({"drive": "sine_rms", "freq_hz": 25.0, "force_n": 3.0}, record)
    assert setup.excitation == {"drive": "sine_rms", "force_n": 3.0, "freq_hz": 25.0, "ramp_s": 0.05}
    # a setting the drive does not take is refused, naming it
    with pytest.raises(ParameterError, match="f0_hz does not apply"):
        setup_from({"drive": "sine_rms", "freq_hz": 25.0, "f0_hz": 5.0}, record)


def test_an_unknown_drive_names_the_kinds():
    with pytest.raises(ParameterError, match="allowed: chirp, free_decay, hammer_joint"):
        drives.get("square")
    with pytest.raises(ValueError, match="without a unit"):
        drives.register(drives.Drive("bad", ("volts",), lambda e: drives.none()))


def test_a_free_decay_is_a_start_not_a_force():
    settings = {"drive": "free_decay", "deflection_cm": 2.0}
    assert drives.start_keywords(settings) == {"free_decay_cm": 2.0}
    assert int(drives.excitation_array(settings)[cx.X_KIND]) == cx.EXC_NONE
    assert drives.drive_hz(settings) is None


def test_the_regime_vocabulary_agrees_with_the_kernels_and_the_reference():
    for set_index in range(regimes.N_SETS):
        for stick in (True, False):
            r = regimes.regime_of(set_index, stick)
            assert r == kernel_regime_of(set_index, stick)
            assert r == Regime(set_index, stick).number
            assert regimes.set_of(r) == set_index
            assert regimes.is_stick(r) == (stick and set_index > 0)
            assert Regime(set_index, stick).points == regimes.SETS[set_index]
    assert [regimes.contact_code(r) for r in range(regimes.N_REGIMES)] == \
        [0, 1, 1, 2, 2, 3, 3, 4, 4, 13, 13, 14, 14, 23, 23, 24, 24]
    assert regimes.regime_name(13) == "stick {2,3}" and regimes.regime_name(6) == "slip {3}"
    assert regimes.in_contact(1, np.arange(17)).tolist() == \
        [0, 0, 0, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1]


def test_a_cork_law_is_one_entry_of_the_table(monkeypatch):
    from workbench.cli import build_parser
    from workbench.model.modes import natural_frequencies
    from workbench.model.params import CORK_MODELS, CorkLaw, Parameters

    monkeypatch.setitem(CORK_MODELS, "soft", CorkLaw(1.0, 1.0e5, 1.0e4))
    p = Parameters(cork="soft")
    assert p.cork_law == (1.0, 1.0e5, 1.0e4, "power")
    stiff = natural_frequencies(Parameters(cork="linear"), "free")
    soft = natural_frequencies(p, "free")
    assert soft[soft > 0].min() < stiff[stiff > 0].min()       # a softer spring on s
    assert build_parser().parse_args(["run", "--cork", "soft"]).cork == "soft"


def test_the_command_line_runs_a_registered_drive(sine_rms, capsys):
    import json

    from workbench import cli

    argv = ["run", "--drive", "sine_rms", "--drive-set", "freq_hz=20", "--drive-set", "force_n=3",
            "--duration", "0.05", "--json"]
    assert cli.main(argv) == 0
    assert json.loads(capsys.readouterr().out)["status"] == "ok"
    for bad, words in ((["run", "--drive", "square"], "--drive = 'square'; allowed"),
                       (["run", "--drive", "sine_rms", "--drive-set", "volts=3"],
                        "--drive-set volts: not a setting of --drive sine_rms"),
                       (["run", "--drive", "sine_rms"], "needs --drive-set freq_hz=VALUE (Hz)"),
                       (["run", "--drive-set", "freq_hz=3"], "give --drive KIND"),
                       (["run", "--drive", "sine_rms", "--drive-set", "freq_hz=20", "--force-n", "3"],
                        "--force-n 3: with --drive, give --drive-set force_n=VALUE")):
        assert cli.main(bad) == cli.EXIT_BAD_INPUT
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and words in err, err
