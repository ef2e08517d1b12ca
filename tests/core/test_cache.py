"""The numba cache is keyed by the kernel sources (workbench/core/_cache.py)."""
from workbench.core import _cache
from workbench.core.constrained import rhs_regime
from workbench.core.hybrid import run_hybrid


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
