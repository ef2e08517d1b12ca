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
"""
from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
from joblib import Parallel, delayed

from workbench.present import observations as O
from workbench.study.definition import load
from workbench.study.sweep import run_point

LONG_S = 10.0
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
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    study = load(args.study)
    out = args.results / study.name
    table = pd.read_parquet(out / "points.parquet")
    table = table[table.status == "ok"].drop_duplicates("key").sort_values("strain1_sub_db")
    picked = table.iloc[np.linspace(0, len(table) - 1, args.points).round().astype(int)]
    long = dataclasses.replace(study, duration_s=LONG_S, window_s=LONG_S / 2,
                               save_series=(), check_accuracy=False)
    scratch = out / "short_runs_points"
    (scratch / "points").mkdir(parents=True, exist_ok=True)
    rows = Parallel(n_jobs=args.jobs)(
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
