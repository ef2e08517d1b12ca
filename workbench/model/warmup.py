"""Compile the kernels ahead of the first run, independent entry points in parallel.

``workbench compile`` (run by ``make setup``) starts one process per group of
entry points, ``jobs`` at a time; each compiles its kernels into numba's
cache (or loads them, when they are there already), so that later runs only
load them.  The groups share their smallest kernels (the equations of
motion), which both compile: the wall time is that of the largest group.
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
import textwrap
import time

#: name -> Python code exercising the entry points of that group.
GROUPS = {
    "event loop (run_adaptive, run_hybrid)": """
        from workbench.model.drives import sine
        from workbench.model.params import Parameters
        from workbench.model.simulate import simulate
        for method in ("dopri5", "rk4"):
            simulate(Parameters(), sine(200.0, 20.0), duration=0.002, initial="paper",
                     method=method)
    """,
    "static start, modes, free flight, hammer": """
        import numpy as np
        from workbench.identify.cork import hammer_record
        from workbench.model import packing
        from workbench.model.freeflight import integrate
        from workbench.model.modes import natural_frequencies
        from workbench.model.params import Parameters
        from workbench.model.statics import static_equilibrium
        static_equilibrium(Parameters())
        natural_frequencies(Parameters())
        integrate(packing.build(Parameters(), fixed=packing.JOINT), np.zeros(18), 1e-3, 1e-4)
        hammer_record("linear", 1e6, 10.0, 10.0, duration=1e-3)
    """,
}


def compile_all(jobs: int = 2) -> list[tuple[str, float, str]]:
    """Compile (or load) every group's kernels in ``jobs`` processes at a time.

    Returns (group, wall seconds, error) per group in the order of GROUPS;
    the error is the last line a failed process wrote ("" when it passed).
    """
    pending = list(GROUPS.items())
    running, done = [], {}
    while pending or running:
        while pending and len(running) < max(1, jobs):
            name, code = pending.pop(0)
            err = tempfile.TemporaryFile("w+")
            proc = subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)],
                                    stdout=subprocess.DEVNULL, stderr=err, text=True)
            running.append((name, proc, err, time.perf_counter()))
        time.sleep(0.1)
        for entry in [e for e in running if e[1].poll() is not None]:
            name, proc, err, t0 = entry
            running.remove(entry)
            err.seek(0)
            lines = err.read().strip().splitlines() if proc.returncode else []
            err.close()
            done[name] = (time.perf_counter() - t0,
                          (lines[-1] if lines else f"exit status {proc.returncode}")
                          if proc.returncode else "")
    return [(name, *done[name]) for name in GROUPS]
