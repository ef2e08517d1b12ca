"""Declared layouts of every array the kernels take.

The kernels see the model as a few flat arrays.  This module is the one place
that names their entries; nothing else hard-codes an index.

Generalised coordinates (MODEL.md §3, seed §2.1: three per beam, three in the
joint)::

    q = (w_A, phi_A, u_A,  s, v, psi,  w_B, phi_B, u_B)
         0    1      2     3  4  5     6    7      8

State ``y = (q, qdot)`` of length 18.
"""

# --- generalised coordinates -------------------------------------------------
W_A, PHI_A, U_A, S, V, PSI, W_B, PHI_B, U_B = range(9)
N_DOF = 9
N_STATE = 2 * N_DOF
COORD_NAMES = ("w_A", "phi_A", "u_A", "s", "v", "psi", "w_B", "phi_B", "u_B")
#: Units of each coordinate (CGS).
COORD_UNITS = ("cm", "rad", "cm", "cm", "cm", "rad", "cm", "rad", "cm")

# --- the flat parameter array P (CGS) ----------------------------------------
# Built by workbench.model.pack from a validated workbench.params.Parameters.
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
P_BETA_A = 10    # beam A stiffness-proportional damping (s)
P_BETA_B = 11    # beam B stiffness-proportional damping (s)
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
P_CORK_N = 28    # cork spring exponent n (-)
P_CORK_K = 29    # cork stiffness k (g/(s^2 cm^(n-1)))
P_CORK_C = 30    # cork damping c (g/s)
P_K_V = 31       # optional spring on v (g/s^2); 0 in the paper's model
P_K_PSI = 32     # optional spring on psi (g cm^2/s^2); 0 in the paper's model
P_X_FORCE = 33   # shaker position on beam A (cm)
P_C_STRAIN = 34  # distance from the neutral axis to the surface (cm)
P_N_GAUSS = 35   # Gauss points per beam (stored as a float)
N_PARAMS = 36

# --- shape-function tables ---------------------------------------------------
# One row per beam point (the Gauss points of a beam, or a sensor position):
# the Hermite shape functions of MODEL.md §4 and the foreshortening matrix
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

# --- excitation array EX -----------------------------------------------------
X_KIND = 0       # one of EXC_* below
X_AMP = 1        # force amplitude F0 (dyn)
X_FREQ = 2       # sine frequency (Hz)
X_F0 = 3         # chirp start frequency (Hz)
X_F1 = 4         # chirp end frequency (Hz)
X_T_SWEEP = 5    # chirp duration (s)
X_RAMP = 6       # soft-start ramp duration (s); 0 for none
N_EXC = 7

EXC_NONE = 0
EXC_SINE = 1
EXC_CHIRP = 2

# --- status codes ------------------------------------------------------------
OK = 0
ERR_NAN = 1
ERR_SINGULAR_MASS = 2
ERR_BAD_INPUT = 3

MESSAGES = {
    OK: "finished",
    ERR_NAN: "the state became NaN or infinite",
    ERR_SINGULAR_MASS: "the mass matrix is not positive definite",
    ERR_BAD_INPUT: "the kernel was given inconsistent array sizes",
}

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
N_RECS = 4

# --- work matrices and vectors -----------------------------------------------
KC_K, KC_C = 0, 1                # kc (2, 9, 9): stiffness, damping
MAT_M, MAT_CHOL = 0, 1           # mat (2, 9, 9): mass matrix, its Cholesky factor
VEC_H, VEC_Q, VEC_RHS = 0, 1, 2  # vec (3, 9): h = sum m J^T kappa, forces, Q - h
N_VEC = 3
STAGE_TMP, STAGE_CUR, STAGE_NEXT = 4, 5, 6   # stages (7, 18): k1..k4 then state buffers
N_STAGES = 7
