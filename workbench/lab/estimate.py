"""Parameter estimator: fit model parameters to measured records (seed §7.2, first item).

The paper names "a parameter estimator to help find the correct inputs for
use by the model" as its most important future work.  This one fits chosen
parameters (:data:`FITTABLE`) to one or more records by nonlinear least
squares (``scipy.optimize.least_squares``, trust-region reflective, bounds)
on features rather than raw time histories, which a chaotic contact
response could never match sample by sample:

* per channel, log10 of the RMS about the mean over the window;
* per channel, log10 of the power in frequency bands (Welch PSD integrated
  over :data:`BANDS_HZ`, floored at :data:`BAND_FLOOR` of the variance), which
  carries the resonances and harmonics;
* the share of time in each contact code, when the record has contact
  patches (weighted by :data:`SHARE_WEIGHT`).

Parameters are fitted in log space (all are positive), so the steps are
relative.  The Jacobian is taken by forward differences of step
:data:`FD_STEP` (a few per cent: contact makes the features rough on a
finer scale), and every simulation of one Jacobian (parameters x records)
runs in parallel on ``jobs`` worker processes (joblib), i.e. on both cores.
A simulation that fails scores :data:`FAILED_RESIDUAL` on every feature.

    fit = estimate([(record, setup)], {"e_b": 7e11, "force_n": 20.0})
    fit.values, fit.intervals, fit.cost

:func:`fit` is the same search against any targets that give residuals of a run;
:mod:`workbench.present.observed` makes the paper's §6 observations such targets.
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .compare import SIGNALS, code_series, code_shares, window
from .files import record_from_run
from .matching import Setup
from ..study.metrics import CONTACT_CODES, psd
from ..model.params import ParameterError

#: What can be fitted: name -> (where it lives, lower, upper bound).  "param" is a
#: field of Parameters (CGS), "mu" sets mu_s = mu_k, "excitation" a drive setting (N),
#: "gain" a factor on every target's own drive force (a shaker's calibration, one for all).
FITTABLE = {
    "e_a": ("param", 1.0e11, 2.0e12), "e_b": ("param", 1.0e11, 2.0e12),
    "zeta_a": ("param", 1.0e-4, 0.2), "zeta_b": ("param", 1.0e-4, 0.2),
    "mu": ("mu", 0.01, 2.0), "cork_k": ("param", 1.0, 1.0e9), "cork_c": ("param", 1.0, 1.0e7),
    "force_n": ("excitation", 0.01, 1000.0), "force_gain": ("gain", 0.01, 100.0),
}
#: Edges of the PSD bands (Hz).
BANDS_HZ = (5.0, 8.0, 12.0, 17.0, 23.0, 30.0, 40.0, 55.0, 75.0, 100.0, 140.0, 200.0)
#: Band powers below BAND_FLOOR x the channel's variance (-30 dB) count as that floor:
#: measurement noise fills empty bands, which a noise-free simulation leaves empty.
BAND_FLOOR = 1e-3
SHARE_WEIGHT = 3.0
FD_STEP = 0.02
FAILED_RESIDUAL = 10.0


def features(record: pd.DataFrame, channels, skip_s: float = 0.0) -> np.ndarray:
    """The feature vector of a record over its window after ``skip_s`` (module docstring)."""
    rec = window(record, skip_s)
    t = rec.index.to_numpy()
    out = []
    for ch in channels:
        x = rec[ch].to_numpy()
        rms = float(np.std(x))
        f, p = psd(t, x)
        df = f[1] - f[0]
        bands = [float(np.sum(p[(f >= lo) & (f < hi)]) * df)
                 for lo, hi in zip(BANDS_HZ[:-1], BANDS_HZ[1:])]
        floor = BAND_FLOOR * rms ** 2 + 1e-300
        out += [np.log10(rms + 1e-300)] + list(np.log10(np.asarray(bands) + floor))
    codes = code_series(rec, 0.5)
    if not codes.empty:
        shares = code_shares(codes)
        out += [SHARE_WEIGHT * shares[c] for c in CONTACT_CODES]
    return np.asarray(out)


def _apply(setup: Setup, values: dict[str, float]) -> Setup:
    params, exc = {}, dict(setup.excitation)
    for name, value in values.items():
        where = FITTABLE[name][0]
        if where in ("excitation", "gain"):
            if "force_n" not in exc or (where == "excitation" and name not in exc):
                raise ParameterError(f"{name} is not a setting of a {exc['drive']} drive")
            exc["force_n"] = value if where == "excitation" else value * exc["force_n"]
        elif where == "mu":
            params.update(mu_s=value, mu_k=value)
        else:
            params[name] = value
    return dataclasses.replace(setup, params=setup.params.replace(**params), excitation=exc)


@dataclass(frozen=True)
class RecordTarget:
    """A measured record as a target: the residuals are the simulated record's features
    less the measured one's (module docstring)."""

    setup: Setup
    target: np.ndarray
    channels: tuple
    skip_s: float

    @property
    def labels(self) -> list[str]:
        return [f"feature {i}" for i in range(len(self.target))]

    def residuals(self, run) -> np.ndarray:
        return features(record_from_run(run), self.channels, self.skip_s) - self.target


def _simulated_residuals(target, values: dict):
    run = _apply(target.setup, values).simulate()
    if not run.ok:
        return np.full(len(target.labels), FAILED_RESIDUAL), False
    return np.asarray(target.residuals(run), dtype=float), True


@dataclass
class Estimate:
    """The fitted values, their two-sigma intervals and how the fit went; ``residuals``
    at the fitted values, one per ``labels``."""

    values: dict
    start: dict
    intervals: dict
    cost: float
    n_simulations: int
    success: bool
    message: str
    wall_s: float
    history: list = field(default_factory=list)     # (values, cost) of each residual evaluation
    residuals: np.ndarray = field(default_factory=lambda: np.zeros(0))
    labels: list = field(default_factory=list)

    def table(self, truth: dict | None = None) -> pd.DataFrame:
        rows = []
        for name, value in self.values.items():
            lo, hi = self.intervals[name]
            row = dict(parameter=name, start=self.start[name], fitted=value, low_2sigma=lo,
                       high_2sigma=hi)
            if truth:
                row.update(truth=truth[name], error_rel=value / truth[name] - 1.0)
            rows.append(row)
        return pd.DataFrame(rows)


def estimate(records: list[tuple[pd.DataFrame, Setup]], start: dict[str, float], *,
             channels=None, skip_s: float = 0.0, bounds: dict | None = None, jobs: int = 2,
             max_nfev: int = 30, xtol: float = 1e-3, fd_step: float = FD_STEP) -> Estimate:
    """Fit the parameters named in ``start`` (initial values, CGS; force_n in N) to
    ``records``, each a (record, Setup) pair; see the module docstring."""
    check_start(start, bounds)
    channels = tuple(channels or [c for c in SIGNALS if c != "force1"
                                  and all(c in rec.columns for rec, _ in records)])
    targets = [RecordTarget(setup, features(rec, channels, skip_s), channels, skip_s)
               for rec, setup in records]
    return fit(targets, start, bounds=bounds, jobs=jobs, max_nfev=max_nfev, xtol=xtol,
               fd_step=fd_step)


def check_start(start: dict, bounds: dict | None = None) -> dict:
    """The bounds of each parameter in ``start``; a ParameterError if one cannot be fitted
    or starts outside its bounds."""
    unknown = sorted(set(start) - set(FITTABLE))
    if unknown or not start:
        raise ParameterError(f"cannot fit {unknown or 'nothing'}: fittable are {', '.join(FITTABLE)}")
    lims = {n: (bounds or {}).get(n, FITTABLE[n][1:]) for n in start}
    for n, (lo, hi) in lims.items():
        if not lo < start[n] < hi:
            raise ParameterError(f"start {n} = {start[n]:g} is outside the allowed range "
                                 f"({lo:g}, {hi:g})")
    return lims


def fit(targets: list, start: dict[str, float], *, bounds: dict | None = None, jobs: int = 2,
        max_nfev: int = 30, xtol: float = 1e-3, fd_step: float = FD_STEP) -> Estimate:
    """Fit the parameters named in ``start`` to ``targets``: each has a ``setup`` (a
    :class:`~workbench.lab.matching.Setup`), ``labels`` (one per residual) and
    ``residuals(run)``, zero where the run matches it (:class:`RecordTarget`, or the paper's
    observations of :mod:`workbench.present.observed`).  Nonlinear least squares in the
    parameters' logs within ``bounds`` (default FITTABLE's), the Jacobian by forward
    differences of ``fd_step``, every simulation of one Jacobian in parallel on ``jobs``
    processes."""
    from joblib import Parallel, delayed
    from scipy.optimize import least_squares

    lims = check_start(start, bounds)
    names = list(start)
    pool = Parallel(n_jobs=jobs, prefer="processes")
    cache: dict[bytes, np.ndarray] = {}
    history = []
    t_wall = time.perf_counter()

    def values_of(x):
        return dict(zip(names, np.exp(x)))

    def residuals_many(xs):
        todo = [x for x in xs if x.tobytes() not in cache]
        jobs_ = [(x, target) for x in todo for target in targets]
        out = pool(delayed(_simulated_residuals)(target, values_of(x)) for x, target in jobs_)
        for k, x in enumerate(todo):
            r = np.concatenate([out[k * len(targets) + i][0] for i in range(len(targets))])
            cache[x.tobytes()] = r
            history.append((values_of(x), 0.5 * float(r @ r)))
        return [cache[x.tobytes()] for x in xs]

    def fun(x):
        return residuals_many([np.asarray(x, dtype=float)])[0]

    def jac(x):
        x = np.asarray(x, dtype=float)
        steps = [x + fd_step * np.eye(len(x))[j] for j in range(len(x))]
        r0, *rs = residuals_many([x] + steps)
        return np.column_stack([(r - r0) / fd_step for r in rs])

    with pool:
        x0 = np.log([start[n] for n in names])
        lo = np.log([lims[n][0] for n in names])
        hi = np.log([lims[n][1] for n in names])
        res = least_squares(fun, x0, jac=jac, bounds=(lo, hi), method="trf", x_scale=1.0,
                            diff_step=None, max_nfev=max_nfev, xtol=xtol)
        jac_end = jac(res.x)
    dof = max(len(res.fun) - len(names), 1)
    cov = float(res.fun @ res.fun) / dof * np.linalg.pinv(jac_end.T @ jac_end)
    half = 2.0 * np.sqrt(np.maximum(np.diag(cov), 0.0))
    fitted = values_of(res.x)
    intervals = {n: (fitted[n] * float(np.exp(-h)), fitted[n] * float(np.exp(h)))
                 for n, h in zip(names, half)}
    labels = [label for target in targets for label in target.labels]
    return Estimate(fitted, dict(start), intervals, float(res.cost), len(cache) * len(targets),
                    bool(res.success), str(res.message), time.perf_counter() - t_wall, history,
                    np.asarray(res.fun, dtype=float), labels)
