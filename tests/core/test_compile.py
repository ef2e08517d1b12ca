"""Each kernel compiles once: one version per function (workbench/core/config.py).

A literal argument or an omitted default makes numba compile a kernel a
second time, for that literal; that doubles the compile and the cache.
"""
import json
import subprocess
import sys
import textwrap

from workbench.core import _cache
from workbench.model.warmup import GROUPS

#: A standard workload: the entry points `workbench compile` compiles (the
#: event loop, both methods; the static start, modes, free flight, hammer),
#: then the kernels' versions in that process.
WORKLOAD = "\n".join(textwrap.dedent(code) for code in GROUPS.values()) + textwrap.dedent("""
    import json
    from workbench.core._cache import kernel_versions
    print(json.dumps(kernel_versions()))
""")


def test_a_standard_run_compiles_each_kernel_once():
    out = subprocess.run([sys.executable, "-c", WORKLOAD], check=True, capture_output=True,
                         text=True)
    versions = json.loads(out.stdout.strip().splitlines()[-1])
    # loaded from the cache, only the entry points show; compiled, every kernel
    assert {"controlled.run_controlled", "hybrid.run_hybrid"} <= set(versions)
    assert {k: n for k, n in versions.items() if n > 1} == {}


def test_the_cache_holds_one_version_per_kernel():
    test_a_standard_run_compiles_each_kernel_once()          # the cache filled
    entries = _cache.index_entries()
    assert len(entries) > 30
    assert {k: n for k, n in entries.items() if n > 1} == {}
