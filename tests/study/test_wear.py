"""The wear measures (study/wear.py), the damage map's report and the controller's advice
(study/advice.py): against the energy audit, a closed form, the tolerance, and saved points."""
from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from workbench import cli
from workbench.core import layout as ly
from workbench.model import drives
from workbench.model.params import ParameterError, Parameters
from workbench.model.simulate import simulate
from workbench.present.report import make_report
from workbench.study import definition as S
from workbench.study import sweep as W
from workbench.study.advice import advise
from workbench.study.metrics import point_metrics
from workbench.study.wear import WearConstants, wear_constants, wear_measures

from small_studies import DAMAGE


def test_the_points_friction_work_adds_up_to_the_audits_over_the_window():
    """100 N at 20 Hz, the steady window the last second: the friction work of the four points
    per cycle sums to the audit's friction dissipation per cycle (``diss_friction``), the
    impact energy to ``diss_impact``, to the audit's own residual."""
    run = simulate(Parameters(), drives.sine(100.0, 20.0, ramp_s=0.3), 2.0)
    assert run.ok, run.message
    m = point_metrics(run, 1.0, 20.0)
    residual = run.summary()["energy_balance_rel"] * run.signals.w_excitation.abs().max() / 20.0
    assert sum(m[f"friction_work{k}_erg"] for k in range(1, 5)) == pytest.approx(
        m["diss_friction"], abs=max(residual, 1e-9 * m["diss_friction"]))
    assert m["impact_energy_erg"] == pytest.approx(m["diss_impact"], rel=1e-9)
    assert m["impacts"] * 20.0 == pytest.approx(m["impacts_per_s"], rel=0.5)  # two-point impacts
    assert m["wear_volume_cm3"] == pytest.approx(
        m["friction_work_erg"] / 0.3 * 1e-4 / 1e10, rel=1e-12)             # k F s / H, mu_k 0.3


def test_one_sliding_contact_does_the_coulomb_oscillators_friction_work():
    """The loose body flat on the lower plate (points 1 and 3), released 1 cm from the linear
    cork's rest: a Coulomb-damped oscillator (Rao, Mechanical Vibrations, 6th ed., §2.9): it
    slides half a period to -(s0 - 2F/k) and sticks, F = mu_k m g.  The friction work is F times
    the distance, 2 F (s0 - F/k), done at points 1 and 3 (with the rotation held, how the weight
    is split between them is not determined); points 2 and 4 do none."""
    p = Parameters().replace(cork="linear", cork_c=0.0, mu_s=0.3, mu_k=0.3,
                             s_travel=float("inf"))
    k = p.cork_law[1]
    m = p.m4 + p.mu_b * p.l_b + (p.m6 if p.tip_mass else 0.0)  # the loose body, beam B, tip mass
    held = tuple(sorted(set(ly.COORD_NAMES) - {"s", "v"}))
    friction = p.mu_k * m * p.g
    s0 = 1.0
    q0 = np.zeros(18)
    q0[ly.S], q0[ly.V] = s0, -p.gap / 2
    run = simulate(p, None, 0.3, dt=2e-5, output_hz=10000, initial=q0,
                   fixed=held)
    assert run.ok, run.message
    w = wear_measures(run, 0.0, 0.3, 1.0)
    exact = 2 * friction * (s0 - friction / k)
    assert w["friction_work_erg"] == pytest.approx(exact, rel=1e-6)
    assert w["friction_work1_erg"] + w["friction_work3_erg"] == pytest.approx(exact, rel=1e-6)
    assert w["friction_work2_erg"] == w["friction_work4_erg"] == 0.0
    # the normal forces carry the body's weight while it slides
    assert w["normal_force_max1_dyn"] + w["normal_force_max3_dyn"] >= m * p.g * (1 - 1e-6)


@pytest.mark.parametrize("freq_hz, force_n", [(20.0, 100.0), (30.0, 45.0)])
def test_the_wear_measures_converge_as_the_tolerance_tightens(freq_hz, force_n):
    """Two steady points at 1.016 mm, measured over 1 s after 0.3 s: tightening the tolerance
    from 1e-5 to 1e-6 to 1e-7 moves each measure less each time, and by under 1e-4 of it in the
    last step.  (In the richest regimes, e.g. 45 Hz and 60 N at 0.508 mm with 20 impacts a
    cycle, the measures agree across the tolerances to about 1.5 %: there the motion itself
    is sensitive to its history.)"""
    got = {}
    for tol in (1e-5, 1e-6, 1e-7):
        run = simulate(Parameters(), drives.sine(force_n, freq_hz, ramp_s=0.3), 1.3, tol=tol)
        assert run.ok, run.message
        got[tol] = wear_measures(run, 0.3, 1.3, freq_hz)
    for key in ("friction_work_erg", "impact_energy_erg", "wear_volume_cm3"):
        a, b, c = (got[t][key] for t in (1e-5, 1e-6, 1e-7))
        assert c > 0, key
        assert abs(b - c) <= abs(a - c) + 1e-12 * c and abs(b - c) < 1e-4 * c, (key, a, b, c)
    assert got[1e-6]["impacts"] == got[1e-7]["impacts"]


def test_the_wear_constants_are_checked():
    assert wear_constants(None) == WearConstants()
    assert wear_constants({"k_archard": 1e-3}).k_archard == 1e-3
    with pytest.raises(ParameterError, match=r"wear.k_archard = 0.5: allowed \[1e-08, 0.01\] -"):
        wear_constants({"k_archard": 0.5})
    with pytest.raises(ParameterError, match=r"\[wear\] hardness: unknown; allowed: k_archard"):
        wear_constants({"hardness": 1e9})




@pytest.fixture(scope="module")
def damage_map(tmp_path_factory):
    root = tmp_path_factory.mktemp("damage")
    (root / "damage.toml").write_text(DAMAGE)
    study = S.load(root / "damage.toml")
    table = W.run_study(study, root / "res", jobs=2, progress=False)
    make_report(study, root / "res")
    return study, root, table


def test_the_damage_report_maps_the_wear_and_marks_the_regime_to_avoid(damage_map):
    study, root, table = damage_map
    out = root / "res" / "damage"
    assert (table.status == "ok").all()
    for name in ("wear_map", "impact_map", "friction_map"):
        assert (out / "figures" / f"{name}.png").exists()
    ext = pd.read_csv(out / "tables" / "damage_extremes.csv")
    assert len(ext) == 4                                   # 2 gaps x 2 levels
    for _, row in ext.iterrows():
        panel = table[(table.axis_gap_mm == float(row.panel.split()[1]))
                      & (table.axis_force_n == row["force [N]"])]
        assert row["safest [Hz]"] == panel.loc[panel.wear_volume_cm3.idxmin()].axis_freq_hz
        assert row["worst [Hz]"] == panel.loc[panel.wear_volume_cm3.idxmax()].axis_freq_hz
    above = (table.wear_volume_cm3 * 1e3 >= 1e-7).sum()
    report = (out / "report.md").read_text()
    assert f"{above} of {len(table)} finished points lie in the regime to avoid" in report
    assert 0 < above < len(table)                 # the threshold splits this map
    assert "\\begin{table}" in (out / "tables" / "damage_extremes.tex").read_text()


def test_the_map_is_rebuilt_from_the_saved_points(damage_map, tmp_path):
    """The points table and the report come back from the per-point files alone: the sweep
    finds every point done and runs none."""
    import shutil
    study, root, table = damage_map
    copy = tmp_path / "res"
    shutil.copytree(root / "res", copy)
    for gone in ("points.parquet", "tables", "figures", "report.md"):
        path = copy / "damage" / gone
        shutil.rmtree(path) if path.is_dir() else path.unlink()
    again = W.run_study(study, copy, jobs=1, progress=False)
    assert (again.wall_s.to_numpy() == table.wall_s.to_numpy()).all()      # none re-run
    make_report(study, copy)
    pd.testing.assert_frame_equal(pd.read_csv(copy / "damage" / "tables" / "damage_extremes.csv"),
                                  pd.read_csv(root / "res" / "damage" / "tables" /
                                              "damage_extremes.csv"))


def test_the_advice_at_a_grid_point_and_between(damage_map):
    study, root, table = damage_map
    folder = root / "res" / "damage"
    hot = table.loc[table.wear_volume_cm3.idxmax()]
    a = advise(folder, hot.axis_gap_mm, hot.axis_freq_hz, hot.axis_force_n, change_level=True)
    assert not a.interpolated and a.avoid
    assert a.here["wear_volume_mm3"] == pytest.approx(hot.wear_volume_cm3 * 1e3)
    if a.frequency_change:                     # the nearest frequency out of the regime
        c = a.frequency_change
        assert c["wear_volume_mm3"] < 1e-7 and c["change_hz"] != 0
        nearer = np.arange(15.0, 45.01, 0.5)
        nearer = nearer[np.abs(nearer - hot.axis_freq_hz) < abs(c["change_hz"])]
        for f in nearer:
            assert advise(folder, hot.axis_gap_mm, f, hot.axis_force_n).avoid
    assert a.level_change is None or a.level_change["force_n"] < hot.axis_force_n
    between = advise(folder, 0.762, 22.5, 50.0)
    assert between.interpolated and between.distance == {"gap_mm": pytest.approx(0.254),
                                                         "freq_hz": 7.5, "force_n": 30.0}
    assert "interpolated" in between.notes[0]
    corners = table[table.axis_force_n.isin([20.0, 100.0]) & table.axis_freq_hz.isin([15.0, 30.0])]
    lo, hi = corners.wear_volume_cm3.min() * 1e3, corners.wear_volume_cm3.max() * 1e3
    assert lo - 1e-15 <= between.here["wear_volume_mm3"] <= hi + 1e-15


def test_the_advise_command_refuses_a_point_outside_the_map(damage_map, capsys):
    study, root, table = damage_map
    folder = str(root / "res" / "damage")
    assert cli.main(["advise", "--results", folder, "--gap-mm", "0.508", "--freq-hz", "60",
                     "--force-n", "50"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "workbench: error: --freq-hz 60: outside the map's range; allowed [15, 45] Hz"
    assert cli.main(["advise", "--results", folder, "--gap-mm", "0.508", "--freq-hz", "30",
                     "--force-n", "100", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) >= {"here", "avoid", "interpolated", "distance", "frequency_change",
                        "threshold_mm3"} and not out["interpolated"]
    assert cli.main(["advise", "--results", folder, "--gap-mm", "0.508", "--freq-hz", "30",
                     "--force-n", "100"]) == 0
    text = capsys.readouterr().out
    assert text.startswith("here (0.508 mm, 30 Hz, 100 N): wear_volume_mm3 ")
    assert cli.main(["advise", "--results", str(root), "--gap-mm", "0.5", "--freq-hz", "30",
                     "--force-n", "100"]) == 2
    assert "no points.parquet" in capsys.readouterr().err
    assert math.isfinite(out["here"]["wear_volume_mm3"])
