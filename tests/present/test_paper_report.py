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
