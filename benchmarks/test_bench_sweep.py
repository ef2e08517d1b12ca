"""Benchmarks of the sweep runner; never part of pass/fail.

* scaling: the default study's grid (studies/shaker.toml: 240 points, 4 gaps
  x 10 frequencies x tip mass on/off x 3 cork models) with 1 and 2 worker
  processes, side by side in one run; each point simulates 1 s instead of
  10 s so that the pair takes minutes.  The speed-up
  is the ratio of the two wall times;
* the sensitivity study's design (studies/sensitivity.toml) cut to n = 4
  base samples (52 runs of 3 s) on 1 and 2 joblib workers and on a Dask
  LocalCluster of 2 worker processes, side by side in one run;
* ``make study`` whole, warm cache, into an empty results folder: every
  study of the Makefile's STUDIES, the modes, the identification tables
  and the estimator, figures and reports included.
"""
import dataclasses
import os
import re
import shutil
import subprocess
from pathlib import Path

import pandas as pd
import pytest

from workbench.study import definition as S
from workbench.study.sweep import run_study

ROOT = Path(__file__).resolve().parents[1]
SCALING_DURATION_S = 1.0
#: The sweep studies of ``make study``: the Makefile's STUDIES.
STUDIES = re.search(r"^STUDIES := (.+)$", (ROOT / "Makefile").read_text(), re.M).group(1).split()


def _fresh_run(study, results, jobs):
    shutil.rmtree(results, ignore_errors=True)
    return run_study(study, results, jobs=jobs, progress=False)


@pytest.fixture(scope="module")
def default_grid(tmp_path_factory):
    study = S.load(ROOT / "studies" / "shaker.toml")
    short = dataclasses.replace(study, duration_s=SCALING_DURATION_S, window_s=0.5,
                                save_series=())
    warm = dataclasses.replace(short, points=short.points[:2], duration_s=0.1, window_s=0.05)
    _fresh_run(warm, tmp_path_factory.mktemp("warm"), 2)      # compile / load caches
    return short


@pytest.mark.parametrize("jobs", [1, 2])
def test_sweep_scaling(benchmark, tmp_path, default_grid, jobs):
    table = benchmark.pedantic(_fresh_run, args=(default_grid, tmp_path / "res", jobs),
                               rounds=1, iterations=1)
    benchmark.extra_info.update({"points": len(table), "jobs": jobs,
                                 "duration_s": SCALING_DURATION_S,
                                 "cpu_s": float(table.wall_s.sum()),
                                 "failed": int((table.status != "ok").sum())})
    assert len(table) == len(default_grid.points)


#: The sensitivity design's base samples for the scaling runs.
SENSITIVITY_N = 4


@pytest.fixture(scope="module")
def small_design(tmp_path_factory):
    from workbench.study.sensitivity import parse
    import tomllib
    path = ROOT / "studies" / "sensitivity.toml"
    data = tomllib.loads(path.read_text())
    data["sample"]["n"] = SENSITIVITY_N
    study = S.from_dict(data, source=str(path))
    assert study.sample == parse(data["sample"], data["ranges"])
    warm = dataclasses.replace(study, points=study.points[:2], duration_s=0.1, window_s=0.05)
    _fresh_run(warm, tmp_path_factory.mktemp("warm"), 2)
    return study


def _on_cluster(study, results, workers):
    import distributed
    shutil.rmtree(results, ignore_errors=True)
    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, host="127.0.0.1",
                                  dashboard_address=None, processes=True) as cluster:
        return run_study(study, results, scheduler=cluster.scheduler_address, progress=False)


@pytest.mark.parametrize("runner, workers", [("joblib", 1), ("joblib", 2), ("dask", 2)])
def test_sensitivity_scaling(benchmark, tmp_path, small_design, runner, workers):
    run = _fresh_run if runner == "joblib" else _on_cluster
    table = benchmark.pedantic(run, args=(small_design, tmp_path / "res", workers), rounds=1,
                               iterations=1)
    benchmark.extra_info.update({"points": len(table), "runner": runner, "workers": workers,
                                 "cpu_s": float(table.wall_s.sum()),
                                 "failed": int((table.status != "ok").sum())})
    assert len(table) == small_design.n_points


def _make_study(results):
    shutil.rmtree(results, ignore_errors=True)
    env = {k: v for k, v in os.environ.items() if not k.startswith("MAKE")}
    subprocess.run(["make", "-s", "study", f"RESULTS={results}"], cwd=ROOT, env=env, check=True,
                   stdout=subprocess.DEVNULL)


def study_counts(results: Path) -> dict:
    """The grid points of ``make study``'s sweeps in ``results``, those failed and their walls
    (s); a study that traces a branch (period_doubling) writes no point table."""
    tables = [pd.read_parquet(results / name / "points.parquet") for name in STUDIES
              if (results / name / "points.parquet").exists()]
    return {"points": int(sum(len(t) for t in tables)),
            "failed": int(sum((t.status != "ok").sum() for t in tables)),
            "cpu_s": float(sum(t.wall_s.sum() for t in tables))}


def test_make_study(benchmark, tmp_path):
    """``make study`` whole (every study, figure and table) into an empty folder."""
    results = tmp_path / "results"
    benchmark.pedantic(_make_study, args=(results,), rounds=1, iterations=1)
    benchmark.extra_info.update(study_counts(results))
    assert all((results / name / "report.md").exists() for name in STUDIES)
    assert (results / "index.md").exists()
