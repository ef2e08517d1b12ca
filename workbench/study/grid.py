"""Reading a study's points table: axis names, panel grouping, titles.

Axis columns of ``points.parquet`` are named ``axis_<name>``; figures and
tables group the points by the axes they do not plot, and title each group
and each point in user units ("gap 1.016 mm, tip mass on").
"""
from __future__ import annotations

import re

import numpy as np
import pandas as pd

AXIS_LABELS = {"gap_mm": "gap (mm)", "freq_hz": "drive frequency (Hz)", "tip_mass": "tip mass",
               "cork": "cork", "force_n": "force (N)", "mu": "friction coefficient"}


def label(axis: str) -> str:
    return AXIS_LABELS.get(axis, axis)


def axis_text(axis: str, value) -> str:
    """'gap 1.016 mm', 'tip mass on', 'cork cubic' for a panel title."""
    if isinstance(value, (bool, np.bool_)):
        return f"{label(axis)} {'on' if value else 'off'}"
    name = label(axis)
    if name.endswith(")"):                      # 'gap (mm)' -> 'gap 1.016 mm'
        base, unit = name[:-1].split(" (")
        return f"{base} {value:g} {unit}"
    if isinstance(value, (float, np.floating)):     # a drawn value: six digits say it
        return f"{name} {value:.6g}"
    return f"{name} {value}"


def panels(table: pd.DataFrame, exclude: tuple[str, ...]) -> list[tuple[str, pd.DataFrame]]:
    """Split the table by every axis not in ``exclude`` that takes several values."""
    by = [c for c in table.columns if c.startswith("axis_") and c[5:] not in exclude
          and table[c].nunique() > 1]
    if not by:
        return [("", table)]
    out = []
    for values, group in table.groupby(by, sort=True):
        values = values if isinstance(values, tuple) else (values,)
        out.append((", ".join(axis_text(c[5:], v) for c, v in zip(by, values)), group))
    return out


def point_title(row) -> str:
    """'gap 1.016 mm, drive frequency 20 Hz, ...' from a points-table row's axis values."""
    return ", ".join(axis_text(k[5:], v) for k, v in row.items() if k.startswith("axis_"))


def point_slug(row) -> str:
    """'gap-1.016mm_tip-mass-on' from a points-table row's axis values: a file name
    that says which point it is (:func:`point_title` in lower case, without spaces)."""
    return "_".join(re.sub(r" (mm|hz|n|s)$", r"\1", axis_text(k[5:], v).lower())
                    .replace(" ", "-").replace("/", "-")
                    for k, v in row.items() if k.startswith("axis_"))
