"""Tables of the newest ``make bench`` JSON (pytest-benchmark autosave) for docs/performance.md.

    python benchmarks/summarise.py [--json FILE] [--readme docs/performance.md] [--out FILE]

Prints Markdown; ``--out`` writes it to a file; ``--readme`` replaces the
part of that file between the markers ``<!-- bench:start -->`` and
``<!-- bench:end -->``.  Every figure is a median of the saved rounds.  Each
benchmark is taken from the newest saved run that has it (a partial run,
``pytest benchmarks/test_bench_reference.py ...``, updates its tables only);
each table names its run, and a table's ratios come from one run.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
START, END = "<!-- bench:start -->", "<!-- bench:end -->"


def saved_runs() -> list[Path]:
    files = sorted((ROOT / ".benchmarks").glob("*/*.json"))
    if not files:
        raise SystemExit("no saved benchmark run under .benchmarks/: run `make bench` first")
    return files


def newest_by_name(paths: list[Path]) -> tuple[dict, dict]:
    """{benchmark name: its newest entry} (each entry notes its file) and the newest run's header."""
    out, header = {}, {}
    for path in paths:                          # oldest first: newer runs override
        data = json.loads(path.read_text())
        header = data
        for b in data["benchmarks"]:
            b["source"] = path.name
            out[b["name"]] = b
    return out, header


def _median(b) -> float:
    return b["stats"]["median"]


def _fmt(x, digits=3) -> str:
    return f"{x:.{digits}g}" if isinstance(x, (int, float)) else str(x)


def rhs_table(b) -> list[str]:
    rows = ["| right-hand side | µs per evaluation |", "|---|---|"]
    labels = {"test_rhs_evaluation[locked]": "free flight, joint locked (6 DOF)",
              "test_rhs_evaluation[9dof]": "free flight, 9 DOF (`rhs`)"}
    for name, bench in b.items():
        if name.startswith("test_rhs_regime_evaluation["):
            labels[name] = "regime: " + name.split("[")[1].rstrip("]")
    for name, label in labels.items():
        if name in b:
            per = _median(b[name]) / b[name]["extra_info"]["calls_per_round"] * 1e6
            rows.append(f"| {label} | {per:.2f} |")
    return rows


def runs_table(b) -> list[str]:
    rows = ["| run | workbench wall (s) | simulated s per wall s | reference (LSODA rtol 1e-8) "
            "wall per simulated s | ratio | events |", "|---|---|---|---|---|---|"]
    refs = {"sine": b.get("test_accuracy_reference[1e-08]"),
            "chirp": b.get("test_reference_window[chirp]")}
    for key, ref in refs.items():
        whole = b.get(f"test_whole_run[{key}]")
        if whole is None:
            continue
        info = whole["extra_info"]
        wall = _median(whole)
        per_kernel = wall / info["simulated_s"]
        ref_cell, ratio = "-", "-"
        if ref is not None:
            per_ref = _median(ref) / ref["extra_info"]["window_s"]
            ref_cell = f"{per_ref:.1f} ({ref['extra_info']['window_s']:.2f} s window)"
            ratio = f"{per_ref / per_kernel:.0f}×"
        rows.append(f"| {info['case']} (dt {info['dt']:g} s) | {wall:.2f} | "
                    f"{info['simulated_s'] / wall:.1f} | {ref_cell} | {ratio} | {info['n_events']} |")
    return rows


def accuracy_table(b) -> list[str]:
    rows = ["| solver | step or rtol | wall per simulated s (s) | tip height error (of its range) "
            "| contact share error | RHS evaluations |", "|---|---|---|---|---|---|"]
    entries = [v for k, v in b.items() if k.startswith(("test_accuracy_kernel[",
                                                        "test_accuracy_reference["))]
    converged = None
    for bench in entries:
        info = bench["extra_info"]
        mark = " (default)" if info.get("default") else ""
        rows.append(f"| {info['solver']} | {info['setting']:g}{mark} | "
                    f"{_median(bench) / info['window_s']:.3g} | {info['tip_error_rel']:.1e} | "
                    f"{info['share_error']:.1e} | {info['nfev'] or '-'} |")
        converged = info
    if converged:
        rows.append("")
        rows.append(f"Converged solution: RK4 at 3.125e-6 s; against half that step it differs "
                    f"by {converged['converged_tip_error_rel']:.1e} (tip) and "
                    f"{converged['converged_share_error']:.1e} (shares).")
    return rows


def compile_table(b) -> list[str]:
    rows = ["| fresh process | process wall (s) | imports (s) | first 10 s run (s) |",
            "|---|---|---|---|"]
    for cache in ("cold", "warm"):
        bench = b.get(f"test_first_run_in_a_fresh_process[{cache}]")
        if bench:
            info = bench["extra_info"]
            label = "no cache (compiles)" if cache == "cold" else "warm cache"
            rows.append(f"| {label} | {_median(bench):.1f} | {info['import_s']:.2f} | "
                        f"{info['first_run_s']:.2f} |")
    return rows


def scaling_table(b) -> list[str]:
    rows = ["| workers | wall (s) | points | speed-up |", "|---|---|---|---|"]
    one = b.get("test_sweep_scaling[1]")
    for jobs in (1, 2):
        bench = b.get(f"test_sweep_scaling[{jobs}]")
        if bench:
            speed = _median(one) / _median(bench) if one else float("nan")
            rows.append(f"| {jobs} | {_median(bench):.0f} | {bench['extra_info']['points']} | "
                        f"{speed:.2f} |")
    return rows


def summary(paths: list[Path]) -> str:
    b, data = newest_by_name(paths)
    machine = data.get("machine_info", {})
    parts = [f"Measured by `make bench` ({machine.get('cpu', {}).get('brand_raw', '?')}, "
             f"{machine.get('cpu', {}).get('count', '?')} cores); JSON in `.benchmarks/`.", ""]
    for title, table in (("Cost of one right-hand side", rhs_table(b)),
                         ("Whole runs against the paper's method", runs_table(b)),
                         ("Accuracy against cost (sine window)", accuracy_table(b)),
                         ("Compilation", compile_table(b)),
                         ("Scaling: the default study's grid, 2 s per point", scaling_table(b))):
        if len(table) > 2:
            parts += [f"**{title}** ({_sources(b, title)})", "", *table, ""]
    return "\n".join(parts)


_TABLE_PREFIXES = {"Cost": ("test_rhs",), "Whole": ("test_whole_run", "test_reference_window",
                                                    "test_accuracy_reference[1e-08]"),
                   "Accuracy": ("test_accuracy",), "Compilation": ("test_first_run",),
                   "Scaling": ("test_sweep_scaling",)}


def _sources(b, title) -> str:
    prefixes = _TABLE_PREFIXES[title.split()[0].rstrip(":")]
    names = sorted({v["source"] for k, v in b.items() if k.startswith(prefixes)})
    return "run " + ", ".join(f"`{n.split('_')[0]}`" for n in names)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, nargs="*", default=None,
                    help="saved runs to read, oldest first (default: all under .benchmarks/)")
    ap.add_argument("--readme", type=Path, default=None)
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args(argv)
    text = summary(args.json or saved_runs())
    if args.out:
        args.out.write_text(text + "\n")
    if args.readme:
        readme = args.readme.read_text()
        if START not in readme or END not in readme:
            raise SystemExit(f"{args.readme} has no {START} ... {END} section")
        head, rest = readme.split(START, 1)
        _, tail = rest.split(END, 1)
        args.readme.write_text(f"{head}{START}\n{text}\n{END}{tail}")
    print(text)


if __name__ == "__main__":
    main()
