"""``workbench sweep``, ``report`` and ``advise``: a study's grid, in parallel and resumably
(on joblib or a Dask cluster), its figures, tables and report, and the advice a damage map
gives (study/advice.py)."""
from __future__ import annotations

from pathlib import Path

from ..model.params import ParameterError
from ..study.paths import check_output_dir
from .common import (EXIT_OK, EXIT_POINTS_FAILED, RESULTS, add_jobs_option, json_text, number,
                     on_off)


def _cmd_sweep(args) -> int:
    from ..study.definition import load
    from ..study.sweep import plan, run_study

    study = load(args.study)
    check_output_dir("--results", args.results)
    if args.scheduler is not None:
        _check_scheduler(args.scheduler)
    if study.continuation is not None:
        return _branches(study, args)
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
        from ..present.report import make_report
        summary["report"] = str(make_report(study, args.results, jobs=args.jobs))
    print(json_text(summary))
    return EXIT_OK if counts.get("ok", 0) == study.n_points else EXIT_POINTS_FAILED


def _branches(study, args) -> int:
    """``workbench sweep`` of a continuation study: its branches (study/branches.py)."""
    import json
    from ..study.branches import label, run_branches
    if args.scheduler is not None:
        raise ParameterError(f"--scheduler {args.scheduler}: a continuation study runs its "
                             "branches on this machine's processes (--jobs)")
    if args.dry_run:
        print(json_text({"study": study.name, "branches": [label(p) for p in study.points],
                         "jobs": min(args.jobs, study.n_points)}))
        return EXIT_OK
    from ..present.branch import write_branch, write_study_report
    table = run_branches(study, write_branch, args.results, jobs=args.jobs, fresh=args.fresh,
                         progress=not args.quiet)
    out = Path(args.results) / study.name
    write_study_report(study, out.resolve(), table, Path(args.results).resolve())
    summaries = {label(p): json.loads((out / label(p) / "summary.json").read_text())
                 for p in study.points}
    ends = {k: s["status"] for k, s in summaries.items()}
    print(json_text({"study": study.name, "branches": ends, "results": str(out),
                     "report": str(out / "report.md")}))
    return EXIT_OK if all(v.startswith("done") for v in ends.values()) else EXIT_POINTS_FAILED


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
    from ..present.report import make_report
    from ..study.definition import load

    study = load(args.study)
    if study.continuation is not None:
        from ..present.branch import write_study_report
        from ..study.branches import collect
        from ..study.store import write_atomic
        out = Path(args.results).resolve() / study.name
        table = collect(study, out)
        write_atomic(table, out / "branches.parquet")        # the table the report links
        print(write_study_report(study, out, table, Path(args.results).resolve()))
        return EXIT_OK
    if not (Path(args.results) / study.name / "points.parquet").is_file():
        raise ParameterError(f"report {args.study}: no results in {Path(args.results) / study.name}"
                             f"; run `workbench sweep {args.study} --results {args.results}` first")
    print(make_report(study, args.results, jobs=args.jobs))
    return EXIT_OK


def _cmd_advise(args) -> int:
    from ..study.advice import ADVICE_MEASURES, advise

    advice = advise(args.results, args.gap_mm, args.freq_hz, args.force_n, args.tip_mass,
                    args.allow_level)
    if args.json:
        print(json_text(advice.to_dict()))
        return EXIT_OK
    units = {name: unit for name, _, unit in ADVICE_MEASURES.values()}

    def measures(values: dict) -> str:
        return ", ".join(f"{k} {values[k]:.3g} {units[k]}" for k in units)

    where = f"{args.gap_mm:g} mm, {args.freq_hz:g} Hz, {args.force_n:g} N"
    lines = [f"here ({where}): {measures(advice.here)}",
             f"regime to avoid (wear volume >= {advice.threshold_mm3:.3g} mm³/cycle): "
             f"{'yes' if advice.avoid else 'no'}"]
    if advice.frequency_change:
        c = advice.frequency_change
        lines.append(f"move the frequency by {c['change_hz']:+g} Hz to {c['freq_hz']:g} Hz: "
                     f"{measures(c)}")
    if advice.level_change:
        c = advice.level_change
        lines.append(f"or lower the level by {-c['change_n']:g} N to {c['force_n']:g} N: "
                     f"{measures(c)}")
    lines += [f"note: {n}" for n in advice.notes]
    print("\n".join(lines))
    return EXIT_OK


def add_parsers(sub) -> None:
    """Add this module's sub-commands to the parser's ``sub``."""
    sweep = sub.add_parser("sweep", help="run a study's grid (TOML) in parallel, resumably")
    sweep.add_argument("study", help="study definition, e.g. studies/default.toml")
    add_jobs_option(sweep, "worker processes")
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
    add_jobs_option(report, "processes drawing the figures")
    report.set_defaults(func=_cmd_report)

    adv = sub.add_parser("advise", help="a damage map's advice at a gap, frequency and level: the "
                         "wear here, whether to avoid it, the nearest way out")
    adv.add_argument("--gap-mm", type=number(0, lo_open=True), required=True, help="the gap (mm)")
    adv.add_argument("--freq-hz", type=number(0, lo_open=True), required=True,
                     help="the drive frequency (Hz)")
    adv.add_argument("--force-n", type=number(0, lo_open=True), required=True,
                     help="the drive's force amplitude (N)")
    adv.add_argument("--tip-mass", type=on_off, default=None,
                     help="on or off (needed when the map has both)")
    adv.add_argument("--allow-level", action="store_true",
                     help="also look for a lower level that leaves the regime to avoid")
    adv.add_argument("--results", default=str(RESULTS / "damage"),
                     help="the damage map's folder (default results/damage)")
    adv.add_argument("--json", action="store_true", help="one JSON object")
    adv.set_defaults(func=_cmd_advise)
