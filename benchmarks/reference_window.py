"""The NumPy reference (the paper's method) on a sine window of ``make bench``, against the kernel.

    python benchmarks/reference_window.py sine-tip 1e-6 [1e-7 ...]

Runs the case's whole 10 s sine with the kernel to find the window (see
:func:`cases.window_start`), then the reference under LSODA at each
rtol over the 0.25 s window, and prints its wall time, events and errors
against the kernel on the same window at 2.5e-5 s (a quarter of the default
step: its own error is about 1e-6 of the tip's range).  A failure is
printed with its message; the next tolerance still runs.
"""
import sys
import time

import cases as sbs

KERNEL_DT = 2.5e-5


def main(argv):
    case = sbs.CASES[argv[0]]
    t0, y0, regime = sbs.window_start(sbs.full_run(case), case)
    kernel = sbs.kernel_window(case, t0, y0, regime, KERNEL_DT)
    print(f"{case.name}: window from t = {t0:g} s, regime {regime}; kernel at {KERNEL_DT:g} s: "
          f"{kernel.n_events} events", flush=True)
    for rtol in map(float, argv[1:]):
        start = time.perf_counter()
        try:
            ref = sbs.jet_window(case, t0, y0, regime, rtol)
        except (RuntimeError, ValueError) as exc:
            print(f"rtol {rtol:g}: failed after {time.perf_counter() - start:.0f} s: {exc}",
                  flush=True)
            continue
        err = ref.errors(kernel)
        print(f"rtol {rtol:g}: {ref.wall_s:.0f} s, {ref.n_events} events, tip error "
              f"{err['tip_error_rel']:.2g}, share error {err['share_error']:.2g}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
