"""A slow, obviously-correct NumPy reference of the free-flight equations.

Same physics as the kernels (docs/model.md §4-6), coded independently, for the
tests (which check the kernels against it) and the benchmarks (the paper's
method, :mod:`workbench.reference.events`):

* positions are written as plain formulas of q, evaluated on *jets* that
  carry the value, the gradient d/dq (-> J and the angle rows a) and the
  first and second derivatives along q' (-> kappa = q'^T (d2 r/dq2) q', the
  acceleration with q'' = 0).  No Jacobian or convective term is derived by
  hand, so the kernel's hand-derived ones are checked against calculus;
* the foreshortening matrix Sigma(x) is integrated numerically (Gauss-
  Legendre, exact for its polynomial) instead of by the closed form;
* the equations of motion are solved by numpy.linalg.solve and integrated
  by scipy's solve_ivp.
"""
from __future__ import annotations

import functools

import numpy as np
from scipy.integrate import solve_ivp

N = 9


class Jet:
    """A batch of values with gradient (., 9) and directional derivatives d1, d2."""

    __slots__ = ("v", "g", "d1", "d2")
    __array_ufunc__ = None        # make numpy arrays defer to Jet's reflected operators

    def __init__(self, v, g, d1, d2):
        self.v, self.g, self.d1, self.d2 = v, g, d1, d2

    @staticmethod
    def const(c):
        c = np.atleast_1d(np.asarray(c, dtype=float))
        z = np.zeros(c.shape)
        return Jet(c, np.zeros(c.shape + (N,)), z, z)

    @staticmethod
    def coord(q, qd, i):
        g = np.zeros((1, N))
        g[0, i] = 1.0
        return Jet(np.array([q[i]]), g, np.array([qd[i]]), np.zeros(1))

    @staticmethod
    def lift(x):
        return x if isinstance(x, Jet) else Jet.const(x)

    def __add__(self, o):
        if not isinstance(o, Jet) and np.ndim(o) == 0:     # a constant moves the value only
            return Jet(self.v + o, self.g, self.d1, self.d2)
        o = Jet.lift(o)
        return Jet(self.v + o.v, self.g + o.g, self.d1 + o.d1, self.d2 + o.d2)

    __radd__ = __add__

    def __neg__(self):
        return Jet(-self.v, -self.g, -self.d1, -self.d2)

    def __sub__(self, o):
        return self + (-o)

    def __rsub__(self, o):
        return Jet.lift(o) - self

    def __mul__(self, o):
        if not isinstance(o, Jet):          # constants (one, or one per batch entry) scale
            c = np.asarray(o, dtype=float)
            return Jet(self.v * c, self.g * c[..., None], self.d1 * c, self.d2 * c)
        return Jet(self.v * o.v, self.g * o.v[..., None] + self.v[..., None] * o.g,
                   self.d1 * o.v + self.v * o.d1,
                   self.d2 * o.v + 2.0 * self.d1 * o.d1 + self.v * o.d2)

    __rmul__ = __mul__


def jsin(x):
    c, s = np.cos(x.v), np.sin(x.v)
    return Jet(s, c[..., None] * x.g, c * x.d1, c * x.d2 - s * x.d1 ** 2)


def jcos(x):
    c, s = np.cos(x.v), np.sin(x.v)
    return Jet(c, -s[..., None] * x.g, -s * x.d1, -s * x.d2 - c * x.d1 ** 2)


def rotate(angle, px, py):
    """R(angle) (px, py) for jets."""
    c, s = jcos(angle), jsin(angle)
    return c * px - s * py, s * px + c * py


def hermite(xi, L):
    """N1, N2 and their x-derivatives at xi = x/L (docs/model.md §4)."""
    return (3 * xi ** 2 - 2 * xi ** 3, L * (xi ** 3 - xi ** 2),
            6 * (xi - xi ** 2) / L, 3 * xi ** 2 - 2 * xi)


def sigma(xi, L, n=8):
    """Sigma(x) = int_0^x n' n'^T by Gauss-Legendre quadrature; (..., 3) = S00, S01, S11."""
    xi = np.atleast_1d(xi)
    return _sigma(tuple(xi.tolist()), float(L), n)


@functools.lru_cache(maxsize=64)
def _sigma(xi, L, n):
    t, w = np.polynomial.legendre.leggauss(n)
    xi = np.array(xi)
    out = np.zeros(xi.shape + (3,))
    for k, x in enumerate(xi):
        s = 0.5 * x * (t + 1.0)
        _, _, d1, d2 = hermite(s, L)
        ww = 0.5 * x * L * w
        out[k] = [np.sum(ww * d1 * d1), np.sum(ww * d1 * d2), np.sum(ww * d2 * d2)]
    return out


def beam_point(q, qd, i0, xi, L, x_offset):
    """A beam point (batch over xi) in the beam's root frame, as jets, and its slope jet."""
    w, phi, u = (Jet.coord(q, qd, i0 + k) for k in range(3))
    n1, n2, dn1, dn2 = hermite(xi, L)
    S = sigma(xi, L)
    f = 0.5 * (S[:, 0] * w * w + 2.0 * S[:, 1] * w * phi + S[:, 2] * phi * phi)
    x = x_offset + xi * L + xi * u - f
    y = n1 * w + n2 * phi
    slope = dn1 * w + dn2 * phi
    return x, y, slope


class Reference:
    """Free-flight equations of motion of one parameter set, in NumPy."""

    def __init__(self, p, free=range(N), excitation=None, n_gauss=6):
        self.p = p
        if p.cork_law.form != "power":
            raise NotImplementedError(f"the reference equations have the power-law cork only, "
                                      f"not the {p.cork_law.form!r} form of cork = {p.cork!r}")
        self.free = np.array(sorted(free))
        self.excitation = excitation or (lambda t: 0.0)
        t, w = np.polynomial.legendre.leggauss(n_gauss)
        self.xi = 0.5 * (t + 1.0)
        self.wA = 0.5 * p.l_a * w
        self.wB = 0.5 * p.l_b * w
        self.K, self.C = self._linear()

    def _linear(self):
        p = self.p
        K = np.zeros((N, N))
        C = np.zeros((N, N))
        for i0, L, E, I, A, mu, zeta in ((0, p.l_a, p.e_a, p.rho_i_a / p.rho, p.mu_a / p.rho, p.mu_a, p.zeta_a),
                                         (6, p.l_b, p.e_b, p.rho_i_b / p.rho, p.mu_b / p.rho, p.mu_b, p.zeta_b)):
            blk = np.zeros((3, 3))
            blk[:2, :2] = E * I / L ** 3 * np.array([[12, -6 * L], [-6 * L, 4 * L * L]])
            blk[2, 2] = E * A / L
            omega1 = 3.516 / L ** 2 * np.sqrt(E * I / mu)
            K[i0:i0 + 3, i0:i0 + 3] = blk
            C[i0:i0 + 2, i0:i0 + 2] = 2 * zeta / omega1 * blk[:2, :2]
            # the axial coordinate's own mode at the same zeta (docs/model.md §5)
            C[i0 + 2, i0 + 2] = 2 * zeta * np.sqrt(blk[2, 2] * p.axial_mass("a" if i0 == 0 else "b"))
        K[4, 4] = p.k_v
        K[5, 5] = p.k_psi
        return K, C

    def elements(self, q, qd):
        """(mass, rotary inertia, x jet, y jet, angle jet) of each batch of mass elements."""
        p = self.p
        out = []
        xa, ya, sa = beam_point(q, qd, 0, self.xi, p.l_a, 0.0)
        out.append((p.mu_a * self.wA, p.rho_i_a * self.wA, xa, ya, sa))
        xt, yt, _ = beam_point(q, qd, 0, np.array([1.0]), p.l_a, 0.0)
        phi_a = Jet.coord(q, qd, 1)
        s, v, psi = (Jet.coord(q, qd, k) for k in (3, 4, 5))
        dx, dy = rotate(phi_a, s + p.x_in, v)
        x4, y4 = xt + dx, yt + dy
        cx, cy = rotate(phi_a, Jet.const(p.c3), Jet.const(0.0))
        out.append((np.array([p.m3]), np.array([p.i3]), xt + cx, yt + cy, phi_a))
        alpha4 = phi_a + psi
        lx, ly = rotate(alpha4, Jet.const(p.loose_cm), Jet.const(0.0))
        out.append((np.array([p.m4]), np.array([p.i4]), x4 + lx, y4 + ly, alpha4))
        xis = np.append(self.xi, 1.0)
        on = 1.0 if p.tip_mass else 0.0
        bx, by, bs = beam_point(q, qd, 6, xis, p.l_b, p.l4)
        gx, gy = rotate(alpha4, bx, by)
        out.append((np.append(p.mu_b * self.wB, on * p.m6), np.append(p.rho_i_b * self.wB, on * p.i6),
                    x4 + gx, y4 + gy, alpha4 + bs))
        return out

    def inertia(self, q, qd):
        """M, h = sum m J^T kappa, gravity force and gravitational energy."""
        M = np.zeros((N, N))
        h = np.zeros(N)
        Qg = np.zeros(N)
        Vg = 0.0
        g = self.p.g
        for m, rot, x, y, ang in self.elements(q, qd):
            M += np.einsum("k,ki,kj->ij", m, x.g, x.g) + np.einsum("k,ki,kj->ij", m, y.g, y.g)
            M += np.einsum("k,ki,kj->ij", rot, ang.g, ang.g)
            h += np.einsum("k,ki->i", m * x.d2, x.g) + np.einsum("k,ki->i", m * y.d2, y.g)
            h += np.einsum("k,ki->i", rot * ang.d2, ang.g)
            Qg -= g * np.einsum("k,ki->i", m, y.g)
            Vg += g * np.sum(m * y.v)
        return M, h, Qg, Vg

    def cork(self, s, sd):
        """Cork spring and damper plus the slot's end stop (docs/model.md §6)."""
        n, k, c, _ = self.p.cork_law
        over = max(abs(s) - self.p.s_travel, 0.0)
        return k * np.sign(s) * abs(s) ** n + self.p.k_stop * np.sign(s) * over + c * sd

    def generalized(self, t, q, qd):
        """M and the generalized force Q - h (applied, elastic, damping, cork, inertial)."""
        M, h, Q, _ = self.inertia(q, qd)
        Q = Q - self.K @ q - self.C @ qd
        Q[3] -= self.cork(q[3], qd[3])
        # shaker: the vertical force at force1 does work F dy
        _, yf, _ = beam_point(q, qd, 0, np.array([self.p.x_force / self.p.l_a]), self.p.l_a, 0.0)
        Q += self.excitation(t) * yf.g[0]
        return M, Q - h

    def accelerations(self, t, q, qd):
        M, F = self.generalized(t, q, qd)
        f = self.free
        qdd = np.zeros(N)
        qdd[f] = np.linalg.solve(M[np.ix_(f, f)], F[f])
        return qdd

    def tip_y(self, q):
        """Height of beam B's tip (cm), the last beam B element."""
        return float(self.elements(q, np.zeros(N))[-1][3].v[-1])

    def rhs(self, t, y):
        return np.concatenate([y[N:], self.accelerations(t, y[:N], y[N:])])

    def energy(self, y):
        q, qd = y[:N], y[N:]
        M, _, _, Vg = self.inertia(q, qd)
        n, k, _, _ = self.p.cork_law
        over = max(abs(q[3]) - self.p.s_travel, 0.0)
        return (0.5 * qd @ M @ qd + 0.5 * q @ self.K @ q + Vg + k * abs(q[3]) ** (n + 1) / (n + 1)
                + 0.5 * self.p.k_stop * over ** 2)

    def integrate(self, y0, t_eval, rtol=1e-11, atol=1e-13, method="DOP853"):
        sol = solve_ivp(self.rhs, (t_eval[0], t_eval[-1]), y0, method=method, t_eval=t_eval,
                        rtol=rtol, atol=atol)
        assert sol.success, sol.message
        return sol.y.T, sol.nfev


def shaker(ex):
    """The shaker force F(t) (dyn) of a workbench excitation array (docs/model.md §8).

    Sine F0 sin(2 pi f t) or linear chirp F0 sin(2 pi (f0 t + (f1 - f0) t^2 / 2T)),
    times the soft start 1/2 (1 - cos(pi t / t_ramp)) before t_ramp; written
    out again here, from the array's documented layout, not the kernel's code.
    Other force shapes raise NotImplementedError.
    """
    from ..core import excitation as cx
    kind, amp, t_ramp = int(ex[cx.X_KIND]), float(ex[cx.X_AMP]), float(ex[cx.X_RAMP])
    if kind not in (cx.EXC_SINE, cx.EXC_CHIRP):
        raise NotImplementedError(f"the reference drives only sine and chirp excitations, "
                                  f"not the force shape {kind} (workbench.core.excitation)")

    def force(t):
        if kind == cx.EXC_SINE:
            phase = ex[cx.X_FREQ] * t
        else:
            f0 = ex[cx.X_F0]
            phase = f0 * t + (ex[cx.X_F1] - f0) * t * t / (2.0 * ex[cx.X_T_SWEEP])
        soft = 1.0 if t >= t_ramp else 0.5 * (1.0 - np.cos(np.pi * max(t, 0.0) / t_ramp))
        return amp * soft * np.sin(2.0 * np.pi * phase)
    return force
