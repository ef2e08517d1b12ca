"""A record against the matching simulation (seed §6): the differences, as tables.

:func:`workbench.present.comparison.compare` (``workbench compare FILE``)
draws the paper's comparisons from these and writes them:

1. time-history overlay of the sensor channels (Fig. 6);
2. power spectra of the strains and accelerations (Fig. 7-8);
3. contact switching diagrams (Fig. 9-10), both sides through the same
   detection (:func:`workbench.identify.contact_code_series`; a simulated
   patch reads 1 V while its point is closed);
4. for chirps, spectrograms of strain1 (Fig. 11-12);
5. for chirps, the FRFs (H1 and coherence of each acceleration and strain
   against force1, :mod:`workbench.lab.frf`), simulation over
   record, with the modes of each in the chirp's band (:mod:`workbench.lab.modal`;
   a sine's force has no band to refer a response to).

The differences (``differences.csv``/``.md``), over the comparison window:

* per channel: RMS of the record and of the simulation (about their
  means), their ratio, and the RMS of their difference on the record's time
  base, absolute and relative to the record's RMS;
* per channel, the three most prominent spectral peaks of the record and
  the nearest peak of the simulation: their frequencies and shift (Hz);
* per contact code, the share of time in the record and in the simulation
  and their difference;
* for chirps, the modes of the record's and the simulation's FRFs: frequency,
  damping ratio (LSCF, :mod:`workbench.lab.modal`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .channels import CHANNELS, kind
from ..identify.contacts import PATCHES, contact_code_series
from ..study.metrics import CONTACT_CODES, psd, spectral_peaks

#: Channels compared as signals (the contact patches are compared as codes).
SIGNALS = tuple(c for c in CHANNELS if kind(c) != "contact")
#: Voltage above which a patch reads as touched (the simulated patches read 0 or 1 V).
DEFAULT_THRESHOLD_V = 0.5


@dataclass
class Comparison:
    """The tables of a comparison; ``figures`` lists the files written."""

    signals: pd.DataFrame       # channel -> RMS, ratio, RMS error
    peaks: pd.DataFrame         # channel, rank -> record / simulation peak, shift
    contacts: pd.DataFrame      # code -> shares, difference
    figures: list
    frf_modes: pd.DataFrame | None = None     # source -> modes of the FRFs (lab.modal)
    notes: list = field(default_factory=list)


def window(record: pd.DataFrame, skip_s: float) -> pd.DataFrame:
    """The record after its first ``skip_s`` seconds (the transient)."""
    t = record.index.to_numpy()
    return record[t >= t[0] + skip_s]


def signal_differences(rec: pd.DataFrame, sim: pd.DataFrame) -> pd.DataFrame:
    """Per channel present in both: RMS levels, ratio and the RMS of the difference."""
    rows = []
    t = rec.index.to_numpy()
    for ch in [c for c in SIGNALS if c in rec.columns and c in sim.columns]:
        x = rec[ch].to_numpy()
        y = np.interp(t, sim.index.to_numpy(), sim[ch].to_numpy())
        rms_rec = float(np.std(x))
        rms_sim = float(np.std(y))
        err = float(np.sqrt(np.mean((y - x) ** 2)))
        rows.append(dict(channel=ch, rms_record=rms_rec, rms_simulation=rms_sim,
                         rms_ratio=rms_sim / rms_rec if rms_rec > 0 else np.nan,
                         rms_error=err, rms_error_rel=err / rms_rec if rms_rec > 0 else np.nan))
    return pd.DataFrame(rows)


def peak_shifts(rec: pd.DataFrame, sim: pd.DataFrame, n: int = 3) -> pd.DataFrame:
    """The record's ``n`` most prominent spectral peaks per channel and the simulation's
    nearest ones (Hz)."""
    rows = []
    for ch in [c for c in SIGNALS if c in rec.columns and c in sim.columns]:
        f_rec = spectral_peaks(*psd(rec.index.to_numpy(), rec[ch].to_numpy()), n=n)
        f_sim = spectral_peaks(*psd(sim.index.to_numpy(), sim[ch].to_numpy()), n=2 * n)
        for rank, f in enumerate(f_rec, 1):
            near = float(f_sim[np.argmin(np.abs(f_sim - f))]) if len(f_sim) else np.nan
            rows.append(dict(channel=ch, peak=rank, record_hz=float(f), simulation_hz=near,
                             shift_hz=near - float(f)))
    return pd.DataFrame(rows, columns=["channel", "peak", "record_hz", "simulation_hz", "shift_hz"])


def code_series(record: pd.DataFrame, threshold) -> pd.Series:
    """The contact code at each sample of a record with contact1-4 (else empty)."""
    if not all(p in record.columns for p in PATCHES):
        return pd.Series(dtype=np.int64)
    return pd.Series(contact_code_series(record, threshold), index=record.index, name="code")


def code_shares(codes: pd.Series) -> dict[int, float]:
    """Fraction of samples in each contact code."""
    if codes.empty:
        return {}
    counts = codes.value_counts(normalize=True)
    return {c: float(counts.get(c, 0.0)) for c in CONTACT_CODES}


def contact_differences(rec_codes: pd.Series, sim_codes: pd.Series) -> pd.DataFrame:
    a, b = code_shares(rec_codes), code_shares(sim_codes)
    rows = [dict(code=c, share_record=a.get(c, np.nan), share_simulation=b.get(c, np.nan),
                 difference=b.get(c, np.nan) - a.get(c, np.nan)) for c in CONTACT_CODES
            if a.get(c, 0.0) > 0 or b.get(c, 0.0) > 0]
    return pd.DataFrame(rows, columns=["code", "share_record", "share_simulation", "difference"])
