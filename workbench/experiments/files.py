"""Experiment files: LabVIEW measurement files (.lvm) and plain tab-delimited text.

The rig's LabVIEW instruments wrote the sensors of Table 2 (seed §3.3-3.4):
Force1, Strain1, Accel1, Contact1-4, Accel2, Strain2, Accel3.  A record is
read into a DataFrame indexed by time ``t`` (s), with the workbench's
channel names (``force1`` ... ``accel3``, ``contact1-4``) in CGS units:

    rec = read("trial.lvm")               # or .txt / .tsv: tab-delimited text
    rec["strain1"], rec.attrs["meta"]     # the settings the file records
    write("sim.lvm", record_from_run(run), meta)

**Units.**  An ``.lvm`` segment gives one ``Y_Unit_Label`` per channel; a
text header may write ``Force1 (N)`` or ``Force1 [N]``.  Accepted units are
those of :data:`UNITS`; a channel without a unit is read in
:data:`DEFAULT_UNITS` (recorded in ``attrs["units_assumed"]``).  A strain
channel in volts (a PVDF patch) needs its scale factor (strain per volt,
§4.4, :func:`workbench.identify.calibrate_patch`) in ``strain_scale``.
Contact patches stay in volts: :mod:`workbench.identify.contacts` turns them
into contact codes.

**Settings.**  Header keys starting with ``WB_`` (``WB_gap_mm 1.016``) are
the run's settings (``attrs["meta"]``): the simulated files the writers
produce carry them so ``workbench compare`` can run the matching
simulation; for a measured file they are given on the command line.

Every problem raises :class:`ExperimentFileError` naming the file, the line
and what is wrong.
"""
from __future__ import annotations

import datetime as _dt
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd

from ..model.params import ParameterError

#: Table 2's sensor names, as the files write them, by workbench channel.
TABLE2_NAMES = {"force1": "Force1", "strain1": "Strain1", "accel1": "Accel1",
                "contact1": "Contact1", "contact2": "Contact2", "contact3": "Contact3",
                "contact4": "Contact4", "accel2": "Accel2", "strain2": "Strain2", "accel3": "Accel3"}
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
META_PREFIX = "WB_"
END_OF_HEADER = "***End_of_Header***"
_TIME_NAMES = {"x_value", "time", "t", "times"}


class ExperimentFileError(ParameterError):
    """A measurement file is malformed, truncated or mislabelled."""

    def __init__(self, path, line: int | None, problem: str):
        where = f"{path}" if line is None else f"{path}, line {line}"
        super().__init__(f"{where}: {problem}")
        self.path, self.line, self.problem = str(path), line, problem


def kind(channel: str) -> str:
    """'force', 'strain', 'accel' or 'contact' of a workbench channel name."""
    return re.sub(r"\d+$", "", channel)


def _channel(label: str) -> str | None:
    """The workbench channel of a file's label ('Strain 1', 'strain_1' -> 'strain1')."""
    key = re.sub(r"[\s_]+", "", label).lower()
    return key if key in TABLE2_NAMES else None


def _split_unit(label: str) -> tuple[str, str | None]:
    m = re.fullmatch(r"\s*(.*?)\s*[\(\[]\s*([^\)\]]*?)\s*[\)\]]\s*", label)
    return (m.group(1), m.group(2)) if m else (label.strip(), None)


def _factor(path, line, channel: str, unit: str | None, strain_scale: dict) -> float:
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


def _labels_to_channels(path, line, labels: list[str]) -> list[str]:
    channels = []
    for label in labels:
        channel = _channel(label)
        if channel is None:
            raise ExperimentFileError(path, line, f"unknown channel {label!r}: the channels of "
                                      f"Table 2 are {', '.join(TABLE2_NAMES.values())}")
        if channel in channels:
            raise ExperimentFileError(path, line, f"channel {label!r} appears twice")
        channels.append(channel)
    return channels


def _number(path, line, column: str, text: str, decimal: str) -> float:
    try:
        value = float(text.replace(decimal, ".") if decimal != "." else text)
    except ValueError:
        raise ExperimentFileError(path, line, f"column {column!r}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise ExperimentFileError(path, line, f"column {column!r}: {text!r} is not finite")
    return value


def _meta_value(text: str):
    for cast in (int, float):
        try:
            return cast(text)
        except ValueError:
            pass
    return {"true": True, "false": False}.get(text.lower(), text)


def _finish(path, t: np.ndarray, data: np.ndarray, channels: list[str], factors: list[float],
            meta: dict, assumed: list[str], first_data_line: int) -> pd.DataFrame:
    if len(t) < 2:
        raise ExperimentFileError(path, None, f"has {len(t)} data row(s): need at least 2")
    bad = np.flatnonzero(np.diff(t) <= 0)
    if len(bad):
        raise ExperimentFileError(path, first_data_line + int(bad[0]) + 1,
                                  f"time {t[bad[0] + 1]} s does not increase (previous {t[bad[0]]} s)")
    df = pd.DataFrame(data * np.asarray(factors), columns=channels,
                      index=pd.Index(t, name="t"))
    df.attrs.update(meta=meta, units_assumed=assumed, source=str(path))
    return df


# --- LabVIEW measurement files ----------------------------------------------------------
def read_lvm(path, strain_scale: dict | None = None) -> pd.DataFrame:
    """A LabVIEW measurement file (text, one or more segments) as a record (module docstring)."""
    path = Path(path)
    strain_scale = strain_scale or {}
    lines = _read_lines(path)
    if not lines or not lines[0].startswith("LabVIEW Measurement"):
        raise ExperimentFileError(path, 1, "not a LabVIEW measurement file (the first line must "
                                  "be 'LabVIEW Measurement')")
    i, header = _header_block(path, lines, 1, "\t")
    separator = _text_field(path, header, "Separator", "Tab")
    sep = {"Tab": "\t", "Comma": ",", "Semicolon": ";", "Space": " "}.get(separator)
    if sep is None:
        raise ExperimentFileError(path, None, f"Separator {separator!r} is not supported")
    if sep != "\t":
        i, header = _header_block(path, lines, 1, sep)
    decimal = _text_field(path, header, "Decimal_Separator", ".")
    x_columns = _text_field(path, header, "X_Columns", "One")
    if x_columns not in ("No", "One"):
        raise ExperimentFileError(path, None, f"X_Columns {x_columns!r} is not supported "
                                  "(use No or One: the channels share one time base)")
    meta = {k[len(META_PREFIX):]: _meta_value(v[0]) for k, v in header.items()
            if k.startswith(META_PREFIX) and v}
    times, blocks, channels, factors, assumed, first_data = [], [], None, None, [], None
    while i < len(lines):
        if not lines[i].strip():
            i += 1
            continue
        seg_line = i + 1
        i, seg = _header_block(path, lines, i, sep)
        n_ch = _int_field(path, seg_line, seg, "Channels")
        if i >= len(lines):
            raise ExperimentFileError(path, len(lines), "the file ends before the column names")
        names = lines[i].split(sep)
        names_line = i + 1
        if names and names[-1].strip() in ("Comment", ""):
            names = names[:-1]
        if x_columns == "One":
            if not names or names[0].strip().lower() not in _TIME_NAMES:
                raise ExperimentFileError(path, names_line, "the first column must be X_Value (time)")
            names = names[1:]
        if len(names) != n_ch:
            raise ExperimentFileError(path, names_line, f"{len(names)} channel names for "
                                      f"Channels {n_ch}")
        seg_channels = _labels_to_channels(path, names_line, [n.strip() for n in names])
        if channels is not None and seg_channels != channels:
            raise ExperimentFileError(path, names_line, "the segment's channels differ from the first segment's")
        units = _per_channel(path, seg_line, seg, "Y_Unit_Label", n_ch)
        seg_factors = [_factor(path, seg_line, c, (u or None), strain_scale)
                       for c, u in zip(seg_channels, units)]
        assumed += [c for c, u in zip(seg_channels, units) if not u and c not in assumed]
        channels, factors = seg_channels, seg_factors
        i += 1
        first_data = first_data or i + 1
        rows, i = _data_rows(path, lines, i, sep, decimal, ["X_Value"] * (x_columns == "One")
                             + [TABLE2_NAMES[c] for c in channels])
        if not rows:
            raise ExperimentFileError(path, names_line + 1, "no data rows after the column names")
        declared = _per_channel(path, seg_line, seg, "Samples", n_ch)
        if any(d and _number(path, seg_line, "Samples", d, decimal) != len(rows)
               for d in declared):
            raise ExperimentFileError(path, seg_line, f"the segment declares {declared[0]} samples "
                                      f"but has {len(rows)} rows (truncated file?)")
        rows = np.asarray(rows, dtype=float).reshape(len(rows), -1)
        if x_columns == "One":
            times.append(rows[:, 0])
            blocks.append(rows[:, 1:])
        else:
            x0 = _per_channel(path, seg_line, seg, "X0", n_ch)[0]
            x0 = _number(path, seg_line, "X0", x0, decimal) if x0 else 0.0
            dx = _per_channel(path, seg_line, seg, "Delta_X", n_ch)[0]
            if not dx:
                raise ExperimentFileError(path, seg_line, "X_Columns No needs Delta_X")
            dx = _number(path, seg_line, "Delta_X", dx, decimal)
            times.append(x0 + np.arange(len(rows)) * dx)
            blocks.append(rows)
    if channels is None:
        raise ExperimentFileError(path, len(lines), "no data segment")
    return _finish(path, np.concatenate(times), np.vstack(blocks), channels, factors, meta,
                   assumed, first_data)


def _read_lines(path: Path) -> list[str]:
    try:
        text = path.read_text(encoding="utf-8", errors="strict")
    except FileNotFoundError:
        raise ExperimentFileError(path, None, "no such file") from None
    except UnicodeDecodeError as exc:
        line = path.read_bytes()[:exc.start].count(b"\n") + 1
        raise ExperimentFileError(path, line, "not UTF-8 text (a binary file?)") from None
    return [line.rstrip("\r") for line in text.split("\n")]


def _header_block(path, lines, i, sep) -> tuple[int, dict[str, list[str]]]:
    """Key/value lines up to End_of_Header: (index after it, {key: [values]})."""
    header = {}
    start = i
    while i < len(lines):
        cells = lines[i].split(sep)
        key = cells[0].strip()
        if key == END_OF_HEADER:
            return i + 1, header
        if key:
            header[key] = [c.strip() for c in cells[1:]]
        i += 1
    raise ExperimentFileError(path, start + 1, f"header without {END_OF_HEADER} (truncated file?)")


def _text_field(path, header, key, default: str) -> str:
    """The first value of a header key; ``default`` if the key is absent, an error if it is empty."""
    if key not in header:
        return default
    if not header[key] or not header[key][0]:
        raise ExperimentFileError(path, None, f"the header line '{key}' has no value")
    return header[key][0]


def _int_field(path, line, seg, key) -> int:
    values = seg.get(key)
    try:
        n = int(values[0])
    except (TypeError, IndexError, ValueError):
        raise ExperimentFileError(path, line, f"the segment header needs '{key}' with a whole number") from None
    if n < 1:
        raise ExperimentFileError(path, line, f"{key} = {n}: must be at least 1")
    return n


def _per_channel(path, line, seg, key, n_ch) -> list[str]:
    values = [v for v in seg.get(key, [])]
    while values and values[-1] == "" and len(values) > n_ch:
        values.pop()
    if not values:
        return [""] * n_ch
    if len(values) == 1:
        return values * n_ch
    if len(values) != n_ch:
        raise ExperimentFileError(path, line, f"{key} has {len(values)} values for {n_ch} channels")
    return values


def _data_rows(path, lines, i, sep, decimal, names) -> tuple[list[list[float]], int]:
    """Numeric rows from line i until a blank line, a header or the end."""
    rows = []
    while i < len(lines):
        text = lines[i]
        if not text.strip():
            break
        cells = text.split(sep)
        if len(cells) > len(names) and all(not c.strip() or not _looks_numeric(c) for c in cells[len(names):]):
            cells = cells[:len(names)]          # the comment column
        if len(cells) != len(names):
            problem = "too few" if len(cells) < len(names) else "too many"
            raise ExperimentFileError(path, i + 1, f"{problem} values: {len(cells)} for the "
                                      f"{len(names)} columns {', '.join(names)} (truncated row?)")
        rows.append([_number(path, i + 1, n, c.strip(), decimal) for n, c in zip(names, cells)])
        i += 1
    return rows, i


def _looks_numeric(text: str) -> bool:
    try:
        float(text)
        return True
    except ValueError:
        return False


def write_lvm(path, record: pd.DataFrame, meta: dict | None = None) -> Path:
    """Write a record (CGS, index t) as a LabVIEW measurement file in DEFAULT_UNITS."""
    path = Path(path)
    channels, values = _for_writing(record)
    now = _dt.datetime.now()
    head = ["LabVIEW Measurement\t", "Writer_Version\t2", "Reader_Version\t2", "Separator\tTab",
            "Decimal_Separator\t.", "Multi_Headings\tNo", "X_Columns\tOne", "Time_Pref\tRelative",
            "Operator\tworkbench", f"Date\t{now:%Y/%m/%d}", f"Time\t{now:%H:%M:%S}"]
    head += [f"{META_PREFIX}{k}\t{v}" for k, v in (meta or {}).items()]
    head += [END_OF_HEADER + "\t", "\t"]
    n = len(channels)
    seg = [f"Channels\t{n}", "Samples\t" + "\t".join([str(len(record))] * n),
           "Y_Unit_Label\t" + "\t".join(DEFAULT_UNITS[kind(c)] for c in channels),
           "X_Dimension\t" + "\t".join(["Time"] * n), "X0\t" + "\t".join(["0.0"] * n),
           f"Delta_X\t" + "\t".join([f"{_step(record):.9g}"] * n), END_OF_HEADER + "\t",
           "X_Value\t" + "\t".join(TABLE2_NAMES[c] for c in channels) + "\tComment"]
    body = _rows(record.index.to_numpy(), values, "\t")
    path.write_text("\n".join(head + seg) + "\n" + body)
    return path


# --- plain tab-delimited text ----------------------------------------------------------
def read_tab(path, strain_scale: dict | None = None) -> pd.DataFrame:
    """Tab-delimited text: '#' comment lines (``# WB_key<TAB>value`` are settings), a
    header line 'Time<TAB>Force1 (N)<TAB>...', then numeric rows."""
    path = Path(path)
    lines = _read_lines(path)
    meta, i = {}, 0
    while i < len(lines) and (lines[i].startswith("#") or not lines[i].strip()):
        key, _, value = lines[i].lstrip("#").strip().partition("\t")
        if key.startswith(META_PREFIX):
            meta[key[len(META_PREFIX):]] = _meta_value(value.strip())
        i += 1
    if i >= len(lines):
        raise ExperimentFileError(path, len(lines), "no header line (Time, then the channels)")
    labels = [_split_unit(c) for c in lines[i].split("\t")]
    if labels[0][0].lower() not in _TIME_NAMES:
        raise ExperimentFileError(path, i + 1, f"the first column must be the time, got {labels[0][0]!r}")
    if labels[0][1] not in (None, "s"):
        raise ExperimentFileError(path, i + 1, f"time unit {labels[0][1]!r}: use s")
    channels = _labels_to_channels(path, i + 1, [name for name, _ in labels[1:]])
    factors = [_factor(path, i + 1, c, u, strain_scale or {}) for c, (_, u) in zip(channels, labels[1:])]
    assumed = [c for c, (_, u) in zip(channels, labels[1:]) if u is None]
    rows, end = _data_rows(path, lines, i + 1, "\t", ".", [labels[0][0]]
                           + [TABLE2_NAMES[c] for c in channels])
    if not rows:
        raise ExperimentFileError(path, i + 2, "no data rows after the header line")
    if any(line.strip() for line in lines[end:]):
        extra = end + next(k for k, line in enumerate(lines[end:]) if line.strip())
        raise ExperimentFileError(path, extra + 1, "text after a blank line ends the data")
    rows = np.asarray(rows, dtype=float).reshape(len(rows), -1)
    return _finish(path, rows[:, 0], rows[:, 1:], channels, factors, meta, assumed, i + 2)


def write_tab(path, record: pd.DataFrame, meta: dict | None = None) -> Path:
    """Write a record (CGS, index t) as tab-delimited text in DEFAULT_UNITS."""
    path = Path(path)
    channels, values = _for_writing(record)
    head = [f"# {META_PREFIX}{k}\t{v}" for k, v in (meta or {}).items()]
    head.append("Time (s)\t" + "\t".join(f"{TABLE2_NAMES[c]} ({DEFAULT_UNITS[kind(c)]})"
                                         for c in channels))
    path.write_text("\n".join(head) + "\n" + _rows(record.index.to_numpy(), values, "\t"))
    return path


# --- both ------------------------------------------------------------------------------
def read(path, strain_scale: dict | None = None) -> pd.DataFrame:
    """Read an .lvm file, or tab-delimited text (.txt, .tsv, .dat, .tab)."""
    suffix = Path(path).suffix.lower()
    if suffix == ".lvm":
        return read_lvm(path, strain_scale)
    if suffix in (".txt", ".tsv", ".dat", ".tab"):
        return read_tab(path, strain_scale)
    raise ExperimentFileError(path, None, f"unknown file type {suffix!r}: use .lvm or tab-delimited "
                              ".txt/.tsv/.dat/.tab")


def write(path, record: pd.DataFrame, meta: dict | None = None) -> Path:
    """Write ``record`` in the format of the path's suffix (.lvm or text)."""
    return (write_lvm if Path(path).suffix.lower() == ".lvm" else write_tab)(path, record, meta)


def record_from_run(run) -> pd.DataFrame:
    """The Table 2 channels of a simulated run as a record (CGS; contacts as an ideal
    patch: 1 V while the point is closed, 0 V while open)."""
    return run.signals[list(CHANNELS)].astype(float)


def _for_writing(record: pd.DataFrame):
    channels = [c for c in CHANNELS if c in record.columns]
    unknown = sorted(set(record.columns) - set(CHANNELS))
    if unknown or not channels:
        raise ParameterError(f"a record holds only the channels {', '.join(CHANNELS)}; got {unknown}")
    factors = np.array([UNITS[kind(c)][DEFAULT_UNITS[kind(c)]] for c in channels])
    return channels, record[channels].to_numpy(dtype=float) / factors


def _step(record) -> float:
    t = record.index.to_numpy(dtype=float)
    return float(np.median(np.diff(t))) if len(t) > 1 else 0.0


def _rows(t, values, sep) -> str:
    table = np.column_stack([t, values])
    return "\n".join(sep.join(f"{x:.10g}" for x in row) for row in table) + "\n"
