"""A continued branch of periodic orbits on disk (``workbench continue``): ``branch.parquet``
(one row per orbit, :func:`workbench.model.continuation.branch_rows`, rewritten after every
orbit so that an interrupted continuation keeps every orbit found), the frequency- (or
force-) response curve with stable orbits solid and unstable dashed and the bifurcations
marked, and ``report.md``."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..model.continuation import Branch, branch_rows
from ..study.store import write_atomic
from . import figures as F
from . import units

#: The axis label of each continuation parameter.
PARAMETER_LABELS = {"freq_hz": "drive frequency (Hz)", "force_n": "drive force (N)"}
#: The marker of each kind of bifurcation.
MARKERS = {"fold": "s", "period doubling": "D", "neimark-sacker": "^", "grazing": "x"}


def branch_figure(table: pd.DataFrame, parameter: str, title: str):
    """The tip's amplitude (mm) along the branch: stable orbits solid, unstable (or of
    undetermined stability) dashed, each bifurcation marked at the orbit after it."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.0, 4.2), layout="constrained")
    unit, factor = units.channel("tip")
    x, y = table[parameter].to_numpy(), table.tip_amplitude_cm.to_numpy() * factor
    stable = table.stable.to_numpy(bool)
    for i in range(len(x) - 1):
        both = stable[i] and stable[i + 1]
        ax.plot(x[i:i + 2], y[i:i + 2], "-" if both else "--", color="C0" if both else "C3",
                lw=1.4)
    ax.plot(x[stable], y[stable], "o", color="C0", ms=3, label="stable")
    word = table.stability.to_numpy()
    ax.plot(x[word == "unstable"], y[word == "unstable"], "o", mfc="none", color="C3", ms=4,
            label="unstable")
    if (word == "undetermined").any():
        ax.plot(x[word == "undetermined"], y[word == "undetermined"], "o", mfc="none",
                color="0.5", ms=4, label="undetermined (|μ| within its error of 1)")
    for kind, marker in MARKERS.items():
        at = table.bifurcation == kind
        if at.any():
            ax.plot(x[at], y[at], marker, color="k", ms=7, mfc="none", label=kind)
    ax.set_xlabel(PARAMETER_LABELS[parameter])
    ax.set_ylabel(f"tip amplitude ({unit})")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
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
    lines = [f"# A branch of periodic orbits", "", title + ".", "",
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
        lines += ["| at | kind |", "|---|---|"]
        lines += [f"| {table[branch.parameter].iloc[i]:.5g} | {kind} |"
                  for i, kind in branch.bifurcations]
        lines.append("")
    lines += ["![branch](branch.png) ([PDF](branch.pdf)); every orbit: "
              "[branch.parquet](branch.parquet) (CGS, as the points table).", ""]
    (out / "report.md").write_text("\n".join(lines) + "\n")
