"""Each kernel's machine code once (workbench/core/compiler/linking.py).

A caller links its callees ``available_externally`` (LLVM sees their bodies
but emits no copy) and calls their own code; a cached caller loads its
callees first, and is compiled afresh when a callee's code under the name it
calls is missing.  Each step runs in a fresh process on one cache root.
"""
import json
import os
import subprocess
import sys
import textwrap

import numpy as np

from workbench.core import layout as ly
from workbench.core.contact import eval_geometry
from workbench.model import packing
from workbench.model.params import Parameters

import pytest
from workbench.core import compiler

pytestmark = pytest.mark.skipif(not compiler.active(), reason="the compiler's workarounds are off")

#: eval_geometry (a kernel) calls fill_geometry (a kernel) in a fresh process;
#: prints the gaps, how the caller's module holds the callee, and which
#: kernels this process compiled or loaded.
STEP = textwrap.dedent("""
    import json
    import numpy as np
    from workbench.core import layout as ly
    from workbench.core.compiler import cache as _cache, linking as _linking
    from workbench.core.contact import eval_geometry, fill_geometry
    from workbench.model import packing
    from workbench.model.params import Parameters
    q = np.zeros(ly.N_DOF); q[ly.PSI] = 0.003; q[ly.V] = 0.004
    cg = np.zeros((8, ly.N_CG))
    eval_geometry(q, packing.pack(Parameters()), cg)
    (cres,) = eval_geometry.overloads.values()
    linkage = sorted({"declaration" if fn.is_declaration else fn.linkage.name
                      for fn in cres.library._final_module.functions if "fill_geometry" in fn.name})
    print(json.dumps({"gaps": cg[:4, ly.CG_VAL].tolist(), "linkage": linkage,
                      "versions": _cache.kernel_versions(), "loaded": len(_linking._LOADED)}))
""")


def _step(root):
    out = subprocess.run([sys.executable, "-c", STEP], check=True, capture_output=True, text=True,
                         env={**os.environ, "WORKBENCH_CACHE_ROOT": str(root)})
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_caller_links_its_callee_without_a_copy_and_loads_it_first(tmp_path):
    q = np.zeros(ly.N_DOF)
    q[ly.PSI], q[ly.V] = 0.003, 0.004
    cg = np.zeros((8, ly.N_CG))
    eval_geometry(q, packing.pack(Parameters()), cg)
    expected = cg[:4, ly.CG_VAL].tolist()

    compiled = _step(tmp_path)
    assert compiled["gaps"] == expected
    # compiled here: the callee's body was in the caller's module for LLVM, and is
    # left a declaration (numba alone links a linkonce_odr copy and emits it)
    assert compiled["linkage"] == ["declaration"]

    loaded = _step(tmp_path)
    assert loaded["gaps"] == expected
    assert loaded["linkage"] == []            # loaded: machine code only
    # the cached caller brought its callee in before its own code
    assert {"contact.eval_geometry", "contact.fill_geometry"} <= set(loaded["versions"])
    assert loaded["loaded"] >= 2

    # the callee's cache entry gone: it compiles under a new name (numba numbers
    # functions in the order a process meets them), and the caller that calls the
    # old name is compiled afresh instead of failing to load
    (cache_dir,) = tmp_path.glob("numba-*")
    for entry in cache_dir.glob("contact.fill_geometry-*"):
        entry.unlink()
    again = _step(tmp_path)
    assert again["gaps"] == expected
    assert again["linkage"] == ["declaration"]


#: A user's cached jit function that calls a kernel, in a module of its own.
USER_MODULE = textwrap.dedent("""
    import numba
    from workbench.core.contact import eval_geometry

    @numba.njit(cache=True)
    def gaps(q, P, cg):
        eval_geometry(q, P, cg)
        return cg[0, 0] + cg[1, 0]
""")

USER_STEP = textwrap.dedent("""
    import json
    import numpy as np
    from workbench.core import layout as ly
    from workbench.model import packing
    from workbench.model.params import Parameters
    import user_kernels
    q = np.zeros(ly.N_DOF); q[ly.PSI] = 0.003; q[ly.V] = 0.004
    print(json.dumps(user_kernels.gaps(q, packing.pack(Parameters()), np.zeros((8, ly.N_CG)))))
""")


def test_a_users_cached_function_that_calls_a_kernel_loads_in_a_fresh_process(tmp_path):
    (tmp_path / "user_kernels.py").write_text(USER_MODULE)
    env = {**os.environ, "WORKBENCH_CACHE_ROOT": str(tmp_path / "cache"),
           "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])}
    q = np.zeros(ly.N_DOF)
    q[ly.PSI], q[ly.V] = 0.003, 0.004
    cg = np.zeros((8, ly.N_CG))
    eval_geometry(q, packing.pack(Parameters()), cg)
    runs = [subprocess.run([sys.executable, "-c", USER_STEP], capture_output=True, text=True,
                           env=env, cwd=tmp_path) for _ in range(2)]
    assert [r.returncode for r in runs] == [0, 0], runs[-1].stderr[-2000:]
    assert list((tmp_path / "__pycache__").glob("user_kernels.gaps-*.nbi"))      # cached, then loaded
    assert [json.loads(r.stdout) for r in runs] == [cg[0, ly.CG_VAL] + cg[1, ly.CG_VAL]] * 2
