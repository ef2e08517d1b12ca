"""Natural frequencies of the model linearised about the undeformed state or, joint locked,
about the static equilibrium under gravity.

``about="undeformed"``: at q = 0, q' = 0 the linearised free vibration is
M(0) x'' + K_lin x = 0 with M(0) the kernel's mass matrix and K_lin the
elastic stiffness plus the cork's tangent stiffness at s = 0 (k for the
linear and static models, 0 for the quadratic and cubic ones) and the
optional loose-body springs; gravity's geometric stiffness is not included
(the customary unloaded linearisation).  The step policy takes these
(:func:`linear_eigenvalues`).

``about="static"`` (joint locked): at the static equilibrium q_s
(:func:`workbench.model.statics.static_equilibrium`) the mass matrix is
M(q_s) and the stiffness the tangent -dQ/dq of the generalised force at rest
(elastic, gravity, cork; the equilibrium's own kernel), by central
differences: what a hammer test of the rig at rest measures.  A free joint
rests on its contacts there, whose linearisation is a constrained one, not
done here.

Joint ``locked`` holds s = v = psi = 0; joint ``free`` leaves them to the
cork alone, so v and psi (and s with a quadratic or cubic cork) have no
stiffness and give rigid-body modes at 0 Hz.
"""
from __future__ import annotations

import functools

import numpy as np

from . import packing as mdl
from ..core import layout as ly
from ..core.cork import FORMS as CORK_FORMS, cork_stiffness
from ..core.dynamics import eval_inertia
from .params import ParameterError, Parameters


#: Where the model may be linearised.
ABOUT = ("undeformed", "static")
#: The central-difference step of the tangent stiffness, relative to a coordinate's size
#: (at least 1 cm or 1 rad).
FD_REL = 1e-6


def linear_matrices(p: Parameters, joint: str = "locked", about: str = "undeformed",
                    joint_at: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """M and K restricted to the moving coordinates (module docstring), and their names.
    ``joint_at`` (q, 9 values; about "static" only): the locked joint's coordinates s, v, psi
    are held at its values (default: centred, 0), e.g. where a run's contacts hold them."""
    if joint not in ("locked", "free"):
        raise ParameterError(f"joint must be 'locked' or 'free', got {joint!r}")
    if about not in ABOUT:
        raise ParameterError(f"about must be one of {ABOUT}, got {about!r}")
    if about == "static":
        return _about_static(p, joint, joint_at)
    model = mdl.build(p, fixed=mdl.JOINT if joint == "locked" else ())
    work = mdl.make_work()
    zero = np.zeros(ly.N_DOF)
    eval_inertia(zero, zero, model, work)
    M = work.mat[ly.MAT_M].copy()
    K = model.kc[ly.KC_K].copy()
    law = p.cork_law
    K[ly.S, ly.S] += cork_stiffness(0.0, CORK_FORMS.index(law.form), law.n, law.k)
    f = model.free
    return M[np.ix_(f, f)], K[np.ix_(f, f)], [ly.COORD_NAMES[i] for i in f]


def _about_static(p: Parameters, joint: str, joint_at: np.ndarray | None = None):
    """M(q_s) and the tangent stiffness at the static equilibrium, joint locked (at
    ``joint_at``'s s, v, psi if given)."""
    from ..core.equilibrium import static_state
    from .drives import none
    from .statics import static_equilibrium
    if joint != "locked":
        raise ParameterError("linearising about the static equilibrium needs the joint locked "
                             "(a free joint rests on its contacts): use about='undeformed'")
    q_s = (static_equilibrium(p, 0.0, mdl.JOINT).q if joint_at is None else
           static_equilibrium(p, 0.0, mdl.JOINT, s0=float(joint_at[ly.S]),
                              q_guess=np.asarray(joint_at, float)[:ly.N_DOF]).q)
    model, work, ex = mdl.build(p, fixed=mdl.JOINT), mdl.make_work(), none()
    f = model.free
    case = (q_s.copy(), f, np.zeros(0, dtype=np.int64), False, 0.0)
    q, Q, res, energy = (np.zeros(ly.N_DOF), np.zeros(ly.N_DOF), np.zeros(len(f)),
                         np.zeros(4))

    def force(z):
        static_state(z, case, model, ex, work, q, Q, res, energy)
        return Q[f].copy()
    z0 = q_s[f].copy()
    K = np.empty((len(f), len(f)))
    for j in range(len(f)):
        h = FD_REL * max(1.0, abs(z0[j]))
        up, down = z0.copy(), z0.copy()
        up[j] += h
        down[j] -= h
        K[:, j] = -(force(up) - force(down)) / (2.0 * h)
    eval_inertia(q_s, np.zeros(ly.N_DOF), model, work)
    M = work.mat[ly.MAT_M][np.ix_(f, f)].copy()
    return M, 0.5 * (K + K.T), [ly.COORD_NAMES[i] for i in f]


#: Eigenvalues below this fraction of the largest are rigid-body modes (0 Hz).
RIGID_REL = 1e-12


def _to_hz(lam: np.ndarray) -> np.ndarray:
    lam = np.where(lam < RIGID_REL * np.max(np.abs(lam)), 0.0, lam)
    return np.sqrt(lam) / (2.0 * np.pi)


def natural_frequencies(p: Parameters, joint: str = "locked",
                        about: str = "undeformed") -> np.ndarray:
    """Natural frequencies (Hz), ascending; rigid-body modes give exactly 0."""
    import scipy.linalg         # here, not at import: a run needs only linear_eigenvalues
    M, K, _ = linear_matrices(p, joint, about)
    return _to_hz(scipy.linalg.eigh(K, M, eigvals_only=True))


def mode_shapes(p: Parameters, joint: str = "locked",
                about: str = "undeformed") -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Frequencies (Hz), mass-normalised mode shapes (columns) and coordinate names."""
    import scipy.linalg
    M, K, names = linear_matrices(p, joint, about)
    lam, vec = scipy.linalg.eigh(K, M)
    return _to_hz(lam), vec, names


#: The largest condition number of M accepted: beyond it double precision
#: cannot separate the modes (a mass of 1e300 g beside one of 1e2 g).
MAX_MASS_CONDITION = 1e12


def _check_conditioned(M, K, joint) -> None:
    """M and K finite, M positive definite and well conditioned, else a ParameterError."""
    if not (np.all(np.isfinite(M)) and np.all(np.isfinite(K))):
        raise ParameterError(f"the linear model (joint {joint}) has non-finite mass or stiffness "
                             "entries: a mass, length or modulus is out of scale")
    eig = np.linalg.eigvalsh(0.5 * (M + M.T))
    if not eig[0] > 0.0 or eig[-1] / eig[0] > MAX_MASS_CONDITION:
        raise ParameterError(f"the mass matrix (joint {joint}) is not positive definite or is "
                             f"ill-conditioned (eigenvalues {eig[0]:.3g} .. {eig[-1]:.3g}): "
                             "a mass or length is out of scale")


def linear_damping(p: Parameters, joint: str = "locked") -> np.ndarray:
    """The damping matrix C (dyn s/cm and kin) on the moving coordinates: the beams' and the
    cork's dampers (docs/model.md §5-6), in the order of :func:`linear_matrices`."""
    model = mdl.build(p, fixed=mdl.JOINT if joint == "locked" else ())
    C = model.kc[ly.KC_C][np.ix_(model.free, model.free)].copy()
    if ly.S in model.free:
        i = list(model.free).index(ly.S)
        C[i, i] += p.cork_law.c
    return C


def _state_matrix(p: Parameters, joint: str, about: str = "undeformed",
                  joint_at: np.ndarray | None = None) -> np.ndarray:
    M, K, _ = linear_matrices(p, joint, about, joint_at)
    C = linear_damping(p, joint)
    _check_conditioned(M, K, joint)
    n = len(M)
    Minv = np.linalg.inv(M)
    return np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])


#: A damped eigenvalue belongs to an undamped mode when their |lambda| differ by at most this.
MODE_MATCH_REL = 0.05


def damping_ratios(p: Parameters, joint: str = "locked",
                   about: str = "undeformed") -> tuple[np.ndarray, np.ndarray]:
    """Natural frequencies (Hz, as :func:`natural_frequencies`) and each mode's damping ratio.

    The ratio of mode i is -Re(lambda) / |lambda| of the damped system's eigenvalue
    (upper half plane, not taken by a lower mode) nearest to its omega_i (within
    MODE_MATCH_REL), the exact modal
    damping of the linearised model even where the cork's damper makes the damping
    non-proportional; a mode with no such eigenvalue (overdamped) takes the projection
    phi_i^T C phi_i / (2 omega_i) of its mass-normalised shape.  Rigid-body modes (0 Hz)
    have NaN.
    """
    f, shapes, _ = mode_shapes(p, joint, about)
    lam = np.linalg.eigvals(_state_matrix(p, joint, about))
    lam = lam[lam.imag > 0.0]
    C = linear_damping(p, joint)
    zeta = np.full(len(f), np.nan)
    free = np.ones(len(lam), dtype=bool)
    for i, fi in enumerate(f):
        if fi == 0.0:
            continue
        omega = 2.0 * np.pi * fi
        miss = np.where(free, np.abs(np.abs(lam) - omega), np.inf)
        j = int(np.argmin(miss)) if len(lam) else -1
        if j >= 0 and miss[j] <= MODE_MATCH_REL * omega:
            zeta[i] = -lam[j].real / abs(lam[j])
            free[j] = False
        else:
            zeta[i] = shapes[:, i] @ C @ shapes[:, i] / (2.0 * omega)
    return f, zeta


@functools.lru_cache(maxsize=4096)
def linear_eigenvalues(p: Parameters) -> np.ndarray:
    """Eigenvalues (1/s) of the damped linear system, joint free and locked (concatenated).

    Computed once per parameter set (the array is read-only; a study checks its
    points, then plans them: the cache holds the largest designs' sets).

    They set the explicit integrator's step (:func:`workbench.model.step_policy.default_dt`):
    the fastest are the beams' axial modes, damped at their own zeta
    (docs/model.md §5): -246 +- 2.05e4 j 1/s with the tip mass, -321 +- 3.54e4 j
    without.
    """
    lam = np.concatenate([np.linalg.eigvals(_state_matrix(p, joint))
                          for joint in ("free", "locked")])
    lam.flags.writeable = False
    return lam

