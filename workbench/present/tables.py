"""Paper-style tables of a study: CSV, Markdown and LaTeX.

Two tables, each per gap x drive frequency with a block per value of the
other axes (tip mass, cork, ...):

- ``response``: RMS of the tip displacement (mm), of strain1 (µε) and
  accel3 (m/s²), and the tip's amplitude at the drive frequency (mm);
- ``contact``: impacts and regime switches per second, stick share, the
  share of free flight and the dominant contact code.

Values are in SI (:mod:`workbench.present.units`; the points table keeps
CGS).  The CSV is long (one row per point, every column with its unit in the
header, ``steady`` and ``status`` included).  The Markdown and LaTeX tables pivot one quantity per
block: gap rows, frequency columns; ``*`` marks a point that is not steady,
``!`` one whose response left the validated range (``out_of_range`` in the
CSV: ``metrics.validity``) and ``failed`` one that did not finish.  A study without both axes gets
the long table in every format.  A study of chirps also gets ``frf_modes``,
the modes of each point's FRFs (:func:`write_frf_modes`).
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..study.metrics import CONTACT_CODES, QUANTITIES
from . import units
from ..study.grid import label, panels

TABLES = {
    "response": {k: units.quantity_label(k) for k in ("tip_rms", "tip_h1", "strain1_rms", "accel3_rms")},
    "contact": {**{k: units.quantity_label(k) for k in ("impacts_per_s", "switches_per_s", "stick_share",
                                                  "share_0")},
                "dominant_code": "dominant contact code"},
}
PIVOT = ("gap_mm", "freq_hz")


def with_dominant_code(table: pd.DataFrame) -> pd.DataFrame:
    """Add ``dominant_code``: the contact code with the largest time share (NA if none)."""
    shares = table[[f"share_{c}" for c in CONTACT_CODES if f"share_{c}" in table]]
    codes = [pd.NA if row.isna().all() else int(row.idxmax().split("_")[1])
             for _, row in shares.iterrows()] if len(shares.columns) else pd.NA
    return table.assign(dominant_code=codes)


def cell(row, name: str) -> str:
    """A point's value as printed, in SI (:mod:`workbench.present.units`): 3 significant
    digits, '*' if not steady, '!' if outside the validated range."""
    if row.status != "ok":
        return "failed"
    v = row[name]
    if isinstance(v, float) and name in QUANTITIES:
        v *= units.quantity(name)[2]
    text = f"{v:.3g}" if isinstance(v, float) else str(v)
    text = text if bool(row.steady) else text + "*"
    return text + "!" if row.get("out_of_range", "") else text


def pivots(table: pd.DataFrame, quantity: str) -> list[tuple[str, pd.DataFrame]]:
    """(block title, gap x frequency frame of printed cells) per value of the other axes."""
    out = []
    for title, part in panels(table, PIVOT):
        grid = pd.DataFrame({
            f"{f:g} Hz": {f"{r.axis_gap_mm:g}": cell(r, quantity)
                          for _, r in part.iterrows() if r.axis_freq_hz == f}
            for f in sorted(part.axis_freq_hz.unique())})
        grid.index.name = label("gap_mm")
        out.append((title, grid.sort_index()))
    return out


def latex_text(text: str) -> str:
    """Escape the characters LaTeX treats specially in running text."""
    for a, b in (("\\", r"\textbackslash{}"), ("_", r"\_"), ("%", r"\%"), ("&", r"\&"),
                 ("#", r"\#")):
        text = text.replace(a, b)
    return text


def latex_units(text: str) -> str:
    """The SI units' characters as LaTeX math: m/s², µε."""
    return text.replace("²", "$^2$").replace("µε", r"$\mu\varepsilon$")


def _long(table: pd.DataFrame, columns: dict) -> pd.DataFrame:
    """One row per point: its axes, status and the columns, in SI with the unit in each
    column's header (``tip_rms [mm]``)."""
    axes = [c for c in table.columns if c.startswith("axis_")]
    keep = axes + [c for c in ("status", "message", "steady", "steady_change", "out_of_range",
                               *columns)
                   if c in table]
    out = table[keep].copy()
    for c in columns:
        if c in out and c in QUANTITIES:
            out[c] = out[c] * units.quantity(c)[2]
    return out.rename(columns={**{c: c[5:] for c in axes}, **{c: units.column(c) for c in columns}})


def write_tables(table: pd.DataFrame, out: Path) -> list[Path]:
    """Write every table of the module docstring under ``out``; return the paths."""
    out.mkdir(parents=True, exist_ok=True)
    table = with_dominant_code(table)
    pivotable = all(f"axis_{a}" in table for a in PIVOT)
    written = []
    for name, columns in TABLES.items():
        present = {c: t for c, t in columns.items() if c in table}
        long = _long(table, present)
        csv = out / f"{name}.csv"
        long.to_csv(csv, index=False)
        md, tex = [f"# {name.capitalize()} per point\n"], []
        if pivotable:
            md.append("`*`: not steady (RMS changed by more than the tolerance between the "
                      "last two windows); `failed`: see points.parquet.\n")
            for quantity, title in present.items():
                for block, grid in pivots(table, quantity):
                    caption = f"{title}{', ' + block if block else ''}"
                    md += [f"\n## {caption}\n", grid.to_markdown(stralign="right"), ""]
                    tex.append(grid.to_latex(caption=latex_text(caption), escape=True,
                                             position="htbp").replace("*", r"$^*$"))
        else:
            md.append(long.to_markdown(index=False, floatfmt=".4g"))
            tex.append(long.to_latex(index=False, float_format="%.4g", escape=True))
        (out / f"{name}.md").write_text("\n".join(md) + "\n")
        (out / f"{name}.tex").write_text(latex_units("\n".join(tex)))
        written += [csv, out / f"{name}.md", out / f"{name}.tex"]
    return written


def write_frf_modes(modes: pd.DataFrame, out: Path) -> list[Path]:
    """The modes of a study's chirps' FRFs (``frf_modes.{csv,md,tex}``, one row per point and
    mode, :mod:`workbench.lab.modal`); return the paths."""
    from ..lab.modal import MIN_DECAY_TIMES
    out.mkdir(parents=True, exist_ok=True)
    modes = modes.rename(columns={"source": "point"})
    caption = ("Modes of the FRFs (H1 against force1; LSCF and a stabilisation chart): frequency "
               "f_hz (Hz), damping ratio zeta (empty where the record spans fewer than "
               f"{MIN_DECAY_TIMES:g} of the mode's decay times), the band fitted (Hz)")
    paths = [out / f"frf_modes.{ext}" for ext in ("csv", "md", "tex")]
    modes.to_csv(paths[0], index=False)
    paths[1].write_text(f"# {caption}\n\n{modes.to_markdown(index=False, floatfmt='.4g')}\n")
    paths[2].write_text(modes.to_latex(index=False, float_format="%.4g", escape=True,
                                       caption=latex_text(caption)))
    return paths
