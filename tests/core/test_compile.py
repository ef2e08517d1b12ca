"""Each kernel compiles once: one version per function (workbench/core/config.py).

A literal argument or an omitted default makes numba compile a kernel a
second time, for that literal; that doubles the compile and the cache.
"""
import functools
import json
import subprocess
import sys
import textwrap

from workbench.core.compiler import cache as _cache
from workbench.model import compile_plan
from workbench.model.warmup import GROUPS

import pytest
from workbench.core import compiler

pytestmark = pytest.mark.skipif(not compiler.active(), reason="the compiler's workarounds are off")

#: A standard workload: the entry points `workbench compile` compiles (the
#: event loop, both methods; the static start, modes, free flight, hammer),
#: then the kernels' versions in that process.
WORKLOAD = "\n".join(textwrap.dedent(code) for code in GROUPS.values()) + textwrap.dedent("""
    import json
    from workbench.core.compiler.cache import kernel_versions
    from workbench.core.compiler.linking import kernel_graph
    print(json.dumps({"versions": kernel_versions(), "graph": kernel_graph()}))
""")


@functools.lru_cache(maxsize=1)
def _standard_run():
    out = subprocess.run([sys.executable, "-c", WORKLOAD], check=True, capture_output=True,
                         text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_standard_run_compiles_each_kernel_once():
    versions = _standard_run()["versions"]
    # compiled or loaded from the cache (with the kernels it links), every kernel
    assert {"adaptive.run_adaptive", "hybrid.run_hybrid", "dynamics.rhs"} <= set(versions)
    assert {k: n for k, n in versions.items() if n > 1} == {}


def test_the_cache_holds_one_version_per_kernel():
    test_a_standard_run_compiles_each_kernel_once()          # the cache filled
    entries = _cache.index_entries()
    assert len(entries) > 30
    assert {k: n for k, n in entries.items() if n > 1} == {}


def test_the_compile_plan_lists_the_kernels_of_a_standard_run():
    """workbench/model/compile_plan.json: rewrite it with
    ``python -m workbench.model.compile_plan --write`` when this fails."""
    graph = _standard_run()["graph"]
    plan = compile_plan.load_plan()
    stale = sorted(set(plan) ^ set(graph)) + sorted(
        name for name in set(plan) & set(graph)
        if (plan[name]["signature"], plan[name]["links"])
        != (graph[name]["signature"], graph[name]["links"]))
    assert not stale, (f"the compile plan no longer matches the kernels ({', '.join(stale[:5])}"
                       f"{' ...' if len(stale) > 5 else ''}): run `python -m "
                       "workbench.model.compile_plan --write`")
    assert all(entry["seconds"] > 0 for entry in plan.values())
