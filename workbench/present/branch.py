"""A continued branch of periodic orbits on disk (``workbench continue``): ``branch.parquet``
(one row per orbit, :func:`workbench.model.continuation.branch_rows`, rewritten after every
orbit so that an interrupted continuation keeps every orbit found), the frequency- (or
force-) response curve with stable orbits solid and unstable dashed and the bifurcations
marked, and ``report.md``; and a continuation study's report (:mod:`workbench.study.branches`:
its branches, and a stepped study set beside them)."""
from __future__ import annotations

from pathlib import Path

import json

import numpy as np
import pandas as pd

from ..model.continuation import SMOOTH, Branch, branch_rows
from ..model.orbit import SETTLE
from ..study import branches as B
from ..study.store import write_atomic, write_text_atomic
from . import figures as F
from . import units

#: The axis label of each continuation parameter.
PARAMETER_LABELS = {"freq_hz": "drive frequency (Hz)", "force_n": "drive force (N)"}
#: The marker of each kind of bifurcation.
MARKERS = {"fold": "s", "period doubling": "D", "neimark-sacker": "^", "nonsmooth": "*",
           "grazing": "x"}


def nonsmooth_note(where: str) -> str:
    """What a nonsmooth change of stability is, for the reports; ``where`` says where the
    report gives the multiplier's crossing ("the column says", "in brackets,")."""
    return ("A change of stability is *nonsmooth* where the orbits on its two sides have "
            "different events per period: the monodromy changes with the events, and a "
            "multiplier jumps across the unit circle rather than crossing it (a "
            f"discontinuity-induced bifurcation); {where} where it left or entered the circle.")


#: Where a multiplier crossed the unit circle, in words.
CROSSING_WORDS = {"+1": "at +1", "-1": "at -1", "complex": "as a complex pair"}


def bifurcation_words(kind: str, crossing: str = "", turns: bool = False) -> str:
    """A bifurcation's kind in a report, with where its multiplier crossed the unit circle
    when the kind does not say it and whether the parameter turns there when the kind is not
    a fold: "nonsmooth (at -1, the parameter turns)"."""
    notes = [CROSSING_WORDS[crossing]] if kind == "nonsmooth" and crossing else []
    notes += ["the parameter turns"] if turns and kind != "fold" else []
    return f"{kind} ({', '.join(notes)})" if notes else kind


def branch_figure(table: pd.DataFrame, parameter: str, title: str,
                  column: str = "tip_amplitude_cm", overlay: pd.DataFrame | None = None):
    """The tip's amplitude (mm; ``column``: half its range, or ``tip_h1_cm``, its line at the
    drive frequency) along each branch of ``table`` (one, or several told apart by a
    ``branch`` column): stable orbits solid, unstable (or of undetermined stability) dashed,
    each bifurcation marked at the orbit after it; ``overlay``: a stepped sweep's points
    (:func:`workbench.study.branches.stepped_beside`), up and down apart."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.0, 4.2), layout="constrained")
    unit, factor = units.channel("tip")
    groups = table.groupby("branch", sort=False) if "branch" in table else [("", table)]
    first = True
    for _, part in groups:
        x, y = part[parameter].to_numpy(), part[column].to_numpy() * factor
        stable = part.stable.to_numpy(bool)
        for i in range(len(x) - 1):
            both = stable[i] and stable[i + 1]
            ax.plot(x[i:i + 2], y[i:i + 2], "-" if both else "--",
                    color="C0" if both else "C3", lw=1.4)
        word = part.stability.to_numpy()
        ax.plot(x[stable], y[stable], "o", color="C0", ms=3, label="stable" if first else None)
        ax.plot(x[word == "unstable"], y[word == "unstable"], "o", mfc="none", color="C3",
                ms=4, label="unstable" if first else None)
        if (word == "undetermined").any():
            ax.plot(x[word == "undetermined"], y[word == "undetermined"], "o", mfc="none",
                    color="0.5", ms=4, label="undetermined (|μ| within its error of 1)")
        for kind, marker in MARKERS.items():
            at = (part.bifurcation == kind).to_numpy()
            if at.any():
                ax.plot(x[at], y[at], marker, color="k", ms=7, mfc="none", label=kind)
        first = False
    if overlay is not None and len(overlay):
        for direction, marker in (("up", "^"), ("down", "v")):
            at = overlay.direction == direction
            if at.any():
                ax.plot(overlay[parameter][at], overlay.stepped_tip_h1_cm[at] * factor, marker,
                        color="C2", ms=7, mfc="none", label=f"stepped sweep, {direction}")
    handles, labels = ax.get_legend_handles_labels()
    keep = dict(zip(labels, handles))
    ax.legend(keep.values(), keep.keys(), fontsize=8)
    ax.set_xlabel(PARAMETER_LABELS[parameter])
    ax.set_ylabel(f"tip {'line at the drive frequency' if column == 'tip_h1_cm' else 'amplitude'}"
                  f" ({unit})")
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=9)
    return fig


def write_branch(branch: Branch, out: Path, params) -> None:
    """``branch.parquet`` now; the figure and ``report.md`` once the branch has ended."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    table = pd.DataFrame(branch_rows(branch))
    if not len(table):
        table = pd.DataFrame({branch.parameter: pd.Series(dtype=float),
                              "stable": pd.Series(dtype=bool),
                              "bifurcation": pd.Series(dtype=str)})
    write_atomic(table, out / "branch.parquet")
    if branch.status == "running":
        return
    title = (f"periodic orbits over {PARAMETER_LABELS[branch.parameter]}, gap "
             f"{params.gap * 10:g} mm, tip mass {'on' if params.tip_mass else 'off'}, "
             f"cork {params.cork}")
    if len(table):
        F.save(branch_figure(table, branch.parameter, title), out / "branch")
    stable = table.stable.to_numpy(bool) if len(table) else np.zeros(0, bool)
    lines = ["# A branch of periodic orbits", "", title + ".", "",
             f"Status: {branch.status} ({branch.message}); {len(table)} orbits, "
             f"{int(stable.sum())} stable, "
             f"{int((table.stability == 'undetermined').sum()) if len(table) else 0} of "
             f"stability undetermined (a multiplier within its error of 1), in "
             f"{branch.wall_s:.0f} s (pseudo-arclength "
             "continuation, `workbench/model/continuation.py`; the monodromy "
             + (", ".join(f"{m} for {n} orbits" for m, n in
                          table.monodromy.value_counts().items()) if len(table) else "none")
             + ").", ""]
    if branch.bifurcations:
        lines += ["| at | kind | multiplier crossed at | events per period changed |",
                  "|---|---|---|---|"]
        lines += [f"| {table[branch.parameter].iloc[b.index]:.5g} | "
                  f"{bifurcation_words(b.kind, turns=b.turns)} | "
                  f"{b.crossing or '—'} | {b.events_changed or '—'} |"
                  for b in branch.bifurcations]
        lines.append("")
        if any(b.kind == "nonsmooth" for b in branch.bifurcations):
            lines += [nonsmooth_note("the column says"), ""]
    lines += ["![branch](branch.png) ([PDF](branch.pdf)); every orbit: "
              "[branch.parquet](branch.parquet) (CGS, as the points table).", ""]
    (out / "report.md").write_text("\n".join(lines) + "\n")


def write_study_report(study, out: Path, table: pd.DataFrame, results: Path) -> Path:
    """``report.md``: each branch's end, orbits and bifurcations, the doubled branches, and
    the stepped study beside the branches with its cost (module docstring)."""
    c = study.continuation
    unit = B.PARAMETERS[c.parameter]
    lines = [f"# {study.name}: branches of periodic orbits", "", study.description, "",
             f"Continued in {PARAMETER_LABELS[c.parameter]} from {c.start:g} to {c.end:g} "
             f"{unit}, orbits of {c.periods} drive period(s); drive {study.excitation}; fixed "
             f"{study.fixed or 'none'}; one branch per {list(study.axes) or 'study'} "
             "(`workbench/model/continuation.py`; every orbit: [branches.parquet]"
             "(branches.parquet)).  An orbit is found when its residual is at most 1e-7 of "
             "the error scales (the map integrated at tolerance 1e-9).", "",
             "| branch | status | orbits | stable | bifurcations | wall (s) |",
             "|---|---|---|---|---|---|"]
    summaries = []
    for p in study.points:
        f = out / B.label(p) / "summary.json"
        s = json.loads(f.read_text()) if f.is_file() else B.cut_short(p, table, c.parameter)
        if s is None:
            lines.append(f"| {B.label(p)} | not traced | 0 | 0 | none | |")
            continue
        summaries.append((p, s))
        if not s["segments"]:
            lines.append(f"| {B.label(p)} | {s['status']}: {s['message']} | 0 | 0 | none | 0 |")
        for seg in s["segments"]:
            name = B.label(p) if seg["folder"] == "." else f"{B.label(p)}/{seg['folder']}"
            rows = table[table.branch == name] if len(table) else table
            bif = "; ".join(
                f"{bifurcation_words(b['kind'], b.get('crossing', ''), b.get('turns', False))} "
                f"at {b['at']:.5g}" for b in seg["bifurcations"])
            lines.append(f"| [{name}]({name}/report.md) | {seg['status']}: {seg['message']} "
                         f"| {seg['orbits']} | {int(rows.stable.sum()) if len(rows) else 0} | "
                         f"{bif or 'none'} | {seg['wall_s']:.0f} |".replace("| nan |", "| — |"))
    if any(b["kind"] == "nonsmooth" for _, s in summaries for seg in s["segments"]
           for b in seg["bifurcations"]):
        lines += ["", nonsmooth_note("in brackets,")]
    if any(s.get("interrupted") for _, s in summaries):
        lines += ["", "A branch marked interrupted was cut short before it finished: the "
                  "orbits on disk are reported, its wall time is not known."]
    if any(len(s["segments"]) > 1 for _, s in summaries):
        lines += ["", f"A branch that ends before its range's end starts anew "
                  f"{100 * B.RESTART:g} % of the range beyond the farthest value it reached "
                  "(`from-<value>`): a new segment, found by shooting there, not continued "
                  "from the one before (the two may lie on different branches)."]
    doubled = [(s["label"], d) for _, s in summaries for d in s["doubled"]]
    if doubled:
        lines += ["", "Branches of twice the period, switched to where a multiplier left the "
                  "unit circle at -1 (`continue_doubled`):", "",
                  "| branch | status | orbits |", "|---|---|---|"]
        lines += [f"| [{lab}/{d['folder']}]({lab}/{d['folder']}/report.md) | {d['status']}: "
                  f"{d['message']} | {d['orbits']} |" for lab, d in doubled]
    if c.compare:
        lines += ["", *_comparison(study, out, table, results, summaries)]
    text = "\n".join(lines) + "\n"
    write_text_atomic(text, out / "report.md")
    return out / "report.md"


def _comparison(study, out, table, results, summaries) -> list[str]:
    """The stepped study beside the branches: a table per branch, its figure, its cost."""
    c = study.continuation
    f = results / c.compare / "points.parquet"
    lines = [f"## The stepped study `{c.compare}` beside the branches", ""]
    if not f.is_file():
        return lines + [f"No results at {f}: run its study first "
                        f"(`workbench sweep studies/{c.compare}.toml`)."]
    stepped = pd.read_parquet(f)
    if f"axis_{c.parameter}" not in stepped:
        return lines + [f"The study `{c.compare}` has no axis {c.parameter}: nothing to set "
                        "beside the branches."]
    lines += ["Per stepped point, its tip line at the drive frequency (`tip_h1`, a "
              "least-squares fit over its window) against the nearest orbit's there (exact "
              "over the period); `steady` is the stepped run's own indicator (the tip RMS of "
              "its last two windows within its tolerance), the Poincaré spread the range of "
              "its tip at the drive's phase 0 over the window (zero on a period-1 orbit).", ""]
    total_branch, total_stepped, orbits_traced, settle_s, settle_wall = 0.0, 0.0, 0, [], []
    for p, s in summaries:
        mask = np.ones(len(stepped), bool)
        for k, v in p.values.items():
            col = f"axis_{k}"
            if col in stepped:
                mask &= np.isclose(stepped[col].to_numpy(float), float(v)) \
                    if isinstance(v, float) else (stepped[col] == v).to_numpy()
        points = stepped[mask & (stepped.status == "ok")]
        branch = table[(table.branch == B.label(p)) | table.branch.str.startswith(B.label(p) + "/")
                       ] if len(table) else table
        if not len(points) or not len(branch):
            continue
        beside = B.stepped_beside(branch, points, c.parameter)
        if not len(beside):
            lines += [f"### {B.label(p)}", "", "No stepped point inside the branch's range.", ""]
            continue
        write_atomic(beside, out / B.label(p) / "stepped_beside.parquet")
        if not s.get("interrupted"):                   # a cut-short branch has no wall time
            total_branch += sum(seg["wall_s"] for seg in s["segments"])
            orbits_traced += sum(seg["orbits"] for seg in s["segments"])
            speed = points.simulated_s.sum() / points.wall_s.sum()   # simulated s per wall s
            settle = beside.settle_periods.to_numpy(float) / beside[c.parameter].to_numpy(float)
            settle_s += [x for x in settle if np.isfinite(x)]
            settle_wall += [x / speed for x in settle if np.isfinite(x)]
            ran = points[f"axis_{c.parameter}"].between(branch[c.parameter].min(),
                                                        branch[c.parameter].max())
            total_stepped += float(points.wall_s[ran].sum())
        lines += [f"### {B.label(p)}", "",
                  "| value | sweep | stepped tip_h1 (cm) | steady | Poincaré spread (cm) | "
                  "orbits there (stable) | nearest orbit (cm) | its stability | difference |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for _, r in beside.iterrows():
            near = ("| — | — | — |" if not r.orbits_there else
                    f"| {r.orbit_tip_h1_cm:.4f} | {r.orbit_stability}"
                    f" | {100 * r.difference_rel:.2f} % |")
            lines.append(f"| {r[c.parameter]:g} | {r.direction} | {r.stepped_tip_h1_cm:.4f} | "
                         f"{'yes' if r.stepped_steady else 'no'} | "
                         f"{r.stepped_poincare_spread_cm:.3f} | {r.orbits_there} "
                         f"({r.stable_orbits_there}) {near}")
        jumps = B.jumps_and_folds(beside, branch, c.parameter)
        lines.append("")
        if jumps:
            lines += [f"Where the sweeps up and down differ (by more than {100 * B.HYSTERESIS:g} % "
                      "of the larger: a jump between there and a neighbouring step), the "
                      "branch's nearest folds on either side and its stable orbits there:", "",
                      "| value | up (cm) | down (cm) | fold below | fold above | stable orbits "
                      "there | bracketed |", "|---|---|---|---|---|---|---|"]
            fmt = lambda v: "none" if v is None else f"{v:.4g}"          # noqa: E731
            lines += [f"| {j[c.parameter]:g} | {j['up']:.4f} | {j['down']:.4f} | "
                      f"{fmt(j['fold_below'])} | {fmt(j['fold_above'])} | {j['stable_orbits']} "
                      f"| {'yes' if j['fold_below'] is not None and j['fold_above'] is not None else 'no'} |"
                      for j in jumps]
        else:
            lines.append(f"The sweeps up and down agree (within {100 * B.HYSTERESIS:g} %) at every "
                         "value: no jump to bracket.")
        fig = branch_figure(branch, c.parameter, f"{B.label(p)}: the branch (tip line at the "
                            "drive frequency) and the stepped sweep's points",
                            column="tip_h1_cm", overlay=beside)
        F.save(fig, out / B.label(p) / "stepped_beside")
        lines += ["", f"![{B.label(p)}]({B.label(p)}/stepped_beside.png)", ""]
    if total_stepped:
        lines += ["### Cost", "",
                  f"The branches (the doubled ones aside) took {total_branch:.0f} s of worker "
                  f"time; the stepped study's points at the same axis values "
                  f"{total_stepped:.0f} s (the sum of their runs' wall times in "
                  f"`{c.compare}/points.parquet`; its tolerance "
                  f"{stepped.tol.iloc[0]:.0e}, {stepped.simulated_s.iloc[0]:g} s a step, "
                  "steady states only where the transient has died).  Both measured on this "
                  "machine, not side by side.", ""]
        if settle_s:
            lines += [f"At the same accuracy: a run settles onto a stable orbit to "
                      f"{SETTLE:g} of its distance in log({SETTLE:g}) / log|μ| periods (|μ| "
                      "the orbit's largest multiplier): at the stepped points with a stable "
                      f"orbit, {np.median(settle_s):.0f} s of simulated time (median; "
                      f"{min(settle_s):.0f}–{max(settle_s):.0f} s), {np.median(settle_wall):.0f} "
                      "s of wall at the stepped runs' own speed, per point, against "
                      f"{total_branch / max(orbits_traced, 1):.1f} s per orbit on the branches "
                      f"(each to a residual of 1e-7 of the error scales).", ""]
    return lines


def period_doubling_finding(study, folder: Path) -> dict | None:
    """Where the period-1 orbit of a continuation ``study``'s first branch (``folder`` its
    results, :mod:`workbench.study.branches`) loses stability, and how: the parameter, its
    range, the first orbit's largest multiplier and the time constant it sets (s); at the
    first bifurcation into instability, its kind, where its multiplier crossed the unit
    circle, the events that changed, the last stable orbit's value before it and the first
    unstable one's with its largest multiplier's modulus, the crossing multiplier's angle
    (rad) and the line that angle gives (Hz: f / 2 at -1), and for a crossing at -1 the
    doubled branch's orbits, status and largest lines at f / 2 (tip, cm; strain1) against the
    drive's; ``doubling`` None where the branch has none.  A study
    cut short is read from the orbits on disk (status "interrupted").  None where the study
    has not run."""
    folder = Path(folder)
    point, parameter = study.points[0], study.continuation.parameter
    table = B.collect(study, folder)
    f = folder / B.label(point) / "summary.json"
    summary = json.loads(f.read_text()) if f.is_file() else B.cut_short(point, table,
                                                                         parameter)
    if summary is None:
        return None
    main = table[table.branch == B.label(point)].reset_index(drop=True)
    first = main.iloc[0]
    period = 1.0 / float(point.excitation["freq_hz"]) if parameter == "force_n" \
        else 1.0 / float(first[parameter])
    out = {"parameter": parameter, "unit": B.PARAMETERS[parameter],
           "start": float(first[parameter]), "end": float(main[parameter].iloc[-1]),
           "status": summary["status"], "message": summary["message"],
           "orbits": len(main), "first_stable": first.stability,
           "first_multiplier": float(first.max_multiplier),
           "time_constant_s": (-period / np.log(first.max_multiplier)
                               if 0 < first.max_multiplier < 1 else None),
           "doubling": None}
    # the first bifurcation into instability (any but a grazing)
    at = main.index[main.bifurcation.isin([*SMOOTH.values(), "nonsmooth"])
                    & (main.stability == "unstable")]
    if not len(at):
        return out
    i = int(at[0])
    kind = main.bifurcation.iloc[i]
    crossing = (main.multiplier_crossing.iloc[i] if "multiplier_crossing" in main else
                {v: k for k, v in SMOOTH.items()}.get(kind, ""))
    before = main.iloc[:i][main.stability.iloc[:i] == "stable"]
    angle = (abs(float(main.crossing_angle.iloc[i])) if "crossing_angle" in main
             else {"-1": np.pi, "+1": 0.0}.get(crossing))
    doubled = list(summary["doubled"]) if crossing == "-1" else []
    info = {"kind": kind, "crossing": crossing,
            "events_changed": main.events_changed.iloc[i] if "events_changed" in main else "",
            "last_stable": float(before[parameter].iloc[-1]) if len(before)
            else None, "first_unstable": float(main[parameter].iloc[i]),
            "multiplier": float(main.max_multiplier.iloc[i]), "angle": angle,
            "line_hz": None if angle is None else float(point.excitation["freq_hz"])
            * angle / (2 * np.pi) if parameter == "force_n" else None, "doubled": None}
    if doubled:
        d = doubled[0]
        rows = table[table.branch == f"{B.label(point)}/{d['folder']}"]
        info["doubled"] = {"status": d["status"], "message": d["message"],
                           "orbits": len(rows)}
        if len(rows):
            k = int(np.argmax(rows["strain1_h0.5"].to_numpy()))
            info["doubled"].update(
                range=(float(rows[parameter].min()), float(rows[parameter].max())),
                stable=int(rows.stable.sum()),
                tip_half_cm=float(rows["tip_h0.5_cm"].max()),
                strain_half_over_drive=float(rows["strain1_h0.5"].iloc[k]
                                             / rows["strain1_h1"].iloc[k]),
                at=float(rows[parameter].iloc[k]))
    out["doubling"] = info
    return out
