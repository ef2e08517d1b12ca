"""Compilation: the first run in a fresh process, with and without numba's cache.

Each round starts a new Python process that imports the workbench and
simulates the benchmark run (10 s sine, 1.016 mm, 20 Hz, tip mass, cubic
cork).  "cold": the kernels' cache folder (WORKBENCH_CACHE_ROOT) is empty,
so numba compiles everything; "warm": the same folder again, so the
kernels are loaded from it.  The benchmark times the whole process; the
process reports its import time and its first simulate call.
"""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FIRST_RUN = """
import json, time
t0 = time.perf_counter()
from workbench.model.excitation import DEFAULT_FORCE_N, sine
from workbench.model.params import Parameters
from workbench.model.simulate import simulate
t1 = time.perf_counter()
run = simulate(Parameters().replace(gap_mm=1.016, tip_mass=True, cork="cubic"),
               sine(DEFAULT_FORCE_N, 20.0, ramp_s=1.0), 10.0)
t2 = time.perf_counter()
print(json.dumps({"import_s": t1 - t0, "first_run_s": t2 - t1, "ok": run.ok,
                  "run_wall_s": run.wall_s}))
"""


def _fresh_process(cache_root):
    env = dict(os.environ, WORKBENCH_CACHE_ROOT=str(cache_root))
    out = subprocess.run([sys.executable, "-c", FIRST_RUN], env=env, cwd=ROOT, check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def cache_root(tmp_path_factory):
    return tmp_path_factory.mktemp("numba-cache")


@pytest.mark.parametrize("cache", ["cold", "warm"])
def test_first_run_in_a_fresh_process(benchmark, cache_root, cache):
    if cache == "warm":
        _fresh_process(cache_root)                     # make sure the cache is filled
    result = {}

    def once():
        if cache == "cold":
            for entry in cache_root.iterdir():
                subprocess.run(["rm", "-rf", str(entry)], check=True)
        result.update(_fresh_process(cache_root))

    benchmark.pedantic(once, rounds=1 if cache == "cold" else 3, iterations=1)
    benchmark.extra_info.update(result)
    assert result["ok"]
