"""A record: the rig's sensor channels of Table 2, their units, and their settings.

The rig's LabVIEW instruments wrote the sensors of Table 2 (seed §3.3-3.4):
Force1, Strain1, Accel1, Contact1-4, Accel2, Strain2, Accel3; an impact
test adds the hammer's force gauge (Hammer, a force channel: §4.3, §5.4).  Every file
format (:mod:`workbench.lab.formats`) reads into the same record: a
DataFrame indexed by time ``t`` (s), with the workbench's channel names
(``force1`` ... ``accel3``, ``contact1-4``) in CGS units, and the attributes

- ``attrs["meta"]``: the run's settings (``WB_`` keys of the file; see
  :mod:`workbench.lab.matching` for what they mean);
- ``attrs["units_assumed"]``: the channels whose file gave no unit and that
  were read in :data:`DEFAULT_UNITS`;
- ``attrs["source"]``: the file.

**Units.**  Accepted units are those of :data:`UNITS`.  A strain channel in
volts (a PVDF patch) needs its scale factor (strain per volt, §4.4,
:func:`workbench.identify.calibrate_patch`) in ``strain_scale``.  Contact
patches stay in volts: :mod:`workbench.identify.contacts` turns them into
contact codes.  The writers write :data:`DEFAULT_UNITS`.

Every problem with a file raises :class:`ExperimentFileError` naming the
file, the line (text formats) and what is wrong.
"""
from __future__ import annotations

import math
import re
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..model.params import ParameterError

if TYPE_CHECKING:
    import pandas as pd

#: Table 2's sensor names, as the files write them, by workbench channel.
TABLE2_NAMES = {"force1": "Force1", "strain1": "Strain1", "accel1": "Accel1",
                "contact1": "Contact1", "contact2": "Contact2", "contact3": "Contact3",
                "contact4": "Contact4", "accel2": "Accel2", "strain2": "Strain2", "accel3": "Accel3",
                "hammer": "Hammer"}
CHANNELS = tuple(TABLE2_NAMES)
#: Unit -> factor to CGS, by kind of channel.
UNITS = {
    "force": {"N": 1.0e5, "dyn": 1.0, "lbf": 4.4482216e5, "kN": 1.0e8},
    "strain": {"strain": 1.0, "-": 1.0, "m/m": 1.0, "cm/cm": 1.0, "ue": 1.0e-6, "microstrain": 1.0e-6},
    "accel": {"cm/s^2": 1.0, "m/s^2": 100.0, "g": 980.665},
    "contact": {"V": 1.0},
}
#: Units of a channel whose file gives none; also the units the writers use.
DEFAULT_UNITS = {"force": "N", "strain": "strain", "accel": "m/s^2", "contact": "V"}
#: Prefix of a setting's key in a file (``WB_gap_mm``).
META_PREFIX = "WB_"
#: Names a file may give its time column.
TIME_NAMES = {"x_value", "time", "t", "times"}


class ExperimentFileError(ParameterError):
    """A measurement file is malformed, truncated or mislabelled."""

    def __init__(self, path, line: int | None, problem: str):
        where = f"{path}" if line is None else f"{path}, line {line}"
        super().__init__(f"{where}: {problem}")
        self.path, self.line, self.problem = str(path), line, problem


def kind(channel: str) -> str:
    """'force', 'strain', 'accel' or 'contact' of a workbench channel name."""
    return "force" if channel == "hammer" else re.sub(r"\d+$", "", channel)


def reference_of(drive: str | None) -> str:
    """The force channel a record's responses refer to: the hammer in an impact test
    (a ``hammer_*`` drive), else the shaker's force1."""
    return "hammer" if str(drive).startswith("hammer") else "force1"


def channel_of(label: str) -> str | None:
    """The workbench channel of a file's label ('Strain 1', 'strain_1' -> 'strain1')."""
    key = re.sub(r"[\s_]+", "", label).lower()
    return key if key in TABLE2_NAMES else None


def labels_to_channels(path, line, labels: list[str]) -> list[str]:
    """The workbench channels of a file's labels; an error for an unknown or repeated one."""
    channels = []
    for label in labels:
        channel = channel_of(label)
        if channel is None:
            raise ExperimentFileError(path, line, f"unknown channel {label!r}: the channels of "
                                      f"Table 2 are {', '.join(TABLE2_NAMES.values())}")
        if channel in channels:
            raise ExperimentFileError(path, line, f"channel {label!r} appears twice")
        channels.append(channel)
    return channels


def factor(path, line, channel: str, unit: str | None, strain_scale: dict) -> float:
    """The factor from a channel's file unit to CGS (DEFAULT_UNITS when ``unit`` is None)."""
    k = kind(channel)
    if k == "strain" and unit == "V":
        if channel not in strain_scale:
            raise ExperimentFileError(path, line, f"{TABLE2_NAMES[channel]} is in V (a PVDF patch): "
                                      f"give its scale factor (strain per volt, §4.4) in strain_scale")
        return float(strain_scale[channel])
    unit = unit or DEFAULT_UNITS[k]
    if unit not in UNITS[k]:
        raise ExperimentFileError(path, line, f"{TABLE2_NAMES[channel]}: unit {unit!r} is not one of "
                                  f"{', '.join(UNITS[k])}")
    return UNITS[k][unit]


def number(path, line, column: str, text: str, decimal: str = ".") -> float:
    """A finite number from a file's text, or an error naming the column and the text."""
    try:
        value = float(text.replace(decimal, ".") if decimal != "." else text)
    except ValueError:
        raise ExperimentFileError(path, line, f"column {column!r}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise ExperimentFileError(path, line, f"column {column!r}: {text!r} is not finite")
    return value


def meta_value(text: str):
    """A setting's value from text: int, float, bool, or the text itself."""
    for cast in (int, float):
        try:
            return cast(text)
        except ValueError:
            pass
    return {"true": True, "false": False}.get(text.lower(), text)


def read_lines(path: Path) -> list[str]:
    """The lines of a UTF-8 text file (an error for a missing or binary file)."""
    try:
        text = path.read_text(encoding="utf-8", errors="strict")
    except FileNotFoundError:
        raise ExperimentFileError(path, None, "no such file") from None
    except IsADirectoryError:
        raise ExperimentFileError(path, None, "is a directory, not a file") from None
    except UnicodeDecodeError as exc:
        line = path.read_bytes()[:exc.start].count(b"\n") + 1
        raise ExperimentFileError(path, line, "not UTF-8 text (a binary file?)") from None
    return [line.rstrip("\r") for line in text.split("\n")]


def record(path, t: np.ndarray, data: np.ndarray, channels: list[str], factors: list[float],
           meta: dict, assumed: list[str], line_of_row=None) -> pd.DataFrame:
    """The record of a file's time, values (file units) and channels, checked: at least
    two rows and increasing time.  ``line_of_row(i)`` gives the file line of row i."""
    if len(t) < 2:
        raise ExperimentFileError(path, None, f"has {len(t)} data row(s): need at least 2")
    if not np.all(np.isfinite(t)):
        raise ExperimentFileError(path, None, "the time has values that are not finite")
    bad = np.flatnonzero(np.diff(t) <= 0)
    if len(bad):
        line = line_of_row(int(bad[0]) + 1) if line_of_row else None
        raise ExperimentFileError(path, line, f"time {t[bad[0] + 1]} s does not increase "
                                  f"(previous {t[bad[0]]} s)")
    with np.errstate(over="ignore", invalid="ignore"):
        values = np.asarray(data, dtype=float) * np.asarray(factors)
    bad = np.flatnonzero(~np.all(np.isfinite(values), axis=0))
    if len(bad):
        raise ExperimentFileError(path, None, f"{TABLE2_NAMES[channels[bad[0]]]}: values that are "
                                  "not finite, or out of range in CGS units")
    import pandas as pd                 # here: a simulation's command line does not need it
    df = pd.DataFrame(values, columns=channels, index=pd.Index(np.asarray(t, dtype=float), name="t"))
    df.attrs.update(meta=meta, units_assumed=assumed, source=str(path))
    return df


def for_writing(record: pd.DataFrame) -> tuple[list[str], np.ndarray]:
    """The Table 2 channels of a record and their values in DEFAULT_UNITS."""
    channels = [c for c in CHANNELS if c in record.columns]
    unknown = sorted(set(record.columns) - set(CHANNELS))
    if unknown or not channels:
        raise ParameterError(f"a record holds only the channels {', '.join(CHANNELS)}; got {unknown}")
    factors = np.array([UNITS[kind(c)][DEFAULT_UNITS[kind(c)]] for c in channels])
    return channels, record[channels].to_numpy(dtype=float) / factors


def time_step(record: pd.DataFrame) -> float | None:
    """The record's sample interval (s) if its time base is uniform, else None."""
    t = record.index.to_numpy(dtype=float)
    if len(t) < 2:
        return None
    dt = np.diff(t)
    step = float(np.median(dt))
    return step if np.allclose(dt, step, rtol=1e-6, atol=0.0) else None


def text_rows(t, values, sep: str) -> str:
    """Text rows of the time and the values (10 significant digits)."""
    table = np.column_stack([t, values])
    return "\n".join(sep.join(f"{x:.10g}" for x in row) for row in table) + "\n"
