"""Global sensitivity studies: the design, the indices, the report (workbench/study/sensitivity.py,
workbench/present/sensitivity.py)."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from workbench.study import definition as S
from workbench.study import sweep as W
from workbench.study.sensitivity import indices

HEAD = """
[study]
name = "{name}"
duration_s = {duration}
window_s = {window}

[excitation]
drive = "sine"
freq_hz = 20.0
ramp_s = 0.1

[fixed]
tip_mass = true
"""

#: Ishigami & Homma (1990) with a = 7, b = 0.1 on [-pi, pi]^3: V = a^2/8 + b pi^4/5
#: + b^2 pi^8/18 + 1/2, V1 = (1 + b pi^4/5)^2 / 2, V2 = a^2/8, V13 = b^2 pi^8 (1/18 - 1/50)
#: (Saltelli et al., Global Sensitivity Analysis: The Primer, 2008, §4.9).
A, B = 7.0, 0.1
V = A ** 2 / 8 + B * math.pi ** 4 / 5 + B ** 2 * math.pi ** 8 / 18 + 0.5
V1, V2, V13 = (1 + B * math.pi ** 4 / 5) ** 2 / 2, A ** 2 / 8, B ** 2 * math.pi ** 8 * (1 / 18 - 1 / 50)
EXACT = pd.DataFrame({"S1": [V1 / V, V2 / V, 0.0], "ST": [(V1 + V13) / V, V2 / V, V13 / V]})


def write(tmp_path, text, name="s.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_ishigami_functions_indices_come_back_through_a_study(tmp_path):
    """Three model parameters drawn over their ranges, mapped onto [-pi, pi], give the
    Ishigami function's known indices within their bootstrap intervals (and 0.03)."""
    ranges = {"zeta_b": (0.002, 0.02), "zeta_a": (0.002, 0.02), "e_a_gpa": (46.0, 70.0)}
    text = HEAD.format(name="ishigami", duration=0.5, window=0.25) + """
[sample]
n = 1024
seed = 7

[ranges]
""" + "\n".join(f"{k} = [{lo}, {hi}]" for k, (lo, hi) in ranges.items()) + "\n"
    study = S.load(write(tmp_path, text))
    assert study.n_points == 1024 * 5 == study.sample.n_points
    x = np.array([[(-math.pi + 2 * math.pi * (p.values[k] - lo) / (hi - lo))
                   for k, (lo, hi) in ranges.items()] for p in study.points])
    y = np.sin(x[:, 0]) + A * np.sin(x[:, 1]) ** 2 + B * x[:, 2] ** 4 * np.sin(x[:, 0])
    got = indices(study.sample, y)
    assert list(got.input) == list(ranges) and (got.n_used == 1024).all()
    for key in ("S1", "ST"):
        err = np.abs(got[key].to_numpy() - EXACT[key].to_numpy())
        assert (err < np.maximum(got[f"{key}_conf"].to_numpy(), 0.01) + 0.02).all(), (key, got)
        assert (err < 0.03).all(), (key, got)


def test_a_failed_point_takes_its_block_out():
    from workbench.study.sensitivity import parse
    sample = parse({"n": 8, "seed": 1}, {"mu_s": [0.1, 0.6], "gap_mm": [0.5, 1.0]})
    rng = np.random.default_rng(0)
    y = rng.normal(size=sample.n_points)
    y[5] = np.nan                                        # in the second block of 4 rows
    assert indices(sample, y).n_used.iloc[0] == 7
    with pytest.raises(ValueError, match="3 outputs for a design of 32 points"):
        indices(sample, y[:3])


def test_choices_and_factors_and_tied_inputs_make_the_points(tmp_path):
    text = HEAD.format(name="mixed", duration=0.5, window=0.25) + """
[sample]
n = 4
seed = 3
same = {mu_k = "mu_s"}

[ranges]
mu_s = [0.1, 0.6]
cork = ["linear", "cubic"]
cork_k = {times = [0.5, 2.0]}
force_n = [100.0, 200.0]
"""
    study = S.load(write(tmp_path, text))
    design = study.sample.design_matrix()
    assert study.n_points == len(design) == 4 * 6
    for p, row in zip(study.points, design):
        law = "linear" if row[1] < 1 else "cubic"
        own_k = {"linear": 2.70e5, "cubic": 1.0e4}[law]
        assert p.params.cork == law and p.params.mu_k == p.params.mu_s == pytest.approx(row[0])
        assert p.params.cork_k == pytest.approx(row[2] * own_k)
        assert p.excitation["force_n"] == pytest.approx(row[3])


@pytest.mark.parametrize("tables, message", [
    ('[axes]\ngap_mm = [0.5]\n[sample]\nn = 4\n[ranges]\nmu_s = [0.1, 0.6]',
     r"\[axes\] \(a grid\) or \[sample\] with \[ranges\]"),
    ('[sample]\nn = 6\n[ranges]\nmu_s = [0.1, 0.6]', r"\[sample\] n = 6 must be a power of 2"),
    ('[sample]\nn = 4\n[ranges]\nmu_s = [0.6, 0.1]', r"\[ranges\] mu_s = \[0.6, 0.1\] must be"),
    ('[sample]\nn = 4\n[ranges]\nmu_s = {times = [0.0, 2.0]}', r"factors must be > 0"),
    ('[sample]\nn = 4\nsame = {mu_k = "mu"}\n[ranges]\nmu_s = [0.1, 0.6]',
     r"same: mu_k = 'mu' names no input"),
    ('[sample]\nn = 4\n[ranges]\nmu_z = [0.1, 0.6]', r"unknown parameter 'mu_z'"),
    ('[ranges]\nmu_s = [0.1, 0.6]', r"\[ranges\] needs a \[sample\] table"),
    ('[sample]\nn = 4\n[ranges]\nmu_s = [0.1, 9.0]', r"mu_s"),
])
def test_a_bad_design_is_refused_in_one_line(tmp_path, tables, message):
    text = HEAD.format(name="bad", duration=0.5, window=0.25) + tables + "\n"
    with pytest.raises(S.StudyError, match=message):
        S.load(write(tmp_path, text))


def test_a_sampled_study_runs_and_its_report_is_rebuilt_from_the_saved_points(tmp_path):
    """Eight short runs; the indices' table comes back the same from points.parquet alone."""
    from workbench.present.report import make_report
    text = HEAD.format(name="tiny", duration=2.0, window=1.0) + """
[sample]
n = 2
seed = 5

[ranges]
force_n = [20.0, 200.0]
cork = ["linear", "cubic"]
"""
    study = S.load(write(tmp_path, text))
    table = W.run_study(study, tmp_path / "res", jobs=1, progress=False)
    assert (table.status == "ok").all() and table.strain1_sub_db.notna().all()
    report = make_report(study, tmp_path / "res")
    text = report.read_text()
    assert "# Global sensitivity `tiny`" in text and "| force_n | 20 to 200 | interval |" in text
    first = pd.read_csv(tmp_path / "res" / "tiny" / "tables" / "sobol.csv")
    assert set(first.output) >= {"share_14", "strain1_sub_db", "band1_min", "holds_subharmonic"}
    assert (first[first.output == "strain1_h1"].n_used == 2).all()
    (tmp_path / "res" / "tiny" / "tables" / "sobol.csv").unlink()
    make_report(study, tmp_path / "res")                 # no run: the points are read back
    again = pd.read_csv(tmp_path / "res" / "tiny" / "tables" / "sobol.csv")
    pd.testing.assert_frame_equal(first, again)
    assert (tmp_path / "res" / "tiny" / "figures" / "sobol_share_14.png").is_file()
