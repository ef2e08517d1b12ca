"""The ``workbench`` command line.

    workbench run --gap-mm G --tip-mass on|off --cork MODEL
                  [--freq-hz F | --chirp F0:F1:T | --free-decay CM | --impulse joint|tip]
                  [--force-n A] [--mu M] [--duration T] [--dt DT] [--out FILE] [--json]
    workbench modes [--tip-mass on|off] [--joint locked|free] [--cork MODEL] [--json]
    workbench params [--json]
    workbench compare FILE [model and drive options] [--skip-s S] [--out DIR]
    workbench frf FILE [--response CH]... [--segment-s S] [--out DIR]
    workbench convert SOURCE TARGET [--from FORMAT] [--to FORMAT]
    workbench estimate FILE... --fit NAME=START ... [model and drive options]
    workbench identify tables [--out DIR] | identify decrement X1 XN T1 TN N [--beam a|b]

Every subcommand accepts ``--params FILE.toml`` and ``--set NAME=VALUE``
(repeatable; unit-suffixed names such as ``gap_mm`` are converted).

Exit codes (:data:`EXIT_CODES`): 0 done; 1 a simulation ended with a
failure status (what it computed is still written); 2 bad input, refused
before any work, in one line naming the option or key as written; 3 a sweep
ran but some points failed; 4 an estimate's fit did not converge; 70 an internal error (a bug of ours: one line,
the traceback in a file named there); 130 interrupted.
"""
from __future__ import annotations

import argparse
import gc
import json
import math
import os
import sys
import time
import traceback
from pathlib import Path

from . import __version__
from .model.params import CORK_MODELS, ParameterError, Parameters, describe
from .study.paths import check_output_dir, check_output_file
from .model.limits import (DEFAULT_TOL, FREE_DECAY_MAX_CM, MAX_DT, MAX_DURATION_S, MAX_FORCE_N,
                           MAX_OUTPUT_HZ, MIN_DT)

#: The results root every command's default output folder is in (relative to the working
#: directory, as the Makefile's RESULTS): sweeps and reports under it by study name,
#: results/identification, results/compare/<file stem>, results/frf/<file stem>.
RESULTS = Path("results")

EXIT_OK = 0
EXIT_RUN_FAILED = 1
EXIT_BAD_INPUT = 2
#: Exit status of ``workbench sweep`` when the sweep ran but some points failed.
EXIT_POINTS_FAILED = 3
EXIT_NOT_CONVERGED = 4
EXIT_INTERNAL = 70          # sysexits.h EX_SOFTWARE
EXIT_INTERRUPTED = 130
EXIT_CODES = {EXIT_OK: "done", EXIT_RUN_FAILED: "a simulation ended with a failure status",
              EXIT_BAD_INPUT: "bad input, refused before any work",
              EXIT_POINTS_FAILED: "a sweep ran but some points failed",
              EXIT_NOT_CONVERGED: "an estimate's fit did not converge",
              EXIT_INTERNAL: "internal error (traceback written to a file)",
              EXIT_INTERRUPTED: "interrupted"}


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors raised (not printed with the usage and exited)."""

    def error(self, message):
        raise ParameterError(f"{self.prog}: {message}")


def _number(lo=None, hi=None, lo_open=False, hi_open=False, integer=False):
    """An argparse type: a finite number in the range given (the message names the range)."""
    left = "(" if lo_open or lo is None else "["
    right = ")" if hi_open or hi is None else "]"
    allowed = f"{left}{'-inf' if lo is None else f'{lo:g}'}, {'inf' if hi is None else f'{hi:g}'}{right}"

    def parse(text: str):
        try:
            value = int(text) if integer else float(text)
        except ValueError:
            kind = "an integer" if integer else "a number"
            raise argparse.ArgumentTypeError(f"{text!r} is not {kind}") from None
        if not integer and not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{text!r} must be finite, in {allowed}")
        below = lo is not None and (value <= lo if lo_open else value < lo)
        above = hi is not None and (value >= hi if hi_open else value > hi)
        if below or above:
            raise argparse.ArgumentTypeError(f"{text} is outside the allowed range {allowed}")
        return value
    parse.__name__ = "integer" if integer else "number"
    return parse


def _cut(text: str, n: int = 24) -> str:
    """``text`` cut to n characters for a message."""
    return text if len(text) <= n else text[:n - 3] + "..."


def _given(option: str, call, *args, **kwargs):
    """call(*args, **kwargs), a ParameterError prefixed with the option as the user wrote it."""
    try:
        return call(*args, **kwargs)
    except ParameterError as exc:
        raise ParameterError(f"{option}: {exc}") from None


def _on_off(text: str) -> bool:
    if text in ("on", "off"):
        return text == "on"
    raise argparse.ArgumentTypeError(f"must be 'on' or 'off', got {text!r}")


def _value(text: str):
    """A --set value: a TOML scalar (number, true/false, "string") or a bare word."""
    import tomllib
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def _pairs(items: list[str], option: str, what: str = "VALUE") -> dict[str, str]:
    """Repeated ``--option NAME=VALUE`` arguments as {name: text}."""
    out = {}
    for item in items:
        name, sep, text = item.partition("=")
        if not sep:
            raise ParameterError(f"{option} expects NAME={what}, got {item!r}")
        out[name.strip()] = text.strip()
    return out


def _add_model_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--params", metavar="FILE.toml", help="parameters from a TOML file")
    parser.add_argument("--set", metavar="NAME=VALUE", action="append", default=[],
                        help="set one parameter (repeatable), e.g. --set gap_mm=0.762")
    parser.add_argument("--tip-mass", type=_on_off, metavar="on|off", help="attach the tip mass")
    parser.add_argument("--cork", choices=sorted(CORK_MODELS), help="cork model (docs/model.md §6)")


def _parameters(args) -> Parameters:
    """The model of --params, --set and the model options (--tip-mass, --cork, --gap-mm, --mu).

    Each value is checked alone first, so that the message names the option
    the user wrote; a parameter given twice (``--set cork=linear --cork
    none``) is refused.
    """
    from .model.params import resolve_name
    base = _given(f"--params {args.params}", Parameters.from_toml, args.params) \
        if args.params else Parameters()
    given = [(f"--set {_cut(name)}={_cut(text)}", name, _value(text))
             for name, text in _pairs(args.set, "--set").items()]
    if args.tip_mass is not None:
        given.append((f"--tip-mass {'on' if args.tip_mass else 'off'}", "tip_mass", args.tip_mass))
    if args.cork is not None:
        given.append((f"--cork {args.cork}", "cork", args.cork))
    if getattr(args, "gap_mm", None) is not None:
        given.append((f"--gap-mm {args.gap_mm:g}", "gap_mm", args.gap_mm))
    if getattr(args, "mu", None) is not None:
        given += [(f"--mu {args.mu:g}", "mu_s", args.mu), (f"--mu {args.mu:g}", "mu_k", args.mu)]
    seen: dict[str, str] = {}
    for label, name, value in given:
        field = _given(label, resolve_name, name)[0]
        if field in seen and seen[field] != label:
            raise ParameterError(f"{label} conflicts with {seen[field]}: give {field} once")
        seen[field] = label
    changes = {name: value for _, name, value in given}
    if not changes:
        return base

    def build(values):
        p = base.replace(**values)
        check_model(p)
        return p
    try:
        return build(changes)
    except ParameterError as exc:
        culprits = []
        for label, name, value in given:
            try:
                build({name: value})
            except ParameterError:
                culprits.append(label)
        labels = list(dict.fromkeys(culprits or [label for label, _, _ in given]))
        raise ParameterError(f"{' '.join(labels)}: {exc}") from None


def check_model(p: Parameters) -> None:
    """The linear model of p is usable (finite, positive definite, conditioned), or ParameterError."""
    from .model.modes import linear_eigenvalues
    linear_eigenvalues(p)


def _cmd_modes(args) -> int:
    from .model.modes import natural_frequencies
    p = _parameters(args)
    freqs = natural_frequencies(p, args.joint)
    if args.json:
        print(json_text({"frequencies_hz": [float(f) for f in freqs], "joint": args.joint,
                          "tip_mass": p.tip_mass, "cork": p.cork}))
    else:
        print(f"Natural frequencies, joint {args.joint}, tip mass {'on' if p.tip_mass else 'off'}, "
              f"cork {p.cork} (linearised about the undeformed state):")
        for i, f in enumerate(freqs, 1):
            print(f"  mode {i}: {f:12.4f} Hz")
    return EXIT_OK


def _cmd_compile(args) -> int:
    from .core._cache import CACHE_DIR
    from .model.warmup import compile_all
    print(f"workbench: compiling the numba kernels into {CACHE_DIR} ({args.jobs} processes)",
          file=sys.stderr, flush=True)
    t0 = time.perf_counter()
    failed = 0
    for name, seconds, error in compile_all(args.jobs):
        print(f"  {name}: {seconds:.0f} s" + (f" FAILED: {error}" if error else ""))
        failed += bool(error)
    print(f"  total wall time {time.perf_counter() - t0:.0f} s")
    return EXIT_INTERNAL if failed else EXIT_OK


def _chirp(text: str) -> tuple[float, float, float]:
    parts = text.split(":")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"expects F0:F1:T (Hz:Hz:s), got {text!r}")
    positive = _number(0, lo_open=True)
    try:
        return tuple(positive(x) for x in parts)
    except argparse.ArgumentTypeError as exc:
        raise argparse.ArgumentTypeError(f"{text!r}: {exc} (F0:F1:T, each > 0)") from None


def _shortcut_drive(args) -> dict | None:
    """The drive of --freq-hz, --chirp, --free-decay, --impulse or --drive, as settings
    {"drive": ..., key: value} with the keys those options give; None without a drive."""
    if args.freq_hz is not None:
        return {"drive": "sine", "freq_hz": args.freq_hz}
    if args.chirp is not None:
        return dict(zip(("drive", "f0_hz", "f1_hz", "sweep_s"), ("chirp", *args.chirp)))
    if args.free_decay is not None:
        return {"drive": "free_decay", "deflection_cm": args.free_decay}
    if args.impulse is not None:
        return {"drive": f"hammer_{args.impulse}", "width_s": args.pulse_s, "t_hit_s": args.hit_s}
    if args.drive is not None:
        return _drive_settings(args)
    return None


def _run_drive(args) -> dict:
    """The complete drive settings of ``workbench run`` (amplitude and soft start filled)."""
    from .model import drives
    drive = _shortcut_drive(args) or {"drive": "none"}
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


#: The run options behind the names of :func:`workbench.model.simulate.check_settings`.
RUN_OPTION_NAMES = {"duration": "--duration", "dt": "--dt", "output_hz": "--output-hz",
                    "method": "--method", "tol": "--tol",
                    "freq_hz": "--freq-hz", "f0_hz": "--chirp F0", "f1_hz": "--chirp F1",
                    "width_s": "--pulse-s", "t_hit_s": "--hit-s", "ramp_s": "--ramp-s"}


def _cmd_run(args) -> int:
    from .experiments import files
    from .experiments.matching import settings_of
    from .model import drives
    from .model.simulate import check_method, check_settings, simulate
    n_drives = sum(x is not None for x in (args.freq_hz, args.chirp, args.free_decay, args.impulse,
                                           args.drive))
    if n_drives > 1:
        raise ParameterError("choose one of --freq-hz, --chirp, --free-decay, --impulse, --drive")
    if args.drive_set and args.drive is None:
        raise ParameterError("--drive-set sets a --drive: give --drive KIND")
    p = _parameters(args)
    names = dict(RUN_OPTION_NAMES)
    drive = _run_drive(args)
    if args.drive is not None:
        names.update({key: f"--drive-set {key}" for key in drive if key != "drive"})
    ex = drives.excitation_array(drive)
    check_settings(p, ex, args.duration, args.dt, args.output_hz, names=names)
    check_method(args.method, args.tol, dt_given=args.dt is not None, names=names)
    if args.out:
        check_output_file("--out", args.out, files.SUFFIXES)
        meta = settings_of(drive, p)
        files.check_settings(args.out, meta)
    run = simulate(p, ex, args.duration, dt=args.dt, output_hz=args.output_hz,
                   method=args.method, tol=args.tol, initial=args.initial, progress=not args.json and sys.stderr.isatty(),
                   **drives.start_keywords(drive))
    if args.out:
        if files.format_of(args.out) == "parquet":       # the whole run: every signal, events
            run.signals.attrs["meta"] = meta
            run.to_parquet(args.out)
        else:
            files.write(args.out, files.record_from_run(run), meta)
    summary = run.summary()
    if args.json:
        print(json_text(summary))
    else:
        for key, value in summary.items():
            print(f"{key:>24}: {value}")
    return EXIT_OK if run.ok else EXIT_RUN_FAILED


def _cmd_params(args) -> int:
    p = _parameters(args)
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


def _cmd_sweep(args) -> int:
    from .study.definition import load
    from .study.sweep import plan, run_study

    study = load(args.study)
    check_output_dir("--results", args.results)
    if args.scheduler is not None:
        _check_scheduler(args.scheduler)
    if args.dry_run:
        print(json_text(plan(study, args.results, fresh=args.fresh, jobs=args.jobs)))
        return EXIT_OK
    table = run_study(study, args.results, jobs=args.jobs, scheduler=args.scheduler,
                      fresh=args.fresh, progress=not args.quiet)
    counts = table.status.value_counts().to_dict() if len(table) else {}
    summary = {"study": study.name, "points": study.n_points,
               "status": {str(k): int(v) for k, v in counts.items()},
               "results": str(Path(args.results) / study.name)}
    if not args.no_report:
        from .present.report import make_report
        summary["report"] = str(make_report(study, args.results, jobs=args.jobs))
    print(json_text(summary))
    return EXIT_OK if counts.get("ok", 0) == study.n_points else EXIT_POINTS_FAILED


def _check_scheduler(address: str) -> None:
    """A Dask scheduler address tcp://HOST:PORT (or HOST:PORT) that accepts a connection."""
    import socket
    from urllib.parse import urlsplit
    text = address if "://" in address else f"tcp://{address}"
    try:
        url = urlsplit(text)
        scheme, host, port = url.scheme, url.hostname, url.port
    except ValueError:
        scheme, host, port = None, None, None
    if scheme not in ("tcp", "tls") or not host or not port:
        raise ParameterError(f"--scheduler {address}: expects a Dask scheduler address "
                             "tcp://HOST:PORT")
    try:
        socket.create_connection((host, port), timeout=5.0).close()
    except OSError as exc:
        raise ParameterError(f"--scheduler {address}: no scheduler answers there "
                             f"({exc.strerror or exc}); start one with `dask scheduler`") from None


def _cmd_report(args) -> int:
    from .present.report import make_report
    from .study.definition import load

    study = load(args.study)
    if not (Path(args.results) / study.name / "points.parquet").is_file():
        raise ParameterError(f"report {args.study}: no results in {Path(args.results) / study.name}"
                             f"; run `workbench sweep {args.study} --results {args.results}` first")
    print(make_report(study, args.results, jobs=args.jobs))
    return EXIT_OK


def _add_drive_options(parser, ramp_help="soft-start ramp of sine/chirp (s)") -> None:
    from .model import drives
    drive = parser.add_argument_group("excitation (one; default none)")
    drive.add_argument("--freq-hz", type=_number(0, lo_open=True), help="sine at force1, frequency (Hz)")
    drive.add_argument("--chirp", type=_chirp, metavar="F0:F1:T", help="linear chirp F0 -> F1 Hz over T s")
    drive.add_argument("--free-decay", type=_number(-FREE_DECAY_MAX_CM, FREE_DECAY_MAX_CM), metavar="CM",
                       help="release from a static tip deflection (cm, + up)")
    drive.add_argument("--impulse", choices=("joint", "tip"),
                       help="half-sine hammer: vertical at the joint body, or axial at the tip")
    drive.add_argument("--force-n", type=_number(-MAX_FORCE_N, MAX_FORCE_N),
                       help="shaker amplitude or hammer peak (N); default: see docs/usage.md")
    drive.add_argument("--ramp-s", type=_number(0), help=ramp_help)
    drive.add_argument("--pulse-s", type=_number(0, lo_open=True), default=drives.DEFAULTS["width_s"],
                       help="hammer pulse duration (s)")
    drive.add_argument("--hit-s", type=_number(0), default=drives.DEFAULTS["t_hit_s"],
                       help="hammer pulse start (s)")
    drive.add_argument("--drive", metavar="KIND",
                       help="any registered drive (workbench/model/drives.py), set by --drive-set")
    drive.add_argument("--drive-set", metavar="KEY=VALUE", action="append", default=[],
                       help="a setting of --drive in its units (e.g. freq_hz=20), repeatable")


def _drive_settings(args) -> dict:
    """The settings {"drive": ..., key: value} of ``--drive`` and its ``--drive-set`` pairs."""
    from .model import drives
    drive = drives.get(args.drive, where="--drive")
    given = _pair_numbers(args.drive_set, "--drive-set", "VALUE")
    unknown = sorted(set(given) - set(drive.keys))
    if unknown:
        raise ParameterError(f"--drive-set {_cut(unknown[0])}: not a setting of --drive "
                             f"{drive.name} (its settings: {', '.join(drive.keys) or 'none'})")
    return drives.complete(drive.name, given, lambda key: f"--drive {drive.name} needs "
                           f"--drive-set {key}=VALUE ({drives.UNITS[key]})",
                           duration_s=getattr(args, "duration", None))


def _record_settings(args, meta: dict) -> dict:
    """A record's settings (matching.py): the file's, overridden by the command line."""
    from .model import drives

    settings = dict(meta)
    given = {"gap_mm": args.gap_mm, "tip_mass": args.tip_mass, "cork": args.cork}
    settings.update({k: v for k, v in given.items() if v is not None})
    if args.mu is not None:
        settings.update(mu_s=args.mu, mu_k=args.mu)
    settings.update({name: _value(text) for name, text in _pairs(args.set, "--set").items()})
    drive = _shortcut_drive(args)
    if drive:                  # a drive given here replaces the file's (its amplitude may stay)
        for key in set(drives.all_keys()) - {"force_n", "ramp_s"} | {"drive"}:
            settings.pop(key, None)
        settings.update(drive)
    if args.force_n is not None:
        settings["force_n"] = args.force_n
    if args.ramp_s is not None and drives.DRIVES.get(settings.get("drive")) is not None \
            and drives.DRIVES[settings["drive"]].ramped:
        settings["ramp_s"] = args.ramp_s
    return settings


def _pair_numbers(items, option, what, lo=None, lo_open=False) -> dict[str, float]:
    """Repeated ``--option NAME=NUMBER`` as {name: number}; a bad number names the item."""
    parse = _number(lo, lo_open=lo_open)
    out = {}
    for name, text in _pairs(items, option, what).items():
        try:
            out[name] = parse(text)
        except argparse.ArgumentTypeError as exc:
            raise ParameterError(f"{option} {_cut(name)}={_cut(text)}: {exc}") from None
    return out


def _strain_scale(args) -> dict[str, float]:
    scale = _pair_numbers(args.strain_scale, "--strain-scale", "STRAIN_PER_VOLT", 0, lo_open=True)
    return {name.lower(): value for name, value in scale.items()}


def _read_record(args, path):
    from .experiments import files
    return files.read(path, _strain_scale(args), files.format_of(path, args.format))


def _add_joint_options(parser) -> None:
    parser.add_argument("--gap-mm", type=_number(0, lo_open=True), help="total transverse clearance (mm)")
    parser.add_argument("--mu", type=_number(0, 5), help="friction coefficient (sets mu_s = mu_k)")


def _add_record_options(parser) -> None:
    _add_model_options(parser)
    _add_joint_options(parser)
    _add_drive_options(parser)
    parser.add_argument("--strain-scale", metavar="CHANNEL=K", action="append", default=[],
                        help="scale factor of a strain channel recorded in V (strain per volt)")
    parser.add_argument("--skip-s", type=_number(0), default=0.0,
                        help="leave out the first seconds (the transient)")
    _add_format_option(parser)


def _add_jobs_option(parser, what: str) -> None:
    parser.add_argument("--jobs", type=_number(1, 256, integer=True), default=2,
                        help=f"{what} (default 2)")


def _add_format_option(parser, option="--format", dest="format", what="the file's format") -> None:
    from .experiments.files import FORMATS
    parser.add_argument(option, dest=dest, choices=tuple(FORMATS),
                        help=f"{what} (default: by its suffix)")


def _check_window(path, record, skip_s: float) -> None:
    """--skip-s leaves at least two samples of the record."""
    t = record.index.to_numpy()
    if len(t) < 2 or t[-1] - t[0] <= skip_s:
        raise ParameterError(f"--skip-s {skip_s:g}: {path} lasts {t[-1] - t[0]:g} s; leave "
                             "less out than that")


def _cmd_convert(args) -> int:
    from .experiments import files
    source_format = files.format_of(args.source, args.source_format, option="--from")
    target_format = files.format_of(args.target, args.target_format, option="--to")
    check_output_file("TARGET", args.target)
    if Path(args.target).resolve() == Path(args.source).resolve():
        raise ParameterError(f"TARGET {args.target}: is the SOURCE; write to another file")
    record = files.convert(args.source, args.target, _strain_scale(args), source_format,
                           target_format)
    t = record.index.to_numpy()
    print(json_text({"source": args.source, "target": args.target, "format": target_format,
                     "channels": list(record.columns), "samples": len(record),
                     "duration_s": float(t[-1] - t[0]), "settings": record.attrs["meta"],
                     "units_assumed": record.attrs["units_assumed"]}))
    return EXIT_OK


def _cmd_compare(args) -> int:
    from .present.comparison import compare
    from .model import drives
    from .experiments.matching import setup_from

    from .experiments.compare import SIGNALS
    record = _read_record(args, args.file)
    _check_window(args.file, record, args.skip_s)
    if not any(c in record.columns for c in SIGNALS):
        raise ParameterError(f"{args.file}: no signal channel to compare (has "
                             f"{list(record.columns)}; signals: {list(SIGNALS)})")
    out = check_output_dir("--out", args.out or RESULTS / "compare" / Path(args.file).stem)
    base = _given(f"--params {args.params}", Parameters.from_toml, args.params) \
        if args.params else None
    setup = setup_from(_record_settings(args, record.attrs["meta"]), record, base)
    run = setup.simulate()
    title = f"{Path(args.file).name} vs simulation ({setup.excitation['drive']})"
    result = compare(record, run, out, skip_s=args.skip_s, threshold=args.threshold,
                     chirp=drives.DRIVES[setup.excitation["drive"]].swept,
                     band=drives.band_hz(setup.excitation), title=title)
    print(json_text({"record": args.file, "simulation_status": run.status, "out": str(out),
                      "figures": [str(p) for p in result.figures if p.suffix == ".png"],
                      "rms_error_rel": dict(zip(result.signals.channel,
                                                result.signals.rms_error_rel.round(4)))}))
    return EXIT_OK if run.ok else EXIT_RUN_FAILED


def _cmd_frf(args) -> int:
    from .experiments.formats import uff
    from .experiments.frf import frf, magnitude_phase, peak_table as peak_table_of, responses_of
    from .present.figures import frf_figure, save

    path = Path(args.file)
    record = _read_record(args, args.file)
    meta = record.attrs.get("meta", {})
    uff.check_settings(Path(args.file), meta, records=len(args.response) or sum(
        str(c).startswith(("accel", "strain")) for c in record.columns))
    _check_window(args.file, record, args.skip_s)
    t = record.index.to_numpy()
    length = (t[-1] - t[0] - args.skip_s) * len(t) / max(len(t) - 1, 1)    # samples x dt
    if args.segment_s > length * (1 + 1e-9):
        raise ParameterError(f"--segment-s {args.segment_s:g}: longer than {args.file} after "
                             f"--skip-s; allowed: (0, {length:g}] s")
    out = check_output_dir("--out", args.out or RESULTS / "frf" / path.stem)
    out.mkdir(parents=True, exist_ok=True)
    table = frf(record, args.response or None, force=args.force, segment_s=args.segment_s,
                skip_s=args.skip_s)
    responses = responses_of(table)
    magnitude_phase(table).to_csv(out / "frf.csv")
    peak_table = peak_table_of({args.file: table}, responses, args.f_min,
                               args.f_max).drop(columns="source")
    peak_table.to_csv(out / "peaks.csv", index=False)
    (out / "peaks.md").write_text("# FRF peaks (H1): frequency (Hz), magnitude in its unit, "
                                  "coherence, half-power damping ratio\n\n"
                                  + peak_table.to_markdown(index=False, floatfmt=".4g") + "\n")
    figures = save(frf_figure(table, responses, f"{path.name}: H1, H2, coherence against "
                              f"{args.force}", args.f_max), out / "frf")
    uff.write_frf(out / "frf.uff", table, responses, args.force, meta=meta)
    print(json_text({"record": args.file, "out": str(out), "resolution_hz": float(table.index[1]),
                     "uff": str(out / "frf.uff"),
                     "figures": [str(p) for p in figures if p.suffix == ".png"],
                     "peaks": peak_table.to_dict("records")}))
    return EXIT_OK


def _cmd_estimate(args) -> int:
    from .experiments.estimate import estimate
    from .experiments.matching import setup_from

    from .experiments.estimate import FITTABLE
    start = _pair_numbers(args.fit, "--fit", "START", 0, lo_open=True)
    unknown = sorted(set(start) - set(FITTABLE))
    if unknown:
        raise ParameterError(f"--fit {', '.join(_cut(u) for u in unknown)}: not fittable; "
                             f"fittable are {', '.join(FITTABLE)}")
    if args.out:
        check_output_file("--out", args.out, (".csv",))
    base = _given(f"--params {args.params}", Parameters.from_toml, args.params) \
        if args.params else None
    pairs = []
    for path in args.files:
        record = _read_record(args, path)
        _check_window(path, record, args.skip_s)
        pairs.append((record, setup_from(_record_settings(args, record.attrs["meta"]), record, base)))
    fit = estimate(pairs, start, skip_s=args.skip_s, jobs=args.jobs, max_nfev=args.max_nfev)
    table = fit.table()
    if args.out:
        table.to_csv(args.out, index=False)
    print(json_text({"values": fit.values, "intervals_2sigma": fit.intervals, "cost": fit.cost,
                      "simulations": fit.n_simulations, "success": fit.success,
                      "message": fit.message, "wall_s": round(fit.wall_s, 1)}))
    return EXIT_OK if fit.success else EXIT_NOT_CONVERGED


def _cmd_identify_tables(args) -> int:
    from .identify import tables

    check_output_dir("--out", args.out)
    built = tables.build(include_table6=not args.no_table6, jobs=args.jobs)
    paths = tables.write(built, args.out)
    agree = {title: dict(t.agrees.value_counts()) for title, t in built.items()}
    print(json_text({"markdown": str(paths["md"]), "latex": str(paths["tex"]),
                      "agreement": {k: {str(a): int(n) for a, n in v.items()} for k, v in agree.items()}}))
    return EXIT_OK


def _cmd_identify_decrement(args) -> int:
    from .identify import log_decrement

    beam = {}
    if args.beam is not None:
        length, _, inertia, mu = _parameters(args).beam(args.beam)
        beam = dict(mu=mu, length=length, area_moment=inertia)
    d = log_decrement(args.x1, args.xn, args.t1, args.tn, args.n, **beam)
    print(json_text({**d._asdict(), "E_gpa": d.E_gpa}))
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    from .model import drives
    parser = _Parser(
        prog="workbench", description="Loose bolted lap joint workbench (9-DOF Gibbs-Appell model).")
    parser.add_argument("--version", action="version", version=f"workbench {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    modes = sub.add_parser("modes", help="natural frequencies of the linearised model")
    _add_model_options(modes)
    modes.add_argument("--joint", choices=("locked", "free"), default="locked",
                       help="locked: s = v = psi = 0; free: held only by the cork")
    modes.add_argument("--json", action="store_true", help="print one JSON object")
    modes.set_defaults(func=_cmd_modes)

    run = sub.add_parser("run", help="simulate one run with contact (docs/model.md §7-9)")
    _add_model_options(run)
    _add_joint_options(run)
    _add_drive_options(run, ramp_help=f"soft-start ramp of sine/chirp (s); default "
                                      f"{drives.DEFAULTS['ramp_s']:g} s, or half the run if shorter")
    run.add_argument("--duration", type=_number(0, MAX_DURATION_S, lo_open=True), default=1.0, help="simulated time (s)")
    run.add_argument("--dt", type=_number(MIN_DT, MAX_DT),
                     help="fixed RK4 step (s; implies --method rk4 unless --tol is given); default "
                     "from the model's fastest mode")
    run.add_argument("--method", default=None,
                     help="integration method: controlled (default: steps chosen by the error "
                     "against --tol) or rk4 (fixed steps of --dt)")
    run.add_argument("--tol", type=_number(0, lo_open=True), default=None,
                     help=f"relative tolerance of the controlled method (default {DEFAULT_TOL:g}; "
                     "docs/model.md 'Integration')")
    run.add_argument("--output-hz", type=_number(0, MAX_OUTPUT_HZ, lo_open=True), default=1000.0, help="sample rate of the signals")
    run.add_argument("--initial", choices=("static", "paper"), default="static",
                     help="static equilibrium (default) or the paper's undeformed free start")
    run.add_argument("--out", metavar="FILE", help="write the signals, in the format of the suffix: "
                     ".parquet (every signal, and the events), .lvm, .txt, .tdms, .uff (Table 2)")
    run.add_argument("--json", action="store_true", help="print one JSON object")
    run.set_defaults(func=_cmd_run)

    sweep = sub.add_parser("sweep", help="run a study's grid (TOML) in parallel, resumably")
    sweep.add_argument("study", help="study definition, e.g. studies/default.toml")
    _add_jobs_option(sweep, "worker processes")
    sweep.add_argument("--scheduler", default=None,
                       help="Dask scheduler address (tcp://host:port): run on that cluster")
    sweep.add_argument("--fresh", action="store_true", help="discard finished points first")
    sweep.add_argument("--results", default=str(RESULTS), help="results root (default results/)")
    sweep.add_argument("--quiet", action="store_true", help="no progress bar")
    sweep.add_argument("--no-report", action="store_true",
                       help="skip the figures, tables and report.md")
    sweep.add_argument("--dry-run", action="store_true",
                       help="check the study, print its grid size and expected cost, run nothing")
    sweep.set_defaults(func=_cmd_sweep)

    report = sub.add_parser("report", help="figures, tables and report.md of a study already run")
    report.add_argument("study", help="study definition (TOML)")
    report.add_argument("--results", default=str(RESULTS), help="results root (default results/)")
    _add_jobs_option(report, "processes drawing the figures")
    report.set_defaults(func=_cmd_report)

    compare = sub.add_parser("compare", help="a measurement file against the matching simulation")
    compare.add_argument("file", help="a .lvm or tab-delimited record (Table 2 channels)")
    _add_record_options(compare)
    compare.add_argument("--threshold", type=_number(0, lo_open=True), default=0.5,
                         help="contact patch voltage that counts as touched (V)")
    compare.add_argument("--out", help="output folder (default results/compare/<file stem>)")
    compare.set_defaults(func=_cmd_compare)

    fr = sub.add_parser("frf", help="H1, H2 and coherence of a record or a run against its force")
    fr.add_argument("file", help="a record (.lvm .txt .tdms .uff .parquet), e.g. of workbench run --out")
    fr.add_argument("--force", default="force1", help="the force channel (default force1)")
    fr.add_argument("--response", action="append", default=[],
                    help="a response channel, repeatable (default: every accel and strain)")
    fr.add_argument("--segment-s", type=_number(0, lo_open=True), default=2.0,
                    help="Welch segment (s): the frequency resolution is 1/segment (default 2)")
    fr.add_argument("--skip-s", type=_number(0), default=0.0, help="leave out the first seconds")
    fr.add_argument("--f-min", type=_number(0), default=0.0, help="lowest peak frequency (Hz)")
    fr.add_argument("--f-max", type=_number(0, lo_open=True), default=None,
                    help="highest frequency shown and searched for peaks (Hz)")
    fr.add_argument("--strain-scale", metavar="CHANNEL=K", action="append", default=[],
                    help="scale factor of a strain channel recorded in V (strain per volt)")
    _add_format_option(fr)
    fr.add_argument("--out", help="output folder (default results/frf/<file stem>)")
    fr.set_defaults(func=_cmd_frf)

    conv = sub.add_parser("convert", help="write a record in another format (.lvm .txt .tdms .uff .parquet)")
    conv.add_argument("source", help="the record to read")
    conv.add_argument("target", help="the file to write (its format by its suffix or --to)")
    _add_format_option(conv, "--from", "source_format", "the source's format")
    _add_format_option(conv, "--to", "target_format", "the target's format")
    conv.add_argument("--strain-scale", metavar="CHANNEL=K", action="append", default=[],
                      help="scale factor of a strain channel recorded in V (strain per volt)")
    conv.set_defaults(func=_cmd_convert)

    est = sub.add_parser("estimate", help="fit model parameters to measurement files (§7.2)")
    est.add_argument("files", nargs="+", help="records (.lvm or tab-delimited)")
    est.add_argument("--fit", metavar="NAME=START", action="append", required=True,
                     help="a parameter to fit and its start (CGS; force_n in N), repeatable; "
                          "fittable: e_a, e_b, zeta_a, zeta_b, mu, cork_k, cork_c, force_n")
    _add_record_options(est)
    _add_jobs_option(est, "worker processes")
    est.add_argument("--max-nfev", type=_number(1, 100000, integer=True), default=30, help="most residual evaluations")
    est.add_argument("--out", metavar="FILE.csv", help="write the fitted values")
    est.set_defaults(func=_cmd_estimate)

    ident = sub.add_parser("identify", help="the paper's parameter identification (§4)")
    isub = ident.add_subparsers(dest="what", required=True)
    tab = isub.add_parser("tables", help="Tables 3-6 and Appendix B from their raw inputs")
    tab.add_argument("--out", default=str(RESULTS / "identification"),
                     help="output folder (default results/identification)")
    tab.add_argument("--no-table6", action="store_true", help="skip Table 6's fits (~40 s)")
    _add_jobs_option(tab, "processes running Table 6's fits")
    tab.set_defaults(func=_cmd_identify_tables)
    dec = isub.add_parser("decrement", help="Td, zeta, omega_n (and EI, E) from two peaks")
    for name, kind_, text in (("x1", float, "first peak"), ("xn", float, "n-th peak"),
                              ("t1", float, "time of the first (s)"), ("tn", float, "time of the n-th (s)"),
                              ("n", int, "number of peaks")):
        dec.add_argument(name, type=kind_, help=text)
    dec.add_argument("--beam", choices=("a", "b"), help="give EI and E with this beam's mu, L, I")
    _add_model_options(dec)
    dec.set_defaults(func=_cmd_identify_decrement)

    comp = sub.add_parser("compile", help="compile the numba kernels ahead of the first run, "
                          "in parallel processes (make setup)")
    comp.add_argument("--jobs", type=_number(1, 256, integer=True), default=2,
                      help="processes compiling at once (default 2)")
    comp.set_defaults(func=_cmd_compile)

    params = sub.add_parser("params", help="list every parameter with its unit, range and source")
    _add_model_options(params)
    params.add_argument("--json", action="store_true", help="print JSON")
    params.set_defaults(func=_cmd_params)
    return parser


def json_text(obj) -> str:
    """JSON without NaN or Infinity: such a number becomes null, its reason in ``"nulls"``."""
    nulls: dict[str, str] = {}

    def clean(value, where):
        if isinstance(value, float) and not math.isfinite(value):
            nulls[where] = f"not a finite number ({value!r})"
            return None
        if isinstance(value, dict):
            return {k: clean(v, f"{where}.{k}" if where else str(k)) for k, v in value.items()}
        if isinstance(value, (list, tuple)):
            return [clean(v, f"{where}[{i}]") for i, v in enumerate(value)]
        if hasattr(value, "item") and not isinstance(value, (str, bytes)):
            return clean(value.item(), where)        # numpy scalars
        return value

    out = clean(obj, "")
    if nulls and isinstance(out, dict):
        out["nulls"] = nulls
    return json.dumps(out, allow_nan=False, default=str)


def _crash_report(argv) -> Path:
    """Write the current exception's traceback to a file; return its path."""
    folder = Path(os.environ.get("WORKBENCH_CRASH_DIR") or
                  Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "workbench")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        import tempfile
        folder = Path(tempfile.gettempdir())
    path = folder / f"crash-{time.strftime('%Y%m%d-%H%M%S')}-{os.getpid()}.txt"
    path.write_text(f"workbench {__version__}\nargv: {argv!r}\n\n{traceback.format_exc()}")
    return path


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit code (:data:`EXIT_CODES`), never raises."""
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        args = build_parser().parse_args(argv)
        return args.func(args)
    except ParameterError as exc:                 # bad input, refused before the work
        print(f"workbench: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except SystemExit as exc:                     # --help, --version
        return exc.code if isinstance(exc.code, int) else EXIT_OK
    except KeyboardInterrupt:
        print("workbench: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        return EXIT_OK
    except Exception as exc:                      # noqa: BLE001 - our bug: say where it is
        try:
            where = f"traceback in {_crash_report(argv)}"
        except OSError:
            where = "the traceback could not be written"
        print(f"workbench: internal error: {type(exc).__name__}: {_one_line(exc)} ({where}); "
              "please report it", file=sys.stderr)
        return EXIT_INTERNAL


#: The collector's first threshold for the command-line process (CPython's default is 700):
#: importing numba and loading the kernels allocate about 110 000 long-lived objects, and at
#: the default a fresh ``workbench run`` spends about 0.06 s collecting while they are made.
GC_THRESHOLD = 10_000


def entry() -> None:
    """The process's entry point (``workbench``, ``python -m workbench``): :func:`main`, then exit.

    The collector runs less often (:data:`GC_THRESHOLD`), and before the
    interpreter exits the surviving objects are frozen out of its final
    collections: these would traverse the libraries' objects once more
    for about 0.2 s and free nothing the operating system does not reclaim
    anyway.  Exit handlers (``atexit``) still run.  :func:`main` itself
    leaves the collector alone, so that callers in a longer-lived process
    (the tests) keep their own settings.
    """
    gc.set_threshold(GC_THRESHOLD)
    code = main()
    gc.freeze()
    sys.exit(code)


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text if len(text) <= 400 else text[:397] + "..."


if __name__ == "__main__":
    entry()
