"""Where a result came from: the code version, packages and machine."""
from __future__ import annotations

import functools
import hashlib
import importlib.metadata
import os
import platform
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent
PACKAGES = ("numba", "numpy", "scipy", "pandas", "joblib", "pyarrow", "matplotlib")


@functools.lru_cache(maxsize=1)
def code_version() -> str:
    """A hash of every source file of the package (16 hex digits).

    Part of each sweep point's key: results of other code are not reused.
    """
    h = hashlib.sha256()
    for path in sorted(_PACKAGE.rglob("*.py")):
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
