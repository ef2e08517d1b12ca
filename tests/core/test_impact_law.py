"""Moreau's impact law (workbench.core.impact_law) alone, without the model's geometry.

Closed forms: the oblique plastic impact of a ball, a rigid rod landing flat on
two supports, and Housner's rocking block.  A hypothesis test over random
Delassus matrices checks every complementarity condition, that kinetic energy
never rises, and agreement with an independent slow LCP solve (below: every
complementary basis of the Stewart-Trinkle LCP, solved by least squares in NumPy).
"""
import itertools

import numpy as np
import pytest
from hypothesis import example, assume, given, settings, strategies as st

from workbench.core import layout as ly
from workbench.core.impact_law import (FOUND_ENUMERATION, NOT_FOUND, OPEN, SLIP_NEG, SLIP_POS,
                                       STICK, energy_change, eval_impact, lemke_impact)


def delassus(W, Minv):
    return W @ Minv @ W.T


def check_conditions(G, u, mu, m, P, tol=1e-7):
    """Assert Moreau's law at every point: plastic, in the cone, slip opposed by friction."""
    up = u + G @ P
    scale_u = max(np.abs(u).max(), 1e-12)
    scale_p = max(np.abs(P).max(), scale_u / max(np.abs(np.diag(G)).max(), 1e-12))
    for i in range(m):
        pn, pt = P[2 * i], P[2 * i + 1]
        un, ut = up[2 * i], up[2 * i + 1]
        assert pn >= -tol * scale_p
        assert un >= -tol * scale_u
        assert abs(pn * un) <= tol * scale_p * scale_u          # 0 <= u_n+ _|_ P_n >= 0
        assert abs(pt) <= mu[i] * pn + tol * scale_p              # the cone
        if abs(ut) > tol * scale_u:                               # post-impact slip
            assert pt == pytest.approx(-mu[i] * pn * np.sign(ut), abs=tol * scale_p)
    return up


# --- closed forms -------------------------------------------------------------------------

@pytest.mark.parametrize("vn, vt, mu", [(-2.0, 3.0, 0.3), (-2.0, 0.5, 0.3), (-1.0, -4.0, 0.5),
                                        (-3.0, 0.0, 0.2), (-1.0, 2.0, 0.0)])
def test_ball_oblique_plastic_impact(vn, vt, mu):
    """A ball at e = 0: v_t+ = sign(v_t) max(|v_t| - mu |v_n|, 0), v_n+ = 0 (Stronge 2000, §3)."""
    mass = 2.5
    G = np.eye(2) / mass
    u = np.array([vn, vt])
    source, P, modes = eval_impact(G, u, np.array([mu]), 1)
    assert source == FOUND_ENUMERATION
    up = check_conditions(G, u, [mu], 1, P)
    assert up[0] == pytest.approx(0.0, abs=1e-12)
    assert up[1] == pytest.approx(np.sign(vt) * max(abs(vt) - mu * abs(vn), 0.0), abs=1e-12)
    assert modes[0] == (STICK if abs(vt) <= mu * abs(vn) else (SLIP_POS if vt > 0 else SLIP_NEG))


def rod(mass=2.0, inertia=0.5, a=1.0):
    """A rod (x, y, theta) with supports under x = -a (point 1) and x = +a (point 2), flat."""
    W = np.array([[0.0, 1.0, -a], [1.0, 0.0, 0.0], [0.0, 1.0, a], [1.0, 0.0, 0.0]])
    return W, np.diag([1 / mass, 1 / mass, 1 / inertia])


@pytest.mark.parametrize("xd, yd, thd", [(0.7, -1.0, 0.1), (0.0, -2.0, -0.5), (0.3, -1.0, 0.0)])
def test_rod_landing_flat_stops_dead(xd, yd, thd):
    """Both closed-form impulses >= 0: the rod stops dead (y' = theta' = 0), x' loses mu sum P_n / m.

    Sum P_n = -m y', a (P_2 - P_1) = -I theta' (impulse-momentum of the rigid rod).
    """
    mass, inertia, a, mu = 2.0, 0.5, 1.0, 0.5
    W, Minv = rod(mass, inertia, a)
    qd = np.array([xd, yd, thd])
    p1 = 0.5 * (-mass * yd + inertia * thd / a)
    p2 = 0.5 * (-mass * yd - inertia * thd / a)
    assert p1 >= 0 and p2 >= 0
    G = delassus(W, Minv)
    source, P, _ = eval_impact(G, W @ qd, np.array([mu, mu]), 2)
    check_conditions(G, W @ qd, [mu, mu], 2, P)
    qd_plus = qd + Minv @ W.T @ P
    assert qd_plus[1:] == pytest.approx([0.0, 0.0], abs=1e-12)
    assert [P[0], P[2]] == pytest.approx([p1, p2], rel=1e-10)
    assert qd_plus[0] == pytest.approx(np.sign(xd) * max(abs(xd) - mu * (p1 + p2) / mass, 0.0),
                                       abs=1e-12)


def test_rod_landing_rotating_rocks_about_one_support():
    """One closed-form impulse < 0: only point 1 takes the impact and the rod rocks about it.

    Angular momentum about point 1 is conserved: (I + m a^2) w+ = I theta' + m a y'
    (sticking at point 1, mu large); point 2 leaves.
    """
    mass, inertia, a, mu = 2.0, 0.5, 1.0, 5.0
    W, Minv = rod(mass, inertia, a)
    qd = np.array([0.0, -0.2, 3.0])
    assert 0.5 * (-mass * qd[1] - inertia * qd[2] / a) < 0
    G = delassus(W, Minv)
    source, P, modes = eval_impact(G, W @ qd, np.array([mu, mu]), 2)
    up = check_conditions(G, W @ qd, [mu, mu], 2, P)
    w_plus = (inertia * qd[2] + mass * a * qd[1]) / (inertia + mass * a * a)
    qd_plus = qd + Minv @ W.T @ P
    assert qd_plus[2] == pytest.approx(w_plus, rel=1e-10)
    assert list(modes) == [STICK, OPEN] and up[2] > 0 and P[2] == 0.0


@pytest.mark.parametrize("b, h", [(0.2, 1.0), (0.5, 1.5), (1.0, 2.0)])
def test_housner_rocking_block(b, h):
    """Housner (1963): a block rocking onto its other corner keeps r = 1 - 1.5 sin^2 alpha of w.

    Uniform block 2b x 2h, I_cm = m (b^2 + h^2) / 3, alpha = atan(b / h), plastic impact
    without slip; at the flat position rotating about corner 2 at w-, corner 1 lands.
    """
    mass = 3.0
    inertia = mass * (b * b + h * h) / 3.0
    Minv = np.diag([1 / mass, 1 / mass, 1 / inertia])
    # points rho_1 = (-b, -h), rho_2 = (b, -h): normal row (0, 1, rho_x), tangential (1, 0, -rho_y)
    W = np.array([[0.0, 1.0, -b], [1.0, 0.0, h], [0.0, 1.0, b], [1.0, 0.0, h]])
    w = 1.7
    qd = np.array([-h * w, -b * w, w])          # about corner 2: v_cm = w z x (-b, h)
    G = delassus(W, Minv)
    u = W @ qd
    assert u[2] == pytest.approx(0.0, abs=1e-12) and u[0] < 0
    source, P, modes = eval_impact(G, u, np.array([2.0, 2.0]), 2)
    check_conditions(G, u, [2.0, 2.0], 2, P)
    qd_plus = qd + Minv @ W.T @ P
    alpha = np.arctan(b / h)
    assert qd_plus[2] / w == pytest.approx(1.0 - 1.5 * np.sin(alpha) ** 2, rel=1e-10)
    assert modes[1] == OPEN


# --- random Delassus matrices against an independent LCP solve --------------------------------

def lcp_matrix(G, u, mu, m):
    """Stewart & Trinkle's LCP w = A z + q, per point z = (P_n, beta+, beta-, slip speed)."""
    n = 4 * m
    A = np.zeros((n, n))
    q = np.zeros(n)
    for i, j in itertools.product(range(m), range(m)):
        gnn, gnt = G[2 * i, 2 * j], G[2 * i, 2 * j + 1]
        gtn, gtt = G[2 * i + 1, 2 * j], G[2 * i + 1, 2 * j + 1]
        A[4 * i, 4 * j:4 * j + 3] = [gnn, gnt, -gnt]
        A[4 * i + 1, 4 * j:4 * j + 3] = [gtn, gtt, -gtt]
        A[4 * i + 2, 4 * j:4 * j + 3] = [-gtn, -gtt, gtt]
    for i in range(m):
        A[4 * i + 1, 4 * i + 3] = A[4 * i + 2, 4 * i + 3] = 1.0
        A[4 * i + 3, 4 * i:4 * i + 3] = [mu[i], -1.0, -1.0]
        q[4 * i:4 * i + 3] = [u[2 * i], u[2 * i + 1], -u[2 * i + 1]]
    return A, q


def slow_lcp_solutions(G, u, mu, m):
    """Every complementary basis of the LCP with a solution: the impulses P of each.

    For a basis (z_i > 0 allowed, w_i = 0 on it; z_i = 0, w_i >= 0 off it)
    the equalities are solved by least squares; when they leave a
    one-dimensional family (dependent rows) the family is searched for a
    member with z >= 0 and w >= 0 (an interval of its parameter).
    """
    A, q = lcp_matrix(G, u, mu, m)
    n = A.shape[0]
    tol = 1e-9 * max(1.0, np.abs(q).max(), np.abs(A).max())
    out = []
    for basis in itertools.product((0, 1), repeat=n):
        on = np.array(basis, dtype=bool)
        idx = np.flatnonzero(on)
        z = np.zeros(n)
        if idx.size:
            sub = A[np.ix_(on, idx)]
            z_b, *_ = np.linalg.lstsq(sub, -q[on], rcond=None)
            if np.abs(sub @ z_b + q[on]).max() > tol:
                continue                                  # the equalities have no solution
            _, sv, vt = np.linalg.svd(sub)
            null = vt[np.sum(sv > 1e-10 * max(sv.max(), 1e-300)):]
            z[idx] = z_b
            if len(null) == 1:
                d = np.zeros(n)
                d[idx] = null[0]
                # conditions c + a d_c >= 0: z on the basis, w off it
                c = np.concatenate([z[idx], (A @ z + q)[~on]])
                dc = np.concatenate([d[idx], (A @ d)[~on]])
                lo = max([-ci / di for ci, di in zip(c, dc) if di > 1e-12] + [-np.inf])
                hi = min([-ci / di for ci, di in zip(c, dc) if di < -1e-12] + [np.inf])
                fixed_ok = all(ci >= -tol for ci, di in zip(c, dc) if abs(di) <= 1e-12)
                if not fixed_ok or lo > hi + tol:
                    continue
                a = 0.0 if lo <= 0.0 <= hi else (lo if np.isfinite(lo) else hi)
                z = z + a * d
            elif len(null) > 1:
                continue
        w = A @ z + q
        if z.min() >= -tol and w.min() >= -tol:
            P = np.zeros(2 * m)
            for i in range(m):
                P[2 * i] = z[4 * i]
                P[2 * i + 1] = z[4 * i + 1] - z[4 * i + 2]
            out.append(P)
    return out


@st.composite
def impact_problems(draw, physical_rates=True):
    """(G, u, mu, m) of random contact rows W and mass matrix M: G = W M^-1 W^T; u the rates
    W q' of a velocity q' (as in a run), or with ``physical_rates=False`` drawn freely (then
    possibly outside G's range when G is singular, where no kinetic energy is defined)."""
    m = draw(st.sampled_from([1, 2]))
    ndof = draw(st.sampled_from([3, 5]))
    rows = np.array(draw(st.lists(st.floats(-2, 2, allow_subnormal=False), min_size=2 * m * ndof,
                                  max_size=2 * m * ndof)))
    W = rows.reshape(2 * m, ndof)
    # contact normals are directions (|grad g| = 1 in the joint): no vanishing normal row
    assume(all(np.linalg.norm(W[2 * i]) > 0.1 for i in range(m)))
    flat = m == 2 and draw(st.booleans())
    if flat:                                   # a flat double contact: dependent tangential rows
        W[3] = W[1]
    # the normal rows independent (no pair of opposite faces, as 1 with 2 or 3 with 4):
    # the frictionless problem is solvable (Delassus block G_nn positive definite)
    normals = W[[0, 2]] if m == 2 else W[[0]]
    sv = np.linalg.svd(normals, compute_uv=False)
    assume(sv.min() > 0.05 * sv.max())
    # all rows dependent or independent by a margin, as the model's (rank 3 with
    # sigma_3 / sigma_1 > 0.1, tests/core/test_contact.py): between round-off and that margin
    # the law's rank decisions (LAW_RANK_TOL) meet impulses of 1e5 against rates of 1e-5,
    # and a point whose tangential row equals its normal row has no solution for rates
    # off G's range by round-off (G = [[1, 1], [1, 1]], u = (-2.2e-16, 0), mu = 1)
    sv = np.linalg.svd(W, compute_uv=False)
    assume(np.all((sv < 1e-12 * sv.max()) | (sv > 1e-3 * sv.max())))
    # and each point's normal and tangential rows independent, as the model's
    for i in range(m):
        sv = np.linalg.svd(W[[2 * i, 2 * i + 1]], compute_uv=False)
        assume(sv.min() > 1e-3 * sv.max())
    diag = np.array(draw(st.lists(st.floats(0.2, 5), min_size=ndof, max_size=ndof)))
    mix = np.array(draw(st.lists(st.floats(-0.3, 0.3, allow_subnormal=False), min_size=ndof * ndof,
                                 max_size=ndof * ndof))).reshape(ndof, ndof)
    M = np.diag(diag) + mix @ mix.T
    G = W @ np.linalg.inv(M) @ W.T
    if physical_rates:
        qd = np.array(draw(st.lists(st.floats(-3, 3, allow_subnormal=False), min_size=ndof,
                                    max_size=ndof)))
        u = W @ qd
    else:
        u = np.array(draw(st.lists(st.floats(-3, 3, allow_subnormal=False), min_size=2 * m,
                                   max_size=2 * m)))
    mu = np.array(draw(st.lists(st.floats(0.0, 1.2), min_size=m, max_size=m)))
    return G, u, mu, m


def _satisfies(G, u, mu, m, P, tol):
    try:
        check_conditions(G, u, mu, m, P, tol=tol)
    except AssertionError:
        return False
    return True


@settings(max_examples=60, deadline=None)
@given(impact_problems())
@example((np.array([[2.0, 0.0, 4.0, 0.0], [0.0, 0.0, 0.0, 0.0], [4.0, 0.0, 9.0, 0.0],
                    [0.0, 0.0, 0.0, 4.0]]), np.array([0.0, 0.0, 0.0, 5.96046448e-08]),
          np.array([0.0, 0.0]), 2))
def test_random_delassus_against_slow_lcp(problem):
    """Rates of a velocity: the law finds a solution, every condition holds, the kinetic energy
    neither rises nor falls by more than the contacts' share of it (1/2 u^T G^+ u), and it is
    at least as dissipative as every solution of the exhaustive solve that satisfies the law's
    conditions to 1e-9 (that solve skips bases with a null space of dimension 2, so the law
    may find a more dissipative one)."""
    G, u, mu, m = problem
    source, P, _ = eval_impact(G, u, mu, m)
    assert source != NOT_FOUND
    check_conditions(G, u, mu, m, P, tol=1e-6)
    de = energy_change(G, u, P, m)
    scale = max(1e-12, float(np.abs(u).max() ** 2 / max(np.abs(np.diag(G)).max(), 1e-12)))
    slow = [p for p in slow_lcp_solutions(G, u, mu, m) if _satisfies(G, u, mu, m, p, 1e-9)]
    # the slow solve's least squares leave round-off of the size eps |G| |P|^2 in its energies
    # (4e-16 where u is 6e-8 and scale 1e-12)
    roundoff = 1e-14 * (1.0 + max(np.abs(G).max() * float(np.abs(p).max()) ** 2
                                  for p in [P, *slow]))
    tol = 1e-6 * scale + roundoff
    assert de <= 1e-9 * scale                                  # kinetic energy never rises
    visible = 0.5 * u @ np.linalg.pinv(G, rcond=1e-13, hermitian=True) @ u
    assert de >= -visible - tol                                # nor falls below zero
    if slow:
        assert de <= min(energy_change(G, u, p, m) for p in slow) + tol


@settings(max_examples=60, deadline=None)
@given(impact_problems(physical_rates=False))
# point 2's tangential row equals its normal row (G's block [[1, 1], [1, 1]]), its rates
# (-1, 0) are outside G's range and mu = 1: no impulse satisfies the law (P_n = 1 / (1 - mu)
# for mu < 1)
@example((np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 1.0],
                    [0.0, 0.0, 1.0, 1.0]]), np.array([0.0, 0.0, -1.0, 0.0]),
          np.array([0.0, 1.0]), 2))
# a flat double contact (equal tangential rows) whose tangential rates differ: along G's null
# direction P^T u + P^T G P / 2 is unbounded below, so no energy is compared here
@example((np.array([[1.0000001442248299, 1.0, 0.0, 1.0], [1.0, 2.0, 1.0, 2.0],
                    [0.0, 1.0, 1.0, 1.0], [1.0, 2.0, 1.0, 2.0]]), np.array([0.0, 0.0, 0.0, 1.0]),
          np.array([0.0, 1.0]), 2))
@example((np.ones((2, 2)), np.array([-3.74769908797976e-61, 0.0]), np.array([1.0]), 1))
def test_rates_outside_the_range_of_G(problem):
    """Rates no velocity has (outside G's range where G is singular; not in a run): whatever
    the law returns satisfies every condition, and NOT_FOUND (P = 0) only where the exhaustive
    solve finds no solution either (a point whose tangential row is parallel to its normal row
    under M^-1 with G_nn <= mu |G_nt| can have none)."""
    G, u, mu, m = problem
    source, P, _ = eval_impact(G, u, mu, m)
    if source == NOT_FOUND:
        # the law is homogeneous in u: posed at max |u| = 1, the exhaustive solve's
        # tolerances are relative to the rates (u = -3.7e-61 is an approach, not round-off)
        assert np.all(P == 0.0) and np.abs(u).max() > 0.0
        assert not slow_lcp_solutions(G, u / np.abs(u).max(), mu, m)
    else:
        check_conditions(G, u, mu, m, P, tol=1e-6)


def test_a_rank_two_flat_double_contact_gets_bounded_impulses():
    """Rates of a velocity (u = W q') against a flat double contact of rank 2 (found by
    hypothesis).  In the mode (stick, slip-) the slip's tangential row equals the stick's,
    so its slope along the null direction is round-off; read as a bound, it let the
    impulse run to P_n1 = 7.5e7 and round-off then made that the most dissipative.  The
    velocities stop, the impulses stay of the size u / |G|, and the energy falls by the
    contacts' share 1/2 u^T G^+ u, no more."""
    G = np.array([[0.011962890625, 0.109375, 0.109375, 0.109375], [0.109375, 1.0, 1.0, 1.0],
                  [0.109375, 1.0, 1.5625, 1.0], [0.109375, 1.0, 1.0, 1.0]])
    u = np.array([0.0, 0.0, -0.75, 0.0])
    mu = np.array([1.0, 0.0])
    source, P, _ = eval_impact(G, u, mu, 2)
    assert source == FOUND_ENUMERATION
    check_conditions(G, u, mu, 2, P, tol=1e-9)
    assert np.abs(u + G @ P).max() < 1e-12
    assert np.abs(P).max() < 10.0
    share = 0.5 * u @ np.linalg.pinv(G, rcond=1e-13) @ u
    assert energy_change(G, u, P, 2) == pytest.approx(-share, rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(impact_problems(physical_rates=False))
# rates at round-off scale: ties of the ratio test are relative to q's scale
@example((np.eye(2), np.array([0.0, 2.220446049250313e-16]), np.array([0.0]), 1))
@example((np.ones((2, 2)), np.array([0.0, 2.220446049250313e-16]), np.array([0.0]), 1))
# flat double contacts with a nearly singular G: pivoting can end on a basis of round-off
# values (impulses of 1e5 off the friction cone's edge, a closed point left approaching),
# which the law rejects
@example((np.array([[1.0000152587890625, -1.0, 0.0, -1.0], [-1.0, 2.125, -0.75, 2.125],
                    [0.0, -0.75, 0.5, -0.75], [-1.0, 2.125, -0.75, 2.125]]),
          np.array([0.0, 0.0, -1.0, 0.0]), np.array([1.0, 1.0]), 2))
@example((np.array([[1.000244140625, -1.0, 0.0, -1.0], [-1.0, 2.125, -0.75, 2.125],
                    [0.0, -0.75, 0.5, -0.75], [-1.0, 2.125, -0.75, 2.125]]),
          np.array([0.0, 0.0, -1.0, 0.0]), np.array([1.0, 0.0]), 2))
def test_lemke_fallback_solves_the_same_lcp(problem):
    """Whatever Lemke's method returns as a solution satisfies the law (it may also give up:
    it is the fallback of the enumeration)."""
    G, u, mu, m = problem
    lw = np.zeros((ly.N_LAW, ly.N_LAW_COLS))
    P = np.zeros(2 * m)
    if lemke_impact(G, u, mu, m, lw, P):
        check_conditions(G, u, mu, m, P, tol=1e-6)


def test_a_point_without_normal_mobility_gets_no_impulse():
    """A normal row that vanishes (a held direction; here with subnormal round-off): P = 0."""
    G = np.array([[0.0, -6.18e-310], [-6.18e-310, 0.944]])
    for u in ([1.0, 0.0], [-1.0, 0.5]):
        source, P, _ = eval_impact(G, np.array(u), np.array([1.0]), 1)
        assert np.all(np.isfinite(P))
        if u[0] >= 0:
            assert source != NOT_FOUND and np.all(P == 0.0)
