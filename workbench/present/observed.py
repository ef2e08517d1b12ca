"""The paper's §6 observations as targets of the estimator (the inverse question).

The paper gives no records to fit, only observations: the simulation switches
mostly between contact codes 14 and 23 (Fig. 9), the strain shows a 10 Hz
subharmonic of the 20 Hz drive (Fig. 7-8), and the 5-65 Hz, 240 s chirp shows
bands of resonance near 0.83, 1.67 and 3 minutes (Fig. 11-12).  Each is judged
by the rule of :mod:`workbench.present.observations`; here each becomes a
miss, how far a run misses the rule in units of the rule's own scale (0 and
below where it holds):

- switching (:class:`SineObservations`): for codes 14 and 23,
  ``(DOMINANT_SHARE - share) / DOMINANT_SHARE``;
- the subharmonic: ``(LINE_MARGIN_DB - level) / LINE_MARGIN_DB`` of strain1's
  10 Hz line over its floor (a record without a floor counts as a full miss,
  1);
- each paper band (:class:`ChirpBands`): ``(d - BAND_MATCH_MIN) /
  BAND_MATCH_MIN`` with d the distance (min) to the nearest band the run
  shows; with no band at all, d is the chirp's length.

The residual is ``max(0, miss + SEARCH_MARGIN)``: 0 only where each rule holds
with a margin, so that a search, which approaches a boundary from outside,
ends inside it.  The estimator's cost (half the sum of squares) is 0 where
every observation holds with that margin, and
:func:`workbench.lab.estimate.fit` searching the parameters within
their ranges either finds such a set or ends where the misses are smallest;
:func:`misses` says which rules still miss there (a miss above 0).

    targets = paper_targets(Parameters().replace(gap_mm=1.016))
    result = fit(targets, {"e_a": 5.0e11, "e_b": 4.7e11}, bounds=...)
    misses(result)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import observations as O
from ..lab.matching import Setup
from ..model.params import Parameters
from ..model.regimes import contact_shares_of
from ..study.metrics import LINE_MARGIN_DB, line_level

#: The records' sample rate (Hz); the cases are those of present/observations.py.
OUTPUT_HZ = 1000.0
#: How far inside each rule a residual reaches 0 (a fraction of the rule's scale).
SEARCH_MARGIN = 0.05


def residual(miss):
    """The search's residual of a rule's miss (module docstring)."""
    return np.maximum(0.0, np.asarray(miss, dtype=float) + SEARCH_MARGIN)


class _Observed:
    """A case's observations as a target: ``measures(run)`` (a dict), ``miss(measures)`` (one
    per ``labels``) and the search's ``residuals(run)``."""

    def residuals(self, run) -> np.ndarray:
        return residual(self.miss(self.measures(run)))


@dataclass(frozen=True)
class SineObservations(_Observed):
    """Fig. 7-10 on a 20 Hz sine run: codes 14 and 23 dominate, the subharmonic is present."""

    setup: Setup
    skip_s: float = O.SINE_SKIP_S

    @property
    def labels(self) -> list[str]:
        return ["share of 14 (Fig. 9)", "share of 23 (Fig. 9)", "10 Hz subharmonic (Fig. 7-8)"]

    def measures(self, run) -> dict:
        sig = run.signals
        t = sig.index.to_numpy()
        keep = t >= self.skip_s - 1e-12
        shares = contact_shares_of(run.log[:, 0], run.log[:, 3], self.skip_s, float(t[-1]))
        sub = line_level(t[keep], sig.strain1.to_numpy()[keep], O.SUBHARMONIC_HZ)
        return {"share_14": shares.get("14", 0.0), "share_23": shares.get("23", 0.0),
                "sub_db": sub["level_db"]}

    def miss(self, m: dict) -> np.ndarray:
        """Each rule's miss (module docstring) given the measures."""
        sub = 1.0 if np.isnan(m["sub_db"]) else (LINE_MARGIN_DB - m["sub_db"]) / LINE_MARGIN_DB
        return np.array([(O.DOMINANT_SHARE - m["share_14"]) / O.DOMINANT_SHARE,
                         (O.DOMINANT_SHARE - m["share_23"]) / O.DOMINANT_SHARE, sub])


@dataclass(frozen=True)
class ChirpBands(_Observed):
    """Fig. 11-12 on a chirp run: a band within BAND_MATCH_MIN of each of the paper's."""

    setup: Setup
    skip_s: float = O.CHIRP_SKIP_S

    @property
    def labels(self) -> list[str]:
        return [f"chirp band near {b:g} min (Fig. 11-12)" for b in O.PAPER_BANDS_MIN]

    def measures(self, run) -> dict:
        sig = run.signals
        bands = O.resonance_bands(sig.index.to_numpy(), sig.strain1.to_numpy(), self.skip_s)
        return {"bands_min": [b / 60.0 for b in bands]}

    def miss(self, m: dict) -> np.ndarray:
        """Each paper band's miss given the measures."""
        return band_misses(m["bands_min"], self.setup.duration / 60.0)


def band_misses(bands_min, chirp_min: float) -> np.ndarray:
    """Each paper band's miss (module docstring) given the bands a run shows (min)."""
    found = np.asarray(bands_min, dtype=float)
    d = [float(np.min(np.abs(found - b))) if found.size else chirp_min for b in O.PAPER_BANDS_MIN]
    return (np.array(d) - O.BAND_MATCH_MIN) / O.BAND_MATCH_MIN


def paper_targets(params: Parameters, sine_force_n: float, chirp_force_n: float,
                  initial: str = "static") -> list:
    """The paper's two cases as targets, with ``params``: the sine (switching and the
    subharmonic) at ``sine_force_n`` and the chirp (its bands) at ``chirp_force_n`` (N),
    each from ``initial`` ("static" or "paper")."""
    sine = {"drive": "sine", "force_n": sine_force_n, "freq_hz": O.DRIVE_HZ, "ramp_s": O.RAMP_S}
    chirp = {"drive": "chirp", "force_n": chirp_force_n, "f0_hz": O.CHIRP_F0_HZ,
             "f1_hz": O.CHIRP_F1_HZ, "sweep_s": O.CHIRP_S, "ramp_s": O.RAMP_S}
    return [SineObservations(Setup(params, sine, O.SINE_S, OUTPUT_HZ, initial)),
            ChirpBands(Setup(params, chirp, O.CHIRP_S, OUTPUT_HZ, initial))]


def misses(result) -> list[tuple[str, float]]:
    """The observations a fit still misses at its values: (label, miss > 0)."""
    return [(label, float(r) - SEARCH_MARGIN) for label, r in zip(result.labels, result.residuals)
            if r > SEARCH_MARGIN]
