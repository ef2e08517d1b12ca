"""A fresh ``workbench run`` process of the 10 s case, in checkouts side by side.

    python benchmarks/fresh_side_by_side.py times 10 /tmp/old .    # alternate, 10 rounds each
    python benchmarks/fresh_side_by_side.py phases                 # where one process's time goes

``times``: each round starts one process per checkout, in turn, running

    python -m workbench run --gap-mm 1.016 --tip-mass on --cork cubic --freq-hz 20 --duration 10 --json

with the checkout's own ``.venv`` (its numba cache warm: run it once first)
and prints each checkout's median, least and largest wall time (s).  As on a
user's machine, Python writes its bytecode cache (an inherited
``PYTHONDONTWRITEBYTECODE`` is dropped).

``phases``: the same command in this process, with ``time.perf_counter``
marks around the imports, the model's check (the first kernel load, which
brings numba's registries), the static start, loading ``run_hybrid``, the run
and the summary.  The process entry point's collector settings
(``cli.entry``) are applied; its exit is not timed.  Run this copy with an
older checkout's interpreter to see that checkout's phases.
"""
from __future__ import annotations

import gc
import io
import os
import statistics
import subprocess
import sys
import time
from contextlib import redirect_stdout
from pathlib import Path

ARGS = ["run", "--gap-mm", "1.016", "--tip-mass", "on", "--cork", "cubic", "--freq-hz", "20",
        "--duration", "10", "--json"]


def times(rounds: int, checkouts: list[str]) -> None:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    walls: dict[str, list[float]] = {c: [] for c in checkouts}
    for _ in range(rounds):
        for c in checkouts:
            venv = Path(c) / ".venv" / "bin" / "python"
            python = str(venv) if venv.exists() else sys.executable
            start = time.perf_counter()
            subprocess.run([python, "-m", "workbench", *ARGS], cwd=c, env=env, check=True,
                           stdout=subprocess.DEVNULL)
            walls[c].append(time.perf_counter() - start)
    for c, w in walls.items():
        print(f"{c}: median {statistics.median(w):.3f} s, least {min(w):.3f}, "
              f"largest {max(w):.3f} ({len(w)} rounds)")


def phases() -> None:
    marks = [("start", time.perf_counter())]

    def mark(name):
        marks.append((name, time.perf_counter()))

    import numpy                                               # noqa: F401
    mark("import numpy")
    import numba                                               # noqa: F401
    mark("import numba")
    from workbench import cli
    from workbench.model import simulate as sim
    from workbench.model import statics                         # noqa: F401
    import workbench.experiments.files                         # noqa: F401
    import workbench.experiments.matching                      # noqa: F401
    mark("import workbench")
    if hasattr(cli, "GC_THRESHOLD"):                            # older checkouts: the default
        gc.set_threshold(cli.GC_THRESHOLD)

    def timed(owner, name, label, before="other Python"):
        inner = getattr(owner, name)

        def wrapper(*a, **k):
            mark(before)
            out = inner(*a, **k)
            mark(label)
            return out
        setattr(owner, name, wrapper)

    timed(cli, "check_model", "check the model (first kernel load: numba's registries)")
    timed(sim, "static_equilibrium", "static start")
    timed(sim, "compile_kernel", "load run_hybrid")
    timed(sim, "_assemble", "assemble the Run", before="run (the kernel)")
    timed(sim.Run, "summary", "summary")
    with redirect_stdout(io.StringIO()):
        cli.main(ARGS)
    mark("other Python")
    spent: dict[str, float] = {}
    for (_, t0), (label, t1) in zip(marks, marks[1:]):
        spent[label] = spent.get(label, 0.0) + t1 - t0
    for label, s in spent.items():
        print(f"{label:>58} {s:6.3f} s")
    total = "total (the interpreter's start and exit not included)"
    print(f"{total:>58} {marks[-1][1] - marks[0][1]:6.3f} s")


if __name__ == "__main__":
    if sys.argv[1:2] == ["times"]:
        times(int(sys.argv[2]), sys.argv[3:])
    elif sys.argv[1:2] == ["phases"]:
        phases()
    else:
        sys.exit(__doc__)
