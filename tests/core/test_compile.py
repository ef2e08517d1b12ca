"""Each kernel compiles once: one version per function (workbench/core/config.py).

A literal argument or an omitted default makes numba compile a kernel a
second time, for that literal; that doubles the compile and the cache.
"""
import json
import subprocess
import sys
import textwrap

from workbench.core import _cache

#: A standard workload: controlled runs with impacts and stick-slip (tip on
#: and off), a fixed-step run, the static start, the signals.
WORKLOAD = textwrap.dedent("""
    import json
    from workbench.core._cache import kernel_versions
    from workbench.model.excitation import sine
    from workbench.model.params import Parameters
    from workbench.model.simulate import simulate
    for tip in (True, False):
        simulate(Parameters(tip_mass=tip), sine(200.0, 55.0, 0.1), duration=0.3)
    simulate(Parameters(), sine(200.0, 20.0), duration=0.05, method="rk4")
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
