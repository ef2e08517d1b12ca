"""The ``workbench`` command line.

    workbench run --gap-mm G --tip-mass on|off --cork MODEL
                  [--freq-hz F | --chirp F0:F1:T | --free-decay CM | --impulse joint|tip]
                  [--force-n A] [--mu M] [--duration T] [--dt DT] [--out FILE.parquet] [--json]
    workbench modes [--tip-mass on|off] [--joint locked|free] [--cork MODEL] [--json]
    workbench params [--json]
    workbench compare FILE [model and drive options] [--skip-s S] [--out DIR]
    workbench estimate FILE... --fit NAME=START ... [model and drive options]
    workbench identify tables [--out DIR] | identify decrement X1 XN T1 TN N [--beam a|b]

Every subcommand accepts ``--params FILE.toml`` and ``--set NAME=VALUE``
(repeatable; unit-suffixed names such as ``gap_mm`` are converted).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from . import __version__
from .params import CORK_MODELS, ParameterError, Parameters, describe


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
    parser.add_argument("--cork", choices=sorted(CORK_MODELS), help="cork model (MODEL.md §6)")


def _parameters(args) -> Parameters:
    p = Parameters.from_toml(args.params) if args.params else Parameters()
    changes = {name: _value(text) for name, text in _pairs(args.set, "--set").items()}
    if args.tip_mass is not None:
        changes["tip_mass"] = args.tip_mass
    if args.cork is not None:
        changes["cork"] = args.cork
    return p.replace(**changes) if changes else p


def _cmd_modes(args) -> int:
    from .modes import natural_frequencies
    p = _parameters(args)
    freqs = natural_frequencies(p, args.joint)
    if args.json:
        print(json.dumps({"frequencies_hz": [float(f) for f in freqs], "joint": args.joint,
                          "tip_mass": p.tip_mass, "cork": p.cork}))
    else:
        print(f"Natural frequencies, joint {args.joint}, tip mass {'on' if p.tip_mass else 'off'}, "
              f"cork {p.cork} (linearised about the undeformed state):")
        for i, f in enumerate(freqs, 1):
            print(f"  mode {i}: {f:12.4f} Hz")
    return 0


def _chirp(text: str) -> tuple[float, float, float]:
    try:
        f0, f1, sweep = (float(x) for x in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"--chirp expects F0:F1:T (Hz:Hz:s), got {text!r}") from None
    return f0, f1, sweep


def _excitation(args):
    from . import excitation as X
    force = X.DEFAULT_FORCE_N if args.force_n is None else args.force_n
    if args.freq_hz is not None:
        return X.sine(force, args.freq_hz, ramp_s=args.ramp_s)
    if args.chirp is not None:
        return X.chirp(force, *args.chirp, ramp_s=args.ramp_s)
    if args.impulse is not None:
        hammer = X.hammer_joint if args.impulse == "joint" else X.hammer_tip
        peak = X.DEFAULT_HAMMER_N if args.force_n is None else args.force_n
        return hammer(peak, args.pulse_s, args.hit_s)
    return None


def _cmd_run(args) -> int:
    from .simulate import simulate
    p = _parameters(args)
    changes = {}
    if args.gap_mm is not None:
        changes["gap_mm"] = args.gap_mm
    if args.mu is not None:
        changes["mu_s"] = changes["mu_k"] = args.mu
    p = p.replace(**changes) if changes else p
    n_drives = sum(x is not None for x in (args.freq_hz, args.chirp, args.free_decay, args.impulse))
    if n_drives > 1:
        raise ParameterError("choose one of --freq-hz, --chirp, --free-decay, --impulse")
    run = simulate(p, _excitation(args), args.duration, dt=args.dt, output_hz=args.output_hz,
                   initial=args.initial, free_decay_cm=args.free_decay,
                   progress=not args.json and sys.stderr.isatty())
    if args.out:
        run.to_parquet(args.out)
    summary = run.summary()
    if args.json:
        print(json.dumps(summary))
    else:
        for key, value in summary.items():
            print(f"{key:>24}: {value}")
    return 0 if run.ok else 1


def _cmd_params(args) -> int:
    p = _parameters(args)
    rows = describe()
    for row in rows:
        row["value"] = getattr(p, row["name"])
    if args.json:
        print(json.dumps(rows, default=str, indent=1))
        return 0
    print(f"{'name':<11} {'value':>12} {'unit':<18} {'allowed':<16} source")
    for r in rows:
        flag = "  ASSUMPTION" if r["assumption"] else ""
        value = "None" if r["value"] is None else (f"{r['value']:.6g}" if isinstance(r["value"], float)
                                                  else str(r["value"]))
        print(f"{r['name']:<11} {value:>12} {r['unit']:<18} {r['allowed']:<16} {r['source']}{flag}")
    return 0


def _cmd_sweep(args) -> int:
    from .study import load
    from .sweep import run_study

    study = load(args.study)
    if args.jobs < 1:
        raise ParameterError(f"--jobs = {args.jobs} must be at least 1")
    table = run_study(study, args.results, jobs=args.jobs, scheduler=args.scheduler,
                      fresh=args.fresh, progress=not args.quiet)
    counts = table.status.value_counts().to_dict() if len(table) else {}
    summary = {"study": study.name, "points": study.n_points,
               "status": {str(k): int(v) for k, v in counts.items()},
               "results": str(Path(args.results) / study.name)}
    if not args.no_report:
        from .report import make_report
        summary["report"] = str(make_report(study, args.results))
    print(json.dumps(summary))
    return 0 if counts.get("ok", 0) == study.n_points else EXIT_POINTS_FAILED


#: Exit status of ``workbench sweep`` when the sweep ran but some points failed.
EXIT_POINTS_FAILED = 3


def _cmd_report(args) -> int:
    from .report import make_report
    from .study import load

    print(make_report(load(args.study), args.results))
    return 0


def _add_drive_options(parser, ramp_default=None) -> None:
    drive = parser.add_argument_group("excitation (one; default none)")
    drive.add_argument("--freq-hz", type=float, help="sine at force1, frequency (Hz)")
    drive.add_argument("--chirp", type=_chirp, metavar="F0:F1:T", help="linear chirp F0 -> F1 Hz over T s")
    drive.add_argument("--free-decay", type=float, metavar="CM",
                       help="release from a static tip deflection (cm, + up)")
    drive.add_argument("--impulse", choices=("joint", "tip"),
                       help="half-sine hammer: vertical at the joint body, or axial at the tip")
    drive.add_argument("--force-n", type=float,
                       help="shaker amplitude or hammer peak (N); default: see README")
    drive.add_argument("--ramp-s", type=float, default=ramp_default,
                       help="soft-start ramp of sine/chirp (s)")
    drive.add_argument("--pulse-s", type=float, default=1e-3, help="hammer pulse duration (s)")
    drive.add_argument("--hit-s", type=float, default=0.01, help="hammer pulse start (s)")


def _record_settings(args, meta: dict) -> dict:
    """A record's settings (matching.py): the file's, overridden by the command line."""
    from .study import ALL_EXCITATION_KEYS

    settings = dict(meta)
    given = {"gap_mm": args.gap_mm, "tip_mass": args.tip_mass, "cork": args.cork}
    settings.update({k: v for k, v in given.items() if v is not None})
    if args.mu is not None:
        settings.update(mu_s=args.mu, mu_k=args.mu)
    settings.update({name: _value(text) for name, text in _pairs(args.set, "--set").items()})
    drive = {}
    if args.freq_hz is not None:
        drive = {"drive": "sine", "freq_hz": args.freq_hz}
    elif args.chirp is not None:
        drive = dict(zip(("drive", "f0_hz", "f1_hz", "sweep_s"), ("chirp", *args.chirp)))
    elif args.free_decay is not None:
        drive = {"drive": "free_decay", "deflection_cm": args.free_decay}
    elif args.impulse is not None:
        drive = {"drive": f"hammer_{args.impulse}", "width_s": args.pulse_s, "t_hit_s": args.hit_s}
    if drive:                  # a drive given here replaces the file's (its amplitude may stay)
        for key in set(ALL_EXCITATION_KEYS) - {"force_n", "ramp_s"} | {"drive"}:
            settings.pop(key, None)
        settings.update(drive)
    if args.force_n is not None:
        settings["force_n"] = args.force_n
    if args.ramp_s is not None and settings.get("drive") in ("sine", "chirp"):
        settings["ramp_s"] = args.ramp_s
    return settings


def _read_record(args, path):
    from .expfiles import read
    scale = _pairs(args.strain_scale, "--strain-scale", "STRAIN_PER_VOLT")
    return read(path, strain_scale={name.lower(): float(text) for name, text in scale.items()})


def _add_joint_options(parser) -> None:
    parser.add_argument("--gap-mm", type=float, help="total transverse clearance (mm)")
    parser.add_argument("--mu", type=float, help="friction coefficient (sets mu_s = mu_k)")


def _add_record_options(parser) -> None:
    _add_model_options(parser)
    _add_joint_options(parser)
    _add_drive_options(parser)
    parser.add_argument("--strain-scale", metavar="CHANNEL=K", action="append", default=[],
                        help="scale factor of a strain channel recorded in V (strain per volt)")
    parser.add_argument("--skip-s", type=float, default=0.0,
                        help="leave out the first seconds (the transient)")


def _cmd_compare(args) -> int:
    from .compare import compare
    from .matching import setup_from

    record = _read_record(args, args.file)
    base = Parameters.from_toml(args.params) if args.params else None
    setup = setup_from(_record_settings(args, record.attrs["meta"]), record, base)
    run = setup.simulate()
    out = Path(args.out or Path("results") / "compare" / Path(args.file).stem)
    title = f"{Path(args.file).name} vs simulation ({setup.excitation['kind']})"
    result = compare(record, run, out, skip_s=args.skip_s, threshold=args.threshold,
                     chirp=setup.excitation["kind"] == "chirp", title=title)
    print(json.dumps({"record": args.file, "simulation_status": run.status, "out": str(out),
                      "figures": [str(p) for p in result.figures if p.suffix == ".png"],
                      "rms_error_rel": dict(zip(result.signals.channel,
                                                result.signals.rms_error_rel.round(4)))}))
    return 0 if run.ok else 1


def _cmd_estimate(args) -> int:
    from .estimate import estimate
    from .matching import setup_from

    start = {name: float(text) for name, text in _pairs(args.fit, "--fit", "START").items()}
    base = Parameters.from_toml(args.params) if args.params else None
    pairs = []
    for path in args.files:
        record = _read_record(args, path)
        pairs.append((record, setup_from(_record_settings(args, record.attrs["meta"]), record, base)))
    fit = estimate(pairs, start, skip_s=args.skip_s, jobs=args.jobs, max_nfev=args.max_nfev)
    table = fit.table()
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        table.to_csv(args.out, index=False)
    print(json.dumps({"values": fit.values, "intervals_2sigma": fit.intervals, "cost": fit.cost,
                      "simulations": fit.n_simulations, "success": fit.success,
                      "message": fit.message, "wall_s": round(fit.wall_s, 1)}))
    return 0 if fit.success else 1


def _cmd_identify_tables(args) -> int:
    from .identify import tables

    built = tables.build(include_table6=not args.no_table6)
    paths = tables.write(built, args.out)
    agree = {title: dict(t.agrees.value_counts()) for title, t in built.items()}
    print(json.dumps({"markdown": str(paths["md"]), "latex": str(paths["tex"]),
                      "agreement": {k: {str(a): int(n) for a, n in v.items()} for k, v in agree.items()}}))
    return 0


def _cmd_identify_decrement(args) -> int:
    from .identify import log_decrement

    beam = {}
    if args.beam is not None:
        length, _, inertia, mu = _parameters(args).beam(args.beam)
        beam = dict(mu=mu, length=length, area_moment=inertia)
    d = log_decrement(args.x1, args.xn, args.t1, args.tn, args.n, **beam)
    print(json.dumps({**d._asdict(), "E_gpa": d.E_gpa}))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="workbench", description="Loose bolted lap joint workbench (9-DOF Gibbs-Appell model).")
    parser.add_argument("--version", action="version", version=f"workbench {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    modes = sub.add_parser("modes", help="natural frequencies of the linearised model")
    _add_model_options(modes)
    modes.add_argument("--joint", choices=("locked", "free"), default="locked",
                       help="locked: s = v = psi = 0; free: held only by the cork")
    modes.add_argument("--json", action="store_true", help="print one JSON object")
    modes.set_defaults(func=_cmd_modes)

    run = sub.add_parser("run", help="simulate one run with contact (MODEL.md §7-9)")
    _add_model_options(run)
    _add_joint_options(run)
    _add_drive_options(run, ramp_default=1.0)
    run.add_argument("--duration", type=float, default=1.0, help="simulated time (s)")
    run.add_argument("--dt", type=float, help="RK4 step (s); default from the model's fastest mode")
    run.add_argument("--output-hz", type=float, default=1000.0, help="sample rate of the signals")
    run.add_argument("--initial", choices=("static", "paper"), default="static",
                     help="static equilibrium (default) or the paper's undeformed free start")
    run.add_argument("--out", metavar="FILE.parquet", help="write the signals (and events) to Parquet")
    run.add_argument("--json", action="store_true", help="print one JSON object")
    run.set_defaults(func=_cmd_run)

    sweep = sub.add_parser("sweep", help="run a study's grid (TOML) in parallel, resumably")
    sweep.add_argument("study", help="study definition, e.g. studies/default.toml")
    sweep.add_argument("--jobs", type=int, default=2, help="worker processes (default 2)")
    sweep.add_argument("--scheduler", default=None,
                       help="Dask scheduler address (tcp://host:port): run on that cluster")
    sweep.add_argument("--fresh", action="store_true", help="discard finished points first")
    sweep.add_argument("--results", default="results", help="results root (default results/)")
    sweep.add_argument("--quiet", action="store_true", help="no progress bar")
    sweep.add_argument("--no-report", action="store_true",
                       help="skip the figures, tables and report.md")
    sweep.set_defaults(func=_cmd_sweep)

    report = sub.add_parser("report", help="figures, tables and report.md of a study already run")
    report.add_argument("study", help="study definition (TOML)")
    report.add_argument("--results", default="results", help="results root (default results/)")
    report.set_defaults(func=_cmd_report)

    compare = sub.add_parser("compare", help="a measurement file against the matching simulation")
    compare.add_argument("file", help="a .lvm or tab-delimited record (Table 2 channels)")
    _add_record_options(compare)
    compare.add_argument("--threshold", type=float, default=0.5,
                         help="contact patch voltage that counts as touched (V)")
    compare.add_argument("--out", help="output folder (default results/compare/<file stem>)")
    compare.set_defaults(func=_cmd_compare)

    est = sub.add_parser("estimate", help="fit model parameters to measurement files (§7.2)")
    est.add_argument("files", nargs="+", help="records (.lvm or tab-delimited)")
    est.add_argument("--fit", metavar="NAME=START", action="append", required=True,
                     help="a parameter to fit and its start (CGS; force_n in N), repeatable; "
                          "fittable: e_a, e_b, zeta_a, zeta_b, mu, cork_k, cork_c, force_n")
    _add_record_options(est)
    est.add_argument("--jobs", type=int, default=2, help="worker processes (default 2)")
    est.add_argument("--max-nfev", type=int, default=30, help="most residual evaluations")
    est.add_argument("--out", metavar="FILE.csv", help="write the fitted values")
    est.set_defaults(func=_cmd_estimate)

    ident = sub.add_parser("identify", help="the paper's parameter identification (§4)")
    isub = ident.add_subparsers(dest="what", required=True)
    tab = isub.add_parser("tables", help="Tables 3-6 and Appendix B from their raw inputs")
    tab.add_argument("--out", default="results/identify", help="output folder")
    tab.add_argument("--no-table6", action="store_true", help="skip Table 6's fits (~40 s)")
    tab.set_defaults(func=_cmd_identify_tables)
    dec = isub.add_parser("decrement", help="Td, zeta, omega_n (and EI, E) from two peaks")
    for name, kind_, text in (("x1", float, "first peak"), ("xn", float, "n-th peak"),
                              ("t1", float, "time of the first (s)"), ("tn", float, "time of the n-th (s)"),
                              ("n", int, "number of peaks")):
        dec.add_argument(name, type=kind_, help=text)
    dec.add_argument("--beam", choices=("a", "b"), help="give EI and E with this beam's mu, L, I")
    _add_model_options(dec)
    dec.set_defaults(func=_cmd_identify_decrement)

    params = sub.add_parser("params", help="list every parameter with its unit, range and source")
    _add_model_options(params)
    params.add_argument("--json", action="store_true", help="print JSON")
    params.set_defaults(func=_cmd_params)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except ParameterError as exc:
        print(f"workbench: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
