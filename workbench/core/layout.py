"""Declared layouts of every array the kernels take.

The kernels see the model as a few flat arrays.  This module is the one place
that names their entries; nothing else hard-codes an index.

Generalised coordinates (docs/model.md §3, seed §2.1: three per beam, three in the
joint)::

    q = (w_A, phi_A, u_A,  s, v, psi,  w_B, phi_B, u_B)
         0    1      2     3  4  5     6    7      8

State ``y = (q, qdot)`` of length 18.
"""

# --- generalised coordinates -------------------------------------------------
W_A, PHI_A, U_A, S, V, PSI, W_B, PHI_B, U_B = range(9)
N_DOF = 9
N_STATE = 2 * N_DOF
#: The beams' coordinates: all but the joint's (s, v, psi).
BEAM_COORDS = (W_A, PHI_A, U_A, W_B, PHI_B, U_B)
COORD_NAMES = ("w_A", "phi_A", "u_A", "s", "v", "psi", "w_B", "phi_B", "u_B")
#: Units of each coordinate (CGS).
COORD_UNITS = ("cm", "rad", "cm", "cm", "cm", "rad", "cm", "rad", "cm")

# --- the flat parameter array P (CGS) ----------------------------------------
# Built by workbench.model.packing.pack from a validated workbench.model.params.Parameters.
P_L_A = 0        # beam A length (cm)
P_L_B = 1        # beam B length (cm)
P_MU_A = 2       # beam A mass per length (g/cm)
P_MU_B = 3       # beam B mass per length (g/cm)
P_RHOI_A = 4     # beam A rotary inertia per length (g cm)
P_RHOI_B = 5     # beam B rotary inertia per length (g cm)
P_EI_A = 6       # beam A bending stiffness (g cm^3/s^2)
P_EI_B = 7       # beam B bending stiffness (g cm^3/s^2)
P_EA_A = 8       # beam A axial stiffness (g cm/s^2)
P_EA_B = 9       # beam B axial stiffness (g cm/s^2)
P_BETA_A = 10    # beam A bending damping C_b = beta K_b (s)
P_BETA_B = 11    # beam B bending damping (s)
P_M3 = 12        # joint body mass (g)
P_I3 = 13        # joint body inertia about its CM (g cm^2)
P_C3 = 14        # joint body CM along the joint axis (cm)
P_X_IN = 15      # contacts 1, 2 along the joint axis (cm)
P_X_LIP = 16     # contacts 3, 4 (plate lips) along the joint axis (cm)
P_M4 = 17        # loose body mass (g)
P_I4 = 18        # loose body inertia about its CM (g cm^2)
P_L4 = 19        # loose body length, inner end to beam B root (cm)
P_C4 = 20        # loose body CM from its inner end (cm)
P_H4 = 21        # loose body thickness at the contacts (cm)
P_GAP = 22       # total transverse clearance (cm)
P_M6 = 23        # tip mass (g), already multiplied by the on/off switch
P_I6 = 24        # tip mass inertia about its CM (g cm^2), likewise
P_MU_S = 25      # static friction coefficient (-)
P_MU_K = 26      # kinetic friction coefficient (-)
P_GRAV = 27      # gravitational acceleration (cm/s^2)
P_CORK_N = 28    # cork law's shape parameter n (the power law's exponent, -)
P_CORK_K = 29    # cork law's stiffness k (the power law's g/(s^2 cm^(n-1)))
P_CORK_C = 30    # cork damping c (g/s)
P_K_V = 31       # optional spring on v (g/s^2); 0 in the paper's model
P_K_PSI = 32     # optional spring on psi (g cm^2/s^2); 0 in the paper's model
P_X_FORCE = 33   # shaker position on beam A (cm)
P_C_STRAIN = 34  # distance from the neutral axis to the surface (cm)
P_N_GAUSS = 35   # Gauss points per beam (stored as a float)
P_X_ACCEL1 = 36  # accel1 on the joint body, from its base (cm)
P_X_ACCEL2 = 37  # accel2 on the loose body, from its inner end (cm)
P_C_AX_A = 38    # beam A axial damping on u_A (g/s)
P_C_AX_B = 39    # beam B axial damping on u_B (g/s)
P_S_TRAVEL = 40  # slide before the slot's end stop, each way (cm; inf for none)
P_K_STOP = 41    # end-stop stiffness beyond |s| > s_travel (g/s^2)
P_STEPPED_DT = 42  # largest Moreau-Jean step (s); inf until simulate sets it from the model's modes
P_CORK_FORM = 43   # cork law's form: its index in workbench.core.cork.FORMS (stored as a float)
# The step method: the explicit Runge-Kutta tableau (Butcher's c, A, b) that
# every integrator steps with (workbench.core.integrate.rk_step); written by
# workbench.model.tableaus.write_tableau (classical RK4 by default).  An
# embedded pair (workbench.core.pair) adds its error weights e and its dense
# output's coefficients (zeros for a tableau without them).
MAX_RK_STAGES = 16
#: Powers theta^1 .. theta^MAX_DENSE_DEGREE of a dense output's weights.
MAX_DENSE_DEGREE = 7
P_RK_STAGES = 44   # number of stages s (stored as a float)
P_RK_ORDER = 45    # order p: global error O(dt^p) (the PI controller's exponents)
P_RK_C = 46        # P_RK_C + i: node c_i (-), i < MAX_RK_STAGES
P_RK_B = P_RK_C + MAX_RK_STAGES   # P_RK_B + i: weight b_i (-)
P_RK_A = P_RK_B + MAX_RK_STAGES   # P_RK_A + MAX_RK_STAGES i + j: coefficient a_ij (-), j < i
P_RK_E = P_RK_A + MAX_RK_STAGES * MAX_RK_STAGES   # P_RK_E + i: error weight e_i = b_i - bhat_i (-)
P_RK_D = P_RK_E + MAX_RK_STAGES   # P_RK_D + MAX_DENSE_DEGREE i + j: dense weight of k_i, theta^(j+1)
P_RK_DEGREE = P_RK_D + MAX_RK_STAGES * MAX_DENSE_DEGREE   # the dense output's degree (0: none)
P_RK_EXTRA = P_RK_DEGREE + 1      # stages computed for the dense output only (after the s of a step)
P_RK_E3 = P_RK_EXTRA + 1          # P_RK_E3 + i: a second, lower-order error weight (DOP853's; 0: none)
P_RK_STEP_FACTOR = P_RK_E3 + MAX_RK_STAGES   # a controlled step is at most this many base steps
N_RK_END = P_RK_STEP_FACTOR + 1   # the step method's entries end here
# --- a beam's inertia invariants ---------------------------------------------
# Weighted sums over a beam's Gauss points, fixed once the parameters are
# (workbench.core.inertia.fill_invariants); the mass matrix, h and gravity
# are polynomials in the beam's coordinates with these coefficients.  With
# m = mu w and r = rho_I w a point's mass and rotary inertia, X its position
# along its root frame's axis (the root's offset included), xi, N = (N1, N2),
# S = (S00, S01, S11) and d = (dN1, dN2) its shape-table entries:
INV_M = 0      # sum m (g)
INV_X = 1      # sum m X (g cm)
INV_XX = 2     # sum m X^2 (g cm^2)
INV_XI = 3     # sum m xi (g)
INV_XIXI = 4   # sum m xi^2 (g)
INV_XXI = 5    # sum m X xi (g cm)
INV_N = 6      # sum m N (2)
INV_NN = 8     # sum m N N^T: (1,1), (1,2), (2,2) (3)
INV_XIN = 11   # sum m xi N (2)
INV_XN = 13    # sum m X N (2)
INV_S = 15     # sum m S (3)
INV_XS = 18    # sum m X S (3)
INV_XIS = 21   # sum m xi S (3)
INV_NS = 24    # sum m N1 S (3), then sum m N2 S (3)
INV_SS = 30    # sum m S_a S_b, (a, b) = (00,00), (00,01), (00,11), (01,01), (01,11), (11,11) (6)
INV_R = 36     # sum r (g cm^2)
INV_RD = 37    # sum r d (2)
INV_RDD = 39   # sum r d d^T: (1,1), (1,2), (2,2) (3)
N_INV = 42
P_INV_A = N_RK_END               # beam A's invariants (N_INV)
P_INV_B = P_INV_A + N_INV        # beam B's, its root at the loose body's outer end (N_INV)
N_PARAMS = P_INV_B + N_INV

# --- shape-function tables ---------------------------------------------------
# One row per beam point (the Gauss points of a beam, or a sensor position):
# the Hermite shape functions of docs/model.md §4 and the foreshortening matrix
# Sigma(x) at that point, and the point's quadrature length weight.
T_XI = 0      # x / L (-)
T_X = 1       # x (cm)
T_N1 = 2      # N1 (-)
T_N2 = 3      # N2 (cm)
T_DN1 = 4     # N1' (1/cm)
T_DN2 = 5     # N2' (-)
T_DDN1 = 6    # N1'' (1/cm^2)
T_DDN2 = 7    # N2'' (1/cm)
T_S00 = 8     # Sigma_00 (1/cm)
T_S01 = 9     # Sigma_01 (-)
T_S11 = 10    # Sigma_11 (cm)
T_WEIGHT = 11 # quadrature weight w_i L / 2 (cm); 0 for sensor rows
N_TAB = 12

# --- status codes ------------------------------------------------------------
OK = 0
ERR_NAN = 1
ERR_SINGULAR_MASS = 2
ERR_BAD_INPUT = 3
ERR_EVENT_FLOOD = 4
ERR_NO_IMPACT_CANDIDATE = 5
ERR_NO_REGIME = 6
LOG_FULL = 7     # not an error: the event log is full, call again to continue
STOPPED = 8      # not a kernel's: simulate(stop=...) ended the run early, as asked
ERR_JUMP_AMBIGUOUS = 9   # an event's outcome changes within the differencing step (core.variational)
ERR_EVENT_TANGENT = 10   # the orbit meets the event surface tangentially: dh/dt = 0 (core.variational)
ERR_VAR_STEPS = 11       # the variational equations' step fell below its floor, or they took
                         # more steps than allowed (core.variational)

MESSAGES = {
    OK: "finished",
    ERR_NAN: "the state became NaN or infinite",
    ERR_SINGULAR_MASS: "the mass matrix is not positive definite",
    ERR_BAD_INPUT: "the kernel was given inconsistent array sizes",
    ERR_EVENT_FLOOD: "Zeno-like flood of events: too many events within one step",
    ERR_NO_IMPACT_CANDIDATE: "no consistent momentum-transfer candidate for an impact",
    ERR_NO_REGIME: "no consistent regime after a transition (every candidate violated "
                   "a force or friction condition)",
    LOG_FULL: "the event log is full (the run continues in a new chunk)",
    STOPPED: "stopped early by the caller's condition",
    ERR_JUMP_AMBIGUOUS: "an event's outcome (the regime after it) changes within the "
                        "differencing step: the jump is not differentiable there",
    ERR_EVENT_TANGENT: "the orbit meets an event surface tangentially (dh/dt = 0): no "
                       "saltation matrix",
    ERR_VAR_STEPS: "the variational equations' step fell below its floor or far below the "
                   "run's (more steps than allowed)",
}

# --- status codes of the static equilibrium (workbench.core.equilibrium) -------
EQ_CONVERGED = 0
EQ_DAMPED_OUT = 1       # damped Newton steps in a row: no equilibrium near the start
EQ_SINGULAR = 2         # the Jacobian has a zero pivot
EQ_NOT_CONVERGED = 3    # the iteration limit was reached

# --- rows of the shape table ``tab`` -----------------------------------------
# tab has 2 n_gauss + N_PTS rows: beam A's Gauss points, beam B's Gauss
# points, then these special points (row 2 n_gauss + R_*).
R_TIP_A = 0      # beam A tip (x = L_A): origin of the joint frame
R_TIP_B = 1      # beam B tip (x = L_B): the tip mass
R_FORCE1 = 2     # force1, beam A 13.2 cm (Table 2)
R_STRAIN1 = 3    # strain1, beam A 21.9 cm (Table 2)
R_STRAIN2 = 4    # strain2, beam B 13.4 cm (Table 2)
R_ACCEL3 = 5     # accel3, beam B 28.4 cm (Table 2)
N_PTS = 6

# --- point records ``rec`` (N_RECS, N_REC) ------------------------------------
# A point record holds a point's position, velocity, convective acceleration,
# Jacobian and angle row; a frame record adds the frame's angle.  The kernels
# build every mass element in row REC_POINT from the frame rows.
RX, RY = 0, 1            # position (cm)
VX, VY = 2, 3            # velocity (cm/s); used for points local to a frame
KX, KY = 4, 5            # convective acceleration kappa (cm/s^2)
JX = 6                   # JX + j: d(x)/dq_j
JY = JX + N_DOF          # JY + j: d(y)/dq_j
AA = JY + N_DOF          # AA + j: d(angle)/dq_j
COS = AA + N_DOF         # cos(angle) of a frame
SIN = COS + 1            # sin(angle)
RATE = SIN + 1           # angle rate (rad/s)
N_REC = RATE + 1

REC_JOINT = 0    # joint frame: origin beam A's tip, angle alpha3 = phi_A
REC_LOOSE = 1    # loose-body frame: origin d = (x_in + s, v), angle phi_A + psi
REC_LOCAL = 2    # a point in a frame, before it is carried to global
REC_POINT = 3    # the current point, global
REC_ACC = 4      # sums over a frame's points (workbench.core.inertia)
REC_U = 5        # a frame's Jacobian rows in its own axes, JX/JY columns (workbench.core.inertia)
N_RECS = 6

# --- work matrices and vectors -----------------------------------------------
KC_K, KC_C = 0, 1                # kc (2, 9, 9): stiffness, damping
MAT_M, MAT_CHOL = 0, 1           # mat (2, 9, 9): mass matrix, its LDL^T factor (dynamics._factor)
VEC_H, VEC_Q, VEC_RHS, VEC_AUX = 0, 1, 2, 3  # vec (4, 9): h = sum m J^T kappa, forces, Q - h,
AUX_VGRAV, AUX_P_EXT, AUX_F_SHAKER, AUX_F_HAMMER, AUX_P_DAMP = 0, 1, 2, 3, 4   # and scalars of the last rhs:
N_VEC = 4   # gravity energy (erg), excitation power (erg/s), shaker and hammer forces (dyn),
            # structural damping dissipation (erg/s)
# stages (N_STAGES, N_AUG): the stage derivatives k_1..k_s of a step (rows
# 0..MAX_RK_STAGES-1), then state buffers.  STAGE_K1 keeps k1 of
# the current step for re-integrating partial steps; STAGE_TRY and STAGE_HI
# hold trial states while an event is bracketed (HI: the earliest state
# found past an event), STAGE_KNEXT and STAGE_KTRY the right-hand sides at
# STAGE_NEXT and STAGE_TRY; STAGE_QD holds q'- in [0, 9) and a candidate
# q'+ in [9, 18) during an impact.
# STAGE_ERR holds an embedded pair's error estimate of the step (workbench.core.pair);
# STAGE_BASE and STAGE_KBASE a step of the pair towards an event and its right-hand side,
# from which short steps move on to the event (workbench.core.adaptive).
(STAGE_TMP, STAGE_CUR, STAGE_NEXT, STAGE_K1, STAGE_TRY, STAGE_HI, STAGE_KNEXT, STAGE_KTRY,
 STAGE_QD, STAGE_ERR, STAGE_BASE, STAGE_KBASE) = range(MAX_RK_STAGES, MAX_RK_STAGES + 12)
N_STAGES = MAX_RK_STAGES + 12

# --- augmented state -----------------------------------------------------------
# The integrators carry (q, q') and these running integrals (erg), integrated
# by the same steps as the motion, for the energy account.
A_WORK = N_STATE        # work of the applied excitation (shaker or hammer)
A_DAMP = N_STATE + 1    # dissipated by structural damping, int q'^T C q' dt
A_CORK = N_STATE + 2    # dissipated by the cork damper, int c s'^2 dt
A_FRIC = N_STATE + 3    # dissipated by Coulomb friction while slipping
A_CONSTR = N_STATE + 4  # work of the normal and sticking contact forces (ideally 0)
A_FRIC_P = N_STATE + 5  # A_FRIC_P + k: the part of A_FRIC dissipated at point k + 1
N_AUG = A_FRIC_P + 4

# --- contact (docs/model.md §7) ---------------------------------------------------
N_POINTS = 4
# Geometry record cg (2 N_POINTS, N_CG): rows G1..G4 are the gaps g_k, rows
# T1..T4 the tangential coordinates tau_k; columns the value, gradient with
# respect to (s, v, psi) and Hessian (upper triangle).
CG_G = 0                     # row CG_G + k: gap of point k + 1 (cm)
CG_T = N_POINTS              # row CG_T + k: tangential coordinate of point k + 1 (cm)
CG_VAL = 0
CG_DS, CG_DV, CG_DPSI = 1, 2, 3
CG_HSS, CG_HSV, CG_HSP, CG_HVV, CG_HVP, CG_HPP = 4, 5, 6, 7, 8, 9
N_CG = 10

# Contact sets (points 0-based), in the order of docs/model.md §7: set k of regimes
# 2k - 1 (stick) and 2k (slip).  -1 marks no point.
N_SETS = 9
SET_FIRST = (-1, 0, 1, 2, 3, 0, 0, 1, 1)
SET_SECOND = (-1, -1, -1, -1, -1, 2, 3, 2, 3)
CONTACT_CODE = (0, 1, 2, 3, 4, 13, 14, 23, 24)
N_REGIMES = 2 * N_SETS - 1

# Regime record rg (N_RG,): the regime being integrated (input) and the
# contact forces of the last right-hand side (output).
RG_SET = 0       # contact set index 0..8
RG_STICK = 1     # 1.0 sticking, 0.0 slipping
RG_SIGN = 2      # slipping: sign of tau' of the set's points (+1 or -1)
RG_LN = 3        # RG_LN + k: normal force lambda_n of point k + 1 (dyn), 0 if open
RG_LT = RG_LN + N_POINTS   # sticking: tangential force lambda_t (dyn)
RG_VGRAV = RG_LT + 1       # gravitational energy of the last state (erg)
RG_ARM = RG_VGRAV + 1      # RG_ARM + k: an open gap's impact fires at g_k < -rg[RG_ARM + k] (cm)
N_RG = RG_ARM + N_POINTS

# Constraint work array cw (N_CW, N_CW_COLS): up to 4 constraint rows A (the
# normal and tangential rows of two points), their force directions B (A when
# sticking; W_n - mu sigma W_t when slipping), the columns X = M^-1 B^T, a
# small dense system D lambda = c; then the impact law's Delassus matrix G,
# rates u, impulses P, modes and friction coefficients, and its scratch rows
# (workbench.core.impact_law).  Rows A, B, X use the first N_DOF columns.
MAX_ROWS = 4
CW_A = 0
CW_B = CW_A + MAX_ROWS
CW_X = CW_B + MAX_ROWS
CW_D = CW_X + MAX_ROWS       # rows CW_D..: D in columns 0..3, c in column 4, lambda in 5
CW_C_COL, CW_L_COL = MAX_ROWS, MAX_ROWS + 1
CW_G = CW_D + MAX_ROWS       # rows CW_G..CW_G + 3: G in columns 0..3
CW_U = CW_G + MAX_ROWS       # u- (cm/s) of the impact rows
CW_P = CW_U + 1              # impulses P (dyn s)
CW_MODES = CW_P + 1          # per point: impact_law.OPEN, STICK, SLIP_POS, SLIP_NEG
CW_MU = CW_MODES + 1         # per point: mu
CW_PTS = CW_MU + 1           # the impact set's points (0-based), -1 for none
CW_LOSS = CW_PTS + 1         # per point of the set: kinetic energy its impulses removed (erg)
N_LAW = 23                   # scratch rows of the impact law
N_LAW_COLS = 18              # its columns: Lemke's tableau of 8 unknowns
CW_LAW = CW_LOSS + 1
N_CW = CW_LAW + N_LAW
N_CW_COLS = N_LAW_COLS

# Event values ev (N_EV_ROWS, N_EV): every event function changes sign from
# + to - when its event happens; functions not watched in a regime are +1.
# Rows: values at the step's start, end, a trial point, the earliest point
# found past an event (HI); gap rates at the start, end and trial point;
# (EV_MIN) the smallest value of each event function over a step's stages;
# (EV_NOISE) the error each function may carry (a dip inside a step counts
# only below minus it; zeros for the fixed-step method).
EV_START, EV_END, EV_TRY, EV_HI, EV_RATE_START, EV_RATE_END, EV_RATE_TRY, EV_MIN, EV_NOISE = range(9)
N_EV_ROWS = 9
EV_GAP = 0                   # EV_GAP + k: open gap g_k (impact); rates hold g_k'
EV_LAMBDA = EV_GAP + N_POINTS  # EV_LAMBDA + k: lambda_n of active point k (separation)
EV_STICK = EV_LAMBDA + N_POINTS  # mu_s sum lambda_n - |lambda_t| (stick -> slip)
EV_SLIP = EV_STICK + 1           # sigma tau' of the set's first point (slip -> stick)
N_EV = EV_SLIP + 1
EV_NAMES = ("gap1", "gap2", "gap3", "gap4", "lambda_n1", "lambda_n2", "lambda_n3", "lambda_n4",
            "stick_margin", "slip_rate")

# Event log (max_events, N_LOG)
KIND_START, KIND_IMPACT, KIND_SEPARATION, KIND_STICK_SLIP, KIND_SLIP_STICK = 0, 1, 2, 3, 4
EVENT_KINDS = ("start", "impact", "separation", "stick-slip", "slip-stick")
LOG_T = 0        # time (s)
LOG_KIND = 1     # KIND_*
LOG_FROM = 2     # regime before
LOG_TO = 3       # regime after
LOG_POINT = 4    # the point whose event it was (1..4), 0 for none
LOG_P = 5        # LOG_P + k: normal impulse of point k + 1 (dyn s)
LOG_PT = LOG_P + N_POINTS    # tangential impulse (dyn s)
LOG_DKE = LOG_PT + 1         # kinetic energy lost (erg)
LOG_DKE_P = LOG_DKE + 1      # LOG_DKE_P + k: the part lost at point k + 1 (erg)
N_LOG = LOG_DKE_P + N_POINTS

# Run statistics st (N_ST,)
ST_MAX_PEN = 0       # largest penetration -g of an open gap at an accepted state (cm)
ST_MAX_DRIFT = 1     # largest |g| of an active gap after its projection (cm)
ST_N_EVENTS = 2
ST_N_IMPACTS = 3
ST_E_IMPACT = 4      # kinetic energy lost in impacts (erg)
ST_T = 5             # time reached (s)
ST_STEP = 6          # steps completed
ST_N_ACCUM = 7       # accumulations of impacts closed by a full-set impact (docs/model.md §7)
ST_E_ACCUM = 8       # kinetic energy those impacts removed (erg; also in ST_E_IMPACT)
ST_N_INCONSISTENT = 9    # states with no consistent regime resolved by the impact law
ST_E_INCONSISTENT = 10   # kinetic energy those impulses removed (erg; also in ST_E_IMPACT)
ST_N_UNRESOLVED = 11     # states left in the least violated regime
ST_N_STEPPED = 12    # steps taken by Moreau-Jean time-stepping (event flood)
ST_E_STEPPED = 13    # kinetic energy its impulses removed (erg; also in ST_E_IMPACT)
ST_S_MIN = 14        # smallest slide s at an accepted step (cm)
ST_S_MAX = 15        # largest slide s (cm)
ST_T_IMPACT = 16     # time of the last impact (s)
ST_MAX_CORRECTION = 17   # largest |g| of an active gap before its projection (cm)
ST_T_MAX_PEN = 18    # time of the largest penetration (s)
ST_PEN_WHERE = 19    # where it was found: 10 x (1 event bracket, 2 step end) + point (0..3)
ST_FLOOD_T0 = 20     # start of the window in which events are counted for a flood (s)
ST_FLOOD_N = 21      # events in that window
ST_STEPPED_UNTIL = 22    # Moreau-Jean time-stepping runs until this time (s) after a flood
ST_E_IMPACT_P = 23   # ST_E_IMPACT_P + k: the part of ST_E_IMPACT lost at point k + 1 (erg)
ST_N_PAST_END = ST_E_IMPACT_P + 4   # _step_past reached the step's end
ST_N_PAST_END_UNCROSSED = ST_N_PAST_END + 1   # ... where event e's function had not crossed
ST_PAST_INFO = ST_N_PAST_END_UNCROSSED + 1   # t, h, e, f_start, f_end, theta0, lo
N_ST = ST_PAST_INFO + 7

# --- the error-controlled integration (workbench.core.adaptive) ----------------
# Controller record ctl (N_CTL,): its state between calls and its statistics.
CTL_STEPS = 1        # accepted steps
CTL_WORK = 2         # steps tried (accepted and rejected)
CTL_INTERVALS = 3    # accepted steps (the summary's "intervals")
CTL_REJECTED = 4     # rejected steps
CTL_H_MIN = 5        # smallest accepted step (s)
CTL_H_MAX = 6        # largest accepted step (s)
CTL_ERR_MAX = 7      # largest error estimate of an accepted step, over the tolerance
CTL_T_ERR_MAX = 8    # the start of that step (s)
CTL_N_FLOOR = 9      # steps accepted at the smallest size above the tolerance
CTL_F_SCALE = 10     # largest total normal contact force at a step's end (dyn)
CTL_ARG_ERR_MAX = 11     # what set CTL_ERR_MAX: a component of (q, q'), N_STATE + an event,
                         # or N_STATE + N_EV an event's time
CTL_REJECTED_EVENTS = 12  # rejections set by an event function or an event's time
CTL_LEVELS = 13      # CTL_LEVELS + j: steps accepted in (dt / 2^(j+1), dt / 2^j] (j = 0: above)
N_CTL_LEVELS = 10
# Sums of squares of the accepted steps' local estimates (not over the
# tolerance): the largest relative error of a position q_i (over its scale)
# per step, and each event's time error (s).
CTL_Q_SSQ = CTL_LEVELS + N_CTL_LEVELS
CTL_T_SSQ = CTL_Q_SSQ + 1
# The next step to try (s; 0 before the first) and the last accepted
# estimate over the tolerance (the PI controller's memory), between calls.
CTL_H_NEXT = CTL_T_SSQ + 1
CTL_ERR_PREV = CTL_H_NEXT + 1
N_CTL = CTL_ERR_PREV + 1
# Error scales scale (2, N_STATE): row SCALE_FLOOR the smallest scale of each
# component of (q, q'), row SCALE_PEAK its largest |value| so far.
SCALE_FLOOR, SCALE_PEAK = 0, 1
N_SCALE_ROWS = 2
# Steps accepted at the smallest size above the tolerance, floor_log
# (capacity, N_FLOOR): where, the regimes at its ends, events (0), the
# estimate over the tolerance, and Moreau-Jean steps (0).
FL_T0, FL_T1, FL_FROM, FL_TO, FL_EVENTS, FL_ERR, FL_STEPPED = range(7)
N_FLOOR = 7

# Signals stored at the output rate (out_sig columns), CGS units.
SIGNALS = ("force1", "hammer", "strain1", "strain2", "accel1", "accel2", "accel3", "tip_y",
           "gap1", "gap2", "gap3", "gap4", "lambda_n1", "lambda_n2", "lambda_n3", "lambda_n4",
           "lambda_t", "regime",
           "e_kin", "e_elastic", "e_gravity", "e_cork",
           "w_excitation", "d_structural", "d_cork", "d_friction", "d_impact", "w_constraint",
           "d_friction1", "d_friction2", "d_friction3", "d_friction4",
           "d_impact1", "d_impact2", "d_impact3", "d_impact4")
SIGNAL_UNITS = ("dyn", "dyn", "-", "-", "cm/s^2", "cm/s^2", "cm/s^2", "cm",
                "cm", "cm", "cm", "cm", "dyn", "dyn", "dyn", "dyn", "dyn", "-") + ("erg",) * 18
SIG_FORCE1 = SIGNALS.index("force1")
SIG_HAMMER = SIGNALS.index("hammer")
SIG_STRAIN1 = SIGNALS.index("strain1")
SIG_STRAIN2 = SIGNALS.index("strain2")
SIG_ACCEL1 = SIGNALS.index("accel1")
SIG_ACCEL2 = SIGNALS.index("accel2")
SIG_ACCEL3 = SIGNALS.index("accel3")
SIG_TIP_Y = SIGNALS.index("tip_y")
SIG_GAP = SIGNALS.index("gap1")
SIG_LN = SIGNALS.index("lambda_n1")
SIG_LT = SIGNALS.index("lambda_t")
SIG_REGIME = SIGNALS.index("regime")
SIG_E_KIN = SIGNALS.index("e_kin")
SIG_E_ELA = SIGNALS.index("e_elastic")
SIG_E_GRAV = SIGNALS.index("e_gravity")
SIG_E_CORK = SIGNALS.index("e_cork")
SIG_W_EXT = SIGNALS.index("w_excitation")
SIG_D_STRUCT = SIGNALS.index("d_structural")
SIG_D_CORK = SIGNALS.index("d_cork")
SIG_D_FRIC = SIGNALS.index("d_friction")
SIG_D_IMPACT = SIGNALS.index("d_impact")
SIG_W_CONSTR = SIGNALS.index("w_constraint")
SIG_D_FRIC_P = SIGNALS.index("d_friction1")      # + k: point k + 1's part of d_friction
SIG_D_IMPACT_P = SIGNALS.index("d_impact1")      # + k: point k + 1's part of d_impact
N_SIG = len(SIGNALS)
