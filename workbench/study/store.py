"""A study's results folder: atomic writes, damaged files set aside, the run log, the lock, the
watchdog that stops a worker whose sweep has gone.

    results/<study>/points/<key>.parquet   one row per finished point
    results/<study>/runs.json              one entry per sweep invocation
    results/<study>/damaged/               files that could not be read, set aside
    results/<study>/.lock                  held while a sweep runs

Every file is written to a temporary name and renamed, so a reader sees
the old file or the new one, never half of one.  A file that cannot be read
(a disk fault, a copy cut short) is moved to ``damaged/`` with a time stamp
and reported; its point is computed again.  ``runs.json`` holds an entry
per invocation, written when it starts (``"state": "running"``) and
updated when it ends (``"done"``, ``"interrupted"`` or ``"failed"``), so
a sweep killed without warning is still on record.
"""
from __future__ import annotations

import contextlib
import json
import os
import sys
import time
from pathlib import Path

import pandas as pd

from ..model.params import ParameterError


def write_atomic(df: pd.DataFrame, path: Path) -> None:
    """``df`` to Parquet at ``path`` through a temporary file and a rename."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    df.to_parquet(tmp)
    os.replace(tmp, path)


def write_text_atomic(text: str, path: Path) -> None:
    """``text`` to ``path`` through a temporary file and a rename."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def set_aside(path: Path, reason: str) -> Path:
    """Move a damaged file to ``damaged/`` beside its folder's parent; report it on stderr."""
    folder = path.parent.parent / "damaged" if path.parent.name in ("points", "series") \
        else path.parent / "damaged"
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / f"{path.name}.{time.strftime('%Y%m%d-%H%M%S')}"
    os.replace(path, target)
    print(f"workbench: {path} could not be read ({reason}); moved to {target}, "
          "it will be computed again", file=sys.stderr)
    return target


def read_point(path: Path) -> pd.DataFrame | None:
    """A point file's row, or None if it is missing or damaged (then set aside)."""
    if not path.exists():
        return None
    try:
        table = pd.read_parquet(path)
        if len(table) != 1 or "status" not in table.columns:
            raise ValueError(f"{len(table)} rows, columns {list(table.columns)[:5]}...")
        return table
    except Exception as exc:          # noqa: BLE001 - any unreadable file is set aside
        set_aside(path, f"{type(exc).__name__}: {exc}"[:200])
        return None


def read_runs(out: Path) -> list:
    """The run log of a study folder ([] if none; a damaged log is set aside)."""
    path = out / "runs.json"
    if not path.exists():
        return []
    try:
        runs = json.loads(path.read_text())
        if not isinstance(runs, list):
            raise ValueError("not a list")
        return runs
    except (ValueError, UnicodeDecodeError) as exc:
        set_aside(path, f"{type(exc).__name__}: {exc}"[:200])
        return []


def log_run(out: Path, entry: dict) -> int:
    """Append an entry to runs.json; return its index (for :func:`update_run`).

    Called under the study's :class:`StudyLock`: an earlier entry still
    "running" belongs to a sweep whose process is gone (killed before it
    could close its entry), and is marked "interrupted".
    """
    runs = read_runs(out)
    for run in runs:
        if run.get("state") == "running":
            run.update(state="interrupted", note="its process ended without closing this entry")
    write_text_atomic(json.dumps(runs + [entry], indent=1) + "\n", out / "runs.json")
    return len(runs)


def update_run(out: Path, index: int, changes: dict) -> None:
    runs = read_runs(out)
    if 0 <= index < len(runs):
        runs[index].update(changes)
    else:
        runs.append(changes)
    write_text_atomic(json.dumps(runs, indent=1) + "\n", out / "runs.json")


@contextlib.contextmanager
def logged_run(out: Path, entry: dict):
    """An invocation on record in runs.json while its block runs: ``entry`` with its start
    and process, "running", then "done", "interrupted" or "failed" and its wall time."""
    t0 = time.perf_counter()
    index = log_run(out, {"started": time.strftime("%Y-%m-%dT%H:%M:%S%z"), **entry,
                          "pid": os.getpid(), "state": "running"})
    state = "failed"
    try:
        yield
        state = "done"
    except KeyboardInterrupt:
        state = "interrupted"
        raise
    finally:
        update_run(out, index, {"state": state, "wall_s": time.perf_counter() - t0})


class StudyLock:
    """An exclusive lock on a study folder while a sweep runs (released when the process ends).

    A second sweep of the same study is refused with a clear error, rather
    than computing the same points twice.
    """

    def __init__(self, out: Path):
        self.path = out / ".lock"
        self.handle = None

    def __enter__(self):
        import fcntl
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.handle = open(self.path, "a+")
        try:
            fcntl.flock(self.handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self.handle.seek(0)
            holder = self.handle.read().strip() or "another process"
            self.handle.close()
            raise ParameterError(f"{self.path.parent}: another sweep of this study is running "
                                 f"({holder}); wait for it or stop it") from None
        self.handle.seek(0)
        self.handle.truncate()
        self.handle.write(f"pid {os.getpid()} since {time.strftime('%Y-%m-%dT%H:%M:%S')}")
        self.handle.flush()
        return self

    def __exit__(self, *exc):
        import fcntl
        fcntl.flock(self.handle, fcntl.LOCK_UN)
        self.handle.close()
        return False


#: A worker whose sweep process is gone stops within this many seconds.
WATCHDOG_S = 1.0
_WATCHED: set = set()


def watch_sweep(pid: int) -> None:
    """In a worker: a daemon thread that ends the process once ``pid`` has gone."""
    if pid in _WATCHED:
        return
    _WATCHED.add(pid)
    import threading

    def watch():
        while True:
            time.sleep(WATCHDOG_S)
            try:
                os.kill(pid, 0)
            except ProcessLookupError:
                os._exit(1)
            except PermissionError:
                pass

    threading.Thread(target=watch, name="sweep-watchdog", daemon=True).start()
