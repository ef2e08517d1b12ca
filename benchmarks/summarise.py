"""Tables of the newest ``make bench`` JSON (pytest-benchmark autosave).

    python benchmarks/summarise.py [--json FILE ...] [--readme docs/performance.md]
                                   [--targets README.md] [--out FILE]

Prints Markdown; ``--out`` writes the tables to a file; ``--readme``
replaces the part of that file between the markers ``<!-- bench:start -->``
and ``<!-- bench:end -->`` with them; ``--targets`` replaces the part
between ``<!-- targets:start -->`` and ``<!-- targets:end -->`` with the
table of the speed targets (measured, met or not, run id).  Every figure
is a median of the saved rounds.  Each benchmark is taken from the newest
saved run that has it (a partial run, ``pytest benchmarks/test_bench_runs.py
...``, updates its tables only); each table names its runs.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
START, END = "<!-- bench:start -->", "<!-- bench:end -->"
TARGETS_START, TARGETS_END = "<!-- targets:start -->", "<!-- targets:end -->"


def saved_runs() -> list[Path]:
    files = sorted((ROOT / ".benchmarks").glob("*/*.json"))
    if not files:
        raise SystemExit("no saved benchmark run under .benchmarks/: run `make bench` first")
    return files


def newest_by_name(paths: list[Path]) -> tuple[dict, dict]:
    """{benchmark name: its entry} (each entry notes its file) and the newest run's header.

    Each test function's entries come from the newest run that has it, all of them: a
    parameter an older run had and the newest does not (a former default tolerance) is
    dropped with that run.
    """
    out, header = {}, {}
    for path in paths:                          # oldest first: newer runs override
        data = json.loads(path.read_text())
        header = data
        functions = {b["name"].split("[")[0] for b in data["benchmarks"]}
        out = {k: v for k, v in out.items() if k.split("[")[0] not in functions}
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


WHOLE_CASES = ("sine-tip", "sine-no-tip", "chirp")
WINDOW_CASES = ("sine-tip", "sine-no-tip")


def _run_id(bench) -> str:
    return f"`{bench['source'].split('_')[0]}`"


def whole_table(b) -> list[str]:
    rows = ["| run (defaults: 1.016 mm, 200 N, cubic cork) | method | base step (s) | wall (s), "
            "median | rounds | simulated s per wall s | events |",
            "|---|---|---|---|---|---|---|"]
    for key in WHOLE_CASES:
        for name, method in ((f"test_whole_run[{key}]", "controlled (default)"),
                             (f"test_whole_run_fixed_step[{key}]", "fixed RK4")):
            bench = b.get(name)
            if bench:
                info, wall = bench["extra_info"], _median(bench)
                rows.append(f"| {info['case']} | {method} | {info['dt']:g} | {wall:.2f} | "
                            f"{bench['stats']['rounds']} | {info['simulated_s'] / wall:.1f} | "
                            f"{info['n_events']} |")
    return rows


def _window_rows(b, key) -> list[dict]:
    """The accuracy entries of one case: kernel rows (largest step first), then LSODA's."""
    out = []
    for prefix in ("test_accuracy_kernel", "test_accuracy_controlled", "test_accuracy_lsoda"):
        entries = [v for k, v in b.items() if k.startswith(f"{prefix}[{key}-")]
        entries.sort(key=lambda v: -v["extra_info"]["setting"])
        for bench in entries:
            info = bench["extra_info"]
            out.append({**info, "per_sim_s": _median(bench) / info["window_s"],
                        "rounds": bench["stats"]["rounds"]})
    return out


def lsoda_ratio(b, key) -> tuple[float, str] | None:
    """LSODA's wall over the kernel's (default settings) on a window, at equal accuracy, how
    its tolerance was chosen and its row.

    The cheapest LSODA tolerance whose tip and share errors are both at most
    the kernel's; if none is, the cheapest tolerance tried (each is then
    less accurate than the kernel, so the ratio is a lower bound).  Returns
    (ratio, how it was chosen, LSODA's row).
    """
    rows = _window_rows(b, key)
    own = [r for r in rows if r["solver"].startswith("workbench") and r.get("default")]
    kernel = next((r for r in own if r["solver"] == "workbench controlled"), None) or next(
        iter(own), None)
    lsoda = [r for r in rows if not r["solver"].startswith("workbench")]
    if kernel is None or not lsoda:
        return None
    as_good = [r for r in lsoda if r["tip_error_rel"] <= kernel["tip_error_rel"]
               and r["share_error"] <= kernel["share_error"]]
    if as_good:
        best = min(as_good, key=lambda r: r["per_sim_s"])
        how = f"rtol {best['setting']:g}, the cheapest as accurate as the kernel"
    else:
        best = min(lsoda, key=lambda r: r["per_sim_s"])
        how = (f"rtol {best['setting']:g}, the cheapest; no tolerance tried reached the "
               f"kernel's accuracy, so this is a lower bound")
    return best["per_sim_s"] / kernel["per_sim_s"], how, best


def accuracy_table(b) -> list[str]:
    rows = ["| case | solver | step (s) or rtol | wall per simulated s (s) | tip height error "
            "(of its range) | contact share error | events (converged) | RHS evaluations |",
            "|---|---|---|---|---|---|---|---|"]
    notes = []
    for key in WINDOW_CASES:
        entries = _window_rows(b, key)
        ratio = lsoda_ratio(b, key)
        chosen = ratio[2] if ratio else None
        for info in entries:
            if not (info.get("default") or (chosen is not None and info["solver"] == chosen["solver"]
                                             and info["setting"] == chosen["setting"])):
                continue                # the defaults, and LSODA at equal accuracy
            mark = " (default)" if info.get("default") else ""
            rows.append(f"| {info['case']} | {info['solver']} | {info['setting']:g}{mark} | "
                        f"{info['per_sim_s']:.3g} | {info['tip_error_rel']:.1e} | "
                        f"{info['share_error']:.1e} | {info['n_events']} "
                        f"({info['converged_events']}) | {info['nfev'] or '-'} |")
        if entries:
            info = entries[0]
            notes.append(f"- {info['case']}: window from t = {info['t0']:.3f} s; converged "
                         f"solution RK4 at 3.125e-6 s, against half that step "
                         f"{info['converged_tip_error_rel']:.1e} (tip) and "
                         f"{info['converged_share_error']:.1e} (shares).")
        if ratio:
            notes.append(f"  LSODA's wall over the kernel's at its default settings: "
                         f"**{ratio[0]:.0f}×** ({ratio[1]}).")
    return rows + ([""] + notes if notes else [])


def compile_table(b) -> list[str]:
    rows = ["| fresh process, `workbench run` of the 10 s sine | process wall (s), median | "
            "rounds | of which the run (s) | compiling or loading the kernels (s) | "
            "kernels cached | versions cached | cache (MB) |", "|---|---|---|---|---|---|---|---|"]
    for cache in ("cold", "warm"):
        bench = b.get(f"test_workbench_run_in_a_fresh_process[{cache}]")
        if bench:
            label = "no cache (compiles)" if cache == "cold" else "warm cache"
            info = bench["extra_info"]
            extra = [f"{info['compile_or_load_s']:.2f}", str(info["cache_kernels"]),
                     str(info["cache_versions"]), f"{info['cache_bytes'] / 1e6:.1f}"] \
                if "cache_versions" in info else ["", "", "", ""]
            rows.append(f"| {label} | {_median(bench):.2f} | {bench['stats']['rounds']} | "
                        f"{info['run_wall_s']:.2f} | " + " | ".join(extra) + " |")
    return rows


def scaling_table(b) -> list[str]:
    rows = ["| run | workers | wall (s) | points | speed-up |", "|---|---|---|---|---|"]
    one = b.get("test_sweep_scaling[1]")
    for jobs in (1, 2):
        bench = b.get(f"test_sweep_scaling[{jobs}]")
        if bench:
            speed = _median(one) / _median(bench) if one else float("nan")
            rows.append(f"| the default grid, 1 s per point | {jobs} | {_median(bench):.0f} | "
                        f"{bench['extra_info']['points']} | {speed:.2f} |")
    alone = b.get("test_sensitivity_scaling[joblib-1]")
    for runner, workers in (("joblib", 1), ("joblib", 2), ("dask", 2)):
        bench = b.get(f"test_sensitivity_scaling[{runner}-{workers}]")
        if bench:
            speed = _median(alone) / _median(bench) if alone else float("nan")
            where = "joblib" if runner == "joblib" else "a Dask LocalCluster"
            rows.append(f"| the sensitivity design at n = 4, 3 s per point, on {where} | "
                        f"{workers} | {_median(bench):.0f} | {bench['extra_info']['points']} | "
                        f"{speed:.2f} |")
    study = b.get("test_make_study")
    if study:
        info = study["extra_info"]
        rows.append(f"| `make study` (warm cache, every study, figure and table) | 2 | "
                    f"{_median(study):.0f} | {info['points']} ({info['failed']} failed) | "
                    f"{info['cpu_s'] / _median(study):.2f} (points' wall over the total) |")
    return rows


def targets_table(b) -> list[str]:
    """The speed targets: what was measured, met or not, and the run that measured it."""
    rows = ["| target | measured | met | run |", "|---|---|---|---|"]

    def add(label, bench, text, met):
        if bench is not None:
            rows.append(f"| {label} | {text} | {'yes' if met else '**no**'} | {_run_id(bench)} |")

    for key, label in (("sine-tip", "10 s sine, tip mass: ≥ 30 simulated s per wall s"),
                       ("sine-no-tip", "10 s sine, no tip mass: ≥ 30 simulated s per wall s")):
        bench = b.get(f"test_whole_run[{key}]")
        if bench:
            rate = bench["extra_info"]["simulated_s"] / _median(bench)
            add(label, bench, f"{rate:.1f}", rate >= 30.0)
    bench = b.get("test_whole_run[chirp]")
    if bench:
        add("240 s chirp within 8 s", bench, f"{_median(bench):.1f} s", _median(bench) <= 8.0)
    bench = b.get("test_make_study")
    if bench:
        wall = _median(bench)
        add("`make study` within 3 min (warm cache)", bench,
            f"{int(wall // 60)} min {wall % 60:.0f} s", wall <= 180.0)
    bench = b.get("test_workbench_run_in_a_fresh_process[warm]")
    if bench:
        add("fresh `workbench run` of the 10 s sine within 1.5 s (warm cache)", bench,
            f"{_median(bench):.2f} s", _median(bench) <= 1.5)
    ratios = {key: lsoda_ratio(b, key) for key in WINDOW_CASES}
    if all(ratios.values()):
        low = min(r[0] for r in ratios.values())
        bench = next(v for k, v in b.items() if k.startswith("test_accuracy_lsoda["))
        text = ", ".join(f"{r[0]:.0f}× ({key})" for key, r in ratios.items())
        add("≥ 3× the compiled model under LSODA, equal accuracy (sine windows)", bench, text,
            low >= 3.0)
    return rows


def summary(b: dict, data: dict) -> str:
    """The tables of docs/performance.md from the newest entries ``b`` and the newest run's header."""
    machine = data.get("machine_info", {})
    parts = [f"Measured by `make bench` ({machine.get('cpu', {}).get('brand_raw', '?')}, "
             f"{machine.get('cpu', {}).get('count', '?')} cores); JSON in `.benchmarks/`.", ""]
    for title, table in (("Cost of one right-hand side", rhs_table(b)),
                         ("Whole runs at the default settings", whole_table(b)),
                         ("Accuracy against cost (0.25 s windows of the sines)", accuracy_table(b)),
                         ("A fresh process", compile_table(b)),
                         ("Sweeps", scaling_table(b))):
        if len(table) > 2:
            parts += [f"**{title}** ({_sources(b, title)})", "", *table, ""]
    return "\n".join(parts)


_TABLE_PREFIXES = {"Cost": ("test_rhs",),
                   "Whole": tuple(f"test_whole_run{kind}[{key}]" for key in WHOLE_CASES
                                  for kind in ("", "_fixed_step")),
                   "Accuracy": tuple(f"test_accuracy_{solver}[{key}-" for key in WINDOW_CASES
                                     for solver in ("kernel", "controlled", "lsoda")),
                   "A": ("test_workbench_run",),
                   "Sweeps": ("test_sweep_scaling", "test_sensitivity_scaling", "test_make_study")}


def _sources(b, title) -> str:
    prefixes = _TABLE_PREFIXES[title.split()[0]]
    names = sorted({v["source"] for k, v in b.items() if k.startswith(prefixes)})
    return "run " + ", ".join(f"`{n.split('_')[0]}`" for n in names)


def _replace_between(path: Path, start: str, end: str, text: str) -> None:
    page = path.read_text()
    if start not in page or end not in page:
        raise SystemExit(f"{path} has no {start} ... {end} section")
    head, rest = page.split(start, 1)
    _, tail = rest.split(end, 1)
    path.write_text(f"{head}{start}\n{text}\n{end}{tail}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, nargs="*", default=None,
                    help="saved runs to read, oldest first (default: all under .benchmarks/)")
    ap.add_argument("--readme", type=Path, default=None)
    ap.add_argument("--targets", type=Path, default=None,
                    help="a file whose targets:start ... targets:end section gets the targets table")
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args(argv)
    b, data = newest_by_name(args.json or saved_runs())
    text = summary(b, data)
    if args.out:
        args.out.write_text(text + "\n")
    if args.readme:
        _replace_between(args.readme, START, END, text)
    targets = "\n".join(targets_table(b))
    if args.targets:
        _replace_between(args.targets, TARGETS_START, TARGETS_END, targets)
    print(text)
    print(targets)


if __name__ == "__main__":
    main()
