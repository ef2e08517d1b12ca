"""Studies and sweeps: definition -> parallel, resumable runs -> points table."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from workbench.study import definition as S
from workbench.study import sweep as W
from workbench.present.report import make_report, series_tags
from workbench.model.params import ParameterError
from workbench.study.store import WATCHDOG_S, read_runs

from small_studies import CHIRP, SMALL



def write(tmp_path, text, name="study.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def comparable(table):
    """The table without what legitimately differs between runs (wall time)."""
    return table.drop(columns=["wall_s"]).sort_values("key").reset_index(drop=True)


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    root = tmp_path_factory.mktemp("sweep")
    study = S.load(write(root, SMALL))
    return study, root, W.run_study(study, root / "res1", jobs=1, progress=False)


def test_small_grid_end_to_end(small_run):
    study, root, table = small_run
    assert study.n_points == 4 and len(table) == 4
    assert (table.status == "ok").all()
    assert sorted(zip(table.axis_gap_mm, table.axis_freq_hz)) == \
        [(0.508, 20.0), (0.508, 30.0), (1.016, 20.0), (1.016, 30.0)]
    # the fit recovers the drive: 20 N = 2e6 dyn at f (through the anti-alias filter, within
    # its passband ripple), nothing at f/2 in the force
    from workbench.model.antialias import design
    ripple = 10 ** (design(10, 10_000.0)["ripple_db"] / 20) - 1
    assert np.allclose(table["force1_h1"], 2e6, rtol=ripple)
    assert (table["force1_h0.5"] < 1e-6 * 2e6).all()
    shares = table[[c for c in table if c.startswith("share_")]].sum(axis=1)
    assert np.allclose(shares, 1.0, atol=1e-12)
    assert (table.tip_rms > 0).all() and table.steady.dtype == bool
    on_disk = pd.read_parquet(root / "res1" / "small" / "points.parquet")
    pd.testing.assert_frame_equal(on_disk, table)
    # each point keeps the integrator's account: the default method met its tolerance
    assert (table.method == "dop853").all() and (table.tol == study.tol).all()
    assert (table.error_over_tol_max <= 1.0).all() and (table.floor_count == 0).all()
    assert (table.steps_all >= table.steps).all() and (table.h_min <= table.h_max).all()
    series = sorted(p.name for p in (root / "res1" / "small" / "series").iterdir())
    assert len(series) == 2          # one named point: signals + events
    key = table[(table.axis_gap_mm == 1.016) & (table.axis_freq_hz == 20.0)].key.iloc[0]
    assert series == [f"{key}.events.parquet", f"{key}.parquet"]


def test_two_workers_give_the_same_results_to_the_bit(small_run):
    study, root, table = small_run
    table2 = W.run_study(study, root / "res2", jobs=2, progress=False)
    pd.testing.assert_frame_equal(comparable(table), comparable(table2), check_exact=True)


def test_rerun_skips_finished_points_and_recomputes_a_missing_one(small_run, tmp_path):
    study, root, table = small_run
    res = tmp_path / "res"
    W.run_study(study, res, jobs=1, progress=False)
    files = sorted((res / "small" / "points").glob("*.parquet"))
    stamps = {f: f.stat().st_mtime_ns for f in files}
    files[0].unlink()
    again = W.run_study(study, res, jobs=1, progress=False)
    assert files[0].exists()
    assert all(f.stat().st_mtime_ns == stamps[f] for f in files[1:])
    pd.testing.assert_frame_equal(comparable(again), comparable(table), check_exact=True)


def test_a_killed_sweep_resumes(small_run, tmp_path):
    """kill -9 the CLI after its first point is on disk; a rerun completes the grid."""
    study, root, table = small_run
    res = tmp_path / "res"
    cmd = [sys.executable, "-m", "workbench", "sweep", study.source, "--jobs", "1",
           "--results", str(res), "--quiet"]
    proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    points = res / "small" / "points"
    deadline = time.time() + 600
    while time.time() < deadline and not (points.exists() and any(points.glob("*.parquet"))):
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    done = list(points.glob("*.parquet"))
    assert 1 <= len(done) < 4, "the kill should land mid-sweep"
    resumed = W.run_study(study, res, jobs=1, progress=False)
    pd.testing.assert_frame_equal(comparable(resumed), comparable(table), check_exact=True)


def test_a_failing_point_is_recorded_and_the_sweep_goes_on(small_run, tmp_path, monkeypatch):
    study, _, _ = small_run
    real = W.simulate

    def flaky(params, excitation, *args, **kwargs):
        if excitation[2] == 30.0 and params.gap > 0.1:         # X_FREQ; the 1.016 mm gap
            raise RuntimeError("injected failure")
        return real(params, excitation, *args, **kwargs)

    monkeypatch.setattr(W, "simulate", flaky)
    table = W.run_study(study, tmp_path / "res", jobs=1, progress=False)
    bad = table[table.status != "ok"]
    assert len(bad) == 1 and len(table) == 4
    assert bad.status.iloc[0] == "error" and "injected failure" in bad.message.iloc[0]
    assert "RuntimeError" in bad.traceback.iloc[0]
    report = make_report(study, tmp_path / "res").read_text()
    assert "injected failure" in report           # listed with its reason
    tables = tmp_path / "res" / "small" / "tables"
    assert (tables / "response.md").read_text().count("failed") == 4 + 1   # 4 blocks + legend


def test_an_unstable_point_is_recorded_as_failed(tmp_path, monkeypatch):
    """A run that ends with a failure status (here: fixed RK4 steps far beyond its stability,
    which a study cannot ask for, forced through the API) is a recorded point, with its
    figures.  (The controlled method shrinks such a step until it is stable.)"""
    text = SMALL.replace("gap_mm = [0.508, 1.016]", "gap_mm = [1.016]").replace(
        "freq_hz = [20.0, 30.0]", "freq_hz = [20.0]")
    with pytest.raises(ParameterError, match="stability limit"):
        S.load(write(tmp_path, text.replace("window_s = 0.2", "window_s = 0.2\ndt = 1e-3"),
                     "unstable.toml"))
    real = W.simulate
    monkeypatch.setattr(W, "simulate", lambda p, ex, *a, **kw: real(
        p, ex, *a, **{**kw, "dt": 1e-3, "method": "rk4", "tol": None}))
    table = W.run_study(S.load(write(tmp_path, text)), tmp_path / "res", jobs=1, progress=False)
    assert table.status.tolist() == ["failed"]
    assert table.message.iloc[0]
    # a grid with no finished point still gets its tables, and the partial series its figures
    make_report(S.load(tmp_path / "study.toml"), tmp_path / "res")
    out = tmp_path / "res" / "small"
    assert pd.read_csv(out / "tables" / "response.csv").status.tolist() == ["failed"]
    assert (out / "figures" / f"time_history_{series_tags(table)[0]}.png").exists()


def test_stepped_sweep_carries_the_state(tmp_path):
    text = SMALL.replace('window_s = 0.2', 'window_s = 0.2\nsweep = "up-down"').replace(
        "freq_hz = [20.0, 30.0]", "freq_hz = [20.0, 25.0, 30.0]").replace(
        "gap_mm = [0.508, 1.016]", "gap_mm = [1.016]")
    study = S.load(write(tmp_path, text))
    chain = study.chains()[0]
    assert [p.values["freq_hz"] for p in chain] == [20.0, 25.0, 30.0, 25.0, 20.0]
    assert [p.direction for p in chain] == ["up"] * 3 + ["down"] * 2
    table = W.run_study(study, tmp_path / "res", jobs=1, progress=False)
    assert (table.status == "ok").all() and len(table) == 5
    assert table.sort_values("step").continued.tolist() == [False, True, True, True, True]
    assert len(set(table.key)) == 5      # 25 Hz up and down are different points


@pytest.mark.parametrize("edit, message", [
    (("[axes]", "[axis]"), "unknown table"),
    (('name = "small"', 'name = "small"\nlength = 3'), "unknown key(s) ['length']"),
    (("gap_mm = [0.508, 1.016]", "gapp_mm = [0.508]"), "did you mean gap_mm"),
    (("gap_mm = [0.508, 1.016]", "gap_mm = [0.508, 6.0]"), "gap_mm = 6.0 mm is outside"),
    (("force_n = 20.0", "force_n = 20.0\nf0_hz = 5.0"), "does not apply to a 'sine'"),
    (("window_s = 0.2", "window_s = 0.4"), "at most half of duration_s"),
    (("window_s = 0.2", 'window_s = 0.2\nsweep = "sideways"'), "sweep = 'sideways'"),
    (("ramp_s = 0.1", "ramp_s = -1.0"), "ramp_s"),
    (("freq_hz = [20.0, 30.0]", "freq_hz = [20.0, 20.0]"), "lists a value twice"),
    (("freq_hz = [20.0, 30.0]", "freq_hz = [20, 20.0]"), "lists a value twice"),
    (("freq_hz = [20.0, 30.0]", "freq_hz = [20.0, 1e5]"), "freq_hz = 100000 Hz is above"),
    (("ramp_s = 0.1", "ramp_s = 3.0"), "soft start would end after the run"),
    (("window_s = 0.2", "window_s = 0.2\ndt = nan"), "[study] dt = nan"),
    (("window_s = 0.2", "window_s = 0.2\noutput_hz = 333.0"), "output_hz = 333.0 Hz"),
    (("[axes]", "[axes]\ncork = [[\"linear\"]]"), "[axes] cork"),
    (("[excitation]", "[fixed]\ncork = {n = 1}\n[excitation]"), "[fixed] cork"),
    (('name = "small"', 'name = "' + "x" * 300 + '"'), "at most 100"),
    (("save_series = [{gap_mm = 1.016, freq_hz = 20.0}]", "save_series = 3"), "save_series"),
    (("[study]", "study = 3\n[other]"), "unknown table"),
    (("[axes]", "[fixed]\ngap_mm = 1.0\n[axes]"), "both as an axis and as a fixed value"),
])
def test_bad_study_files_are_rejected_before_running(tmp_path, edit, message):
    text = SMALL.replace(*edit)
    assert text != SMALL
    with pytest.raises(ParameterError) as err:
        S.load(write(tmp_path, text))
    assert message in str(err.value)
    assert str(tmp_path) in str(err.value)      # names the file


def test_cli_sweep_rejects_a_bad_file(tmp_path, capsys):
    from workbench.cli import main
    assert main(["sweep", str(write(tmp_path, SMALL.replace("[axes]", "[axis]")))]) == 2
    assert "unknown table" in capsys.readouterr().err


def test_dask_cluster_gives_the_local_results(small_run, tmp_path):
    import distributed       # a dev dependency: the Dask path is always tested
    study, _, table = small_run
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1",
                                  dashboard_address=None, processes=True) as cluster:
        remote = W.run_study(study, tmp_path / "res", scheduler=cluster.scheduler_address,
                             progress=False)
    pd.testing.assert_frame_equal(comparable(remote), comparable(table), check_exact=True)


def test_report_figures_and_tables_of_a_grid(small_run):
    """Definition -> results -> figures -> tables: every artefact exists and says what the table says."""
    import json
    import re

    study, root, table = small_run
    out = root / "res1" / "small"
    index = make_report(study, root / "res1")
    tag = "gap-1.016mm_drive-frequency-20hz"
    assert tag in series_tags(table)
    expected = ["frf_map_tip", "frf_map_strain1", "response_curves", "regime_shares",
                "bifurcation", f"time_history_{tag}", f"strain_spectra_{tag}", f"switching_{tag}"]
    for name in expected:
        for ext in ("png", "pdf"):
            assert (out / "figures" / f"{name}.{ext}").stat().st_size > 5000
    links = re.findall(r"\]\(([^)]+)\)", index.read_text())
    assert len(links) >= 2 * len(expected) + 6 + 2
    assert all((out / link).exists() for link in links)
    csv = pd.read_csv(out / "tables" / "response.csv")
    merged = csv.merge(table, left_on=["gap_mm", "freq_hz"], right_on=["axis_gap_mm", "axis_freq_hz"])
    assert len(merged) == 4 and np.allclose(merged["tip_rms [mm]"], 10 * merged.tip_rms,
                                            rtol=1e-12)                  # SI: cm -> mm
    md = (out / "tables" / "response.md").read_text()
    block = md.split("## tip RMS (mm)")[1].split("##")[0]
    assert block.count("*") == (~table.steady).sum()
    for value in table.tip_rms:
        assert f"{10 * value:.3g}" in block
    tex = (out / "tables" / "contact.tex").read_text()
    assert tex.count(r"\begin{table}") == tex.count(r"\end{table}") == 5
    prov = json.loads((out / "provenance.json").read_text())
    assert prov["code_version"] and prov["packages"]["numba"]
    assert prov["study"]["axes"]["gap_mm"] == [0.508, 1.016]
    assert prov["runs"][0]["wall_s"] > 0 and prov["points"]["total"] == 4
    # the bifurcation samples: one per forcing period of the window
    assert all(len(s) == round(0.2 * f) + 1 for s, f in zip(table.tip_poincare, table.axis_freq_hz))


def test_the_report_names_the_largest_estimate_and_flags_points_above_the_tolerance(small_run):
    from workbench.present.report import accuracy_lines

    study, _, table = small_run
    text = "\n".join(accuracy_lines(study, table))
    worst = table.error_over_tol_max.max()
    assert f"tol = {study.tol:g}" in text and f"{worst:.3g} of the tolerance" in text
    assert "above their tolerance" not in text
    over = table.copy()
    over.loc[over.index[1], "error_over_tol_max"] = 3.5
    over.loc[over.index[2], "floor_count"] = 2
    text = "\n".join(accuracy_lines(study, over))
    assert "## Points above their tolerance" in text
    rows = [line for line in text.splitlines() if line.startswith("| ") and "estimate" not in line]
    assert len(rows) == 2 and "| 3.5 | 0 |" in rows[0] and rows[1].endswith("| 2 |")


def test_report_drawn_by_two_processes_is_the_serial_one(small_run, tmp_path):
    """jobs=2 draws the same figures and writes the same report.md, in the same order."""
    import shutil

    study, root, _ = small_run
    serial = make_report(study, root / "res1").read_text()
    shutil.copytree(root / "res1" / "small", tmp_path / "small",
                    ignore=shutil.ignore_patterns("figures", "report.md"))
    parallel = make_report(study, tmp_path, jobs=2).read_text()
    assert parallel == serial
    assert sorted(p.name for p in (tmp_path / "small" / "figures").iterdir()) == \
        sorted(p.name for p in (root / "res1" / "small" / "figures").iterdir())


def test_report_of_a_chirp_has_a_spectrogram_and_its_frfs(tmp_path):
    text = CHIRP
    study = S.load(write(tmp_path, text))
    table = W.run_study(study, tmp_path / "res", jobs=1, progress=False)
    assert table.status.tolist() == ["ok"] and "tip_poincare" not in table
    make_report(study, tmp_path / "res")
    out = tmp_path / "res" / "chirp"
    assert (out / "figures" / "spectrogram_gap-1.016mm.png").exists()
    assert "### spectrogram — gap 1.016 mm" in (out / "report.md").read_text()
    assert not (out / "figures" / "frf_map_tip.png").exists()     # no gap x frequency grid
    long = pd.read_csv(out / "tables" / "response.csv")       # in SI: mm, m/s², µε
    assert long["tip_rms [mm]"].iloc[0] == pytest.approx(10 * table.tip_rms.iloc[0], rel=1e-12)
    assert long["accel3_rms [m/s²]"].iloc[0] == pytest.approx(table.accel3_rms.iloc[0] / 100)
    assert long["strain1_rms [µε]"].iloc[0] == pytest.approx(table.strain1_rms.iloc[0] * 1e6)
    assert (out / "figures" / "frf_gap-1.016mm.png").exists()
    modes = pd.read_csv(out / "tables" / "frf_modes.csv")
    assert len(modes) > 0 and modes.f_hz.between(5.0, 65.0).all()       # the chirp's band
    assert (modes.band_lo_hz == 5.0).all() and (modes.band_hi_hz == 65.0).all()
    assert "frf_modes.md" in (out / "report.md").read_text()


def test_a_damaged_point_file_is_set_aside_and_recomputed(small_run, tmp_path, capsys):
    study, root, table = small_run
    res = tmp_path / "res"
    W.run_study(study, res, jobs=1, progress=False)
    files = sorted((res / "small" / "points").glob("*.parquet"))
    files[0].write_bytes(b"PAR1 not really parquet")
    (res / "small" / "runs.json").write_text("{ damaged")
    again = W.run_study(study, res, jobs=1, progress=False)
    pd.testing.assert_frame_equal(comparable(again), comparable(table), check_exact=True)
    damaged = sorted(p.name for p in (res / "small" / "damaged").iterdir())
    assert any(n.startswith(files[0].name) for n in damaged)
    assert any(n.startswith("runs.json") for n in damaged)
    err = capsys.readouterr().err
    assert files[0].name in err and "computed again" in err
    runs = read_runs(res / "small")
    assert runs[-1]["state"] == "done" and runs[-1]["points_run"] == 1


def test_an_interrupted_sweep_is_on_record(small_run, tmp_path, monkeypatch):
    study, _, _ = small_run

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt
    monkeypatch.setattr(W, "_execute", interrupted)
    with pytest.raises(KeyboardInterrupt):
        W.run_study(study, tmp_path / "res", jobs=1, progress=False)
    runs = read_runs(tmp_path / "res" / "small")
    assert [r["state"] for r in runs] == ["interrupted"] and runs[0]["points_run"] == 4


def test_a_second_sweep_of_the_same_study_is_refused(small_run, tmp_path):
    from workbench.study.store import StudyLock
    study, _, _ = small_run
    out = tmp_path / "res" / "small"
    with StudyLock(out):
        with pytest.raises(ParameterError, match="another sweep of this study is running"):
            W.run_study(study, tmp_path / "res", jobs=1, progress=False)
    W.run_study(study, tmp_path / "res", jobs=1, progress=False)      # free again


def _children(pid):
    kids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            kids.append(int(stat.parent.name))
    return kids


def _alive(pid):
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_kill_9_of_the_sweep_leaves_no_worker_computing(tmp_path):
    text = SMALL.replace("duration_s = 0.5", "duration_s = 30.0")
    path = write(tmp_path, text)
    cmd = [sys.executable, "-m", "workbench", "sweep", str(path), "--jobs", "2",
           "--results", str(tmp_path / "res"), "--quiet", "--no-report"]
    proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    try:
        deadline = time.time() + 300
        workers = []
        while time.time() < deadline and len(workers) < 2:
            workers = [k for k in _children(proc.pid)
                       if b"loky" in Path(f"/proc/{k}/cmdline").read_bytes()
                       or b"joblib" in Path(f"/proc/{k}/cmdline").read_bytes()]
            time.sleep(0.2)
        assert workers, "the sweep started no worker processes"
        time.sleep(2.0)                                   # the workers are computing
        os.kill(proc.pid, signal.SIGKILL)                 # the sweep only, not its group
        proc.wait()
        deadline = time.time() + 10 * WATCHDOG_S + 5
        while time.time() < deadline and any(_alive(w) for w in workers):
            time.sleep(0.2)
        assert not any(_alive(w) for w in workers), "workers computed on after the sweep died"
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


def test_the_code_version_covers_the_kernels_and_the_model_not_the_presentation():
    """A sweep reuses a point only if the code that computes it is unchanged."""
    from workbench.study.provenance import computing_sources

    names = {p.relative_to(p.parents[1]).as_posix() for p in computing_sources()}
    for computing in ("core/hybrid.py", "core/config.py", "model/simulate.py", "model/params.py",
                      "study/sweep.py", "study/metrics.py"):
        assert computing in names
    for presenting in ("present/figures.py", "lab/files.py", "cli.py"):
        assert presenting not in names


def test_a_run_left_running_by_a_dead_process_is_marked_interrupted(tmp_path):
    """runs.json of a sweep killed by SIGKILL says "running"; the next sweep (which holds
    the study's lock, so no sweep of it is alive) marks that entry interrupted."""
    from workbench.study.store import StudyLock, log_run, read_runs
    (tmp_path / "runs.json").write_text('[{"started": "then", "state": "running", "pid": 1},'
                                        ' {"started": "before", "state": "done"}]')
    with StudyLock(tmp_path):
        index = log_run(tmp_path, {"started": "now", "state": "running"})
    runs = read_runs(tmp_path)
    assert index == 2 and [r["state"] for r in runs] == ["interrupted", "done", "running"]


def test_a_relative_results_folder_is_the_callers_whatever_the_workers_cwd(tmp_path, monkeypatch):
    """joblib keeps its worker processes between sweeps, with the working directory they
    started in: a relative --results must still mean the caller's folder."""
    text = SMALL.replace("freq_hz = [20.0, 30.0]", "freq_hz = [20.0]").replace(
        "save_series = [{gap_mm = 1.016, freq_hz = 20.0}]", "")
    for folder in ("first", "second"):
        (tmp_path / folder).mkdir()
        monkeypatch.chdir(tmp_path / folder)
        table = W.sweep(write(tmp_path, text), "res", jobs=2, progress=False)
        assert table.status.tolist() == ["ok", "ok"]
        assert len(list((tmp_path / folder / "res" / "small" / "points").glob("*.parquet"))) == 2


def test_a_checked_study_keeps_each_points_measured_error_and_reports_it(tmp_path):
    text = SMALL.replace('name = "small"', 'name = "checked"\ncheck_accuracy = true').replace(
        "gap_mm = [0.508, 1.016]", "gap_mm = [1.016]").replace("save_series = [{gap_mm = 1.016, freq_hz = 20.0}]\n", "")
    study = S.load(write(tmp_path, text))
    assert study.check_accuracy
    table = W.run_study(study, tmp_path / "res", jobs=1, progress=False)
    assert (table.status == "ok").all() and table.error_measured.notna().all()
    assert (table.error_measured == table[["tip_error_measured", "share_error_measured"]].max(axis=1)).all()
    from workbench.present.report import accuracy_lines
    text = "\n".join(accuracy_lines(study, table))
    assert f"largest error (the tip's of its range, or a contact share's) is " \
           f"{table.error_measured.max():.2g}" in text and "every one is within 0.001" in text
    over = table.assign(error_measured=[2e-3, 1e-6])
    assert "1 exceed 0.001" in "\n".join(accuracy_lines(study, over))
    plain = "\n".join(accuracy_lines(study, table.drop(columns=["error_measured"])))
    assert "No point was checked against a companion run" in plain
