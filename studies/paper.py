"""The paper, side by side: each §6 observation measured in the model, with a verdict.

    python studies/paper.py --out results/paper [--jobs 2]

Runs the paper's cases (1.016 mm gap, tip mass, the default parameters): the 20 Hz sine of
10 s (Fig. 6-10) and the 5-65 Hz chirp of 240 s (Fig. 11-12), each from the static
equilibrium and from the paper's undeformed start, at the default shaker force (200 N) and
at a level the lab could have used: the paper's operator set the amplitude "so
as to not saturate the sensors", so the force is lowered by the response-limited rule
(``workbench.study.leveling``) until the accelerometers stay within their 50 g range.  The
sine from the static equilibrium runs also with the moduli the paper identified (MODULI).  Each
observation of ``workbench.present.observations.OBSERVATIONS`` is measured by the rule the
report states and given a verdict.  Writes report.md, observations.csv/.md/.tex, figures
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
from workbench.model.limits import ACCEL_RANGE_G
from workbench.model.params import Parameters
from workbench.model.regimes import contact_shares_of
from workbench.present import figures as F
from workbench.present import observations as O
from workbench.present.tables import latex_text
from workbench.study.leveling import limited_run
from workbench.study.metrics import accel_peak_g
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
MODULI = {"standard": {},
          "identified": {"e_a_gpa": float(APPENDIX_B_MEAN_E_GPA[1]),
                         "e_b_gpa": float(APPENDIX_B_MEAN_E_GPA[2])}}


def case_params(moduli: str = "standard") -> Parameters:
    return Parameters().replace(gap_mm=1.016, tip_mass=True, **MODULI[moduli])


def run_case(kind: str, start: str, level: str, moduli: str = "standard") -> dict:
    """One case's measures: the observations, the figures' data and the force used."""
    from workbench.model.simulate import simulate

    p = case_params(moduli)

    def at(force, check_accuracy=False):
        drive = (sine(force, O.DRIVE_HZ, ramp_s=RAMP_S) if kind == "sine"
                 else chirp(force, O.CHIRP_F0_HZ, O.CHIRP_F1_HZ, CHIRP_S, ramp_s=RAMP_S))
        return simulate(p, drive, SINE_S if kind == "sine" else CHIRP_S, initial=start,
                        check_accuracy=check_accuracy)
    if level == "default":
        run, force, runs, met = at(FORCE_N, True), FORCE_N, 1, True
    else:
        run, force, runs, met = limited_run(at, FORCE_N, ACCEL_RANGE_G, peak=accel_peak_g)
        run = at(force, True)          # the same run, with its companion
    out = {"kind": kind, "start": start, "level": level, "moduli": moduli, "force_n": force,
           "level_runs": runs,
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


def _number(value) -> str:
    return "none (the run failed)" if value is None else f"{value:.1e}"


def scenario(case: dict) -> str:
    level = (f"{case['force_n']:.0f} N" if case["level"] == "default"
             else f"lab level {case['force_n']:.0f} N (accel within {ACCEL_RANGE_G:g} g)")
    moduli = "" if case["moduli"] == "standard" else ", the identified moduli"
    return f"{case['kind']}, from {case['start']}, {level}{moduli}"


def table(cases: list[dict]) -> pd.DataFrame:
    rows = []
    for obs in O.OBSERVATIONS:
        for case in cases:
            if obs["id"] not in case.get("verdicts", {}):
                continue
            measure, verdict = case["verdicts"][obs["id"]]
            rows.append({"observation": obs["id"], "figures": obs["figures"],
                         "paper": obs["claim"], "case": scenario(case), "measure": measure,
                         "verdict": verdict})
    return pd.DataFrame(rows)


def tag_of(case: dict) -> str:
    """A case's file name: kind, start, level and any moduli other than the standard."""
    return f"{case['kind']}_{case['start']}_{case['level']}" + (
        "" if case["moduli"] == "standard" else f"_{case['moduli']}")


def save_cases(cases: list[dict], out: Path) -> None:
    """Each case's measures to cases.json; its signals and events to cases/<tag>.parquet."""
    (out / "cases").mkdir(parents=True, exist_ok=True)
    for c in cases:
        if "signals" in c:
            c["signals"].to_parquet(out / "cases" / f"{tag_of(c)}.parquet")
        if "events" in c:
            c["events"].astype({"kind": str}).to_parquet(out / "cases" / f"{tag_of(c)}.events.parquet")
    measures = [{k: v for k, v in c.items() if k not in ("signals", "events")} for c in cases]
    (out / "cases.json").write_text(json.dumps(measures, indent=1, default=float))


def load_cases(out: Path) -> list[dict]:
    """The cases saved by :func:`save_cases`, their signals and events read back where saved."""
    cases = json.loads((out / "cases.json").read_text())
    for c in cases:
        for key, suffix in (("signals", ".parquet"), ("events", ".events.parquet")):
            path = out / "cases" / f"{tag_of(c)}{suffix}"
            if path.is_file():
                c[key] = pd.read_parquet(path)
    return cases


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--rebuild", action="store_true",
                        help="write the tables, figures and report from the saved cases, no runs")
    args = parser.parse_args(argv)
    start_wall = time.perf_counter()
    if args.rebuild:
        cases = load_cases(args.out)
    else:
        jobs = [(kind, s, level) for kind in ("chirp", "sine") for s in STARTS
                for level in ("default", "lab")]
        jobs += [("sine", "static", level, "identified") for level in ("default", "lab")]
        cases = Parallel(n_jobs=args.jobs)(delayed(run_case)(*j) for j in jobs)
        args.out.mkdir(parents=True, exist_ok=True)
        save_cases(cases, args.out)
    write_report(cases, args.out, time.perf_counter() - start_wall)
    print(f"wrote {args.out}/report.md")


def write_report(cases: list[dict], out: Path, wall_s: float) -> None:
    """The observations' tables, the figures, report.md and provenance.json of the cases."""
    args = argparse.Namespace(out=out)
    (args.out / "figures").mkdir(parents=True, exist_ok=True)
    obs = table(cases)
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
             "force lowered by the response-limited rule until the accelerometers stay within "
             f"their {ACCEL_RANGE_G:g} g range (the paper's operator kept the sensors from "
             "saturating). Records are alias-free (valid to "
             f"{cases[0]['valid_band_hz'][1]:g} Hz).", "",
             "## Rules", ""]
    lines += [f"- {name}: {rule}." for name, rule in O.RULES.items()]
    lines += ["", "## Observations and verdicts", "", obs.to_markdown(index=False), "",
              "## Cases", "",
              "| case | force (N) | runs to level | accel peak (g) | status | global error "
              "estimate | error measured against the companion |",
              "|---|---|---|---|---|---|---|"]
    lines += [f"| {scenario(c)} | {c['force_n']:.1f} | {c['level_runs']} | "
              f"{c['accel_peak_g']:.1f} | {c['message']} | {c['global_error_est'] or 0:.1e} | "
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
                             if k not in ("signals", "events", "verdicts")} for c in cases]}
    (args.out / "provenance.json").write_text(json.dumps(provenance, indent=1, default=str))




if __name__ == "__main__":
    main()
