"""LabVIEW measurement files (.lvm): read by ``lvm_read`` (SDyPy), written here.

``lvm_read`` parses the file into a header and segments; this module checks
what it returns against the file (NI's LVM specification: one header, then
segments of a header, the column names after ``X_Value`` and the rows), so
that a damaged file ends in an :class:`ExperimentFileError` naming the line.
Header keys starting with ``WB_`` are the record's settings.  Each segment
gives one ``Y_Unit_Label`` per channel; a channel without one is read in
:data:`~workbench.lab.channels.DEFAULT_UNITS`.
"""
from __future__ import annotations

import ast
import datetime as _dt
from pathlib import Path

import lvm_read
import numpy as np

from ..channels import (DEFAULT_UNITS, META_PREFIX, TABLE2_NAMES, ExperimentFileError, factor,
                        for_writing, kind, labels_to_channels, meta_value, number, read_lines,
                        record, text_rows, time_step)

END_OF_HEADER = "***End_of_Header***"
MAGIC = "LabVIEW Measurement"


def read(path, strain_scale: dict | None = None):
    """A LabVIEW measurement file (one or more segments) as a record."""
    path = Path(path)
    lines = read_lines(path)
    if not lines or not lines[0].startswith(MAGIC):
        raise ExperimentFileError(path, 1, f"not a LabVIEW measurement file (the first line must "
                                  f"be '{MAGIC}')")
    sep = _separator(path, lines)
    if not any(line.split(sep)[0].strip() == END_OF_HEADER for line in lines):
        raise ExperimentFileError(path, 2, f"header without {END_OF_HEADER} (truncated file?)")
    raw = [line + "\n" for line in lines[:-1]] + ([lines[-1]] if lines[-1] else [])
    segments = _segments(raw, sep)
    if not segments:
        raise ExperimentFileError(path, len(lines), "no data segment")
    try:
        lvm = lvm_read.read_lines(raw, separator=sep)
    except Exception as exc:                  # noqa: BLE001 - the library's word on a bad file
        raise ExperimentFileError(path, _bad_literal_line(raw, sep),
                                  f"lvm_read cannot parse it ({type(exc).__name__}: "
                                  f"{' '.join(str(exc).split())[:120]})") from None
    if lvm["Segments"] != len(segments):      # the layout below mirrors lvm_read's
        raise ExperimentFileError(path, None, f"lvm_read finds {lvm['Segments']} segments where "
                                  f"the file has {len(segments)}")
    decimal = lvm.get("Decimal_Separator", ".") or "."
    x_columns = lvm.get("X_Columns", "One")
    if x_columns not in ("No", "One"):
        raise ExperimentFileError(path, None, f"X_Columns {x_columns!r} is not supported "
                                  "(use No or One: the channels share one time base)")
    meta = {k[len(META_PREFIX):]: meta_value(v.strip()) for k, v in lvm.items()
            if isinstance(k, str) and k.startswith(META_PREFIX) and v.strip()}
    times, blocks, rows_lines, channels, factors, assumed = [], [], [], None, None, []
    for k, where in enumerate(segments):
        seg_t, seg_data, seg_channels, seg_factors, seg_assumed = _segment(
            path, lines, sep, decimal, x_columns, lvm[k], where, strain_scale or {})
        if channels is not None and seg_channels != channels:
            raise ExperimentFileError(path, where["names"], "the segment's channels differ from "
                                      "the first segment's")
        channels, factors = seg_channels, seg_factors
        assumed += [c for c in seg_assumed if c not in assumed]
        times.append(seg_t)
        blocks.append(seg_data)
        rows_lines += where["rows"]
    return record(path, np.concatenate(times), np.vstack(blocks), channels, factors, meta,
                  assumed, line_of_row=lambda i: rows_lines[i])


def _separator(path, lines) -> str:
    """The column separator: the character after 'Separator' in the header (tab if absent)."""
    for line in lines[:40]:
        if line.startswith("Separator"):
            if len(line) < 10 or not line[9:].strip(" \t"):
                raise ExperimentFileError(path, lines.index(line) + 1,
                                          "the header line 'Separator' has no value")
            return line[9]
    return "\t"


def _segments(raw: list[str], sep: str) -> list[dict]:
    """Where each segment lies (1-based lines): its start, 'Channels', the column names and
    the rows, segmented as lvm_read does (a blank line opens a segment)."""
    segments, current, reading = [], None, False
    for n, line in enumerate(raw, 1):
        line = line.replace("\r", "")
        first = line.rstrip("\n").split(sep)[0]
        if first in (END_OF_HEADER, MAGIC):
            continue
        if line in ("\n", sep + "\n"):
            current, reading = {"start": n, "rows": []}, False
            segments.append(current)
        elif reading:
            current["rows"].append(n)
        elif current is not None and first == "Channels":
            current.setdefault("channels", n)
        elif current is not None and first == "X_Value":
            current["names"], reading = n, True
    if segments and set(segments[-1]) == {"start", "rows"} and not segments[-1]["rows"]:
        segments.pop()                        # the blank line that ends the file
    return segments


def _bad_literal_line(raw, sep) -> int | None:
    """The line of a Samples / X0 / Delta_X value lvm_read cannot evaluate, if there is one."""
    for n, line in enumerate(raw, 1):
        cells = line.rstrip("\n").split(sep)
        if cells[0] in ("Samples", "X0", "Delta_X", "Channels"):
            for cell in cells[1:]:
                try:
                    if cell:
                        ast.literal_eval(cell.replace(",", "."))
                except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
                    return n
    return None


def _segment(path, lines, sep, decimal, x_columns, seg: dict, where: dict, strain_scale):
    """Time, values (file units), channels, factors to CGS and channels without a unit of
    one segment lvm_read returned, checked against the file's lines."""
    head = where.get("channels", where["start"])
    if "Channels" not in seg or "names" not in where:
        raise ExperimentFileError(path, where["start"], "a segment needs a 'Channels' line and "
                                  "the column names (X_Value ...) (truncated file?)")
    n_ch = seg["Channels"]
    if not isinstance(n_ch, int) or isinstance(n_ch, bool) or n_ch < 1:
        raise ExperimentFileError(path, head, f"Channels {n_ch!r}: must be a whole number >= 1")
    names = [n.strip() for n in seg["Channel names"]]
    if x_columns == "One":
        if not names or names[0].lower() != "x_value":
            raise ExperimentFileError(path, where["names"],
                                      "the first column must be X_Value (time)")
        names = names[1:]
    if names and names[-1] in ("Comment", ""):
        names = names[:-1]
    if len(names) != n_ch:
        raise ExperimentFileError(path, where["names"], f"{len(names)} channel names for "
                                  f"Channels {n_ch}")
    channels = labels_to_channels(path, where["names"], names)
    units = _per_channel(path, head, seg.get("Y_Unit_Label", []), "Y_Unit_Label", n_ch)
    factors = [factor(path, head, c, str(u).strip() or None, strain_scale)
               for c, u in zip(channels, units)]
    assumed = [c for c, u in zip(channels, units) if not str(u).strip()]
    if not where["rows"]:
        raise ExperimentFileError(path, where["names"] + 1, "no data rows after the column names")
    first = 1 if x_columns == "No" else 0             # lvm_read's first column
    width = n_ch + (x_columns == "One")
    columns = ["X_Value"] * (x_columns == "One") + [TABLE2_NAMES[c] for c in channels]
    data = np.asarray(seg["data"], dtype=float).reshape(len(where["rows"]), -1)[:, :width]
    for j, n in enumerate(where["rows"]):             # what lvm_read leaves out or fills in
        cells = lines[n - 1].split(sep)[first:]
        extra = cells[width:]
        if len(cells) < width:
            raise ExperimentFileError(path, n, f"too few values: {len(cells)} for the {width} "
                                      f"columns {', '.join(columns)} (truncated row?)")
        if any(c.strip() and _is_number(c) for c in extra):
            raise ExperimentFileError(path, n, f"too many values: {len(cells)} for the {width} "
                                      f"columns {', '.join(columns)}")
        bad = np.flatnonzero(~np.isfinite(data[j]))
        if len(bad):
            text = cells[bad[0]].strip(" ")
            number(path, n, columns[bad[0]], text, decimal)       # says why, if float() agrees
            raise ExperimentFileError(path, n, f"column {columns[bad[0]]!r}: {text!r} is not "
                                      "a number")
    declared = _per_channel(path, head, seg.get("Samples", []), "Samples", n_ch)
    if any(_given(d) and d != len(data) for d in declared):
        raise ExperimentFileError(path, head, f"the segment declares {declared[0]} samples but has "
                                  f"{len(data)} rows (truncated file?)")
    if x_columns == "One":
        return data[:, 0], data[:, 1:], channels, factors, assumed
    x0 = _per_channel(path, head, seg.get("X0", []), "X0", n_ch)[0]
    dx = _per_channel(path, head, seg.get("Delta_X", []), "Delta_X", n_ch)[0]
    if not _given(dx) or not dx > 0:
        raise ExperimentFileError(path, head, "X_Columns No needs a Delta_X > 0")
    x0 = float(x0) if _given(x0) else 0.0
    return x0 + np.arange(len(data)) * float(dx), data, channels, factors, assumed


def _given(value) -> bool:
    """A number lvm_read evaluated from a non-empty field (it gives NaN for an empty one)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    return bool(np.isfinite(value))


def _per_channel(path, line, values: list, key: str, n_ch: int) -> list:
    """One value per channel of a segment header line (one value counts for all)."""
    values = list(values)
    while len(values) > n_ch and (values[-1] == "" or _is_nan(values[-1])):
        values.pop()
    if not values:
        return [""] * n_ch
    if len(values) == 1:
        return values * n_ch
    if len(values) != n_ch:
        raise ExperimentFileError(path, line, f"{key} has {len(values)} values for {n_ch} channels")
    for v in values:
        if key != "Y_Unit_Label" and not (_given(v) or _is_nan(v)):
            raise ExperimentFileError(path, line, f"{key} {v!r} is not a number")
    return values


def _is_nan(value) -> bool:
    """lvm_read's value of an empty numeric field."""
    return isinstance(value, float) and np.isnan(value)


def _is_number(text: str) -> bool:
    try:
        float(text)
        return True
    except ValueError:
        return False


def write(path, record, meta: dict | None = None) -> Path:
    """Write a record (CGS, index t) as a LabVIEW measurement file in DEFAULT_UNITS."""
    path = Path(path)
    channels, values = for_writing(record)
    now = _dt.datetime.now()
    head = [f"{MAGIC}\t", "Writer_Version\t2", "Reader_Version\t2", "Separator\tTab",
            "Decimal_Separator\t.", "Multi_Headings\tNo", "X_Columns\tOne", "Time_Pref\tRelative",
            "Operator\tworkbench", f"Date\t{now:%Y/%m/%d}", f"Time\t{now:%H:%M:%S}"]
    head += [f"{META_PREFIX}{k}\t{v}" for k, v in (meta or {}).items()]
    head += [END_OF_HEADER + "\t", "\t"]
    n = len(channels)
    step = time_step(record) or 0.0
    seg = [f"Channels\t{n}", "Samples\t" + "\t".join([str(len(record))] * n),
           "Y_Unit_Label\t" + "\t".join(DEFAULT_UNITS[kind(c)] for c in channels),
           "X_Dimension\t" + "\t".join(["Time"] * n),
           "X0\t" + "\t".join([f"{record.index[0]:.10g}"] * n),
           "Delta_X\t" + "\t".join([f"{step:.9g}"] * n), END_OF_HEADER + "\t",
           "X_Value\t" + "\t".join(TABLE2_NAMES[c] for c in channels) + "\tComment"]
    path.write_text("\n".join(head + seg) + "\n" + text_rows(record.index.to_numpy(), values, "\t"))
    return path
