"""An independent Euler-Bernoulli finite-element model of the locked structure.

Written for the tests only, from textbook element matrices, sharing nothing
with the workbench's kernels but the parameter values.  Bending only: in the
straight, undeformed configuration axial and transverse motion decouple.

Element matrices (Przemieniecki, *Theory of Matrix Structural Analysis*,
1968; Cook et al., *Concepts and Applications of FEA*, 4th ed., §16.3) for a
beam element of length l with nodal DOFs (w1, t1, w2, t2):

    K = EI/l^3 [[12, 6l, -12, 6l], [6l, 4l^2, -6l, 2l^2], [-12, -6l, 12, -6l], [6l, 2l^2, -6l, 4l^2]]
    M = mu l/420 [[156, 22l, 54, -13l], [22l, 4l^2, 13l, -3l^2], [54, 13l, 156, -22l], [-13l, -3l^2, -22l, 4l^2]]
    M_rot = rhoI/(30 l) [[36, 3l, -36, 3l], [3l, 4l^2, -3l, -l^2], [-36, -3l, 36, -3l], [3l, -l^2, -3l, 4l^2]]

The locked joint is rigid: the joint body (m3, I3 at c3), the loose body
(m4, I4 at x_in + c4) and beam B's root (at x_in + l4) hang on beam A's tip
node; a rigid point at axial offset e moves by w + e t and turns by t.  The
tip mass (m6, I6) sits at beam B's tip node.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg


def element_matrices(length, ei, mu, rho_i):
    """Stiffness and consistent mass (with rotary inertia) of one element."""
    l = length
    k = ei / l ** 3 * np.array([[12, 6 * l, -12, 6 * l], [6 * l, 4 * l * l, -6 * l, 2 * l * l],
                                [-12, -6 * l, 12, -6 * l], [6 * l, 2 * l * l, -6 * l, 4 * l * l]])
    m = mu * l / 420 * np.array([[156, 22 * l, 54, -13 * l], [22 * l, 4 * l * l, 13 * l, -3 * l * l],
                                 [54, 13 * l, 156, -22 * l], [-13 * l, -3 * l * l, -22 * l, 4 * l * l]])
    m += rho_i / (30 * l) * np.array([[36, 3 * l, -36, 3 * l], [3 * l, 4 * l * l, -3 * l, -l * l],
                                      [-36, -3 * l, 36, -3 * l], [3 * l, -l * l, -3 * l, 4 * l * l]])
    return k, m


def rigid_mass(m, inertia, offset):
    """Mass matrix on a node's (w, t) of a rigid mass at axial offset (cm)."""
    return np.array([[m, m * offset], [m * offset, m * offset ** 2 + inertia]])


def locked_structure(p, n_el=40):
    """Global K and M of the locked structure, DOFs (w, t) of every free node.

    Node 0 of beam A is clamped.  Beam A nodes 1..n_el, then beam B nodes
    1..n_el; beam B's node 0 is slaved to beam A's tip by the rigid joint.
    """
    n = 2 * n_el + 2 * n_el
    K = np.zeros((n, n))
    M = np.zeros((n, n))

    def dofs_a(node):          # global indices of beam A node's (w, t), or None (clamped)
        return None if node == 0 else [2 * (node - 1), 2 * (node - 1) + 1]

    tip_a = dofs_a(n_el)
    e_root_b = p.x_in + p.l4

    def add(kel, mel, left, right, left_map=None):
        # left_map: 2x2 transformation from the tip DOFs to a slaved node's DOFs
        T = np.zeros((4, n))
        for local, node_dofs, tmap in ((0, left, left_map), (2, right, None)):
            if node_dofs is None:
                continue
            if tmap is None:
                T[local, node_dofs[0]] = 1.0
                T[local + 1, node_dofs[1]] = 1.0
            else:
                T[local:local + 2, node_dofs] = tmap
        K[:] += T.T @ kel @ T
        M[:] += T.T @ mel @ T

    ka, ma = element_matrices(p.l_a / n_el, p.e_a * p.inertia_a, p.mu_a, p.rho_i_a)
    for e in range(n_el):
        add(ka, ma, dofs_a(e), dofs_a(e + 1))
    kb, mb = element_matrices(p.l_b / n_el, p.e_b * p.inertia_b, p.mu_b, p.rho_i_b)
    off_b = 2 * n_el

    def dofs_b(node):
        return [off_b + 2 * (node - 1), off_b + 2 * (node - 1) + 1]

    slave = np.array([[1.0, e_root_b], [0.0, 1.0]])
    add(kb, mb, tip_a, dofs_b(1), left_map=slave)
    for e in range(1, n_el):
        add(kb, mb, dofs_b(e), dofs_b(e + 1))
    ix = np.ix_(tip_a, tip_a)
    M[ix] += rigid_mass(p.m3, p.i3, p.c3)
    M[ix] += rigid_mass(p.m4, p.i4, p.x_in + p.loose_cm)
    if p.tip_mass:
        tip_b = dofs_b(n_el)
        M[np.ix_(tip_b, tip_b)] += rigid_mass(p.m6, p.i6, 0.0)
    return K, M


def locked_frequencies(p, n_el=40):
    """Bending natural frequencies (Hz) of the locked structure, ascending."""
    K, M = locked_structure(p, n_el)
    lam = scipy.linalg.eigh(K, M, eigvals_only=True)
    return np.sqrt(lam) / (2 * np.pi)


def cantilever_frequencies(length, ei, mu, rho_i=0.0, n_el=40):
    """A uniform clamped-free beam by the same elements (Hz)."""
    k, m = element_matrices(length / n_el, ei, mu, rho_i)
    n = 2 * n_el
    K = np.zeros((n + 2, n + 2))
    M = np.zeros((n + 2, n + 2))
    for e in range(n_el):
        s = slice(2 * e, 2 * e + 4)
        K[s, s] += k
        M[s, s] += m
    lam = scipy.linalg.eigh(K[2:, 2:], M[2:, 2:], eigvals_only=True)
    return np.sqrt(lam) / (2 * np.pi)
