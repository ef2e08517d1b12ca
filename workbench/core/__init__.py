"""numba kernels: floats, ints and arrays in, status codes out.

Nothing in this package imports pandas, matplotlib or joblib, allocates in a
hot loop, or raises; the Python layer around it validates, converts units,
allocates and builds tables.  The compiler's workarounds are the subpackage
:mod:`.compiler`, installed here before any kernel is defined.
"""

from . import compiler

compiler.install()
