"""The response-limited drive (workbench/study/leveling.py) and the validated range flags."""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from workbench.model.params import Parameters
from workbench.present.point_checks import range_lines
from workbench.study import definition as S
from workbench.study import sweep as W
from workbench.study.leveling import MIN_FORCE_FRACTION, Limits, level
from workbench.model.validity import G_CM_S2, N_DYN, validity

S_TRAVEL = Parameters().s_travel


def _fake(responses, ok=True):
    """simulate_at for a structure whose largest responses at a force F (N) are
    ``responses(F)``: a dict of any of tip (cm), slide (cm), accel (g), force1 (N) reached
    within the first 4 s, and optionally under "late" those reached by the end (10 s)."""
    calls = []

    def record(force, r, seconds):
        r = {"tip": 0.0, "slide": 0.0, "accel": 0.0, "force1": force, **r}
        sig = pd.DataFrame({"tip_y": [5.0, 5.0 + r["tip"]], "s": [0.0, -r["slide"]],
                            "accel1": [0.0, r["accel"] * G_CM_S2], "accel2": [0.0, 0.0],
                            "accel3": [0.0, 0.0], "force1": [0.0, r["force1"] * N_DYN]},
                           index=[0.0, seconds])
        return SimpleNamespace(ok=ok, stopped=False, signals=sig, static_tip_y=5.0,
                               params=Parameters(), force=force, simulated_s=seconds)

    def simulate_at(force, stop=None):
        calls.append(force)
        early = {k: v for k, v in responses(force).items() if k != "late"}
        run = record(force, early, 4.0)
        if ok and stop is not None and stop(run):          # as simulate: ended there
            run.ok, run.stopped = False, True
            return run
        run = record(force, {**early, **responses(force).get("late", {})}, 10.0)
        if ok and stop is not None and stop(run):
            run.ok, run.stopped = False, True
        return run
    return simulate_at, calls


def _ratchet(threshold_n):
    """The slide of a friction ratchet: nothing below the threshold, the end stop above."""
    return lambda f: {"slide": 0.01 if f <= threshold_n else S_TRAVEL + 0.005}


def _bracketed(found, largest, resolution=1.25):
    """The kept force meets the limits and the bracket's failing force is within the resolution."""
    assert found.met and found.force_n <= largest + 1e-9
    assert found.force_over_n > largest and found.force_over_n <= resolution * found.force_n * (1 + 1e-12)


@pytest.mark.parametrize("kind, responses, limits, largest", [
    ("tip", lambda f: {"tip": 0.05 * f}, Limits(tip_cm=4.0), 80.0),
    ("accel", lambda f: {"accel": 0.5 * f}, Limits(), 100.0),
    ("force", lambda f: {}, Limits(force_transducer_n=150.0), 150.0),
    ("slot", _ratchet(37.0), Limits(), 37.0),
])
def test_each_limit_kind_sets_the_force_within_the_resolution(kind, responses, limits, largest):
    simulate_at, calls = _fake(responses)
    found = level(simulate_at, 200.0, limits)
    _bracketed(found, largest)
    assert found.limit == kind and found.estimate_n == 200.0 and found.runs == len(calls)
    assert found.run.force == found.force_n and found.run.ok     # the kept run, run whole
    assert validity(found.run)["out_of_range"] == ""


def test_the_most_restrictive_of_several_limits_decides():
    responses = lambda f: {"tip": 0.05 * f, "accel": f / 1.2, **_ratchet(120.0)(f)}  # noqa: E731
    found = level(_fake(responses)[0], 200.0, Limits(tip_cm=4.0))      # tip 80, accel 60, slot 120
    _bracketed(found, 60.0)
    assert found.limit == "accel"


def test_a_good_estimate_needs_few_runs_and_a_point_within_limits_runs_once():
    simulate_at, calls = _fake(_ratchet(37.0))
    found = level(simulate_at, 200.0, Limits(), estimate=35.0)
    _bracketed(found, 37.0)
    assert calls == [35.0, 35.0 * 1.25]                # up one resolution step: bracketed
    simulate_at, calls = _fake(lambda f: {"tip": 0.001 * f})
    found = level(simulate_at, 200.0, Limits(), estimate=150.0)
    assert (found.met, found.limit, calls[-1]) == (True, "force_n", 200.0)
    simulate_at, calls = _fake(lambda f: {})
    assert level(simulate_at, 200.0, Limits()).runs == 1 and calls == [200.0]


def test_a_limit_exceeded_late_in_the_run_moves_the_bracket_down():
    """A slow ratchet: above 37 N the slide reaches the end stop within 4 s, between 30 and
    37 N only later; the kept force's whole run meets the limits."""
    def responses(f):
        slow = {"late": {"slide": S_TRAVEL + 0.005}} if f > 30.0 else {}
        return {**_ratchet(37.0)(f), **slow}
    simulate_at, calls = _fake(responses)
    found = level(simulate_at, 200.0, Limits())
    _bracketed(found, 30.0)
    assert found.run.ok and found.run.simulated_s == 10.0 and found.limit == "slot"


def test_a_point_that_no_force_keeps_within_the_limits_is_reported_not_hidden():
    simulate_at, calls = _fake(lambda f: {"slide": 1.0})           # past the slot at any force
    found = level(simulate_at, 200.0, Limits(max_runs=50))
    assert not found.met and found.limit == "slot"
    assert found.force_n == pytest.approx(200.0 * MIN_FORCE_FRACTION)   # the lowest force tried
    assert validity(found.run)["out_of_range"] == "slot"
    assert found.run.ok and calls[-1] == calls[-2] == found.force_n   # the lowest, run whole
    simulate_at, calls = _fake(lambda f: {"slide": 1.0})
    assert level(simulate_at, 200.0, Limits(max_runs=3)).runs == 4 == len(calls)


def test_a_failed_run_stops_the_search():
    found = level(_fake(lambda f: {}, ok=False)[0], 200.0, Limits())
    assert not found.met and found.runs == 1 and found.limit == "the run failed"


@settings(max_examples=200, deadline=None)
@given(threshold=st.floats(0.3, 250.0), estimate=st.one_of(st.none(), st.floats(0.5, 400.0)),
       resolution=st.floats(1.05, 2.0), proportional=st.booleans())
def test_the_bracket_holds_for_any_threshold_and_estimate(threshold, estimate, resolution,
                                                          proportional):
    responses = ((lambda f: {"accel": 50.0 * f / threshold}) if proportional
                 else _ratchet(threshold))
    found = level(_fake(responses)[0], 200.0, Limits(resolution=resolution, max_runs=50),
                  estimate)
    if threshold >= 200.0:
        assert found.met and found.force_n == 200.0 and found.limit == "force_n"
    else:
        _bracketed(found, threshold, resolution)
        assert found.runs <= 2 + math.ceil(math.log2(max(1.0, math.log(200 / 0.2)
                                                          / math.log(resolution)))) * 2 + 8


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
    assert "0 of 1 points" in text
    assert "1 of 1 points" in range_lines(table.assign(out_of_range=""))[0]


STUDY = """
[study]
name = "lev"
duration_s = 1.0
window_s = 0.25
{head}

[excitation]
drive = "{drive}"
{extra}

[limits]
{limits}

[axes]
tip_mass = [false]
{axes}
"""


def test_a_levelled_study_chains_its_frequencies_and_keeps_each_point_within(tmp_path):
    """Without the tip mass, 200 N at 20 Hz sends the tip past 3 cm: the point runs again at
    lower forces; the 25 Hz point starts from the 20 Hz point's force."""
    path = tmp_path / "lev.toml"
    path.write_text(STUDY.format(head="check_accuracy = true", drive="sine",
                                 extra="force_n = 200.0\nramp_s = 0.25",
                                 limits="tip_cm = 3.0\nslot = false\naccel_g = false",
                                 axes="freq_hz = [20.0, 25.0]"))
    study = S.load(path)
    assert study.limits == Limits(tip_cm=3.0, slot=False, accel_g=None) and study.chained
    assert [len(c) for c in study.chains()] == [2]
    W.sweep(study, results=tmp_path / "res", jobs=1, progress=False)
    rows = pd.read_parquet(tmp_path / "res" / "lev" / "points.parquet")
    first, second = rows.iloc[0], rows.iloc[1]
    assert (rows.status == "ok").all() and rows.level_met.all() and (rows.level_limit == "tip").all()
    assert first.level_runs >= 2 and first.force_n_used < 200.0
    assert (rows.tip_abs_max_cm <= 3.0).all() and (rows.level_force_over_n <= 1.25 * rows.force_n_used).all()
    assert second.level_estimate_n == first.force_n_used
    # the accepted run, checked against its companion
    assert (0.0 < rows.error_measured).all() and (rows.error_measured < 1e-3).all()


@pytest.mark.parametrize("drive, extra, limits, match", [
    ("free_decay", "deflection_cm = 8.4", "", "\\[limits\\] sets each point's force: a 'free_decay'"),
    ("sine", "force_n = 20.0\nfreq_hz = 20.0", "tip_cm = -1.0", "\\[limits\\] tip_cm"),
    ("sine", "force_n = 20.0\nfreq_hz = 20.0", "accel = 50", "unknown key\\(s\\) \\['accel'\\] in \\[limits\\]"),
    ("sine", "force_n = 20.0\nfreq_hz = 20.0", "resolution = 1.0", "\\[limits\\] resolution = 1.0 must be"),
    ("sine", "force_n = 20.0\nfreq_hz = 20.0", "max_runs = 0", "\\[limits\\] max_runs = 0"),
    ("sine", "force_n = 20.0\nfreq_hz = 20.0", "slot = 1", "\\[limits\\] slot = 1 must be true or false"),
])
def test_bad_limits_are_one_line_errors_naming_the_key(tmp_path, drive, extra, limits, match):
    path = tmp_path / "bad.toml"
    path.write_text(STUDY.format(head="", drive=drive, extra=extra, limits=limits, axes=""))
    with pytest.raises(S.StudyError, match=match) as err:
        S.load(path)
    assert "\n" not in str(err.value)


def test_a_run_stopped_at_a_limit_is_the_whole_runs_first_part():
    """simulate(stop=...) ends the run after the second in which the record first exceeds the
    limit; the stopped record equals the whole run's up to there (the filtered channels too)."""
    from workbench.model.drives import sine
    from workbench.model.simulate import simulate

    p = Parameters().replace(tip_mass=False)
    drive = sine(200.0, 20.0, ramp_s=0.25)
    whole = simulate(p, drive, 3.0)
    limits = Limits(tip_cm=1.0, slot=False, accel_g=None)
    seen = []

    def stop(record):
        seen.append(len(record.t))
        return limits.exceeded(record)
    part = simulate(p, drive, 3.0, stop=stop)
    assert part.stopped and not part.ok and "tip at" in part.message
    assert part.t_end < 3.0 and len(seen) >= 1
    n = seen[-1]                            # the record the condition saw: its filters final
    assert n > len(part.t) - 100
    cols = ["tip_y", "s", "accel1", "accel3", "force1", "strain1"]
    np.testing.assert_array_equal(part.signals[cols].iloc[:n].to_numpy(),
                                  whole.signals[cols].iloc[:n].to_numpy())
    assert validity(part)["tip_abs_max_cm"] > 1.0


def test_the_documented_limits_are_the_defaults():
    """docs/usage.md's [limits] example states every key at its default."""
    import tomllib

    from workbench.study.definition import _limits
    text = (S.__file__.rsplit("/workbench/", 1)[0] + "/docs/usage.md")
    block = open(text).read().split("```toml\n  [limits]", 1)[1].split("```", 1)[0]
    table = tomllib.loads("[limits]" + "\n".join(line[2:] for line in block.splitlines()))
    assert set(table["limits"]) == {"accel_g", "force_transducer_n", "tip_cm", "slot",
                                    "resolution", "max_runs"}
    assert _limits(table["limits"]) == Limits()
