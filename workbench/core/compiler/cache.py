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
everything afresh.  The environment variable ``WORKBENCH_CACHE_ROOT`` puts
the ``numba-<hash>`` folders elsewhere: a read-only install, the compile
benchmark's cold start, or one folder shared by several checkouts and
machines of the same kind (numba's index is keyed by the source's content,
the CPU and numba's version, not by a path or a timestamp).  Every import
marks its own version's folder as used; folders of other versions unused
for :data:`PRUNE_AFTER_DAYS` are removed, so checkouts of different
versions sharing a root do not delete each other's live caches.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import time
from pathlib import Path

_CORE = Path(__file__).resolve().parents[1]
#: The kernels and their config.py, and this package's workarounds (they shape the code).
_KERNELS = sorted(_CORE.glob("*.py"))
_SOURCES = _KERNELS + sorted(Path(__file__).parent.glob("*.py"))
#: The package of the kernels.
CORE_PACKAGE = __package__.rsplit(".", 1)[0]
_PREFIX = "numba-"

#: A cache folder of another version unused this long (days) is removed.
PRUNE_AFTER_DAYS = 14


def source_hash() -> str:
    """Hash of the kernel sources and the numerical configuration."""
    h = hashlib.sha256()
    for path in _SOURCES:
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def _folder() -> str:
    """numba-<hash>, or numba-<hash>-plain for kernels compiled without the workarounds."""
    from . import active
    return _PREFIX + source_hash() + ("" if active() else "-plain")


CACHE_ROOT = Path(os.environ.get("WORKBENCH_CACHE_ROOT") or _CORE / "__pycache__")
CACHE_DIR = CACHE_ROOT / _folder()
_LOCATOR: list = []


def kernel_locator():
    """The cache locator class of the kernels (built on first use: it subclasses numba's
    private ``InTreeCacheLocator``)."""
    if _LOCATOR:
        return _LOCATOR[0]
    from numba.core import caching

    class KernelCacheLocator(caching.InTreeCacheLocator):
        """Cache files of workbench.core in CACHE_DIR; other functions are not ours."""

        def __init__(self, py_func, py_file):
            super().__init__(py_func, py_file)
            self._cache_path = str(CACHE_DIR)

        @classmethod
        def from_function(cls, py_func, py_file):
            if Path(py_file).resolve().parent != _CORE:
                return None
            return super().from_function(py_func, py_file)
    _LOCATOR.append(KernelCacheLocator)
    return KernelCacheLocator


def install() -> None:
    """Put the locator first in numba's list, then :func:`keep`."""
    from numba.core import caching
    locators = caching.CacheImpl._locator_classes
    if kernel_locator() not in locators:
        locators.insert(0, kernel_locator())
    keep()


def use_plain() -> None:
    """Without the workarounds: numba's own locator for a user's cache folder
    (``numba.config.CACHE_DIR``, public), set to CACHE_DIR, then :func:`keep`."""
    import numba
    numba.config.CACHE_DIR = str(CACHE_DIR)
    keep()


def keep() -> None:
    """Mark this version's folder as used, and prune folders of other versions unused for
    PRUNE_AFTER_DAYS."""
    if not CACHE_ROOT.is_dir():
        return
    try:
        if CACHE_DIR.is_dir():
            os.utime(CACHE_DIR)
    except OSError:                       # a read-only install
        pass
    cutoff = time.time() - PRUNE_AFTER_DAYS * 86400.0
    for entry in CACHE_ROOT.iterdir():
        try:
            if entry.is_dir() and entry.name.startswith(_PREFIX) and entry != CACHE_DIR:
                if entry.stat().st_mtime < cutoff:
                    shutil.rmtree(entry, ignore_errors=True)
            elif entry.suffix in (".nbi", ".nbc") and entry.parent.parent == _CORE:
                os.remove(entry)
        except OSError:
            pass


def index_entries(cache_dir: Path = None) -> dict:
    """Compiled versions in a cache folder: {index file name: number of entries}."""
    import pickle
    import numba
    out = {}
    for path in sorted(Path(cache_dir or CACHE_DIR).glob("*.nbi")):
        with open(path, "rb") as f:
            if pickle.load(f) != numba.__version__:
                continue
            _stamp, overloads = pickle.loads(f.read())
        out[path.name] = len(overloads)
    return out


def kernel_versions() -> dict:
    """Compiled versions of every kernel of workbench.core in this process:
    {"module.function": number of signatures} for those compiled or loaded."""
    import importlib
    from numba.core.registry import CPUDispatcher
    out = {}
    for path in _KERNELS:
        module = importlib.import_module(f"{CORE_PACKAGE}.{path.stem}")
        for name, obj in vars(module).items():
            if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == module.__name__ \
                    and obj.signatures:
                out[f"{path.stem}.{name}"] = len(obj.signatures)
    return out
