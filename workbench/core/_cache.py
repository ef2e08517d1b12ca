"""numba's on-disk cache, keyed by the source of every kernel.

numba's ``cache=True`` checks only the timestamp of the file that defines a
function.  A kernel that calls a jit function of another module keeps the
callee's machine code compiled into its own cache entry, and so does a
global constant read from :mod:`workbench.core.config`: change the callee or the
constant, and the caller silently runs the old code.  (Measured: after the
double-contact friction changed in constrained.py, the cached rk4_step kept
the old friction and a slip phase drifted 6e-4 cm/s off the new equations.)

This module keys the cache by a hash of all kernel sources (config.py
included): the kernels of ``workbench.core`` are cached under
``__pycache__/numba-<hash>/``, so any change to any of them compiles
everything afresh, and entries of other versions are removed.  The
environment variable ``WORKBENCH_CACHE_ROOT`` puts the ``numba-<hash>``
folders elsewhere (a read-only install; the compile benchmark's cold start).
"""
from __future__ import annotations

import hashlib
import os
import shutil
from pathlib import Path

from numba.core import caching

_CORE = Path(__file__).resolve().parent
_SOURCES = sorted(_CORE.glob("*.py"))           # the kernels and their config.py
_PREFIX = "numba-"


def source_hash() -> str:
    """Hash of the kernel sources and the numerical configuration."""
    h = hashlib.sha256()
    for path in _SOURCES:
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


CACHE_ROOT = Path(os.environ.get("WORKBENCH_CACHE_ROOT") or _CORE / "__pycache__")
CACHE_DIR = CACHE_ROOT / (_PREFIX + source_hash())


class _KernelCacheLocator(caching.InTreeCacheLocator):
    """Cache files of workbench.core in CACHE_DIR; other functions are not ours."""

    def __init__(self, py_func, py_file):
        super().__init__(py_func, py_file)
        self._cache_path = str(CACHE_DIR)

    @classmethod
    def from_function(cls, py_func, py_file):
        if Path(py_file).resolve().parent != _CORE:
            return None
        return super().from_function(py_func, py_file)


def install() -> None:
    """Put the locator first in numba's list and prune caches of other versions."""
    locators = caching.CacheImpl._locator_classes
    if _KernelCacheLocator not in locators:
        locators.insert(0, _KernelCacheLocator)
    if CACHE_ROOT.is_dir():
        for entry in CACHE_ROOT.iterdir():
            stale = (entry.is_dir() and entry.name.startswith(_PREFIX) and entry != CACHE_DIR) \
                or (entry.suffix in (".nbi", ".nbc") and entry.parent.parent == _CORE)
            if stale:
                if entry.is_dir():
                    shutil.rmtree(entry, ignore_errors=True)
                else:
                    try:
                        os.remove(entry)
                    except OSError:
                        pass
