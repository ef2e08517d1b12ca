"""Parquet (.parquet): a record, or the signals of a run (``workbench run --out``).

The settings travel in the table's metadata (pandas ``attrs["meta"]``, which
pyarrow stores with the table).  Reading keeps the Table 2 channels; a run's
other signals (coordinates, contact codes, energies) are left out.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..channels import CHANNELS, ExperimentFileError, for_writing, record


def read(path, strain_scale: dict | None = None):
    """A Parquet record, or a run's signals, as a record (CGS, as written)."""
    path = Path(path)
    if not path.is_file():
        raise ExperimentFileError(path, None, "no such file")
    try:
        table = pd.read_parquet(path)
    except Exception as exc:                  # noqa: BLE001 - pyarrow's word on a bad file
        raise ExperimentFileError(path, None, f"not a readable Parquet file ({type(exc).__name__}: "
                                  f"{' '.join(str(exc).split())[:120]})") from None
    channels = [c for c in CHANNELS if c in table.columns]
    if not channels:
        raise ExperimentFileError(path, None, f"no channel of Table 2 (its columns: "
                                  f"{', '.join(map(str, table.columns[:12]))})")
    if not pd.api.types.is_numeric_dtype(table.index):
        raise ExperimentFileError(path, None, "not indexed by time (s)")
    data = table[channels].to_numpy(dtype=float)
    bad = np.argwhere(~np.isfinite(data))
    if len(bad):
        raise ExperimentFileError(path, None, f"{channels[bad[0][1]]}: values that are not finite")
    meta = table.attrs.get("meta", {}) if isinstance(table.attrs.get("meta"), dict) else {}
    return record(path, table.index.to_numpy(dtype=float), data, channels,
                  [1.0] * len(channels), dict(meta), [])


def write(path, rec, meta: dict | None = None) -> Path:
    """Write a record (CGS, index t) as Parquet, the settings in its metadata."""
    path = Path(path)
    channels, _ = for_writing(rec)
    out = rec[channels].astype(float)
    out.attrs = {"meta": dict(meta or {})}
    out.to_parquet(path)
    return path
