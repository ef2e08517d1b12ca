"""numba kernels: floats, ints and arrays in, status codes out.

Nothing in this package imports pandas, matplotlib or joblib, allocates in a
hot loop, or raises; the Python layer around it validates, converts units,
allocates and builds tables.
"""

from . import _cache, _inlining, _linking

_cache.install()   # before any kernel is defined: see _cache for why
_linking.install()
_inlining.install()
