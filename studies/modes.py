"""Modal table of the model: natural frequencies and damping ratios for tip
mass on/off, joint locked/free and every cork model, linearised as
``workbench modes`` does: the locked joint about the static equilibrium under
gravity, the free joint about the undeformed state (``workbench.model.modes``).

Writes ``modes.csv``, ``modes.md`` and ``provenance.json`` into ``--out``;
part of ``make study``.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import pandas as pd

from workbench.model.modes import damping_ratios
from workbench.model.params import CORK_MODELS, Parameters
from workbench.study.provenance import environment

N_MODES = 6


def table() -> pd.DataFrame:
    rows = []
    for tip in (True, False):
        for joint in ("locked", "free"):
            for cork in (CORK_MODELS if joint == "free" else ["cubic"]):
                p = Parameters(tip_mass=tip, cork=cork)
                about = "static" if joint == "locked" else "undeformed"
                f, zeta = damping_ratios(p, joint, about)
                rigid = int((f == 0.0).sum())
                row = {"tip_mass": "on" if tip else "off", "joint": joint, "about": about,
                       "cork": cork if joint == "free" else "-", "rigid_modes": rigid}
                for i, (fi, zi) in enumerate(zip(f[f > 0.0][:N_MODES], zeta[f > 0.0][:N_MODES])):
                    row[f"f{i + 1}_hz"] = fi
                    row[f"zeta{i + 1}"] = zi
                rows.append(row)
    return pd.DataFrame(rows)


def _markdown(df: pd.DataFrame) -> str:
    """Frequencies with 3 decimals, damping ratios with 4 significant digits."""
    out = df.copy()
    for col in out.columns:
        if col.startswith("f") and col.endswith("_hz"):
            out[col] = out[col].map(lambda v: f"{v:.3f}")
        elif col.startswith("zeta"):
            out[col] = out[col].map(lambda v: f"{v:.4g}")
    return out.to_markdown(index=False)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args()
    start = time.perf_counter()
    df = table()
    args.out.mkdir(parents=True, exist_ok=True)
    df.to_csv(args.out / "modes.csv", index=False, float_format="%.6g")
    note = ("Natural frequencies (Hz) and damping ratios (zeta: -Re/|lambda| of the damped "
            "linear system's eigenvalue, the beams' structural damping and the cork's damper) "
            "of the 9-DOF model, linearised ('about') with the joint locked (s = v = psi = 0) "
            "about the static equilibrium under gravity (what a hammer test of the rig at rest "
            "measures), with the joint free about the undeformed state (gravity's geometric "
            "stiffness omitted; the free joint rests on its contacts at the static "
            "equilibrium). 'free' leaves s, v, psi to the cork, whose tangent stiffness at s = 0 is zero for the "
            "quadratic and cubic models: those coordinates are rigid-body modes (counted in "
            "rigid_modes, 0 Hz) and the elastic frequencies follow.\n\n")
    (args.out / "modes.md").write_text("# Modal table\n\n" + note
                                       + _markdown(df) + "\n")
    provenance = {**environment(), "study": "modes", "wall_s": time.perf_counter() - start,
                  "parameters": Parameters().to_dict()}
    (args.out / "provenance.json").write_text(json.dumps(provenance, indent=1, default=str))
    print(f"wrote {args.out}/modes.csv, modes.md, provenance.json")


if __name__ == "__main__":
    main()
