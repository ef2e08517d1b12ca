"""Tab-delimited text (.txt, .tsv, .dat, .tab): '#' comment lines (``# WB_key<TAB>value``
lines are the settings), a header line ``Time<TAB>Force1 (N)<TAB>...`` (a unit in
parentheses or brackets), then numeric rows."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..channels import (DEFAULT_UNITS, META_PREFIX, TABLE2_NAMES, TIME_NAMES, ExperimentFileError,
                        factor, for_writing, kind, labels_to_channels, meta_value, number,
                        read_lines, record, text_rows)


def read(path, strain_scale: dict | None = None):
    """Tab-delimited text (module docstring) as a record."""
    path = Path(path)
    lines = read_lines(path)
    meta, i = {}, 0
    while i < len(lines) and (lines[i].startswith("#") or not lines[i].strip()):
        key, _, value = lines[i].lstrip("#").strip().partition("\t")
        if key.startswith(META_PREFIX):
            meta[key[len(META_PREFIX):]] = meta_value(value.strip())
        i += 1
    if i >= len(lines):
        raise ExperimentFileError(path, len(lines), "no header line (Time, then the channels)")
    labels = [_split_unit(c) for c in lines[i].split("\t")]
    if labels[0][0].lower() not in TIME_NAMES:
        raise ExperimentFileError(path, i + 1, f"the first column must be the time, got {labels[0][0]!r}")
    if labels[0][1] not in (None, "s"):
        raise ExperimentFileError(path, i + 1, f"time unit {labels[0][1]!r}: use s")
    channels = labels_to_channels(path, i + 1, [name for name, _ in labels[1:]])
    factors = [factor(path, i + 1, c, u, strain_scale or {}) for c, (_, u) in zip(channels, labels[1:])]
    assumed = [c for c, (_, u) in zip(channels, labels[1:]) if u is None]
    names = [labels[0][0]] + [TABLE2_NAMES[c] for c in channels]
    values, end = _data_rows(path, lines, i + 1, names)
    if not values:
        raise ExperimentFileError(path, i + 2, "no data rows after the header line")
    if any(line.strip() for line in lines[end:]):
        extra = end + next(k for k, line in enumerate(lines[end:]) if line.strip())
        raise ExperimentFileError(path, extra + 1, "text after a blank line ends the data")
    values = np.asarray(values, dtype=float).reshape(len(values), -1)
    return record(path, values[:, 0], values[:, 1:], channels, factors, meta, assumed,
                  line_of_row=lambda r: i + 2 + r)


def _split_unit(label: str) -> tuple[str, str | None]:
    m = re.fullmatch(r"\s*(.*?)\s*[\(\[]\s*([^\)\]]*?)\s*[\)\]]\s*", label)
    return (m.group(1), m.group(2)) if m else (label.strip(), None)


def _data_rows(path, lines, i, names) -> tuple[list[list[float]], int]:
    """Numeric rows from line i until a blank line or the end."""
    values = []
    while i < len(lines):
        text = lines[i]
        if not text.strip():
            break
        cells = text.split("\t")
        if len(cells) != len(names):
            problem = "too few" if len(cells) < len(names) else "too many"
            raise ExperimentFileError(path, i + 1, f"{problem} values: {len(cells)} for the "
                                      f"{len(names)} columns {', '.join(names)} (truncated row?)")
        values.append([number(path, i + 1, n, c.strip()) for n, c in zip(names, cells)])
        i += 1
    return values, i


def write(path, record, meta: dict | None = None) -> Path:
    """Write a record (CGS, index t) as tab-delimited text in DEFAULT_UNITS."""
    path = Path(path)
    channels, values = for_writing(record)
    head = [f"# {META_PREFIX}{k}\t{v}" for k, v in (meta or {}).items()]
    head.append("Time (s)\t" + "\t".join(f"{TABLE2_NAMES[c]} ({DEFAULT_UNITS[kind(c)]})"
                                         for c in channels))
    path.write_text("\n".join(head) + "\n" + text_rows(record.index.to_numpy(), values, "\t"))
    return path
