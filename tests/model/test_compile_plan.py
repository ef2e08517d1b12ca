"""The parallel compile (workbench/model/compile_plan.py)."""
import json
import os
import subprocess
import sys
import textwrap

import pytest

from workbench.model import compile_plan
from workbench.model.params import ParameterError

from workbench.core import compiler

pytestmark = pytest.mark.skipif(not compiler.active(), reason="the compiler's workarounds are off")

TOY = {"a": {"signature": [], "links": ["b", "c"], "seconds": 1.0},
       "b": {"signature": [], "links": ["d"], "seconds": 2.0},
       "c": {"signature": [], "links": [], "seconds": 5.0},
       "d": {"signature": [], "links": [], "seconds": 0.5},
       "e": {"signature": [], "links": [], "seconds": 9.0}}


def test_the_closure_and_the_chains_of_callers_above_each_kernel():
    assert set(compile_plan.closure(TOY, ["b", "unknown"])) == {"b", "d"}
    assert set(compile_plan.closure(TOY, ["a"])) == {"a", "b", "c", "d"}
    # d -> b -> a: 0.5 + 2 + 1; c -> a: 5 + 1; e alone
    assert compile_plan.chain_seconds(TOY) == {"a": 1.0, "b": 3.0, "c": 6.0, "d": 3.5, "e": 9.0}
    # within a closure, only the callers in it count
    assert compile_plan.chain_seconds(compile_plan.closure(TOY, ["b"])) == {"b": 2.0, "d": 2.5}


#: In a fresh process with an empty cache: two workers compile _accumulating and
#: fill_geometry (which it links); then what the cache holds and a second call.
CASE = textwrap.dedent("""
    import json
    from workbench.model import compile_plan
    roots = ["hybrid._accumulating"]
    plan = compile_plan.closure(compile_plan.load_plan(), roots)
    before = compile_plan.missing(plan)
    errors = compile_plan.compile_parallel(roots, 2)
    again = compile_plan.compile_parallel(roots, 2)
    print(json.dumps({"plan": sorted(plan), "before": sorted(before), "errors": errors,
                      "after": compile_plan.missing(plan), "again": again}))
""")


def test_two_workers_compile_a_kernel_and_its_callee_into_the_cache(tmp_path):
    out = subprocess.run([sys.executable, "-c", CASE], check=True, capture_output=True, text=True,
                         env={**os.environ, "WORKBENCH_CACHE_ROOT": str(tmp_path)})
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert result["plan"] == ["contact.fill_geometry", "hybrid._accumulating"]
    assert result["before"] == result["plan"]
    assert result["errors"] == [] and result["after"] == []
    assert result["again"] == []
    assert [p.name.split("-")[0] for p in sorted(tmp_path.glob("numba-*/*.nbi"))] == \
        ["contact.fill_geometry", "hybrid._accumulating"]


def test_a_kernel_that_fails_to_compile_is_reported_and_the_rest_still_compile(tmp_path):
    plan = {"contact.fill_geometry": {"signature": ["float64"], "links": [], "seconds": 1.0},
            "contact.eval_geometry": {"signature": ["float64"], "links": ["contact.fill_geometry"],
                                      "seconds": 1.0}}
    errors = compile_plan.work(plan, tmp_path)
    assert [e.split(":")[0] for e in errors] == ["contact.fill_geometry", "contact.eval_geometry"]
    assert sorted(p.name for p in tmp_path.glob("*.done")) == \
        ["contact.eval_geometry.done", "contact.fill_geometry.done"]


def test_the_number_of_processes_from_the_environment(monkeypatch):
    monkeypatch.setenv(compile_plan.JOBS_VARIABLE, "0")
    assert compile_plan.jobs_from_environment() == 0
    monkeypatch.delenv(compile_plan.JOBS_VARIABLE)
    assert compile_plan.jobs_from_environment() == len(os.sched_getaffinity(0))
    monkeypatch.setenv(compile_plan.JOBS_VARIABLE, "two")
    with pytest.raises(ParameterError, match="WORKBENCH_COMPILE_JOBS='two': expects a whole number"):
        compile_plan.jobs_from_environment()


def test_the_first_use_clock_counts_a_callers_compile_once():
    """WORKBENCH_COMPILE_JOBS=0: a run's compile_s adds the kernels compiled on first
    use before its event loop (kernel_loading.FirstUseClock); a callee compiled inside its
    caller's compile is not counted again."""
    import time

    import numba

    from workbench.model.kernel_loading import FirstUseClock

    @numba.njit
    def callee(x):
        return x + 1.0

    @numba.njit
    def caller(x):
        return callee(x) * 2.0

    clock = FirstUseClock().register()
    try:
        start = time.perf_counter()
        assert caller(1.0) == 4.0                   # compiles both, the callee inside
        wall = time.perf_counter() - start
        counted = clock.take()
        assert 0.0 < counted <= wall
        assert clock.take() == 0.0                  # taken
        caller(2.0)                                 # compiled already: nothing counted
        assert clock.take() == 0.0
    finally:
        clock.unregister()
