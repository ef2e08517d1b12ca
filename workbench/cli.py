"""The ``workbench`` command line.

    workbench modes [--tip-mass on|off] [--joint locked|free] [--cork MODEL] [--json]
    workbench params [--json]

Every subcommand accepts ``--params FILE.toml`` and ``--set NAME=VALUE``
(repeatable; unit-suffixed names such as ``gap_mm`` are converted).
"""
from __future__ import annotations

import argparse
import json
import sys

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


def _add_model_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--params", metavar="FILE.toml", help="parameters from a TOML file")
    parser.add_argument("--set", metavar="NAME=VALUE", action="append", default=[],
                        help="set one parameter (repeatable), e.g. --set gap_mm=0.762")
    parser.add_argument("--tip-mass", type=_on_off, metavar="on|off", help="attach the tip mass")
    parser.add_argument("--cork", choices=sorted(CORK_MODELS), help="cork model (MODEL.md §6)")


def _parameters(args) -> Parameters:
    p = Parameters.from_toml(args.params) if args.params else Parameters()
    changes = {}
    for item in args.set:
        name, sep, text = item.partition("=")
        if not sep:
            raise ParameterError(f"--set expects NAME=VALUE, got {item!r}")
        changes[name.strip()] = _value(text.strip())
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
