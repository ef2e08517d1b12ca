"""Cork stiffness and damping (seed §4.3, Tables 5-6; docs/model.md §6).

Two methods, as in the paper:

* :func:`hooke_stiffness`: a static compression, k = F / (pre-load gap - load gap)
  (Table 5);
* :func:`fit_cork`: the axial hammer test.  The tip is struck axially and
  its accelerometer records the damped slide of the loose body, beam B and
  the tip mass on the cork.  An exhaustive search over the hammer's
  velocity v0, the stiffness k and the damping c scores each combination
  by the squared difference between the modelled and the recorded
  acceleration (Table 6), for a linear, quadratic or cubic spring.

The forward model is one mass on the cork law, m s'' = -k sign(s)|s|^n - c s'
(:mod:`workbench.core.hammer`), with m from :func:`sliding_mass`.  The
search is the paper's grid, followed by ``refine`` zoomed grids about the
best point; each grid runs in parallel on every core (numba prange).

The fit also reports, per parameter, the range the record cannot tell
apart from the best value: the values whose profile (the least score over
the other two parameters) is within ``4 sigma^2`` of the best score
(sigma^2 = best score / samples, the residual variance), a two-sigma
profile-likelihood interval for Gaussian noise; 0 or inf where it runs to
the end of the searched range.  (A linearised covariance is no substitute: at
a spurious minimum of a flat direction it reports a narrow interval that
misses the truth.  Measured on a quadratic-spring record.)  A cubic
spring stiffness at hammer velocities of cm/s is barely felt
(k |s|^3 ~ 10 dyn against c v ~ 1e5 dyn), so its interval is wide: that is
a property of the test, and the fit says so rather than pretending.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core import layout as ly
from ..core.hammer import hammer_response, hammer_scores
from ..model.params import CORK_MODELS, ParameterError, Parameters, check_positive

#: Spring exponent of each law the paper fitted (Table 6), from the model's table.
CORK_LAWS = {law: CORK_MODELS[law].n for law in ("linear", "quadratic", "cubic")}
#: The searched parameters, in the order of the score array's axes.
NAMES = ("v0", "k", "c")
#: Values per parameter of the profile behind the intervals, over the searched range.
PROFILE_POINTS = 41
#: RK4 substeps per record sample of the hammer model.
SUBSTEPS = 4


def hooke_stiffness(load: float, pre_load_gap: float, load_gap: float) -> float:
    """k = F / (pre-load gap - load gap) (g/s^2; Table 5).

    ``load`` in dyn (g cm/s^2), the gaps in cm before and under the load.
    """
    load = check_positive("load", load, "dyn")
    closing = check_positive("pre_load_gap", pre_load_gap, "cm") - check_positive(
        "load_gap", load_gap, "cm")
    if closing <= 0:
        raise ParameterError(f"load_gap = {load_gap} cm must be below pre_load_gap = "
                             f"{pre_load_gap} cm: the load closes the gap")
    return load / closing


def sliding_mass(p: Parameters | None = None) -> float:
    """The mass that slides axially on the cork (g): loose body + beam B (+ tip mass)."""
    p = p or Parameters()
    return p.m4 + p.mu_b * p.l_b + (p.m6 if p.tip_mass else 0.0)


def _law_exponent(law: str) -> float:
    if law not in CORK_LAWS:
        raise ParameterError(f"law = {law!r}: use one of {', '.join(CORK_LAWS)}")
    return CORK_LAWS[law]


def hammer_record(law: str, k: float, c: float, v0: float, *, mass: float | None = None,
                  dt: float = 1e-4, duration: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and axial tip acceleration (cm/s^2) of the hammer model.

    ``k`` in g/(s^2 cm^(n-1)), ``c`` in g/s, ``v0`` the velocity the hammer
    gives (cm/s), ``mass`` (g, default :func:`sliding_mass`).
    """
    n_exp = _law_exponent(law)
    mass = sliding_mass() if mass is None else check_positive("mass", mass, "g")
    dt = check_positive("dt", dt, "s")
    n = int(round(check_positive("duration", duration, "s") / dt)) + 1
    out = np.empty(n)
    status = hammer_response(mass, n_exp, check_positive("k", k, "g/(s^2 cm^(n-1))", True),
                             check_positive("c", c, "g/s", True), float(v0), dt, SUBSTEPS, out)
    if status != ly.OK:
        raise ParameterError(f"the hammer model diverged (k = {k}, c = {c}, v0 = {v0}): "
                             "use a smaller dt")
    return np.arange(n) * dt, out


@dataclass(frozen=True)
class CorkFit:
    """The best (v0, k, c) of the search and what the record allows."""

    law: str
    v0: float            #: hammer velocity (cm/s)
    k: float             #: stiffness, g/(s^2 cm^(n-1))
    c: float             #: damping (g/s)
    score: float         #: sum of squared differences at the best point ((cm/s^2)^2)
    rms_residual: float  #: sqrt(score / samples) (cm/s^2)
    #: parameter -> (low, high): two-sigma profile interval (module docstring)
    intervals: dict = field(default_factory=dict)
    evaluations: int = 0

    def as_dict(self) -> dict:
        return dict(law=self.law, v0=self.v0, k=self.k, c=self.c, score=self.score,
                    rms_residual=self.rms_residual, evaluations=self.evaluations,
                    **{f"{name}_low": lo for name, (lo, _) in self.intervals.items()},
                    **{f"{name}_high": hi for name, (_, hi) in self.intervals.items()})


def _uniform_dt(t: np.ndarray) -> float:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or len(t) < 10:
        raise ParameterError(f"the record needs at least 10 samples, got {t.shape}")
    dt = np.diff(t)
    if not np.all(dt > 0) or np.ptp(dt) > 1e-6 * dt.mean():
        raise ParameterError("the record's times must be uniformly spaced and increasing")
    return float(dt.mean())


def default_grid(law: str, n: int = 21) -> dict[str, np.ndarray]:
    """The search ranges: a decade and a half about Table 6's values (log spacing
    for k and c), v0 in 1-100 cm/s."""
    k_paper = CORK_MODELS[law].k
    c_paper = CORK_MODELS[law].c
    return {"v0": np.geomspace(1.0, 100.0, n), "k": np.geomspace(k_paper / 30, k_paper * 30, n),
            "c": np.geomspace(c_paper / 30, c_paper * 30, n)}


def fit_cork(t: np.ndarray, accel: np.ndarray, law: str = "linear", *, mass: float | None = None,
             grid: dict[str, np.ndarray] | None = None, refine: int = 3,
             intervals: bool = True) -> CorkFit:
    """Exhaustive search for the hammer velocity, cork stiffness and damping (Table 6).

    ``t`` (s, uniform, t[0] the impact) and ``accel`` (cm/s^2) of the axial
    tip accelerometer; ``law`` linear, quadratic or cubic; ``grid`` maps
    "v0", "k", "c" to increasing arrays of candidates (default
    :func:`default_grid`); ``refine`` zoomed searches follow, each a grid
    of the same size spanning two cells of the last one about its best
    point.  ``intervals`` adds each parameter's two-sigma interval (module docstring).
    """
    n_exp = _law_exponent(law)
    dt = _uniform_dt(t)
    record = np.ascontiguousarray(accel, dtype=float)
    if record.shape != np.shape(t) or not np.all(np.isfinite(record)):
        raise ParameterError("accel must be finite and as long as t")
    mass = sliding_mass() if mass is None else check_positive("mass", mass, "g")
    grid_in = grid
    grid = _initial_grid(law, grid)
    searched = _search(mass, n_exp, dt, record, grid, refine)
    grid, scores = searched[-1]
    best = np.unravel_index(int(np.argmin(scores)), scores.shape)
    best_score = float(scores[best])
    sigma2 = best_score / len(record)
    fit = dict(zip(NAMES, (float(grid[name][i]) for name, i in zip(NAMES, best))))
    if intervals:
        intervals = _intervals(law, fit, mass, dt, record, best_score + 4.0 * sigma2,
                               _initial_grid(law, grid_in))
    return CorkFit(law, fit["v0"], fit["k"], fit["c"], best_score, float(np.sqrt(sigma2)),
                   intervals, sum(s.size for _, s in searched))


def _search(mass, n_exp, dt, record, grid, refine):
    """The grid search and its zoomed refinements: [(grid, scores), ...] of every round."""
    searched = []
    for round_ in range(refine + 1):
        scores = np.empty((len(grid["v0"]), len(grid["k"]), len(grid["c"])))
        hammer_scores(mass, n_exp, grid["v0"], grid["k"], grid["c"], dt, SUBSTEPS, record, scores)
        searched.append((grid, scores))
        if round_ < refine:
            best = np.unravel_index(int(np.argmin(scores)), scores.shape)
            grid = {name: _zoom(grid[name], i) for name, i in zip(NAMES, best)}
    return searched


def _intervals(law, fit, mass, dt, record, threshold, wide, bisections=12):
    """Per parameter, the values whose profile (the least score over the other two,
    by Nelder-Mead in log parameters) stays within ``threshold``: (low, high).

    The profile is walked outward from the best value over PROFILE_POINTS
    log-spaced values of the searched range ``wide``; each end is then
    bisected in log between the last value inside and the first outside.
    An end that reaches the searched range is 0 (low) or inf (high).
    """
    from scipy.optimize import minimize

    n_exp = _law_exponent(law)
    buf = np.empty(len(record))

    def score(values: dict) -> float:
        hammer_response(mass, n_exp, values["k"], values["c"], values["v0"], dt, SUBSTEPS, buf)
        return float(np.sum((buf - record) ** 2)) if np.all(np.isfinite(buf)) else np.inf

    out = {}
    for name in NAMES:
        others = [o for o in NAMES if o != name]

        def profile(value, start):
            res = minimize(lambda x: score({name: value, **dict(zip(others, np.exp(x)))}),
                           start, method="Nelder-Mead", options=dict(xatol=1e-5, fatol=1e-9))
            return res.fun <= threshold, res.x

        ends = []
        for stop in (wide[name][0], wide[name][-1]):
            inner, start = fit[name], np.log([fit[o] for o in others])
            outer = None
            for value in np.geomspace(fit[name], stop, PROFILE_POINTS // 2 + 1)[1:]:
                ok, x = profile(value, start)
                if not ok:
                    outer = value
                    break
                inner, start = value, x
            if outer is None:
                ends.append(np.inf)
                continue
            for _ in range(bisections):
                middle = float(np.sqrt(inner * outer))
                ok, x = profile(middle, start)
                inner, outer, start = (middle, outer, x) if ok else (inner, middle, start)
            ends.append(inner)
        out[name] = (0.0 if np.isinf(ends[0]) else ends[0], ends[1])
    return out


def _initial_grid(law, grid):
    grid = {k: np.asarray(v, dtype=float) for k, v in (grid or default_grid(law)).items()}
    if sorted(grid) != sorted(NAMES) or any(len(v) < 3 or np.any(np.diff(v) <= 0) or v[0] <= 0
                                           for v in grid.values()):
        raise ParameterError("grid must map 'v0', 'k', 'c' to increasing positive arrays "
                             "of >= 3 values")
    return grid


def _zoom(values: np.ndarray, i: int) -> np.ndarray:
    """A grid of the same size over the neighbouring cells of values[i], log-spaced
    (the zoom keeps the relative resolution); a single value stays fixed."""
    if len(values) == 1:
        return values
    return np.geomspace(values[max(i - 1, 0)], values[min(i + 1, len(values) - 1)], len(values))
