"""One place for numba options and numerical tolerances.

Every kernel is compiled with :data:`JIT`; no module sets its own ``fastmath``
or ``cache`` flags.  Tolerances used by more than one module live here too.
"""

#: Options passed to every ``numba.njit`` in :mod:`workbench.core`.
#: ``error_model="numpy"`` lets division by zero give inf/NaN (caught by the
#: NaN status check) instead of raising inside the kernel.
JIT = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")

#: Number of Gauss-Legendre points per beam.  Six integrate the beam's kinetic
#: energy exactly: the foreshortening makes the Jacobian entries polynomials
#: of degree 5 in x, so J^T J is of degree 10 and needs 2n - 1 >= 10.
N_GAUSS = 6

#: Smallest pivot accepted by the Cholesky factorisation of the mass matrix,
#: relative to the largest diagonal entry.
CHOLESKY_REL_PIVOT = 1e-14

#: Options for small helpers called inside the hot loop: inlined at numba's
#: IR level, so that calls do not pass the model and work tuples (dozens of
#: array structs) by value.  Measured: an element's kinematics went from
#: ~700 ns to ~100 ns (see benchmarks/).
JIT_INLINE = dict(JIT, inline="always")
