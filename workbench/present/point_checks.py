"""What a study's report states about its points: the integration's accuracy (estimated and
measured against companion runs), the forces a levelled study used, and the points outside
the range the model is validated for.  Each function returns Markdown lines."""
from __future__ import annotations

import pandas as pd

from ..model.accuracy import ERROR_BOUND
from ..study.grid import point_title
from .units import si

#: mm per cm: lengths are reported in mm (:mod:`workbench.present.units`).
MM = si("cm")[1]


def accuracy_lines(study, table: pd.DataFrame) -> list[str]:
    """The integration's accuracy: the method, the worst estimate, and every point above its tolerance."""
    ok = table[table.status == "ok"] if len(table) else table
    if study.tol is None or not len(ok) or "error_over_tol_max" not in ok:
        return ([f"Integration: {study.method}, fixed step "
                 f"{'the stability step' if study.dt is None else f'{study.dt:g} s'}: "
                 "no error estimate. " + (measured_sentence(ok) if len(ok) else ""), ""])
    worst = ok.loc[ok.error_over_tol_max.idxmax()]
    lines = [f"Integration: {study.method}, tol = {study.tol:g}; the largest error estimate is "
             f"{worst.error_over_tol_max:.3g} of the tolerance ({point_title(worst)}); steps "
             f"{ok.h_min.min():.3g}-{ok.h_max.max():.3g} s.", ""]
    if "global_error_est" in ok and ok.global_error_est.notna().any():
        g = ok.loc[ok.global_error_est.idxmax()]
        lines[0] += (f" The largest global error estimate (the local estimates' root sum of "
                     f"squares, of a position's scale or a contact share) is "
                     f"{g.global_error_est:.2g} ({point_title(g)}).")
    lines[0] += " " + measured_sentence(ok)
    over = ok[(ok.error_over_tol_max > 1.0) | (ok.floor_count > 0)]
    if len(over):
        lines += ["## Points above their tolerance", "",
                  "Each has steps accepted at the smallest size above the tolerance "
                  "(`run.control['floor_intervals']` lists them).", "",
                  "| point | estimate / tol | steps at the floor |", "|---|---|---|"]
        lines += [f"| {point_title(r)} | {r.error_over_tol_max:.3g} | {int(r.floor_count)} |"
                  for _, r in over.iterrows()]
        lines.append("")
    return lines


def measured_sentence(ok: pd.DataFrame) -> str:
    """The errors measured against companion runs (``[study] check_accuracy``), or that none were."""
    if "error_measured" not in ok or not ok.error_measured.notna().any():
        return ("No point was checked against a companion run (`check_accuracy = true` "
                "measures each point's error).")
    checked = ok[ok.error_measured.notna()]
    worst = checked.loc[checked.error_measured.idxmax()]
    above = checked[checked.error_measured > ERROR_BOUND]
    text = (f"Measured against a companion run at finer settings (a tenth of the tolerance "
            f"and half the coarsest step, or a quarter of a fixed step), the largest error "
            f"(the tip's of its range, or a contact share's) is {worst.error_measured:.2g} "
            f"({point_title(worst)}), over {len(checked)} points")
    if len(above):
        return text + (f"; {len(above)} exceed {ERROR_BOUND:g}: "
                       + "; ".join(point_title(r) for _, r in above.iterrows()) + ".")
    return text + f"; every one is within {ERROR_BOUND:g}."


def range_lines(table: pd.DataFrame) -> list[str]:
    """How many finished points stayed within the range the model is validated for, and every
    one that did not (``metrics.validity``: the tip beyond the paper's 8.4 cm, the slide beyond
    the slot's travel, an accelerometer or the force transducer beyond its range)."""
    if "out_of_range" not in table:
        return []
    ok = table[table.status == "ok"]
    over = ok[ok.out_of_range.fillna("") != ""]
    count = (f"{len(ok) - len(over)} of {len(ok)} points lie inside the validated range (tip "
             "within 84 mm of its static position, the slide within the slot's travel, the "
             "sensors within their ranges")
    if not len(over):
        return [count + ").", ""]
    kinds = pd.Series([k for v in over.out_of_range for k in v.split(",")]).value_counts()
    lines = ["## Points outside the validated range", "",
             count + f"; outside: {', '.join(f'{k} at {n}' for k, n in kinds.items())}).", "",
             "The tip beyond the paper's 84 mm (§5.3; the beams' small-slope shapes were "
             "compared with the rig up to there), the slide beyond the slot's travel (the "
             "end stop, an ASSUMPTION, carries it), or a sensor beyond its range (50 g, "
             "2224 N: a lab's record would be clipped). Marked '!' in the maps.", "",
             "| point | outside | tip max (mm) | slide max (mm) | accel max (g) | force1 max (N) |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {point_title(r)} | {r.out_of_range} | {r.tip_abs_max_cm * MM:.3g} | "
              f"{r.slide_abs_max_cm * MM:.3g} | {r.accel_abs_max_g:.3g} | "
              f"{r.force1_abs_max_n:.3g} |"
              for _, r in over.iterrows()]
    return lines + [""]


def level_lines(study, table: pd.DataFrame) -> list[str]:
    """A levelled study's rule, the forces it found and which limit decided them, and every
    point whose limits no force met (with its largest responses)."""
    if study.limits is None or "force_n_used" not in table:
        return []
    lim = study.limits
    ok = table[table.status == "ok"]
    named = [f"accelerometers {lim.accel_g:g} g" if lim.accel_g else "",
             f"force transducer {lim.force_transducer_n:g} N" if lim.force_transducer_n else "",
             f"tip {lim.tip_cm * MM:g} mm" if lim.tip_cm else "",
             "the slide within the slot's travel" if lim.slot else ""]
    lines = ["## Each point's force", "",
             f"Each point's force is the largest, up to {study.excitation['force_n']:g} N, at "
             f"which every limit holds over the whole run ({', '.join(n for n in named if n)}), "
             f"found within a factor {lim.resolution:g} by a bracket search "
             "(`workbench/study/leveling.py`; the map `force_map` shows it)."]
    if len(ok):
        decided = ok.level_limit.value_counts()
        lines[-1] += (f" Forces {ok.force_n_used.min():.3g}-{ok.force_n_used.max():.3g} N "
                      f"(median {ok.force_n_used.median():.3g} N); decided by "
                      + ", ".join(f"{k} at {n}" for k, n in decided.items())
                      + f"; {ok.level_runs.mean():.2g} runs a point on average "
                      f"({int(ok.level_runs.sum())} in all).")
    unmet = ok[~ok.level_met.astype(bool)]
    lines.append("")
    if len(unmet):
        lines += [f"{len(unmet)} points meet the limits at no force tried:", "",
                  "| point | lowest force (N) | runs | limit | tip max (mm) | slide max (mm) | "
                  "accel max (g) |", "|---|---|---|---|---|---|---|"]
        lines += [f"| {point_title(r)} | {r.force_n_used:.3g} | {int(r.level_runs)} | "
                  f"{r.level_limit} | {r.tip_abs_max_cm * MM:.3g} | {r.slide_abs_max_cm * MM:.3g} | "
                  f"{r.accel_abs_max_g:.3g} |" for _, r in unmet.iterrows()]
        lines.append("")
    return lines
