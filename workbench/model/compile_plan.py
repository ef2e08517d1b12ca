"""Compile the kernels in parallel processes, each once, callees before callers.

The plan (``compile_plan.json`` beside this module) lists the kernels of the
standard workload (:data:`workbench.model.warmup.GROUPS`): each with its one
signature, the kernels it links (which must be compiled before it) and its
own compile time on one core (s).  :func:`compile_parallel` runs ``jobs``
workers, this process and ``jobs - 1`` helper processes: each takes the next
kernel whose callees are done, the longest chain of compile time above it
(itself and its callers up to the last) first, claims it with a file, compiles it into numba's cache and marks it
done; a callee another worker compiled it loads from the cache.  A kernel
the plan does not know, or a helper that fails, only costs time: whatever is
left compiles on first use as always.

``python -m workbench.model.compile_plan --write`` measures the standard
workload in a fresh process with an empty cache (each kernel compiled on
first use, ``WORKBENCH_COMPILE_JOBS=0``) and rewrites the plan;
``tests/core/test_compile.py`` fails when the kernels' signatures or links
no longer match it.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .params import ParameterError

PLAN_FILE = Path(__file__).with_name("compile_plan.json")
#: Environment variable: processes compiling at a run's first use (default:
#: the usable cores); 0 compiles each kernel on first use in the calling process.
JOBS_VARIABLE = "WORKBENCH_COMPILE_JOBS"
#: Seconds a worker waits before looking again for a kernel whose callees are done.
POLL_S = 0.02


def usable_cores() -> int:
    """The cores this process may run on (the default number of workers)."""
    return len(os.sched_getaffinity(0))


def jobs_from_environment() -> int:
    """Processes for a first-use compile: WORKBENCH_COMPILE_JOBS, or the usable cores."""
    text = os.environ.get(JOBS_VARIABLE, "").strip()
    if not text:
        return usable_cores()
    try:
        jobs = int(text)
        if jobs < 0:
            raise ValueError
    except ValueError:
        raise ParameterError(f"{JOBS_VARIABLE}={text!r}: expects a whole number of processes "
                         ">= 0 (0: compile on first use in the calling process)") from None
    return jobs


def load_plan() -> dict:
    """{"module.function": {"signature": [numba type names], "links": [...], "seconds": s}}."""
    return json.loads(PLAN_FILE.read_text())["kernels"]


def closure(plan: dict, roots) -> dict:
    """The plan's kernels reachable from ``roots`` (names) through their links."""
    out, todo = {}, [r for r in roots if r in plan]
    while todo:
        name = todo.pop()
        if name not in out:
            out[name] = plan[name]
            todo.extend(d for d in plan[name]["links"] if d in plan)
    return out


def chain_seconds(plan: dict) -> dict:
    """Per kernel, its compile time plus the longest chain of its callers' in ``plan`` (s).

    A caller compiles after its callees, so a kernel's chain is the least time
    from its start to the end of the plan; workers take the ready kernel with
    the longest chain first (list scheduling by highest level first).
    """
    callers = {name: [] for name in plan}
    for name, entry in plan.items():
        for callee in entry["links"]:
            if callee in callers:
                callers[callee].append(name)
    memo = {}

    def chain(name):
        if name not in memo:
            memo[name] = plan[name]["seconds"] + max((chain(c) for c in callers[name]),
                                                     default=0.0)
        return memo[name]
    return {name: chain(name) for name in plan}


def missing(plan: dict) -> list[str]:
    """The plan's kernels without an entry in numba's cache folder."""
    from ..core.compiler.cache import CACHE_DIR
    return [name for name in plan if not any(CACHE_DIR.glob(f"{name}-*.nbi"))]


def _compile(name: str, signature) -> None:
    import importlib
    module, function = name.rsplit(".", 1)
    kernel = getattr(importlib.import_module(f"workbench.core.{module}"), function)
    kernel.compile(tuple(eval_type(t) for t in signature))


def eval_type(text: str):
    """A numba type from its name in the plan (workbench.core.compiler.linking.type_name)."""
    import importlib
    import numba
    namespace = dict(vars(numba.types))
    for module in ("workbench",):
        namespace[module] = importlib.import_module(module)
    importlib.import_module("workbench.model.packing")      # named tuples of the kernels
    return eval(text, namespace)


def _claim(path: Path) -> bool:
    try:
        os.close(os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
        return True
    except FileExistsError:
        return False


def work(plan: dict, claims: Path, helpers=()) -> list[str]:
    """Compile the plan's kernels with the other workers sharing ``claims``.

    ``helpers`` (the main worker's helper processes): when all have ended
    and kernels they claimed are not done, this worker compiles them.
    Returns the errors met ("name: message").
    """
    chain = chain_seconds(plan)
    order = sorted(plan, key=lambda n: -chain[n])
    parent = os.getppid()
    errors = []
    while True:
        done = {p.name[:-len(".done")] for p in claims.glob("*.done")}
        pending = [n for n in order if n not in done]
        if not pending:
            return errors
        ready = [n for n in pending if all(d in done or d not in plan for d in plan[n]["links"])]
        took = next((n for n in ready if _claim(claims / f"{n}.claim")), None)
        if took is None:
            orphaned = helpers and all(h.poll() is not None for h in helpers)
            if orphaned and ready:
                took = ready[0]
            elif not helpers and os.getppid() != parent:     # the main worker is gone
                return errors
            else:
                time.sleep(POLL_S)
                continue
        try:
            _compile(took, plan[took]["signature"])
        except Exception as exc:                     # compiled on first use instead
            errors.append(f"{took}: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}")
        (claims / f"{took}.done").touch()


def compile_parallel(roots=None, jobs: int | None = None) -> list[str]:
    """Compile the plan's kernels reachable from ``roots`` (all when None) in ``jobs``
    workers (default: the usable cores).  Returns the errors met."""
    plan = load_plan()
    if roots is not None:
        plan = closure(plan, roots)
    jobs = max(1, jobs or usable_cores())
    claims = Path(tempfile.mkdtemp(prefix="workbench-compile-"))
    code = ("import json, sys; from pathlib import Path; "
            "from workbench.model.compile_plan import work; "
            "errors = work(json.loads(sys.argv[1]), Path(sys.argv[2])); "
            "print('\\n'.join(errors), file=sys.stderr)")
    helpers = [subprocess.Popen([sys.executable, "-c", code, json.dumps(plan), str(claims)],
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
               for _ in range(jobs - 1)]
    try:
        errors = work(plan, claims, helpers)
        for helper in helpers:
            _out, err = helper.communicate()
            errors.extend(line for line in err.splitlines() if line.strip())
    finally:
        for helper in helpers:
            if helper.poll() is None:
                helper.kill()
        shutil.rmtree(claims, ignore_errors=True)
    return errors


def measure() -> dict:
    """The standard workload in a fresh process with an empty cache: the plan."""
    from .warmup import GROUPS
    code = "\n".join(__import__("textwrap").dedent(c) for c in GROUPS.values()) + _RECORD
    with tempfile.TemporaryDirectory() as root:
        out = subprocess.run([sys.executable, "-c", _LISTEN + code], check=True, text=True,
                             capture_output=True,
                             env={**os.environ, "WORKBENCH_CACHE_ROOT": root, JOBS_VARIABLE: "0"})
    return json.loads(out.stdout.strip().splitlines()[-1])


#: Records each kernel's own compile time (s; its callees' excluded) from numba's events.
_LISTEN = """
import time
from collections import defaultdict
import numba.core.event as ev
_stack, _own = [], defaultdict(float)
class _Listener(ev.Listener):
    def on_start(self, event):
        d = event.data["dispatcher"]
        _stack.append([d.py_func.__module__.rsplit(".", 1)[-1] + "." + d.py_func.__name__,
                       time.perf_counter(), 0.0])
    def on_end(self, event):
        name, t0, inner = _stack.pop()
        total = time.perf_counter() - t0
        _own[name] += total - inner
        if _stack:
            _stack[-1][2] += total
ev.register("numba:compile", _Listener())
"""

#: Prints the kernels of this process: signature, links and own compile time.
_RECORD = """
import json
from workbench.core.compiler.linking import kernel_graph
print(json.dumps({name: dict(entry, seconds=round(_own.get(name, 0.0), 2))
                  for name, entry in kernel_graph().items()}))
"""


def main(argv=None) -> int:
    import argparse
    ap = argparse.ArgumentParser(prog="python -m workbench.model.compile_plan",
                                 description="Measure the standard workload's kernels and "
                                             "rewrite the compile plan.")
    ap.add_argument("--write", action="store_true", help=f"rewrite {PLAN_FILE.name}")
    args = ap.parse_args(argv)
    kernels = measure()
    rows = [f"  {json.dumps(name)}: {json.dumps(kernels[name])}" for name in sorted(kernels)]
    text = '{"kernels": {\n' + ",\n".join(rows) + "\n}}\n"
    if args.write:
        PLAN_FILE.write_text(text)
    else:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
