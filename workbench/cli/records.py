"""``workbench convert``, ``compare``, ``frf`` and ``estimate``: lab records read,
written, set beside their simulation, turned into FRFs, and fitted."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..model.limits import MAX_FORCE_N
from ..model.params import ParameterError, Parameters
from ..study.paths import check_output_dir, check_output_file, staged_output
from .common import (EXIT_NOT_CONVERGED, EXIT_OK, EXIT_RUN_FAILED, RESULTS, add_format_option,
                     add_jobs_option, add_record_options, check_window, cut,
                     json_text, number, pair_numbers, pairs, parameters_of, read_record,
                     record_settings, shortcut_drive, strain_scale, with_option)


def _cmd_convert(args) -> int:
    from ..lab import files
    source_format = files.format_of(args.source, args.source_format, option="--from")
    target_format = files.format_of(args.target, args.target_format, option="--to")
    check_output_file("TARGET", args.target)
    if Path(args.target).resolve() == Path(args.source).resolve():
        raise ParameterError(f"TARGET {args.target}: is the SOURCE; write to another file")
    record = files.convert(args.source, args.target, strain_scale(args), source_format,
                           target_format)
    t = record.index.to_numpy()
    print(json_text({"source": args.source, "target": args.target, "format": target_format,
                     "channels": list(record.columns), "samples": len(record),
                     "duration_s": float(t[-1] - t[0]), "settings": record.attrs["meta"],
                     "units_assumed": record.attrs["units_assumed"]}))
    return EXIT_OK


def _cmd_compare(args) -> int:
    from ..present.comparison import compare
    from ..model import drives
    from ..lab.matching import setup_from

    from ..lab.compare import SIGNALS
    record = read_record(args, args.file)
    check_window(args.file, record, args.skip_s)
    if not any(c in record.columns for c in SIGNALS):
        raise ParameterError(f"{args.file}: no signal channel to compare (has "
                             f"{list(record.columns)}; signals: {list(SIGNALS)})")
    out = check_output_dir("--out", args.out or RESULTS / "compare" / Path(args.file).stem)
    base = with_option(f"--params {args.params}", Parameters.from_toml, args.params) \
        if args.params else None
    setup = setup_from(record_settings(args, record.attrs["meta"]), record, base)
    run = setup.simulate()
    title = f"{Path(args.file).name} vs simulation ({setup.excitation['drive']})"
    result = compare(record, run, out, skip_s=args.skip_s, threshold=args.threshold,
                     chirp=drives.DRIVES[setup.excitation["drive"]].swept,
                     band=drives.band_hz(setup.excitation), title=title)
    print(json_text({"record": args.file, "simulation_status": run.status, "out": str(out),
                      "figures": [str(p) for p in result.figures if p.suffix == ".png"],
                      "rms_error_rel": dict(zip(result.signals.channel,
                                                result.signals.rms_error_rel.round(4))),
                      "notes": result.notes}))
    return EXIT_OK if run.ok else EXIT_RUN_FAILED


def _cmd_frf(args) -> int:
    from ..lab.channels import reference_of
    from ..lab.formats import uff
    from ..lab.frf import (DEFAULT_SEGMENT_S, default_window, frf, magnitude_phase, responses_of,
                           window_words)
    from ..lab.modal import MIN_DECAY_TIMES, chart, modes, unresolved_words
    from ..present.figures import frf_figure, save, stabilisation_chart

    if args.f_max is not None and args.f_min >= args.f_max:
        raise ParameterError(f"--f-min {args.f_min:g} Hz must be below --f-max {args.f_max:g} Hz")
    path = Path(args.file)
    record = read_record(args, args.file)
    meta = record.attrs.get("meta", {})
    uff.check_settings(Path(args.file), meta, records=len(args.response) or sum(
        str(c).startswith(("accel", "strain")) for c in record.columns))
    check_window(args.file, record, args.skip_s)
    force = args.force or reference_of(meta.get("drive"))
    if force not in record.columns:
        raise ParameterError(f"--force {force}: {args.file} has no such channel (its channels: "
                             f"{', '.join(map(str, record.columns))})")
    window = args.window or default_window(meta.get("drive"))
    t = record.index.to_numpy()
    length = (t[-1] - t[0] - args.skip_s) * len(t) / max(len(t) - 1, 1)    # samples x dt
    segment_s = args.segment_s if args.segment_s is not None else (
        None if window in ("rect", "impact") else DEFAULT_SEGMENT_S)
    if segment_s is not None and segment_s > length * (1 + 1e-9):
        raise ParameterError(f"--segment-s {segment_s:g}: longer than {args.file} after "
                             f"--skip-s; allowed: (0, {length:g}] s")
    out = check_output_dir("--out", args.out or RESULTS / "frf" / path.stem)
    table = frf(record, args.response or None, force=force, segment_s=segment_s,
                skip_s=args.skip_s, window=window)
    responses = responses_of(table)
    if args.f_max is not None and args.f_max > table.attrs["band_hz"]:
        raise ParameterError(f"--f-max {args.f_max:g} Hz: above {args.file}'s valid band; "
                             f"allowed: (--f-min, {table.attrs['band_hz']:g}] Hz")
    poles = chart(table, responses, args.f_min, args.f_max, args.order)
    found = modes(table, poles)
    notes = unresolved_words(found)
    described = (f"# H1, H2 and coherence of {', '.join(responses)} against {force}, "
                 f"0-{table.attrs['band_hz']:g} Hz (the record's valid band); window: "
                 f"{window_words(table)}\n")
    band = f"{poles.attrs['band_lo_hz']:g}-{poles.attrs['band_hi_hz']:g} Hz"
    with staged_output(out) as stage:
        with open(stage / "frf.csv", "w") as f:
            f.write(described)
            magnitude_phase(table).to_csv(f)
        found.to_csv(stage / "modes.csv", index=False)
        (stage / "modes.md").write_text(
            f"# Modes of {path.name} (H1 of {', '.join(responses)} against {force})\n\n"
            f"LSCF (sdypy-EMA) over {band}, model orders 2-{2 * poles.attrs['orders']}, read from the "
            f"stabilisation chart (stabilisation.png); {window_words(table)}. f_hz in Hz; zeta "
            f"the damping ratio, measured where the record spans at least {MIN_DECAY_TIMES:g} "
            f"of the mode's decay times (decay_times); contribution: the mode's largest share "
            f"of a response's largest |H1|.\n\n"
            + found.to_markdown(index=False, floatfmt=".4g") + "\n"
            + "".join(f"\n- {n}" for n in notes) + ("\n" if notes else ""))
        save(frf_figure(table, responses, f"{path.name}: H1 against {force} ({window} window)",
                        args.f_max, modes=found, f_min=args.f_min), stage / "frf")
        save(stabilisation_chart(poles, table, found, f"{path.name}: stabilisation chart "
                                 f"(LSCF, {band})"), stage / "stabilisation")
        uff.write_frf(stage / "frf.uff", table, responses, force, meta=meta,
                      window=window_words(table))
    print(json_text({"record": args.file, "out": str(out), "force": force, "window": window,
                     "averages": table.attrs["averages"],
                     "exp_tau_s": table.attrs.get("exp_tau_s"),
                     "window_words": window_words(table), "band_hz": table.attrs["band_hz"],
                     "resolution_hz": float(table.index[1]), "uff": str(out / "frf.uff"),
                     "figures": [str(out / f"{name}.png") for name in ("frf", "stabilisation")],
                     "modes": found.to_dict("records"), "notes": notes}))
    return EXIT_OK


def _cmd_estimate(args) -> int:
    from ..lab.estimate import FITTABLE, check_start, estimate, fit
    from ..lab.matching import setup_from

    start = pair_numbers(args.fit, "--fit", "START", 0, lo_open=True)
    unknown = sorted(set(start) - set(FITTABLE))
    if unknown:
        raise ParameterError(f"--fit {', '.join(cut(u) for u in unknown)}: not fittable; "
                             f"fittable are {', '.join(FITTABLE)}")
    bounds = _bounds(args.bounds, start)
    check_start(start, bounds)
    if args.out:
        check_output_file("--out", args.out, (".csv",))
    if args.paper:
        if args.files:
            raise ParameterError(f"--paper fits the paper's observations, not files: leave out "
                                 f"{cut(Path(args.files[0]).name)}")
        if shortcut_drive(args) or args.force_n is not None or args.skip_s:
            raise ParameterError("--paper sets its own drives and windows (the 20 Hz sine and the "
                                 "5-65 Hz chirp): leave out the drive options and --skip-s")
        from ..present.observed import misses, paper_targets
        targets = paper_targets(parameters_of(args), *args.paper, initial=args.initial)
        result = fit(targets, start, bounds=bounds, jobs=args.jobs, max_nfev=args.max_nfev,
                     fd_step=args.fd_step)
    else:
        if not args.files:
            raise ParameterError("estimate needs records to fit (FILE...), or --paper")
        if args.initial != "static":
            raise ParameterError(f"--initial {args.initial}: only with --paper (a record's "
                                 "start is its own)")
        base = with_option(f"--params {args.params}", Parameters.from_toml, args.params) \
            if args.params else None
        recorded = []
        for path in args.files:
            record = read_record(args, path)
            check_window(path, record, args.skip_s)
            recorded.append((record, setup_from(record_settings(args, record.attrs["meta"]), record,
                                             base)))
        result = estimate(recorded, start, skip_s=args.skip_s, bounds=bounds, jobs=args.jobs,
                          max_nfev=args.max_nfev, fd_step=args.fd_step)
    if args.out:
        result.table().to_csv(args.out, index=False)
    out = {"values": result.values, "intervals_2sigma": result.intervals, "cost": result.cost,
           "simulations": result.n_simulations, "success": result.success,
           "message": result.message, "wall_s": round(result.wall_s, 1)}
    if args.paper:
        out["misses"] = dict(misses(result))
        out["all_observations_hold"] = not out["misses"]
    print(json_text(out))
    return EXIT_OK if result.success else EXIT_NOT_CONVERGED


def _bounds(items: list[str], start: dict) -> dict:
    """--bounds NAME=LO:HI of fitted parameters (CGS; force_n in N)."""
    out = {}
    for name, text in pairs(items, "--bounds", "LO:HI").items():
        if name not in start:
            raise ParameterError(f"--bounds {cut(name)}: not a parameter given by --fit")
        try:
            lo, hi = (float(v) for v in text.split(":"))
        except ValueError:
            raise ParameterError(f"--bounds {cut(name)}={cut(text)}: give LO:HI, two numbers") from None
        if not 0.0 < lo < hi:
            raise ParameterError(f"--bounds {cut(name)}={cut(text)}: need 0 < LO < HI")
        out[name] = (lo, hi)
    return out


def _paper_forces(text: str) -> tuple[float, float]:
    try:
        sine_n, chirp_n = (float(v) for v in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: give SINE_N:CHIRP_N, two forces in N") from None
    if not (0.0 < sine_n <= MAX_FORCE_N and 0.0 < chirp_n <= MAX_FORCE_N):
        raise argparse.ArgumentTypeError(f"{text!r}: each force within (0, {MAX_FORCE_N:g}] N")
    return sine_n, chirp_n


def add_parsers(sub) -> None:
    """Add this module's sub-commands to the parser's ``sub``."""
    compare = sub.add_parser("compare", help="a measurement file against the matching simulation")
    compare.add_argument("file", help="a .lvm or tab-delimited record (Table 2 channels)")
    add_record_options(compare)
    compare.add_argument("--threshold", type=number(0, lo_open=True), default=0.5,
                         help="contact patch voltage that counts as touched (V)")
    compare.add_argument("--out", help="output folder (default results/compare/<file stem>)")
    compare.set_defaults(func=_cmd_compare)

    fr = sub.add_parser("frf", help="H1, H2 and coherence of a record or a run against its force")
    fr.add_argument("file", help="a record (.lvm .txt .tdms .uff .parquet), e.g. of workbench run --out")
    fr.add_argument("--force", default=None, help="the force channel (default: the hammer in an "
                    "impact test's record, else force1)")
    fr.add_argument("--window", choices=("hann", "rect", "impact"), default=None,
                    help="hann: Welch's Hann segments (a sine, noise); rect: one record-long "
                    "rectangular segment (a chirp); impact: force and exponential windows on one "
                    "hit, the damping corrected (default by the record's drive: hammer impact, "
                    "chirp rect, else hann)")
    fr.add_argument("--response", action="append", default=[],
                    help="a response channel, repeatable (default: every accel and strain)")
    fr.add_argument("--segment-s", type=number(0, lo_open=True), default=None,
                    help="Welch segment (s): the frequency resolution is 1/segment (default 2 "
                    "with the Hann window, the whole record with rect and impact)")
    fr.add_argument("--skip-s", type=number(0), default=0.0, help="leave out the first seconds")
    fr.add_argument("--f-min", type=number(0), default=0.0,
                    help="lower end of the band the modes are fitted in (Hz)")
    fr.add_argument("--f-max", type=number(0, lo_open=True), default=None,
                    help="upper end of the band shown and fitted (Hz; default the record's "
                    "valid band, 0.4 of its sample rate)")
    fr.add_argument("--order", type=number(2, 200, integer=True), default=None,
                    help="highest model order of the LSCF fit: orders 2, 4, ... 2 x ORDER "
                    "(default 40, lab.modal.ORDER, or a quarter of the band's frequency lines if "
                    "fewer)")
    fr.add_argument("--strain-scale", metavar="CHANNEL=K", action="append", default=[],
                    help="scale factor of a strain channel recorded in V (strain per volt)")
    add_format_option(fr)
    fr.add_argument("--out", help="output folder (default results/frf/<file stem>)")
    fr.set_defaults(func=_cmd_frf)

    conv = sub.add_parser("convert", help="write a record in another format (.lvm .txt .tdms .uff .parquet)")
    conv.add_argument("source", help="the record to read")
    conv.add_argument("target", help="the file to write (its format by its suffix or --to)")
    add_format_option(conv, "--from", "source_format", "the source's format")
    add_format_option(conv, "--to", "target_format", "the target's format")
    conv.add_argument("--strain-scale", metavar="CHANNEL=K", action="append", default=[],
                      help="scale factor of a strain channel recorded in V (strain per volt)")
    conv.set_defaults(func=_cmd_convert)

    est = sub.add_parser("estimate", help="fit model parameters to measurement files, or to the "
                         "paper's observations (§7.2)")
    est.add_argument("files", nargs="*", help="records (.lvm or tab-delimited)")
    est.add_argument("--fit", metavar="NAME=START", action="append", required=True,
                     help="a parameter to fit and its start (CGS; force_n in N), repeatable; "
                          "fittable: e_a, e_b, zeta_a, zeta_b, mu, cork_k, cork_c, force_n, "
                          "force_gain (a factor on every drive's force)")
    est.add_argument("--bounds", metavar="NAME=LO:HI", action="append", default=[],
                     help="the range searched for a fitted parameter (default: wide, "
                          "workbench/lab/estimate.py FITTABLE)")
    est.add_argument("--paper", type=_paper_forces, metavar="SINE_N:CHIRP_N",
                     help="fit to the paper's §6 observations instead of files: switching "
                          "between 14 and 23 and the 10 Hz subharmonic on the 20 Hz sine at "
                          "SINE_N, the bands near 0.83, 1.67 and 3 min on the 240 s chirp at "
                          "CHIRP_N (workbench/present/observed.py)")
    est.add_argument("--initial", choices=("static", "paper"), default="static",
                     help="with --paper: the runs' start")
    est.add_argument("--fd-step", type=number(0, 1, lo_open=True), default=0.02,
                     help="the Jacobian's relative difference step (default 0.02)")
    add_record_options(est)
    add_jobs_option(est, "worker processes")
    est.add_argument("--max-nfev", type=number(1, 100000, integer=True), default=30, help="most residual evaluations")
    est.add_argument("--out", metavar="FILE.csv", help="write the fitted values")
    est.set_defaults(func=_cmd_estimate)
