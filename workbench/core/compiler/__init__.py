"""The workbench's workarounds of numba's compiler, behind one switch.

Three modules change what numba does with this package's kernels, through
numba's private internals (docs/compile.md):

- :mod:`.cache`: the kernels' on-disk cache keyed by a hash of every kernel
  source (numba's checks only the timestamp of a function's own file);
- :mod:`.linking`: each kernel's machine code once, callers calling it
  instead of carrying a copy;
- :mod:`.inlining`: each inlined helper's untyped IR built once per process.

They run only on the numba release the suite was run with (TESTED_NUMBA,
the range ``pyproject.toml`` pins) and unless ``WORKBENCH_NUMBA_PATCHES=0``.
Otherwise the kernels are plain ``numba.njit(cache=True)`` functions, cached
under their own source-hash folder through numba's public ``CACHE_DIR``
setting and compiled on first use in the calling process, and one line on
stderr says so: slower to compile, the same results
(``tests/core/test_plain_numba.py`` runs the fast physics checks so).
"""
from __future__ import annotations

import os
import sys

import numba

#: The environment variable that switches the workarounds off ("0").
SWITCH = "WORKBENCH_NUMBA_PATCHES"
#: The numba release series (major.minor) the workarounds were written and tested for.
TESTED_NUMBA = "0.68"


def _why_not() -> str | None:
    """Why the workarounds are off, or None when they run."""
    if os.environ.get(SWITCH, "").strip() == "0":
        return f"{SWITCH}=0"
    if ".".join(numba.__version__.split(".")[:2]) != TESTED_NUMBA:
        return f"numba {numba.__version__} is not the tested {TESTED_NUMBA}"
    return None


REASON = _why_not()


def active() -> bool:
    """Whether the workarounds run in this process."""
    return REASON is None


def install() -> None:
    """Install the workarounds (before any kernel is defined), or say why not and use
    plain numba."""
    from . import cache
    if REASON is None:
        from . import inlining, linking
        cache.install()
        linking.install()
        inlining.install()
    else:
        cache.use_plain()
        print(f"workbench: numba's compiler workarounds are off ({REASON}): plain "
              "numba.njit(cache=True), slower to compile", file=sys.stderr)
