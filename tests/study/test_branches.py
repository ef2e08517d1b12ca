"""Continuation studies (study/branches.py): the [study] continuation table, the stepped sweep
set beside a branch, and a small study end to end, resumed."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from workbench import cli
from workbench.study import branches as B
from workbench.study import definition as S

TINY = """
[study]
name = "tiny_branch"
description = "the stuck joint's branch over 19.6-20.4 Hz"
continuation = {parameter = "freq_hz", from = 19.6, to = 20.4, compare = "fake_stepped"}
[excitation]
drive = "sine"
force_n = 0.5
[fixed]
tip_mass = true
[axes]
gap_mm = [1.016]
"""


def load(tmp_path, text):
    path = tmp_path / "study.toml"
    path.write_text(text)
    return S.load(path)


def test_a_continuation_study_is_read(tmp_path):
    study = load(tmp_path, TINY)
    c = study.continuation
    assert (c.parameter, c.start, c.end, c.periods, c.compare) == (
        "freq_hz", 19.6, 20.4, 1, "fake_stepped")
    assert not c.period_doubling and c.monodromy == "variational"
    assert study.n_points == 1 and study.points[0].excitation["freq_hz"] == 19.6
    assert B.label(study.points[0]) == "gap_mm-1.016"


@pytest.mark.parametrize("edit, message", [
    (('parameter = "freq_hz"', 'parameter = "gap_mm"'),
     "[study] continuation parameter = 'gap_mm'; allowed: ['force_n', 'freq_hz']"),
    (("to = 20.4", "to = 19.6"), "[study] continuation from = to = 19.6: the range is empty"),
    (("to = 20.4", "to = -1.0"), "[study] continuation to = -1.0 must be a positive number (Hz)"),
    (('compare = "fake_stepped"', "periods = 0"),
     "[study] continuation periods = 0 must be a whole number in [1, 8]"),
    (('compare = "fake_stepped"', "switch = true"), "unknown key(s) ['switch'] in [study] "
     "continuation"),
    (("gap_mm = [1.016]", "gap_mm = [1.016]\nfreq_hz = [20.0]"),
     "[axes] freq_hz: the continued parameter's range is the continuation's from and to"),
    (('description', 'duration_s = 5.0\ndescription'), "[study] duration_s sets a grid's runs"),
    (('drive = "sine"\nforce_n = 0.5', 'drive = "chirp"'), "orbits of a sine drive"),
])
def test_a_bad_continuation_table_is_refused_in_one_line(tmp_path, edit, message):
    with pytest.raises(S.StudyError) as err:
        load(tmp_path, TINY.replace(*edit))
    assert message in str(err.value) and "\n" not in str(err.value)


def _branch(values, amplitudes, stable, folds=()):
    return pd.DataFrame({"freq_hz": values, "tip_h1_cm": amplitudes, "stable": stable,
                         "bifurcation": ["fold" if v in folds else "" for v in values]})


def test_the_orbits_at_a_frequency_are_read_off_every_segment_of_a_folded_branch():
    """An S-shaped branch (two folds) has three orbits between its folds; linear between the
    orbits that bracket the frequency, their stability where both agree."""
    branch = _branch([10.0, 12.0, 11.0, 13.0], [1.0, 3.0, 5.0, 9.0], [True, True, False, True],
                     folds=(12.0, 11.0))
    there = B.orbits_at(branch, "freq_hz", 11.5)
    assert sorted(there) == [(2.5, "stable"), (4.0, "changes"), (6.0, "changes")]
    assert B.orbits_at(branch, "freq_hz", 10.0) == [(1.0, "stable")]
    assert B.orbits_at(branch, "freq_hz", 13.5) == []
    two = pd.concat([branch.assign(branch="a"), _branch([10.0, 14.0], [0.5, 0.5], [True, True])
                     .assign(branch="b")])
    assert (0.5, "stable") in B.orbits_at(two, "freq_hz", 11.5) and len(B.orbits_at(
        two, "freq_hz", 11.5)) == 4
    branch["stability"] = ["stable", "undetermined", "unstable", "unstable"]
    assert sorted(B.orbits_at(branch, "freq_hz", 11.5)) == [
        (2.5, "undetermined"), (4.0, "undetermined"), (6.0, "unstable")]


def test_a_jump_of_the_stepped_sweep_is_set_between_the_folds():
    """Up and down differ at 11.5 (hysteresis): the folds at 11 and 12 bracket it; at 10 and
    13 they agree."""
    branch = _branch([10.0, 12.0, 11.0, 13.0], [1.0, 3.0, 5.0, 9.0], [True, True, False, True],
                     folds=(12.0, 11.0))
    beside = pd.DataFrame({"freq_hz": [10.0, 11.5, 13.0, 11.5, 10.0],
                           "direction": ["up", "up", "up", "down", "down"],
                           "stepped_tip_h1_cm": [1.0, 2.5, 9.0, 7.0, 1.02]})
    jumps = B.jumps_and_folds(beside, branch, "freq_hz")
    assert len(jumps) == 1
    j = jumps[0]
    assert (j["freq_hz"], j["up"], j["down"], j["fold_below"], j["fold_above"]) == (
        11.5, 2.5, 7.0, 11.0, 12.0)


@pytest.fixture(scope="module")
def tiny_study(tmp_path_factory):
    """The stuck joint's branch at 0.5 N, beside a made-up stepped sweep at 20 Hz whose up
    point is the orbit's line and whose down point is 30 % above it."""
    root = tmp_path_factory.mktemp("branches")
    path = root / "tiny.toml"
    path.write_text(TINY)
    from workbench.model import drives
    from workbench.model.orbit import periodic_orbit
    study = S.load(path)
    orbit = periodic_orbit(study.points[0].params, drives.sine(0.5, 20.0))
    h1 = orbit.responses["tip_h1_cm"]
    (root / "res" / "fake_stepped").mkdir(parents=True)
    pd.DataFrame({"axis_gap_mm": [1.016, 1.016, 1.016], "axis_freq_hz": [20.0, 20.0, 25.0],
                  "direction": ["up", "down", "up"], "status": ["ok"] * 3,
                  "tip_h1": [h1, 1.3 * h1, 1.0], "steady": [True, True, True],
                  "steady_change": [0.0, 0.0, 0.0],
                  "tip_poincare": [[0.1, 0.1], [0.1, 0.3], [0.0]], "wall_s": [2.0, 3.0, 4.0],
                  "tol": [1e-5] * 3, "simulated_s": [5.0] * 3}
                 ).to_parquet(root / "res" / "fake_stepped" / "points.parquet")
    code = cli.main(["sweep", str(path), "--results", str(root / "res"), "--quiet"])
    return root, code, h1


def test_a_continuation_study_traces_writes_and_compares(tiny_study):
    root, code, h1 = tiny_study
    out = root / "res" / "tiny_branch"
    assert code == 0
    summary = json.loads((out / "gap_mm-1.016" / "summary.json").read_text())
    assert summary["status"] == "done" and len(summary["segments"]) == 1
    table = pd.read_parquet(out / "branches.parquet")
    assert set(table.branch) == {"gap_mm-1.016"} and (table.axis_gap_mm == 1.016).all()
    assert table.freq_hz.iloc[0] == 19.6 and table.freq_hz.iloc[-1] > 20.4
    beside = pd.read_parquet(out / "gap_mm-1.016" / "stepped_beside.parquet")
    assert list(beside.direction) == ["up", "down"]          # 25 Hz is outside the range
    up, down = beside.iloc[0], beside.iloc[1]
    assert up.orbits_there == 1 and up.orbit_stability == "stable" and up.difference_rel < 1e-4
    assert down.difference_rel == pytest.approx(0.3 / 1.3, rel=1e-3)
    # log(1e-3) / log|mu|: the periods a run takes to come within 1e-3 of the orbit
    assert up.settle_periods == pytest.approx(np.log(1e-3) / np.log(up.orbit_max_multiplier))
    assert 0.99 < up.orbit_max_multiplier < 1.0
    report = (out / "report.md").read_text()
    assert "| none | none | 1 | no |" in report          # the jump at 20 Hz: no fold brackets it
    assert "points at the same axis values 5 s" in report   # 2 s + 3 s: 25 Hz is outside
    assert "At the same accuracy: a run settles onto a stable orbit" in report
    assert (out / "gap_mm-1.016" / "stepped_beside.png").is_file()


def test_a_continuation_study_run_again_traces_nothing_and_a_changed_one_again(tiny_study):
    root, _, _ = tiny_study
    path = root / "tiny.toml"
    out = root / "res" / "tiny_branch" / "gap_mm-1.016" / "summary.json"
    before = out.read_text()
    assert cli.main(["sweep", str(path), "--results", str(root / "res"), "--quiet"]) == 0
    assert out.read_text() == before
    path.write_text(TINY.replace("to = 20.4", "to = 19.8"))
    assert cli.main(["sweep", str(path), "--results", str(root / "res"), "--quiet"]) == 0
    assert json.loads(out.read_text())["definition"]["continuation"]["end"] == 19.8
    table = pd.read_parquet(root / "res" / "tiny_branch" / "branches.parquet")
    assert table.freq_hz.max() < 20.0


def test_a_study_cut_short_reports_the_orbits_on_disk(tiny_study, tmp_path):
    """Without the branch's summary (the study killed while tracing), the report lists the
    orbits on disk as interrupted and still sets the stepped points beside them."""
    import shutil
    root, _, _ = tiny_study
    res = tmp_path / "res"
    shutil.copytree(root / "res", res)
    (res / "tiny_branch" / "gap_mm-1.016" / "summary.json").unlink()
    (root / "tiny.toml").write_text(TINY)
    (res / "tiny_branch" / "branches.parquet").unlink()
    assert cli.main(["report", str(root / "tiny.toml"), "--results", str(res)]) == 0
    assert (res / "tiny_branch" / "branches.parquet").is_file()
    report = (res / "tiny_branch" / "report.md").read_text()
    orbits = len(pd.read_parquet(res / "tiny_branch" / "gap_mm-1.016" / "branch.parquet"))
    assert f"| interrupted: cut short: the orbits on disk | {orbits} |" in report
    assert "## The stepped study `fake_stepped` beside the branches" in report
    assert "At the same accuracy" not in report                 # no wall time to count


def test_a_branch_that_ends_early_starts_anew_beyond_it_and_from_the_end(tmp_path, monkeypatch):
    """Each segment that ends (here every one, after 0.2 Hz) starts the next 1 % of the range
    beyond the farthest value it reached; after MAX_SEGMENTS, one branch from the range's end
    back towards them.  The tracing itself is stood in for (continuation.continue_branch)."""
    from workbench.model import continuation
    from workbench.model.continuation import Branch
    calls = []

    def ends_early(shooter, lo, hi, on_orbit=None, **_):
        calls.append((lo, hi))
        step = 0.2 if hi > lo else -0.2
        return Branch("freq_hz", orbits=[(lo, None), (lo + step, None)], status="step floor",
                      message="stood in")
    monkeypatch.setattr(continuation, "continue_branch", ends_early)
    study = load(tmp_path, TINY.replace("to = 20.4", "to = 30.0"))
    summary = B.trace(study, study.points[0], tmp_path / "b", lambda *a: None)
    step = B.RESTART * (30.0 - 19.6)
    starts = [lo for lo, _ in calls]
    assert len(calls) == B.MAX_SEGMENTS + 1
    assert np.allclose(np.diff(starts[:-1]), 0.2 + step)
    assert calls[-1] == (30.0, pytest.approx(starts[-2] + 0.2))
    assert [s["folder"] for s in summary["segments"]][:2] == [".", f"from-{starts[1]:.4g}"]
    assert summary["segments"][-1]["folder"] == "from-end"
    assert summary["status"] == f"step floor ({B.MAX_SEGMENTS + 1} segments)"


def test_a_branch_cut_short_resumes_from_its_last_orbit(tmp_path):
    """A study killed while a branch is traced (here after its 4th orbit) and run again keeps
    the orbits on disk as an interrupted segment and continues from the last of them, found
    again from the state its row holds (the same orbit), onwards to the range's end."""
    from workbench.present.branch import write_branch

    class Killed(BaseException):
        pass

    def killed_after_four(branch, out, params):
        write_branch(branch, out, params)
        if len(branch.orbits) == 4:
            raise Killed

    study = load(tmp_path, TINY)
    folder = tmp_path / "b"
    with pytest.raises(Killed):
        B.trace(study, study.points[0], folder, killed_after_four)
    before = pd.read_parquet(folder / "branch.parquet")
    tracing = json.loads((folder / B.TRACING).read_text())
    assert len(before) == 4 and [s["status"] for s in tracing["segments"]] == ["running"]
    summary = B.trace(study, study.points[0], folder, write_branch)
    segments = summary["segments"]
    last = before.iloc[-1]
    assert [s["status"] for s in segments] == ["interrupted", "done"]
    assert segments[0]["orbits"] == 4 and segments[1]["folder"] == f"resumed-{last.freq_hz:.6g}"
    after = pd.read_parquet(folder / segments[1]["folder"] / "branch.parquet")
    assert after.freq_hz.iloc[0] == last.freq_hz
    state, again = np.asarray(last.state), np.asarray(after.state.iloc[0])
    assert np.max(np.abs(again - state)) <= 1e-6 * np.max(np.abs(state))
    assert np.all(np.diff(after.freq_hz) > 0) and after.freq_hz.iloc[-1] > 20.4
    assert summary["orbits"] == 4 + len(after)
    again = B.trace(study, study.points[0], folder, write_branch, fresh=True)
    assert [s["folder"] for s in again["segments"]] == ["."]
    assert not (folder / segments[1]["folder"] / "branch.parquet").exists()


def test_doubled_branches_are_traced_where_the_orbit_loses_stability_at_minus_one(tmp_path,
                                                                                  monkeypatch):
    """From the rows on disk: a doubled branch at each change of stability at -1 into an
    orbit that is not stable (not where the orbit after it is stable), MAX_DOUBLED of them,
    the rest listed; traced again, the record's finished branches are not traced again.
    The tracing itself is stood in for."""
    from workbench.model import continuation
    from workbench.model.continuation import Branch
    values = [19.6 + 0.15 * k for k in range(8)]
    crossing = ["", "-1", "-1", "-1", "-1", "-1", "-1", ""]
    stability = ["stable", "unstable", "unstable", "stable", "unstable", "unstable", "unstable",
                 "unstable"]
    traced, doubled = [], []

    def whole_branch(shooter, lo, hi, on_orbit=None, **_):
        traced.append(lo)
        branch = Branch("freq_hz", orbits=[(v, None) for v in values], status="done",
                        towards=hi)
        on_orbit(branch)
        return branch

    def write(branch, sub, params):
        sub.mkdir(parents=True, exist_ok=True)
        pd.DataFrame({"freq_hz": values, "multiplier_crossing": crossing,
                      "stability": stability, "bifurcation": [""] * len(values)}
                     ).to_parquet(sub / "branch.parquet")

    def stood_in(shooter, parent, index, lo, hi, on_orbit=None):
        doubled.append(parent)
        return Branch("freq_hz", status="ended", message="stood in")
    monkeypatch.setattr(continuation, "continue_branch", whole_branch)
    monkeypatch.setattr(continuation, "continue_doubled", stood_in)
    monkeypatch.setattr(B, "_parent", lambda shooter, rows, i: (shooter, rows.freq_hz.iloc[i], 1))
    study = load(tmp_path, TINY.replace("compare =", "period_doubling = true, compare ="))
    summary = B.trace(study, study.points[0], tmp_path / "b", write)
    assert doubled == [values[i] for i in (1, 2, 4, 5)] and B.MAX_DOUBLED == 4
    assert [d["folder"] for d in summary["doubled"]] == [f"doubled-{values[i]:.4g}"
                                                         for i in (1, 2, 4, 5)]
    assert summary["doublings_not_traced"] == [values[6]]
    (tmp_path / "b" / "summary.json").unlink()                  # cut short after the last
    again = B.trace(study, study.points[0], tmp_path / "b", write)
    assert traced == [19.6] and len(doubled) == 4 and again["doubled"] == summary["doubled"]
