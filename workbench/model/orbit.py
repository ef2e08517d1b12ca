"""Periodic responses of the sine-driven model by shooting, and their Floquet multipliers.

A periodic orbit of K drive periods T = K / f is a fixed point of the K-period map: the
state x = (q, q') at a drive phase (the section, 0 unless the state there is near an event:
then the next of PHASES) and its regime (contact set, stick or slip) such that integrating K
periods from x returns to x.  :func:`periodic_orbit` solves Phi(x) = x by
Newton's method from a guess (by default the closest return of a run of GUESS_PERIODS drive
periods from the static equilibrium, the drive's soft start over the first RAMP_PERIODS).

**Reduced coordinates.**  In a regime with closed contacts the state moves on the
constraint manifold: the closed points' gaps are zero and so are their rates, and a sticking
point's tangential rate (its tangential position is free: any position in the friction cone
holds).  The orbit is sought, and its monodromy taken, in coordinates of the manifold's
tangent space at x: orthonormal bases Nq of the null space of the normal rows and Nv of all
active rows W (q-space), positions q + Nq a and rates q' + Nv b - W^+ (dW[Nq a]) q' (the
correction keeps W(q) q' = 0 to first order).  Free flight: 18 coordinates; the stuck joint
(two points closed, sticking) 7 + 6 = 13.

**Monodromy.**  The Jacobian of the K-period map in those coordinates: by default from the
variational equations along the map's run with a saltation matrix at each of its events
(:mod:`workbench.model.monodromy`, in the full state, then reduced), about as costly as ten
periods of integration; by central finite differences of the map (``monodromy=
"finite-difference"``, 2 x dim integrations of K periods) where asked, or where the run has
no saltation matrices (Moreau-Jean steps, an event met tangentially; the orbit's message
says so).  Its eigenvalues are the Floquet multipliers (the reduced system's; the
constrained directions have none); the multipliers' error is estimated by the monodromy
again at CHECK_FACTOR times the tolerance and the state Jacobian's difference step
(variational; at a CHECK_FACTOR-th where that one is off by more than FINER_ABOVE) or the
map's difference step (finite differences) (``multiplier_error``, the largest shift of a
multiplier).  A variational monodromy that neither settles so (an event whose kind or regime
after it changes with the tolerance) is set beside the finite differences (checked by their
own step):
where they agree the error is the larger difference, else the finite differences' multipliers
are taken (``monodromy`` says so).  The orbit is stable when every
|multiplier| is below 1 by more than that, unstable when one is above 1 by more, and its
stability undetermined (``stable`` null, the message says so) in between; all but the
neutral one: where
friction holds the loose body, the orbit is one of a family (held at any position in the
cone: shifted along the slide it is still an orbit, the cork's pull aside), with a multiplier
1 along the body's tangential position, reported as ``neutral_multiplier`` and left out of
the stability (NEUTRAL_TOL).

**Residual.**  |Phi(x) - x| on the integrator's error scales (``core.error_scales``: each
component's largest |value| over the orbit, its partner's, or the floor from the gap) —
the orbit is found when the largest is at most ``newton_tol``; a Newton step that makes it
grow, or leaves the regime, is halved (BACKTRACK times at most).

**Grazing.**  An orbit on which an open point's gap has a minimum in time within GRAZE_REL
of the clearance of zero (it touches without closing) is flagged: its multipliers are not defined there (the map is not
differentiable), and the status says so.

Limits: only a sine drive (a forcing period) (docs/usage.md).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..core import excitation as cx
from ..core import layout as ly
from ..core.config import VAR_FD_REL
from ..core.contact import eval_geometry
from . import packing as mdl
from .limits import MONODROMY_METHODS
from .params import ParameterError, Parameters
from .regimes import SETS, contact_code, in_contact, is_stick, set_of

#: The guess: a run of GUESS_PERIODS drive periods from the static equilibrium, the first
#: RAMP_PERIODS a soft start, and its closest return: of its states at the section from period
#: RETURN_FROM on, the one the next K periods bring back nearest (largest difference on the
#: error scales, in the same regime), the run's nearest point to an orbit of K periods (the
#: close returns of Lathrop & Kostelich, Phys. Rev. A 40, 4028, 1989).  The state at the run's
#: end instead: at 83.7 N, 20 Hz Newton's method converges from 35 periods and not from 20,
#: 25, 30, 40 or 60; from the closest return of 40 it does, and at 42 Hz, 200 N too (6ba25b2).
GUESS_PERIODS = 40
RAMP_PERIODS = 5
RETURN_FROM = 10
#: The drive phases (fractions of a period) a section is tried at, in order: where the state
#: at one is near an event (the map ends in another regime), the next.
PHASES = (0.0, 0.25, 0.5, 0.75)
#: Newton's step is halved at most this many times while the residual grows.
BACKTRACK = 4
#: A Newton step whose period map fails is cut to move no reduced coordinate by more than
#: this many of its error scales (the largest |value| over the map's run): at 47 Hz, 1.016 mm,
#: 200 N a full step put the loose body 14 cm along its slot and 3.6 rad about.
MAX_STEP = 1.0
#: Newton: iterations at most, and the relative finite-difference step on the error scales.
MAX_NEWTON = 15
FD_REL = 1e-6
#: The integrator's tolerance for the period map (tighter than the Newton tolerance by 100).
MAP_TOL = 1e-9
#: The variational equations' tolerance on the error scales.  Measured on the period map at
#: 200 N from a 30-period run: the multipliers at 1e-6 are within 4e-6 of those at 1e-7 at
#: 45 Hz and 1e-7 at 20 Hz, at 855 and 1198 steps (the run's own: 804 and 1313); at 1e-7 the
#: forward-differenced Jacobian's noise makes 45 Hz take 4292.
VAR_TOL = 1e-6
#: The monodromy again with CHECK_FACTOR times the tolerance or the finite-difference step:
#: the multipliers' error estimate; where that differs by more than FINER_ABOVE from the
#: variational monodromy (the coarser run's own error: an event its steps place otherwise),
#: the estimate is the difference from the one at a CHECK_FACTOR-th instead.
CHECK_FACTOR = 10.0
FINER_ABOVE = 1e-3

#: |multiplier| below 1 - max(STABLE_MARGIN, its error) is stable, above 1 + that unstable.
STABLE_MARGIN = 1e-6
#: A multiplier this close to 1 moving the body's tangential position is the friction-held
#: family's (measured: 1 - 1e-9 on the stuck joint, 1 + 4e-4 with 15 stick-slip cycles a
#: period, 1 + 1e-4 to 3e-3 rocking at 200 N: the finite differences through the events).
NEUTRAL_TOL = 5e-3
#: An open gap within GRAZE_REL of the clearance of zero grazes.
GRAZE_REL = 1e-4
#: Samples a drive period of the orbit's record (the tip's amplitude, the gaps' minimum).
SAMPLES_PER_PERIOD = 400
#: A disturbance of a stable orbit falls to SETTLE of itself in log(SETTLE) / log|mu| orbit
#: periods, |mu| its largest deciding multiplier: how long a run started near it takes to
#: reach it (``settle_s``), the brute force's cost.
SETTLE = 1e-3


def settle_periods(mu: float) -> float:
    """Orbit periods for a disturbance along the multiplier of modulus ``mu`` (0 < mu < 1) to
    fall to SETTLE of itself; nan for any other modulus."""
    return float(np.log(SETTLE) / np.log(mu)) if 0.0 < mu < 1.0 else float("nan")


@dataclass
class Orbit:
    """A periodic orbit found (or the last iterate of a search that was not)."""

    status: str                       # "ok" (found), "not converged", "grazing", "failed"
    message: str
    period_s: float
    periods: int
    state: np.ndarray                 # (q, q') at the section's phase, (18,)
    regime: int
    residual: float
    newton_iterations: int
    multipliers: np.ndarray           # complex, largest modulus first
    stable: bool | None
    grazing: bool
    min_open_gap_cm: float
    events_per_period: dict
    contact_time_share: dict
    tip_amplitude_cm: float
    wall_s: float
    dimension: int
    history: list = field(default_factory=list)     # the residual after each Newton step
    neutral: complex | None = None    # the stuck position's multiplier (module docstring)
    monodromy: np.ndarray | None = None   # the K-period map's Jacobian, reduced coordinates
    responses: dict = field(default_factory=dict)   # amplitude and RMS of accel1-3 (cm/s²) and
                                                    # strain1-2 over the orbit; the tip's (cm)
                                                    # and strain1's lines at the drive frequency
                                                    # f (tip_h1_cm, strain1_h1) and at f / 2
                                                    # (tip_h0.5_cm, strain1_h0.5)
    tip_rms_cm: float = float("nan")
    multiplier_error: float = float("nan")   # the multipliers' error estimate (module docstring)
    phase: float = 0.0                # the section's drive phase (fraction of a period)
    monodromy_method: str = "variational"   # how the monodromy was taken (module docstring)

    def deciding(self) -> np.ndarray:
        """The multipliers that decide the stability: all but the neutral one."""
        if self.neutral is None:
            return self.multipliers
        i = int(np.argmin(np.abs(self.multipliers - self.neutral)))
        return np.delete(self.multipliers, i)

    def settle_s(self) -> float | None:
        """Time (s) in which a disturbance of this stable orbit falls to SETTLE of itself along
        its slowest multiplier; None unless the orbit is stable."""
        mu = self.deciding()
        if self.stable is not True or not len(mu):
            return None
        return settle_periods(float(np.abs(mu).max())) * self.period_s

    def slowest_hz(self) -> float | None:
        """The slowest multiplier's frequency (Hz): its angle over 2 pi times the orbit's period,
        in [0, 1 / (2 period_s)] (a mode's frequency is this modulo 1 / period_s); None
        without multipliers."""
        mu = self.deciding()
        if not len(mu):
            return None
        return abs(float(np.angle(mu[np.argmax(np.abs(mu))]))) / (2 * np.pi * self.period_s)

    def to_dict(self) -> dict:
        """The JSON object of ``workbench orbit --json``."""
        return {"status": self.status, "message": self.message, "period_s": self.period_s,
                "periods": self.periods, "residual": self.residual,
                "newton_iterations": self.newton_iterations,
                "multipliers": [[float(m.real), float(m.imag)] for m in self.multipliers],
                "stable": self.stable, "multiplier_error": self.multiplier_error,
                "settle_s": self.settle_s(), "slowest_multiplier_hz": self.slowest_hz(),
                "grazing": self.grazing,
                "min_open_gap_cm": self.min_open_gap_cm,
                "events_per_period": self.events_per_period,
                "contact_time_share": self.contact_time_share,
                "tip_amplitude_cm": self.tip_amplitude_cm, "tip_rms_cm": self.tip_rms_cm,
                "phase": self.phase,
                **self.responses, "wall_s": self.wall_s,
                "regime": self.regime, "contact_code": int(contact_code(self.regime)),
                "dimension": self.dimension, "monodromy": self.monodromy_method,
                "neutral_multiplier": (None if self.neutral is None
                                       else [self.neutral.real, self.neutral.imag]),
                "residual_history": self.history, "state": self.state.tolist()}


def sine_of(drive) -> tuple[np.ndarray, float]:
    """The drive as a sine's excitation array without a soft start, and its frequency (Hz);
    ``drive`` an excitation array (``drives.sine``) or settings {"drive": "sine", ...}."""
    from . import drives
    ex = drives.excitation_array(drive) if isinstance(drive, dict) else np.array(drive, float)
    if int(ex[cx.X_KIND]) != cx.EXC_SINE:
        raise ParameterError("a periodic orbit needs a sine drive (a forcing period); "
                             f"got the drive {drives.of_array(ex).name!r}")
    ex[cx.X_RAMP] = 0.0
    return ex, float(ex[cx.X_FREQ])


def _geometry(P, q) -> np.ndarray:
    cg = np.zeros((2 * ly.N_POINTS, ly.N_CG))
    eval_geometry(q, P, cg)
    return cg


def _row(cg, r) -> np.ndarray:
    """Geometry row r (CG_G + k or CG_T + k) as a gradient in q (9; only s, v, psi move it)."""
    row = np.zeros(ly.N_DOF)
    row[ly.S], row[ly.V], row[ly.PSI] = cg[r, ly.CG_DS], cg[r, ly.CG_DV], cg[r, ly.CG_DPSI]
    return row


def constraint_rows(P: np.ndarray, q: np.ndarray, regime: int) -> np.ndarray:
    """The active constraint rows W (m x 9) of a regime at q: the closed points' gap gradients
    and, sticking, the first point's tangential gradient (docs/model.md §7)."""
    points = SETS[set_of(regime)]
    rows = [ly.CG_G + p for p in points] + ([ly.CG_T + points[0]] if is_stick(regime) else [])
    cg = _geometry(P, q)
    return np.array([_row(cg, r) for r in rows]).reshape(len(rows), ly.N_DOF)


def _gaps(P, q, regime) -> np.ndarray:
    """The closed points' gaps (cm) of a regime at q."""
    cg = _geometry(P, q)
    return np.array([cg[ly.CG_G + p, ly.CG_VAL] for p in SETS[set_of(regime)]])


def _null_basis(W: np.ndarray, free: np.ndarray) -> np.ndarray:
    """An orthonormal basis (9 x d) of the moving coordinates' directions that W keeps at 0."""
    W = W[:, free]
    if len(W):
        _, s, vt = np.linalg.svd(W)
        rank = int(np.sum(s > 1e-12 * max(1.0, s.max())))
    else:
        vt, rank = np.eye(len(free)), 0
    N = np.zeros((ly.N_DOF, len(free) - rank))
    N[free] = vt[rank:].T
    return N


class Manifold:
    """The reduced coordinates of a regime about a state (module docstring): positions in the
    null space of the closed points' normal rows (a sticking point's tangential position is
    free: any position in the friction cone holds), rates in that of every active row."""

    def __init__(self, P, x, regime, free):
        self.P, self.regime = P, regime
        self.n_normal = len(_gaps(P, x[:ly.N_DOF], regime))
        W = constraint_rows(P, x[:ly.N_DOF], regime)
        self.Nq, self.Nv = _null_basis(W[:self.n_normal], free), _null_basis(W, free)
        self.dim = self.Nq.shape[1] + self.Nv.shape[1]

    def _rates_fix(self, x, dq):
        """-W^+ (dW[dq]) q': keeps W q' = 0 to first order when q moves by dq."""
        W = constraint_rows(self.P, x[:ly.N_DOF], self.regime)
        if not len(W) or not np.any(dq):
            return np.zeros(ly.N_DOF)
        h = 1e-7 / np.abs(dq).max()
        dW = (constraint_rows(self.P, x[:ly.N_DOF] + h * dq, self.regime)
              - constraint_rows(self.P, x[:ly.N_DOF] - h * dq, self.regime)) / (2 * h)
        return -np.linalg.pinv(W) @ (dW @ x[ly.N_DOF:])

    def move(self, x, z):
        """x moved by reduced coordinates z (first order on the manifold)."""
        m = self.Nq.shape[1]
        dq = self.Nq @ z[:m]
        out = x.copy()
        out[:ly.N_DOF] += dq
        out[ly.N_DOF:] += self.Nv @ z[m:] + self._rates_fix(x, dq)
        return out

    def coordinates(self, dx):
        """The reduced coordinates of a state difference dx."""
        return np.concatenate([self.Nq.T @ dx[:ly.N_DOF], self.Nv.T @ dx[ly.N_DOF:]])

    def basis(self, x) -> np.ndarray:
        """The full state's change (N_STATE x dim) per unit of each reduced coordinate at x
        (:meth:`move` is linear in z)."""
        return np.column_stack([self.move(x, z) - x for z in np.eye(self.dim)])

    def project(self, x):
        """x back onto the manifold: the closed gaps to zero (Gauss-Newton in the normal
        rows' span), then the rates onto W q' = 0."""
        out = x.copy()
        for _ in range(5):
            g = _gaps(self.P, out[:ly.N_DOF], self.regime)
            if not len(g) or np.abs(g).max() < 1e-13:
                break
            W = constraint_rows(self.P, out[:ly.N_DOF], self.regime)[:len(g)]
            out[:ly.N_DOF] -= np.linalg.pinv(W) @ g
        W = constraint_rows(self.P, out[:ly.N_DOF], self.regime)
        if len(W):
            out[ly.N_DOF:] -= np.linalg.pinv(W) @ (W @ out[ly.N_DOF:])
        return out


def error_scales(P, states: np.ndarray) -> np.ndarray:
    """The integrator's error scale of each component of (q, q') over a record of states
    (``core.error_scales``: the floor from the clearance, the largest |value| of it or its
    partner)."""
    from ..core.error_scales import PARTNER, floors
    scale = np.zeros((ly.N_SCALE_ROWS, ly.N_STATE))
    floors(P, scale)
    floor = scale[ly.SCALE_FLOOR]
    peak = np.abs(states[:, :ly.N_STATE]).max(axis=0)
    partner = np.concatenate([peak[:ly.N_DOF][list(PARTNER)],
                              peak[ly.N_DOF:][list(PARTNER)]])
    return np.maximum.reduce([floor, peak, partner])


class Shooter:
    """The K-period map of a sine drive and what Newton's method needs of it; the drive's
    frequency or force may be a parameter (``parameter``: "freq_hz" or "force_n", for
    continuation)."""

    def __init__(self, params: Parameters, drive, periods: int = 1, fixed=(),
                 parameter: str | None = None, monodromy: str = "variational"):
        if not isinstance(params, Parameters):
            raise ParameterError(f"params must be Parameters, got {type(params).__name__}")
        if not isinstance(periods, (int, np.integer)) or isinstance(periods, bool) or periods < 1:
            raise ParameterError(f"periods = {periods!r}: a whole number of drive periods, >= 1")
        if parameter not in (None, "freq_hz", "force_n"):
            raise ParameterError(f"parameter = {parameter!r}: allowed freq_hz, force_n")
        if monodromy not in MONODROMY_METHODS:
            raise ParameterError(f"monodromy = {monodromy!r}: allowed "
                                 f"{', '.join(MONODROMY_METHODS)}")
        self.method = monodromy
        self.fallback = ""        # why the last monodromy was not variational, if it was not
        self.params, self.periods, self.fixed, self.parameter = params, int(periods), fixed, parameter
        self.ex, _ = sine_of(drive)
        model = mdl.build(params, fixed=fixed)
        self.P, self.free = model.P, np.array(model.free)
        self.phase = 0.0          # the section's drive phase, a fraction of a period

    def t0(self, ex) -> float:
        """The section's time (s): its phase of the drive period."""
        return self.phase / float(ex[cx.X_FREQ])

    def value(self, ex=None) -> float:
        """The parameter's value (Hz or N) of an excitation array (default the drive's)."""
        ex = self.ex if ex is None else ex
        return float(ex[cx.X_FREQ] if self.parameter == "freq_hz" else ex[cx.X_AMP] / 1e5)

    def drive_at(self, value: float | None) -> np.ndarray:
        """The drive with the parameter at ``value`` (None: the drive as given)."""
        ex = self.ex.copy()
        if value is not None:
            if self.parameter == "freq_hz":
                ex[cx.X_FREQ] = value
            else:
                ex[cx.X_AMP] = value * 1e5
        return ex

    def period_s(self, ex) -> float:
        return self.periods / float(ex[cx.X_FREQ])

    def run(self, x, regime, ex, periods: int | None = None):
        """``periods`` (default K) drive periods from (x, regime) at phase 0."""
        from .simulate import simulate
        f = float(ex[cx.X_FREQ])
        dt, rate = lattice(self.params, ex, 1.0 / f)
        return simulate(self.params, ex, (periods or self.periods) / f, initial=x[:ly.N_STATE],
                        regime=regime, tol=MAP_TOL, dt=dt, output_hz=rate, fixed=self.fixed,
                        t0=self.t0(ex))

    def guess(self, ex) -> tuple[np.ndarray, int]:
        """The state and regime of the closest return of a run of GUESS_PERIODS periods from
        the static equilibrium (its constants); ParameterError if that run fails."""
        from .simulate import simulate
        f = float(ex[cx.X_FREQ])
        ramped = ex.copy()
        ramped[cx.X_RAMP] = RAMP_PERIODS / f
        dt, rate = lattice(self.params, ex, 1.0 / f)
        start = simulate(self.params, ramped, GUESS_PERIODS / f + self.t0(ex), tol=MAP_TOL,
                         dt=dt, output_hz=rate, fixed=self.fixed)
        if not start.ok:
            raise ParameterError(f"the guess run failed: {start.message}")
        at = np.searchsorted(start.t, self.t0(ex) + np.arange(RETURN_FROM, GUESS_PERIODS + 1) / f
                             - 0.5 * dt)
        states = start.states[at, :ly.N_STATE]
        regimes = start.signal("regime")[at].astype(int)
        K = self.periods
        scale = error_scales(self.P, start.states[at[0]:])
        apart = np.max(np.abs(states[K:] - states[:-K]) / scale, axis=1)
        apart[regimes[K:] != regimes[:-K]] = np.inf
        k = int(np.argmin(apart)) if np.isfinite(apart).any() else len(states) - 1
        return states[k].copy(), int(regimes[k])

    def manifold(self, x, regime) -> "Manifold":
        return Manifold(self.P, x, regime, self.free)

    def residual(self, x, regime, ex):
        """(record, Phi(x) - x, error scales, largest scaled residual, end regime)."""
        record = self.run(x, regime, ex)
        if not record.ok:
            raise ParameterError(f"the period map failed: {record.message}")
        scale = error_scales(self.P, record.states)
        res = record.states[-1, :ly.N_STATE] - x
        return (record, res, scale, float(np.max(np.abs(res) / scale)),
                int(record.signal("regime")[-1]))

    def monodromy(self, manifold, x, regime, ex, record, scale, factor: float = 1.0
                  ) -> tuple[np.ndarray, str]:
        """(J, method): the K-period map's Jacobian in the reduced coordinates, along
        ``record`` (the map's run from x) by the variational equations and saltation
        matrices, or by finite differences (module docstring; ``self.fallback`` says why
        where the variational equations were asked for).  ``factor``: the tolerance and the
        difference steps times that (the error estimate's other monodromy)."""
        from .monodromy import MonodromyError, variational_monodromy
        if self.method == "variational":
            try:
                if record.stats["stepped_steps"]:
                    raise MonodromyError("the run took Moreau-Jean steps (an event flood)")
                dt, _ = lattice(self.params, ex, 1.0 / float(ex[cx.X_FREQ]))
                M = variational_monodromy(self.params, ex, x, regime, self.t0(ex),
                                          self.period_s(ex), record.log, manifold.basis(x),
                                          scale, factor * VAR_TOL, dt, self.fixed,
                                          factor * VAR_FD_REL,
                                          int(record.control.get("steps_all", 0)))
                self.fallback = ""
                return np.column_stack([manifold.coordinates(v) for v in M.matrix.T]), \
                    "variational"
            except MonodromyError as exc:
                self.fallback = f"finite differences: the variational equations failed ({exc})"
        return self.fd_monodromy(manifold, x, regime, ex, scale, factor * FD_REL), \
            "finite-difference"

    def fd_monodromy(self, manifold, x, regime, ex, scale, rel: float = FD_REL) -> np.ndarray:
        """The K-period map's Jacobian in the reduced coordinates, by central differences of
        ``rel`` of the error scales."""
        J = np.empty((manifold.dim, manifold.dim))
        steps = rel * reduced_scales(manifold, scale)
        for j in range(manifold.dim):
            z = np.zeros(manifold.dim)
            z[j] = steps[j]
            ends = [self._end(manifold.move(x, sign * z), regime, ex) for sign in (1.0, -1.0)]
            J[:, j] = manifold.coordinates(ends[0] - ends[1]) / (2 * steps[j])
        return J

    def d_parameter(self, manifold, x, regime, value: float) -> np.ndarray:
        """d(Phi(x) - x)/d(parameter) in the reduced coordinates (per Hz or per N)."""
        h = FD_REL * max(abs(value), 1.0) * 100.0
        ends = [self._end(x, regime, self.drive_at(value + sign * h)) for sign in (1.0, -1.0)]
        return manifold.coordinates(ends[0] - ends[1]) / (2 * h)

    def _end(self, x, regime, ex) -> np.ndarray:
        r = self.run(x, regime, ex)
        if not r.ok:
            raise ParameterError(f"the period map failed at a perturbed state: {r.message}")
        return r.states[-1, :ly.N_STATE]

    def find(self, guess, newton_tol, max_newton, t_wall) -> "Orbit":
        """Newton's method on the map at the section's phase (module docstring)."""
        ex = self.ex
        try:
            x, regime = self.guess(ex) if guess is None else (
                np.array(guess[0], float)[:ly.N_STATE].copy(), int(guess[1]))
        except ParameterError as exc:
            return _failed(str(exc), self.period_s(ex), self.periods, t_wall)
        history, status, message = [], "not converged", f"no fixed point in {max_newton} steps"
        iterations, J, record, method = 0, None, None, self.method
        try:
            for iterations in range(1, max_newton + 1):
                manifold = self.manifold(x, regime)
                x = manifold.project(x)
                record, res, scale, residual, end_regime = self.residual(x, regime, ex)
                history.append(residual)
                if end_regime != regime:
                    message = (f"the period map ends in regime {end_regime}, not {regime}: the "
                               "iterate is not near an orbit of this regime")
                    x, regime = record.states[-1, :ly.N_STATE].copy(), end_regime  # on a period
                    continue
                J, method = self.monodromy(manifold, x, regime, ex, record, scale)
                if residual <= newton_tol:
                    status, message = "ok", "found"
                    break
                step = np.linalg.lstsq(J - np.eye(manifold.dim), -manifold.coordinates(res),
                                       rcond=None)[0]
                x = self._damped(manifold, x, regime, ex, step, residual, scale)
        except ParameterError as exc:
            return _failed(str(exc), self.period_s(ex), self.periods, t_wall)
        return self.orbit(x, regime, ex, record, J, history, iterations, status, message, t_wall,
                          method)

    def _damped(self, manifold, x, regime, ex, step, residual, scale):
        """x moved by the Newton step, halved (at most BACKTRACK times) while the residual
        grows or the map leaves the regime: Newton's method damped.  A step whose period map
        fails (the run cannot go on from it) is first cut to at most MAX_STEP of the error
        scales ``scale`` in every reduced coordinate; if any trial failed and none is
        accepted, the last trial whose map ran (else x itself) is returned."""
        failed, ran = False, None
        for _ in range(BACKTRACK):
            trial = manifold.project(manifold.move(x, step))
            try:
                _, _, _, new, end = self.residual(trial, regime, ex)
            except ParameterError:
                if not failed:
                    failed = True
                    reach = np.max(np.abs(step) / reduced_scales(manifold, scale))
                    step = step * min(1.0, MAX_STEP / max(reach, 1e-300))
                    continue
                step = step / 2.0
                continue
            if end == regime and new < residual:
                return trial
            ran = trial
            step = step / 2.0
        if failed:
            return x if ran is None else ran
        return manifold.project(manifold.move(x, step))

    def _checked(self, manifold, x, regime, ex, record, scale, J, method):
        """(J, method, the multipliers' error estimate) at an orbit found (module docstring):
        J against the monodromy at CHECK_FACTOR times its tolerance (or a CHECK_FACTOR-th);
        a variational J that neither settles is set beside the finite differences, which
        replace it where the two disagree."""
        coarse, how = self.monodromy(manifold, x, regime, ex, record, scale, CHECK_FACTOR)
        error = multiplier_error(J, coarse)
        if method != "variational" or error <= FINER_ABOVE:
            return J, method, error
        finer, how_finer = self.monodromy(manifold, x, regime, ex, record, scale,
                                          1.0 / CHECK_FACTOR)
        if how_finer == "variational":
            error = multiplier_error(J, finer)
        if error <= FINER_ABOVE:
            return J, method, error
        # not settled by its own tolerance: finite differences, checked by their own step,
        # decide; where they agree, the larger of the two differences
        fd = self.fd_monodromy(manifold, x, regime, ex, scale)
        fd_check = coarse if how != "variational" else self.fd_monodromy(
            manifold, x, regime, ex, scale, FD_REL * CHECK_FACTOR)
        fd_error = multiplier_error(fd, fd_check)
        agreement = multiplier_error(J, fd)
        if agreement <= max(fd_error, FINER_ABOVE):
            return J, method, max(agreement, fd_error)
        self.fallback = ("finite differences: the variational equations' multipliers moved "
                         f"by {fd_error:.1e} with their tolerance and differ from these by "
                         f"{agreement:.1e}")
        return fd, "finite-difference", fd_error

    def orbit(self, x, regime, ex, record, J, history, iterations, status, message,
              t_wall, method: str = "variational") -> "Orbit":
        """The :class:`Orbit` at a solution (or the last iterate) with its multipliers and the
        facts of its record."""
        T = self.period_s(ex)
        manifold = self.manifold(x, regime)
        if J is not None and J.shape[0] != manifold.dim:     # another regime's, at no orbit
            J = None
        multipliers, neutral = _floquet(J, manifold, x, error_scales(self.P, record.states))
        facts = _orbit_facts(record, self.P, self.periods, T)
        if status == "ok" and facts["grazing"]:
            status, message = "grazing", ("found, but an open gap grazes zero: the multipliers "
                                          "are not defined there")
        error = np.nan
        stable = None
        if status == "ok":
            scale = error_scales(self.P, record.states)
            J_checked, method, error = self._checked(manifold, x, regime, ex, record, scale, J,
                                                     method)
            if J_checked is not J:
                J = J_checked
                multipliers, neutral = _floquet(J, manifold, x, scale)
            others = np.abs(np.delete(multipliers, [] if neutral is None else [neutral]))
            largest = others.max(initial=0.0)
            if largest < 1.0 - max(error, STABLE_MARGIN):
                stable = True
            elif largest > 1.0 + max(error, STABLE_MARGIN):
                stable = False
            else:
                message = (f"found; stability undetermined: the largest |multiplier| "
                           f"{largest:.6f} is within the monodromy's error {error:.1e} of 1")
        message += f" (section at phase {self.phase:g} of the drive period)" if self.phase else ""
        message += f"; monodromy by {self.fallback}" if method != self.method else ""
        return Orbit(status, message, T, self.periods, x, regime,
                     history[-1] if history else np.inf, iterations, multipliers, stable,
                     facts["grazing"], facts["min_open_gap_cm"], facts["events_per_period"],
                     facts["contact_time_share"], facts["tip_amplitude_cm"],
                     time.perf_counter() - t_wall, manifold.dim, history,
                     None if neutral is None else complex(multipliers[neutral]), J,
                     facts["responses"], facts["tip_rms_cm"], error, self.phase, method)


def multiplier_error(J: np.ndarray, other: np.ndarray) -> float:
    """The largest distance from a multiplier of J to the nearest of ``other`` (the same
    monodromy by another finite-difference step): the multipliers' error estimate."""
    a, b = np.linalg.eigvals(J), np.linalg.eigvals(other)
    return float(max((np.abs(b - m).min() for m in a), default=0.0))


def periodic_orbit(params: Parameters, drive, periods: int = 1, guess=None,
                   newton_tol: float = 1e-7, max_newton: int = MAX_NEWTON,
                   fixed=(), phases=PHASES, monodromy: str = "variational") -> Orbit:
    """A periodic orbit of ``periods`` drive periods (module docstring).

    ``drive``: a sine (``drives.sine(force_n, freq_hz)`` or its settings; the soft start is
    dropped).  ``guess``: (state (18,), regime) at the first phase to start Newton from; by
    default the closest return of a run from the static equilibrium (``Shooter.guess``).
    The section is taken at the drive phases ``phases`` in turn (fractions of a period)
    until one gives an orbit.  Returns an :class:`Orbit` whose ``status`` says whether it was found; never
    one it did not find.  ``monodromy``: "variational" or "finite-difference" (module
    docstring).
    """
    t_wall = time.perf_counter()
    shooter = Shooter(params, drive, periods, fixed, monodromy=monodromy)
    orbit = None
    for k, phase in enumerate(phases):
        shooter.phase = float(phase)
        orbit = shooter.find(guess if k == 0 else None, newton_tol, max_newton, t_wall)
        if orbit.status in ("ok", "grazing"):
            break
    return orbit


def lattice(params, ex, period_s: float) -> tuple[float, float]:
    """(largest step, sample rate) with a whole number of both in a drive period: the step at
    most the default (``step_policy.default_dt``), about SAMPLES_PER_PERIOD samples a period,
    so that a run of whole periods ends exactly at the drive's phase 0."""
    from .step_policy import default_dt
    n = int(np.ceil(period_s / default_dt(params, ex) - 1e-9))
    decim = max(1, int(np.ceil(n / SAMPLES_PER_PERIOD)))
    n = len(PHASES) * decim * int(np.ceil(n / (len(PHASES) * decim)))   # the phases on it
    dt = period_s / n
    return dt, 1.0 / (decim * dt)


def reduced_scales(manifold, scale) -> np.ndarray:
    """The error scale of each reduced coordinate: its basis vector's weighted mean of the
    components' scales (cm, rad and per s)."""
    Nq, Nv = np.abs(manifold.Nq), np.abs(manifold.Nv)
    return np.concatenate([Nq.T @ scale[:ly.N_DOF] / Nq.sum(axis=0),
                           Nv.T @ scale[ly.N_DOF:] / Nv.sum(axis=0)])


def stuck_direction(manifold, x) -> np.ndarray | None:
    """In a regime with a contact at phase 0, the unit vector (reduced coordinates) that moves
    its first point's tangential position (where friction holds the body); None in free
    flight."""
    if manifold.regime == 0:
        return None
    first = SETS[set_of(manifold.regime)][0]
    row = _row(_geometry(manifold.P, x[:ly.N_DOF]), ly.CG_T + first)
    along = np.concatenate([manifold.Nq.T @ row, np.zeros(manifold.Nv.shape[1])])
    return along / max(np.linalg.norm(along), 1e-300)


def _floquet(J, manifold, x, scale) -> tuple[np.ndarray, int | None]:
    """The multipliers, largest modulus first, and the index of the neutral one: with a
    contact at phase 0, the multiplier within NEUTRAL_TOL of 1 whose eigenvector (on the error
    scales) moves mostly the body's tangential position (a family of orbits held by friction
    at any position)."""
    if J is None:
        return np.zeros(0, complex), None
    d = reduced_scales(manifold, scale)
    mu, vec = np.linalg.eig(J)
    vec = vec / d[:, None]
    order = np.argsort(-np.abs(mu), kind="stable")
    mu, vec = mu[order], vec[:, order]
    along = stuck_direction(manifold, x)
    if along is None:
        return mu, None
    share = np.abs(along @ vec) / np.linalg.norm(vec, axis=0)
    candidates = np.flatnonzero((np.abs(mu - 1.0) < NEUTRAL_TOL) & (share > 0.5))
    return mu, (int(candidates[np.argmax(share[candidates])]) if len(candidates) else None)


def _orbit_facts(record, P, periods, T) -> dict:
    """Events per drive period by kind, contact-time shares, the tip's amplitude and the
    smallest open gap over the orbit's record."""
    kinds = record.log[:, ly.LOG_KIND]
    per = {name: float((kinds == code).sum()) / periods
           for code, name in enumerate(ly.EVENT_KINDS) if code != ly.KIND_START}
    tip = record.signal("tip_y")
    regimes = record.signal("regime").astype(int)
    gaps = np.stack([record.signal(f"gap{k + 1}") for k in range(ly.N_POINTS)], axis=1)
    closed = np.stack([in_contact(p, regimes) for p in range(ly.N_POINTS)], axis=1) == 1
    open_gaps = np.where(closed, np.inf, gaps)
    # a graze: an open gap's minimum in time (not the approach to a closing, nor an impact
    # that bounces, open again, between the samples either side: its minimum is a kink)
    inner = ((open_gaps[1:-1] < open_gaps[:-2]) & (open_gaps[1:-1] <= open_gaps[2:])
             & np.isfinite(open_gaps[:-2]) & np.isfinite(open_gaps[2:]))
    t = record.t
    for point in range(ly.N_POINTS):
        hits = record.log[(kinds == ly.KIND_IMPACT)
                          & (record.log[:, ly.LOG_POINT] == point + 1), ly.LOG_T]
        if len(hits):
            hits = np.sort(hits)
            between = (np.searchsorted(hits, t[2:], side="right")
                       - np.searchsorted(hits, t[:-2], side="left")) > 0
            inner[:, point] &= ~between
    minima = open_gaps[1:-1][inner]
    smallest = float(minima.min()) if len(minima) else float("inf")
    responses = {}
    for name in ("accel1", "accel2", "accel3", "strain1", "strain2"):
        x = record.signal(name)
        responses[f"{name}_amplitude"] = float((x.max() - x.min()) / 2.0)
        responses[f"{name}_rms"] = float(np.std(x))
    # the lines at the drive frequency f and at f / 2 (the subharmonic of an orbit of an even
    # number of periods; zero for one period)
    for name, x, unit in (("tip", tip, "_cm"), ("strain1", record.signal("strain1"), "")):
        responses[f"{name}_h1{unit}"] = _line(record.t, x, T, periods)
        responses[f"{name}_h0.5{unit}"] = _line(record.t, x, T, periods / 2.0)
    return {"events_per_period": per, "contact_time_share": record.contact_time_share(),
            "tip_amplitude_cm": float((tip.max() - tip.min()) / 2.0),
            "tip_rms_cm": float(np.std(tip)), "responses": responses,
            "min_open_gap_cm": smallest, "grazing": bool(smallest < GRAZE_REL * P[ly.P_GAP])}


def _line(t, x, T, k) -> float:
    """The amplitude of x's k-th harmonic over one orbit period T sampled at t (both ends): the
    discrete Fourier sum over the samples (the last, the first's repeat, left out), exact for
    a periodic record with no window; zero where k is not a whole number."""
    if k != int(k):
        return 0.0
    phase = np.exp(-2j * np.pi * k * (t[:-1] - t[0]) / T)
    return float(2.0 * np.abs(np.mean(x[:-1] * phase)))


def _failed(message, T, periods, t_wall) -> Orbit:
    return Orbit("failed", message, T, periods, np.full(ly.N_STATE, np.nan), 0, float("inf"),
                 0, np.zeros(0, complex), None, False, float("nan"), {}, {}, float("nan"),
                 time.perf_counter() - t_wall, 0)
