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

One module per group of sub-commands (:mod:`.simulation`: run, modes,
params, compile; :mod:`.studies`: sweep, report; :mod:`.records`: convert,
compare, frf, estimate; :mod:`.identify`), each adding its parsers
(``add_parsers``); :mod:`.common` holds what they share: option types and
groups, the settings the options give, JSON output and the exit codes.

Exit codes (:data:`EXIT_CODES`): 0 done; 1 a simulation ended with a
failure status (what it computed is still written); 2 bad input, refused
before any work, in one line naming the option or key as written; 3 a sweep
ran but some points failed; 4 an estimate's fit did not converge; 70 an internal error (a bug of ours: one line,
the traceback in a file named there); 130 interrupted.
"""
from __future__ import annotations

import argparse
import gc
import os
import sys
import time
import traceback
from pathlib import Path

from .. import __version__
from ..model.params import ParameterError
from . import identify, records, simulation, studies
from .common import (EXIT_BAD_INPUT, EXIT_CODES, EXIT_INTERNAL, EXIT_INTERRUPTED, EXIT_NOT_CONVERGED,
                     EXIT_OK, EXIT_POINTS_FAILED, EXIT_RUN_FAILED, RESULTS, Parser, json_text)

__all__ = ["EXIT_BAD_INPUT", "EXIT_CODES", "EXIT_INTERNAL", "EXIT_INTERRUPTED", "EXIT_NOT_CONVERGED",
           "EXIT_OK", "EXIT_POINTS_FAILED", "EXIT_RUN_FAILED", "RESULTS", "build_parser", "entry",
           "json_text", "main"]


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="workbench", description="Loose bolted lap joint workbench (9-DOF Gibbs-Appell model).")
    parser.add_argument("--version", action="version", version=f"workbench {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for module in (simulation, studies, records, identify):
        module.add_parsers(sub)
    return parser


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
