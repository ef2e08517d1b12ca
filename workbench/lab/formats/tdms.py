"""LabVIEW TDMS files (.tdms), read and written by ``npTDMS``.

A record is one group (``Table 2``) of channels named as Table 2 names the
sensors (``Force1`` ... ``Accel3``), each with its unit in the
``unit_string`` property (DAQmx files write ``NI_UnitDescription``, also
read).  The time base is the channels' waveform properties
(``wf_start_offset``, ``wf_increment``, s), or a channel ``Time`` (s) of the
same group.  The file's properties with keys starting ``WB_`` are the
settings.  A file with several groups is read from the one group that holds
Table 2 channels.
"""
from __future__ import annotations

import contextlib
import logging
from pathlib import Path

import numpy as np

from ..channels import (DEFAULT_UNITS, META_PREFIX, TABLE2_NAMES, TIME_NAMES, ExperimentFileError,
                        channel_of, factor, for_writing, kind, labels_to_channels, record,
                        time_step)

GROUP = "Table 2"
UNIT_PROPERTIES = ("unit_string", "NI_UnitDescription")


def read(path, strain_scale: dict | None = None):
    """A TDMS file (module docstring) as a record."""
    from nptdms import TdmsFile

    path = Path(path)
    if not path.is_file():
        raise ExperimentFileError(path, None, "no such file")
    with _warnings_of("nptdms") as warned:
        try:
            tdms = TdmsFile.read(path)
            groups = [(g, g.channels()) for g in tdms.groups()]
        except Exception as exc:              # noqa: BLE001 - npTDMS's word on a bad file
            raise ExperimentFileError(path, None, f"not a readable TDMS file ({type(exc).__name__}: "
                                      f"{' '.join(str(exc).split())[:120]})") from None
    if warned:                                # npTDMS reads on past damage, with a warning
        raise ExperimentFileError(path, None, f"damaged or truncated TDMS file (npTDMS: "
                                  f"{' '.join(warned[0].split())[:120]})")
    ours = [(g, chs) for g, chs in groups if any(channel_of(c.name) for c in chs)]
    if len(ours) != 1:
        raise ExperimentFileError(path, None, f"{len(ours)} groups hold Table 2 channels "
                                  f"({', '.join(repr(g.name) for g, _ in ours)}); need one")
    group, chs = ours[0]
    time = [c for c in chs if c.name.strip().lower() in TIME_NAMES]
    signals = [c for c in chs if c not in time]
    where = f"group {group.name!r}"
    channels = labels_to_channels(path, None, [c.name for c in signals])
    units = [_unit(c) for c in signals]
    factors = [factor(path, None, ch, u, strain_scale or {}) for ch, u in zip(channels, units)]
    try:
        data = [np.asarray(c[:], dtype=float) for c in signals]
    except (TypeError, ValueError) as exc:
        raise ExperimentFileError(path, None, f"{where}: a channel is not numeric ({exc})") from None
    lengths = {len(d) for d in data}
    if len(lengths) != 1:
        raise ExperimentFileError(path, None, f"{where}: the channels differ in length "
                                  f"({sorted(lengths)} samples)")
    for name, d in zip(channels, data):
        if not np.all(np.isfinite(d)):
            raise ExperimentFileError(path, None, f"{where}, channel {TABLE2_NAMES[name]}: values "
                                      "that are not finite")
    t = _time(path, where, time, signals[0], lengths.pop())
    meta = {k[len(META_PREFIX):]: _plain(v) for k, v in tdms.properties.items()
            if k.startswith(META_PREFIX)}
    assumed = [ch for ch, u in zip(channels, units) if u is None]
    return record(path, t, np.column_stack(data), channels, factors, meta, assumed)


@contextlib.contextmanager
def _warnings_of(prefix: str):
    """Collect the warnings the loggers of a library (names starting ``prefix``) log,
    instead of letting them print, into a list."""
    messages: list[str] = []

    class Collect(logging.Handler):
        def emit(self, record):
            if record.levelno >= logging.WARNING:
                messages.append(record.getMessage())

    collect = Collect()
    loggers = [logging.getLogger(name) for name in list(logging.root.manager.loggerDict)
               if name == prefix or name.startswith(prefix + ".")]
    saved = [(log, log.handlers[:], log.propagate) for log in loggers]
    for log in loggers:
        log.handlers[:] = [collect]
        log.propagate = False
    try:
        yield messages
    finally:
        for log, handlers, propagate in saved:
            log.handlers[:] = handlers
            log.propagate = propagate


def _unit(channel) -> str | None:
    for key in UNIT_PROPERTIES:
        value = channel.properties.get(key)
        if isinstance(value, str) and value.strip():
            return value.strip()
    return None


def _time(path, where, time, first, n: int) -> np.ndarray:
    if len(time) > 1:
        raise ExperimentFileError(path, None, f"{where}: {len(time)} time channels")
    if time:
        unit = _unit(time[0])
        if unit not in (None, "s"):
            raise ExperimentFileError(path, None, f"{where}: time unit {unit!r}: use s")
        t = np.asarray(time[0][:], dtype=float)
        if len(t) != n:
            raise ExperimentFileError(path, None, f"{where}: {len(t)} times for {n} samples")
        return t
    props = first.properties
    try:
        t0, dt = float(props.get("wf_start_offset", 0.0)), float(props["wf_increment"])
    except (KeyError, TypeError, ValueError):
        raise ExperimentFileError(path, None, f"{where}: no time base (a Time channel, or the "
                                  "waveform properties wf_increment and wf_start_offset)") from None
    if not (np.isfinite(t0) and np.isfinite(dt) and dt > 0):
        raise ExperimentFileError(path, None, f"{where}: wf_increment {dt!r} s: must be > 0")
    return t0 + np.arange(n) * dt


def _plain(value):
    """A TDMS property as a plain Python value (numpy scalars, timestamps as text)."""
    if isinstance(value, (bool, int, float, str)):
        return value
    if hasattr(value, "item"):
        try:
            return value.item()
        except (TypeError, ValueError):
            pass
    return str(value)


def write(path, record, meta: dict | None = None) -> Path:
    """Write a record (CGS, index t) as TDMS in DEFAULT_UNITS, with waveform timing when
    the time base is uniform (else a Time channel)."""
    from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

    path = Path(path)
    channels, values = for_writing(record)
    t = record.index.to_numpy(dtype=float)
    step = time_step(record)
    timing = {"wf_start_offset": float(t[0]), "wf_increment": step,
              "wf_samples": len(t)} if step else {}
    objects = [RootObject({"name": path.stem, "author": "workbench",
                           **{f"{META_PREFIX}{k}": _property(v) for k, v in (meta or {}).items()}}),
               GroupObject(GROUP, {"description": "sensors of Table 2 (seed §3.3-3.4)"})]
    if not step:
        objects.append(ChannelObject(GROUP, "Time", t, {"unit_string": "s"}))
    for c, column in zip(channels, values.T):
        objects.append(ChannelObject(GROUP, TABLE2_NAMES[c], np.ascontiguousarray(column),
                                     {"unit_string": DEFAULT_UNITS[kind(c)], **timing}))
    with TdmsWriter(str(path)) as writer:
        writer.write_segment(objects)
    return path


def _property(value):
    """A setting as a TDMS property value (bool, int, float or text)."""
    if isinstance(value, (bool, int, float, str)):
        return value
    return str(value)
