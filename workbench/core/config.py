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

#: Contact event thresholds (MODEL.md §7).  An event function must pass its
#: threshold to fire, so that round-off at a freshly switched constraint
#: (a gap of 1e-16 cm, a force of 1e-10 dyn) cannot toggle it back:
#: an impact needs a gap below -GAP_EPS (cm), far inside the 1e-8 cm
#: penetration budget; a separation or stick->slip a force below
#: -LAMBDA_EPS (dyn; contact forces are 1e4-1e7 dyn); a slip reversal a
#: slip velocity past -RATE_EPS (cm/s).
GAP_EPS = 1e-12
LAMBDA_EPS = 1e-6
RATE_EPS = 1e-10

#: The stick margin mu_s sum lambda_n - |lambda_t| is the difference of
#: forces of 1e5 dyn and more, computed to ~1e-10 relative; stick -> slip
#: fires below -FRICTION_REL_EPS mu_s sum lambda_n (- LAMBDA_EPS), and a
#: sticking regime is accepted down to half that.
FRICTION_REL_EPS = 1e-7

#: Events are located to this time (s); MODEL.md and issue 3 ask for 1e-10.
EVENT_TIME_TOL = 1e-11

#: More events than this inside one integration step end the run
#: (a Zeno-like accumulation of impacts or regime switches).
MAX_EVENTS_PER_STEP = 64

#: Options of the kernels that split independent work over the cores with
#: ``numba.prange`` (the cork fit's exhaustive search).
JIT_PARALLEL = dict(JIT, parallel=True)
