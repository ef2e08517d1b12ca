"""Global sensitivity: a Sobol' design over parameter ranges and the Sobol' indices of each output.

A study with a ``[sample]`` table instead of ``[axes]`` runs the points of a
Saltelli design (SALib: Sobol' sequences, Saltelli's cross-sampling):

    [sample]
    design = "sobol"                 # the only design
    n = 128                          # base samples (a power of 2); n (D + 2) points
    seed = 20261126                  # the scrambled sequence's seed: the same points every run
    same = {mu_k = "mu_s"}           # optional: a parameter that takes another's sampled value
    resamples = 1000                 # optional: bootstrap resamples of the confidence intervals

    [ranges]                         # D inputs, each drawn uniformly
    mu_s = [0.1, 0.6]                # an interval of a model or excitation parameter (user units)
    cork = ["linear", "cubic"]       # a choice among values, each with the same probability
    cork_k = {times = [0.5, 2.0]}    # a factor of the value the point has otherwise (the cork
                                     # law's own k here)

First-order indices S1 (the share of an output's variance that an input
explains alone) and total indices ST (alone and with all others) come from
SALib's estimators (Saltelli et al. 2010, Comput. Phys. Commun. 181, 259),
with bootstrap confidence intervals at 95 %.  A choice enters as a uniform
number on [0, k) whose integer part picks the value: a discrete uniform
input, to which the indices apply unchanged.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..model.params import ParameterError

SAMPLE_KEYS = {"design", "n", "seed", "same", "resamples"}
DESIGNS = ("sobol",)
DEFAULT_RESAMPLES = 1000
CONF_LEVEL = 0.95
#: Largest base sample (2^16 base samples of a dozen inputs: a million points).
MAX_N = 2 ** 16


@dataclass(frozen=True)
class Range:
    """One input of the design: an interval, a choice, or a factor of the point's own value."""

    name: str                        # as the user wrote it (a parameter name, unit suffix allowed)
    kind: str                        # "interval", "choice" or "times"
    lo: float = 0.0
    hi: float = 1.0
    choices: tuple = ()

    @property
    def bounds(self) -> list[float]:
        """The uniform interval the design draws this input from."""
        return [0.0, float(len(self.choices))] if self.kind == "choice" else [self.lo, self.hi]

    def value(self, u: float):
        """The input's value at the design's number u (a factor for "times")."""
        if self.kind == "choice":
            return self.choices[min(int(math.floor(u)), len(self.choices) - 1)]
        return float(u)


@dataclass(frozen=True)
class Sample:
    """A validated ``[sample]`` table with its ``[ranges]``."""

    ranges: tuple
    n: int
    seed: int
    same: dict
    resamples: int = DEFAULT_RESAMPLES
    design: str = "sobol"

    @property
    def names(self) -> list[str]:
        return [r.name for r in self.ranges]

    @property
    def problem(self) -> dict:
        """SALib's problem: the inputs' names and the intervals drawn from."""
        return {"num_vars": len(self.ranges), "names": self.names,
                "bounds": [r.bounds for r in self.ranges]}

    @property
    def n_points(self) -> int:
        return self.n * (len(self.ranges) + 2)

    def design_matrix(self) -> np.ndarray:
        """The Saltelli design: n (D + 2) rows of D numbers (first-order and total indices)."""
        from SALib.sample import sobol
        return sobol.sample(self.problem, self.n, calc_second_order=False, scramble=True,
                            seed=self.seed)

    def values(self, row: np.ndarray) -> tuple[dict, dict]:
        """A design row as ({name: value} of intervals and choices, {name: factor} of "times")."""
        plain, factors = {}, {}
        for r, u in zip(self.ranges, row):
            (factors if r.kind == "times" else plain)[r.name] = r.value(u)
        return plain, factors


def parse(sample: dict, ranges: dict, error=ParameterError) -> Sample:
    """Check a ``[sample]`` and a ``[ranges]`` table; ``error`` is the exception raised."""
    bad = sorted(set(sample) - SAMPLE_KEYS)
    if bad:
        raise error(f"[sample] unknown key(s) {bad}; allowed: {sorted(SAMPLE_KEYS)}")
    design = sample.get("design", "sobol")
    if design not in DESIGNS:
        raise error(f"[sample] design = {design!r}; allowed: {list(DESIGNS)}")
    n = sample.get("n")
    if isinstance(n, bool) or not isinstance(n, int) or not 2 <= n <= MAX_N or n & (n - 1):
        raise error(f"[sample] n = {n!r} must be a power of 2 from 2 to {MAX_N} "
                    "(the Sobol' sequence's balance)")
    seed = sample.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise error(f"[sample] seed = {seed!r} must be a whole number >= 0")
    resamples = sample.get("resamples", DEFAULT_RESAMPLES)
    if isinstance(resamples, bool) or not isinstance(resamples, int) or not 10 <= resamples <= 100_000:
        raise error(f"[sample] resamples = {resamples!r} must be a whole number from 10 to 100000")
    if not isinstance(ranges, dict) or not ranges:
        raise error("[sample] needs a [ranges] table of at least one input")
    out = []
    for name, spec in ranges.items():
        out.append(_range(name, spec, error))
    same = sample.get("same", {})
    if not isinstance(same, dict):
        raise error(f"[sample] same must be a table such as {{mu_k = \"mu_s\"}}, got {same!r}")
    for target, source in same.items():
        if source not in ranges:
            raise error(f"[sample] same: {target} = {source!r} names no input of [ranges] "
                        f"({sorted(ranges)})")
        if target in ranges:
            raise error(f"[sample] same: {target} is an input of [ranges] itself")
    return Sample(tuple(out), n, seed, dict(same), resamples, design)


def _range(name: str, spec, error) -> Range:
    where = f"[ranges] {name}"
    if isinstance(spec, dict):
        if set(spec) != {"times"}:
            raise error(f"{where} = {spec!r}: a table takes one key, times = [lo, hi]")
        lo, hi = _interval(where + ".times", spec["times"], error)
        if lo <= 0:
            raise error(f"{where}.times = {spec['times']!r}: factors must be > 0")
        return Range(name, "times", lo, hi)
    if isinstance(spec, list) and spec and all(isinstance(v, str) for v in spec):
        if len(set(spec)) != len(spec):
            raise error(f"{where} lists a value twice: {spec!r}")
        return Range(name, "choice", choices=tuple(spec))
    lo, hi = _interval(where, spec, error)
    return Range(name, "interval", lo, hi)


def _interval(where: str, spec, error) -> tuple[float, float]:
    if (not isinstance(spec, list) or len(spec) != 2
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in spec)
            or not all(math.isfinite(v) for v in spec) or not spec[0] < spec[1]):
        raise error(f"{where} = {spec!r} must be [lo, hi] with lo < hi, a list of strings "
                    "(a choice) or {times = [lo, hi]}")
    return float(spec[0]), float(spec[1])


def indices(sample: Sample, y: np.ndarray) -> pd.DataFrame:
    """Sobol' indices of one output ``y`` (one value per design row, in the design's order).

    Rows with a NaN (a failed point, or an output a point does not have)
    take their whole block of D + 2 rows out (the estimators pair each base
    sample's rows); the remaining blocks' count is ``n_used``.  Returns one
    row per input: S1, S1_conf, ST, ST_conf (half widths of the 95 %
    bootstrap intervals), n_used.
    """
    from SALib.analyze import sobol
    y = np.asarray(y, dtype=float)
    d = len(sample.ranges)
    if y.shape != (sample.n_points,):
        raise ValueError(f"{y.shape[0] if y.ndim else 0} outputs for a design of "
                         f"{sample.n_points} points")
    blocks = y.reshape(sample.n, d + 2)
    whole = np.isfinite(blocks).all(axis=1)
    used = int(whole.sum())
    if used < 2 or np.ptp(blocks[whole]) == 0.0:
        nan = np.full(d, np.nan)
        return pd.DataFrame({"input": sample.names, "S1": nan, "S1_conf": nan, "ST": nan,
                             "ST_conf": nan, "n_used": used})
    res = sobol.analyze(sample.problem, blocks[whole].ravel(), calc_second_order=False,
                        num_resamples=sample.resamples, conf_level=CONF_LEVEL,
                        seed=sample.seed)
    return pd.DataFrame({"input": sample.names, "S1": res["S1"], "S1_conf": res["S1_conf"],
                         "ST": res["ST"], "ST_conf": res["ST_conf"], "n_used": used})
