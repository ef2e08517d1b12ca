"""Cubic Hermite beam shapes and the foreshortening matrix (docs/model.md §4).

A clamped beam of length L with tip deflection w, tip slope phi and tip
elongation u has, with xi = x / L::

    w(x) = N1 w + N2 phi,    N1 = 3 xi^2 - 2 xi^3,    N2 = L (xi^3 - xi^2)
    u(x) = xi u
    f(x) = 1/2 b^T Sigma(x) b,  b = (w, phi),  Sigma(x) = int_0^x n' n'^T

where f is the foreshortening (the axial pull-back of a point by the bending
of the beam inboard of it) and n' = (N1', N2').  Sigma is integrated exactly:

    Sigma_00 = (36 / L) (xi^3/3 - xi^4/2 + xi^5/5)
    Sigma_01 = 6 (-3 xi^5/5 + 5 xi^4/4 - 2 xi^3/3)
    Sigma_11 = L (9 xi^5/5 - 3 xi^4 + 4 xi^3/3)

At the tip Sigma = [[6/(5L), -1/10], [-1/10, 2L/15]], the familiar geometric
stiffness of a cubic beam element.
"""
import numba as nb

from .config import JIT
from . import layout as ly


@nb.njit(**JIT)
def fill_shape_row(xi, length, weight, row):
    """Fill one shape-table row (layout ``T_*``) for the point x = xi * length.

    jit-compiled.  ``xi`` (-), ``length`` (cm), ``weight`` the quadrature
    length weight (cm, 0 for a sensor point); ``row`` float64 (N_TAB,).
    """
    L = length
    xi2 = xi * xi
    xi3 = xi2 * xi
    xi4 = xi3 * xi
    xi5 = xi4 * xi
    row[ly.T_XI] = xi
    row[ly.T_X] = xi * L
    row[ly.T_N1] = 3.0 * xi2 - 2.0 * xi3
    row[ly.T_N2] = L * (xi3 - xi2)
    row[ly.T_DN1] = 6.0 * (xi - xi2) / L
    row[ly.T_DN2] = 3.0 * xi2 - 2.0 * xi
    row[ly.T_DDN1] = (6.0 - 12.0 * xi) / (L * L)
    row[ly.T_DDN2] = (6.0 * xi - 2.0) / L
    row[ly.T_S00] = 36.0 / L * (xi3 / 3.0 - xi4 / 2.0 + xi5 / 5.0)
    row[ly.T_S01] = 6.0 * (-0.6 * xi5 + 1.25 * xi4 - 2.0 * xi3 / 3.0)
    row[ly.T_S11] = L * (1.8 * xi5 - 3.0 * xi4 + 4.0 * xi3 / 3.0)
    row[ly.T_WEIGHT] = weight
