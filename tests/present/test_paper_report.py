"""The paper comparison report (studies/paper.py): its tables come back from the saved cases."""
from __future__ import annotations

import importlib.util
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
    paper.save_cases([case], tmp_path)
    paper.write_report([case], tmp_path, 1.0)
    first = pd.read_csv(tmp_path / "observations.csv")
    report = (tmp_path / "report.md").read_text()
    assert set(first.observation) == {"drive_line", "subharmonic", "peaks_60_100", "above_200",
                                      "switch_14_23", "code_13", "switch_rate"}
    assert (first.case == "sine, from static, 200 N, the identified moduli").all()
    for name in ("observations.csv", "observations.md", "observations.tex", "report.md"):
        (tmp_path / name).unlink()
    paper.main(["--out", str(tmp_path), "--rebuild"])          # no run
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "observations.csv"), first)
    assert (tmp_path / "report.md").read_text() == report
    assert (tmp_path / "figures" / "switching_sine_static_default_identified.png").is_file()
