"""The units a user reads: SI as the field writes it (N, m/s², µε, mm).

The kernels, a run's signals and a study's points table keep CGS (cm, g, s,
dyn; strain as a ratio), which the model's parameters and equations are
written in (docs/model.md).  Every figure, table, report and human-readable
line converts on the way out, with the unit in its label or column header:
:func:`channel` for a record's channels, :func:`quantity` for a points
table's metrics, :func:`si` for a value of a CGS unit.
"""
from __future__ import annotations

from ..lab.channels import kind
from ..model.shown_units import SI
from ..study.metrics import QUANTITIES

#: The CGS unit of each kind of channel of a record (``tip``: beam B's tip displacement).
CHANNEL_CGS = {"force": "dyn", "strain": "strain", "accel": "cm/s²", "tip": "cm",
               "contact": ""}


def si(cgs_unit: str) -> tuple[str, float]:
    """(unit shown, factor from CGS) of a CGS unit."""
    return SI[cgs_unit]


def channel(name: str) -> tuple[str, float]:
    """(unit shown, factor from CGS) of a record's channel ('accel3', 'tip', ...)."""
    return si(CHANNEL_CGS["tip" if name.startswith("tip") else kind(name)])


def channel_label(name: str, what: str = "") -> str:
    """An axis label of a channel: 'accel3 (m/s²)', 'strain1 (µε)'; ``what`` before the name."""
    unit = channel(name)[0]
    return f"{what + ' ' if what else ''}{name}{f' ({unit})' if unit else ''}"


def quantity(name: str) -> tuple[str, str, float]:
    """(title, unit shown, factor from CGS) of a points table's metric (``metrics.QUANTITIES``)."""
    title, cgs = QUANTITIES[name]
    unit, factor = si(cgs)
    return title, unit, factor


def quantity_label(name: str) -> str:
    """'tip RMS (mm)', 'impacts per s' (a metric's title and unit shown)."""
    title, unit, _ = quantity(name)
    return f"{title} ({unit})" if unit else title


def column(name: str) -> str:
    """A table's column header with its unit: 'tip_rms [mm]' (a metric without one as is)."""
    unit = quantity(name)[1] if name in QUANTITIES else ""
    return f"{name} [{unit}]" if unit else name
