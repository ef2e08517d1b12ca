"""``workbench compare FILE``: a record against the matching simulation (seed §6).

The four comparisons of the paper, as figures, and a table of differences:

1. time-history overlay of the sensor channels (Fig. 6);
2. power spectra of the strains and accelerations (Fig. 7-8);
3. contact switching diagrams (Fig. 9-10), both sides through the same
   detection (:func:`workbench.identify.contact_code_series`; a simulated
   patch reads 1 V while its point is closed);
4. for chirps, spectrograms of strain1 (Fig. 11-12);
5. for chirps, the FRFs (H1 and coherence of each acceleration and strain
   against force1, :mod:`workbench.experiments.frf`), simulation over
   record, with the peaks of each in the chirp's band (a sine's force has
   no band to refer a response to).

The differences (``differences.csv``/``.md``), over the comparison window:

* per channel: RMS of the record and of the simulation (about their
  means), their ratio, and the RMS of their difference on the record's time
  base, absolute and relative to the record's RMS;
* per channel, the three most prominent spectral peaks of the record and
  the nearest peak of the simulation: their frequencies and shift (Hz);
* per contact code, the share of time in the record and in the simulation
  and their difference;
* for chirps, the FRF peaks of record and simulation: frequency, |H1|, coherence and
  half-power damping ratio.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .channels import CHANNELS, kind
from .files import record_from_run
from .frf import frf, peak_table, segment_for
from ..model.params import ParameterError
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
    frf_peaks: pd.DataFrame | None = None     # source, response -> FRF peaks
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


def compare(record: pd.DataFrame, run, out: str | Path, *, skip_s: float = 0.0,
            threshold=DEFAULT_THRESHOLD_V, seconds: float = 0.5, chirp: bool = False,
            band: tuple[float, float] | None = None, title: str = "") -> Comparison:
    """Compare ``record`` with a simulated ``run`` and write figures and tables into ``out``;
    ``band`` (Hz) limits the FRF peaks to where the drive has force (a chirp's band)."""
    from ..present import figures as F

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    sim = record_from_run(run)
    sim.index = sim.index + record.index[0]          # the simulation starts with the record
    rec_w, sim_w = window(record, skip_s), window(sim, skip_s)
    rec_codes, sim_codes = code_series(rec_w, threshold), code_series(sim_w, DEFAULT_THRESHOLD_V)
    result = Comparison(signal_differences(rec_w, sim_w), peak_shifts(rec_w, sim_w),
                        contact_differences(rec_codes, sim_codes), [])
    sources = {"record": rec_w, "simulation": sim_w}
    channels = [c for c in SIGNALS if c in record.columns]
    result.figures += F.save(F.overlay_time_history(sources, channels, title, seconds),
                             out / "time_history")
    spectra = [c for c in channels if kind(c) != "force"] or channels
    result.figures += F.save(F.overlay_spectra(sources, spectra, title), out / "spectra")
    if not rec_codes.empty:
        result.figures += F.save(F.code_series_diagrams(
            {"record": rec_codes, "simulation": sim_codes}, title, seconds), out / "switching")
    if chirp and "strain1" in record.columns:
        for name, rec in sources.items():
            result.figures += F.save(F.spectrogram(rec, f"{title} — {name}"),
                                     out / f"spectrogram_{name}")
    responses = [c for c in channels if kind(c) in ("accel", "strain")]
    if chirp and "force1" in rec_w.columns and responses:
        try:
            seg = segment_for(rec_w)
            tables = {name: frf(rec, responses, segment_s=seg) for name, rec in sources.items()}
        except ParameterError as exc:
            result.notes.append(f"FRFs not computed: {exc}")
        else:
            f_lo, f_hi = band or (0.0, None)
            result.frf_peaks = peak_table(tables, responses, f_lo, f_hi)
            result.figures += F.save(F.frf_figure(tables, responses, f"{title}: H1 against force1",
                                                  1.2 * f_hi if f_hi else None), out / "frf")
    _write_tables(result, out, title)
    return result


def _write_tables(result: Comparison, out: Path, title: str) -> None:
    tables = {"signals": result.signals, "peaks": result.peaks, "contacts": result.contacts}
    if result.frf_peaks is not None:
        tables["frf_peaks"] = result.frf_peaks
    md = [f"# Comparison: {title}", ""] + [f"{note}\n" for note in result.notes]
    for name, table in tables.items():
        table.to_csv(out / f"differences_{name}.csv", index=False)
        md += [f"## {name}", "", table.to_markdown(index=False, floatfmt=".4g") if len(table)
               else "(none)", ""]
    md += ["## figures", ""] + [f"- [{p.name}]({p.name})" for p in result.figures
                               if p.suffix == ".png"]
    (out / "differences.md").write_text("\n".join(md) + "\n")
