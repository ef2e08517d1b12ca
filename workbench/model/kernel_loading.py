"""Loading a run's kernels: compiled in parallel when numba's cache lacks them, the
seconds spent reported in the run's ``compile_s``."""
from __future__ import annotations

import sys
import time

from numba.core import event as numba_event


#: What the first compile of a run's kernels takes on this 2-core machine, from
#: an idle hour to a busy one (docs/compile.md), for the message.
COMPILE_NOTE = "15-45 s on 2 cores"

#: The kernels a run uses besides its method's event loop: the model's shape
#: table and stiffness (packing), the linear model's eigenvalues (the default
#: step) and the static start.
_RUN_KERNELS = ("shapes.fill_shape_row", "dynamics.fill_stiffness_damping",
                "dynamics.eval_inertia", "cork.cork_stiffness", "equilibrium.static_state",
                "equilibrium.newton_set")
_prepared: set = set()
#: Seconds compiled for a run kernel not yet reported in a run's ``compile_s``.
compile_unreported: dict = {}


class FirstUseClock(numba_event.Listener):
    """Seconds numba spends compiling kernels on their first use in this process,
    counted from numba's ``numba:compile`` events (a caller's compile includes
    its callees': nested compiles count once), until :meth:`take` reads them.

    With ``WORKBENCH_COMPILE_JOBS=0`` a run's kernels compile on first use,
    the static start's and the step's eigenvalues' before the event loop's,
    so a run's ``compile_s`` adds what this clock counted before it.
    """

    def __init__(self):
        self.depth, self.started, self.seconds = 0, 0.0, 0.0

    def on_start(self, event):
        if self.depth == 0:
            self.started = time.perf_counter()
        self.depth += 1

    def on_end(self, event):
        self.depth -= 1
        if self.depth == 0:
            self.seconds += time.perf_counter() - self.started

    def take(self) -> float:
        """The seconds counted since the last call (s)."""
        seconds, self.seconds = self.seconds, 0.0
        return seconds

    def register(self) -> "FirstUseClock":
        """Start counting."""
        numba_event.register("numba:compile", self)
        return self

    def unregister(self) -> None:
        numba_event.unregister("numba:compile", self)


#: Counts first-use compiles once a process runs with ``WORKBENCH_COMPILE_JOBS=0``.
first_use: list = []


def kernel_name(kernel) -> str:
    function = getattr(kernel, "py_func", kernel)      # plain Python under NUMBA_DISABLE_JIT
    return f"{function.__module__.rsplit('.', 1)[-1]}.{function.__name__}"


def prepare_kernels(kernel) -> None:
    """Before a process's first run of ``kernel``: when numba's cache lacks any of
    the run's kernels, compile them in parallel on the usable cores
    (:mod:`~workbench.model.compile_plan`), saying so on stderr first (with the
    compiler's workarounds off, :mod:`workbench.core.compiler`, on first use instead).  The
    first run of ``kernel`` reports the seconds in its ``compile_s``.
    """
    if not hasattr(kernel, "signatures") or kernel_name(kernel) in _prepared:
        return                                      # NUMBA_DISABLE_JIT, or done
    from . import compile_plan
    from ..core import compiler
    from ..core.compiler.cache import CACHE_DIR
    _prepared.add(kernel_name(kernel))
    roots = (kernel_name(kernel), *_RUN_KERNELS)
    jobs = compile_plan.jobs_from_environment() if compiler.active() else 0
    if jobs == 0:
        if not first_use:
            first_use.append(FirstUseClock().register())
        return
    if not compile_plan.missing(compile_plan.closure(compile_plan.load_plan(), roots)):
        return
    print(f"workbench: compiling the numba kernels ({COMPILE_NOTE}; once, then cached in "
          f"{CACHE_DIR})", file=sys.stderr, flush=True)
    t = time.perf_counter()
    compile_plan.compile_parallel(roots, jobs)
    compile_unreported[kernel_name(kernel)] = time.perf_counter() - t


def compile_kernel(kernel, args) -> float:
    """Compile a run kernel for these arguments' types, or load it from numba's cache.

    Returns the seconds spent (0 when already in this process).
    """
    import numba
    if not hasattr(kernel, "signatures") or kernel.signatures:   # NUMBA_DISABLE_JIT: plain Python
        return 0.0
    t = time.perf_counter()
    kernel.compile(tuple(numba.typeof(a) for a in args))
    return time.perf_counter() - t
