"""Study definitions: a grid of simulations described once in a TOML file.

    [study]
    name = "shaker"                  # results go to results/<name>/
    duration_s = 10.0                # simulated time per point (s)
    window_s = 2.0                   # steady-state window at the end of each point (s)
    sweep = "independent"            # or "up", "down", "up-down" (stepped frequency sweeps)
    tol = 1e-4                       # optional tolerance of the controlled method (the default)
    method = "dop853"                # optional: "dop853", "dopri5" (controlled), or "rk4" (fixed dt)
    dt = 5e-5                        # optional step (s): rk4's fixed step (without tol), or the
                                     # controlled method's largest; default: step_policy.default_dt
    output_hz = 1000.0               # optional sample rate of the signals (Hz)
    check_accuracy = true            # optional: each point also run at a tenth of tol and half
                                     # the step (a quarter of a fixed dt), its error measured
                                     # against that companion (model/accuracy.py)
    save_series = [{gap_mm = 1.016, freq_hz = 20.0}]   # optional: points whose time series are kept
                                     # (each selector names axis values; {} selects every point)

    [excitation]
    drive = "sine"                   # a drive of model/drives.py: sine, chirp, free_decay, hammer_joint, hammer_tip, none
    force_n = 20.0
    ramp_s = 1.0                     # soft start (s)

    [limits]                         # optional: a response-limited drive (study/leveling.py): each
                                     # point's force the largest, up to force_n, keeping every
                                     # limit; each key optional (default), false switches one off
    accel_g = 50.0                   # accelerometers' range (g; PCB 352A24 datasheet)
    force_transducer_n = 2224.0      # force transducer's range (N; PCB 208C03 datasheet)
    tip_cm = 8.4                     # tip deflection (cm; seed §5.3)
    slot = true                      # the slide within the slot's travel (s_travel)
    resolution = 1.25                # the force found within this factor of the largest
    max_runs = 10                    # runs a point may take

    [wear]                           # optional: Archard's constants of the wear volume
    k_archard = 1e-4                 # (study/wear.py: unit, range, source of each)
    hardness_pa = 1e9

    [fixed]                          # any model parameter (workbench params), unit suffixes allowed
    mu_s = 0.3

    [axes]                           # the grid: any model or excitation parameter, lists of values
    gap_mm = [0.508, 1.016]
    freq_hz = [10.0, 20.0, 30.0]
    tip_mass = [true, false]

Every key is checked before anything runs (:func:`load`), and every grid
point's model parameters and excitation are built once, so a bad value is
reported with the parameter's allowed range, not halfway through a sweep.

A study with ``[limits]`` over a sine's frequency axis levels each chain of
frequencies (all other axes equal) in order, each point's search starting
from the force its lower neighbour used; only the force carries over, not
the state.

A ``continuation`` table in ``[study]`` traces branches of periodic orbits instead, one per
combination of ``[axes]`` (:mod:`workbench.study.branches` describes it).

A ``[sample]`` table with ``[ranges]`` instead of ``[axes]`` draws the points
from a Saltelli design for a global sensitivity study
(:mod:`workbench.study.sensitivity` describes both tables).

A stepped sweep (``sweep = "up"`` etc.) runs each frequency from the final
state of the previous one, all other axes equal; the soft start applies to
the first frequency only.  ``up-down`` runs the frequencies up and then down
again, so that hysteresis and jumps of the nonlinear response show.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..model import drives
from . import branches, sensitivity
from .leveling import Limits
from .wear import WearConstants, wear_constants
from ..model.limits import MAX_NAME_CHARS
from ..model.params import ParameterError, Parameters, check_positive, read_toml, resolve_name

SWEEP_MODES = ("independent", "up", "down", "up-down")
#: A continuation study's points are checked (the step against the drive) as runs of this
#: length (s); it runs no grid (:mod:`workbench.study.branches`).
CONTINUATION_CHECK_S = 1.0
STUDY_KEYS = {"name", "description", "duration_s", "window_s", "sweep", "dt", "output_hz", "tol",
              "method", "save_series", "initial", "check_accuracy", "continuation"}
LIMIT_KEYS = {"accel_g": "g", "force_transducer_n": "N", "tip_cm": "cm"}


class StudyError(ParameterError):
    """A study file that cannot run (names the file, the key and what is allowed)."""


@dataclass(frozen=True)
class Point:
    """One grid point: its axis values, the model parameters and the excitation settings."""

    values: dict            # axis name -> value (user units), in axis order
    params: Parameters
    excitation: dict        # the drive ("drive": its name) and its settings (user units)
    chain: int = 0          # stepped sweeps: the points of one chain share all but freq_hz
    step: int = 0           # position within the chain
    direction: str = ""     # "up" or "down" in a stepped sweep

    def excitation_array(self, first_in_chain: bool = True) -> np.ndarray:
        """The kernel's excitation array (the soft start only on a chain's first point)."""
        return drives.excitation_array(self.excitation, first_in_chain)

    @property
    def start_keywords(self) -> dict:
        """The keywords of simulate() that set the drive's start (a free decay's deflection)."""
        return drives.start_keywords(self.excitation)

    @property
    def drive_hz(self):
        """The forcing frequency (Hz) of a drive that has one (a sine), else None."""
        return drives.drive_hz(self.excitation)


@dataclass(frozen=True)
class Study:
    """A validated study definition (see the module docstring for the file format)."""

    name: str
    description: str
    duration_s: float
    window_s: float
    sweep: str
    dt: float | None
    output_hz: float
    initial: str
    excitation: dict
    fixed: dict
    axes: dict
    save_series: tuple = ()
    source: str = ""
    method: str = "dop853"
    tol: float | None = None
    limits: Limits | None = None
    wear: WearConstants = WearConstants()
    check_accuracy: bool = False
    sample: sensitivity.Sample | None = None
    continuation: branches.Continuation | None = None
    points: tuple = field(default=(), repr=False)

    @property
    def n_points(self) -> int:
        return len(self.points)

    def chains(self) -> list[list[Point]]:
        """Points grouped into the sequences that run one after another (stepped sweeps),
        or one point per group (independent)."""
        groups: dict[int, list[Point]] = {}
        for p in self.points:
            groups.setdefault(p.chain, []).append(p)
        return [sorted(g, key=lambda p: p.step) for g in groups.values()]

    @property
    def chained(self) -> bool:
        """Whether a point depends on the one before it in its chain (a stepped sweep's state,
        or a levelled chain's first estimate of the force)."""
        return any(p.step > 0 for p in self.points)

    def saves_series(self, point: Point) -> bool:
        return any(all(_same(point.values.get(k, point.excitation.get(k)), v)
                       for k, v in sel.items()) for sel in self.save_series)


def _same(a, b):
    if isinstance(a, float) or isinstance(b, float):
        try:
            return math.isclose(float(a), float(b), rel_tol=1e-12)
        except (TypeError, ValueError):
            return False
    return a == b


def load(path: str | Path) -> Study:
    """Read and validate a study file; raises StudyError naming what is wrong."""
    path = Path(path)
    data = read_toml(path, StudyError)
    try:
        return from_dict(data, source=str(path))
    except ParameterError as exc:
        raise StudyError(f"{path}: {exc}") from None


def from_dict(data: dict[str, Any], source: str = "") -> Study:
    """A Study from the parsed TOML tables (see the module docstring)."""
    tables = ("study", "excitation", "limits", "wear", "fixed", "axes", "sample", "ranges")
    unknown = sorted(set(data) - set(tables))
    if unknown:
        raise StudyError(f"unknown table(s) {unknown}: use [study], [excitation], [limits], "
                         "[wear], [fixed], [axes], or [sample] with [ranges]")
    for table in tables:
        if table in data and not isinstance(data[table], dict):
            raise StudyError(f"[{table}] must be a table of keys, got {_short(data[table])}")
    head = dict(data.get("study", {}))
    continuation = None
    if "continuation" in head:
        continuation = branches.parse(head.pop("continuation"), head, StudyError)
        head["duration_s"] = CONTINUATION_CHECK_S
    run = _run_settings(head)
    exc = dict(data.get("excitation", {"drive": "none"}))
    drive = exc.pop("drive", None)
    if not isinstance(drive, str) or drive not in drives.DRIVES:
        raise StudyError(f"[excitation] drive = {drive!r}; allowed: {sorted(drives.DRIVES)}")
    fixed = dict(data.get("fixed", {}))
    axes = dict(data.get("axes", {}))
    if continuation is not None:
        name = continuation.parameter
        if drive != "sine" or "sample" in data:
            raise StudyError("[study] continuation traces orbits of a sine drive over [axes]: "
                             f"got drive {drive!r}" + (" with [sample]" if "sample" in data
                                                       else ""))
        if name in axes or name in exc:
            raise StudyError(f"[{'axes' if name in axes else 'excitation'}] {name}: the "
                             "continued parameter's range is the continuation's from and to")
        exc[name] = continuation.start
    sample = None
    if "sample" in data or "ranges" in data:
        if axes:
            raise StudyError("a study has [axes] (a grid) or [sample] with [ranges] (a design), "
                             "not both")
        if "sample" not in data:
            raise StudyError("[ranges] needs a [sample] table (n, seed) to draw the design")
        if run["sweep"] != "independent":
            raise StudyError(f"[study] sweep = {run['sweep']!r} steps a grid's frequency axis; "
                             "a [sample] design runs independent points")
        sample = sensitivity.parse(data["sample"], data.get("ranges", {}), StudyError)
    _check_axes(axes)
    inputs = {} if sample is None else {k: None for k in [*sample.names, *sample.same]}
    _check_keys(drive, exc, fixed, axes, inputs)
    limits = _limits(data["limits"]) if "limits" in data else None
    try:
        wear = wear_constants(data.get("wear"))
    except ParameterError as exc:
        raise StudyError(str(exc)) from None
    if limits is not None and "force_n" not in drives.DRIVES[drive].keys:
        raise StudyError(f"[limits] sets each point's force: a {drive!r} excitation has no "
                         "force_n")
    frequency = drives.DRIVES[drive].frequency_key
    sweep = run["sweep"]
    if sweep != "independent" and (frequency is None or frequency not in axes):
        raise StudyError(f"[study] sweep = {sweep!r} steps the drive frequency: it needs a drive "
                         "with a forcing frequency (a sine) with that frequency in [axes]")
    points = _grid_points(drive, exc, fixed, axes, sample, inputs, run)
    if sweep != "independent":
        points = _frequency_chains(points, sweep)
    elif limits is not None and frequency is not None and frequency in axes:
        points = _frequency_chains(points, "up", direction="")
    else:
        points = [Point(p.values, p.params, p.excitation, chain=i) for i, p in enumerate(points)]
    series = _save_series(head.get("save_series", []), set(axes) | set(drives.DRIVES[drive].keys))
    return Study(**run, excitation={"drive": drive, **exc}, fixed=fixed, axes=axes,
                 save_series=series, source=source, points=tuple(points), limits=limits,
                 wear=wear, sample=sample, continuation=continuation)


def _run_settings(head: dict) -> dict:
    """The [study] table's run settings, checked: Study's name, description, duration_s,
    window_s, sweep, dt, output_hz, method, tol, check_accuracy and initial."""
    bad = sorted(set(head) - STUDY_KEYS)
    if bad:
        raise StudyError(f"unknown key(s) {bad} in [study]; allowed: {sorted(STUDY_KEYS)}")
    name = head.get("name")
    if not isinstance(name, str) or not name or not all(c.isalnum() or c in "-_" for c in name):
        raise StudyError(f"[study] name = {_short(name)} must be a non-empty word of letters, "
                         "digits, '-' and '_' (it names results/<name>/)")
    if len(name) > MAX_NAME_CHARS:
        raise StudyError(f"[study] name is {len(name)} characters long; at most {MAX_NAME_CHARS} "
                         "(it names a folder)")
    if not isinstance(head.get("description", ""), str):
        raise StudyError(f"[study] description must be a string, got {_short(head['description'])}")
    duration = check_positive("[study] duration_s", head.get("duration_s"), "s")
    window = check_positive("[study] window_s", head.get("window_s", min(2.0, duration / 2)), "s")
    if window > duration / 2:
        raise StudyError(f"[study] window_s = {window} s must be at most half of duration_s = "
                         f"{duration} s (two windows give the steady-state indicator)")
    sweep = head.get("sweep", "independent")
    if sweep not in SWEEP_MODES:
        raise StudyError(f"[study] sweep = {sweep!r}; allowed: {list(SWEEP_MODES)}")
    dt = head.get("dt")
    if dt is not None:
        dt = check_positive("[study] dt", dt, "s")
    output_hz = check_positive("[study] output_hz", head.get("output_hz", 1000.0), "Hz")
    from ..model.run_settings import check_method
    tol = head.get("tol")
    if tol is not None and (isinstance(tol, bool) or not isinstance(tol, (int, float))):
        raise StudyError(f"[study] tol = {_short(tol)} must be a number")
    method, tol = check_method(head.get("method"), tol, dt_given=dt is not None,
                               names={"method": "[study] method", "tol": "[study] tol"})
    if abs(duration * output_hz - round(duration * output_hz)) > 1e-9 * duration * output_hz:
        raise StudyError(f"[study] duration_s = {duration} s must be a whole number of samples "
                         f"at output_hz = {output_hz} Hz (the last sample is the final state)")
    check_accuracy = head.get("check_accuracy", False)
    if not isinstance(check_accuracy, bool):
        raise StudyError(f"[study] check_accuracy = {_short(check_accuracy)} must be true or false")
    if check_accuracy and tol is not None:
        from ..model.accuracy import companion_settings
        companion_settings(True, tol, 0.0, name="[study] tol")
    initial = head.get("initial", "static")
    if initial not in ("static", "paper"):
        raise StudyError(f"[study] initial = {initial!r}; allowed: 'static', 'paper'")

    return {"name": name, "description": str(head.get("description", "")),
            "duration_s": duration, "window_s": window, "sweep": sweep, "dt": dt,
            "output_hz": output_hz, "method": method, "tol": tol,
            "check_accuracy": check_accuracy, "initial": initial}


def _check_axes(axes: dict) -> None:
    """Each axis a non-empty list of distinct numbers, booleans or strings."""
    for key, values in axes.items():
        if not isinstance(values, list) or not values:
            raise StudyError(f"[axes] {key} must be a non-empty list of values, got {_short(values)}")
        for v in values:
            if not isinstance(v, (bool, int, float, str)):
                raise StudyError(f"[axes] {key}: each value must be a number, true/false or a "
                                 f"string, got {_short(v)}")
        if len(set(map(_value_key, values))) != len(values):
            raise StudyError(f"[axes] {key} lists a value twice: {_short(values)}")


def _check_keys(drive: str, exc: dict, fixed: dict, axes: dict, inputs: dict) -> None:
    """Every key of [excitation], [fixed], [axes] and [ranges] a setting of the drive or a
    model parameter, given once, and every setting the drive needs given."""
    allowed_exc = set(drives.DRIVES[drive].keys)
    for key, value in list(exc.items()) + list(fixed.items()):
        if not isinstance(value, (bool, int, float, str)):
            table = "excitation" if key in exc else "fixed"
            raise StudyError(f"[{table}] {key} must be a number, true/false or a string, "
                             f"got {_short(value)}")
    for table, keys in (("excitation", exc), ("axes", axes), ("fixed", fixed),
                        ("ranges", inputs)):
        for key in keys:
            if key in allowed_exc:
                if table == "fixed":
                    raise StudyError(f"[fixed] {key} is an excitation setting: put it in "
                                     "[excitation] or [axes]")
                continue
            if key in drives.all_keys():
                raise StudyError(f"[{table}] {key} does not apply to a {drive!r} excitation "
                                 f"(its settings: {sorted(allowed_exc)})")
            if table == "excitation":
                raise StudyError(f"[excitation] unknown key {key!r}; a {drive!r} excitation "
                                 f"takes {sorted(allowed_exc)}")
            resolve_name(key)                      # raises, with a suggestion, if unknown
    both = sorted((set(axes) | set(inputs)) & (set(fixed) | set(exc)))
    if both:
        raise StudyError(f"{both} given both as an axis and as a fixed value")
    missing = sorted(k for k in allowed_exc - set(exc) - set(axes) - set(inputs)
                     if drives.DRIVES[drive].default(k) is None)
    if missing:
        raise StudyError(f"a {drive!r} excitation needs {missing} in [excitation] or [axes]")


def _grid_points(drive, exc, fixed, axes, sample, inputs, run) -> list[Point]:
    """The grid's (or the design's) points, each checked against what its step resolves."""
    duration, dt, output_hz = run["duration_s"], run["dt"], run["output_hz"]
    allowed_exc = set(drives.DRIVES[drive].keys)
    where = {"duration": "[study] duration_s", "dt": "[study] dt", "output_hz": "[study] output_hz"}
    for k in allowed_exc:
        where[k] = f"[{'axes' if k in axes else 'ranges' if k in inputs else 'excitation'}] {k}"
    points = []
    for values, factors in _combinations(axes, sample):
        try:
            model_values = {**fixed, **{k: v for k, v in values.items() if k not in allowed_exc}}
            settings = {"drive": drive}
            for k in drives.DRIVES[drive].keys:
                settings[k] = values.get(k, exc.get(k, drives.DRIVES[drive].default(k, duration)))
            for k, factor in factors.items():      # a factor of the point's own value
                if k in allowed_exc:
                    settings[k] = values[k] = factor * settings[k]
                else:
                    base = own_value(Parameters.from_user(model_values), k)
                    model_values[k] = values[k] = factor * base
            params = Parameters.from_user(model_values)
            pt = Point(values=values, params=params, excitation=settings)
            _check_point(pt, duration, dt, output_hz, where)
        except StudyError:
            raise
        except ParameterError as exc_:
            at = f" (at {_short(values)})" if values else ""
            raise StudyError(f"{exc_}{at}") from None
        points.append(pt)
    return points


def _save_series(raw, selectable: set) -> tuple:
    """[study] save_series: selectors of points by axis (or drive setting) values."""
    if not isinstance(raw, list) or not all(isinstance(sel, dict) for sel in raw):
        raise StudyError("[study] save_series must be a list of tables such as "
                         f"[{{gap_mm = 1.016}}], got {_short(raw)}")
    series = tuple(dict(s) for s in raw)
    for sel in series:
        bad = sorted(set(sel) - selectable)
        if bad:
            raise StudyError(f"[study] save_series selects by {bad}, which are not axes")
    return series


def _combinations(axes: dict, sample) -> list[tuple[dict, dict]]:
    """Each point's (values, factors): the grid's combinations of the axes in order, or the
    design's rows in order ([sample]; factors of "times" inputs, "same" inputs copied)."""
    if sample is None:
        names = list(axes)
        return [(dict(zip(names, combo)), {}) for combo in itertools.product(*axes.values())]
    out = []
    for row in sample.design_matrix():
        values, factors = sample.values(row)
        for target, source in sample.same.items():
            (factors if source in factors else values)[target] = (
                factors[source] if source in factors else values[source])
        out.append((values, factors))
    return out


def own_value(params: Parameters, name: str) -> float:
    """A model parameter's value at ``params`` in the unit ``name`` carries: its field, or for a
    cork coefficient left to the law (None), the law's value."""
    field_name, to_cgs = resolve_name(name)
    value = getattr(params, field_name)
    if value is None and field_name in ("cork_n", "cork_k", "cork_c"):
        value = getattr(params.cork_law, field_name[len("cork_"):])
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        raise StudyError(f"[ranges] {name}: a factor needs a numeric parameter, got {value!r}")
    return float(value) / to_cgs


def _short(value) -> str:
    """repr of a value, cut to 60 characters for a one-line message."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _value_key(value):
    """Axis values equal as numbers are the same value (1 and 1.0)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        try:
            return ("number", float(value))
        except OverflowError:
            return ("number", str(value))
    return (type(value).__name__, value)


def _check_point(point: Point, duration, dt, output_hz, where) -> None:
    """A point's excitation values, and its run settings against what the step resolves."""
    from ..model.run_settings import check_settings
    ex = point.excitation_array()                  # validates the excitation values
    drives.start_keywords(point.excitation, where)
    check_settings(point.params, ex, duration, dt, output_hz, names=where)


def _limits(table: dict) -> Limits:
    """The ``[limits]`` table as :class:`~workbench.study.leveling.Limits` (one-line errors)."""
    bad = sorted(set(table) - set(LIMIT_KEYS) - {"slot", "resolution", "max_runs"})
    if bad:
        raise StudyError(f"unknown key(s) {bad} in [limits]; allowed: "
                         f"{sorted([*LIMIT_KEYS, 'slot', 'resolution', 'max_runs'])}")
    values = {}
    for key, unit in LIMIT_KEYS.items():
        if key in table:
            value = table[key]
            values[key] = None if value is False else check_positive(f"[limits] {key}", value, unit)
    if "slot" in table:
        if not isinstance(table["slot"], bool):
            raise StudyError(f"[limits] slot = {_short(table['slot'])} must be true or false")
        values["slot"] = table["slot"]
    if "resolution" in table:
        r = table["resolution"]
        if isinstance(r, bool) or not isinstance(r, (int, float)) or not 1.01 <= r <= 4.0:
            raise StudyError(f"[limits] resolution = {_short(r)} must be a number in [1.01, 4] "
                             "(the largest force is found within this factor)")
        values["resolution"] = float(r)
    if "max_runs" in table:
        n = table["max_runs"]
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= 50:
            raise StudyError(f"[limits] max_runs = {_short(n)} must be a whole number in [1, 50]")
        values["max_runs"] = n
    return Limits(**values)


def _frequency_chains(points, sweep, direction=None):
    """Chains of equal non-frequency values, ordered by frequency (up, down or both); the
    points' ``direction`` is the sweep's, or ``direction`` if given."""
    chains: dict[tuple, list[Point]] = {}
    for p in points:
        key = tuple((k, repr(v)) for k, v in p.values.items() if k != "freq_hz")
        chains.setdefault(key, []).append(p)
    out = []
    for c, members in enumerate(chains.values()):
        up = sorted(members, key=lambda p: p.values["freq_hz"])
        order = {"up": [(p, "up") for p in up],
                 "down": [(p, "down") for p in reversed(up)],
                 "up-down": [(p, "up") for p in up] + [(p, "down") for p in reversed(up[:-1])]}[sweep]
        for step, (p, way) in enumerate(order):
            out.append(Point(p.values, p.params, p.excitation, chain=c, step=step,
                             direction=way if direction is None else direction))
    return out
