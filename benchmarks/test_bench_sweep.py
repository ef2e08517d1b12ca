"""Benchmarks of the sweep runner (issue 4); never part of pass/fail.

* scaling: the same 8-point grid (a corner of the default study, 2 s per
  point) with 1 and 2 worker processes, fresh each round; the speed-up is
  the ratio of the two medians of one run;
* the whole default study (studies/shaker.toml, 240 points x 10 s) only
  when WORKBENCH_BENCH_FULL=1 (about half an hour on 2 cores today);
  ``make study`` records the same wall time in results/shaker/runs.json.
"""
import os
import shutil
from pathlib import Path

import pytest

from workbench import study as S
from workbench.sweep import run_study

ROOT = Path(__file__).resolve().parents[1]
CORNER = """
[study]
name = "corner"
duration_s = 2.0
window_s = 0.5

[excitation]
kind = "sine"
force_n = 20.0
ramp_s = 0.5

[fixed]
cork = "cubic"

[axes]
gap_mm = [0.508, 1.016]
freq_hz = [20.0, 40.0]
tip_mass = [true, false]
"""


def _fresh_run(study, results, jobs):
    shutil.rmtree(results, ignore_errors=True)
    return run_study(study, results, jobs=jobs, progress=False)


@pytest.mark.parametrize("jobs", [1, 2])
def test_sweep_scaling(benchmark, tmp_path, jobs):
    path = tmp_path / "corner.toml"
    path.write_text(CORNER)
    study = S.load(path)
    _fresh_run(study, tmp_path / "warm", jobs)                 # compile / load caches in workers
    table = benchmark.pedantic(_fresh_run, args=(study, tmp_path / "res", jobs),
                               rounds=3, iterations=1)
    benchmark.extra_info.update({"points": len(table), "jobs": jobs,
                                 "cpu_s": float(table.wall_s.sum())})
    assert (table.status == "ok").all()


@pytest.mark.skipif(os.environ.get("WORKBENCH_BENCH_FULL") != "1",
                    reason="the whole default study: set WORKBENCH_BENCH_FULL=1")
def test_default_study(benchmark, tmp_path):
    study = S.load(ROOT / "studies" / "shaker.toml")
    table = benchmark.pedantic(_fresh_run, args=(study, tmp_path / "res", 2), rounds=1,
                               iterations=1)
    benchmark.extra_info.update({"points": len(table), "cpu_s": float(table.wall_s.sum())})
