"""One place for numba options and numerical tolerances.

Every kernel is compiled with :data:`JIT`; no module sets its own ``fastmath``
or ``cache`` flags.  Every tolerance, margin and scale of the kernels lives
here, each with what it bounds.
"""

#: Options passed to every ``numba.njit`` in :mod:`workbench.core`.
#: ``error_model="numpy"`` lets division by zero give inf/NaN (caught by the
#: NaN status check) instead of raising inside the kernel.
#: ``_nrt=False``: the kernels allocate nothing, so they need no reference
#: counts; with them, each call of a compiled kernel increments and
#: decrements every array argument atomically (measured: a call passing 10
#: arrays 77 ns with the counts, 26 ns without;
#: docs/compile.md).
JIT = dict(cache=True, nogil=True, fastmath=False, error_model="numpy", _nrt=False)

#: Kernels that allocate their own work arrays (the static start, not in the
#: time loop).
JIT_ALLOC = dict(JIT, _nrt=True)

#: A literal argument (``f(y, 0)``, ``f(y, True)``) or an omitted default
#: makes numba compile a second version of a kernel for that literal: pass
#: ``np.int64(0)``, ``np.bool_(True)``, ``np.float64(0.0)`` and give every
#: argument (tests/core/test_compile.py counts the versions).

#: Smallest pivot accepted by the LDL^T factorisation of the mass matrix,
#: relative to the largest diagonal entry.
CHOLESKY_REL_PIVOT = 1e-14

#: A projection onto a regime's constraints sets the components of (q, q') smaller than this
#: in magnitude (cm, rad, cm/s, rad/s) to zero.  A locked joint's velocities s', v', psi' are
#: zero in exact arithmetic, but their round-off decays from step to step into the subnormal
#: doubles (below 2.2e-308; about 5e-323 cm/s) and stays there, and an operation with a
#: subnormal operand or result is microcode-assisted on Intel processors, about a hundred
#: times the cost of a normal one: the 10 s sine with the tip mass took 2.6 s with them and
#: 1.4 s without on an Ice Lake Xeon (docs/performance.md).  The value is the square root of
#: the smallest normal double, so that no product of two components is subnormal; it is far
#: below every scale of the state (docs/model.md, 'Integration'); on the 10 s sines' first 2 s
#: what it drops changed no other value of the samples or the events.
TINY_STATE = 1.4916681462400413e-154

#: Options for small helpers (a few dozen lines at most, their own inlined
#: callees included) called inside the time loop: inlined at numba's IR
#: level, where LLVM would not inline them.  numba types and lowers an inlined
#: helper again at every call site, so a helper that grows, or calls big ones,
#: is a kernel of its own (``JIT``): the aggregates of the equations of motion
#: (rhs, assemble_inertia, add_contact_forces, fill_geometry, ...) are compiled
#: once and called (docs/compile.md).  The exception is the right-hand side of
#: the time loop, ``rhs_regime``: its mass matrix, forces and the locked
#: joint's blocks are inlined into it, once (the sines 10 % faster for 12 s
#: more of ``workbench compile`` on 2 cores, docs/compile.md).
JIT_INLINE = dict(JIT, inline="always")

#: Contact event thresholds (docs/model.md §7).  An event function must pass its
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

#: Events are located to this time (s); the specification asks for 1e-10.
EVENT_TIME_TOL = 1e-11
#: The state at an event comes from one step of the pair towards it; the pair's state and
#: its dense output's, where the event was located, differ by the step's error, about
#: 1e-9 to 1e-8 s in the event's time.  A correction of at most this time (s) is a Heun
#: step from the pair's state, not another step of the pair from the step's start: its
#: error, about (omega d)^3 / 6 relative for a mode of omega rad/s over d s, is 7e-9 at
#: the axial modes' 3.5e4 rad/s, far below the tolerance.
SHORT_STEP_S = 1e-7

#: Room in the event log for one integration step: more events than this
#: inside one step hand the step to Moreau-Jean time-stepping whatever the
#: flood rule below says (the log is written in place, without bounds checks).
MAX_EVENTS_PER_STEP = 64

#: The physics' own thresholds, in physical units: no decision of the model
#: depends on the step an integrator takes, so tightening a tolerance or
#: refining a fixed step converges to one solution (docs/model.md §7).
#:
#: An event flood: more than FLOOD_EVENTS events within FLOOD_WINDOW_S (s)
#: (a third of the period of the fastest linear mode, the axial one at
#: 3.3 kHz with the tip mass, 5.6 kHz without) is an episode the
#: event-driven logic cannot resolve; Moreau-Jean time-stepping takes over
#: for STEPPED_TIME_S (s; ten of the stability steps of 1e-4 s with the tip
#: mass), then the event-driven steps resume.
FLOOD_EVENTS = 64
FLOOD_WINDOW_S = 1e-4
STEPPED_TIME_S = 1e-3
#: Options of the kernels that split independent work over the cores with
#: ``numba.prange`` (the cork fit's exhaustive search).
JIT_PARALLEL = dict(JIT, parallel=True)

# --- hybrid -----------------------------------------------------------
#: An impact recurring within this time (s) of the last one, or closing slower
#: than the gap's free acceleration makes in this time, belongs to an
#: accumulation (docs/model.md §7): the impact set then takes the points
#: closing within it.  A tenth of the period of the fastest linear mode
#: (3.0e-4 s with the tip mass, 1.8e-4 s without): a bounce that returns
#: sooner is the same landing, not a new motion of the structure.
ACCUM_TIME_S = 3e-5
#: A gap that turns within a step is evaluated where its Hermite interpolant
#: comes within this fraction of its change of slope (m1 - m0) of zero ...
GRAZE_MARGIN = 0.02
#: ... and its minimum followed for at most this many trial states, while the
#: secant's bracket on the step's fraction is wider than GRAZE_BRACKET.
GRAZE_ITERS = 4
GRAZE_BRACKET = 1e-9
#: What is left of a step below this fraction of the lattice step is none
#: (the round-off of t + h, not time to integrate).
STEP_REMAINDER_REL = 1e-15

# --- transitions -----------------------------------------------------------
#: A point whose gap is within this of zero (cm) is closed or closing: it joins
#: an impact and may stay closed in the regime choice.  RK4's gaps carry errors
#: of ~1e-8-1e-7 cm at the default step (measured at 1e-4 s).
GAP_TOL = 1e-7
#: Within an accumulation of impacts (docs/model.md §7) the impact set takes
#: points this close (cm): a corner lifted by the previous micro-impact.
ACCUM_GAP_TOL = 1e-5
#: A closed point's normal rate is below this (cm/s).
CLOSED_RATE = 1e-6
#: A slip velocity below this (cm/s) is at rest: stick, or slip either way.
REST_RATE = 1e-6
#: Relative tolerance of the regime conditions (on the forces' and the
#: accelerations' scales).
REGIME_REL_TOL = 1e-9

# --- impact_law -----------------------------------------------------------
#: Relative tolerance of the conditions (on the rates' and impulses' scales).
LAW_REL_TOL = 1e-9
#: A pivot below this fraction of the largest entry is a dependent row.
LAW_RANK_TOL = 1e-10
#: A condition's slope along the null direction below this fraction of the sum
#: of its terms' magnitudes is round-off: of the at most 4 products and of the
#: elimination that gave the direction (about 4500 ulps).
SLOPE_ROUND_OFF = 1e-12
#: ... and a slope below this fraction of the condition's value is none.
SLOPE_REL = 1e-13
#: Lemke's result must satisfy the law to this fraction of the rates' and impulses' scales.
LEMKE_CHECK_TOL = 1e-6
#: A mode combination's reduced system is inconsistent when a dependent row's
#: right side exceeds this fraction of the right sides' scale.
CONSISTENCY_REL = 1e-8
#: Of two solutions of the enumeration, the later replaces the earlier only if it
#: loses more energy by this fraction of the largest impulse-rate product.
ENERGY_TIE_REL = 1e-12
#: After an impact a point leaves (is open) when its normal rate exceeds this
#: fraction of the largest rate before it (cm/s over cm/s).
OPEN_RATE_REL = 1e-7

# --- constrained -------------------------------------------------------------
#: The constrained accelerations' elimination sets an unknown to 0 when its pivot
#: is below this fraction of the largest entry (a row zero on the free
#: coordinates, or dependent on the others).
PIVOT_REL = 1e-12
#: Two contacts' 3 x 4 rows have no common null direction when every 3 x 3
#: cofactor is below this times the cube of the rows' scale.
NULL_COFACTOR_REL = 1e-12
#: A sticking double contact locks the joint (and its accelerations are solved
#: by blocks, constrained.locked_joint_accelerations) when the determinant of its
#: 3 x 3 rows on (s, v, psi) exceeds this fraction of Hadamard's bound; below it
#: (rows nearly dependent) the pivoted elimination of add_contact_forces decides.
LOCK_DET_REL = 1e-6

# --- controlled --------------------------------------------------------------
#: An event's time is controlled on this scale (s): its estimated error (the
#: event function's estimate over its rate) within tol times it, as the time
#: of one sample of the default 1 kHz record.
EVENT_TIME_SCALE_S = 1e-3
#: Floors of the error scales: the clearance (cm) for positions (over a
#: length for angles), and that times REF_RATE (1/s) for velocities.
REF_RATE = 100.0

# --- equilibrium (the static start) --------------------------------------------
#: Scales of the Newton residual's rows: forces (dyn) and gaps (cm).
FORCE_SCALE = 1e5
GAP_SCALE = 1e-3
#: Relative central-difference steps of the Jacobian: coordinates, forces.
FD_COORD = 1e-7
FD_FORCE = 1e-3
#: The line search halves alpha down to this, then takes the last alpha tried.
ALPHA_MIN = 1e-4

# --- variational equations (the monodromy of a periodic orbit) -------------------
#: Forward-difference step of the state Jacobian df/dy, relative to each
#: component's error scale: the truncation error ~1e-7 of the largest curvature
#: over a scale, the round-off ~1e-16 / 1e-7 of f.
VAR_FD_REL = 1e-7
#: Central-difference step of an event's jump map and event-function gradient,
#: relative to the error scales (no integration in between: round-off ~1e-10).
JUMP_FD_REL = 1e-6
#: Time step (s) of the event function's total rate along the old regime's flow
#: (central differences; the fastest mode, ~6 kHz, moves by 4e-5 rad in it).
EVENT_DT_FD_S = 1e-9
#: The variational equations' step (s) at most, and its floor: the run's own
#: steps are 2e-5..1e-4 s; a step below the floor is a failure (ERR_VAR_STEPS).
VAR_H_MAX_S = 1e-3
VAR_H_MIN_S = 1e-12
