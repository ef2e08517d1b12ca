"""The kernels' contract (README "Reading map"), checked on their source.

``workbench/core`` holds numba kernels only: it imports numba, numpy and the
standard library, never pandas, matplotlib, joblib or the rest of the
package; every jit decorator takes its options from ``core/config.py``
(``JIT``, ``JIT_INLINE``, ``JIT_ALLOC`` for the two kernels that allocate,
``JIT_PARALLEL``: ``cache=True`` and the error model in one place); the arrays come in one
order everywhere: the model's (the group ``model`` or its fields), the drive ``ex``, the
work's (the group ``work`` or the fields of :class:`workbench.model.packing.Work`), so a
swapped pair (all are 2-D float arrays) cannot compile silently; and no kernel takes more
than MAX_ARGUMENTS positional arguments (the arrays travel in named groups).
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

from workbench.core import config
from workbench.model.packing import Model, Work

CORE = Path(__file__).resolve().parents[2] / "workbench" / "core"
SOURCES = sorted(CORE.glob("*.py"))
#: What a kernel module may import (the cache and linking modules reach into
#: numba's caching and code generation, and numba's LLVM binding, llvmlite).
ALLOWED_IMPORTS = {"numba", "numpy", "math", "__future__", "hashlib", "os", "shutil", "pathlib",
                   "time", "pickle", "importlib", "sys", "llvmlite", "copy"}
#: Calls that allocate an array: only kernels compiled with JIT_ALLOC (reference
#: counts on) may make them; the others have none (config.JIT).
ALLOCATING = {"np.zeros", "np.empty", "np.ones", "np.full", "np.array", "np.copy",
              "np.concatenate", "np.zeros_like", "np.empty_like"}
#: The one order of the arrays a kernel takes: the model's, the drive, the work's.
ARGUMENT_ORDER = ["model", *Model._fields, "ex", "work", *Work._fields]
#: The most positional arguments a kernel takes.
MAX_ARGUMENTS = 12


def _tree(path):
    return ast.parse(path.read_text(), filename=str(path))


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: p.name)
def test_core_imports_only_numba_numpy_and_the_standard_library(path):
    for node in ast.walk(_tree(path)):
        if isinstance(node, ast.Import):
            roots = {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            if node.level == 1:            # from . import / from .x import: core itself
                continue
            assert node.level == 0, f"{path.name}:{node.lineno} imports from outside core"
            roots = {node.module.split(".")[0]}
        else:
            continue
        assert roots <= ALLOWED_IMPORTS, f"{path.name}:{node.lineno} imports {roots - ALLOWED_IMPORTS}"


def _jit_decorators(tree):
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef):
            for dec in node.decorator_list:
                target = dec.func if isinstance(dec, ast.Call) else dec
                name = ast.unparse(target)
                if name.split(".")[-1] in ("njit", "jit", "vectorize", "guvectorize", "cfunc"):
                    yield node, dec


def test_every_jit_decorator_takes_the_config_options():
    seen = 0
    for path in SOURCES:
        for fn, dec in _jit_decorators(_tree(path)):
            seen += 1
            where = f"{path.name}:{fn.name}"
            assert isinstance(dec, ast.Call) and not dec.args, where
            assert len(dec.keywords) == 1 and dec.keywords[0].arg is None, where   # **options only
            options = ast.unparse(dec.keywords[0].value)
            assert options in ("JIT", "JIT_INLINE", "JIT_ALLOC", "JIT_PARALLEL"), where
            allocates = any(isinstance(n, ast.Call) and ast.unparse(n.func) in ALLOCATING
                            for n in ast.walk(fn))
            assert allocates == (options == "JIT_ALLOC"), f"{where}: allocates {allocates}, {options}"
    assert seen > 50                                   # the kernels were found
    assert config.JIT["cache"] is True and config.JIT_INLINE["cache"] is True
    assert config.JIT["_nrt"] is False and config.JIT_ALLOC["_nrt"] is True


def test_the_kernels_take_their_arrays_in_one_order():
    checked = 0
    for path in SOURCES:
        for node in ast.walk(_tree(path)):
            if not isinstance(node, ast.FunctionDef):
                continue
            names = [a.arg for a in node.args.args if a.arg in ARGUMENT_ORDER]
            if len(names) < 2:
                continue
            checked += 1
            positions = [ARGUMENT_ORDER.index(a) for a in names]
            assert positions == sorted(positions), (f"{path.name}:{node.name} takes {names}; "
                                                    f"the order is {ARGUMENT_ORDER}")
    assert checked > 30


def test_no_kernel_takes_more_than_a_dozen_arguments():
    wide = [f"{path.name}:{node.name} ({len(node.args.args)})" for path in SOURCES
            for node in ast.walk(_tree(path))
            if isinstance(node, ast.FunctionDef) and len(node.args.args) > MAX_ARGUMENTS
            and any("jit" in ast.unparse(d) for d in node.decorator_list)]
    assert not wide, wide
