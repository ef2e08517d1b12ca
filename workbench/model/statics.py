"""Static equilibrium of the rig under gravity and an optional tip load.

The rig hangs before the shaker starts: the structure sags by centimetres
and the loose body rests on the contacts that statics selects (docs/model.md §8;
with the tip mass, beam B pries the loose body into contact set {2, 3}).

For each contact set the equations

    Q(q) + W_n^T lambda_n + W_t^T lambda_t = 0     (free coordinates)
    g_k(q) = 0                                     (the set's points)
    s = s0                                         (friction holds the slide)

are solved by the compiled damped Newton iteration of
:mod:`workbench.core.equilibrium` (a set that needs _MAX_DAMPED_IN_A_ROW
damped steps in a row has no equilibrium near the start and is given up);
Q is the generalised force at rest (gravity, elastic, cork) plus the tip
load.  Friction is indeterminate in statics; the slide is held where the
joint was assembled (s0, default 0) by the tangential force lambda_t of the
set's first point, and the solution is accepted only if that force lies in
the friction cone |lambda_t| <= mu_s sum lambda_n.  When no set passes, the
frictionless equilibrium (lambda_t = 0, s free) is used and flagged.  Of the
admissible sets (lambda_n >= 0, every other gap open) the one of least
potential energy is the equilibrium.
"""
from __future__ import annotations

import copy
import functools
from dataclasses import dataclass

import numpy as np

from . import packing as mdl
from ..core import layout as ly
from ..core.equilibrium import newton_set, static_state
from .drives import DYN_PER_N, none
from .params import ParameterError, Parameters
from .regimes import CONTACT_CODES, SETS

_TOL = 1e-10           # scaled residual at convergence
_MAX_NEWTON = 60
#: A set whose Newton iteration needs this many damped steps in a row has no
#: equilibrium near the start: over the default study's 24 models the sets that
#: converge take at most one damped step (3-8 iterations), the single
#: contacts {3} and {4} damp 57-59 of their 60 and fail.
_MAX_DAMPED_IN_A_ROW = 20


@dataclass
class Equilibrium:
    """A static equilibrium: q (9,) in CGS, the contact set (0..8), forces (dyn)."""

    q: np.ndarray
    contact_set: int
    lambda_n: np.ndarray       # (4,) per contact point, 0 if open
    lambda_t: float
    friction_held: bool        # False: frictionless fallback, s slid to equilibrium
    tip_y: float               # vertical position of beam B's tip (cm)
    residual: float            # largest force residual (dyn)

    @property
    def contact_code(self) -> int:
        return CONTACT_CODES[self.contact_set]


class _Statics:
    """One model's static problem: its kernel arrays and the tip load (dyn)."""

    def __init__(self, p: Parameters, fixed, tip_load_dyn: float):
        self.p = p
        self.model = mdl.build(p, fixed)
        self.work = mdl.make_work()
        self.ex = none()
        self.tip_load = tip_load_dyn
        self.free = list(self.model.free)

    def unknowns(self, set_index: int, hold_s: bool):
        """The coordinates and contact points of a set's unknowns (int64 arrays), and whether
        friction holds the slide."""
        coords = [i for i in self.free if not (hold_s and i == ly.S)]
        friction = hold_s and ly.S in self.free and set_index > 0
        return (np.array(coords, dtype=np.int64), np.array(SETS[set_index], dtype=np.int64),
                friction)

    def newton(self, z, q_base, set_index: int, hold_s: bool) -> bool:
        """Solve the set's equations from z (overwritten); True when converged."""
        coords, points, friction = self.unknowns(set_index, hold_s)
        case = (q_base, coords, points, friction, self.tip_load)
        status = newton_set(z, case, _TOL, _MAX_NEWTON, _MAX_DAMPED_IN_A_ROW, self.model,
                            self.ex, self.work)
        return status == ly.EQ_CONVERGED

    def state(self, z, q_base, set_index: int, hold_s: bool):
        """q, the force with the contact forces Q (dyn, dyn cm), the gaps (cm), the potential
        energy (erg) and the tip's height (cm) of unknowns z."""
        coords, points, friction = self.unknowns(set_index, hold_s)
        q, Q, f, energy = np.zeros(ly.N_DOF), np.zeros(ly.N_DOF), np.zeros(z.size), np.zeros(4)
        static_state(z, (q_base, coords, points, friction, self.tip_load), self.model, self.ex,
                     self.work, q, Q, f, energy)
        gaps = self.work.cg[ly.CG_G:ly.CG_G + ly.N_POINTS, ly.CG_VAL].copy()
        potential = energy[0] + energy[1] + energy[2] - self.tip_load * energy[3]
        return q, Q, gaps, potential, energy[3]


def _solve_set(st: _Statics, q_guess, set_index, hold_s):
    """Equilibrium in one contact set and its potential energy (erg), or None if it fails
    or is inadmissible."""
    coords, points, friction = st.unknowns(set_index, hold_s)
    z = np.concatenate([q_guess[coords], np.zeros(points.size + (1 if friction else 0))])
    q_base = q_guess.copy()
    if not st.newton(z, q_base, set_index, hold_s):
        return None
    q, Q, gaps, potential, tip_y = st.state(z, q_base, set_index, hold_s)
    lambda_n = np.zeros(ly.N_POINTS)
    lambda_n[points] = z[coords.size:coords.size + points.size]
    lambda_t = z[-1] if friction else 0.0
    scale = max(1.0, np.max(np.abs(lambda_n)))
    if np.any(lambda_n < -1e-9 * scale):
        return None
    others = [p for p in range(ly.N_POINTS) if p not in points]
    if np.any(gaps[others] < -1e-12):
        return None
    held = abs(lambda_t) <= st.p.mu_s * lambda_n.sum() * (1 + 1e-12)
    if friction and not held:
        return None
    eq = Equilibrium(q=q, contact_set=set_index, lambda_n=lambda_n, lambda_t=float(lambda_t),
                     friction_held=bool(friction or not hold_s), tip_y=float(tip_y),
                     residual=float(np.max(np.abs(Q[coords]))) if coords.size else 0.0)
    return eq, potential


def static_equilibrium(p: Parameters, tip_load_n: float = 0.0, fixed=(), s0: float = 0.0,
                       q_guess: np.ndarray | None = None) -> Equilibrium:
    """The static equilibrium under gravity and a vertical tip load (N, + up).

    ``s0`` (cm) is the slide at which friction holds the loose body.  Raises
    :class:`ParameterError` when no contact set gives an admissible
    equilibrium.
    """
    if not isinstance(p, Parameters):
        raise ParameterError(f"expected workbench.model.params.Parameters, got {type(p).__name__}")
    if not np.isfinite(tip_load_n):
        raise ParameterError(f"tip_load_n = {tip_load_n!r} N must be finite")
    if q_guess is None:     # the common case (every simulate call): solved once per process
        return copy.deepcopy(_equilibrium_from_rest(p, float(tip_load_n), tuple(fixed),
                                                    float(s0)))
    return _solve_equilibrium(p, tip_load_n, fixed, s0, q_guess)


@functools.lru_cache(maxsize=256)
def _equilibrium_from_rest(p: Parameters, tip_load_n: float, fixed: tuple, s0: float):
    return _solve_equilibrium(p, tip_load_n, fixed, s0, None)


def _solve_equilibrium(p, tip_load_n, fixed, s0, q_guess):
    st = _Statics(p, fixed, tip_load_n * DYN_PER_N)
    guess = np.zeros(ly.N_DOF) if q_guess is None else np.array(q_guess, dtype=float)
    guess[ly.S] = s0
    sets = list(range(1, ly.N_SETS))
    held_joint = ly.V not in st.free and ly.PSI not in st.free
    if (p.k_v > 0 and p.k_psi > 0) or held_joint:   # the body can rest without contact
        sets.insert(0, 0)
    for hold_s in (True, False):
        found = [e for e in (_solve_set(st, guess, k, hold_s) for k in sets) if e is not None]
        if found:
            best, _ = min(found, key=lambda e: e[1])
            if not hold_s:
                best.friction_held = False
            return best
    raise ParameterError("no static equilibrium found in any contact set "
                         f"(tip load {tip_load_n} N); check gap, h4 and the loads")


def tip_load_for_deflection(p: Parameters, deflection_cm: float, fixed=(),
                            base: Equilibrium | None = None) -> tuple[float, Equilibrium]:
    """The vertical tip load (N) that moves the tip by ``deflection_cm`` from its
    gravity equilibrium ``base`` (+ up; solved if not given), and that
    equilibrium (secant iteration to 1e-6 cm)."""
    if not (np.isfinite(deflection_cm) and abs(deflection_cm) <= 20.0):
        raise ParameterError(f"deflection_cm = {deflection_cm!r} cm is outside the allowed "
                             "range [-20, 20] cm")
    base = static_equilibrium(p, 0.0, fixed) if base is None else base
    if deflection_cm == 0.0:
        return 0.0, base
    target = base.tip_y + deflection_cm
    f0, y0 = 0.0, base.tip_y
    f1 = 1.0 if deflection_cm > 0 else -1.0
    eq = static_equilibrium(p, f1, fixed, q_guess=base.q)
    y1 = eq.tip_y
    for _ in range(30):
        if abs(y1 - target) < 1e-6:
            return f1, eq
        f2 = f1 + (target - y1) * (f1 - f0) / (y1 - y0)
        f0, y0 = f1, y1
        f1 = f2
        eq = static_equilibrium(p, f1, fixed, q_guess=eq.q)
        y1 = eq.tip_y
    raise ParameterError(f"could not find a tip load deflecting the tip by {deflection_cm} cm")
