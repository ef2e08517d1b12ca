"""Where a run's time goes inside the kernels: Linux perf's samples by kernel, grouped.

    python benchmarks/profile_kernels.py [--case sine-tip|sine-no-tip] [--duration 10]

A child process compiles (or loads) the kernels with a short run, then waits while
``perf record -p`` attaches to it and runs the case (the 10 s sine: 1.016 mm, 20 Hz,
200 N, cubic cork, 1 s ramp, with or without the tip mass, the default method).  At its
end it writes ``/tmp/perf-<pid>.map``, the address and size of every compiled function
of the process (numba's JIT engine lists the symbols it defined; each function is taken
to end where the next begins), through which ``perf report`` names the samples in the
kernels' machine code.  Prints each kernel's share of the samples in the kernels and
their sum by GROUPS; the samples outside them (Python, NumPy's filtering of the
records, the allocator) are counted apart.  Needs ``perf`` (linux-perf) and permission
to attach (``kernel.perf_event_paranoid`` <= 1, or root).
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: The kernels by what they do.  Inlined helpers count in their caller: ``rhs_regime`` holds
#: the mass matrix, the forces and the locked joint's blocks, ``pair_step`` the event
#: functions at its stages; fill_geometry serves both the right-hand side and the events.
GROUPS = {
    "right-hand side in the time loop (mass matrix, forces, the locked joint's blocks)":
        ("constrained.rhs_regime", "sin/cos (libm)"),
    "right-hand side elsewhere (free flight, the multipliers' contact forces)":
        ("dynamics.rhs", "dynamics.assemble_inertia", "constrained.add_contact_forces",
         "contact.fill_geometry"),
    "the pair's stage sums, estimate, dense output and the event functions at its stages":
        ("pair.pair_step", "pair.dense", "pair.prepare_dense"),
    "event functions elsewhere": ("event_functions.event_values",),
    "projection onto the regime's constraints":
        ("constrained.project", "constrained._project_rows", "constrained._project_gaps"),
    "samples (sensors, storage)": ("sensors.fill_signals", "hybrid.store", "adaptive._samples"),
}
CASES = {"sine-tip": True, "sine-no-tip": False}

CHILD = r"""
import os, sys, time
import workbench as wb
p = wb.Parameters().replace(gap_mm=1.016, tip_mass={tip}, cork="cubic")
ex = wb.sine(200.0, 20.0, ramp_s=1.0)
wb.simulate(p, ex, duration=0.05)
print("ready", flush=True)
while not os.path.exists({go!r}):
    time.sleep(0.05)
time.sleep(0.5)
t = time.perf_counter()
run = wb.simulate(p, ex, duration={duration})
print("wall", time.perf_counter() - t, run.summary()["n_events"], flush=True)
from numba.core.registry import cpu_target
engine = cpu_target.target_context.codegen()._engine
found = []
for name in getattr(engine, "_defined_symbols", ()):
    try:
        address = engine.get_function_address(name)
    except Exception:
        continue
    if address:
        found.append((address, name))
found.sort()
with open(f"/tmp/perf-{{os.getpid()}}.map", "w") as f:
    for i, (address, name) in enumerate(found):
        size = min(found[i + 1][0] - address if i + 1 < len(found) else 4096, 1 << 20)
        f.write(f"{{address:x}} {{size:x}} {{name}}\n")
"""


def kernel_name(symbol: str) -> str:
    """``module.function`` of a mangled name of workbench.core (``_ZN9workbench4core...``)."""
    rest = symbol[len("_ZN9workbench4core"):]
    parts = []
    while rest and rest[0].isdigit():
        n = int(re.match(r"\d+", rest).group())
        k = len(str(n))
        parts.append(rest[k:k + n])
        rest = rest[k + n:]
    return ".".join(parts)


def profile(tip: bool, duration: float) -> tuple[dict, float, float, str]:
    """({kernel: samples}, samples outside the kernels, the run's wall (s), its line)."""
    work = Path(tempfile.mkdtemp())
    go, data = work / "go", work / "perf.data"
    child = subprocess.Popen([sys.executable, "-c", CHILD.format(tip=tip, go=str(go),
                                                                   duration=duration)],
                             stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "ready"
    perf = subprocess.Popen(["perf", "record", "-F", "4000", "-p", str(child.pid), "-o",
                             str(data)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(0.3)
    go.touch()
    line = child.stdout.readline().strip()
    child.wait()
    perf.wait()
    report = subprocess.run(["perf", "report", "-i", str(data), "--no-children", "--sort", "sym",
                             "-F", "sample,sym", "--stdio"], capture_output=True, text=True).stdout
    kernels, outside = {}, 0.0
    for row in report.splitlines():
        m = re.match(r"\s*(\d+)\s+\[.\]\s+(\S+)", row)
        if not m:
            continue
        n, symbol = float(m.group(1)), m.group(2)
        if symbol.startswith("_ZN9workbench4core"):
            name = kernel_name(symbol)
            kernels[name] = kernels.get(name, 0.0) + n
        elif re.match(r"__(sin|cos|sincos)(_fma)?$", symbol):
            kernels["sin/cos (libm)"] = kernels.get("sin/cos (libm)", 0.0) + n
        else:
            outside += n
    os.unlink(f"/tmp/perf-{child.pid}.map")
    return kernels, outside, float(line.split()[1]), line


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", choices=sorted(CASES), default="sine-tip")
    ap.add_argument("--duration", type=float, default=10.0)
    args = ap.parse_args(argv)
    if shutil.which("perf") is None:
        raise SystemExit("profile_kernels.py needs Linux perf (Debian: linux-perf) on the PATH")
    kernels, outside, wall, line = profile(CASES[args.case], args.duration)
    total = sum(kernels.values())
    print(f"{args.case}, {args.duration:g} s: {line}; {total:.0f} samples in the kernels, "
          f"{outside:.0f} outside ({outside / (total + outside):.1%})")
    grouped = set()
    for group, names in GROUPS.items():
        n = sum(kernels.get(k, 0.0) for k in names)
        grouped.update(names)
        print(f"{n / total:6.1%}  {group}")
    rest = {k: v for k, v in kernels.items() if k not in grouped}
    print(f"{sum(rest.values()) / total:6.1%}  the rest (the controller, event location, "
          "events applied)")
    print("\nby kernel:")
    for name, n in sorted(kernels.items(), key=lambda kv: -kv[1])[:25]:
        print(f"{n / total:6.1%}  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
