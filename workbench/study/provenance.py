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
#: Modules that only present results: a change to them keeps computed points valid.
PRESENTATION = frozenset({"figures.py", "tables.py", "report.py", "points.py", "cli.py",
                          "__main__.py", "provenance.py"})


@functools.lru_cache(maxsize=1)
def code_version() -> str:
    """A hash of every source file of the package that computes results (16 hex digits).

    Part of each sweep point's key: results of other code are not reused.
    The presentation modules (:data:`PRESENTATION`) are left out, so that a
    new figure does not recompute a grid.
    """
    h = hashlib.sha256()
    for path in sorted(_PACKAGE.rglob("*.py")):
        if path.parent == _PACKAGE and path.name in PRESENTATION:
            continue
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
