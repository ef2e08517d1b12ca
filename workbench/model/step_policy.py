"""The default step of a run, from the linear model's eigenvalues and a method's stability.

A fixed-step explicit Runge-Kutta method with tableau (A, b) multiplies a mode
exp(lambda t) by R(z) = 1 + z b^T (I - z A)^-1 1 per step (z = lambda dt): it is
stable where |R(z)| <= 1 (Hairer & Wanner II, §IV.2).  :func:`default_dt` is the
largest of NICE_STEPS at which a method is stable for every eigenvalue of the linear
model scaled by STABILITY_MARGIN; the controlled methods take RK4's as their base step
(their output lattice, and the unit of their largest step ``P_RK_STEP_FACTOR * dt``).
"""
from __future__ import annotations

import numpy as np

from . import drives
from .limits import STABILITY_MARGIN
from .params import Parameters
from .tableaus import RK4, Tableau

#: Steps :func:`default_dt` chooses from (s): 1 ms / n for n = 10 ... 200, so that each
#: divides 1 ms (every output rate that divides 1 kHz, and every whole number of ms).
NICE_STEPS = tuple(1e-3 / n for n in range(10, 201))
#: The largest default step (s): on the benchmark windows at 1e-4 s the tip
#: height is within 2.6e-5 of its range and the contact time shares within
#: 5e-6 of a converged run (docs/performance.md).
MAX_DEFAULT_DT = 1e-4


def amplification(tableau: Tableau, z) -> np.ndarray:
    """|R(z)| of an explicit Runge-Kutta tableau, R(z) = 1 + z b^T (I - z A)^-1 1, for
    z = lambda dt (an array).  A is strictly lower triangular, so (I - z A)^-1 1 is the
    stages' forward recursion k_i = 1 + z sum_j a_ij k_j."""
    z = np.asarray(z, dtype=complex)
    k = []
    for row in tableau.a:
        k.append(1.0 + z * sum(a_ij * k[j] for j, a_ij in enumerate(row)))
    return np.abs(1.0 + z * sum(b_i * k_i for b_i, k_i in zip(tableau.b, k)))


def rk4_amplification(z) -> np.ndarray:
    """|R(z)| of classical RK4, R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24 (z = lambda dt)."""
    return amplification(RK4, z)


def default_dt(p: Parameters, excitation: np.ndarray | None = None,
               tableau: Tableau = RK4) -> float:
    """The largest step of NICE_STEPS (at most MAX_DEFAULT_DT) at which ``tableau`` (by
    default RK4, the controlled methods' base step) is stable.

    Stable: |R(STABILITY_MARGIN lambda dt)| <= 1 for every eigenvalue lambda
    of :func:`workbench.model.modes.linear_eigenvalues`.  With the tip mass this
    is 1e-4 s (MAX_DEFAULT_DT; the fastest mode is -246 +- 2.05e4 j 1/s); without
    it 6.25e-5 s (1 ms / 16; -321 +- 3.54e4 j 1/s): the beams' lightly damped axial
    modes, near the imaginary axis where RK4 is stable to |lambda dt| = 2.83.  The
    drive may bound it (a hammer pulse gets at least PULSE_STEPS steps).
    """
    lam = STABILITY_MARGIN * eigenvalues(p)
    limit = MAX_DEFAULT_DT
    if excitation is not None:
        limit = min(limit, drives.of_array(excitation).dt_max(excitation))
    for dt in NICE_STEPS:
        if dt <= limit * (1.0 + 1e-12) and np.all(amplification(tableau, lam * dt) <= 1.0):
            return dt
    return NICE_STEPS[-1]


def eigenvalues(p: Parameters) -> np.ndarray:
    """The linear model's eigenvalues (1/s; :func:`workbench.model.modes.linear_eigenvalues`)."""
    from .modes import linear_eigenvalues  # scipy.linalg: imported when first needed
    return linear_eigenvalues(p)


def stability_limit(p: Parameters, tableau: Tableau = RK4) -> float:
    """The largest step (s) at which ``tableau`` (default RK4) is stable for the linear
    model's eigenvalues.

    No margin (:func:`default_dt` keeps STABILITY_MARGIN below it): a step
    above this grows the fastest mode without bound.
    """
    lam = eigenvalues(p)
    lo, hi = 0.0, 3.0 / float(np.abs(lam).max())
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if np.all(amplification(tableau, lam * mid) <= 1.0):
            lo = mid
        else:
            hi = mid
    return lo


def stepped_dt(p: Parameters) -> float:
    """The largest Moreau-Jean step (s) of the event-flood fallback (docs/model.md §7).

    The Moreau-Jean scheme (theta = 1/2) is explicit in the smooth forces,
    like leapfrog: stable for omega h < 2.  With STABILITY_MARGIN on the
    fastest linear mode: 7.8e-5 s with the tip mass (omega = 2.05e4 1/s),
    4.5e-5 s without (3.54e4 1/s), below RK4's default steps (1e-4, 6.25e-5 s).
    """
    return 2.0 / (STABILITY_MARGIN * float(np.abs(eigenvalues(p)).max()))
