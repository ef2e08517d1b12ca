"""A study's report: figures, tables, an index and the provenance.

    results/<study>/figures/*.png, *.pdf
    results/<study>/tables/{response,contact}.{csv,md,tex}
    results/<study>/report.md          links every figure and table
    results/<study>/provenance.json    code version, packages, machine,
                                       study definition, wall times

Which figures a study gets depends on its axes: the maps and curves need
gap_mm and freq_hz axes, the shares and the bifurcation diagram need a
sine drive over several frequencies; every point with a saved time series
gets a time history, strain spectra and a switching diagram, and a chirp a
spectrogram and its FRFs (H1 and coherence of every acceleration and strain
against force1 over one record-long rectangular window, the chirp's,
:mod:`workbench.lab.frf`) as well, with their modes (:mod:`workbench.lab.modal`)
in ``tables/frf_modes.{csv,md,tex}``.
"""
from __future__ import annotations

import dataclasses
import json
import time
from pathlib import Path

import pandas as pd

from . import damage as D
from . import figures as F
from ..study.grid import point_slug, point_title
from ..study.provenance import environment
from ..study.store import read_runs, write_text_atomic
from ..model import drives
from ..study.definition import Study
from .point_checks import accuracy_lines, level_lines, range_lines
from .tables import write_frf_modes, write_tables
from ..lab.channels import CHANNELS, kind
from ..lab.frf import default_window, frf
from ..lab.modal import mode_table

#: The channels whose FRF against force1 a chirp's report shows.
RESPONSES = tuple(c for c in CHANNELS if kind(c) in ("accel", "strain"))


def _grid_figures(study: Study, table: pd.DataFrame) -> dict[str, object]:
    has = {a for a in ("gap_mm", "freq_hz") if f"axis_{a}" in table and table[f"axis_{a}"].nunique() > 1}
    frequency = drives.DRIVES[study.excitation["drive"]].frequency_key
    sine = frequency == "freq_hz" and "freq_hz" in has
    figs = {}
    if not (table.status == "ok").any():
        return figs
    if has == {"gap_mm", "freq_hz"}:
        figs["frf_map_tip"] = lambda: F.frf_maps(table)
        figs["frf_map_strain1"] = lambda: F.frf_maps(table, "strain1_rms")
        if "force_n_used" in table:
            figs["force_map"] = lambda: F.frf_maps(table, "force_n_used")
        figs["response_curves"] = lambda: F.response_curves(table)
    if sine:
        figs["regime_shares"] = lambda: F.regime_shares(table)
        figs["bifurcation"] = lambda: F.bifurcation(table)
    if D.is_wear_map(table):
        for name, measure in (("wear_map", "wear_volume_cm3"), ("impact_map", "impact_energy_erg"),
                              ("friction_map", "friction_work_erg")):
            figs[name] = (lambda m: lambda: D.wear_map(table, m, study.wear))(measure)
    return figs


def _series_figures(study: Study, row, tag: str, out: Path, frf_modes: list):
    """(name, figure builder) of one point's saved series (none if it has no series),
    each name ``<figure>_<tag>``; a chirp's FRF modes are added to ``frf_modes``."""
    path = out / "series" / f"{row.key}.parquet"
    if not path.exists():
        return
    sig = pd.read_parquet(path)
    ev = pd.read_parquet(path.with_suffix(".events.parquet"))
    t_end = float(sig.index[-1])
    title = point_label(row)
    if row.status != "ok":                     # what was computed before the failure
        title += f" — {row.status} at t = {t_end:.2f} s"
    short = min(0.5, study.window_s)
    yield f"time_history_{tag}", lambda: F.time_history(sig, row.static_tip_y, title, short)
    yield f"strain_spectra_{tag}", lambda: F.strain_spectra(sig, title, study.window_s)
    yield f"switching_{tag}", lambda: F.switching_diagram(ev, t_end, title, short)
    if drives.DRIVES[study.excitation["drive"]].swept:
        yield f"spectrogram_{tag}", lambda: F.spectrogram(sig, title)
        responses = [c for c in sig.columns if c in RESPONSES]
        f_lo, f_hi = drives.band_hz(study.excitation)
        tables = {title: frf(sig, responses, segment_s=None, window=default_window("chirp"))}
        found = mode_table(tables, responses, f_lo, f_hi)
        frf_modes.append(found)
        yield f"frf_{tag}", lambda: F.frf_figure(tables[title], responses,
                                                 f"{title}: H1 against force1", f_max=f_hi,
                                                 modes=found, f_min=f_lo)


#: Relative cost of drawing a grid figure (a series unit is 1): the order of the tasks.
_DRAW_COST = {"regime_shares": 4.0, "bifurcation": 3.0}


def point_label(row) -> str:
    """A point's title: its axis values, and a stepped sweep's direction."""
    return point_title(row) + (f", {row.direction} sweep" if row.direction else "")


def series_tags(table: pd.DataFrame) -> list[str]:
    """Each point's part of its figures' names: its axis values ("gap-1.016mm_tip-mass-on",
    :func:`~workbench.study.grid.point_slug`), a stepped sweep's direction, and the
    point's key where two points would share a name."""
    tags = [f"{point_slug(row) or 'point'}_{row.direction}".rstrip("_")
            for _, row in table.iterrows()]
    shared = {t for t in tags if tags.count(t) > 1}
    return [f"{t}_{key[:8]}" if t in shared else t for t, key in zip(tags, table.key)]


def heading(name: str, labels: dict[str, str]) -> str:
    """A figure's heading in the report: what it shows, and for which point
    (``labels``: each point's tag and :func:`point_label`)."""
    for tag, label in labels.items():
        if name.endswith(f"_{tag}"):
            return f"{name[:-len(tag) - 1].replace('_', ' ')} — {label}"
    return name.replace("_", " ")


def _draw(study: Study, table: pd.DataFrame, out: Path, unit) -> tuple[dict, list]:
    """Draw and save one unit of the report: a grid figure (its name) or the
    figures of one point's series (its row number and tag).  Returns the
    figures made {name: paths} and the FRF peak tables."""
    frf_modes: list = []
    if isinstance(unit, str):
        builders = [(unit, _grid_figures(study, table)[unit])]
    else:
        row, tag = unit
        builders = _series_figures(study, table.iloc[row], tag, out, frf_modes)
    made = {name: F.save(build(), out / "figures" / name) for name, build in builders}
    return made, frf_modes


def make_report(study: Study, results: str | Path = "results", jobs: int = 1) -> Path:
    """Write figures, tables, report.md and provenance.json for a study already run.

    The figures are drawn by ``jobs`` processes (joblib), a grid figure or
    one point's series per task.
    """
    if study.sample is not None:
        from .sensitivity import make_sensitivity_report
        return make_sensitivity_report(study, results)
    out = Path(results).resolve() / study.name      # absolute: worker processes keep their own cwd
    table = pd.read_parquet(out / "points.parquet")
    t0 = time.perf_counter()
    tags = series_tags(table)
    units = list(_grid_figures(study, table)) + [
        (i, tags[i]) for i, key in enumerate(table.key)
        if (out / "series" / f"{key}.parquet").exists()]
    if jobs > 1 and len(units) > 1:
        from joblib import Parallel, delayed
        # the many-panel grid figures first, so that the processes finish
        # together; the report keeps the units' order
        order = sorted(range(len(units)), key=lambda i: -_DRAW_COST.get(units[i], 1.0))
        done = Parallel(n_jobs=jobs)(delayed(_draw)(study, table, out, units[i]) for i in order)
        drawn = [None] * len(units)
        for i, result in zip(order, done):
            drawn[i] = result
    else:
        drawn = [_draw(study, table, out, u) for u in units]
    made = {name: paths for figures, _ in drawn for name, paths in figures.items()}
    frf_modes = [modes for _, found in drawn for modes in found]
    tables = write_tables(table, out / "tables")
    if frf_modes:
        tables += write_frf_modes(pd.concat(frf_modes, ignore_index=True), out / "tables")
    if D.is_wear_map(table):
        tables += D.write_extremes(table, study.wear, out / "tables")
    report_wall = time.perf_counter() - t0
    provenance = {**environment(), "study": study_definition(study),
                  "points": summary(table), "report_wall_s": report_wall,
                  "runs": read_runs(out)}
    write_text_atomic(json.dumps(provenance, indent=2, default=str) + "\n",
                      out / "provenance.json")
    index = out / "report.md"
    index.write_text(render_index(study, table, made, tables, out))
    return index


def study_definition(study: Study) -> dict:
    return {"name": study.name, "description": study.description, "source": study.source,
            "duration_s": study.duration_s, "window_s": study.window_s, "sweep": study.sweep,
            "dt": study.dt, "output_hz": study.output_hz, "method": study.method,
            "tol": study.tol, "initial": study.initial,
            "excitation": study.excitation, "fixed": study.fixed, "axes": study.axes,
            "wear": dataclasses.asdict(study.wear),
            "parameters_of_first_point": study.points[0].params.to_dict() if study.points else {}}


def summary(table: pd.DataFrame) -> dict:
    ok = table[table.status == "ok"] if len(table) else table
    return {"total": len(table),
            "status": {str(k): int(v) for k, v in table.status.value_counts().items()},
            "not_steady": int((~ok.steady.astype(bool)).sum()) if len(ok) else 0,
            "cpu_s": float(table.wall_s.sum()) if len(table) else 0.0,
            "simulated_s": float(ok.simulated_s.sum()) if len(ok) else 0.0}


def render_index(study, table, figures, tables, out) -> str:
    s = summary(table)
    lines = [f"# Study `{study.name}`", "", study.description, "",
             f"Definition: `{study.source}`; {study.n_points} points, {study.duration_s:g} s each, "
             f"steady-state window {study.window_s:g} s, sweep {study.sweep}.", "",
             f"Points: {s['status']}; not steady: {s['not_steady']}; "
             f"{s['simulated_s']:.0f} simulated s in {s['cpu_s']:.0f} CPU s.", "",
             "Data: [points.parquet](points.parquet) (one row per point), "
             "[provenance.json](provenance.json).", ""]
    failed = table[table.status != "ok"] if len(table) else table
    if len(failed):
        lines += ["## Points that did not finish", "",
                  "| point | status | stopped at (s) | reason |", "|---|---|---|---|"]
        lines += [f"| {point_title(r)} | {r.status} | {r.get('simulated_s', float('nan')):.3f} | "
                  f"{r.message} |" for _, r in failed.iterrows()]
        lines.append("")
    lines += accuracy_lines(study, table)
    lines += level_lines(study, table)
    lines += range_lines(table)
    if D.is_wear_map(table):
        lines += D.damage_lines(table, study.wear)
    if tables:
        lines += ["## Tables", "", "Values in SI (N, m/s², µε, mm), each column's unit in its "
                  "header; the points table keeps the model's CGS.", ""]
        lines += [f"- [{p.name}]({p.relative_to(out)})" for p in tables] + [""]
    if figures:
        lines += ["## Figures", ""]
    labels = dict(zip(series_tags(table), (point_label(row) for _, row in table.iterrows())))
    for name, paths in figures.items():
        png, pdf = (p.relative_to(out) for p in paths)
        lines += [f"### {heading(name, labels)}", "",
                  f"![{name}]({png}) ([PDF]({pdf}))", ""]
    return "\n".join(lines) + "\n"
