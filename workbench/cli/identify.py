"""``workbench identify``: the paper's parameter identification (§4, Appendices A-C)."""
from __future__ import annotations


from ..study.paths import check_output_dir
from .common import (EXIT_OK, RESULTS, add_jobs_option, add_model_options, json_text, parameters_of)


def _cmd_identify_tables(args) -> int:
    from ..identify import tables

    check_output_dir("--out", args.out)
    built = tables.build(include_table6=not args.no_table6, jobs=args.jobs)
    paths = tables.write(built, args.out)
    agree = {title: dict(t.agrees.value_counts()) for title, t in built.items()}
    print(json_text({"markdown": str(paths["md"]), "latex": str(paths["tex"]),
                      "agreement": {k: {str(a): int(n) for a, n in v.items()} for k, v in agree.items()}}))
    return EXIT_OK


def _cmd_identify_decrement(args) -> int:
    from ..identify import log_decrement

    beam = {}
    if args.beam is not None:
        length, _, inertia, mu = parameters_of(args).beam(args.beam)
        beam = dict(mu=mu, length=length, area_moment=inertia)
    d = log_decrement(args.x1, args.xn, args.t1, args.tn, args.n, **beam)
    print(json_text({**d._asdict(), "E_gpa": d.E_gpa}))
    return EXIT_OK


def add_parsers(sub) -> None:
    """Add this module's sub-commands to the parser's ``sub``."""
    ident = sub.add_parser("identify", help="the paper's parameter identification (§4)")
    isub = ident.add_subparsers(dest="what", required=True)
    tab = isub.add_parser("tables", help="Tables 3-6 and Appendix B from their raw inputs")
    tab.add_argument("--out", default=str(RESULTS / "identification"),
                     help="output folder (default results/identification)")
    tab.add_argument("--no-table6", action="store_true", help="skip Table 6's fits (~40 s)")
    add_jobs_option(tab, "processes running Table 6's fits")
    tab.set_defaults(func=_cmd_identify_tables)
    dec = isub.add_parser("decrement", help="Td, zeta, omega_n (and EI, E) from two peaks")
    for name, kind_, text in (("x1", float, "first peak"), ("xn", float, "n-th peak"),
                              ("t1", float, "time of the first (s)"), ("tn", float, "time of the n-th (s)"),
                              ("n", int, "number of peaks")):
        dec.add_argument(name, type=kind_, help=text)
    dec.add_argument("--beam", choices=("a", "b"), help="give EI and E with this beam's mu, L, I")
    add_model_options(dec)
    dec.set_defaults(func=_cmd_identify_decrement)
