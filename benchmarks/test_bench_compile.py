"""A fresh process: ``workbench run`` of the 10 s case, with and without numba's cache.

Each round starts a new process running the command a user types,

    workbench run --gap-mm 1.016 --tip-mass on --cork cubic --freq-hz 20 --duration 10 --json

(the 10 s sine at the default force), and the benchmark times the whole
process: imports, the static start, the run and the output.  "cold": the
kernels' cache folder (WORKBENCH_CACHE_ROOT) is emptied first, so numba
compiles everything; "warm": the same folder again, so the kernels are
loaded from it.  The run's own wall time (``wall_s`` of the JSON) is
recorded beside it, with the kernels' ``compile_s`` (compiling, or loading
from the cache), the number of compiled versions in the cache (one per
kernel: a second version of a kernel is a regression) and the cache's size.

The processes write Python's bytecode cache as on a user's machine: an
inherited ``PYTHONDONTWRITEBYTECODE`` (set in some shells and containers) is
dropped, since with it every process compiles the package's sources again
(about 0.08 s).
"""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from workbench.core.compiler.cache import index_entries

ROOT = Path(__file__).resolve().parents[1]
COMMAND = ["-m", "workbench", "run", "--gap-mm", "1.016", "--tip-mass", "on", "--cork", "cubic",
           "--freq-hz", "20", "--duration", "10", "--json"]
ROUNDS = {"cold": 1, "warm": 5}


def _fresh_process(cache_root):
    env = dict(os.environ, WORKBENCH_CACHE_ROOT=str(cache_root))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    out = subprocess.run([sys.executable, *COMMAND], env=env, cwd=ROOT, check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout)


@pytest.fixture(scope="module")
def cache_root(tmp_path_factory):
    return tmp_path_factory.mktemp("numba-cache")


@pytest.mark.parametrize("cache", list(ROUNDS))
def test_workbench_run_in_a_fresh_process(benchmark, cache_root, cache):
    if cache == "warm":
        _fresh_process(cache_root)                     # make sure the cache is filled
    result = {}

    def once():
        if cache == "cold":
            for entry in cache_root.iterdir():
                subprocess.run(["rm", "-rf", str(entry)], check=True)
        result.update(_fresh_process(cache_root))

    benchmark.pedantic(once, rounds=ROUNDS[cache], iterations=1)
    entries = {}
    for folder in cache_root.glob("numba-*"):
        entries.update(index_entries(folder))
    size = sum(p.stat().st_size for p in cache_root.rglob("*") if p.is_file())
    benchmark.extra_info.update({"command": "workbench " + " ".join(COMMAND[2:]),
                                 "run_wall_s": result["wall_s"], "status": result["status"],
                                 "n_events": result["n_events"],
                                 "compile_or_load_s": result["compile_s"],
                                 "cache_kernels": len(entries),
                                 "cache_versions": sum(entries.values()),
                                 "cache_bytes": size})
    assert result["status"] == "ok"
