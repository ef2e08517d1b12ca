"""``workbench run``, ``modes``, ``params`` and ``compile``: one simulation, the
linear model's modes, the parameter table, the kernels' compile."""
from __future__ import annotations

import json
import math
import sys
import time

import numpy as np

from ..model.limits import (DEFAULT_TOL, MAX_DT, MAX_DURATION_S, MAX_FORCE_N, MAX_OUTPUT_HZ,
                            MIN_DT, MONODROMY_METHODS)
from ..model.params import ParameterError, describe
from ..model.shown_units import SI
from ..study.paths import check_output_dir, check_output_file
from .common import (EXIT_INTERNAL, EXIT_NOT_CONVERGED, EXIT_OK, EXIT_RUN_FAILED,
                     add_drive_options, add_joint_options, add_model_options, json_text, number,
                     parameters_of, shortcut_drive)


def _cmd_modes(args) -> int:
    from ..model.modes import damping_ratios
    p = parameters_of(args)
    about = args.about or ("static" if args.joint == "locked" else "undeformed")
    if about == "static" and args.joint != "locked":
        raise ParameterError("--about static needs --joint locked (a free joint rests on its "
                             "contacts at the static equilibrium); use --about undeformed")
    freqs, zeta = damping_ratios(p, args.joint, about)
    state = ("the static equilibrium under gravity" if about == "static"
             else "the undeformed state")
    if args.json:
        print(json_text({"frequencies_hz": [float(f) for f in freqs],
                         "damping_ratios": [None if np.isnan(z) else float(z) for z in zeta],
                         "joint": args.joint, "about": about, "linearised_about": state,
                         "tip_mass": p.tip_mass, "cork": p.cork}))
    else:
        print(f"Natural frequencies and damping ratios, joint {args.joint}, tip mass "
              f"{'on' if p.tip_mass else 'off'}, cork {p.cork} (linearised about {state}; a "
              "rigid-body mode has no damping ratio):")
        for i, (f, z) in enumerate(zip(freqs, zeta), 1):
            print(f"  mode {i}: {f:12.4f} Hz  zeta " + ("   -" if np.isnan(z) else f"{z:.5f}"))
    return EXIT_OK


def _cmd_compile(args) -> int:
    from ..core.compiler.cache import CACHE_DIR
    from ..model.compile_plan import compile_parallel, load_plan, usable_cores
    from ..model.warmup import compile_all
    jobs = args.jobs or usable_cores()
    print(f"workbench: compiling the numba kernels into {CACHE_DIR} ({jobs} processes)",
          file=sys.stderr, flush=True)
    t0 = time.perf_counter()
    from ..core import compiler
    errors = compile_parallel(None, jobs) if compiler.active() else []
    if compiler.active():
        print(f"  {len(load_plan())} kernels of the plan: {time.perf_counter() - t0:.0f} s")
    for error in errors:
        print(f"  FAILED: {error}")
    for name, seconds, error in compile_all(jobs):
        print(f"  {name}: {seconds:.0f} s" + (f" FAILED: {error}" if error else ""))
        if error:
            errors.append(error)
    print(f"  total wall time {time.perf_counter() - t0:.0f} s")
    return EXIT_INTERNAL if errors else EXIT_OK


def _run_drive(args) -> dict:
    """The complete drive settings of ``workbench run`` (amplitude and soft start filled)."""
    from ..model import drives
    drive = shortcut_drive(args) or {"drive": "none"}
    if args.drive is not None:
        for option, value in (("--force-n", args.force_n), ("--ramp-s", args.ramp_s)):
            if value is not None:
                raise ParameterError(f"{option} {value:g}: with --drive, give --drive-set "
                                     f"{option[2:].replace('-', '_')}=VALUE")
        return drive
    hammer = args.impulse is not None
    if args.force_n is not None and args.force_n < 0 and not hammer:
        raise ParameterError(f"--force-n {args.force_n:g}: a shaker amplitude must be >= 0 N "
                             "(a hammer's sign gives its direction)")
    if args.free_decay is not None and args.force_n is not None:
        raise ParameterError("--force-n does not apply to --free-decay (a release without drive)")
    name = drive.pop("drive")
    given = {**drive, "force_n": args.force_n, "ramp_s": args.ramp_s}
    return drives.complete(name, {k: v for k, v in given.items() if v is not None},
                           lambda key: f"the drive needs {key}", duration_s=args.duration)


#: The run options behind the names of :func:`workbench.model.run_settings.check_settings`.
RUN_OPTION_NAMES = {"duration": "--duration", "dt": "--dt", "output_hz": "--output-hz",
                    "method": "--method", "tol": "--tol",
                    "freq_hz": "--freq-hz", "f0_hz": "--chirp F0", "f1_hz": "--chirp F1",
                    "width_s": "--pulse-s", "t_hit_s": "--hit-s", "ramp_s": "--ramp-s",
                    "deflection_cm": "--free-decay"}


def _cmd_run(args) -> int:
    from ..lab import files
    from ..lab.matching import settings_of
    from ..model import drives
    from ..model.methods import METHODS
    from ..model.run_settings import check_method, check_settings
    from ..model.kernel_loading import prepare_kernels
    from ..model.simulate import simulate
    n_drives = sum(x is not None for x in (args.freq_hz, args.chirp, args.free_decay, args.impulse,
                                           args.drive))
    if n_drives > 1:
        raise ParameterError("choose one of --freq-hz, --chirp, --free-decay, --impulse, --drive")
    if args.drive_set and args.drive is None:
        raise ParameterError("--drive-set sets a --drive: give --drive KIND")
    names = dict(RUN_OPTION_NAMES)
    method, _tol = check_method(args.method, args.tol, dt_given=args.dt is not None, names=names)
    prepare_kernels(METHODS[method].kernel)     # checking the model and the step runs kernels
    p = parameters_of(args)
    drive = _run_drive(args)
    if args.drive is not None:
        names.update({key: f"--drive-set {key}" for key in drive if key != "drive"})
    ex = drives.excitation_array(drive)
    start = drives.start_keywords(drive, names)
    check_settings(p, ex, args.duration, args.dt, args.output_hz, names=names)
    if args.out:
        check_output_file("--out", args.out, files.SUFFIXES)
        meta = settings_of(drive, p)
        files.check_settings(args.out, meta)
    from ..model.packing import JOINT
    run = simulate(p, ex, args.duration, dt=args.dt, output_hz=args.output_hz,
                   method=args.method, tol=args.tol, initial=args.initial,
                   progress=not args.json and sys.stderr.isatty(),
                   check_accuracy=args.check_accuracy,
                   fixed=JOINT if args.joint == "locked" else (), **start)
    if args.out:
        if files.format_of(args.out) == "parquet":       # the whole run: every signal, events
            run.signals.attrs["meta"] = meta
            run.to_parquet(args.out)
        else:
            files.write(args.out, files.record_from_run(run), meta)
    from ..model.validity import exceeded_words
    from ..study.wear import run_wear
    summary = run.summary()
    if run.ok:
        summary["wear"] = run_wear(run, drive.get("ramp_s", 0.0), drive.get("freq_hz"))
    if summary["out_of_range"]:
        print(f"workbench: warning: the run left the range the model is validated for "
              f"({exceeded_words(summary, p)})", file=sys.stderr)
    if args.json:
        print(json_text(summary))
    else:
        print(human_summary(summary, args.out))
    return EXIT_OK if run.ok else EXIT_RUN_FAILED


#: The keys of a run's summary the human-readable output shows, with their units (a CGS unit of
#: :data:`~workbench.model.shown_units.SI` is shown in SI, the key without its unit suffix).
HUMAN_KEYS = (("status", ""), ("message", ""), ("simulated_s", "s"), ("wall_s", "s"),
              ("method", ""), ("tol", ""), ("steps", ""), ("rejected", ""),
              ("error_over_tol_max", "of the tolerance"), ("n_events", ""), ("n_impacts", ""),
              ("contact_time_share", ""), ("tip_disp_peak_cm", "cm"),
              ("slide_abs_max_cm", "cm"), ("accel_abs_max_g", "g"),
              ("energy_balance_rel", ""), ("out_of_range", ""))


def _plain(value) -> str:
    """A value as a reader writes it: numbers to 4 significant digits, dicts as k: v."""
    if isinstance(value, dict):
        return ", ".join(f"{k}: {_plain(v)}" for k, v in value.items())
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return str(value)
    try:
        number = float(value)
    except (TypeError, ValueError):
        return str(value)
    return f"{int(number)}" if number.is_integer() and abs(number) < 1e15 else f"{number:.4g}"


def human_summary(summary: dict, out=None) -> str:
    """The run's summary in a few lines of plain numbers (``--json`` gives every key), and
    the file written."""
    lines = []
    for key, unit in HUMAN_KEYS:
        if key in summary:
            value = summary[key]
            if key == "contact_time_share":
                value = {k: v for k, v in sorted(value.items(), key=lambda kv: -kv[1]) if v >= 0.01}
            name = key
            if unit in SI and SI[unit][0] != unit:
                name, (unit, factor) = key.removesuffix(f"_{unit}"), SI[unit]
                value = value * factor
            text = _plain(value) if value not in ("", None) else "-"
            lines.append(f"{name:>20}: {text}{' ' + unit if unit and text != '-' else ''}")
    wear = summary.get("wear")
    if wear:
        lines.append(f"{'wear per ' + wear['per']:>20}: "
                     f"{_plain(wear['wear_volume_cm3'] * SI['cm³'][1])} mm³ (Archard), friction "
                     f"{_plain(wear['friction_work_erg'] * SI['erg'][1])} mJ, impacts "
                     f"{_plain(wear['impact_energy_erg'] * SI['erg'][1])} mJ")
    if out:
        lines.append(f"{'wrote':>20}: {out}")
    return "\n".join(lines)


def _cmd_orbit(args) -> int:
    from ..model import drives
    from ..model.orbit import SETTLE, periodic_orbit
    from ..model.packing import JOINT
    p = parameters_of(args)
    orbit = periodic_orbit(p, drives.sine(args.force_n, args.freq_hz), periods=args.periods,
                           fixed=JOINT if args.joint == "locked" else (),
                           monodromy=args.monodromy)
    found = orbit.to_dict()
    if args.json:
        print(json_text({key: value for key, value in found.items() if key != "state"}))
    else:
        mu, settle = orbit.deciding(), orbit.settle_s()
        print("\n".join([
            f"{'status':>20}: {orbit.status} ({orbit.message})",
            f"{'period':>20}: {orbit.period_s:.6g} s ({orbit.periods} drive period(s))",
            f"{'residual':>20}: {orbit.residual:.3g} after {orbit.newton_iterations} Newton step(s)",
            f"{'largest |multiplier|':>20}: "
            + (f"{abs(mu[0]):.6g}" if len(mu) else "-")
            + ("" if orbit.stable is None else (" (stable)" if orbit.stable else " (unstable)"))
            + ("" if orbit.neutral is None else "; the stuck position's 1 left out"),
            f"{'contact code':>20}: {found['contact_code']} at phase 0; events per period: "
            + (", ".join(f"{k} {v:g}" for k, v in orbit.events_per_period.items() if v) or "none"),
            f"{'tip amplitude':>20}: {_plain(orbit.tip_amplitude_cm * SI['cm'][1])} mm",
            *([] if settle is None else [
                f"{'settles':>20}: to {SETTLE:g} of a disturbance in {settle:.3g} s "
                f"(slowest multiplier at {orbit.slowest_hz():.3g} Hz)"]),
            f"{'wall':>20}: {orbit.wall_s:.3g} s"]))
    return EXIT_OK if orbit.status == "ok" else EXIT_NOT_CONVERGED


def value_or_range(text: str):
    """A number, or FROM:TO (two different numbers; the continuation starts at FROM)."""
    import argparse
    parts = text.split(":")
    try:
        values = [float(v) for v in parts]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number or FROM:TO") from None
    if len(values) == 1:
        return values[0]
    if len(values) != 2 or values[0] == values[1] or not all(map(math.isfinite, values)):
        raise argparse.ArgumentTypeError(f"{text!r}: a range is FROM:TO, two different "
                                         "finite numbers")
    return tuple(values)


def _cmd_continue(args) -> int:
    from ..model import drives
    from ..model.continuation import branch_rows, continue_branch, continue_doubled, doublings
    from ..model.orbit import Shooter
    from ..model.packing import JOINT
    from ..present.branch import write_branch
    from .common import RESULTS
    ranges = [(name, v) for name, v in (("freq_hz", args.freq_hz), ("force_n", args.force_n))
              if isinstance(v, tuple)]
    if len(ranges) != 1:
        raise ParameterError("give one of --freq-hz and --force-n as a range FROM:TO (the other "
                             "a value)")
    parameter, (lo, hi) = ranges[0]
    option = "--" + parameter.replace("_", "-")
    if parameter == "freq_hz" and min(lo, hi) <= 0:
        raise ParameterError(f"{option} {lo:g}:{hi:g}: allowed (0, inf) Hz")
    if parameter == "force_n" and not (0 < min(lo, hi) and max(lo, hi) <= MAX_FORCE_N):
        raise ParameterError(f"{option} {lo:g}:{hi:g}: allowed (0, {MAX_FORCE_N:g}] N")
    p = parameters_of(args)
    freq = lo if parameter == "freq_hz" else args.freq_hz
    force = lo if parameter == "force_n" else args.force_n
    out = check_output_dir("--out", args.out or RESULTS / "continue" / f"{parameter}-{lo:g}-{hi:g}")
    shooter = Shooter(p, drives.sine(force, freq), args.periods,
                      JOINT if args.joint == "locked" else (), parameter, args.monodromy)
    branch = continue_branch(shooter, lo, hi, on_orbit=lambda b: write_branch(b, out, p))
    rows = branch_rows(branch)
    doubled = []
    for i in (doublings(branch) if args.period_doubling else []):
        sub = out / f"doubled-{rows[i][parameter]:.4g}"
        d = continue_doubled(shooter, branch, i, lo, hi,
                             on_orbit=lambda b, sub=sub: write_branch(b, sub, p))
        doubled.append({"at": rows[i][parameter], "status": d.status,
                        "message": d.message, "orbits": len(d.orbits), "out": str(sub)})
    summary = {"status": branch.status, "message": branch.message, "parameter": parameter,
               "range": [lo, hi], "orbits": len(rows),
               "stable": int(sum(r["stable"] for r in rows)),
               "bifurcations": [b.entry(rows[b.index][parameter]) for b in branch.bifurcations],
               "doubled": doubled, "wall_s": branch.wall_s, "out": str(out)}
    print(json_text(summary) if args.json else
          f"{branch.status}: {branch.message}; {len(rows)} orbits, {summary['stable']} stable, "
          f"{len(branch.bifurcations)} bifurcation(s); wrote {out}")
    return EXIT_OK if branch.status == "done" else EXIT_NOT_CONVERGED


def _cmd_params(args) -> int:
    p = parameters_of(args)
    rows = describe()
    for row in rows:
        row["value"] = getattr(p, row["name"])
    if args.json:
        print(json.dumps([{k: (str(v) if isinstance(v, float) and not math.isfinite(v) else v)
                          for k, v in row.items()} for row in rows], default=str, indent=1))
        return EXIT_OK
    print(f"{'name':<11} {'value':>12} {'unit':<18} {'allowed':<16} source")
    for r in rows:
        flag = "  ASSUMPTION" if r["assumption"] else ""
        value = "None" if r["value"] is None else (f"{r['value']:.6g}" if isinstance(r["value"], float)
                                                  else str(r["value"]))
        print(f"{r['name']:<11} {value:>12} {r['unit']:<18} {r['allowed']:<16} {r['source']}{flag}")
    return EXIT_OK


def _add_orbit_options(parser) -> None:
    """The options ``orbit`` and ``continue`` share: the model, the joint, the periods, JSON."""
    add_model_options(parser)
    add_joint_options(parser)
    parser.add_argument("--periods", type=number(1, 64, integer=True), default=1,
                        help="drive periods of an orbit (default 1; 2 for a period doubling)")
    parser.add_argument("--joint", choices=("free", "locked"), default="free",
                        help="free (default) or locked (s = v = psi = 0)")
    parser.add_argument("--monodromy", choices=MONODROMY_METHODS, default="variational",
                        help="the period map's Jacobian from the variational equations with "
                        "saltation matrices (default) or by finite differences of the map")
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def add_parsers(sub) -> None:
    """Add this module's sub-commands to the parser's ``sub``."""
    from ..model import drives
    modes = sub.add_parser("modes", help="natural frequencies of the linearised model")
    add_model_options(modes)
    modes.add_argument("--joint", choices=("locked", "free"), default="locked",
                       help="locked: s = v = psi = 0; free: held only by the cork")
    modes.add_argument("--about", choices=("static", "undeformed"), default=None,
                       help="linearise about the static equilibrium under gravity (the default "
                       "with the joint locked) or the undeformed state (the default, and the "
                       "only one, with the joint free)")
    modes.add_argument("--json", action="store_true", help="print one JSON object")
    modes.set_defaults(func=_cmd_modes)

    run = sub.add_parser("run", help="simulate one run with contact (docs/model.md §7-9)")
    add_model_options(run)
    add_joint_options(run)
    add_drive_options(run, ramp_help=f"soft-start ramp of sine/chirp (s); default "
                                      f"{drives.DEFAULTS['ramp_s']:g} s, or half the run if shorter")
    run.add_argument("--duration", type=number(0, MAX_DURATION_S, lo_open=True), default=1.0,
                     help="simulated time (s; default 1)")
    run.add_argument("--dt", type=number(MIN_DT, MAX_DT),
                     help="fixed RK4 step (s; implies --method rk4 unless --tol is given); default "
                     "from the model's fastest mode")
    run.add_argument("--method", default=None,
                     help="integration method: dop853 (default: Dormand-Prince 8(5,3) steps chosen "
                     "by the error against --tol), dopri5 (5(4), the same way) or rk4 (fixed "
                     "steps of --dt)")
    run.add_argument("--tol", type=number(0, lo_open=True), default=None,
                     help=f"relative tolerance of the controlled method (default {DEFAULT_TOL:g}; "
                     "docs/model.md 'Integration')")
    run.add_argument("--output-hz", type=number(0, MAX_OUTPUT_HZ, lo_open=True), default=None,
                     help="sample rate of the signals (Hz; default 1000, a hammer's 10 samples a pulse)")
    run.add_argument("--check-accuracy", action="store_true",
                     help="also run a companion at a tenth of --tol and half the step (or a quarter "
                     "of a fixed --dt) and "
                     "report the error measured against it (error_measured)")
    run.add_argument("--joint", choices=("free", "locked"), default="free",
                     help="free (default): the loose body moves in its gap; locked: s = v = psi "
                     "= 0, as workbench modes --joint locked (a hammer test of the locked joint)")
    run.add_argument("--initial", choices=("static", "paper"), default="static",
                     help="static equilibrium (default) or the paper's undeformed free start")
    run.add_argument("--out", metavar="FILE", help="write the signals, in the format of the suffix: "
                     ".parquet (every signal, and the events), .lvm, .txt, .tdms, .uff (Table 2)")
    run.add_argument("--json", action="store_true", help="print one JSON object")
    run.set_defaults(func=_cmd_run)

    orbit = sub.add_parser("orbit", help="a periodic response of a sine drive by shooting, and "
                           "its Floquet multipliers (model/orbit.py)")
    _add_orbit_options(orbit)
    orbit.add_argument("--freq-hz", type=number(0, lo_open=True), required=True,
                       help="the sine's frequency (Hz)")
    orbit.add_argument("--force-n", type=number(0, MAX_FORCE_N, lo_open=True),
                       default=drives.DEFAULT_FORCE_N,
                       help=f"the sine's amplitude (N; default {drives.DEFAULT_FORCE_N:g})")
    orbit.set_defaults(func=_cmd_orbit)

    cont = sub.add_parser("continue", help="a branch of periodic orbits over the drive's "
                          "frequency or force (model/continuation.py)")
    _add_orbit_options(cont)
    cont.add_argument("--freq-hz", type=value_or_range, required=True,
                      help="the sine's frequency (Hz), or FROM:TO to continue over it (either "
                      "way)")
    cont.add_argument("--force-n", type=value_or_range, default=drives.DEFAULT_FORCE_N,
                      help=f"the sine's amplitude (N; default {drives.DEFAULT_FORCE_N:g}), or "
                      "FROM:TO to continue over it (either way)")
    cont.add_argument("--out", help="output folder (default results/continue/<parameter>-FROM-TO)")
    cont.add_argument("--period-doubling", action="store_true",
                      help="wherever a multiplier crosses the unit circle at -1 (a period "
                      "doubling, smooth or nonsmooth) also trace the branch of twice the "
                      "period, into OUT/doubled-<value>/")
    cont.set_defaults(func=_cmd_continue)

    comp = sub.add_parser("compile", help="compile the numba kernels ahead of the first run, "
                          "in parallel processes (make setup)")
    comp.add_argument("--jobs", type=number(1, 256, integer=True), default=None,
                      help="processes compiling at once (default: the usable cores)")
    comp.set_defaults(func=_cmd_compile)

    params = sub.add_parser("params", help="list every parameter with its unit, range and source")
    add_model_options(params)
    params.add_argument("--json", action="store_true", help="print JSON")
    params.set_defaults(func=_cmd_params)
