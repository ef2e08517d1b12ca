"""The damage-avoidance map of a wear study (``studies/damage.toml``; :mod:`workbench.study.wear`).

For a study over the drive frequency and the force level (and any other axes: gap, tip
mass, ...), from its points table:

- :func:`wear_map`: a filled contour map per panel (one per value of the other axes) of a wear
  measure per cycle over frequency x level, in SI, the regime to avoid (the wear volume at or
  above the study's ``[wear] threshold_mm3``) hatched and outlined, points outside the validated
  range marked '!';
- :func:`extremes_table`: per panel and level, the safest and the worst drive frequency (the
  smallest and largest wear volume), with their wear volume and impact energy per cycle;
- :func:`damage_lines`: the report's section (the threshold, its source, how many points lie
  in the regime to avoid, the figures and the table).
"""
from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd

from ..study.grid import label, panels, point_title
from ..study.wear import WEAR_SOURCES, WearConstants
from . import figures as F
from . import units
from .tables import latex_text, latex_units

#: mm³ per cm³ and mJ per erg (``model.shown_units``).
MM3, MJ = units.si("cm³")[1], units.si("erg")[1]
#: The measures a map can show: (column, title, CGS unit -> SI factor, SI unit).
MAP_MEASURES = {
    "wear_volume_cm3": ("wear volume per cycle (Archard)", MM3, "mm³"),
    "impact_energy_erg": ("impact energy lost per cycle", MJ, "mJ"),
    "friction_work_erg": ("friction work per cycle", MJ, "mJ"),
    "impacts": ("impacts per cycle", 1.0, ""),
}
AXES = ("freq_hz", "force_n")


def is_wear_map(table: pd.DataFrame) -> bool:
    """Does the points table hold a wear study over frequency x level?"""
    return "wear_volume_cm3" in table and all(f"axis_{a}" in table for a in AXES) \
        and all(table[f"axis_{a}"].nunique() > 1 for a in AXES)


def avoid(table: pd.DataFrame, wear: WearConstants) -> pd.Series:
    """True where a finished point's wear volume per cycle is at or above the threshold."""
    return (table.status == "ok") & (table.wear_volume_cm3 * MM3 >= wear.threshold_mm3)


def wear_map(table: pd.DataFrame, measure: str, wear: WearConstants):
    """The contour map of ``measure`` (a key of MAP_MEASURES) per panel (module docstring)."""
    title, factor, unit = MAP_MEASURES[measure]
    parts = panels(table, AXES)
    fig, axes = F._grid(len(parts), sharex=True, sharey=True)
    ok = table[table.status == "ok"]
    values = ok[measure].to_numpy() * factor
    positive = values[values > 0]
    top = positive.max() if len(positive) else 1.0
    bottom = max(positive.min(), top * 1e-4) if len(positive) else top * 1e-4
    levels = np.logspace(np.log10(bottom), np.log10(top), 13)
    norm = matplotlib.colors.LogNorm(vmin=bottom, vmax=top)
    freqs = np.sort(table.axis_freq_hz.unique())
    forces = np.sort(table.axis_force_n.unique())
    filled = None
    for ax, (name, part) in zip(axes, parts):
        grid = np.full((len(forces), len(freqs)), np.nan)
        volume = np.full_like(grid, np.nan)
        for _, r in part[part.status == "ok"].iterrows():
            i, j = np.searchsorted(forces, r.axis_force_n), np.searchsorted(freqs, r.axis_freq_hz)
            grid[i, j] = max(r[measure] * factor, bottom)
            volume[i, j] = r.wear_volume_cm3 * MM3
        filled = ax.contourf(freqs, forces, grid, levels=levels, norm=norm, cmap="magma_r",
                             extend="both")
        if np.nanmax(volume, initial=0.0) >= wear.threshold_mm3:
            ax.contourf(freqs, forces, volume, levels=[wear.threshold_mm3, np.inf], colors="none",
                        hatches=["///"])
            ax.contour(freqs, forces, volume, levels=[wear.threshold_mm3], colors="tab:cyan",
                       linewidths=1.2)
        out = part[(part.status == "ok") & (part.out_of_range.fillna("") != "")]
        ax.plot(out.axis_freq_hz, out.axis_force_n, "o", mfc="none", mec="tab:blue", ms=6)
        failed = part[part.status != "ok"]
        ax.plot(failed.axis_freq_hz, failed.axis_force_n, "x", color="k", ms=6)
        ax.set_yscale("log")
        ax.yaxis.set_major_locator(matplotlib.ticker.FixedLocator(forces))
        ax.yaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_title(name, fontsize=9)
        ax.set_xlabel(label("freq_hz"))
        ax.set_ylabel(label("force_n"))
    decades = 10.0 ** np.arange(np.floor(np.log10(bottom)), np.ceil(np.log10(top)) + 1)
    fig.colorbar(filled, ax=axes, label=f"{title} ({unit})" if unit else title,
                 ticks=decades[(decades >= bottom) & (decades <= top)],
                 format=matplotlib.ticker.LogFormatterSciNotation())
    fig.supxlabel(f"hatched, cyan line: wear volume ≥ {wear.threshold_mm3:.3g} mm³ per cycle "
                  "(the regime to avoid); circles: outside the validated range; x: failed",
                  fontsize=8)
    return fig


def extremes_table(table: pd.DataFrame, wear: WearConstants) -> pd.DataFrame:
    """Per panel and level: the safest and worst frequency by wear volume (module docstring),
    in SI with the unit in each header."""
    rows = []
    for name, part in panels(table, AXES):
        for force, level in part[part.status == "ok"].groupby("axis_force_n"):
            best = level.loc[level.wear_volume_cm3.idxmin()]
            worst = level.loc[level.wear_volume_cm3.idxmax()]
            rows.append({"panel": name or "all", "force [N]": force,
                         "safest [Hz]": best.axis_freq_hz,
                         "its wear [mm³/cycle]": best.wear_volume_cm3 * MM3,
                         "its impact energy [mJ/cycle]": best.impact_energy_erg * MJ,
                         "worst [Hz]": worst.axis_freq_hz,
                         "its wear [mm³/cycle] ": worst.wear_volume_cm3 * MM3,
                         "its impact energy [mJ/cycle] ": worst.impact_energy_erg * MJ,
                         "avoid at": ", ".join(f"{f:g}" for f in level[avoid(level, wear)]
                                               .axis_freq_hz.sort_values()) or "-"})
    return pd.DataFrame(rows)


def write_extremes(table: pd.DataFrame, wear: WearConstants, out: Path) -> list[Path]:
    """``damage_extremes.{csv,md,tex}`` (:func:`extremes_table`); return the paths."""
    out.mkdir(parents=True, exist_ok=True)
    ext = extremes_table(table, wear)
    caption = ("Safest and worst drive frequency per gap, tip mass and force level, by the wear "
               f"volume per cycle (Archard); 'avoid at': frequencies at or above "
               f"{wear.threshold_mm3:.3g} mm³ per cycle")
    paths = [out / f"damage_extremes.{e}" for e in ("csv", "md", "tex")]
    ext.to_csv(paths[0], index=False)
    paths[1].write_text(f"# {caption}\n\n{ext.to_markdown(index=False, floatfmt='.3g')}\n")
    paths[2].write_text(latex_units(ext.to_latex(index=False, float_format="%.3g", escape=True,
                                                 caption=latex_text(caption))))
    return paths


def damage_lines(table: pd.DataFrame, wear: WearConstants) -> list[str]:
    """The report's damage section (module docstring) as Markdown lines."""
    ok = table[table.status == "ok"]
    hits = table[avoid(table, wear)]
    lines = ["## Where the joint wears", "",
             f"Wear volume per cycle by Archard's law, V = k F_n s / H with F_n s = W_f / mu_k "
             f"(k = {wear.k_archard:g}: {WEAR_SOURCES['k_archard']}; H = "
             f"{wear.hardness_pa:g} Pa: {WEAR_SOURCES['hardness_pa']}). The regime to avoid: "
             f"a wear volume of at least {wear.threshold_mm3:.3g} mm³ per cycle "
             f"(`[wear] threshold_mm3`; the default is {WEAR_SOURCES['threshold_mm3']}).", "",
             f"{len(hits)} of {len(ok)} finished points lie in the regime to avoid"
             + (": " + "; ".join(point_title(r) for _, r in hits.iterrows())
                if 0 < len(hits) <= 12 else "")
             + ". The maps: `wear_map` (wear volume), `impact_map` (impact energy), "
             "`friction_map` (friction work), all per cycle; the safest and worst frequencies: "
             "[damage_extremes.md](tables/damage_extremes.md) "
             "([LaTeX](tables/damage_extremes.tex)).", ""]
    return lines
