"""Each kernel's machine code once: callers call it instead of carrying a copy.

numba links a callee's LLVM module into every caller's module (its functions
``linkonce_odr``) and optimises and emits it there again: the event loop's
top kernels each carried the machine code of every kernel below them, and
LLVM spent most of its time on these copies (docs/compile.md).  For the functions of :mod:`workbench.core`, this module links a
callee's functions ``available_externally`` instead: LLVM still sees their
bodies (and inlines the small ones as before), but emits no copy; a call that
is not inlined goes to the callee's own machine code, which the process has
loaded already (a callee is finalised before its caller links it).

A cached caller then needs its callees' code in the process before its own
code is loaded.  Its cache entry lists the kernels it links (module,
function, signature) and the symbols it needs; loading the entry first loads
those kernels (from the cache, or compiled), and an entry whose symbols are
still missing (a callee recompiled under a new name) is treated as absent
and compiled afresh.  So does the cache entry of any jit function that calls
the kernels (a user's ``njit(cache=True)`` function, say).
"""
from __future__ import annotations


import importlib
import sys

import llvmlite.binding as ll
import numba as nb
from numba.core import caching, codegen
from numba.core.registry import CPUDispatcher

#: The package of the kernels.
_CORE_PACKAGE = __package__.rsplit(".", 1)[0]

#: Marks the mangled names of this package's functions (and their wrappers).
_MARK = "9workbench4core"
_TAG = "workbench-linked-once"

#: Names of this package's functions whose machine code is loaded in this process.
_LOADED: set[str] = set()

_numba_module_for_linking = codegen.CPUCodeLibrary._get_module_for_linking
_numba_finalize = codegen.CPUCodeLibrary.finalize
_numba_reduce = caching.CompileResultCacheImpl.reduce
_numba_rebuild = caching.CompileResultCacheImpl.rebuild


def _ours(fn) -> bool:
    return _MARK in fn.name


def _module_for_linking(self):
    """numba's module for linking, with this package's functions ``available_externally``."""
    if self._shared_module is not None:
        return self._shared_module
    mod = _numba_module_for_linking(self)
    if any(_ours(fn) and not fn.is_declaration for fn in mod.functions):
        if mod is self._final_module:
            mod = mod.clone()
        for fn in mod.functions:
            if _ours(fn) and not fn.is_declaration and fn.linkage in (
                    ll.Linkage.external, ll.Linkage.linkonce_odr):
                fn.linkage = "available_externally"
        self._shared_module = mod
    return mod


def _own_symbols(module) -> list[str]:
    """This package's functions a finalised module defines itself."""
    return [fn.name for fn in module.functions
            if _ours(fn) and not fn.is_declaration and fn.linkage == ll.Linkage.external]


def _finalize(self):
    _numba_finalize(self)
    _LOADED.update(_own_symbols(self._final_module))


def _is_ours(cache_impl) -> bool:
    from .cache import kernel_locator
    return isinstance(cache_impl._locator, kernel_locator())


def _dispatchers():
    for name, module in list(sys.modules.items()):
        if name.startswith(_CORE_PACKAGE + ".") and module is not None:
            for attr, obj in vars(module).items():
                if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == name:
                    yield name, attr, obj


def linked_kernels(library) -> list[tuple[str, str, tuple]]:
    """The kernels a compiled or cache-loaded library links: (module, name, signature)."""
    if hasattr(library, "_workbench_links"):
        return list(library._workbench_links)
    linked = {id(lib) for lib in library._linking_libraries}
    return [(module, attr, tuple(sig)) for module, attr, disp in _dispatchers()
            for sig, other in disp.overloads.items() if id(other.library) in linked]


def _reduce(self, cres):
    payload = _numba_reduce(self, cres)
    deps = linked_kernels(cres.library)
    if not deps and not _is_ours(self):
        return payload                    # a function that calls none of the kernels
    own = set(_own_symbols(cres.library._final_module))
    needed = sorted({fn.name for fn in cres.library._final_module.functions
                     if _ours(fn) and fn.name not in own})
    return (_TAG, tuple(deps), tuple(needed), tuple(sorted(own)), payload)


def _rebuild(self, target_context, payload):
    if not (isinstance(payload, tuple) and payload and payload[0] == _TAG):
        return _numba_rebuild(self, target_context, payload)
    _tag, deps, needed, own, inner = payload
    for module, attr, sig in deps:
        getattr(importlib.import_module(module), attr).compile(sig)
    if not _LOADED.issuperset(needed):
        return None                       # a callee changed its name: compile this one afresh
    cres = _numba_rebuild(self, target_context, inner)
    cres.library._workbench_links = deps
    _LOADED.update(own)
    return cres


def install() -> None:
    """Link this package's kernels once (see the module's docstring)."""
    codegen.CPUCodeLibrary._get_module_for_linking = _module_for_linking
    codegen.CPUCodeLibrary.finalize = _finalize
    caching.CompileResultCacheImpl.reduce = _reduce
    caching.CompileResultCacheImpl.rebuild = _rebuild


def type_name(t) -> str:
    """A numba type as text that evaluates back to it (numba.types' names, and a named
    tuple's class by its module and name: ``NamedTuple((...), workbench.model.packing.Model)``)."""
    if isinstance(t, nb.types.BaseNamedTuple):
        cls = t.instance_class
        return (f"NamedTuple(({', '.join(type_name(x) for x in t.types)},), "
                f"{cls.__module__}.{cls.__qualname__})")
    return repr(t)


def kernel_graph() -> dict:
    """Every kernel compiled or loaded in this process: {"module.function":
    {"signature": [numba type names], "links": ["module.function", ...]}} (one
    entry per kernel; a second version of a kernel would overwrite the first,
    and tests/core/test_compile.py fails on it)."""
    out = {}
    for module, attr, disp in _dispatchers():
        for sig, cres in disp.overloads.items():
            out[f"{module.rsplit('.', 1)[-1]}.{attr}"] = {
                "signature": [type_name(t) for t in sig],
                "links": sorted({f"{m.rsplit('.', 1)[-1]}.{a}"
                                 for m, a, _s in linked_kernels(cres.library)})}
    return out
