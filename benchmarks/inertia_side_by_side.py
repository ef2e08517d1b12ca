"""The frame-sum mass matrix against the element loop it replaced, in one process.

    python benchmarks/inertia_side_by_side.py

The baseline is the element-by-element assembly of M, h and gravity as it
was before core/inertia.py (kept here only as the measurement's baseline):
each of the 15 mass elements through ``kinematics.element`` and a 9 x 9
outer product.  Both are timed alternately, 9 rounds of 100 000 calls
each, and the medians compared; the agreement at one state is printed too.
"""
import time

import numba as nb
import numpy as np

from workbench.model import packing as mdl
from workbench.core import layout as ly
from workbench.core.dynamics import assemble_inertia
from workbench.core.kinematics import compute_frames, element, n_elements
from workbench.model.params import Parameters


@nb.njit(inline="always")
def element_loop(q, qd, P, tab, rec, mat, vec):
    M, h, Q, g = mat[ly.MAT_M], vec[ly.VEC_H], vec[ly.VEC_Q], P[ly.P_GRAV]
    M[:, :] = 0.0
    h[:] = 0.0
    Q[:] = 0.0
    compute_frames(q, qd, P, tab, rec)
    pt = rec[ly.REC_POINT]
    v_grav = 0.0
    for k in range(n_elements(P)):
        m, rot, _ = element(k, q, qd, P, tab, rec)
        for i in range(ly.N_DOF):
            mjx, mjy, ra = m * pt[ly.JX + i], m * pt[ly.JY + i], rot * pt[ly.AA + i]
            if mjx == 0.0 and mjy == 0.0 and ra == 0.0:
                continue
            for j in range(i, ly.N_DOF):
                M[i, j] += mjx * pt[ly.JX + j] + mjy * pt[ly.JY + j] + ra * pt[ly.AA + j]
            h[i] += mjx * pt[ly.KX] + mjy * pt[ly.KY]
            Q[i] -= mjy * g
        v_grav += m * g * pt[ly.RY]
    for i in range(ly.N_DOF):
        for j in range(i):
            M[i, j] = M[j, i]
    return v_grav


@nb.njit
def repeat(which, n, y, P, tab, rec, mat, vec):
    acc = 0.0
    for _ in range(n):
        y[0] += 1e-12                     # defeat hoisting
        if which == 0:
            acc += element_loop(y[:9], y[9:], P, tab, rec, mat, vec)
        else:
            acc += assemble_inertia(y[:9], y[9:], P, tab, rec, mat, vec)
    return acc


def main(rounds=9, calls=100_000):
    for tip in (True, False):
        model, work = mdl.build(Parameters(tip_mass=tip)), mdl.make_work()
        args = (model.P, model.tab, work.rec, work.mat, work.vec)
        rng = np.random.default_rng(1)
        y = np.concatenate([rng.normal(size=9) * 0.1, rng.normal(size=9)])
        out = []
        for which in (0, 1):
            repeat(which, 1, y.copy(), *args)
            out.append((work.mat[ly.MAT_M].copy(), work.vec[ly.VEC_H].copy()))
        dm = np.abs(out[0][0] - out[1][0]).max() / np.abs(out[0][0]).max()
        dh = np.abs(out[0][1] - out[1][1]).max() / np.abs(out[0][1]).max()
        times = ([], [])
        for _ in range(rounds):
            for which in (0, 1):
                t0 = time.perf_counter()
                repeat(which, calls, y, *args)
                times[which].append((time.perf_counter() - t0) / calls * 1e6)
        old, new = np.median(times[0]), np.median(times[1])
        print(f"tip mass {'on ' if tip else 'off'}: element loop {old:.2f} us, frame sums "
              f"{new:.2f} us, ratio {old / new:.2f}; |dM|/|M| {dm:.1e}, |dh|/|h| {dh:.1e}")


if __name__ == "__main__":
    main()
