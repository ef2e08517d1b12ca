"""Inlining this package's helpers at less cost (workbench/core/compiler/inlining.py).

numba's untyped pipeline runs once per helper, not once per call site; the
kept IR is never changed by an inlining; and a caller computes what it
computes with numba's own inliner, and what the helper's Python computes.
"""
import copy

import numba
import numpy as np
import pytest
from numba.core import inline_closurecall

from workbench.core import layout as ly
from workbench.core.compiler import inlining as _inlining
from workbench.core.constrained import kinetic_energy
from workbench.core.hybrid import _hermite_min

from workbench.core import compiler

pytestmark = pytest.mark.skipif(not compiler.active(), reason="the compiler's workarounds are off")


def _callers():
    """Fresh jit functions (no cache) inlining two helpers, one of them at two sites."""
    def two_sites(f0, f1, m0, m1):
        x0, v0 = _hermite_min(f0, f1, m0, m1)
        x1, v1 = _hermite_min(f1, f0, -m1, -m0)
        return x0 + 2.0 * v0 + 3.0 * x1 + 4.0 * v1

    def one_site(f0, f1, m0, m1, qd, mat):
        x, v = _hermite_min(f0, f1, m0, m1)
        return x * v + kinetic_energy(qd, mat)
    return numba.njit(two_sites), numba.njit(one_site)


CASES = [(1.0, 2.0, -3.0, 1.5), (0.5, 0.2, -0.1, 0.4), (2.0, -1.0, 0.3, -0.2), (1.0, 1.0, 0.0, 0.0)]


def _mat():
    rng = np.random.default_rng(7)
    a = rng.standard_normal((9, 9))
    mat = np.zeros((ly.MAT_M + 1, 9, 9))
    mat[ly.MAT_M] = a @ a.T + 9.0 * np.eye(9)
    return rng.standard_normal(9), mat


def test_each_helper_runs_numbas_untyped_pipeline_once_and_its_kept_ir_stays_unchanged(monkeypatch):
    monkeypatch.setattr(_inlining, "_UNTYPED", {})
    ran = []
    numba_pipeline = inline_closurecall.InlineWorker.run_untyped_passes

    def counted(self, func, enable_ssa=False):
        ran.append(func.__name__)
        return numba_pipeline(self, func, enable_ssa)
    monkeypatch.setattr(inline_closurecall.InlineWorker, "run_untyped_passes", counted)

    two_sites, one_site = _callers()
    two_sites(*CASES[0])
    kept = {key[0].__name__: ir for key, ir in _inlining._UNTYPED.items()}
    before = {name: copy.deepcopy(ir.blocks) for name, ir in kept.items()}
    qd, mat = _mat()
    one_site(*CASES[0], qd, mat)
    # _hermite_min inlined at three sites, kinetic_energy at one: the pipeline once each
    assert sorted(ran) == ["_hermite_min", "kinetic_energy"]
    assert kept["_hermite_min"] is next(ir for key, ir in _inlining._UNTYPED.items()
                                        if key[0].__name__ == "_hermite_min")
    for name, blocks in before.items():
        assert kept[name].blocks == blocks, name


def test_a_caller_computes_what_numbas_own_inliner_and_the_python_compute():
    qd, mat = _mat()
    ours = _callers()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(inline_closurecall.InlineWorker, "inline_function",
                   _inlining._numba_inline_function)
        mp.setattr(inline_closurecall, "copy", copy)
        numbas = _callers()
        expected = [(numbas[0](*c), numbas[1](*c, qd, mat)) for c in CASES]
    python = []                     # the helpers' Python, called as the callers call them
    for c in CASES:
        x0, v0 = _hermite_min.py_func(*c)
        x1, v1 = _hermite_min.py_func(c[1], c[0], -c[3], -c[2])
        python.append((x0 + 2.0 * v0 + 3.0 * x1 + 4.0 * v1,
                       x0 * v0 + kinetic_energy.py_func(qd, mat)))
    got = [(ours[0](*c), ours[1](*c, qd, mat)) for c in CASES]
    assert got == expected
    np.testing.assert_allclose(got, python, rtol=1e-15, atol=0.0)
