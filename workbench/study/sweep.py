"""Run a study's grid in parallel, resumably.

    results/<study>/points/<key>.parquet   one row per finished point, written atomically
    results/<study>/series/<key>.parquet   time series of the points the study names
    results/<study>/points.parquet         all rows of the study's current grid

``key`` hashes everything that determines a point: model parameters,
excitation, duration, step, output rate, start, steady-state window, the
key of the previous point of a stepped sweep, and the code version.  A
rerun skips every point whose file exists; an interrupted sweep (even
kill -9) loses at most the points in flight, because a file appears only
by an atomic rename once its point is done.  A point that fails (the
integration stops with a status, or Python raises) is recorded with its
reason, and the sweep goes on; a stepped sweep then restarts the next
frequency from the static equilibrium with the soft start.

Parallelism is joblib's (``jobs`` processes), or a Dask cluster through
joblib's dask backend (``scheduler="tcp://..."``).  Each chain of points
(one point, or one stepped frequency sweep) is one task; results do not
depend on the number of workers.
"""
from __future__ import annotations

import hashlib
import json
import os
import sys
import time
import traceback
from pathlib import Path

import numpy as np
import pandas as pd

from ..core import layout as ly
from .leveling import level
from .metrics import contact_checks, point_metrics
from .provenance import code_version
from ..model.drives import excitation_array
from ..model.methods import METHODS
from ..model.step_policy import default_dt
from ..model.simulate import simulate
from .store import StudyLock, logged_run, read_point, read_runs, watch_sweep, write_atomic
from .definition import Point, Study, load


#: Seconds a sweep spends before its first point: the workers' start, their imports and
#: the kernels loaded from the cache (2.9 s of the docs' 2-point example's 3.3 s, 2 workers).
WORKER_START_S = 3.0
#: The whole runs a levelled point costs: the default grid's 240 points took 1 501 CPU s
#: levelled (4.5 runs a point, those above a limit stopped there), 2.6 times the seconds
#: of one run a point (docs/performance.md, "A levelled grid").
LEVELLED_RUNS = 2.6
STATE_COLUMNS = [f"final_y{i}" for i in range(ly.N_STATE)]
#: The integrator's account kept in a point's row (Run.summary keys).
CONTROL_KEYS = ("steps", "steps_all", "rejected", "h_min", "h_max", "error_est_max",
                "error_over_tol_max", "global_error_est", "floor_count", "error_measured",
                "tip_error_measured", "share_error_measured", "event_error_measured")


def point_key(study: Study, point: Point, previous_key: str = "") -> str:
    """The hash (20 hex digits) naming a point's result file."""
    record = {
        "params": point.params.to_dict(), "excitation": point.excitation,
        "first_in_chain": point.step == 0, "duration_s": study.duration_s,
        "window_s": study.window_s, "dt": study.dt, "output_hz": study.output_hz,
        "method": study.method, "tol": study.tol, "initial": study.initial, "previous": previous_key, "code": code_version(),
        "limits": study.limits.to_dict() if study.limits else None,
        "wear": study.wear.key(), "check_accuracy": study.check_accuracy,
    }
    text = json.dumps(record, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:20]


def chain_keys(study: Study, chain: list[Point]) -> list[str]:
    keys, prev = [], ""
    for p in chain:
        prev = point_key(study, p, prev if study.chained else "")
        keys.append(prev)
    return keys


def _row(point, key, status, message, wall, metrics, run=None, continued=False):
    row = {"key": key, **{f"axis_{k}": v for k, v in point.values.items()},
           "chain": point.chain, "step": point.step, "direction": point.direction,
           "continued": continued, "status": status, "message": message, "wall_s": wall}
    row.update(metrics)
    if run is not None:
        row["simulated_s"] = run.simulated_s
        row["n_events"] = int((run.events.kind != "start").sum())
        row["n_impacts"] = int((run.events.kind == "impact").sum())
        row["max_penetration_cm"] = float(run.stats["max_penetration_cm"])
        row["max_drift_cm"] = float(run.stats["max_drift_cm"])
        row["max_correction_cm"] = float(run.stats["max_correction_cm"])
        row["t_max_penetration"] = float(run.stats["t_max_penetration"])
        row["energy_balance_rel"] = run.energy_balance_rel()
        row["method"] = run.method
        row["tol"] = run.tol
        row.update({key: run.control.get(key) for key in CONTROL_KEYS})
        row.update(contact_checks(run))
        row["static_tip_y"] = run.static_tip_y
        final = run.signals.iloc[-1]
        for i, c in enumerate(STATE_COLUMNS):
            row[c] = float(final.iloc[i])
    return row


def run_point(study: Study, point: Point, key: str, out: Path, initial=None,
              force_estimate: float | None = None) -> dict:
    """Simulate one point, write its row (and series), return the row.

    ``force_estimate`` (N): a levelled study's first force to try (the chain's previous
    point's), else its ``force_n``."""
    t0 = time.perf_counter()
    continued = initial is not None
    try:
        def simulate_at(force_n=None, check_accuracy=False, stop=None):
            settings = point.excitation if force_n is None else {**point.excitation,
                                                                  "force_n": force_n}
            return simulate(point.params, excitation_array(settings, first_in_chain=not continued),
                            study.duration_s, dt=study.dt, output_hz=study.output_hz,
                            method=study.method, tol=study.tol, check_accuracy=check_accuracy,
                            initial=initial if continued else study.initial, stop=stop,
                            **point.start_keywords)
        if study.limits is None:
            run = simulate_at(check_accuracy=study.check_accuracy)
            levelled = {}
        else:
            found = level(simulate_at, point.excitation["force_n"], study.limits, force_estimate)
            run, levelled = found.run, found.row()
            if study.check_accuracy and run.ok:      # the same run again, with its companion
                run = simulate_at(found.force_n, check_accuracy=True)
        metrics = ({**levelled, **point_metrics(run, study.window_s, point.drive_hz, study.wear)}
                   if run.ok else levelled)
        row = _row(point, key, "ok" if run.ok else "failed", run.message,
                   time.perf_counter() - t0, metrics, run, continued)
        if study.saves_series(point):
            write_atomic(run.signals, out / "series" / f"{key}.parquet")
            write_atomic(run.events.astype({"kind": str}), out / "series" / f"{key}.events.parquet")
    except Exception as exc:          # noqa: BLE001 - a failed point is data, the sweep goes on
        msg = f"{type(exc).__name__}: {exc}"
        row = _row(point, key, "error", msg, time.perf_counter() - t0, {},
                   continued=continued)
        row["traceback"] = traceback.format_exc(limit=5)
    write_atomic(pd.DataFrame([row]), out / "points" / f"{key}.parquet")
    return row


def run_chain(study: Study, chain: list[Point], keys: list[str], out: Path,
              sweep_pid: int | None = None) -> list[dict]:
    """Run a chain's points in order, skipping finished ones (their state carries on).

    ``sweep_pid``: the sweep's process; a worker on this machine stops
    itself when that process is gone (a killed sweep leaves no worker).
    """
    if sweep_pid is not None and sweep_pid != os.getpid():
        watch_sweep(sweep_pid)
    rows = []
    state = estimate = None
    for point, key in zip(chain, keys):
        found = read_point(out / "points" / f"{key}.parquet")
        if found is not None:
            row = found.iloc[0].to_dict()
        else:
            row = run_point(study, point, key, out, initial=state, force_estimate=estimate)
        rows.append(row)
        state = estimate = None
        if row.get("status") == "ok":
            if study.sweep != "independent":
                state = np.array([row[c] for c in STATE_COLUMNS])
            if study.limits is not None and row.get("level_met"):
                estimate = float(row["force_n_used"])
    return rows


def estimated_cost(study: Study, chain: list[Point]) -> float:
    """RK4 steps of a chain (a levelled point's runs counted as LEVELLED_RUNS whole runs):
    the longest chains start first, so that workers finish together."""
    runs = LEVELLED_RUNS if study.limits is not None else 1.0
    return runs * sum(study.duration_s / (study.dt or default_dt(p.params, p.excitation_array()))
                      for p in chain)


def _unfinished(study: Study, out: Path):
    chains = study.chains()
    keys = [chain_keys(study, c) for c in chains]
    todo = [(c, k) for c, k in zip(chains, keys)
            if not all(read_point(out / "points" / f"{key}.parquet") is not None for key in k)]
    return keys, todo


def plan(study: Study, results: str | Path = "results", fresh: bool = False,
         jobs: int = 2) -> dict:
    """What a sweep would do: points, how many are finished, the expected steps and wall time.

    The wall time uses the study's own past seconds per step (runs.json) if
    it has run before, else its method's ``seconds_per_step`` and WORKER_START_S; divided
    by the workers.
    """
    out = Path(results) / study.name
    if fresh:
        keys, todo = [chain_keys(study, c) for c in study.chains()], \
            [(c, chain_keys(study, c)) for c in study.chains()]
    else:
        keys, todo = _unfinished(study, out)
    steps = sum(estimated_cost(study, c) for c, _ in todo)
    per_step, basis = METHODS[study.method].seconds_per_step, "assumed"
    past = [r for r in read_runs(out) if r.get("state") == "done" and r.get("steps")]
    if past:
        per_step = sum(r["wall_s"] * r.get("jobs", 1) for r in past) / sum(r["steps"] for r in past)
        basis = "this study's earlier runs"
    n_todo = sum(len(c) for c, _ in todo)
    wall = steps * per_step / max(1, min(jobs, len(todo) or 1))
    if todo and basis == "assumed":
        wall += WORKER_START_S
    return {"study": study.name, "points": study.n_points, "to_run": n_todo,
            "finished": study.n_points - n_todo, "chains": len(keys), "steps": int(steps),
            "expected_wall_s": float(f"{wall:.3g}"),
            "seconds_per_step": per_step, "seconds_per_step_from": basis,
            "results": str(out)}


def sweep(study: Study | str | Path, results: str | Path = "results", jobs: int = 2,
          scheduler: str | None = None, fresh: bool = False, progress: bool = True) -> pd.DataFrame:
    """Run a study (a :class:`Study`, or the path of its TOML file) into ``results``.

    The Python form of ``workbench sweep`` without its report: every
    unfinished point is run (``jobs`` processes, or the Dask cluster at
    ``scheduler``), and the table of the study's points is returned (one
    row per point: its settings, status, metrics and the integrator's
    account; ``results/<name>/points.parquet``).
    """
    if not isinstance(study, Study):
        study = load(study)
    return run_study(study, results, jobs=jobs, scheduler=scheduler, fresh=fresh,
                     progress=progress)


def run_study(study: Study, results: str | Path = "results", jobs: int = 2,
              scheduler: str | None = None, fresh: bool = False, progress: bool = True) -> pd.DataFrame:
    """Run every unfinished point of the study; return (and write) points.parquet.

    The study folder is locked while the sweep runs; the invocation is
    logged in runs.json (running, then done / interrupted / failed).
    """
    out = Path(results).resolve() / study.name      # absolute: worker processes keep their own cwd
    out.mkdir(parents=True, exist_ok=True)
    with StudyLock(out):
        if fresh and (out / "points").exists():
            for f in (out / "points").glob("*.parquet"):
                f.unlink()
        for sub in ("points", "series"):
            (out / sub).mkdir(parents=True, exist_ok=True)
            for tmp in (out / sub).glob(".*.tmp"):         # leftovers of a killed run
                tmp.unlink(missing_ok=True)
        keys, todo = _unfinished(study, out)
        todo.sort(key=lambda item: -estimated_cost(study, item[0]))
        n_points = sum(len(c) for c, _ in todo)
        if todo:
            if progress:
                p = plan(study, results, jobs=jobs)
                print(f"workbench: {study.name}: {n_points} of {study.n_points} points to run, "
                      f"{p['steps']:.3g} steps, about {p['expected_wall_s']:.0f} s on {jobs} "
                      "worker(s)", file=sys.stderr)
            steps = sum(estimated_cost(study, c) for c, _ in todo)
            with logged_run(out, {"points_run": n_points, "steps": steps, "jobs": jobs,
                                  "scheduler": scheduler}):
                _execute(study, todo, out, jobs, scheduler, progress, n_points)
        rows = []
        for k in keys:
            for key in k:
                row = read_point(out / "points" / f"{key}.parquet")
                if row is not None:
                    rows.append(row)
        table = pd.concat(rows, ignore_index=True) if rows else pd.DataFrame()
        write_atomic(table, out / "points.parquet")
    return table


def _execute(study, todo, out, jobs, scheduler, progress, n_points):
    from joblib import Parallel, delayed, parallel_config

    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=n_points, unit="point", desc=study.name)
    sweep_pid = None if scheduler else os.getpid()
    tasks = (delayed(run_chain)(study, c, k, out, sweep_pid) for c, k in todo)
    try:
        if scheduler:
            from dask.distributed import Client     # optional: pip install '.[cluster]'
            client = Client(scheduler, timeout="10s")
            try:
                with parallel_config(backend="dask"):
                    for rows in Parallel(return_as="generator_unordered")(tasks):
                        if bar is not None:
                            bar.update(len(rows))
            finally:
                client.close()
        else:
            for rows in Parallel(n_jobs=jobs, return_as="generator_unordered")(tasks):
                if bar is not None:
                    bar.update(len(rows))
    finally:
        if bar is not None:
            bar.close()
