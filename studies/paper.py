"""The paper, side by side: each §6 observation measured in the model, with a verdict.

    python studies/paper.py --out results/paper [--jobs 2]

Runs the paper's cases (1.016 mm gap, tip mass, the default parameters): the 20 Hz sine of
10 s (Fig. 6-10) and the 5-65 Hz chirp of 240 s (Fig. 11-12), each from the static
equilibrium and from the paper's undeformed start, at the default shaker force (200 N) and
at a level the lab could have used: the paper's operator set the amplitude "so
as to not saturate the sensors", so the force is the largest up to 200 N at which the
sensors, the tip and the slide stay within their ranges (``workbench.study.leveling``, the
default shaker study's rule).  The sine from the static equilibrium runs also with the moduli
the paper identified (MODULI).  Each observation of
``workbench.present.observations.OBSERVATIONS`` is measured by the rule the report states and
given a verdict.  The 14/23 switching and the 10 Hz line are measured also for every gap with
and without the tip mass, at the lab's level and at 200 N, with whether each run stayed within
the range the model is validated for (VALIDATED_GAPS_MM).  Writes report.md, observations.csv/.md/.tex, figures
(PNG and PDF) and provenance.json into --out; part of ``make study``.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import pandas as pd
from joblib import Parallel, delayed

from workbench.identify.paper import APPENDIX_B_MEAN_E_GPA
from workbench.model.drives import chirp, sine
from workbench.model.params import Parameters
from workbench.model.regimes import contact_shares_of
from workbench.present import figures as F
from workbench.present import observations as O
from workbench.present.branch import CROSSING_WORDS, period_doubling_finding
from workbench.present.tables import latex_text
from workbench.study.leveling import Limits, level
from workbench.model.validity import accel_peak_g, validity
from workbench.study.provenance import environment

FORCE_N = 200.0
SINE_S, CHIRP_S, RAMP_S = O.SINE_S, O.CHIRP_S, O.RAMP_S
#: The sine's spectra and shares are taken after the soft start and the first transient.
SKIP_S = O.SINE_SKIP_S
#: The chirp's first seconds are transient ("should be ignored", §6).
CHIRP_SKIP_S = O.CHIRP_SKIP_S
STARTS = ("static", "paper")
#: The beams' moduli: the paper's "standard values" (the model's defaults), or those it
#: identified from the beams' free decays (§4.4, Appendix B's means; beam 1 is beam A), which
#: the sensitivity study finds decide the subharmonic.
#: The gaps of the per-gap section (seed §5.1), each with and without the tip mass.
VALIDATED_GAPS_MM = (0.508, 0.635, 0.762, 1.016)
#: The lab's level: the default shaker study's limits (datasheet ranges, tip, slot).
LAB_LIMITS = Limits()
MODULI = {"standard": {},
          "identified": {"e_a_gpa": float(APPENDIX_B_MEAN_E_GPA[1]),
                         "e_b_gpa": float(APPENDIX_B_MEAN_E_GPA[2])}}


def case_params(moduli: str = "standard") -> Parameters:
    return Parameters().replace(gap_mm=1.016, tip_mass=True, **MODULI[moduli])


def run_case(kind: str, start: str, level: str, moduli: str = "standard") -> dict:
    """One case's measures: the observations, the figures' data and the force used."""
    from workbench.model.simulate import simulate

    p = case_params(moduli)

    def at(force, check_accuracy=False, stop=None):
        drive = (sine(force, O.DRIVE_HZ, ramp_s=RAMP_S) if kind == "sine"
                 else chirp(force, O.CHIRP_F0_HZ, O.CHIRP_F1_HZ, CHIRP_S, ramp_s=RAMP_S))
        return simulate(p, drive, SINE_S if kind == "sine" else CHIRP_S, initial=start,
                        check_accuracy=check_accuracy, stop=stop)
    if level == "default":
        run, force, runs, met, limit = at(FORCE_N, True), FORCE_N, 1, True, "none"
    else:
        found = level_of(at)
        force, runs, met, limit = found.force_n, found.runs, found.met, found.limit
        run = at(force, True)          # the same run, with its companion
    out = {"kind": kind, "start": start, "level": level, "moduli": moduli, "force_n": force,
           "level_runs": runs, "level_limit": limit, **validity(run),
           "level_met": met, "status": run.status, "message": run.message,
           "accel_peak_g": accel_peak_g(run), "global_error_est": run.control.get("global_error_est"),
           "error_measured": run.control.get("error_measured"),
           "valid_band_hz": run.summary()["anti_alias"]["valid_band_hz"]}
    if not run.ok:
        return out
    sig = run.signals
    t = sig.index.to_numpy()
    if kind == "sine":
        keep = t >= SKIP_S - 1e-12
        shares = contact_shares_of(run.log[:, 0], run.log[:, 3], SKIP_S, float(t[-1]))
        ev = run.events[(run.events.t >= SKIP_S) & (run.events.kind != "start")]
        rate = len(ev) / (t[-1] - SKIP_S)
        out["verdicts"] = O.assess_sine(t[keep], sig.strain1.to_numpy()[keep],
                                        {int(k): v for k, v in shares.items()}, rate)
        out["signals"] = sig[["strain1", "strain2"]][keep]
        out["events"] = run.events
        out["t_end"] = float(t[-1])
    else:
        verdicts, bands = O.assess_chirp(t, sig.strain1.to_numpy(), CHIRP_SKIP_S)
        out["verdicts"], out["bands_min"] = verdicts, bands
        out["signals"] = sig[["strain1"]]
    return out


def level_of(at):
    """The lab's level of a case (``at(force, stop=...)`` runs it): the leveling search."""
    return level(at, FORCE_N, LAB_LIMITS)


def run_gap_case(gap_mm: float, tip_mass: bool, level_name: str) -> dict:
    """The 20 Hz sine from the static equilibrium at one gap, with or without the tip mass,
    at the lab's level or at FORCE_N: the 14/23 shares, the 10 Hz line, the validated range."""
    from workbench.model.simulate import simulate

    p = Parameters().replace(gap_mm=gap_mm, tip_mass=tip_mass)

    def at(force, stop=None):
        return simulate(p, sine(force, O.DRIVE_HZ, ramp_s=RAMP_S), SINE_S, stop=stop)
    if level_name == "lab":
        found = level_of(at)
        run, force, limit = found.run, found.force_n, found.limit
    else:
        run, force, limit = at(FORCE_N), FORCE_N, "none"
    out = {"gap_mm": gap_mm, "tip_mass": tip_mass, "level": level_name, "force_n": force,
           "level_limit": limit, "status": run.status, "message": run.message}
    if not run.ok:
        return out
    sig = run.signals
    t = sig.index.to_numpy()
    keep = t >= SKIP_S - 1e-12
    shares = {int(k): v for k, v in contact_shares_of(run.log[:, 0], run.log[:, 3], SKIP_S,
                                                       float(t[-1])).items()}
    ev = run.events[(run.events.t >= SKIP_S) & (run.events.kind != "start")]
    verdicts = O.assess_sine(t[keep], sig.strain1.to_numpy()[keep], shares,
                             len(ev) / (t[-1] - SKIP_S))
    out.update(validity(run))
    out.update({"share_14": shares.get(14, 0.0), "share_23": shares.get(23, 0.0),
                "switch_14_23": verdicts["switch_14_23"][1],
                "subharmonic": verdicts["subharmonic"][1], "sub_measure": verdicts["subharmonic"][0]})
    return out


def gap_table(gap_cases: list[dict]) -> pd.DataFrame:
    """One row per gap and tip mass: each level's force, range and two verdicts."""
    rows = []
    for gap in VALIDATED_GAPS_MM:
        for tip in (True, False):
            row = {"gap (mm)": gap, "tip mass": "on" if tip else "off"}
            for c in gap_cases:
                if c["gap_mm"] != gap or c["tip_mass"] != tip:
                    continue
                name = "lab level" if c["level"] == "lab" else f"{FORCE_N:g} N"
                if c["status"] != 0:
                    row[f"{name}: force (N)"] = f"{c['force_n']:.3g} (failed: {c['message']})"
                    continue
                force = f"{c['force_n']:.3g}" + (f" ({c['level_limit']})" if c["level"] == "lab" else "")
                row[f"{name}: force (N)"] = force
                row[f"{name}: validated range"] = ("inside" if not c["out_of_range"]
                                                   else f"outside ({c['out_of_range']})")
                row[f"{name}: 14/23 switching"] = (f"{c['switch_14_23']} ({c['share_14']:.2f}/"
                                                   f"{c['share_23']:.2f})")
                row[f"{name}: 10 Hz line"] = f"{c['subharmonic']} ({c['sub_measure'].split(' over')[0].replace('10 Hz line ', '')})"
            rows.append(row)
    return pd.DataFrame(rows)


def within_range(gap_cases: list[dict], observation: str) -> tuple[str, str]:
    """Where an observation appears, in words, and a verdict: at the lab's levels inside the
    validated range, or else at 200 N, with the levels involved."""
    def where(level_name):
        found = [c for c in gap_cases if c["level"] == level_name and c["status"] == 0
                 and c[observation] == "reproduced"]
        inside = [c for c in found if not c["out_of_range"]]
        return found, inside
    lab, lab_inside = where("lab")
    high, high_inside = where("fixed")
    n = sum(1 for c in gap_cases if c["level"] == "lab")

    def cases(cs):
        return ", ".join(f"{c['gap_mm']:g} mm {'with' if c['tip_mass'] else 'without'} tip "
                         f"mass at {c['force_n']:.3g} N" for c in cs) or "none"
    text = (f"inside the validated range at the lab's levels: {len(lab_inside)} of {n} gap and "
            f"tip-mass cases ({cases(lab_inside)})")
    if not lab_inside:
        text += (f"; at {FORCE_N:g} N: {len(high)} of {n} ({cases(high)}), "
                 + ("all outside the validated range" if high and not high_inside
                    else f"{len(high_inside)} inside"))
    verdict = ("reproduced within the validated range" if lab_inside
               else "reproduced at 200 N within the range" if high_inside
               else "only beyond the validated range" if high else "not")
    return text, verdict


def _number(value) -> str:
    return "none (the run failed)" if value is None else f"{value:.1e}"


def scenario(case: dict) -> str:
    level = (f"{case['force_n']:.0f} N" if case["level"] == "default"
             else f"lab level {case['force_n']:.0f} N")
    moduli = "" if case["moduli"] == "standard" else ", the identified moduli"
    return f"{case['kind']}, from {case['start']}, {level}{moduli}"


def table(cases: list[dict], gap_cases: list[dict] | None = None) -> pd.DataFrame:
    """The observations and verdicts; the 14/23 switching and the 10 Hz line with where they
    appear within the validated range (``gap_cases``)."""
    rows = []
    for obs in O.OBSERVATIONS:
        for case in cases:
            if obs["id"] not in case.get("verdicts", {}):
                continue
            measure, verdict = case["verdicts"][obs["id"]]
            rows.append({"observation": obs["id"], "figures": obs["figures"],
                         "paper": obs["claim"], "case": scenario(case), "measure": measure,
                         "verdict": verdict,
                         "validated range": ("inside" if not case.get("out_of_range")
                                             else f"outside ({case['out_of_range']})")})
        if gap_cases and obs["id"] in ("switch_14_23", "subharmonic"):
            rows.append({"observation": obs["id"], "figures": obs["figures"],
                         "paper": obs["claim"], "case": "every gap, tip mass on and off, 20 Hz",
                         "measure": within_range(gap_cases, obs["id"])[0],
                         "verdict": within_range(gap_cases, obs["id"])[1],
                         "validated range": "per case, in the measure"})
    return pd.DataFrame(rows)


def tag_of(case: dict) -> str:
    """A case's file name: kind, start, level and any moduli other than the standard."""
    return f"{case['kind']}_{case['start']}_{case['level']}" + (
        "" if case["moduli"] == "standard" else f"_{case['moduli']}")


def save_cases(cases: list[dict], out: Path, gap_cases: list[dict] = ()) -> None:
    """Each case's measures to cases.json; its signals and events to cases/<tag>.parquet; the
    per-gap cases' measures to gap_cases.json."""
    (out / "cases").mkdir(parents=True, exist_ok=True)
    for c in cases:
        if "signals" in c:
            c["signals"].to_parquet(out / "cases" / f"{tag_of(c)}.parquet")
        if "events" in c:
            c["events"].astype({"kind": str}).to_parquet(out / "cases" / f"{tag_of(c)}.events.parquet")
    measures = [{k: v for k, v in c.items() if k not in ("signals", "events")} for c in cases]
    (out / "cases.json").write_text(json.dumps(measures, indent=1, default=float))
    (out / "gap_cases.json").write_text(json.dumps(list(gap_cases), indent=1, default=float))


def load_cases(out: Path) -> tuple[list[dict], list[dict]]:
    """The cases and per-gap cases saved by :func:`save_cases`, the cases' signals and events
    read back where saved."""
    cases = json.loads((out / "cases.json").read_text())
    for c in cases:
        for key, suffix in (("signals", ".parquet"), ("events", ".events.parquet")):
            path = out / "cases" / f"{tag_of(c)}{suffix}"
            if path.is_file():
                c[key] = pd.read_parquet(path)
    return cases, json.loads((out / "gap_cases.json").read_text())


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--rebuild", action="store_true",
                        help="write the tables, figures and report from the saved cases, no runs")
    parser.add_argument("--doubling", type=Path, default=None,
                        help="results of studies/period_doubling.toml (default: beside --out)")
    args = parser.parse_args(argv)
    start_wall = time.perf_counter()
    if args.rebuild:
        cases, gap_cases = load_cases(args.out)
    else:
        jobs = [(run_case, (kind, s, level)) for kind in ("chirp", "sine") for s in STARTS
                for level in ("default", "lab")]
        jobs += [(run_case, ("sine", "static", level, "identified")) for level in ("default", "lab")]
        jobs += [(run_gap_case, (gap, tip, level)) for gap in VALIDATED_GAPS_MM
                 for tip in (True, False) for level in ("lab", "fixed")]
        done = Parallel(n_jobs=args.jobs)(delayed(f)(*a) for f, a in jobs)
        cases = [c for c in done if "kind" in c]
        gap_cases = [c for c in done if "gap_mm" in c]
        args.out.mkdir(parents=True, exist_ok=True)
        save_cases(cases, args.out, gap_cases)
    write_report(cases, args.out, time.perf_counter() - start_wall, gap_cases,
                 args.doubling or args.out.parent / "period_doubling")
    print(f"wrote {args.out}/report.md")


def doubling_lines(folder: Path) -> list[str]:
    """The 10 Hz line against the period-1 orbit continued in force at 20 Hz (the period
    doubling study's results in ``folder``), beside the §6 observation."""
    from workbench.study.definition import load
    f = period_doubling_finding(load(Path(__file__).parent / "period_doubling.toml"), folder)
    head = ["## The 10 Hz line and the period-1 orbit (§6, Fig. 7-8)", ""]
    if f is None:
        return head + [f"The period doubling study has not run (no results in {folder}: "
                       "`workbench sweep studies/period_doubling.toml`).", ""]
    unit = f["unit"]
    lines = head + [
        f"The periodic response of period 1 (the drive's), continued in force from "
        f"{f['start']:g} to {f['end']:.4g} {unit} at {O.DRIVE_HZ:g} Hz "
        "(`studies/period_doubling.toml`, [its report](../period_doubling/report.md); status "
        f"{f['status']}: {f['message']}; {f['orbits']} orbits).  At {f['start']:g} {unit} it is "
        f"{f['first_stable']}, its largest multiplier {f['first_multiplier']:.6f} a period"
        + (f": a disturbance of it decays with a time constant of "
           f"{f['time_constant_s']:.0f} s, so a {SINE_S:g} s run from rest is not yet on it"
           if f["time_constant_s"] else "") + "."]
    d = f["doubling"]
    if d is None:
        lines += ["", f"It loses stability nowhere between {f['start']:g} and {f['end']:.4g} "
                  f"{unit}: where it is stable there, the period-1 orbit has no 10 Hz line.", ""]
        return lines
    line = ("" if d["line_hz"] is None else
            f": a new line near {d['line_hz']:.3g} Hz" + (" (the 10 Hz line)"
                                                        if d["crossing"] == "-1" else ""))
    how = (f"a nonsmooth bifurcation (its events per period change, {d['events_changed']}, "
           f"and a multiplier jumps out of the unit circle {CROSSING_WORDS[d['crossing']]})"
           if d["kind"] == "nonsmooth" else f"a {d['kind']}")
    lines += ["", f"**It loses stability by {how} between "
              f"{d['last_stable']:.4g} and {d['first_unstable']:.4g} {unit}** ("
              + ("" if d["angle"] is None else f"the multiplier that left the unit circle "
                 f"lies at an angle of {d['angle']:.3f} rad{line}; ")
              + f"the largest |μ| at {d['first_unstable']:.4g} {unit} is {d['multiplier']:.3f}; "
              "orbits between, if any, of stability undetermined); above "
              f"{d['last_stable']:.4g} {unit}, the paper's 200 N included, the period-1 orbit, "
              "which has no 10 Hz line, is stable (a coexisting response is not excluded: "
              "continuation follows one branch)."]
    dd = d["doubled"]
    if dd and dd.get("orbits"):
        lines += ["", f"The branch of period 2 born there ({dd['orbits']} orbits over "
                  f"{dd['range'][0]:.4g}-{dd['range'][1]:.4g} {unit}, {dd['stable']} stable; "
                  f"{dd['status']}: {dd['message']}) carries the 10 Hz line: strain1's line at "
                  f"10 Hz up to {dd['strain_half_over_drive']:.3g} of its 20 Hz line (at "
                  f"{dd['at']:.4g} {unit}), the tip's up to {10 * dd['tip_half_cm']:.3g} mm."]
    elif dd:
        lines += ["", f"No orbit of period 2 was found beside it ({dd['status']}: "
                  f"{dd['message']})."]
    return lines + [""]


def write_report(cases: list[dict], out: Path, wall_s: float,
                 gap_cases: list[dict] | None = None, doubling: Path | None = None) -> None:
    """The observations' tables, the figures, report.md and provenance.json of the cases; the
    period doubling study's finding from its results in ``doubling``."""
    args = argparse.Namespace(out=out)
    (args.out / "figures").mkdir(parents=True, exist_ok=True)
    gap_cases = gap_cases or []
    obs = table(cases, gap_cases)
    obs.to_csv(args.out / "observations.csv", index=False)
    (args.out / "observations.md").write_text(obs.to_markdown(index=False) + "\n")
    (args.out / "observations.tex").write_text(
        obs.map(lambda v: latex_text(str(v))).to_latex(index=False, escape=False))
    figures = []
    for c in cases:
        if "signals" not in c:
            continue
        tag = tag_of(c)
        if c["kind"] == "sine":
            figures.append((f"Strain spectra, {scenario(c)} (Fig. 7-8)",
                            F.save(F.strain_spectra(c["signals"], scenario(c)),
                                   args.out / "figures" / f"spectra_{tag}")))
            figures.append((f"Contact switching, {scenario(c)} (Fig. 9)",
                            F.save(F.switching_diagram(c["events"], c["t_end"], scenario(c)),
                                   args.out / "figures" / f"switching_{tag}")))
        else:
            fig = F.spectrogram(c["signals"], scenario(c) + "; detected bands dashed")
            for b in c["bands_min"]:
                fig.axes[0].axvline(b, color="w", ls="--", lw=1.0)
            for b in O.PAPER_BANDS_MIN:
                fig.axes[0].axvline(b, color="k", ls=":", lw=1.0)
            figures.append((f"Spectrogram, {scenario(c)} (Fig. 11-12; the paper's bands dotted)",
                            F.save(fig, args.out / "figures" / f"spectrogram_{tag}")))
    counts = obs.verdict.value_counts().to_dict() if len(obs) else {}
    lines = ["# The paper, side by side",
             "",
             "Each observation of the paper's §6 measured in the model (1.016 mm gap, tip mass, "
             f"default parameters): {', '.join(f'{n} {v}' for v, n in counts.items())}.",
             "",
             "The sine from the static equilibrium runs also with the beams' moduli the paper "
             "identified from their free decays (§4.4, Appendix B: E_A "
             f"{MODULI['identified']['e_a_gpa']:g} GPa, E_B {MODULI['identified']['e_b_gpa']:g} "
             "GPa) instead of its standard 70 GPa: the global sensitivity study finds the moduli "
             "decide the subharmonic.",
             "",
             "Cases: the 20 Hz sine of 10 s (Fig. 6-10; measured after "
             f"{SKIP_S:g} s) and the 5-65 Hz chirp of 240 s (Fig. 11-12; bands after "
             f"{CHIRP_SKIP_S:g} s), from the static equilibrium and from the paper's undeformed "
             f"start, at the default {FORCE_N:g} N and at the lab's level: the "
             f"largest force up to {FORCE_N:g} N at which the accelerometers "
             f"({LAB_LIMITS.accel_g:g} g), the force transducer ({LAB_LIMITS.force_transducer_n:g} N), "
             f"the tip ({10 * LAB_LIMITS.tip_cm:g} mm) and the slide (the slot's travel) stay within "
             "range, found within a factor "
             f"{LAB_LIMITS.resolution:g} (the paper's operator kept the sensors from "
             "saturating; the default shaker study's rule). Records are alias-free (valid to "
             f"{cases[0]['valid_band_hz'][1]:g} Hz).", "",
             "## Rules", ""]
    lines += [f"- {name}: {rule}." for name, rule in O.RULES.items()]
    lines += ["", "## Observations and verdicts", "", obs.to_markdown(index=False), ""]
    lines += doubling_lines(doubling or out.parent / "period_doubling")
    if gap_cases:
        lines += ["## The 14/23 switching and the 10 Hz line at every gap, within the validated range",
                  "",
                  f"The {O.DRIVE_HZ:g} Hz sine of {SINE_S:g} s from the static equilibrium "
                  f"(measured after {SKIP_S:g} s), cubic cork, at the lab's level (the limit "
                  f"that decided it in brackets) and at {FORCE_N:g} N; 'validated range': whether "
                  "the whole run kept the tip within 84 mm, the slide within the slot's travel "
                  "and the sensors within their ranges (the limits it left). The lab observed "
                  "both with sensors that did not saturate (§5.2).", "",
                  gap_table(gap_cases).to_markdown(index=False), ""]
    lines += [
              "## Cases", "",
              "| case | force (N) | runs to level (limit) | accel peak (g) | validated range | "
              "status | global error estimate | error measured against the companion |",
              "|---|---|---|---|---|---|---|---|"]
    lines += [f"| {scenario(c)} | {c['force_n']:.1f} | {c['level_runs']} ({c['level_limit']}) | "
              f"{c['accel_peak_g']:.1f} | {'inside' if not c.get('out_of_range') else 'outside (' + c['out_of_range'] + ')'} | "
              f"{c['message']} | {c['global_error_est'] or 0:.1e} | "
              f"{_number(c['error_measured'])} |" for c in cases]
    lines += ["", "The measured error is the run's difference from a companion run at a tenth of "
              "the tolerance and half the coarsest step: the larger of the tip's over its range "
              "and a contact share's (workbench.model.accuracy)."]
    lines += ["", "Which parameters decide each verdict: the global sensitivity study "
              "(`make sensitivity`, [its report](../sensitivity/report.md) when it has run). "
              "Not here: the Fig. 6 amplitudes against the experiment's (the paper's figures "
              "carry no numbers in the text).", "", "## Figures", ""]
    for title, paths in figures:
        png, pdf = (p.relative_to(args.out) for p in paths)
        lines += [f"### {title}", "", f"![{title}]({png}) ([PDF]({pdf}))", ""]
    (args.out / "report.md").write_text("\n".join(lines) + "\n")
    provenance = {**environment(), "study": "paper", "wall_s": wall_s,
                  "parameters": case_params().to_dict(),
                  "cases": [{k: v for k, v in c.items()
                             if k not in ("signals", "events", "verdicts")} for c in cases],
                  "gap_cases": gap_cases}
    (args.out / "provenance.json").write_text(json.dumps(provenance, indent=1, default=str))




if __name__ == "__main__":
    main()
