"""The kernels without the compiler's workarounds (workbench/core/compiler): plain
``numba.njit(cache=True)``, as on a numba release the workarounds were not tested with.
The fast physics checks (the equations of motion, their energy, the inertia's derivatives
by finite differences) run in a fresh process with the switch off, so that the fallback
cannot rot; the kernels compile there on first use into their own cache folder."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_the_physics_checks_pass_on_plain_numba():
    env = {**os.environ, "WORKBENCH_NUMBA_PATCHES": "0"}
    env.pop("PYTEST_XDIST_WORKER", None)
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:randomly",
                           "-p", "no:cacheprovider", "tests/core/test_dynamics.py"],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert "passed" in done.stdout and "failed" not in done.stdout
    assert "workarounds are off (WORKBENCH_NUMBA_PATCHES=0)" in done.stderr


def test_the_switch_and_the_tested_release():
    """The notice, the cache folder of its own and the plan-free compile, in a fresh process."""
    code = ("from workbench.core import compiler; from workbench.core.compiler import cache; "
            "print(compiler.active(), compiler.REASON, cache.CACHE_DIR.name.endswith('-plain'))")
    env = {**os.environ, "WORKBENCH_NUMBA_PATCHES": "0"}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert done.stdout.split() == ["False", "WORKBENCH_NUMBA_PATCHES=0", "True"]
    assert done.stderr.count("\n") == 1 and "plain numba.njit(cache=True)" in done.stderr
    from workbench.core import compiler
    import numba
    assert compiler.active() == (".".join(numba.__version__.split(".")[:2]) == compiler.TESTED_NUMBA)
    pins = (ROOT / "pyproject.toml").read_text()
    assert f'"numba>={compiler.TESTED_NUMBA},' in pins     # the pin is the tested release
