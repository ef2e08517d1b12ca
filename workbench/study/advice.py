"""The controller's advice from a damage map (``studies/damage.toml``; :mod:`workbench.study.wear`).

Given a gap, a drive frequency, a force level and (where the map has that axis) the tip mass,
:func:`advise` reads the map's points table and answers:

- the wear measures there: at a grid point its values; between grid points, interpolated
  linearly in the gap and the frequency and in log(level) between the 2-8 surrounding points
  (every one of them finished), with the distance to the nearest grid point on each axis;
- whether the point is in the regime to avoid (the wear volume per cycle at or above the
  map's ``[wear] threshold_mm3``);
- if it is, the smallest change of frequency, in steps of ``FREQ_STEP_HZ`` within the map's
  band at the same gap and level, that leaves it, with the measures there; and, if a change
  of level is allowed, the smallest lowering of the level (the largest level below) that
  leaves it at the same frequency.

A point outside the map's range (an axis value beyond its grid, a tip mass it did not run)
is refused in one line.  Measures are in SI (mm³, mJ, N) per drive cycle.
"""
from __future__ import annotations

import itertools
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..model.params import ParameterError
from ..model.shown_units import SI
from .wear import WearConstants

#: The frequency step (Hz) of the search for the nearest frequency out of the regime to avoid.
FREQ_STEP_HZ = 0.5
#: The measures the advice gives: column -> (name, SI factor, SI unit).
ADVICE_MEASURES = {
    "wear_volume_cm3": ("wear_volume_mm3", SI["cm³"][1], "mm³/cycle"),
    "friction_work_erg": ("friction_work_mj", SI["erg"][1], "mJ/cycle"),
    "impact_energy_erg": ("impact_energy_mj", SI["erg"][1], "mJ/cycle"),
    "impacts": ("impacts_per_cycle", 1.0, "1/cycle"),
    "normal_force_max_dyn": ("normal_force_max_n", SI["dyn"][1], "N"),
}


@dataclass
class DamageMap:
    """A damage study's finished points and its wear constants."""

    table: pd.DataFrame
    wear: WearConstants
    source: str

    @classmethod
    def read(cls, folder: str | Path) -> "DamageMap":
        """The map in ``folder`` (a damage study's results: points.parquet, provenance.json)."""
        folder = Path(folder)
        if not (folder / "points.parquet").exists():
            raise ParameterError(f"--results {folder}: no points.parquet (run `workbench sweep "
                                 "studies/damage.toml` first)")
        table = pd.read_parquet(folder / "points.parquet")
        missing = [a for a in ("gap_mm", "freq_hz", "force_n") if f"axis_{a}" not in table]
        if missing or "wear_volume_cm3" not in table:
            raise ParameterError(f"--results {folder}: not a damage map (it needs the axes gap_mm, "
                                 f"freq_hz and force_n and the wear measures; missing "
                                 f"{', '.join(missing) or 'the wear measures'})")
        wear = WearConstants()
        provenance = folder / "provenance.json"
        if provenance.exists():
            stored = json.loads(provenance.read_text()).get("study", {}).get("wear")
            wear = WearConstants(**stored) if stored else wear
        return cls(table, wear, str(folder))


@dataclass
class Advice:
    """What :func:`advise` answers (module docstring)."""

    here: dict
    interpolated: bool
    distance: dict
    avoid: bool
    threshold_mm3: float
    frequency_change: dict | None = None
    level_change: dict | None = None
    notes: list = field(default_factory=list)

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def _axis_range(table: pd.DataFrame, axis: str, value: float, option: str, unit: str):
    grid = np.sort(table[f"axis_{axis}"].unique().astype(float))
    if not grid[0] - 1e-9 <= value <= grid[-1] + 1e-9:
        raise ParameterError(f"{option} {value:g}: outside the map's range; allowed "
                             f"[{grid[0]:g}, {grid[-1]:g}] {unit}")
    return grid


def _bracket(grid: np.ndarray, value: float, log: bool = False) -> list[tuple[float, float]]:
    """(grid value, weight) of the one or two grid values around ``value``."""
    i = int(np.searchsorted(grid, value))
    if i < len(grid) and abs(grid[i] - value) <= 1e-9 * max(1.0, abs(value)):
        return [(grid[i], 1.0)]
    lo, hi = grid[i - 1], grid[i]
    x, a, b = (np.log(value), np.log(lo), np.log(hi)) if log else (value, lo, hi)
    w = (x - a) / (b - a)
    return [(lo, 1.0 - w), (hi, w)]


def measures_at(dmap: DamageMap, gap_mm: float, freq_hz: float, force_n: float,
                tip_mass: bool | None) -> tuple[dict, bool, dict]:
    """(the measures in SI, interpolated?, distance to the nearest grid point per axis) at a
    point of the map (module docstring); ParameterError outside it."""
    t = dmap.table
    if "axis_tip_mass" in t:
        choices = sorted(t.axis_tip_mass.unique())
        if tip_mass is None:
            raise ParameterError(f"--tip-mass: the map has tip mass "
                                 f"{' and '.join('on' if c else 'off' for c in choices)}; say which")
        if tip_mass not in choices:
            raise ParameterError(f"--tip-mass {'on' if tip_mass else 'off'}: the map has only "
                                 f"{' and '.join('on' if c else 'off' for c in choices)}")
        t = t[t.axis_tip_mass == tip_mass]
    grids = {"gap_mm": _axis_range(t, "gap_mm", gap_mm, "--gap-mm", "mm"),
             "freq_hz": _axis_range(t, "freq_hz", freq_hz, "--freq-hz", "Hz"),
             "force_n": _axis_range(t, "force_n", force_n, "--force-n", "N")}
    value = {"gap_mm": gap_mm, "freq_hz": freq_hz, "force_n": force_n}
    brackets = {a: _bracket(g, value[a], log=(a == "force_n")) for a, g in grids.items()}
    out = {name: 0.0 for name, _, _ in ADVICE_MEASURES.values()}
    for corner in itertools.product(*brackets.values()):
        (g, wg), (f, wf), (F, wF) = corner
        rows = t[np.isclose(t.axis_gap_mm, g) & np.isclose(t.axis_freq_hz, f)
                 & np.isclose(t.axis_force_n, F)]
        if not len(rows) or (rows.status != "ok").any():
            raise ParameterError(f"the map's point {g:g} mm, {f:g} Hz, {F:g} N did not finish; "
                                 "no value to interpolate from")
        row = rows.iloc[0]
        for column, (name, factor, _) in ADVICE_MEASURES.items():
            out[name] += wg * wf * wF * float(row[column]) * factor
    distance = {a: float(np.min(np.abs(g - value[a]))) for a, g in grids.items()}
    interpolated = any(len(b) > 1 for b in brackets.values())
    return out, interpolated, distance


def advise(results: str | Path, gap_mm: float, freq_hz: float, force_n: float,
           tip_mass: bool | None = None, change_level: bool = False) -> Advice:
    """The advice of the module docstring from the damage map in ``results``."""
    dmap = DamageMap.read(results)
    here, interpolated, distance = measures_at(dmap, gap_mm, freq_hz, force_n, tip_mass)
    limit = dmap.wear.threshold_mm3
    advice = Advice(here, interpolated, distance, here["wear_volume_mm3"] >= limit, limit)
    if interpolated:
        advice.notes.append("interpolated between grid points (linear in gap and frequency, in "
                            "log level); nearest grid point: "
                            + ", ".join(f"{a} {d:g}" for a, d in distance.items()))
    if not advice.avoid:
        return advice
    freqs = np.sort(dmap.table.axis_freq_hz.unique())
    candidates = np.arange(freqs[0], freqs[-1] + 1e-9, FREQ_STEP_HZ)
    for f in sorted(candidates, key=lambda f: (abs(f - freq_hz), f)):
        there, _, _ = measures_at(dmap, gap_mm, float(f), force_n, tip_mass)
        if there["wear_volume_mm3"] < limit:
            advice.frequency_change = {"freq_hz": float(f), "change_hz": float(f - freq_hz),
                                       **there}
            break
    else:
        advice.notes.append("no frequency in the map's band leaves the regime to avoid at this "
                            "level")
    if change_level:
        forces = np.sort(dmap.table.axis_force_n.unique())
        for F in forces[::-1]:
            if F >= force_n:
                continue
            there, _, _ = measures_at(dmap, gap_mm, freq_hz, float(F), tip_mass)
            if there["wear_volume_mm3"] < limit:
                advice.level_change = {"force_n": float(F), "change_n": float(F - force_n),
                                       **there}
                break
        else:
            advice.notes.append("no level of the map below this one leaves the regime to avoid")
    return advice
