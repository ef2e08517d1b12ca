"""A run's error measured against its companion (workbench/model/accuracy.py)."""
from __future__ import annotations

import pytest

from workbench.model import accuracy, drives
from workbench.model.params import ParameterError, Parameters
from workbench.model.step_policy import default_dt
from workbench.model.simulate import simulate
from workbench.study import definition as S

CASE = (Parameters(), drives.sine(200.0, 20.0, ramp_s=0.1), 0.3)


def test_a_run_differs_from_itself_by_nothing():
    run = simulate(*CASE)
    d = accuracy.difference(run, run)
    assert d["tip_error"] == 0.0 and d["share_error"] == 0.0 and d["event_error"] == 0.0
    assert d["events"] == d["events_ref"] > 0


def test_runs_of_different_output_times_are_not_compared():
    params, ex, duration = CASE
    a = simulate(params, ex, duration)
    b = simulate(params, ex, duration, output_hz=2000.0)
    with pytest.raises(ValueError, match="different output times"):
        accuracy.difference(a, b)


def test_the_companion_measures_the_error_of_a_fixed_step_run():
    """RK4 at the stability step, checked against a quarter step, against RK4 at a 32nd
    (its own error far below): the measured error is the true one within a factor 2,
    and it is the error of a tip and of shares that do differ."""
    params, ex, duration = CASE
    dt = default_dt(params, ex)
    run = simulate(params, ex, duration, dt=dt, check_accuracy=True)
    truth = accuracy.difference(run, simulate(params, ex, duration, dt=dt / 32))
    true_error = max(truth["tip_error"], truth["share_error"])
    c = run.control
    assert c["companion"] == {"dt": dt / 4, "status": "ok", "wall_s": c["companion"]["wall_s"],
                              "n_events": c["companion"]["n_events"]}
    assert true_error > 1e-5
    assert 0.5 < c["error_measured"] / true_error < 2.0, (c["error_measured"], true_error)
    assert c["error_measured"] == max(c["tip_error_measured"], c["share_error_measured"])


def test_the_controlled_run_is_checked_at_a_tenth_of_its_tolerance_and_half_its_step():
    params, ex, duration = CASE
    run = simulate(params, ex, duration, tol=1e-4, check_accuracy=True)
    assert run.control["companion"]["tol"] == pytest.approx(1e-5)
    assert run.control["companion"]["dt"] == default_dt(params, ex) / 2
    assert 0.0 < run.control["error_measured"] < accuracy.ERROR_BOUND
    assert run.summary()["error_measured"] == run.control["error_measured"]
    plain = simulate(params, ex, duration, tol=1e-4)
    assert "error_measured" not in plain.control
    assert (plain.states == run.states).all()          # the check does not change the run


def test_a_tolerance_at_the_floor_has_no_companion():
    with pytest.raises(ParameterError, match=r"tol = 1e-09 leaves no room"):
        accuracy.companion_settings(True, 1e-9, 1e-4)


def test_a_study_checks_its_key(tmp_path):
    text = """
[study]
name = "chk"
duration_s = 0.5
check_accuracy = {value}
{extra}
[excitation]
drive = "sine"
force_n = 20.0
freq_hz = 20.0
"""
    path = tmp_path / "chk.toml"
    path.write_text(text.format(value='"yes"', extra=""))
    with pytest.raises(S.StudyError, match=r"\[study\] check_accuracy = 'yes' must be true or false"):
        S.load(path)
    path.write_text(text.format(value="true", extra="tol = 1e-9"))
    with pytest.raises(ParameterError, match=r"\[study\] tol = 1e-09 leaves no room"):
        S.load(path)
    path.write_text(text.format(value="true", extra=""))
    assert S.load(path).check_accuracy is True
