"""The numba cache is keyed by the kernel sources (workbench/core/compiler/cache.py)."""
import os
import time

from workbench.core.compiler import cache as _cache
from workbench.core.constrained import rhs_regime
from workbench.core.hybrid import run_hybrid

import pytest
from workbench.core import compiler

pytestmark = pytest.mark.skipif(not compiler.active(), reason="the compiler's workarounds are off")


def test_kernels_are_cached_under_the_hash_of_all_kernel_sources():
    assert _cache.CACHE_DIR.name == "numba-" + _cache.source_hash()
    for kernel in (run_hybrid, rhs_regime):
        assert kernel._cache._cache_path == str(_cache.CACHE_DIR)
    names = {p.name for p in _cache._SOURCES}
    assert {"hybrid.py", "constrained.py", "integrate.py", "config.py"} <= names


def test_the_hash_changes_with_any_kernel_source(tmp_path, monkeypatch):
    copies = []
    for path in _cache._SOURCES:
        copy = tmp_path / path.name
        copy.write_bytes(path.read_bytes())
        copies.append(copy)
    monkeypatch.setattr(_cache, "_SOURCES", copies)
    before = _cache.source_hash()
    assert before == _cache.source_hash()
    (tmp_path / "integrate.py").write_text((tmp_path / "integrate.py").read_text() + "\n# x\n")
    assert _cache.source_hash() != before


def test_a_shared_root_keeps_the_live_caches_of_other_versions(tmp_path, monkeypatch):
    mine, other, stale = (tmp_path / f"numba-{n}" for n in ("mine", "other", "stale"))
    for folder in (mine, other, stale):
        folder.mkdir()
    old = time.time() - (_cache.PRUNE_AFTER_DAYS + 1) * 86400.0
    os.utime(mine, (old, old))
    os.utime(stale, (old, old))
    monkeypatch.setattr(_cache, "CACHE_ROOT", tmp_path)
    monkeypatch.setattr(_cache, "CACHE_DIR", mine)
    _cache.install()
    assert mine.is_dir() and mine.stat().st_mtime > old + 86400.0     # marked as used
    assert other.is_dir()                                              # another checkout's
    assert not stale.exists()                                          # unused for 15 days
