"""Benchmarks of the sweep runner; never part of pass/fail.

* scaling: the default study's grid (studies/shaker.toml: 240 points, 4 gaps
  x 10 frequencies x tip mass on/off x 3 cork models) with 1 and 2 worker
  processes, side by side in one run; each point simulates 2 s instead of
  10 s so that the pair takes minutes, not most of an hour.  The speed-up
  is the ratio of the two wall times;
* the whole default study (10 s per point) only when WORKBENCH_BENCH_FULL=1;
  ``make study`` records the same wall time in results/shaker/runs.json.
"""
import dataclasses
import os
import shutil
from pathlib import Path

import pytest

from workbench.study import definition as S
from workbench.study.sweep import run_study

ROOT = Path(__file__).resolve().parents[1]
SCALING_DURATION_S = 2.0


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


@pytest.mark.skipif(os.environ.get("WORKBENCH_BENCH_FULL") != "1",
                    reason="the whole default study: set WORKBENCH_BENCH_FULL=1")
def test_default_study(benchmark, tmp_path):
    study = S.load(ROOT / "studies" / "shaker.toml")
    table = benchmark.pedantic(_fresh_run, args=(study, tmp_path / "res", 2), rounds=1,
                               iterations=1)
    benchmark.extra_info.update({"points": len(table), "cpu_s": float(table.wall_s.sum())})
