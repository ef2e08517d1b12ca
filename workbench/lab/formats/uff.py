"""Universal File Format (.uff, .unv), read and written by ``pyuff`` (SDyPy).

A record is written as, in order:

- dataset 151, the header (the program and the file's name);
- dataset 164, the units: SI (m, N, s), as the file's values are;
- dataset 2411, the nodes: one per sensor of Table 2 at its rest position on
  the rig (m; x along the beam from the clamp, y up, z across), numbered as
  :data:`NODES` (1 Force1 ... 10 Accel3, 11 the hammer's struck point: the
  joint body's base for ``hammer_joint``, beam B's tip for ``hammer_tip``);
- dataset 58, one time history per channel (function type 1): response node
  and direction the sensor's (+Y for force and acceleration, +X for the
  surface strains, +Y for the contact patches; the hammer +Y at the joint,
  +X along beam B at its tip), reference node and direction the drive's
  force (the hammer in an impact test, else the shaker, Force1, +Y), the
  ordinate's specific data type and units label
  (:data:`ORDINATE`), abscissa time (s) with even spacing.  ID line 1 is the
  Table 2 name; ID lines 4 and 5 carry the settings as ``WB_key=value``
  words (UFF has no other place for them), spread over the records.

FRFs (function type 4) are written by :func:`write_frf`.  Reading takes the
time histories (dataset 58, function type 1) whose ID line 1 or response
entity names a Table 2 channel; other datasets are left alone.
"""
from __future__ import annotations

import datetime as _dt
from pathlib import Path

import numpy as np

from ..channels import (CHANNELS, DEFAULT_UNITS, META_PREFIX, TABLE2_NAMES, ExperimentFileError,
                        channel_of, factor, for_writing, kind, labels_to_channels, meta_value,
                        record, reference_of, time_step)

#: Node number of each channel's sensor.
NODES = {c: i + 1 for i, c in enumerate(CHANNELS)}
#: Direction code of each kind of sensor (UFF: 1 +X, 2 +Y, 3 +Z).
DIRECTIONS = {"force": 2, "accel": 2, "strain": 1, "contact": 2}
#: UFF specific data type of each kind (13 excitation force, 12 acceleration, 3 strain,
#: 1 general: the contact patches' voltage).
ORDINATE = {"force": 13, "accel": 12, "strain": 3, "contact": 1}
#: Exponents (length, force) of each kind's SI unit, UFF record 9.
EXPONENTS = {"force": (0, 1), "accel": (1, 0), "strain": (0, 0), "contact": (0, 0)}
TIME_TYPE, FREQUENCY_TYPE = 17, 18
LINE = 80


def hammer_direction(drive: str | None) -> int:
    """The hammer's UFF direction: +X along beam B at its tip, else +Y (docs/model.md §8)."""
    return 1 if drive == "hammer_tip" else 2


def direction(channel: str, drive: str | None) -> int:
    """A channel's UFF direction code in a record of that drive."""
    return hammer_direction(drive) if channel == "hammer" else DIRECTIONS[kind(channel)]


def sensor_positions(p=None, drive: str | None = None) -> dict[str, tuple[float, float, float]]:
    """Rest position (m) of each sensor of Table 2 (MODEL.md §9), the gap centred, and of the
    hammer's struck point for that drive (the joint body's base, or beam B's tip)."""
    from ...model.params import Parameters

    p = p or Parameters()
    root_b = p.l_a + p.x_in + p.l4                     # beam B's root (cm)
    lip = p.h4 / 2.0 + p.gap / 2.0
    cm = {"force1": (p.x_force, 0.0), "strain1": (p.x_strain1, 0.0),
          "accel1": (p.l_a + p.x_accel1, 0.0),
          "contact1": (p.l_a + p.x_in, -p.h4 / 2.0), "contact2": (p.l_a + p.x_in, p.h4 / 2.0),
          "contact3": (p.l_a + p.x_lip, -lip), "contact4": (p.l_a + p.x_lip, lip),
          "accel2": (p.l_a + p.x_in + p.x_accel2, 0.0), "strain2": (root_b + p.x_strain2, 0.0),
          "accel3": (root_b + p.x_accel3, 0.0),
          "hammer": (p.l_a, 0.0) if drive == "hammer_joint" else (root_b + p.l_b, 0.0)}
    return {c: (x / 100.0, y / 100.0, 0.0) for c, (x, y) in cm.items()}


def read(path, strain_scale: dict | None = None):
    """The time histories of a UFF file (module docstring) as a record."""
    import pyuff

    path = Path(path)
    if not path.is_file():
        raise ExperimentFileError(path, None, "no such file")
    try:
        sets = pyuff.UFF(str(path)).read_sets()
    except Exception as exc:                  # noqa: BLE001 - pyuff's word on a bad file
        raise ExperimentFileError(path, None, f"not a readable UFF file ({type(exc).__name__}: "
                                  f"{' '.join(str(exc).split())[:120]})") from None
    sets = [sets] if isinstance(sets, dict) else list(sets)
    histories = [s for s in sets if s.get("type") == 58 and s.get("func_type") == 1]
    if not histories:
        raise ExperimentFileError(path, None, "no time history (dataset 58, function type 1)")
    labels = [_label(s) for s in histories]
    channels = labels_to_channels(path, None, labels)
    units = [_text(s.get("ordinate_axis_units_lab")) for s in histories]
    factors = [factor(path, None, c, u, strain_scale or {}) for c, u in zip(channels, units)]
    t = np.asarray(histories[0].get("x", []), dtype=float)
    data = []
    for label, s in zip(labels, histories):
        x = np.asarray(s.get("x", []), dtype=float)
        y = np.asarray(s.get("data", []))
        if np.iscomplexobj(y) or len(y) != len(x) or len(x) != len(t) or \
                not np.allclose(x, t, rtol=1e-9, atol=1e-12):
            raise ExperimentFileError(path, None, f"{label}: its time base differs from "
                                      f"{labels[0]}'s, or its values are not a real time history")
        if not np.all(np.isfinite(y)):
            raise ExperimentFileError(path, None, f"{label}: values that are not finite")
        data.append(y.astype(float))
    unit = _text(histories[0].get("abscissa_axis_units_lab"))
    if unit not in (None, "s"):
        raise ExperimentFileError(path, None, f"{labels[0]}: abscissa unit {unit!r}: use s")
    words = " ".join(_text(s.get(k)) or "" for s in histories for k in ("id4", "id5")).split()
    meta = {}
    for word in words:
        key, eq, value = word.partition("=")
        if key.startswith(META_PREFIX) and eq:
            meta[key[len(META_PREFIX):]] = meta_value(value)
    assumed = [c for c, u in zip(channels, units) if u is None]
    return record(path, t, np.column_stack(data), channels, factors, meta, assumed)


def _text(value) -> str | None:
    text = str(value).strip() if value is not None else ""
    return None if text in ("", "NONE") else text


def _label(s: dict) -> str:
    for key in ("id1", "rsp_ent_name"):
        text = _text(s.get(key))
        if text and channel_of(text):
            return text
    return _text(s.get("id1")) or f"node {s.get('rsp_node')} direction {s.get('rsp_dir')}"


def _setting_lines(meta: dict, n_lines: int, path="(writing UFF)") -> list[str]:
    """The settings as WB_key=value words, packed into at most n_lines lines of 80 columns."""
    lines, current = [], ""
    for key, value in (meta or {}).items():
        word = f"{META_PREFIX}{key}={value}"
        if any(ch.isspace() for ch in word) or len(word) > LINE:
            raise ExperimentFileError(path, None, f"setting {key} = {value!r}: a UFF "
                                      f"setting is one word of at most {LINE} characters")
        if current and len(current) + 1 + len(word) > LINE:
            lines.append(current)
            current = ""
        current = f"{current} {word}".strip()
    if current:
        lines.append(current)
    if len(lines) > n_lines:
        raise ExperimentFileError(path, None, f"the settings need {len(lines)} lines of "
                                  f"{LINE} columns; the records hold {n_lines}")
    return lines + ["NONE"] * (n_lines - len(lines))


def check_settings(path, meta: dict | None, records: int = len(CHANNELS)) -> None:
    """The settings fit the ID lines of that many records (default: every channel)."""
    _setting_lines(meta, 2 * records, path)


def _header_sets(path: Path, p=None, drive: str | None = None) -> list[dict]:
    import pyuff

    positions = sensor_positions(p, drive)
    nodes = [NODES[c] for c in CHANNELS]
    return [pyuff.prepare_151(model_name=path.stem, description="loose bolted lap joint rig, "
                              "sensors of Table 2", db_app="workbench", program="workbench"),
            pyuff.prepare_164(units_code=1, units_description="SI", temp_mode=1, length=1.0,
                              force=1.0, temp=1.0, temp_offset=273.15),
            pyuff.prepare_2411(node_nums=nodes, def_cs=[0] * len(nodes), disp_cs=[0] * len(nodes),
                               color=[1] * len(nodes),
                               x=[float(positions[c][0]) for c in CHANNELS],
                               y=[float(positions[c][1]) for c in CHANNELS],
                               z=[float(positions[c][2]) for c in CHANNELS])]


def _record_58(**fields) -> dict:
    import pyuff

    return pyuff.prepare_58(binary=0, ver_num=0, load_case_id=0, z_axis_value=0.0,
                            abscissa_len_unit_exp=0, abscissa_force_unit_exp=0,
                            abscissa_temp_unit_exp=0, ordinate_temp_unit_exp=0,
                            orddenom_temp_unit_exp=0, z_axis_spec_data_type=0,
                            z_axis_len_unit_exp=0, z_axis_force_unit_exp=0, z_axis_temp_unit_exp=0,
                            z_axis_axis_units_lab="NONE", **fields)


def write(path, record, meta: dict | None = None) -> Path:
    """Write a record (CGS, index t) as UFF (module docstring) in SI units."""
    path = Path(path)
    channels, values = for_writing(record)
    t = record.index.to_numpy(dtype=float)
    step = time_step(record)
    if step is None:
        raise ExperimentFileError(path, None, "UFF time histories need a uniform time base")
    settings = _setting_lines(meta, 2 * len(channels), path)
    now = f"{_dt.datetime.now():%d-%b-%y %H:%M:%S}"
    drive = (meta or {}).get("drive")
    sets = _header_sets(path, _parameters(meta), drive)
    ref = reference_of(drive)
    for i, (c, column) in enumerate(zip(channels, values.T)):
        length_exp, force_exp = EXPONENTS[kind(c)]
        sets.append(_record_58(
            id1=TABLE2_NAMES[c], id2="workbench record", id3=now, id4=settings[2 * i],
            id5=settings[2 * i + 1], func_type=1, rsp_ent_name=TABLE2_NAMES[c], rsp_node=NODES[c],
            rsp_dir=direction(c, drive), ref_ent_name=TABLE2_NAMES[ref], ref_node=NODES[ref],
            ref_dir=direction(ref, drive), abscissa_spacing=1, abscissa_min=float(t[0]),
            abscissa_inc=float(step), abscissa_spec_data_type=TIME_TYPE,
            abscissa_axis_units_lab="s", ordinate_spec_data_type=ORDINATE[kind(c)],
            ordinate_len_unit_exp=length_exp, ordinate_force_unit_exp=force_exp,
            ordinate_axis_units_lab=DEFAULT_UNITS[kind(c)], orddenom_spec_data_type=0,
            orddenom_len_unit_exp=0, orddenom_force_unit_exp=0, orddenom_axis_units_lab="NONE",
            data=np.ascontiguousarray(column), x=t))
    _write_sets(path, sets)
    return path


def write_frf(path, table, responses, force: str = "force1", estimate: str = "H1",
              meta: dict | None = None, window: str = "") -> Path:
    """Write FRFs (:func:`workbench.lab.frf.frf`'s table, CGS ratios) as UFF
    dataset 58, function type 4, in SI: each response over the force.  ``window`` (the
    window and its damping correction, in words) goes into each record's ID line 2 (80
    characters) and, whole, into the header's description (dataset 151)."""
    path = Path(path)
    f = table.index.to_numpy(dtype=float)
    step = float(f[1] - f[0])
    settings = _setting_lines(meta, 2 * len(responses), path)
    now = f"{_dt.datetime.now():%d-%b-%y %H:%M:%S}"
    drive = (meta or {}).get("drive")
    sets = _header_sets(path, _parameters(meta), drive)
    if window:
        sets[0]["description"] = f"window: {window}"[:80]
    f_unit = DEFAULT_UNITS["force"]
    for i, r in enumerate(responses):
        k = kind(r)
        to_si = 1.0 / _si_factor(k) * _si_factor("force")       # (CGS response / dyn) -> SI / N
        length_exp, force_exp = EXPONENTS[k]
        sets.append(_record_58(
            id1=f"{TABLE2_NAMES[r]}/{TABLE2_NAMES[force]} {estimate}",
            id2=f"workbench FRF; {window}"[:80] if window else "workbench FRF",
            id3=now, id4=settings[2 * i], id5=settings[2 * i + 1], func_type=4,
            rsp_ent_name=TABLE2_NAMES[r], rsp_node=NODES[r], rsp_dir=DIRECTIONS[k],
            ref_ent_name=TABLE2_NAMES[force], ref_node=NODES[force], ref_dir=direction(force, drive),
            abscissa_spacing=1, abscissa_min=float(f[0]), abscissa_inc=step,
            abscissa_spec_data_type=FREQUENCY_TYPE, abscissa_axis_units_lab="Hz",
            ordinate_spec_data_type=ORDINATE[k], ordinate_len_unit_exp=length_exp,
            ordinate_force_unit_exp=force_exp, ordinate_axis_units_lab=DEFAULT_UNITS[k],
            orddenom_spec_data_type=ORDINATE["force"], orddenom_len_unit_exp=0,
            orddenom_force_unit_exp=1, orddenom_axis_units_lab=f_unit,
            data=np.ascontiguousarray(table[f"{r}_{estimate}"].to_numpy() * to_si), x=f))
    _write_sets(path, sets)
    return path


def _si_factor(k: str) -> float:
    """CGS per unit of DEFAULT_UNITS of a kind of channel."""
    from ..channels import UNITS
    return UNITS[k][DEFAULT_UNITS[k]]


def _parameters(meta):
    """The rig's parameters as far as the settings give them (for the sensor positions)."""
    from ...model.params import ParameterError, Parameters, resolve_name

    model = {}
    for key, value in (meta or {}).items():
        try:
            resolve_name(key)
        except ParameterError:
            continue                          # a drive's setting
        model[key] = value
    try:
        return Parameters().replace(**model)
    except (ParameterError, TypeError, ValueError):
        return Parameters()


def _write_sets(path: Path, sets: list[dict]) -> None:
    import pyuff

    if path.exists():
        path.unlink()                         # pyuff appends to an existing file
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")
