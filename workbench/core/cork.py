"""The cork's spring laws (docs/model.md §6, seed §4.3), jit-compiled.

A cork law is a functional form with two shape parameters (n, k) plus a
linear damper c s' (added by :func:`workbench.core.dynamics.cork_force`).
``FORMS`` names the forms; a form's index there is its code in the
parameter array (``P_CORK_FORM``).  Each form gives its spring force, its
potential (the energy balance) and its tangent stiffness (the linear
model's modes, :mod:`workbench.model.modes`).

    power:  F = k sign(s) |s|^n,  V = k |s|^(n+1) / (n+1),  dF/ds = n k |s|^(n-1)
            (k in g/(s^2 cm^(n-1)); Table 6's linear, quadratic and cubic laws)

An unknown code gives NaN, which the integrator reports as a failure.
"""
import math

import numba as nb

from .config import JIT_INLINE

#: The forms, in the order of their codes.
FORMS = ("power",)
POWER = 0


@nb.njit(**JIT_INLINE)
def power_spring(s, n, k):
    """k sign(s)|s|^n (dyn); products for the paper's n = 1, 2, 3 (a power costs ~20x)."""
    a = abs(s)
    if n == 1.0:
        return k * s
    if n == 2.0:
        return k * s * a
    if n == 3.0:
        return k * s * a * a
    return k * math.copysign(a ** n, s)


@nb.njit(**JIT_INLINE)
def cork_spring(s, form, n, k):
    """The cork's spring force (dyn) at the slide s (cm), for the law (form, n, k)."""
    if int(form) == POWER:
        return power_spring(s, n, k)
    return math.nan


@nb.njit(**JIT_INLINE)
def cork_potential(s, form, n, k):
    """The cork spring's potential (erg) at the slide s (cm): V(s) with V(0) = 0."""
    if int(form) == POWER:
        return k * abs(s) ** (n + 1.0) / (n + 1.0)
    return math.nan


@nb.njit(**JIT_INLINE)
def cork_stiffness(s, form, n, k):
    """The tangent stiffness dF/ds (g/s^2) at the slide s (cm)."""
    if int(form) == POWER:
        return n * k * abs(s) ** (n - 1.0)
    return math.nan
