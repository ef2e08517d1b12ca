"""Records in and out of files: one interface, the format chosen by suffix or by name.

    rec = read("trial.lvm")                  # or .txt, .tdms, .uff, .parquet
    rec["strain1"], rec.attrs["meta"]        # the channels (CGS) and the settings
    write("sim.tdms", record_from_run(run), meta)
    convert("trial.lvm", "trial.uff")

The record (channels of Table 2, units, settings) is described in
:mod:`workbench.lab.channels`; each format is one module of
:mod:`workbench.lab.formats`:

| format | suffixes | read by | written by |
|---|---|---|---|
| ``lvm`` | .lvm | lvm_read | this package |
| ``text`` | .txt .tsv .dat .tab | this package | this package |
| ``tdms`` | .tdms | npTDMS | npTDMS |
| ``uff`` | .uff .unv | pyuff | pyuff |
| ``parquet`` | .parquet | pyarrow | pyarrow |
"""
from __future__ import annotations

import importlib
from pathlib import Path
from typing import TYPE_CHECKING

from .channels import (CHANNELS, DEFAULT_UNITS, TABLE2_NAMES, UNITS,  # noqa: F401 - the interface
                       ExperimentFileError, kind)

if TYPE_CHECKING:
    import pandas as pd

#: Format name -> the suffixes that choose it.
FORMATS = {"lvm": (".lvm",), "text": (".txt", ".tsv", ".dat", ".tab"), "tdms": (".tdms",),
           "uff": (".uff", ".unv"), "parquet": (".parquet",)}
SUFFIXES = tuple(s for suffixes in FORMATS.values() for s in suffixes)


def format_of(path, format: str | None = None, option: str = "format") -> str:
    """The format named, or the one of the path's suffix; an error naming ``option``."""
    if format is not None:
        if format not in FORMATS:
            raise ExperimentFileError(path, None, f"{option} {format!r}: allowed "
                                      f"{', '.join(FORMATS)}")
        return format
    suffix = Path(path).suffix.lower()
    for name, suffixes in FORMATS.items():
        if suffix in suffixes:
            return name
    raise ExperimentFileError(path, None, f"unknown file type {suffix!r}: use "
                              f"{', '.join(SUFFIXES)} (or name the format: {', '.join(FORMATS)})")


def _module(name: str):
    return importlib.import_module(f".formats.{name}", __package__)


def read(path, strain_scale: dict | None = None, format: str | None = None) -> pd.DataFrame:
    """The record of a file (channels of Table 2 in CGS, indexed by time in s)."""
    return _module(format_of(path, format)).read(path, strain_scale)


def write(path, record: pd.DataFrame, meta: dict | None = None, format: str | None = None) -> Path:
    """Write ``record`` (CGS, index t) with its settings ``meta``; returns the path."""
    return _module(format_of(path, format)).write(path, record, meta)


def check_settings(path, meta: dict | None, format: str | None = None) -> None:
    """Raise before any work if the format of ``path`` cannot carry these settings."""
    module = _module(format_of(path, format))
    if hasattr(module, "check_settings"):
        module.check_settings(path, meta)


def convert(source, target, strain_scale: dict | None = None, source_format: str | None = None,
            target_format: str | None = None) -> pd.DataFrame:
    """Read ``source`` and write its record and settings to ``target``; returns the record."""
    rec = read(source, strain_scale, source_format)
    check_settings(target, rec.attrs["meta"], target_format)
    write(target, rec, rec.attrs["meta"], target_format)
    return rec


def record_from_run(run) -> pd.DataFrame:
    """The Table 2 channels of a simulated run as a record (CGS; contacts as an ideal
    patch: 1 V while the point is closed, 0 V while open), and the hammer's force when the
    run is an impact test."""
    from ..model import drives

    hit = drives.of_array(run.excitation).name.startswith("hammer")
    return run.signals[[c for c in CHANNELS if c != "hammer" or hit]].astype(float)
