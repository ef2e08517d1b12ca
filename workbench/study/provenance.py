"""Where a result came from: the code version, packages and machine."""
from __future__ import annotations

import functools
import hashlib
import importlib.metadata
import os
import platform
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parents[1]          # workbench/
PACKAGES = ("numba", "numpy", "scipy", "pandas", "joblib", "pyarrow", "matplotlib", "SALib")
#: The sub-packages whose code computes a sweep's points; the others (present/,
#: lab/, identify/, reference/, the command line) only read or present them.
COMPUTING = ("core", "model", "study")


def computing_sources() -> list[Path]:
    """The source files :func:`code_version` hashes, sorted."""
    return sorted(p for sub in COMPUTING for p in (_PACKAGE / sub).rglob("*.py"))


@functools.lru_cache(maxsize=1)
def code_version() -> str:
    """A hash of every source file that computes results (:data:`COMPUTING`; 16 hex digits).

    Part of each sweep point's key: results of other code are not reused,
    while a new figure or file format does not recompute a grid.
    """
    h = hashlib.sha256()
    for path in computing_sources():
        h.update(str(path.relative_to(_PACKAGE)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def environment() -> dict:
    """Code version, Python and package versions, machine."""
    versions = {}
    for name in PACKAGES:
        try:
            versions[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            versions[name] = None
    return {"code_version": code_version(), "python": platform.python_version(),
            "packages": versions, "machine": platform.machine(), "node": platform.node(),
            "cpus": os.cpu_count(), "system": platform.platform()}
