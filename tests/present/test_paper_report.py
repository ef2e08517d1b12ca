"""The paper comparison report (studies/paper.py): its tables come back from the saved cases."""
from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[2]


def paper_module():
    spec = importlib.util.spec_from_file_location("paper_report", ROOT / "studies" / "paper.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_reports_tables_are_rebuilt_from_the_saved_cases(tmp_path, monkeypatch):
    """A short sine case (3 s instead of 10) run, saved and reported; then the tables, the
    figures and the report written again from the saved cases alone, the same."""
    paper = paper_module()
    monkeypatch.setattr(paper, "SINE_S", 3.0)
    monkeypatch.setattr(paper, "SKIP_S", 1.0)
    case = paper.run_case("sine", "static", "default", "identified")
    assert case["error_measured"] is not None and case["status"] == 0
    gaps = [paper.run_gap_case(1.016, False, level) for level in ("lab", "fixed")]
    lab, fixed = gaps
    assert lab["force_n"] < 200.0 and lab["level_limit"] in ("accel", "slot", "tip", "force")
    assert lab["out_of_range"] == "" and fixed["force_n"] == 200.0
    paper.save_cases([case], tmp_path, gaps)
    paper.write_report([case], tmp_path, 1.0, gaps)
    first = pd.read_csv(tmp_path / "observations.csv")
    report = (tmp_path / "report.md").read_text()
    assert set(first.observation) == {"drive_line", "subharmonic", "peaks_60_100", "above_200",
                                      "switch_14_23", "code_13", "switch_rate"}
    per_gap = first[first.case == "every gap, tip mass on and off, 20 Hz"]
    assert set(per_gap.observation) == {"switch_14_23", "subharmonic"}
    assert per_gap.measure.str.contains("inside the validated range at the lab's levels").all()
    assert ((first.case == "sine, from static, 200 N, the identified moduli")
            | (first.case == "every gap, tip mass on and off, 20 Hz")).all()
    assert "## The 14/23 switching and the 10 Hz line at every gap" in report
    assert re.search(r"\|\s+1\.016\s+\|\s+off\s+\|\s+[0-9.]+ \((accel|slot|tip|force)\)", report)
    for name in ("observations.csv", "observations.md", "observations.tex", "report.md"):
        (tmp_path / name).unlink()
    paper.main(["--out", str(tmp_path), "--rebuild"])          # no run
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "observations.csv"), first)
    assert (tmp_path / "report.md").read_text() == report
    assert (tmp_path / "figures" / "switching_sine_static_default_identified.png").is_file()


def test_the_period_doubling_finding_is_read_from_the_study_and_set_beside_the_line(tmp_path):
    """A made-up force branch (200 N down to 80 N at 20 Hz) whose multiplier crosses -1
    between 90 and 85 N, and its doubled branch: the report states the bracket, the first
    orbit's time constant and the 10 Hz line the doubled orbits carry; without the study's
    results it says the study has not run."""
    import json
    import math
    paper = paper_module()
    assert "has not run" in "\n".join(paper.doubling_lines(tmp_path / "none"))
    folder = tmp_path / "period_doubling"
    (folder / "branch").mkdir(parents=True)
    summary = {"label": "branch", "status": "done", "message": "reached 80",
               "definition": {"continuation": {"parameter": "force_n"},
                              "excitation": {"drive": "sine", "freq_hz": 20.0}},
               "doubled": [{"folder": "doubled-85", "status": "done", "message": "reached 80",
                            "orbits": 2, "wall_s": 1.0}]}
    (folder / "branch" / "summary.json").write_text(json.dumps(summary))
    main = pd.DataFrame({"branch": "branch", "force_n": [200.0, 150.0, 90.0, 85.0, 80.0],
                         "stability": ["stable"] * 3 + ["unstable"] * 2,
                         "stable": [True] * 3 + [False] * 2,
                         "max_multiplier": [0.9995, 0.999, 0.99, 1.2, 1.3],
                         "bifurcation": ["", "", "", "period doubling", ""],
                         "strain1_h0.5": 0.0, "strain1_h1": 1e-4, "tip_h0.5_cm": 0.0})
    doubled = pd.DataFrame({"branch": "branch/doubled-85", "force_n": [85.0, 80.0],
                            "stability": "stable", "stable": True, "max_multiplier": 0.9,
                            "bifurcation": "", "strain1_h0.5": [1e-5, 3e-5],
                            "strain1_h1": 1e-4, "tip_h0.5_cm": [0.01, 0.02]})
    main.drop(columns="branch").to_parquet(folder / "branch" / "branch.parquet")
    (folder / "branch" / "doubled-85").mkdir()
    doubled.drop(columns="branch").to_parquet(folder / "branch" / "doubled-85" / "branch.parquet")
    text = "\n".join(paper.doubling_lines(folder))
    assert "period doubling between 90 and 85 N" in text and "|μ| at 85 N is 1.200" in text
    assert f"time constant of {-0.05 / math.log(0.9995):.0f} s" in text
    assert "2 orbits over 80-85 N, 2 stable" in text and "up to 0.3 of its 20 Hz line" in text
    assert "the tip's up to 0.2 mm" in text and "status done" in text
    assert "a new line near 10 Hz (the 10 Hz line)" in text
    (folder / "branch" / "summary.json").unlink()                 # the study cut short
    text = "\n".join(paper.doubling_lines(folder))
    assert "status interrupted" in text and "period doubling between 90 and 85 N" in text
    # lost instead by a complex pair near the negative axis (angle 2.9 rad): a line near
    # 20 * 2.9 / (2 pi) = 9.23 Hz, and no doubled branch
    main["bifurcation"] = ["", "", "", "neimark-sacker", ""]
    main["multiplier_crossing"] = ["", "", "", "complex", ""]
    main["crossing_angle"] = 2.9
    main["max_multiplier_angle"] = 0.0          # the largest multiplier is another one
    main.drop(columns="branch").to_parquet(folder / "branch" / "branch.parquet")
    text = "\n".join(paper.doubling_lines(folder))
    assert "by a neimark-sacker between 90 and 85 N" in text
    assert "at an angle of 2.900 rad: a new line near 9.23 Hz;" in text
    assert "branch of period 2" not in text
    # a nonsmooth loss at -1 (the events per period change): named so, with its events, its
    # line the 10 Hz line, and the doubled branch sought there
    main["bifurcation"] = ["", "", "", "nonsmooth", ""]
    main["multiplier_crossing"] = ["", "", "", "-1", ""]
    main["crossing_angle"] = -math.pi
    main["events_changed"] = ["", "", "", "separation 2->3", ""]
    main.drop(columns="branch").to_parquet(folder / "branch" / "branch.parquet")
    text = "\n".join(paper.doubling_lines(folder))
    assert ("by a nonsmooth bifurcation (its events per period change, separation 2->3, and "
            "a multiplier jumps out of the unit circle at -1) between 90 and 85 N") in text
    assert "a new line near 10 Hz (the 10 Hz line)" in text
    assert "2 orbits over 80-85 N" in text
