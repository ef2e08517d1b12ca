"""Acceptance of the stress studies (`make stress`): results/stress/acceptance.md.

    python studies/stress_check.py results stress stress_paper stress_chirp

Reads each study's points.parquet and checks every point: it finished (status
ok); no impact raised the kinetic energy (beyond round-off, 1e-12 of the run's
largest kinetic energy); penetration and drift at most 1e-8 cm; the slide's
overtravel past the slot at most what the end stop allows under the run's
forces (``metrics.contact_checks``: the plates' largest friction mu_s N
pushing on and the slide's largest speed, by energy).  Writes the
counts (points, events, impacts, accumulations, Moreau-Jean steps,
inconsistent states resolved, least-violated regimes), the largest energy
balance residual and its case, and the per-point table of residuals.  Exit
status 1 if any check fails.
"""
from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd

from workbench.model.shown_units import SI

#: mm per cm: the report gives lengths in mm.
MM = SI["cm"][1]
KE_GAIN_REL = 1e-12
PEN_CM = 1e-8


def check(table: pd.DataFrame) -> pd.DataFrame:
    ok = table.status == "ok"
    out = pd.DataFrame({"finished": ok})
    out["ke_gain"] = table.get("impact_ke_gain_rel", 0.0).fillna(0.0) <= KE_GAIN_REL
    out["penetration"] = table.max_penetration_cm.fillna(1.0) <= PEN_CM
    out["drift"] = table.max_drift_cm.fillna(1.0) <= PEN_CM
    out["stop"] = table.stop_overtravel_cm.fillna(0.0) <= table.stop_allowance_cm.fillna(0.0)
    return out


def main(argv: list[str]) -> int:
    results = Path(argv[0])
    tables = []
    for name in argv[1:]:
        path = results / name / "points.parquet"
        if not path.exists():
            print(f"{path} is missing: run `make stress` (or workbench sweep studies/{name}.toml)")
            return 1
        t = pd.read_parquet(path)
        t.insert(0, "study", name)
        tables.append(t)
    table = pd.concat(tables, ignore_index=True)
    checks = check(table)
    failed = ~checks.all(axis=1)
    axes = [c for c in table.columns if c.startswith("axis_")]
    lines = ["# Stress studies: acceptance", "",
             f"Studies: {', '.join(argv[1:])}. Checks per point: finished; no impact raised the "
             f"kinetic energy (> {KE_GAIN_REL:g} of the run's largest); penetration and drift "
             f"<= {PEN_CM * MM:g} mm (drift: a closed gap after the step's projection; "
             f"the projection's own correction is reported); overtravel past the slot <= "
             f"F/k + sqrt((F/k)^2 + m v^2/k) with F = mu_s x largest normal force, v the "
             f"largest slide speed, m the slide's mass.", "",
             "| quantity | value |", "|---|---|"]
    counts = {
        "points": len(table), "points failing a check": int(failed.sum()),
        "points not finished": int((~checks.finished).sum()),
        "events": int(table.n_events.sum()), "impacts": int(table.n_impacts.sum()),
        "accumulations closed": int(table.accumulations.sum()),
        "inconsistent states resolved by an impulse": int(table.inconsistent_resolved.sum()),
        "least-violated regimes taken": int(table.least_violated.sum()),
        "Moreau-Jean steps": int(table.stepped_steps.sum()),
        "points with Moreau-Jean steps": int((table.stepped_steps > 0).sum()),
        "s range (mm)": f"{table.s_min_cm.min() * MM:.3f} .. {table.s_max_cm.max() * MM:.3f}",
        "largest penetration (mm)": f"{table.max_penetration_cm.max() * MM:.2e}",
        "largest drift (mm)": f"{table.max_drift_cm.max() * MM:.2e}",
        "largest projection correction (mm)": f"{table.max_correction_cm.max() * MM:.2e}",
        "largest overtravel / allowance": f"{(table.stop_overtravel_cm / table.stop_allowance_cm).max():.3f}",
        "wall time of the points (s, sum)": f"{table.wall_s.sum():.0f}",
    }
    worst = table.energy_balance_rel.idxmax()
    counts["largest energy residual"] = (
        f"{table.energy_balance_rel[worst]:.2e} ({table.study[worst]}: "
        + ", ".join(f"{a[5:]}={table[a][worst]}" for a in axes if pd.notna(table[a][worst])) + ")")
    lines += [f"| {k} | {v} |" for k, v in counts.items()]
    if failed.any():
        lines += ["", "## Points failing a check", ""]
        bad = pd.concat([table.loc[failed, ["study", *axes, "status", "message"]],
                         ~checks.loc[failed]], axis=1)
        lines.append(bad.to_markdown(index=False))
    lines += ["", "## Energy balance residual per point", ""]
    cols = ["study", *axes, "energy_balance_rel", "n_impacts", "accumulations", "stepped_steps",
            "s_min_cm", "s_max_cm", "wall_s"]
    lines.append(table[cols].to_markdown(index=False, floatfmt=".3g"))
    out = results / "stress" / "acceptance.md"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(lines) + "\n")
    print("\n".join(lines[:len(counts) + 6]))
    print(f"written: {out}")
    return 1 if failed.any() else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
