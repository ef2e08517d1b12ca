"""Do the sensitivity study's short runs say what 10 s runs say?  A check on design points.

    python studies/sensitivity_check.py studies/sensitivity.toml --results results [--points 16]

The design runs 3 s per point (observations over the last 1.5 s); the
paper's sine ran 10 s.  This script takes ``--points`` finished points of
the design, spread over the subharmonic's measured level (every k-th point
in its order), runs each again for LONG_S seconds (observations over the
last half) and sets each observation's value and verdict side by
side: the shares of 14, 23 and 13, the switching rate and the subharmonic's
level, with the rules of workbench.present.observations.  Writes
``short_runs.md`` and ``short_runs.csv`` into the study's results.

The design reads the chirp's bands from the joint-locked modes (a proxy,
workbench.present.sensitivity.band_times).  ``--chirps`` points of the design,
spread over the second band's proxy time, are run as the paper's 240 s
chirp at CHIRP_N (the lab's level, results/paper) and the bands the record
shows (the rule of workbench.present.observations) are set beside the
proxy's: ``chirp_bands.md`` and ``chirp_bands.csv``.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

import numpy as np
import pandas as pd
from joblib import Parallel, delayed

from workbench.present.observed import paper_targets
from workbench.present import observations as O
from workbench.present.sensitivity import band_times
from workbench.study.definition import load
from workbench.study.sweep import run_point

LONG_S = 10.0
#: The chirp's force (N): the lab's level of the paper's chirp (results/paper, from static).
CHIRP_N = 11.0
COMPARED = ("share_14", "share_23", "share_13", "switches_per_s", "strain1_sub_db")


def verdicts(row) -> dict:
    return {"switching 14/23": row.share_14 > O.DOMINANT_SHARE and row.share_23 > O.DOMINANT_SHARE,
            "code 13": row.share_13 > O.APPEARS_SHARE,
            "subharmonic": row.strain1_sub_db >= O.LINE_MARGIN_DB}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("study")
    ap.add_argument("--results", type=Path, default=Path("results"))
    ap.add_argument("--points", type=int, default=16)
    ap.add_argument("--chirps", type=int, default=8)
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    study = load(args.study)
    out = args.results / study.name
    if args.points:
        short_runs(study, out, args.points, args.jobs)
    if args.chirps:
        chirp_bands(study, out, args.chirps, args.jobs)


def chirp_run(params, saved: Path) -> dict:
    """The bands (min) of the paper's chirp at CHIRP_N with ``params``, and the run's status;
    kept in ``saved`` (JSON) and read from there when it is already."""
    if saved.is_file():
        return json.loads(saved.read_text())
    target = paper_targets(params, CHIRP_N, CHIRP_N)[1]
    run = target.setup.simulate()
    bands = target.measures(run)["bands_min"] if run.ok else []
    out = {"status": run.status, "bands_min": bands, "wall_s": run.wall_s}
    saved.write_text(json.dumps(out))
    return out


def chirp_bands(study, out: Path, n: int, jobs: int) -> None:
    """The proxy's band times against the bands of real chirps on ``n`` design points."""
    proxies = np.array([band_times(p.params) for p in study.points])
    order = np.argsort(np.nan_to_num(proxies[:, 1], nan=np.inf), kind="stable")
    order = order[np.isfinite(proxies[order, 1])]
    picked = order[np.linspace(0, len(order) - 1, n).round().astype(int)]
    saved = out / "chirp_bands_points"
    saved.mkdir(exist_ok=True)
    runs = Parallel(n_jobs=jobs)(delayed(chirp_run)(study.points[int(i)].params,
                                                    saved / f"{int(i)}.json") for i in picked)
    records = []
    for i, run in zip(picked, runs):
        p = study.points[int(i)].params
        rec = {"point": int(i), "e_a_gpa": p.e_a / 1e10, "e_b_gpa": p.e_b / 1e10,
               "gap_mm": p.gap * 10.0, "cork": p.cork, "status": run["status"],
               "bands_min": " ".join(f"{b:.2f}" for b in run["bands_min"]),
               "wall_s": run["wall_s"]}
        for k in (0, 1):
            rec[f"proxy{k + 1}_min"] = proxies[i, k]
            found = np.asarray(run["bands_min"])
            rec[f"nearest{k + 1}_min"] = (float(found[np.argmin(np.abs(found - proxies[i, k]))])
                                          if found.size else np.nan)
        records.append(rec)
    df = pd.DataFrame(records)
    for k in (1, 2):
        df[f"offset{k}_min"] = df[f"nearest{k}_min"] - df[f"proxy{k}_min"]
    df.to_csv(out / "chirp_bands.csv", index=False)
    lines = ["# The band proxy against real chirps", "",
             f"{n} points of the design, spread over the second band's proxy time, run as the "
             f"paper's 5-65 Hz chirp of 240 s at {CHIRP_N:g} N from the static equilibrium (the "
             "lab's level of results/paper); the bands are found by the paper report's rule "
             f"(after {O.CHIRP_SKIP_S:g} s). For "
             "each proxy band (a joint-locked mode), the nearest band the chirp shows and "
             "the offset (min).", "",
             "| point | E_A (GPa) | E_B (GPa) | gap (mm) | cork | chirp's bands (min) | proxy 1 | "
             "offset 1 | proxy 2 | offset 2 |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in df.itertuples():
        lines.append(f"| {r.point} | {r.e_a_gpa:.1f} | {r.e_b_gpa:.1f} | {r.gap_mm:.3f} | {r.cork} "
                     f"| {r.bands_min or 'none'} | {r.proxy1_min:.2f} | {r.offset1_min:+.2f} | "
                     f"{r.proxy2_min:.2f} | {r.offset2_min:+.2f} |")
    for k in (1, 2):
        d = df[f"offset{k}_min"].abs()
        within = int((d <= O.BAND_MATCH_MIN).sum())
        lines += ["", f"Band {k}: the chirp shows a band within {O.BAND_MATCH_MIN:g} min of the "
                  f"proxy at {within} of {len(df)} points; median offset "
                  f"{df[f'offset{k}_min'].median():+.2f} min, largest |offset| {d.max():.2f} min."]
    lines += ["", f"Cost: {df.wall_s.sum():.0f} CPU s. Per point: [chirp_bands.csv](chirp_bands.csv).", ""]
    (out / "chirp_bands.md").write_text("\n".join(lines) + "\n")
    print(out / "chirp_bands.md")


def short_runs(study, out: Path, n_points: int, jobs: int) -> None:
    """The design's short runs against LONG_S runs on ``n_points`` points."""
    table = pd.read_parquet(out / "points.parquet")
    table = table[table.status == "ok"].drop_duplicates("key").sort_values("strain1_sub_db")
    picked = table.iloc[np.linspace(0, len(table) - 1, n_points).round().astype(int)]
    long = dataclasses.replace(study, duration_s=LONG_S, window_s=LONG_S / 2,
                               save_series=(), check_accuracy=False)
    scratch = out / "short_runs_points"
    (scratch / "points").mkdir(parents=True, exist_ok=True)
    rows = Parallel(n_jobs=jobs)(
        delayed(run_point)(long, study.points[int(c)], f"long-{k}", scratch)
        for c, k in zip(picked.chain, picked.key))
    lines = [f"# Short runs against {LONG_S:g} s runs", "",
             f"{len(picked)} finished points of the design, spread over the subharmonic's "
             f"level, run again for {LONG_S:g} s (observations over the last "
             f"{LONG_S / 2:g} s) against the design's {study.duration_s:g} s (the last "
             f"{study.window_s:g} s).", ""]
    records = []
    for (_, short), longrow in zip(picked.iterrows(), rows):
        longrow = pd.Series(longrow)
        rec = {"key": short.key, "status_long": longrow.status}
        for c in COMPARED:
            rec[f"{c}_short"], rec[f"{c}_long"] = short[c], longrow.get(c, np.nan)
        if longrow.status == "ok":
            for name, v in verdicts(short).items():
                rec[f"{name}_short"], rec[f"{name}_long"] = v, verdicts(longrow)[name]
        records.append(rec)
    df = pd.DataFrame(records)
    df.to_csv(out / "short_runs.csv", index=False)
    ok = df[df.status_long == "ok"]
    lines += ["| verdict | agree | of |", "|---|---|---|"]
    for name in ("switching 14/23", "code 13", "subharmonic"):
        agree = int((ok[f"{name}_short"] == ok[f"{name}_long"]).sum())
        lines.append(f"| {name} | {agree} | {len(ok)} |")
    lines += ["", "| measure | median abs difference | largest |", "|---|---|---|"]
    for c in COMPARED:
        d = (ok[f"{c}_short"] - ok[f"{c}_long"]).abs()
        lines.append(f"| {c} | {d.median():.3g} | {d.max():.3g} |")
    lines += ["", "Per point: [short_runs.csv](short_runs.csv).", ""]
    (out / "short_runs.md").write_text("\n".join(lines) + "\n")
    print(out / "short_runs.md")


if __name__ == "__main__":
    main()
