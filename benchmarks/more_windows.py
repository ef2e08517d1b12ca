"""Five more 0.25 s windows, where the joint rocks hard, for ``accuracy_side_by_side``.

    python benchmarks/more_windows.py windows /tmp/hard.json [--set chatter]
    python benchmarks/more_windows.py measure /tmp/hard.json 1e-4 6.25e-5
    WORKBENCH_METHOD=ars343 PYTHONPATH=/path/to/patched/worktree \\
        python benchmarks/more_windows.py measure /tmp/hard.json 2.5e-4

The same windows, converged solution and errors as
``benchmarks/accuracy_side_by_side.py`` (its functions, with these cases):
the sine at 200 N and 45 Hz with and without the tip mass, at 200 N and
20 Hz in the 0.508 mm gap, at 100 N and 55 Hz without the tip mass, and at
50 N and 30 Hz with it; each window from a state clear of events after
5 s.  ``--set chatter`` (with either command) takes five windows around
the no-tip 100 N, 55 Hz one instead.  ``WORKBENCH_METHOD`` is read by the patched worktree's ``simulate``.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import accuracy_side_by_side as acc  # noqa: E402

from workbench.model.excitation import sine  # noqa: E402
from workbench.model.params import Parameters  # noqa: E402


def cases(which="hard") -> dict:
    """name -> (parameters, excitation, whole-run duration (s), window wanted from (s))."""
    base = Parameters().replace(gap_mm=1.016, cork="cubic")
    tip = base.replace(tip_mass=True)
    no_tip = base.replace(tip_mass=False)

    def drive(force_n, freq_hz):
        return sine(force_n, freq_hz, ramp_s=1.0)

    if which == "chatter":          # around the no-tip 100 N, 55 Hz window
        return {"no tip 50 N 55 Hz": (no_tip, drive(50.0, 55.0), 6.0, 5.0),
                "no tip 200 N 55 Hz": (no_tip, drive(200.0, 55.0), 6.0, 5.0),
                "no tip 100 N 45 Hz": (no_tip, drive(100.0, 45.0), 6.0, 5.0),
                "tip 100 N 55 Hz": (tip, drive(100.0, 55.0), 6.0, 5.0),
                "no tip 100 N 55 Hz, 0.508 mm": (no_tip.replace(gap_mm=0.508), drive(100.0, 55.0),
                                                 6.0, 5.0)}
    return {"tip 200 N 45 Hz": (tip, drive(200.0, 45.0), 6.0, 5.0),
            "no tip 200 N 45 Hz": (no_tip, drive(200.0, 45.0), 6.0, 5.0),
            "tip 200 N 0.508 mm": (tip.replace(gap_mm=0.508), drive(200.0, 20.0), 6.0, 5.0),
            "no tip 100 N 55 Hz": (no_tip, drive(100.0, 55.0), 6.0, 5.0),
            "tip 50 N 30 Hz": (tip, drive(50.0, 30.0), 6.0, 5.0)}


if __name__ == "__main__":
    args = sys.argv[1:]
    which = "hard"
    if "--set" in args:
        which = args[args.index("--set") + 1]
        del args[args.index("--set"):args.index("--set") + 2]
    acc.cases = lambda: cases(which)
    if args[0] == "windows":
        acc.save_windows(args[1])
    else:
        acc.measure(args[1], [float(a) for a in args[2:]])
