"""The response-limited drive (workbench/study/leveling.py) and the validated range flags."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from workbench.model.params import Parameters
from workbench.present.report import range_lines
from workbench.study import definition as S
from workbench.study import sweep as W
from workbench.study.leveling import LEVEL_MARGIN, LEVEL_RUNS, limited_run
from workbench.study.metrics import validity


def _fake(peak_per_n, ok=True):
    """simulate_at for a structure whose tip peak is peak_per_n cm per N of force."""
    calls = []

    def simulate_at(force):
        calls.append(force)
        t = np.linspace(0, 1, 5)                      # the peak is sampled
        tip = peak_per_n * force * np.sin(2 * np.pi * t)
        sig = pd.DataFrame({"tip_y": tip + 5.0}, index=t)
        return SimpleNamespace(ok=ok, signals=sig, static_tip_y=5.0)
    return simulate_at, calls


def test_the_force_is_lowered_to_keep_the_tip_within_its_level():
    simulate_at, calls = _fake(0.05)                 # 200 N -> 10 cm
    run, force, runs, met = limited_run(simulate_at, 200.0, 4.0)
    assert met and runs == 2 and calls == [200.0, pytest.approx(200.0 * LEVEL_MARGIN * 4.0 / 10.0)]
    assert force == calls[-1] and np.abs(run.signals.tip_y - 5.0).max() <= 4.0
    simulate_at, calls = _fake(0.01)                 # within the level at once
    assert limited_run(simulate_at, 200.0, 4.0)[1:] == (200.0, 1, True)


def test_a_level_never_met_keeps_the_last_run_and_says_so():
    calls = []

    def stubborn(force):                              # the tip does not follow the force
        calls.append(force)
        sig = pd.DataFrame({"tip_y": [0.0, 9.0]}, index=[0.0, 1.0])
        return SimpleNamespace(ok=True, signals=sig, static_tip_y=0.0)
    run, force, runs, met = limited_run(stubborn, 100.0, 1.0)
    assert not met and runs == LEVEL_RUNS == len(calls) and force == calls[-1]


def test_validity_names_each_limit_a_run_exceeds():
    sig = pd.DataFrame({"tip_y": [1.0, 10.0], "s": [0.0, -0.8], "accel1": [0.0, 60 * 980.665],
                        "accel2": [0.0, 0.0], "accel3": [0.0, 0.0], "force1": [0.0, 1e7]},
                       index=[0.0, 1.0])
    run = SimpleNamespace(signals=sig, static_tip_y=1.0, params=Parameters())
    v = validity(run)
    assert v["out_of_range"] == "tip,slot,accel"
    assert v["tip_abs_max_cm"] == 9.0 and v["accel_abs_max_g"] == pytest.approx(60.0)
    assert v["force1_abs_max_n"] == pytest.approx(100.0)
    table = pd.DataFrame([{"status": "ok", "out_of_range": v["out_of_range"], **v,
                           "axis_gap_mm": 1.016}])
    text = "\n".join(range_lines(table))
    assert "## Points outside the validated range" in text and "tip,slot,accel" in text
    assert "stayed within" in range_lines(table.assign(out_of_range=""))[0]


STUDY = """
[study]
name = "lev"
duration_s = 1.0
window_s = 0.25
tip_limit_cm = {limit}

[excitation]
drive = "{drive}"
{extra}

[axes]
tip_mass = [false]
"""


def test_a_study_with_a_tip_limit_levels_each_point(tmp_path):
    """Without the tip mass, 200 N at 20 Hz sends the tip past 3 cm: the point runs again at
    a lower force and stays within 3 cm."""
    path = tmp_path / "lev.toml"
    path.write_text(STUDY.format(limit=3.0, drive="sine",
                                 extra="force_n = 200.0\nfreq_hz = 20.0\nramp_s = 0.25")
                    .replace("tip_limit_cm", "check_accuracy = true\ntip_limit_cm"))
    study = S.load(path)
    assert study.tip_limit_cm == 3.0
    W.sweep(study, results=tmp_path / "res", jobs=1, progress=False)
    row = pd.read_parquet(tmp_path / "res" / "lev" / "points.parquet").iloc[0]
    assert row.status == "ok" and row.level_met and row.level_runs >= 2
    assert row.force_n_used < 200.0 and row.tip_abs_max_cm <= 3.0
    # the accepted run, checked against its companion
    assert 0.0 < row.error_measured < 1e-3


def test_a_tip_limit_needs_a_drive_with_a_force(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(STUDY.format(limit=3.0, drive="free_decay", extra="deflection_cm = 8.4"))
    with pytest.raises(S.StudyError, match="tip_limit_cm sets each point's force: a 'free_decay'"):
        S.load(path)
    path.write_text(STUDY.format(limit=-1.0, drive="sine", extra="force_n = 20.0\nfreq_hz = 20.0"))
    with pytest.raises(S.StudyError, match="tip_limit_cm"):
        S.load(path)
