"""A branch of periodic orbits over the drive's frequency or force, by pseudo-arclength
continuation (Keller; Seydel, *Practical Bifurcation and Stability Analysis*, 3rd ed., §4.5).

The unknowns are an orbit's reduced coordinates z (:mod:`workbench.model.orbit`: the state
at phase 0 on its regime's manifold) and the parameter lambda (Hz or N), both on scales
(the error scales of z, the range of lambda), u = (z / d, lambda / range).  From an orbit u0
with unit tangent t0 (the null vector of [J - I, dR/dlambda], oriented along the secant
from the orbit before, in the full state, so that a change of reduced coordinates does not
turn it round; the first towards the range's end), the predictor is u0 + ds t0 and the
corrector Newton's method on

    R(z, lambda) = Phi(x(z), lambda) - x(z) = 0,    t0 . (u - u0) - ds = 0,

its Jacobian [[J - I, dR/dlambda], [t0]] (J the monodromy of :mod:`workbench.model.orbit`,
by finite differences of the map where the variational one is poor (POOR), dR/dlambda by
central differences of the map, two more integrations).  The step ds grows by GROW after
a corrector of at most EASY iterations, halves after a failed one (a corrector that does not converge in MAX_CORRECTOR iterations,
or a new orbit farther than JUMP x ds from the last: a jump to another branch).  Where the
orbit's state at phase 0 passes an event along the branch (the period map ends in another
regime than it starts from), the orbit at the predicted parameter is found by shooting
from the predicted state in the regime it reaches, and taken if it lies within JUMP x ds of
the last (on the error scales).  The branch ends, with its status, when ds falls below
DS_MIN, when lambda passes the range's end, or when it folds back past its start (a range
may run downwards: from 200 N to 40 N).

At each orbit its multipliers are computed; between two orbits whose number of multipliers
outside the unit circle is decided (none within its error estimate of the circle,
:mod:`workbench.model.orbit`; orbits between them where it is not are skipped) a change in
that number is a bifurcation.  The multiplier that crossed is the one outside the circle
nearest to it, on the side with more outside; it crossed at +1, -1 or as a complex pair.
Where the two orbits have the same events per period (by kind), the crossing is smooth and
names the bifurcation: at +1 a fold (a saddle-node), at -1 a period doubling, as a complex
pair a Neimark-Sacker.  Where their events differ (an impact, a separation or a stick phase
more or fewer a period), the monodromy, a product of saltation matrices and flows, changes
with the events, and the multipliers jump rather than cross: the change of stability is
"nonsmooth" (a discontinuity-induced bifurcation: di Bernardo et al., *Piecewise-smooth
Dynamical Systems*, 2008, ch. 1), with where its multiplier left and the events that
changed.  An open gap whose minimum starts or stops touching zero is a grazing.  Where the
parameter turns (its steps change sign) the branch has a fold (``turns``; named by the
change of stability there if one left the circle elsewhere than at +1);
an orbit found nearer the orbit before the last than the last is a step back along the
branch (a zig-zag between two orbits across a change of the regime at phase 0), not taken:
the step is halved.

**Branch switching at a period doubling** (Seydel §7.4; Kuznetsov, *Elements of Applied
Bifurcation Theory*, 3rd ed., §4.5): where a multiplier crosses -1, the orbits of twice the
period branch off; where it jumps past -1 at a nonsmooth change of stability, they may
(a period-doubling border collision: di Bernardo et al. §3.6), and are sought the same way
(:func:`doublings`).  :func:`doubled_start` seeks one by shooting the 2K-period map from the
orbit on either side of the crossing, moved along the eigenvector of its multiplier nearest
-1 by SWITCH_OFFSETS of its error scales, and takes an orbit only if its K-period map does
not return it (farther than SAME_ORBIT on the scales: not the K-period orbit again);
:func:`continue_doubled` traces that branch onwards, away from the crossing.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .orbit import (STABLE_MARGIN, Orbit, Shooter, error_scales, reduced_scales,
                    stuck_direction)
from .params import ParameterError
from .regimes import contact_code

#: Step control (scaled arclength): first step, smallest, largest, growth, easy corrector.
DS_FIRST = 0.02
DS_MIN = 1e-4
DS_MAX = 0.08
GROW = 1.5
EASY = 3
MAX_CORRECTOR = 8
#: A new orbit farther than JUMP x ds from the last (scaled) is another branch's.
JUMP = 3.0
#: A corrector converges at this scaled residual (as a single orbit's).
CORRECTOR_TOL = 1e-7
#: The branch ends after this many orbits at most.
MAX_ORBITS = 600
#: A variational monodromy whose multipliers' error estimate exceeds this (an event met
#: nearly tangentially: at 15.05 Hz, 200 N, 0.19) gives the tangent no direction: the
#: tangent is then taken from finite differences of the map, and a corrector that fails with
#: the variational Jacobian is tried again with theirs.
POOR = 1e-2
#: Branch switching: the offsets along the critical Floquet vector (its largest component
#: on the error scales) from which the doubled orbit is sought, smallest first.
SWITCH_OFFSETS = (0.01, 0.03, 0.1, 0.3)
#: A 2K-period orbit whose K-period map moves it less than this (largest component on the
#: error scales) is the K-period orbit.
SAME_ORBIT = 1e-4
#: A change of stability between orbits with the same events per period, by where the
#: multiplier crossed the unit circle.
SMOOTH = {"+1": "fold", "-1": "period doubling", "complex": "neimark-sacker"}


@dataclass(frozen=True)
class Bifurcation:
    """A bifurcation between a branch's orbits ``index - 1`` and ``index`` (module docstring)."""

    index: int
    kind: str                  # fold, period doubling, neimark-sacker, nonsmooth, grazing
    crossing: str = ""         # where the multiplier crossed the circle: +1, -1, complex
    angle: float = float("nan")    # that multiplier's angle (rad) on the side it is outside
    events_changed: str = ""   # the events per period that differ: "impact 4->5; ..."
    turns: bool = False        # the parameter turns here (its steps change sign)

    def entry(self, at: float) -> dict:
        """This bifurcation in a JSON summary, ``at`` the parameter of the orbit after it."""
        return {"at": float(at), "kind": self.kind, "crossing": self.crossing,
                "events_changed": self.events_changed, "turns": self.turns}


@dataclass
class Branch:
    """The orbits of a continuation and how it ended."""

    parameter: str
    orbits: list = field(default_factory=list)        # (value, Orbit)
    bifurcations: list = field(default_factory=list)  # Bifurcation
    status: str = "running"
    message: str = ""
    wall_s: float = 0.0
    towards: float = float("nan")    # the value it is traced towards


def outside_count(orbit: Orbit) -> int | None:
    """How many of the orbit's deciding multipliers lie outside the unit circle, None where
    that is not decided: a multiplier within its error estimate (or STABLE_MARGIN) of the
    circle, or no error estimate (an orbit not found, a grazing one)."""
    error = orbit.multiplier_error
    if not np.isfinite(error) or not len(orbit.multipliers):
        return None
    mu = np.abs(orbit.deciding())
    if np.any(np.abs(mu - 1.0) <= max(error, STABLE_MARGIN)):
        return None
    return int((mu > 1.0).sum())


def _events_changed(before: Orbit, after: Orbit) -> str:
    """The events per period (by kind) that differ between two orbits: "impact 4->5; ...",
    or ''."""
    a, b = before.events_per_period, after.events_per_period
    return "; ".join(f"{k} {a.get(k, 0):g}->{b.get(k, 0):g}" for k in sorted(set(a) | set(b))
                     if a.get(k, 0) != b.get(k, 0))


def _bifurcation(before: Orbit, after: Orbit, index: int) -> Bifurcation | None:
    """The bifurcation between two orbits, ``after`` the branch's orbit ``index`` (module
    docstring), or None: no change of stability, or either's count of multipliers outside
    the unit circle not decided."""
    if before.grazing != after.grazing:
        return Bifurcation(index, "grazing")
    n_a, n_b = outside_count(before), outside_count(after)
    if n_a is None or n_b is None or n_a == n_b:
        return None
    outside = after.deciding() if n_b > n_a else before.deciding()
    outside = outside[np.abs(outside) > 1.0]
    crossed = outside[np.argmin(np.abs(outside))]     # the one outside nearest the circle
    crossing = ("complex" if abs(crossed.imag) > 1e-6 * abs(crossed) else
                "+1" if crossed.real > 0 else "-1")
    changed = _events_changed(before, after)
    return Bifurcation(index, "nonsmooth" if changed else SMOOTH[crossing], crossing,
                       float(np.angle(crossed)), changed)


def continue_branch(shooter: Shooter, lo: float, hi: float, on_orbit: Callable | None = None,
                    ds: float = DS_FIRST, start: Orbit | None = None,
                    until: Callable | None = None, previous: tuple | None = None,
                    back_to: float | None = None) -> Branch:
    """Trace the branch of ``shooter``'s orbits from its parameter ``lo`` towards ``hi``
    (module docstring; ``hi`` may be below ``lo``: the branch is traced downwards);
    ``on_orbit(branch)`` is called after each orbit (to write it out).  ``start``: an orbit
    at ``lo`` (default: found from the state after a run).  ``until(orbit)``: a reason to
    end the branch at that orbit (status "ended"), or ''.  ``previous``: (value, state) of the
    orbit before ``start`` on the branch (a branch resumed), which orients the first tangent;
    ``back_to``: the value the branch may not fold back past (default ``lo``)."""
    from .orbit import periodic_orbit
    t0 = time.perf_counter()
    if lo == hi:
        raise ParameterError(f"the range {lo:g}:{hi:g} is empty")
    direction = 1.0 if hi > lo else -1.0
    branch = Branch(shooter.parameter, towards=hi)
    span = abs(hi - lo)
    back_to = lo if back_to is None else back_to
    if start is None:
        start = periodic_orbit(shooter.params, shooter.drive_at(lo), shooter.periods,
                               fixed=shooter.fixed)
    if start.status not in ("ok", "grazing"):
        branch.status, branch.message = "no start", f"no orbit at {lo:g}: {start.message}"
        return _done(branch, t0, on_orbit)
    shooter.phase = start.phase
    value, orbit = lo, start
    determined = start               # the last orbit whose count outside the circle is decided
    branch.orbits.append((value, orbit))
    while len(branch.orbits) < MAX_ORBITS:
        if on_orbit:
            on_orbit(branch)
        manifold = shooter.manifold(orbit.state, orbit.regime)
        ex = shooter.drive_at(value)
        record, res, scale, _, _ = shooter.residual(orbit.state, orbit.regime, ex)
        d = np.concatenate([reduced_scales(manifold, scale), [span]])
        J = orbit.monodromy if orbit.monodromy is not None and \
            orbit.monodromy.shape[0] == manifold.dim else \
            shooter.monodromy(manifold, orbit.state, orbit.regime, ex, record, scale)[0]
        if orbit.monodromy_method == "variational" and not orbit.multiplier_error <= POOR:
            J = shooter.fd_monodromy(manifold, orbit.state, orbit.regime, ex, scale)
        dR = shooter.d_parameter(manifold, orbit.state, orbit.regime, value)
        pin = _pin(orbit, manifold, d)
        secant = None
        before = (branch.orbits[-2][0], branch.orbits[-2][1].state) if len(branch.orbits) > 1 \
            else previous
        if before is not None:
            secant = np.concatenate([(orbit.state - before[1]) / scale,
                                     [(value - before[0]) / span]])
        tangent = _tangent(J, dR, d, manifold, orbit.state, scale, secant, pin, direction)
        accepted = None
        while accepted is None:
            if ds < DS_MIN:
                branch.status, branch.message = "step floor", (
                    f"the step fell below {DS_MIN:g} at {value:.6g}: a turning point the "
                    "corrector cannot pass, a grazing or the end of a regime at phase 0")
                return _done(branch, t0, on_orbit)
            accepted = _correct(shooter, orbit, value, manifold, d, tangent, ds, pin)
            if accepted is None and shooter.method == "variational":
                accepted = _correct(shooter, orbit, value, manifold, d, tangent, ds, pin, True)
            if accepted is None:
                accepted = _across_phase_zero(shooter, orbit, value, manifold, d, tangent, ds)
            if accepted is not None and len(branch.orbits) > 1 and \
                    _went_back(accepted, branch.orbits[-2], (value, orbit), scale, span):
                accepted = None
            if accepted is None:
                ds /= 2.0
        new_value, new_orbit, iterations = accepted
        found = (Bifurcation(len(branch.orbits), "grazing") if new_orbit.grazing != orbit.grazing
                 else _bifurcation(determined, new_orbit, len(branch.orbits)))
        if len(branch.orbits) > 1 and (new_value - value) * (value - branch.orbits[-2][0]) < 0:
            found = _turning(found, len(branch.orbits))
        if found:
            branch.bifurcations.append(found)
        if outside_count(new_orbit) is not None:
            determined = new_orbit
        branch.orbits.append((new_value, new_orbit))
        reason = until(new_orbit) if until else ""
        if reason:
            branch.status, branch.message = "ended", f"{reason} at {new_value:.6g}"
            return _done(branch, t0, on_orbit)
        if iterations <= EASY:
            ds = min(DS_MAX, ds * GROW)
        if (new_value - hi) * direction > 0:
            branch.status, branch.message = "done", f"reached {hi:g}"
            return _done(branch, t0, on_orbit)
        if (new_value - back_to) * direction < -1e-9 * span:
            branch.status, branch.message = "folded back", (
                f"the branch turned back past its start {back_to:g} (at {new_value:.6g})")
            return _done(branch, t0, on_orbit)
        value, orbit = new_value, new_orbit
    branch.status, branch.message = "max orbits", f"{MAX_ORBITS} orbits"
    return _done(branch, t0, on_orbit)


def _turning(found: Bifurcation | None, index: int) -> Bifurcation:
    """The bifurcation where the parameter turns at the branch's orbit ``index``: a fold,
    unless a change of stability there left the unit circle elsewhere than at +1 (then its
    own kind, marked as turning)."""
    if found is None or found.kind == "grazing":
        return Bifurcation(index, "fold", turns=True)
    kind = "fold" if found.crossing == "+1" else found.kind
    return Bifurcation(index, kind, found.crossing, found.angle, found.events_changed, True)


def _went_back(new, before_last, last, scale, span) -> bool:
    """Whether the orbit ``new`` (value, Orbit, ...) lies nearer the branch's orbit before
    the last than the last (full state on the error scales ``scale``, parameter on
    ``span``): the corrector went back along the branch (a zig-zag between two orbits
    where the regime at phase 0 changes), not on past a turning point."""
    def distance(a, b):
        return np.hypot(np.linalg.norm((a[1].state - b[1].state) / scale), (a[0] - b[0]) / span)
    return distance(new, before_last) < distance(new, last)


def _done(branch: Branch, t0: float, on_orbit=None) -> Branch:
    branch.wall_s = time.perf_counter() - t0
    if on_orbit:
        on_orbit(branch)
    return branch


def _pin(orbit, manifold, d) -> np.ndarray | None:
    """The row (scaled unknowns) that holds a stuck position where friction holds the orbit at
    any (its neutral multiplier): a phase-like condition that makes the branch unique."""
    if orbit.neutral is None:
        return None
    along = stuck_direction(manifold, orbit.state)
    row = np.concatenate([along * d[:manifold.dim], [0.0]])
    return row / np.linalg.norm(row)


def _tangent(J, dR, d, manifold, x, scale, secant=None, pin=None,
             direction: float = 1.0) -> np.ndarray:
    """The unit tangent (scaled) of the branch: the null vector of [J - I, dR] on the scales
    (and of the pin, :func:`_pin`), oriented along ``secant`` (the step from the orbit before
    to this one: full state on the error scales ``scale``, and the scaled parameter), which
    holds where the regime at phase 0, and with it the reduced coordinates, changes; else
    towards lambda's ``direction``."""
    n = manifold.dim
    A = np.hstack([(J - np.eye(n)) * d[:n][None, :], (dR * d[n])[:, None]]) / d[:n][:, None]
    if pin is not None:
        A = np.vstack([A, pin])
    _, _, vt = np.linalg.svd(A)
    t = vt[-1]
    t /= np.linalg.norm(t)
    if secant is not None:
        full = np.concatenate([(manifold.move(x, t[:n] * d[:n]) - x) / scale, [t[n]]])
        return t if full @ secant >= 0 else -t
    return t if t[-1] * direction >= 0 else -t


def _correct(shooter, orbit, value, manifold, d, tangent, ds, pin=None,
             finite_differences: bool = False):
    """Newton on the augmented system from the predictor; (value, Orbit, iterations) or None.
    ``finite_differences``: its Jacobian's monodromy by finite differences of the map."""
    n = manifold.dim
    x0 = orbit.state
    u = ds * tangent                                   # scaled offset from the last orbit
    t_wall = time.perf_counter()
    history = []
    try:
        for it in range(1, MAX_CORRECTOR + 1):
            lam = value + u[n] * d[n]
            ex = shooter.drive_at(lam)
            x = manifold.project(manifold.move(x0, u[:n] * d[:n]))
            record, res, scale, residual, end_regime = shooter.residual(x, orbit.regime, ex)
            history.append(residual)
            if end_regime != orbit.regime:
                return None
            J, method = ((shooter.fd_monodromy(manifold, x, orbit.regime, ex, scale),
                          "finite-difference") if finite_differences else
                         shooter.monodromy(manifold, x, orbit.regime, ex, record, scale))
            if residual <= CORRECTOR_TOL:
                if np.linalg.norm(u) > JUMP * ds:
                    return None
                found = shooter.orbit(x, orbit.regime, ex, record, J, history, it, "ok",
                                      "found", t_wall, method)
                return lam, found, it
            dR = shooter.d_parameter(manifold, x, orbit.regime, lam)
            F = np.concatenate([manifold.coordinates(res) / d[:n], [tangent @ u - ds]])
            A = np.zeros((n + 1, n + 1))
            A[:n, :n] = (J - np.eye(n)) * d[:n][None, :] / d[:n][:, None]
            A[:n, n] = dR * d[n] / d[:n]
            A[n] = tangent
            if pin is not None:
                A, F = np.vstack([A, pin]), np.concatenate([F, [pin @ u]])
            u = u - np.linalg.lstsq(A, F, rcond=None)[0]
    except ParameterError:
        return None
    return None


def _across_phase_zero(shooter, orbit, value, manifold, d, tangent, ds):
    """Where the orbit's state at phase 0 passes an event (the period map ends in another
    regime than it starts from), the corrector's manifold is the wrong one: the orbit at the
    predictor's parameter, found by shooting from the predicted state (which runs on a period
    into the regime it reaches), if it lies within JUMP x ds of the last; else None."""
    from .orbit import periodic_orbit
    n = manifold.dim
    u = ds * tangent
    lam = value + u[n] * d[n]
    x = manifold.project(manifold.move(orbit.state, u[:n] * d[:n]))
    found = periodic_orbit(shooter.params, shooter.drive_at(lam), shooter.periods,
                           guess=(x, orbit.regime), max_newton=MAX_CORRECTOR,
                           newton_tol=CORRECTOR_TOL, fixed=shooter.fixed,
                           phases=(shooter.phase,))
    if found.status not in ("ok", "grazing") or found.regime == orbit.regime:
        return None
    scale = error_scales(shooter.P, shooter.run(orbit.state, orbit.regime,
                                                shooter.drive_at(value)).states)
    if np.max(np.abs(found.state - orbit.state) / scale) > JUMP * ds:
        return None
    return lam, found, found.newton_iterations


def doublings(branch: Branch) -> list[int]:
    """The indices of the orbits after each change of stability of the branch whose
    multiplier crossed the unit circle at -1 (a period doubling, or a nonsmooth one)."""
    return [b.index for b in branch.bifurcations if b.crossing == "-1"]


def doubled_start(shooter: Shooter, branch: Branch, index: int):
    """(value, Orbit of 2K periods, side) born at the period doubling between the branch's
    orbits ``index - 1`` and ``index`` (module docstring), side +1 where it was found on the
    far orbit's side, -1 on the near one's; None where no such orbit is found."""
    from .orbit import periodic_orbit
    for side, (value, orbit) in ((1, branch.orbits[index]), (-1, branch.orbits[index - 1])):
        if orbit.status not in ("ok", "grazing") or orbit.monodromy is None \
                or not len(orbit.multipliers):
            continue
        mu, vectors = np.linalg.eig(orbit.monodromy)
        k = int(np.argmin(np.abs(mu + 1.0)))
        ex = shooter.drive_at(value)
        manifold = shooter.manifold(orbit.state, orbit.regime)
        try:
            scale = error_scales(shooter.P, shooter.run(orbit.state, orbit.regime, ex).states)
        except ParameterError:
            continue
        d = reduced_scales(manifold, scale)
        v = np.real(vectors[:, k])
        v = v / np.max(np.abs(v) / d)
        for offset in SWITCH_OFFSETS:
            guess = manifold.project(manifold.move(orbit.state, offset * v))
            found = periodic_orbit(shooter.params, ex, 2 * shooter.periods,
                                   guess=(guess, orbit.regime), fixed=shooter.fixed,
                                   phases=(shooter.phase,), monodromy=shooter.method)
            if found.status in ("ok", "grazing") and _moved_by_period(shooter, found, ex) \
                    > SAME_ORBIT:
                return value, found, side
    return None


def _moved_by_period(shooter: Shooter, orbit: Orbit, ex) -> float:
    """How far the K-period map moves a 2K-period orbit's state (largest component on its
    error scales): zero for a K-period orbit."""
    record = shooter.run(orbit.state, orbit.regime, ex)
    if not record.ok:
        return 0.0
    scale = error_scales(shooter.P, record.states)
    return float(np.max(np.abs(record.states[-1, :len(orbit.state)] - orbit.state) / scale))


def continue_doubled(shooter: Shooter, branch: Branch, index: int, lo: float, hi: float,
                     on_orbit: Callable | None = None) -> Branch:
    """The branch of twice the period born at the period doubling before the branch's orbit
    ``index``, traced from the orbit :func:`doubled_start` finds away from the crossing:
    towards ``hi`` (the parent's end) where it was found beyond the crossing, else back
    towards ``lo``.  Status "no start" where none is found."""
    t0 = time.perf_counter()
    start = doubled_start(shooter, branch, index)
    if start is None:
        out = Branch(shooter.parameter, status="no start", message=(
            f"no orbit of {2 * shooter.periods} periods found beside the period doubling at "
            f"{branch.orbits[index][0]:.6g}"))
        return _done(out, t0, on_orbit)
    value, orbit, side = start
    doubled = Shooter(shooter.params, shooter.drive_at(value), 2 * shooter.periods,
                      shooter.fixed, shooter.parameter, shooter.method)
    return continue_branch(doubled, value, hi if side > 0 else lo, on_orbit, start=orbit,
                           until=_merged)


#: A doubled orbit whose tip line at half the drive frequency is below this fraction of its
#: line at the drive frequency is the orbit of half its period again (measured: 2.6e-9 there,
#: 4e-3 on the doubled orbit 0.2 N away; strain1's ratio, 5e-6 to 7e-6 of round-off on a
#: period-1 orbit, does not tell them apart).
MERGED = 1e-6


def _merged(orbit: Orbit) -> str:
    """Why a doubled branch ends at ``orbit``: it has merged into the orbit of half its
    period (its tip's line at f / 2 below MERGED of its line at f), or ''."""
    r = orbit.responses
    if abs(r.get("tip_h0.5_cm", 1.0)) < MERGED * abs(r.get("tip_h1_cm", 0.0)):
        return "merged into the orbit of half its period"
    return ""


def found_again(shooter: Shooter, row) -> tuple[float, Orbit]:
    """(value, Orbit) of a row of :func:`branch_rows` (``shooter``'s parameter, ``state``,
    ``regime`` and ``phase``): Newton's method from the stored state, which starts on the
    orbit (its multipliers and monodromy computed anew)."""
    from .orbit import periodic_orbit
    value = float(row[shooter.parameter])
    orbit = periodic_orbit(shooter.params, shooter.drive_at(value), shooter.periods,
                           guess=(np.asarray(row["state"], float), int(row["regime"])),
                           fixed=shooter.fixed, phases=(float(row["phase"]),),
                           monodromy=shooter.method)
    return value, orbit


def continue_from(shooter: Shooter, rows, lo: float, hi: float,
                  on_orbit: Callable | None = None, doubled: bool = False) -> Branch:
    """A branch cut short, continued towards ``hi`` from the last of its orbits stored as
    ``rows`` of :func:`branch_rows` (a DataFrame), found again (:func:`found_again`), in the
    direction from the one before it; ``lo``: where the branch started (it may not fold
    back past it).  A ``doubled`` branch ends where it merges, as :func:`continue_doubled`'s
    do.  Status "no start" where the orbit is not found again."""
    t0 = time.perf_counter()
    value, orbit = found_again(shooter, rows.iloc[-1])
    previous = None
    if len(rows) > 1:
        before = rows.iloc[-2]
        previous = (float(before[shooter.parameter]), np.asarray(before["state"], float))
    if orbit.status not in ("ok", "grazing"):
        return _done(Branch(shooter.parameter, status="no start", message=(
            f"the orbit on disk at {value:.6g} was not found again: {orbit.message}")),
            t0, on_orbit)
    return continue_branch(shooter, value, hi, on_orbit, start=orbit,
                           until=_merged if doubled else None, previous=previous, back_to=lo)


def branch_rows(branch: Branch) -> list[dict]:
    """One row per orbit (CGS like the points table): the parameter, the orbit's responses,
    contact shares, events per period, the largest multiplier's modulus and angle (rad; +-pi
    for a real negative one, as at a period doubling), a stable orbit's ``settle_s``
    (:meth:`Orbit.settle_s`; nan otherwise), how the monodromy
    was taken, ``stable``, and the ``bifurcation`` between it and the one before with where
    its multiplier crossed the circle (``multiplier_crossing``: +1, -1, complex), that
    multiplier's angle (rad) and the events per period that changed; the section's drive
    ``phase`` (fraction of a period), the ``regime`` there and the orbit's ``state`` (q, q') at
    it (CGS, rad), from which :func:`found_again` finds it again."""
    marked = {b.index: b for b in branch.bifurcations}
    rows = []
    for i, (value, orbit) in enumerate(branch.orbits):
        deciding = orbit.deciding()
        row = {branch.parameter: value, "status": orbit.status, "periods": orbit.periods,
               "tip_amplitude_cm": orbit.tip_amplitude_cm, "tip_rms_cm": orbit.tip_rms_cm,
               **orbit.responses,
               **{f"share_{k}": v for k, v in orbit.contact_time_share.items()},
               **{f"{k.replace('-', '_')}_per_period": v
                  for k, v in orbit.events_per_period.items()},
               "max_multiplier": float(np.abs(deciding).max(initial=0.0)),
               "max_multiplier_angle": (float(np.angle(deciding[np.argmax(np.abs(deciding))]))
                                        if len(deciding) else float("nan")),
               "multiplier_error": orbit.multiplier_error,
               "settle_s": orbit.settle_s() or np.nan,
               "monodromy": orbit.monodromy_method,
               "stable": orbit.stable is True,
               "stability": {True: "stable", False: "unstable", None: "undetermined"}[
                   orbit.stable],
               "grazing": orbit.grazing,
               "contact_code_at_phase0": int(contact_code(orbit.regime)),
               "bifurcation": marked[i].kind if i in marked else "",
               "multiplier_crossing": marked[i].crossing if i in marked else "",
               "crossing_angle": marked[i].angle if i in marked else float("nan"),
               "events_changed": marked[i].events_changed if i in marked else "",
               "parameter_turns": bool(i in marked and marked[i].turns),
               "newton_iterations": orbit.newton_iterations,
               "residual": orbit.residual,
               "phase": orbit.phase, "regime": int(orbit.regime),
               "state": [float(x) for x in orbit.state]}
        rows.append(row)
    return rows
