"""``workbench compare FILE``: a record against the matching simulation, as figures and tables.

The paper's comparisons (seed §6) of :mod:`workbench.lab.compare`,
drawn and written into a folder: time-history overlay (Fig. 6), power
spectra (Fig. 7-8), contact switching diagrams (Fig. 9-10), for chirps
spectrograms of strain1 (Fig. 11-12) and the FRFs with their modes; and
the tables of differences (``differences_*.csv``, ``differences.md``).
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..lab.channels import kind
from ..lab.compare import (DEFAULT_THRESHOLD_V, SIGNALS, Comparison, code_series,
                                   contact_differences, peak_shifts, signal_differences, window)
from ..lab.files import record_from_run
from ..lab.frf import default_window, frf
from ..lab.modal import mode_table
from ..model.params import ParameterError
from . import figures as F


def compare(record: pd.DataFrame, run, out: str | Path, *, skip_s: float = 0.0,
            threshold=DEFAULT_THRESHOLD_V, seconds: float = 0.5, chirp: bool = False,
            band: tuple[float, float] | None = None, title: str = "") -> Comparison:
    """Compare ``record`` with a simulated ``run`` and write figures and tables into ``out``;
    ``band`` (Hz) limits the FRFs' modal fit to where the drive has force (a chirp's band)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    sim = record_from_run(run)
    sim.index = sim.index + record.index[0]          # the simulation starts with the record
    rec_w, sim_w = window(record, skip_s), window(sim, skip_s)
    rec_codes, sim_codes = code_series(rec_w, threshold), code_series(sim_w, DEFAULT_THRESHOLD_V)
    result = Comparison(signal_differences(rec_w, sim_w), peak_shifts(rec_w, sim_w),
                        contact_differences(rec_codes, sim_codes), [])
    sources = {"record": rec_w, "simulation": sim_w}
    channels = [c for c in SIGNALS if c in record.columns and c in sim.columns]
    left_out = [c for c in SIGNALS if c in record.columns and c not in sim.columns]
    if left_out:
        result.notes.append(f"compared on the channels both have; the simulation has no "
                            f"{', '.join(left_out)}")
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
        f_lo, f_hi = band or (0.0, None)
        try:
            tables = {name: frf(rec, responses, segment_s=None, window=default_window("chirp"))
                      for name, rec in sources.items()}
        except ParameterError as exc:
            result.notes.append(f"FRFs not computed: {exc}")
        else:
            try:
                result.frf_modes = mode_table(tables, responses, f_lo, f_hi)
            except ParameterError as exc:
                result.notes.append(f"FRF modes not identified: {exc}")
            result.figures += F.save(F.frf_figure(tables, responses, f"{title}: H1 against force1",
                                                  f_hi, f_min=f_lo), out / "frf")
    _write_tables(result, out, title)
    return result


def _write_tables(result: Comparison, out: Path, title: str) -> None:
    tables = {"signals": result.signals, "peaks": result.peaks, "contacts": result.contacts}
    if result.frf_modes is not None:
        tables["frf_modes"] = result.frf_modes
    md = [f"# Comparison: {title}", ""] + [f"{note}\n" for note in result.notes]
    for name, table in tables.items():
        table.to_csv(out / f"differences_{name}.csv", index=False)
        md += [f"## {name}", "", table.to_markdown(index=False, floatfmt=".4g") if len(table)
               else "(none)", ""]
    md += ["## figures", ""] + [f"- [{p.name}]({p.name})" for p in result.figures
                               if p.suffix == ".png"]
    (out / "differences.md").write_text("\n".join(md) + "\n")
