"""A study of branches of periodic orbits instead of a grid of runs.

    [study]
    name = "branches"
    continuation = {parameter = "freq_hz", from = 10.0, to = 55.0}
    # optional keys of the table: periods = 1 (K, drive periods an orbit spans),
    # period_doubling = true (at each period doubling also trace the doubled branch),
    # compare = "stepped" (a stepped study whose steady states are set over the branches),
    # monodromy = "variational" (or "finite-difference")

    [excitation]
    drive = "sine"
    force_n = 200.0                  # the drive's other setting

    [fixed]
    tip_mass = true

    [axes]                           # one branch per combination (not the continued parameter)
    gap_mm = [0.508, 1.016]

Each branch (:func:`workbench.model.continuation.continue_branch`) is written to
``results/<name>/<label>/`` as ``workbench continue`` writes it (:mod:`workbench.present.branch`,
which also writes the study's report): ``branch.parquet`` after every orbit, the figure and
``report.md`` at its end.  ``summary.json`` marks it finished, so that a study run again
traces only the branches not finished with the same definition.  ``tracing.json`` records
each segment and doubled branch as it goes (TRACING): a study cut short and run again keeps
what is on disk and resumes each branch where it was, continuing the one that was running
from its last orbit (found again from the state its row holds).

A branch that ends before the range's end starts anew RESTART of the range beyond the
farthest value it reached (``<label>/from-<value>/``: a new segment, found by shooting there,
not continued from the last); where MAX_SEGMENTS do not reach the end, one branch is traced
from the end back towards them (``<label>/from-end/``).  The doubled branches of the first
MAX_DOUBLED changes of stability at -1 (smooth or nonsmooth) where the orbit loses it go to
``<label>/doubled-<value>/``.  ``results/<name>/branches.parquet`` holds every orbit of every
branch, ``report.md`` the study's account.

With ``compare``, each stepped point of that study (``results/<compare>/points.parquet``)
whose other axes match a branch's is set beside the branch at its frequency: the tip's line
at the drive frequency (``tip_h1``, which the first mode's slow ringing does not reach) of
the stepped run against that of the nearest orbit there (linear between the two orbits that
bracket the frequency on each of the branches' segments), and each value where the sweeps up
and down differ (HYSTERESIS: a jump) against the branch's nearest folds on either side.
"""
from __future__ import annotations

import json
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..model.limits import MONODROMY_METHODS
from ..model.params import ParameterError
from .store import StudyLock, logged_run, watch_sweep, write_atomic, write_text_atomic

#: The table's keys.
KEYS = {"parameter", "from", "to", "periods", "period_doubling", "compare", "monodromy"}
#: The continued parameters and their units.
PARAMETERS = {"freq_hz": "Hz", "force_n": "N"}
#: Up and down sweeps whose tip lines at one value differ by more than this fraction of the
#: larger found different responses there (hysteresis: a jump between there and a neighbour).
HYSTERESIS = 0.1
#: A branch that ends before the range's end (a fold back past its start, a step floor, no
#: orbit found at its start) is started anew this fraction of the range beyond the farthest
#: value it reached (a new segment: found by shooting there, not continued from the last),
#: at most MAX_SEGMENTS times.
RESTART = 0.01
MAX_SEGMENTS = 12
#: The doubled branches traced per branch: at the first MAX_DOUBLED changes of stability where
#: the orbit loses it by a multiplier leaving the unit circle at -1 (smooth or nonsmooth).
MAX_DOUBLED = 4
#: [study] keys of a grid's runs, which a continuation study does not take.
GRID_ONLY = ("duration_s", "window_s", "sweep", "save_series", "check_accuracy", "dt",
             "output_hz", "tol", "method", "initial")


@dataclass(frozen=True)
class Continuation:
    """The ``[study] continuation`` table: what is continued, over what, and how."""

    parameter: str
    start: float
    end: float
    periods: int = 1
    period_doubling: bool = False
    compare: str | None = None
    monodromy: str = "variational"


def parse(raw, head: dict, error=ParameterError) -> Continuation:
    """The table, checked (one-line errors naming the key, the value and what is allowed)."""
    if not isinstance(raw, dict):
        raise error("[study] continuation must be a table such as {parameter = \"freq_hz\", "
                    f"from = 10.0, to = 55.0}}, got {raw!r}")
    bad = sorted(set(raw) - KEYS)
    if bad:
        raise error(f"unknown key(s) {bad} in [study] continuation; allowed: {sorted(KEYS)}")
    grid = sorted(k for k in GRID_ONLY if k in head)
    if grid:
        raise error(f"[study] {grid[0]} sets a grid's runs; a study with continuation traces "
                    "branches of periodic orbits (no duration, window or sweep)")
    parameter = raw.get("parameter")
    if parameter not in PARAMETERS:
        raise error(f"[study] continuation parameter = {parameter!r}; allowed: "
                    f"{sorted(PARAMETERS)}")
    ends = []
    for key in ("from", "to"):
        v = raw.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) or v <= 0:
            raise error(f"[study] continuation {key} = {v!r} must be a positive number "
                        f"({PARAMETERS[parameter]})")
        ends.append(float(v))
    if ends[0] == ends[1]:
        raise error(f"[study] continuation from = to = {ends[0]:g}: the range is empty")
    if parameter == "force_n":
        from ..model.limits import MAX_FORCE_N
        if max(ends) > MAX_FORCE_N:
            raise error(f"[study] continuation {'from' if ends[0] > MAX_FORCE_N else 'to'} = "
                        f"{max(ends):g} N; allowed (0, {MAX_FORCE_N:g}] N")
    periods = raw.get("periods", 1)
    if isinstance(periods, bool) or not isinstance(periods, int) or not 1 <= periods <= 8:
        raise error(f"[study] continuation periods = {periods!r} must be a whole number in "
                    "[1, 8] (drive periods an orbit spans)")
    doubling = raw.get("period_doubling", False)
    if not isinstance(doubling, bool):
        raise error(f"[study] continuation period_doubling = {doubling!r} must be true or false")
    compare = raw.get("compare")
    if compare is not None and (not isinstance(compare, str) or not compare):
        raise error(f"[study] continuation compare = {compare!r} must name a study "
                    "(results/<compare>/points.parquet)")
    monodromy = raw.get("monodromy", "variational")
    if monodromy not in MONODROMY_METHODS:
        raise error(f"[study] continuation monodromy = {monodromy!r}; allowed: "
                    f"{', '.join(MONODROMY_METHODS)}")
    return Continuation(parameter, ends[0], ends[1], periods, doubling, compare, monodromy)


def label(point) -> str:
    """A branch's folder name: its axis values (``gap_mm-0.508``), or ``branch``."""
    if not point.values:
        return "branch"
    return "_".join(f"{k}-{v:g}" if isinstance(v, float) else f"{k}-{v}"
                    for k, v in point.values.items())


def run_branches(study, write, results: str | Path = "results", jobs: int = 2,
                 fresh: bool = False, progress: bool = True) -> pd.DataFrame:
    """Trace every unfinished branch of a continuation study (``jobs`` processes), each
    written by ``write(branch, folder, params)`` after every orbit
    (:func:`workbench.present.branch.write_branch`); write and return ``branches.parquet``
    (every orbit, with its branch's axis values and label)."""
    from joblib import Parallel, delayed
    out = Path(results).resolve() / study.name
    out.mkdir(parents=True, exist_ok=True)
    with StudyLock(out):
        todo = [p for p in study.points if fresh or not finished(study, p, out)]
        if todo:
            if progress:
                print(f"workbench: {study.name}: {len(todo)} of {study.n_points} branches to "
                      f"trace on {min(jobs, len(todo))} worker(s)", file=sys.stderr)
            with logged_run(out, {"branches_run": len(todo), "jobs": jobs}):
                Parallel(n_jobs=min(jobs, len(todo)))(
                    delayed(trace)(study, p, out / label(p), write, os.getpid(), fresh)
                    for p in todo)
        table = collect(study, out)
        write_atomic(table, out / "branches.parquet")
    return table


def definition(study, point) -> dict:
    """What a branch is traced from: a finished branch whose summary holds another is traced
    again."""
    from dataclasses import asdict
    return json.loads(json.dumps({"continuation": asdict(study.continuation),
                                  "values": point.values, "excitation": point.excitation,
                                  "fixed": study.fixed}, default=str))


def finished(study, point, out: Path) -> bool:
    """Whether the branch's folder holds a finished branch of this definition."""
    f = out / label(point) / "summary.json"
    try:
        return json.loads(f.read_text()).get("definition") == definition(study, point)
    except (OSError, ValueError):
        return False


def trace(study, point, folder: Path, write, sweep_pid: int | None = None,
          fresh: bool = False) -> dict:
    """One branch (and its doubled branches): written to ``folder``; its summary (status
    "failed" with the error where tracing raised: the other branches go on).  ``sweep_pid``:
    the study's process; a worker stops itself once that is gone (a killed study leaves no
    worker tracing).  ``fresh``: traced anew from its start, not resumed."""
    if sweep_pid is not None and sweep_pid != os.getpid():
        watch_sweep(sweep_pid)
    try:
        return _trace(study, point, folder, write, fresh)
    except Exception as exc:                           # noqa: BLE001 - kept in the summary
        summary = {"label": folder.name, "definition": definition(study, point),
                   "status": "failed", "message": f"{type(exc).__name__}: {exc}",
                   "orbits": 0, "wall_s": 0.0, "segments": [], "doubled": []}
        write_text_atomic(json.dumps(summary, indent=1), folder / "summary.json")
        return summary


#: A branch's folder records its tracing here: the definition, and each segment and doubled
#: branch as it starts (status "running") and as it ends (its account).  A study cut short
#: resumes from it: a branch still running is kept as "interrupted" and continued from its
#: last orbit on disk (in a folder ``resumed-<value>``).
TRACING = "tracing.json"


class _Record:
    """``folder/TRACING``, read back where its definition is the branch's (unless ``fresh``),
    else begun anew (and the folder's orbits of another definition, or of none, removed)."""

    def __init__(self, folder: Path, definition: dict, fresh: bool = False):
        self.path = folder / TRACING
        try:
            log = json.loads(self.path.read_text())
        except (OSError, ValueError):
            log = {}
        if fresh or log.get("definition") != definition:
            for old in folder.glob("**/branch.parquet"):
                old.unlink()
            log = {"definition": definition, "segments": [], "doubled": []}
        self.log = log

    def save(self):
        write_text_atomic(json.dumps(self.log, indent=1), self.path)


def _rows(sub: Path) -> pd.DataFrame:
    """The orbits on disk in a segment's folder (none where it has no ``branch.parquet``)."""
    try:
        return pd.read_parquet(sub / "branch.parquet")
    except (OSError, ValueError):
        return pd.DataFrame()


def _next_segment(segments: list, c: Continuation, folder: Path):
    """(folder, from, to) of the segment to trace after ``segments`` (module docstring), or
    None: the first from the range's start; after one that ends early, the next RESTART of
    the range beyond the farthest value it reached, MAX_SEGMENTS at most; then one from the
    range's end back towards them."""
    if not segments:
        return folder, c.start, c.end
    last = segments[-1]
    if last["status"] == "done" or any(e["folder"] == "from-end" for e in segments):
        return None
    direction = 1.0 if c.end > c.start else -1.0
    reached = last["start"] if last.get("range") is None else \
        last["range"][1 if direction > 0 else 0]
    start = reached + RESTART * abs(c.end - c.start) * direction
    if len(segments) < MAX_SEGMENTS and (start - c.end) * direction < 0:
        return folder / f"from-{start:.4g}", start, c.end
    if (c.end - reached) * direction > 0:
        return folder / "from-end", c.end, reached
    return None


def _trace(study, point, folder: Path, write, fresh: bool = False) -> dict:
    from ..model.continuation import continue_branch, continue_doubled, continue_from
    from ..model.orbit import Shooter
    c = study.continuation
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "summary.json").unlink(missing_ok=True)
    record = _Record(folder, definition(study, point), fresh)
    segments, doubled = record.log["segments"], record.log["doubled"]

    def shooter(periods=c.periods):
        return Shooter(point.params, point.excitation_array(), periods, (), c.parameter,
                       c.monodromy)

    def traced(entries, sub, start, end, run):
        """One segment or doubled branch traced into ``sub`` by ``run(on_orbit)``, its entry
        in ``entries`` recorded as it starts, after each orbit (its wall time and the value
        it is traced towards) and as it ends."""
        entry = {"folder": str(sub.relative_to(folder)), "start": start, "end": end,
                 "status": "running", "wall_s": 0.0}
        entries.append(entry)
        record.save()
        t0 = time.perf_counter()

        def on_orbit(branch):
            write(branch, sub, point.params)
            entry["wall_s"] = time.perf_counter() - t0
            if not np.isnan(branch.towards):
                entry["end"] = branch.towards
            record.save()
        entry.update(_account(run(on_orbit)), wall_s=time.perf_counter() - t0)
        record.save()

    def resumed(entries, doubled_branch=False):
        """The last of ``entries`` cut short while running: kept as interrupted, and
        continued from its last orbit on disk (traced again from its start where it has
        fewer than two)."""
        if not entries or entries[-1]["status"] != "running":
            return
        entry = entries[-1]
        rows = _rows(folder / entry["folder"])
        if len(rows) < 2 or "state" not in rows or entry["end"] is None:
            entries.pop()
            return
        entry.update(_rows_account(rows, c.parameter))
        row = rows.iloc[-1]
        value = float(row[c.parameter])
        sub = folder / f"resumed-{value:.6g}"
        traced(entries, sub, value, entry["end"],
               lambda on: continue_from(shooter(int(row["periods"])), rows, entry["start"],
                                        entry["end"], on, doubled=doubled_branch))

    resumed(segments)
    while (nxt := _next_segment(segments, c, folder)) is not None:
        sub, lo, hi = nxt
        traced(segments, sub, lo, hi, lambda on, lo=lo, hi=hi: continue_branch(
            shooter(), lo, hi, on_orbit=on))
    last = segments[-1]
    summary = {"label": folder.name, "definition": definition(study, point),
               "status": last["status"] if len(segments) == 1 else
               f"{last['status']} ({len(segments)} segments)",
               "message": last["message"], "segments": segments, "doubled": doubled}
    if c.period_doubling:
        at = [(rows, i) for rows in (_rows(folder / entry["folder"]) for entry in segments)
              for i in _doublings(rows)]
        resumed(doubled, doubled_branch=True)
        for rows, i in at[:MAX_DOUBLED]:
            value = float(rows[c.parameter].iloc[i])
            sub = folder / f"doubled-{value:.4g}"
            if any(d["folder"] == sub.name for d in doubled):
                continue
            traced(doubled, sub, value, None, lambda on, rows=rows, i=i: continue_doubled(
                *_parent(shooter(), rows, i), c.start, c.end, on_orbit=on))
        summary["doublings_not_traced"] = [float(rows[c.parameter].iloc[i])
                                           for rows, i in at[MAX_DOUBLED:]]
    summary["orbits"] = sum(x["orbits"] for x in segments)
    summary["wall_s"] = sum(x["wall_s"] for x in [*segments, *doubled])
    write_text_atomic(json.dumps(summary, indent=1), folder / "summary.json")
    return summary


def _doublings(rows: pd.DataFrame) -> list[int]:
    """The rows of a segment after each change of stability whose multiplier crossed the
    unit circle at -1, where the orbit is not stable (it loses stability there)."""
    if "multiplier_crossing" not in rows:
        return []
    return [i for i in range(len(rows)) if rows.multiplier_crossing.iloc[i] == "-1"
            and rows.stability.iloc[i] != "stable"]


def _parent(shooter, rows: pd.DataFrame, i: int):
    """(shooter, branch, 1): the two orbits of ``rows`` about the change of stability before
    row ``i``, found again from their states, as :func:`continue_doubled` takes them."""
    from ..model.continuation import Branch, found_again
    pair = [found_again(shooter, rows.iloc[j]) for j in (i - 1, i)]
    return shooter, Branch(shooter.parameter, orbits=pair), 1


def _column(table: pd.DataFrame, name: str, blank=""):
    """A column of a branch table, or blanks where the table predates it."""
    return table[name] if name in table else [blank] * len(table)


def _account(branch) -> dict:
    """A traced branch's end, orbits, the range of values they span, wall time and
    bifurcations, for the summary."""
    values = [v for v, _ in branch.orbits]
    return {"status": branch.status, "message": branch.message, "orbits": len(branch.orbits),
            "range": [min(values), max(values)] if values else None, "wall_s": branch.wall_s,
            "bifurcations": [b.entry(branch.orbits[b.index][0]) for b in branch.bifurcations]}


def _rows_account(rows: pd.DataFrame, parameter: str) -> dict:
    """The account of a branch cut short (status "interrupted") from its orbits on disk."""
    from ..model.continuation import Bifurcation
    marked = rows[rows.bifurcation != ""]
    values = rows[parameter]
    return {"status": "interrupted", "message": "cut short: the orbits on disk",
            "orbits": len(rows),
            "range": [float(values.min()), float(values.max())] if len(rows) else None,
            "bifurcations": [Bifurcation(0, k, c, events_changed=e, turns=bool(t)).entry(v)
                             for v, k, c, e, t in zip(
                                 marked[parameter], marked.bifurcation,
                                 _column(marked, "multiplier_crossing"),
                                 _column(marked, "events_changed"),
                                 _column(marked, "parameter_turns", False))]}


def collect(study, out: Path) -> pd.DataFrame:
    """Every orbit of every branch on disk, with the branch's axis values, ``branch`` (its
    folder) and ``periods``."""
    tables = []
    for p in study.points:
        for f in sorted((out / label(p)).glob("**/branch.parquet")):
            t = pd.read_parquet(f)
            if not len(t):
                continue
            for k, v in p.values.items():
                t.insert(0, f"axis_{k}", v)
            t.insert(0, "branch", str(f.parent.relative_to(out)))
            tables.append(t)
    return pd.concat(tables, ignore_index=True) if tables else pd.DataFrame()


def cut_short(point, table: pd.DataFrame, parameter: str) -> dict | None:
    """The summary of a branch whose tracing was cut short (no ``summary.json``) from the
    orbits on disk (``table``, :func:`collect`): its segments and doubled branches, status
    "interrupted", no wall times; None where it has no orbit on disk."""
    name = label(point)
    mine = table[(table.branch == name) | table.branch.str.startswith(name + "/")] \
        if len(table) else table
    if not len(mine):
        return None
    segments, doubled = [], []
    for branch, rows in mine.groupby("branch", sort=False):
        folder = "." if branch == name else branch[len(name) + 1:]
        entry = {"folder": folder, **_rows_account(rows, parameter), "wall_s": float("nan")}
        (doubled if folder.startswith("doubled-") else segments).append(entry)
    return {"label": name, "status": "interrupted", "message": "cut short",
            "segments": segments, "doubled": doubled, "interrupted": True,
            "orbits": sum(x["orbits"] for x in segments), "wall_s": float("nan")}


def orbits_at(table: pd.DataFrame, parameter: str, value: float,
              column: str = "tip_h1_cm") -> list[tuple[float, str]]:
    """The orbits at ``value`` of the parameter on every branch of ``table`` (told apart by
    its ``branch`` column, if any): (``column``, stability) on each segment between two
    orbits that bracket it, linear between them; the stability the two orbits' where they
    agree, "undetermined" where either's is, else "changes" (a bifurcation between)."""
    groups = table.groupby("branch", sort=False) if "branch" in table else [("", table)]
    found = []
    for _, part in groups:
        x = part[parameter].to_numpy(float)
        y = part[column].to_numpy(float)
        word = (part.stability.to_numpy() if "stability" in part else
                np.where(part.stable.to_numpy(bool), "stable", "unstable"))
        for i in range(len(x) - 1):
            lo, hi = sorted((x[i], x[i + 1]))
            if lo < value <= hi or (lo == value and i == 0):
                w = (value - x[i]) / (x[i + 1] - x[i])
                pair = {word[i], word[i + 1]}
                found.append((float(y[i] + w * (y[i + 1] - y[i])),
                              word[i] if len(pair) == 1 else
                              "undetermined" if "undetermined" in pair else "changes"))
        if len(x) == 1 and x[0] == value:
            found.append((float(y[0]), str(word[0])))
    return found


def stepped_beside(branch: pd.DataFrame, stepped: pd.DataFrame, parameter: str
                   ) -> pd.DataFrame:
    """Each stepped point beside the branch (module docstring): its tip line, the nearest
    orbit's there, whether that orbit is stable and its largest multiplier, their difference
    relative to the stepped one, the periods a run takes to settle onto a stable orbit
    (``orbit.SETTLE``), and the stepped run's own steadiness."""
    from ..model.orbit import settle_periods
    rows = []
    lo, hi = branch[parameter].min(), branch[parameter].max()
    for _, s in stepped.iterrows():
        value = float(s[f"axis_{parameter}"])
        if not lo <= value <= hi:
            continue
        there = orbits_at(branch, parameter, value)
        row = {parameter: value, "direction": s.direction, "stepped_tip_h1_cm": s.tip_h1,
               "stepped_steady": bool(s.steady), "stepped_steady_change": s.steady_change,
               "stepped_poincare_spread_cm": float(np.ptp(s.tip_poincare))
               if len(s.tip_poincare) else np.nan,
               "orbits_there": len(there),
               "stable_orbits_there": sum(st == "stable" for _, st in there)}
        if there:
            multipliers = [m for m, _ in orbits_at(branch, parameter, value, "max_multiplier")]
            k = min(range(len(there)), key=lambda j: abs(there[j][0] - s.tip_h1))
            (y, st), mu = there[k], multipliers[k]
            row.update(orbit_tip_h1_cm=y, orbit_stability=st, orbit_max_multiplier=mu,
                       difference_rel=abs(y - s.tip_h1) / max(abs(s.tip_h1), 1e-12),
                       settle_periods=(settle_periods(mu) if st == "stable" else np.nan))
        rows.append(row)
    return pd.DataFrame(rows)


def jumps_and_folds(beside: pd.DataFrame, branch: pd.DataFrame, parameter: str
                    ) -> list[dict]:
    """Each value where the stepped sweep up and the sweep down found different responses
    (tip lines apart by more than HYSTERESIS of the larger: a jump lies between there and a
    neighbouring step), with the nearest fold of the branch on either side and the stable
    orbits the branch has there: the folds bracket the jump when both exist."""
    turning = (branch.parameter_turns.to_numpy(bool) if "parameter_turns" in branch else
               (branch.bifurcation == "fold").to_numpy())
    folds = np.sort(branch.loc[turning, parameter].to_numpy(float))
    up = beside[beside.direction == "up"].set_index(parameter).stepped_tip_h1_cm
    down = beside[beside.direction == "down"].set_index(parameter).stepped_tip_h1_cm
    out = []
    for value in sorted(set(up.index) & set(down.index)):
        a, b = float(up[value]), float(down[value])
        if abs(a - b) <= HYSTERESIS * max(abs(a), abs(b)):
            continue
        below, above = folds[folds <= value], folds[folds >= value]
        there = orbits_at(branch, parameter, value)
        out.append({parameter: value, "up": a, "down": b,
                    "fold_below": float(below[-1]) if len(below) else None,
                    "fold_above": float(above[0]) if len(above) else None,
                    "stable_orbits": int(sum(st == "stable" for _, st in there))})
    return out
