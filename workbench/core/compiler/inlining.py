"""Inline this package's helpers at numba's IR level at a fraction of numba's cost.

A helper compiled with ``inline="always"`` (:data:`workbench.core.config.JIT_INLINE`)
is inlined at numba's IR level, and numba does two costly things at every
call site:

- it runs its whole untyped pipeline on the helper (bytecode to IR, SSA,
  closure and constant rewrites, and the inlining of the helper's own inlined
  callees, again recursively).  The result depends only on the helper's code
  and two of the caller's flags (SSA, rewrites), so this module builds it once
  per process and keeps it; numba copies the IR it inlines, so the kept one is
  never changed.
- it deep-copies that IR twice, block by block, each block with a copy of
  its own of the helper's scope (every variable of the helper): the cost grows
  as blocks times variables.  Here the blocks of one IR are copied together,
  the scope once, which is the same IR numba would build (the variables are
  then renamed into the caller's scope in either case).

Both apply to this package's helpers only; the results are the same to the
bit.  Measured in docs/compile.md.
"""
from __future__ import annotations

import copy

from numba.core import inline_closurecall, ir

#: The package of the kernels.
_CORE_PACKAGE = __package__.rsplit(".", 1)[0]

_numba_inline_function = inline_closurecall.InlineWorker.inline_function

#: (helper's Python function, enable_ssa, no_rewrites) -> its untyped numba IR.
_UNTYPED: dict = {}
#: While one of this package's helpers is inlined: a deepcopy memo per source scope.
_memos: dict | None = None


class _CopyBlocksTogether:
    """Stands in for the ``copy`` module inside numba's inliner: while a helper of
    this package is inlined, the blocks of one IR share one deepcopy memo."""

    def deepcopy(self, obj, memo=None):
        if memo is None and _memos is not None and isinstance(obj, ir.Block):
            memo = _memos.setdefault(id(obj.scope), {})
        return copy.deepcopy(obj, memo)

    def __getattr__(self, name):
        return getattr(copy, name)


def _untyped_ir(worker, func):
    """numba's untyped pipeline on ``func`` as numba's inliner runs it, kept."""
    key = (func, False, worker.flags.no_rewrites)
    kept = _UNTYPED.get(key)
    if kept is None:
        kept = _UNTYPED[key] = worker.run_untyped_passes(func)
    else:
        worker.flags.enable_ssa = False        # as numba's pipeline leaves it
    return kept


def _inline_function(self, caller_ir, block, i, function, arg_typs=None):
    """numba's ``InlineWorker.inline_function``, for this package's helpers at less cost."""
    if not getattr(function, "__module__", "").startswith(_CORE_PACKAGE + "."):
        return _numba_inline_function(self, caller_ir, block, i, function, arg_typs)
    global _memos
    callee_ir = _untyped_ir(self, function)
    _memos = {}
    try:
        return self.inline_ir(caller_ir, block, i, callee_ir, function.__code__.co_freevars,
                              arg_typs=arg_typs)
    finally:
        _memos = None


def install() -> None:
    """Inline this package's helpers at less cost (see the module's docstring)."""
    inline_closurecall.copy = _CopyBlocksTogether()
    inline_closurecall.InlineWorker.inline_function = _inline_function
