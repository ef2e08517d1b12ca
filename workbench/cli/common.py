"""What the sub-commands share: exit codes, the results root, option types and
groups, the model and drive settings the options give, and JSON output.

Every check here names the option as the user wrote it (``--set gap_mm=9``);
the values' rules come from the registries (:mod:`workbench.model.params`,
:mod:`workbench.model.drives`).
"""
from __future__ import annotations

import argparse
import difflib
import json
import math
from pathlib import Path

from ..model.limits import MAX_FORCE_N
from ..model.params import CORK_MODELS, ParameterError, Parameters


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


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors raised (not printed with the usage and exited), naming
    the sub-command, and for an unknown option the nearest ones the command knows."""

    def error(self, message):
        command = self.prog.split(" ", 1)[1] + ": " if " " in self.prog else ""
        if message.startswith("unrecognized arguments:"):
            near = [m for word in message.split(":", 1)[1].split() if word.startswith("--")
                    for m in difflib.get_close_matches(word.split("=")[0], self.options(), 2, 0.7)]
            if near:
                message += f" (did you mean {' or '.join(dict.fromkeys(near))}?)"
        raise ParameterError(f"{command}{message}")

    def parse_args(self, args=None, namespace=None):
        """argparse's, but an unknown option is reported by the sub-command given, so that
        the options it suggests are that command's."""
        known, extras = self.parse_known_args(args, namespace)
        if extras:
            subs = [a for a in self._actions if isinstance(a, argparse._SubParsersAction)]
            command = getattr(known, subs[0].dest, None) if subs else None
            owner = subs[0].choices.get(command, self) if subs else self
            owner.error(f"unrecognized arguments: {' '.join(extras)}")
        return known

    def options(self) -> list[str]:
        """Every option string of this parser and its sub-commands."""
        found = list(self._option_string_actions)
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                for sub in action.choices.values():
                    found += sub.options() if isinstance(sub, Parser) else []
        return found


def number(lo=None, hi=None, lo_open=False, hi_open=False, integer=False):
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


def cut(text: str, n: int = 24) -> str:
    """``text`` cut to n characters for a message."""
    return text if len(text) <= n else text[:n - 3] + "..."


def with_option(option: str, call, *args, **kwargs):
    """call(*args, **kwargs), a ParameterError prefixed with the option as the user wrote it."""
    try:
        return call(*args, **kwargs)
    except ParameterError as exc:
        raise ParameterError(f"{option}: {exc}") from None


def on_off(text: str) -> bool:
    if text in ("on", "off"):
        return text == "on"
    raise argparse.ArgumentTypeError(f"must be 'on' or 'off', got {text!r}")


def toml_value(text: str):
    """A --set value: a TOML scalar (number, true/false, "string") or a bare word."""
    import tomllib
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def pairs(items: list[str], option: str, what: str = "VALUE") -> dict[str, str]:
    """Repeated ``--option NAME=VALUE`` arguments as {name: text}."""
    out = {}
    for item in items:
        name, sep, text = item.partition("=")
        if not sep:
            raise ParameterError(f"{option} expects NAME={what}, got {item!r}")
        out[name.strip()] = text.strip()
    return out


def pair_numbers(items, option, what, lo=None, lo_open=False) -> dict[str, float]:
    """Repeated ``--option NAME=NUMBER`` as {name: number}; a bad number names the item."""
    parse = number(lo, lo_open=lo_open)
    out = {}
    for name, text in pairs(items, option, what).items():
        try:
            out[name] = parse(text)
        except argparse.ArgumentTypeError as exc:
            raise ParameterError(f"{option} {cut(name)}={cut(text)}: {exc}") from None
    return out


def add_model_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--params", metavar="FILE.toml", help="parameters from a TOML file")
    parser.add_argument("--set", metavar="NAME=VALUE", action="append", default=[],
                        help="set one parameter (repeatable), e.g. --set gap_mm=0.762")
    default = Parameters()
    parser.add_argument("--tip-mass", type=on_off, metavar="on|off",
                        help=f"attach the tip mass (default {'on' if default.tip_mass else 'off'})")
    parser.add_argument("--cork", choices=sorted(CORK_MODELS),
                        help=f"cork model (docs/model.md §6; default {default.cork})")


def parameters_of(args) -> Parameters:
    """The model of --params, --set and the model options (--tip-mass, --cork, --gap-mm, --mu).

    Each value is checked alone first, so that the message names the option
    the user wrote; a parameter given twice (``--set cork=linear --cork
    none``) is refused.
    """
    from ..model.params import resolve_name
    base = with_option(f"--params {args.params}", Parameters.from_toml, args.params) \
        if args.params else Parameters()
    given = [(f"--set {cut(name)}={cut(text)}", name, toml_value(text))
             for name, text in pairs(args.set, "--set").items()]
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
        field = with_option(label, resolve_name, name)[0]
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
    from ..model.modes import linear_eigenvalues
    linear_eigenvalues(p)


def chirp_spec(text: str) -> tuple[float, float, float]:
    parts = text.split(":")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"expects F0:F1:T (Hz:Hz:s), got {text!r}")
    positive = number(0, lo_open=True)
    try:
        return tuple(positive(x) for x in parts)
    except argparse.ArgumentTypeError as exc:
        raise argparse.ArgumentTypeError(f"{text!r}: {exc} (F0:F1:T, each > 0)") from None


def shortcut_drive(args) -> dict | None:
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
        return drive_settings(args)
    return None


def add_drive_options(parser, ramp_help="soft-start ramp of sine/chirp (s)") -> None:
    from ..model import drives
    drive = parser.add_argument_group("excitation (one; default none)")
    drive.add_argument("--freq-hz", type=number(0, lo_open=True), help="sine at force1, frequency (Hz)")
    drive.add_argument("--chirp", type=chirp_spec, metavar="F0:F1:T", help="linear chirp F0 -> F1 Hz over T s")
    drive.add_argument("--free-decay", type=number(), metavar="CM",
                       help="release from a static tip deflection (cm, + up)")
    drive.add_argument("--impulse", choices=("joint", "tip"),
                       help="half-sine hammer: vertical at the joint body, or axial at the tip")
    drive.add_argument("--force-n", type=number(-MAX_FORCE_N, MAX_FORCE_N),
                       help=f"shaker amplitude or hammer peak (N; default "
                            f"{drives.DEFAULT_FORCE_N:g} for a shaker, "
                            f"{drives.DEFAULT_HAMMER_N:g} for a hammer)")
    drive.add_argument("--ramp-s", type=number(0), help=ramp_help)
    drive.add_argument("--pulse-s", type=number(0, lo_open=True), default=drives.DEFAULTS["width_s"],
                       help=f"hammer pulse duration (s; default {drives.DEFAULTS['width_s']:g})")
    drive.add_argument("--hit-s", type=number(0), default=drives.DEFAULTS["t_hit_s"],
                       help=f"hammer pulse start (s; default {drives.DEFAULTS['t_hit_s']:g})")
    drive.add_argument("--drive", metavar="KIND",
                       help="any registered drive (workbench/model/drives.py), set by --drive-set")
    drive.add_argument("--drive-set", metavar="KEY=VALUE", action="append", default=[],
                       help="a setting of --drive in its units (e.g. freq_hz=20), repeatable")


def drive_settings(args) -> dict:
    """The settings {"drive": ..., key: value} of ``--drive`` and its ``--drive-set`` pairs."""
    from ..model import drives
    drive = drives.get(args.drive, where="--drive")
    given = pair_numbers(args.drive_set, "--drive-set", "VALUE")
    unknown = sorted(set(given) - set(drive.keys))
    if unknown:
        raise ParameterError(f"--drive-set {cut(unknown[0])}: not a setting of --drive "
                             f"{drive.name} (its settings: {', '.join(drive.keys) or 'none'})")
    return drives.complete(drive.name, given, lambda key: f"--drive {drive.name} needs "
                           f"--drive-set {key}=VALUE ({drives.UNITS[key]})",
                           duration_s=getattr(args, "duration", None))


def _field_of(name: str):
    """The parameter field a setting's name stands for, or None if it names none."""
    from ..model.params import ParameterError, resolve_name
    try:
        return resolve_name(name)[0]
    except ParameterError:
        return None


def record_settings(args, meta: dict) -> dict:
    """A record's settings (matching.py): the file's, overridden by the command line."""
    from ..model import drives

    from ..model.params import resolve_name

    settings = dict(meta)
    given = {"gap_mm": args.gap_mm, "tip_mass": args.tip_mass, "cork": args.cork}
    overrides = {k: v for k, v in given.items() if v is not None}
    if args.mu is not None:
        overrides.update(mu_s=args.mu, mu_k=args.mu)
    overrides.update({name: toml_value(text) for name, text in pairs(args.set, "--set").items()})
    for key in overrides:      # an option replaces the file's value of the same parameter
        field = with_option(key, resolve_name, key)[0]
        for old in [k for k in settings if k not in drives.all_keys() and k != "drive"
                    and _field_of(k) == field]:
            settings.pop(old)
    settings.update(overrides)
    drive = shortcut_drive(args)
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


def strain_scale(args) -> dict[str, float]:
    scale = pair_numbers(args.strain_scale, "--strain-scale", "STRAIN_PER_VOLT", 0, lo_open=True)
    return {name.lower(): value for name, value in scale.items()}


def read_record(args, path):
    from ..lab import files
    return files.read(path, strain_scale(args), files.format_of(path, args.format))


def parameter_number(name: str):
    """An argparse type for a model parameter given as ``name`` (its unit suffix, if any):
    the parameter's own allowed range, so that every message states one range."""
    from ..model.params import FIELDS, resolve_name
    field, to_cgs = resolve_name(name)
    meta = FIELDS[field].metadata
    lo = None if meta["lo"] is None else meta["lo"] / to_cgs
    hi = None if meta["hi"] is None else meta["hi"] / to_cgs
    return number(lo, hi, lo_open=meta["lo_open"], hi_open=meta["hi_open"])


def add_joint_options(parser) -> None:
    default = Parameters()
    parser.add_argument("--gap-mm", type=parameter_number("gap_mm"),
                        help=f"total transverse clearance (mm; default {default.gap * 10:g})")
    parser.add_argument("--mu", type=parameter_number("mu_s"),
                        help=f"friction coefficient (sets mu_s = mu_k; default {default.mu_s:g})")


def add_record_options(parser) -> None:
    add_model_options(parser)
    add_joint_options(parser)
    add_drive_options(parser)
    parser.add_argument("--strain-scale", metavar="CHANNEL=K", action="append", default=[],
                        help="scale factor of a strain channel recorded in V (strain per volt)")
    parser.add_argument("--skip-s", type=number(0), default=0.0,
                        help="leave out the first seconds (the transient)")
    add_format_option(parser)


def add_jobs_option(parser, what: str) -> None:
    parser.add_argument("--jobs", type=number(1, 256, integer=True), default=2,
                        help=f"{what} (default 2)")


def add_format_option(parser, option="--format", dest="format", what="the file's format") -> None:
    from ..lab.files import FORMATS
    parser.add_argument(option, dest=dest, choices=tuple(FORMATS),
                        help=f"{what} (default: by its suffix)")


def check_window(path, record, skip_s: float) -> None:
    """--skip-s leaves at least two samples of the record."""
    t = record.index.to_numpy()
    if len(t) < 2 or t[-1] - t[0] <= skip_s:
        raise ParameterError(f"--skip-s {skip_s:g}: {path} lasts {t[-1] - t[0]:g} s; leave "
                             "less out than that")


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
