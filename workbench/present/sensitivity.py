"""The report of a global sensitivity study: which parameter moves each of the paper's observations.

A study with a ``[sample]`` design (:mod:`workbench.study.sensitivity`) runs
a 20 Hz sine at each point; from its points table this module takes each
observation of the paper's §6 that a sine shows (:data:`OUTPUTS`), and
whether each observation *holds* at a point by the rules of
:mod:`workbench.present.observations` (:data:`HOLDS`: an indicator, 1 where
it holds), and writes:

- ``tables/sobol.csv|md|tex``: first-order and total Sobol' indices of every
  output and indicator over every input, with their 95 % bootstrap half
  widths and the design blocks used;
- ``figures/sobol_<output>``: the indices of each output (bars with
  intervals);
- ``figures/holds_<rule>``: each indicator over the plane of the two inputs
  of largest total index for it, a dot per point (where the observation
  holds, and where not);
- ``report.md`` with the inputs and their ranges, the cost, and the points'
  status.

The chirp's bands (Fig. 11-12) take a 240 s run each; the design reads them
from the joint-locked modes instead: a mode at f Hz is passed by the
5-65 Hz, 240 s chirp at (f - 5) / 15 minutes (``band<k>_min``, the k-th mode
above 5 Hz).  That is the band where the joint stays locked, as at the lab's
chirp level; studies/sensitivity_check.py sets it beside real chirps
(``chirp_bands.md``, docs/verification.md).
"""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pandas as pd

from . import figures as F
from .point_checks import accuracy_lines, range_lines
from . import observations as O
from . import units
from ..model.modes import natural_frequencies
from ..study.provenance import environment
from ..study.sensitivity import indices
from ..study.store import read_runs, write_text_atomic

#: Each output: its column, what it measures, and the paper's figure.
OUTPUTS = (
    ("share_14", "time share of code 14", "Fig. 9-10"),
    ("share_23", "time share of code 23", "Fig. 9-10"),
    ("share_13", "time share of code 13", "Fig. 9-10"),
    ("switches_per_s", "contact switches per s", "Fig. 9-10"),
    ("strain1_sub_db", "strain1 line at half the drive over its floor (dB)", "Fig. 7-8"),
    ("strain1_h1", "strain1 amplitude at the drive frequency (µε)", "Fig. 6"),
    ("strain2_h1", "strain2 amplitude at the drive frequency (µε)", "Fig. 6"),
    ("accel1_h1", "accel1 amplitude at the drive frequency (m/s²)", "Fig. 6"),
    ("accel3_h1", "accel3 amplitude at the drive frequency (m/s²)", "Fig. 6"),
    ("band1_min", "chirp band of the first locked mode above 5 Hz (min)", "Fig. 11-12, proxy"),
    ("band2_min", "chirp band of the second locked mode above 5 Hz (min)", "Fig. 11-12, proxy"),
)


def _near_paper_band(table: pd.DataFrame, band_min: float) -> pd.Series:
    near = [(table[c] - band_min).abs() <= O.BAND_MATCH_MIN for c in ("band1_min", "band2_min")]
    return near[0] | near[1]


#: Each rule: its name, the paper's claim it tests, and the indicator (1 where it holds).
HOLDS = {
    "switching_14_23": ("14 and 23 both dominate (Fig. 9)",
                        lambda t: (t.share_14 > O.DOMINANT_SHARE) & (t.share_23 > O.DOMINANT_SHARE)),
    "subharmonic": ("the 10 Hz subharmonic is present (Fig. 7-8)",
                    lambda t: t.strain1_sub_db >= O.LINE_MARGIN_DB),
    "code_13": ("code 13 appears (Fig. 9-10)", lambda t: t.share_13 > O.APPEARS_SHARE),
    **{f"band_{b:g}_min": (f"a band within {O.BAND_MATCH_MIN:g} min of {b:g} min (Fig. 11-12, "
                           "proxy)", lambda t, b=b: _near_paper_band(t, b))
       for b in O.PAPER_BANDS_MIN},
}


def band_times(params) -> tuple[float, float]:
    """The minutes at which the paper's chirp passes the first two joint-locked modes above
    its start frequency (NaN when fewer lie within the chirp)."""
    f = natural_frequencies(params, "locked")
    inside = f[(f > O.CHIRP_F0_HZ) & (f < O.CHIRP_F1_HZ)]
    minutes = (inside - O.CHIRP_F0_HZ) / (O.CHIRP_F1_HZ - O.CHIRP_F0_HZ) * O.CHIRP_S / 60.0
    padded = np.full(2, np.nan)
    padded[:min(2, len(minutes))] = minutes[:2]
    return float(padded[0]), float(padded[1])


def design_table(study, table: pd.DataFrame) -> pd.DataFrame:
    """The points table in the design's row order, every output and indicator as a column
    (NaN where a point failed; amplitudes in SI, :mod:`workbench.present.units`), the band
    proxies added.  Two rows of the design can be one
    point (a choice drawn the same from both matrices): the sweep keeps one result for them,
    under the index (``chain``) of either, and both rows take it."""
    twins: dict = {}
    for i, p in enumerate(study.points):
        twins.setdefault(_identity(p), []).append(i)
    by_chain = table.drop_duplicates("chain").set_index("chain")
    source = [None] * study.n_points
    for group in twins.values():
        found = next((i for i in group if i in by_chain.index), None)
        for i in group:
            source[i] = found
    rows = by_chain.reindex(source).reset_index(drop=True)
    ok = rows.status == "ok"
    for col, _, _ in OUTPUTS:
        if col not in rows:
            rows[col] = np.nan
    bands = np.array([band_times(p.params) for p in study.points])
    rows["band1_min"], rows["band2_min"] = bands[:, 0], bands[:, 1]
    for col, _, _ in OUTPUTS:
        rows.loc[~ok, col] = np.nan
        if col.endswith("_h1"):                       # the points table's CGS -> SI
            rows[col] = rows[col] * units.channel(col.removesuffix("_h1"))[1]
    for name, (_, rule) in HOLDS.items():
        holds = rule(rows).astype(float)
        rows[f"holds_{name}"] = holds.where(ok)
    return rows


def _identity(point) -> str:
    """What makes two points one run: their parameters and drive."""
    return json.dumps([point.params.to_dict(), point.excitation], sort_keys=True, default=repr)


def sobol_table(study, rows: pd.DataFrame) -> pd.DataFrame:
    """Indices of every output and indicator (long form: output, input, S1, ..., n_used)."""
    parts = []
    for col in [c for c, _, _ in OUTPUTS] + [f"holds_{n}" for n in HOLDS]:
        part = indices(study.sample, rows[col].to_numpy(dtype=float))
        part.insert(0, "output", col)
        part.insert(1, "mean", float(np.nanmean(rows[col])) if rows[col].notna().any()
                    else float("nan"))
        parts.append(part)
    return pd.concat(parts, ignore_index=True)


def _indices_figure(part: pd.DataFrame, title: str):
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 3.2))
    x = np.arange(len(part))
    ax.bar(x - 0.2, part.S1, 0.4, yerr=part.S1_conf, label="first order S1", capsize=2)
    ax.bar(x + 0.2, part.ST, 0.4, yerr=part.ST_conf, label="total ST", capsize=2)
    ax.set_xticks(x, part.input, rotation=45, ha="right")
    ax.set_ylabel("Sobol' index")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8)
    ax.axhline(0.0, color="k", lw=0.5)
    return fig


def _holds_figure(study, rows: pd.DataFrame, name: str, top: list[str], title: str):
    """The indicator over the design's numbers of two inputs (a choice: its value's index,
    a "times" input: the factor)."""
    import matplotlib.pyplot as plt
    design = study.sample.design_matrix()
    names = study.sample.names
    fig, ax = plt.subplots(figsize=(4.8, 3.6))
    col = rows[f"holds_{name}"].to_numpy()
    xs, ys = (_axis_values(study.sample.ranges[names.index(a)], design[:, names.index(a)])
              for a in top)
    for value, color, text in ((0.0, "0.7", "does not hold"), (1.0, "C3", "holds")):
        pick = col == value
        ax.scatter(xs[pick], ys[pick], s=6, c=color, label=f"{text} ({int(pick.sum())})")
    failed = np.isnan(col)
    if failed.any():
        ax.scatter(xs[failed], ys[failed], s=12, marker="x", c="k",
                   label=f"failed ({int(failed.sum())})")
    for axis, a in ((ax.set_xlabel, top[0]), (ax.set_ylabel, top[1])):
        r = study.sample.ranges[names.index(a)]
        axis(a + (" (factor)" if r.kind == "times" else
                  f" ({', '.join(f'{i}: {c}' for i, c in enumerate(r.choices))})"
                  if r.kind == "choice" else ""))
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7)
    return fig


def _axis_values(r, u: np.ndarray) -> np.ndarray:
    """The design's numbers of one input as plotted: a choice's index, else the number."""
    return np.minimum(np.floor(u), len(r.choices) - 1) if r.kind == "choice" else u


def make_sensitivity_report(study, results: str | Path = "results") -> Path:
    """Write the indices' tables and figures and report.md of a sampled study already run."""
    out = Path(results).resolve() / study.name
    table = pd.read_parquet(out / "points.parquet")
    t0 = time.perf_counter()
    rows = design_table(study, table)
    sobol = sobol_table(study, rows)
    tables = out / "tables"
    tables.mkdir(parents=True, exist_ok=True)
    sobol.to_csv(tables / "sobol.csv", index=False)
    (tables / "sobol.md").write_text(sobol.to_markdown(index=False, floatfmt=".3g") + "\n")
    (tables / "sobol.tex").write_text(sobol.to_latex(index=False, float_format="%.3g"))
    made = []
    for col, what, fig in OUTPUTS:
        part = sobol[sobol.output == col]
        path = out / "figures" / f"sobol_{col}"
        made.append((f"{what} ({fig})", F.save(_indices_figure(part, f"{col}: {what}"), path)))
    for name, (claim, _) in HOLDS.items():
        part = sobol[sobol.output == f"holds_{name}"]
        top = list(part.sort_values("ST", ascending=False).input[:2])
        if len(top) < 2 or part.ST.isna().all():
            continue
        path = out / "figures" / f"holds_{name}"
        made.append((f"where {claim} holds, over {top[0]} and {top[1]}",
                     F.save(_holds_figure(study, rows, name, top, claim), path)))
    provenance = {**environment(), "study": study.name, "design": study.sample.problem,
                  "n": study.sample.n, "seed": study.sample.seed,
                  "report_wall_s": time.perf_counter() - t0, "runs": read_runs(out)}
    write_text_atomic(json.dumps(provenance, indent=2, default=str) + "\n",
                      out / "provenance.json")
    index = out / "report.md"
    index.write_text(render(study, table, rows, sobol, made, out))
    return index


def together_lines(study, rows: pd.DataFrame) -> list[str]:
    """The inverse question on the design: the points where every observation holds, with
    the range of each input over them, or, where none does, which pairs never hold together."""
    holds = pd.DataFrame({n: rows[f"holds_{n}"] == 1.0 for n in HOLDS})
    finished = int(rows[f"holds_{next(iter(HOLDS))}"].notna().sum())
    missing = int(rows.status.isna().sum())
    lines = ["## Where the observations hold together", ""]
    if missing:
        lines += [f"{missing} points of the design have no result (not run yet, or run by "
                  "another version of the computing code: run the sweep again).", ""]
    lines += [f"Of {finished} finished points: "
             + "; ".join(f"{n} holds at {int(h.sum())}" for n, h in holds.items()) + ".", "",
             "Points where both hold (the diagonal: where each holds):", "",
             "| | " + " | ".join(holds) + " |", "|---|" + "---|" * len(holds.columns)]
    for a in holds:
        lines.append(f"| {a} | " + " | ".join(str(int((holds[a] & holds[b]).sum()))
                                             for b in holds) + " |")
    every = holds.all(axis=1).to_numpy()
    lines.append("")
    if every.any():
        design = study.sample.design_matrix()[every]
        lines += [f"All of them hold at {int(every.sum())} points; over those, each input "
                  "(a choice: the values drawn; a factor: of the point's own value):", "",
                  "| input | lowest | highest |", "|---|---|---|"]
        for j, r in enumerate(study.sample.ranges):
            if r.kind == "choice":
                drawn = sorted({r.value(u) for u in design[:, j]})
                lines.append(f"| {r.name} | {', '.join(drawn)} | |")
            else:
                lines.append(f"| {r.name} | {design[:, j].min():.4g} | {design[:, j].max():.4g} |")
    else:
        never = [f"{a} and {b}" for i, a in enumerate(holds) for b in list(holds)[i + 1:]
                 if holds[a].any() and holds[b].any() and not (holds[a] & holds[b]).any()]
        absent = [a for a in holds if not holds[a].any()]
        lines.append("No point of the design reproduces them all. "
                     + (f"Never at any point: {', '.join(absent)}. " if absent else "")
                     + (f"Each present somewhere but never together: {'; '.join(never)}."
                        if never else ""))
    return lines + [""]


def render(study, table, rows, sobol, made, out) -> str:
    s = study.sample
    ok = table.status == "ok"
    lines = [f"# Global sensitivity `{study.name}`", "", study.description, "",
             f"Definition: `{study.source}`. A Saltelli design of Sobol' sequences (SALib; seed "
             f"{s.seed}): n = {s.n} base samples of {len(s.ranges)} inputs, {s.n_points} runs of "
             f"{study.duration_s:g} s (the observations over the last {study.window_s:g} s); "
             f"{int(ok.sum())} finished, {int((~ok).sum())} did not. Cost: "
             f"{table.wall_s.sum():.0f} CPU s for {table.get('simulated_s', pd.Series(0.0)).sum():.0f}"
             " simulated s.", ""]
    if (out / "short_runs.md").is_file():
        lines += ["Whether these short runs say what 10 s runs say, on points of the design: "
                  "[short_runs.md](short_runs.md).", ""]
    if (out.parent / "paper_fit" / "all" / "report.md").is_file():
        lines += ["The estimator's search for a set showing the observations together, from the "
                  "design's best points: [paper_fit](../paper_fit/all/report.md).", ""]
    if (out / "chirp_bands.md").is_file():
        lines += ["The chirp's bands read from the locked modes (a proxy) against the bands of "
                  "real 240 s chirps on points of the design: [chirp_bands.md](chirp_bands.md).", ""]
    lines += ["## Inputs", "", "| input | drawn from | kind |", "|---|---|---|"]
    for r in s.ranges:
        drawn = (", ".join(r.choices) if r.kind == "choice" else f"{r.lo:g} to {r.hi:g}"
                 + (" times its own value" if r.kind == "times" else ""))
        lines.append(f"| {r.name} | {drawn} | {r.kind} |")
    for target, source in s.same.items():
        lines.append(f"| {target} | the value of {source} | same |")
    lines += ["", "## What decides each observation", "",
              "Total index ST (the share of the output's variance an input explains, alone "
              "and with others) of the two largest inputs, with 95 % bootstrap half widths; "
              "the full table: [sobol.md](tables/sobol.md) ([CSV](tables/sobol.csv), "
              "[LaTeX](tables/sobol.tex)).", "",
              "| output | paper | mean over the design | largest ST | second | blocks used |",
              "|---|---|---|---|---|---|"]
    described = {c: (w, f) for c, w, f in OUTPUTS}
    described.update({f"holds_{n}": (f"holds: {claim}", "") for n, (claim, _) in HOLDS.items()})
    for col, (what, fig) in described.items():
        part = sobol[sobol.output == col].sort_values("ST", ascending=False)
        if part.ST.isna().all():
            lines.append(f"| {what} | {fig} | {part['mean'].iloc[0]:.3g} | no variance | | "
                         f"{int(part.n_used.iloc[0])} |")
            continue
        top = [f"{r.input} {r.ST:.2f} ± {r.ST_conf:.2f}" for r in part.head(2).itertuples()]
        lines.append(f"| {what} | {fig} | {part['mean'].iloc[0]:.3g} | {top[0]} | {top[1]} | "
                     f"{int(part.n_used.iloc[0])} |")
    lines += ["", *together_lines(study, rows), *accuracy_lines(study, table),
              *range_lines(table)]
    lines += ["## Figures", ""]
    for title, paths in made:
        png, pdf = (p.relative_to(out) for p in paths)
        lines += [f"### {title}", "", f"![{title}]({png}) ([PDF]({pdf}))", ""]
    return "\n".join(lines) + "\n"
