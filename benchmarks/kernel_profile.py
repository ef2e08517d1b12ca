"""Where the kernels' time goes, by function and source line: perf samples of a run
mapped onto the machine code of the cached kernels.

numba's inlined helpers leave no symbols of their own, so the samples are
mapped through the debug line table of the kernels' object code: compile
the kernels once with debug information into a cache of their own (about
17 minutes), then record and report:

    export WORKBENCH_CACHE_ROOT=/tmp/dbgcache NUMBA_DEBUGINFO=1
    python benchmarks/kernel_profile.py run /tmp/kp          # first time: compiles
    perf record -F 5000 -o /tmp/kp/perf.data python benchmarks/kernel_profile.py run /tmp/kp
    python benchmarks/kernel_profile.py report /tmp/kp

``run`` simulates the 10 s sine four times (1.016 mm, 20 Hz, 200 N, cubic
cork; ``--no-tip`` takes the tip mass off) and writes into the folder the
load addresses of the kernels' functions (``symbols.txt``) and the object
code of ``run_hybrid`` with its callees (``run_hybrid.o``).  ``report``
prints the share of the kernels' samples by function and by line
(``addr2line``).  Line numbers are the source lines; numba's inlining keeps
the caller's file name, so a line number of an inlined helper (e.g. the
solves of ``dynamics.py``) is shown under the file of the function it was
inlined into.  Requires ``perf``, ``nm`` and ``addr2line``.
"""
import bisect
import collections
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

_OBJECTS = []           # (library, object code) of every kernel loaded from the cache


def _record_objects():
    from numba.core import codegen
    original = codegen.CPUCodeLibrary._set_compiled_object

    def record(self, value):
        _OBJECTS.append((self, value))
        return original(self, value)

    codegen.CPUCodeLibrary._set_compiled_object = record


def _symbols(obj_path):
    """(offset, size, name, strong) of the functions defined in an object file."""
    out = subprocess.run(["nm", "-S", "--defined-only", obj_path], capture_output=True,
                         text=True, check=True).stdout
    rows = []
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[2] in "tTwW":
            rows.append((int(parts[0], 16), int(parts[1], 16), parts[3], parts[2] == "T"))
    return rows


def run(folder, tip):
    if os.environ.get("NUMBA_DEBUGINFO") != "1" or "WORKBENCH_CACHE_ROOT" not in os.environ:
        sys.exit("set NUMBA_DEBUGINFO=1 and WORKBENCH_CACHE_ROOT (a cache of its own)")
    _record_objects()
    from workbench.model import excitation
    from workbench.model.params import Parameters
    from workbench.model.simulate import simulate
    p = Parameters(tip_mass=tip).replace(gap_mm=1.016)
    ex = excitation.sine(200.0, 20.0, ramp_s=1.0)
    simulate(p, ex, 0.1)
    if not _OBJECTS:
        sys.exit("the kernels were compiled, not loaded: run again to profile them")
    t = time.perf_counter()
    for _ in range(4):
        simulate(p, ex, 10.0)
    print(f"four 10 s runs: {time.perf_counter() - t:.2f} s", file=sys.stderr)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    lines = set()
    for lib, code in _OBJECTS:
        with tempfile.NamedTemporaryFile(suffix=".o", delete=False) as f:
            f.write(code)
        try:
            syms = _symbols(f.name)
        finally:
            os.unlink(f.name)
        base = None
        for off, _, name, strong in syms:  # a strong export places the object (a weak
            if not strong:                 # symbol may resolve to another copy)
                continue
            try:
                addr = lib.get_pointer_to_function(name)
            except Exception:
                addr = 0
            if addr:
                base = addr - off
                break
        if base is None:
            continue
        for off, size, name, _ in syms:
            lines.add(f"{base + off:x} {size:x} {off:x} {lib.name} {name}")
        if lib.name.endswith("run_hybrid"):
            (folder / "run_hybrid.o").write_bytes(code)
    (folder / "symbols.txt").write_text("\n".join(sorted(lines)) + "\n")


def _short(name):
    name = re.sub(r"\[abi:.*", "", name)
    name = re.sub(r"\(.*", "", name)
    return name.replace("workbench::core::", "")


def report(folder):
    folder = Path(folder)
    obj = str(folder / "run_hybrid.o")
    rows = []
    for line in (folder / "symbols.txt").read_text().splitlines():
        addr, size, off, lib, name = line.split()
        if lib.endswith("run_hybrid"):
            rows.append((int(addr, 16), int(size, 16), int(off, 16)))
    rows.sort()
    starts = [r[0] for r in rows]
    ips = subprocess.run(["perf", "script", "-i", str(folder / "perf.data"), "-F", "ip"],
                         capture_output=True, text=True, check=True).stdout.split()
    offsets = collections.Counter()
    for text in ips:
        ip = int(text, 16)
        i = bisect.bisect_right(starts, ip) - 1
        if i >= 0 and ip < rows[i][0] + rows[i][1]:
            offsets[rows[i][2] + ip - rows[i][0]] += 1
    total = sum(offsets.values())
    if not total:
        sys.exit("no samples in the kernels")
    by_function, by_line = collections.Counter(), collections.Counter()
    keys = sorted(offsets)
    out = subprocess.run(["addr2line", "-f", "-C", "-e", obj] + [hex(k) for k in keys],
                         capture_output=True, text=True, check=True).stdout.splitlines()
    for k, function, where in zip(keys, out[0::2], out[1::2]):
        function = _short(function)
        by_function[function] += offsets[k]
        by_line[f"{function}  {where.split('/')[-1]}"] += offsets[k]
    print(f"{total} samples in the kernels ({len(ips)} in all)\n\nby function:")
    for name, n in by_function.most_common(15):
        print(f"{100 * n / total:6.2f} %  {name}")
    print("\nby line:")
    for name, n in by_line.most_common(40):
        print(f"{100 * n / total:6.2f} %  {name}")


if __name__ == "__main__":
    if len(sys.argv) >= 3 and sys.argv[1] == "run":
        run(sys.argv[2], "--no-tip" not in sys.argv)
    elif len(sys.argv) == 3 and sys.argv[1] == "report":
        report(sys.argv[2])
    else:
        sys.exit(__doc__)
