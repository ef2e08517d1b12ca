"""Continuation of periodic orbits (model/continuation.py, `workbench continue`)."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from workbench import cli
from workbench.model import drives
from workbench.model.continuation import (Bifurcation, Branch, _bifurcation, _tangent,
                                          _turning, _went_back, branch_rows, continue_branch,
                                          continue_from, doublings)
from workbench.model.orbit import SETTLE, Orbit, Shooter, periodic_orbit
from workbench.model.params import Parameters
from workbench.present.branch import write_branch


@pytest.fixture(scope="module")
def stuck_branch(tmp_path_factory):
    """0.5 N over 18-22 Hz: the joint stays stuck, a smooth branch of stable orbits."""
    out = tmp_path_factory.mktemp("branch")
    p = Parameters()
    shooter = Shooter(p, drives.sine(0.5, 18.0), parameter="freq_hz")
    branch = continue_branch(shooter, 18.0, 22.0, on_orbit=lambda b: write_branch(b, out, p))
    return branch, out


def test_a_stuck_branch_is_traced_to_its_end_and_written(stuck_branch):
    branch, out = stuck_branch
    assert branch.status == "done" and len(branch.orbits) >= 8, branch.message
    values = [v for v, _ in branch.orbits]
    assert values[0] == 18.0 and values[-1] > 22.0 and np.all(np.diff(values) > 0)
    assert all(o.status == "ok" and o.stable for _, o in branch.orbits)
    table = pd.read_parquet(out / "branch.parquet")
    assert len(table) == len(branch.orbits)
    for column in ("freq_hz", "tip_amplitude_cm", "accel1_amplitude", "strain1_rms",
                   "max_multiplier", "stable", "bifurcation", "impact_per_period"):
        assert column in table, column
    # the slowest multiplier's settling time: log(SETTLE) / log|mu| periods of 1 / f
    assert np.allclose(table.settle_s, np.log(SETTLE) / np.log(table.max_multiplier)
                       / table.freq_hz, rtol=1e-12)
    assert (out / "branch.png").exists() and "Status: done" in (out / "report.md").read_text()


def test_each_orbit_of_the_branch_is_the_orbit_found_alone(stuck_branch):
    """An orbit in the middle of the branch, found again by shooting at its frequency alone:
    the same tip amplitude and multipliers."""
    branch, _ = stuck_branch
    value, orbit = branch.orbits[len(branch.orbits) // 2]
    alone = periodic_orbit(Parameters(), drives.sine(0.5, value))
    assert alone.status == "ok"
    assert alone.tip_amplitude_cm == pytest.approx(orbit.tip_amplitude_cm, rel=1e-5)
    # a linear response is a sine: its line at the drive frequency is half its range (the
    # samples' peak misses the true one by 1 - cos(pi / 400) = 3e-5)
    assert orbit.responses["tip_h1_cm"] == pytest.approx(orbit.tip_amplitude_cm, rel=1e-4)
    assert np.allclose(np.abs(alone.deciding()), np.abs(orbit.deciding()), atol=1e-5)


def _orbit(multipliers, grazing=False, error=1e-6, events=None) -> Orbit:
    mu = np.asarray(multipliers, complex)
    return Orbit("ok", "", 0.05, 1, np.zeros(18), 13, 0.0, 1, mu, bool(np.abs(mu).max() < 1),
                 grazing, 1.0, events or {"impact": 4, "stick-slip": 12}, {}, 0.0, 0.0,
                 len(mu), multiplier_error=error)


def _kind(before, after) -> str:
    found = _bifurcation(before, after, 1)
    return found.kind if found else ""


@pytest.mark.parametrize("before, after, kind", [
    ([0.9, 0.5], [1.1, 0.5], "fold"),
    ([-0.9, 0.5], [-1.1, 0.5], "period doubling"),
    ([0.6 + 0.7j, 0.6 - 0.7j], [0.7 + 0.8j, 0.7 - 0.8j], "neimark-sacker"),
    ([-1.1, 0.5], [-0.9, 0.5], "period doubling"),
    ([0.9, 0.5], [0.95, 0.5], ""),
    # another multiplier already outside: the one that crossed is the one nearest the circle
    ([2.5, -0.9, 0.5], [2.9, -1.1, 0.5], "period doubling"),
    ([-2.5, 0.6 + 0.7j, 0.6 - 0.7j], [-2.4, 0.7 + 0.8j, 0.7 - 0.8j], "neimark-sacker"),
])
def test_a_multiplier_leaving_the_unit_circle_names_the_bifurcation(before, after, kind):
    assert _kind(_orbit(before), _orbit(after)) == kind
    assert _kind(_orbit([0.5]), _orbit([0.5], grazing=True)) == "grazing"


def test_a_change_of_stability_where_the_events_change_is_nonsmooth():
    """The same multipliers, but an impact more a period on the far side: the multipliers
    jump with the events, so the change is named nonsmooth, with where its multiplier left
    the circle (-1), its angle and the events that changed."""
    after = _orbit([-1.3, 0.5], events={"impact": 5, "stick-slip": 12})
    found = _bifurcation(_orbit([-0.9, 0.5]), after, 7)
    assert (found.index, found.kind, found.crossing) == (7, "nonsmooth", "-1")
    assert found.angle == pytest.approx(np.pi) and found.events_changed == "impact 4->5"
    assert found.entry(85.0) == {"at": 85.0, "kind": "nonsmooth", "crossing": "-1",
                                 "events_changed": "impact 4->5", "turns": False}
    # where the parameter also turns there: still named by its crossing at -1, marked as
    # turning; a turn without a change of stability, or with one at +1, is a fold
    turning = _turning(found, 7)
    assert (turning.kind, turning.crossing, turning.turns) == ("nonsmooth", "-1", True)
    assert _turning(None, 7) == Bifurcation(7, "fold", turns=True)
    at_one = _bifurcation(_orbit([0.9, 0.5]), _orbit([1.1, 0.5]), 7)
    assert _turning(at_one, 7).kind == "fold" and _turning(at_one, 7).crossing == "+1"
    smooth = _bifurcation(_orbit([0.6 + 0.7j, 0.6 - 0.7j]), _orbit([0.7 + 0.8j, 0.7 - 0.8j]), 3)
    assert smooth.crossing == "complex" and smooth.angle == pytest.approx(np.angle(0.7 + 0.8j))
    assert smooth.events_changed == ""
    branch = Branch("freq_hz", bifurcations=[found, smooth])
    assert doublings(branch) == [7]


def test_a_doubled_branch_ends_where_it_merges_into_the_orbit_of_half_its_period():
    """The doubled branch at 86.54 N (the period doubling study): 3.4e-3 cm of tip line at
    10 Hz at 86.44 N, then 2.3e-9 cm at 86.67 N, where it is the period-1 orbit again
    (strain1's line at 10 Hz there, 5e-6 of its 20 Hz line, is round-off)."""
    from workbench.model.continuation import _merged
    doubled, merged = _orbit([0.5]), _orbit([0.5])
    doubled.responses = {"tip_h1_cm": 0.87, "tip_h0.5_cm": 3.4e-3, "strain1_h1": 1.7e-4,
                         "strain1_h0.5": 2.9e-9}
    merged.responses = {"tip_h1_cm": 0.87, "tip_h0.5_cm": 2.3e-9, "strain1_h1": 1.7e-4,
                        "strain1_h0.5": 8.2e-10}
    assert _merged(doubled) == "" and _merged(merged).startswith("merged")
    assert _merged(_orbit([0.5])) == ""                 # no lines: not taken as merged


def test_a_step_back_to_the_orbit_before_the_last_is_told_from_a_turning_point():
    """Orbits at 31.08, 31.41 and then 31.30 Hz: back near the first (a zig-zag, as measured
    at 1.016 mm where the regime at phase 0 changes) is a step back; on past a turning point
    (the parameter turns, the state moves on) it is not."""
    def at(value, x):
        orbit = _orbit([0.5])
        orbit.state = np.full(18, x)
        return value, orbit
    scale, span = np.ones(18), 45.0
    first, last = at(31.08, 0.0), at(31.41, 1.0)
    assert _went_back(at(31.10, 0.05), first, last, scale, span)
    assert not _went_back(at(31.30, 2.0), first, last, scale, span)


def test_a_multiplier_within_its_error_of_the_circle_names_nothing():
    """-0.999 and -1.001 with an error estimate of 0.01 either side: no bifurcation is
    claimed (the count outside the circle is not decided), nor without an estimate."""
    assert _kind(_orbit([-0.999, 0.5], error=0.01), _orbit([-1.001, 0.5])) == ""
    assert _kind(_orbit([-0.9, 0.5]), _orbit([-1.001, 0.5], error=0.01)) == ""
    assert _kind(_orbit([-0.9, 0.5]), _orbit([-1.1, 0.5], error=float("nan"))) == ""


def test_a_branch_is_traced_downwards_too():
    """22 to 21 Hz at 0.5 N: the same orbits as upwards (the frequencies decrease)."""
    shooter = Shooter(Parameters(), drives.sine(0.5, 22.0), parameter="freq_hz")
    branch = continue_branch(shooter, 22.0, 21.0)
    values = [v for v, _ in branch.orbits]
    assert branch.status == "done" and values[-1] < 21.0 and np.all(np.diff(values) < 0)


def test_an_interrupted_continuation_keeps_every_orbit_found(tmp_path):
    p = Parameters()
    shooter = Shooter(p, drives.sine(0.5, 20.0), parameter="freq_hz")
    seen = []

    def write_then_stop(branch):
        write_branch(branch, tmp_path, p)
        seen.append(len(branch.orbits))
        if len(branch.orbits) == 3:
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        continue_branch(shooter, 20.0, 24.0, on_orbit=write_then_stop)
    assert len(pd.read_parquet(tmp_path / "branch.parquet")) == 3
    assert branch_rows(Branch("freq_hz")) == []


def test_a_branch_resumed_from_its_rows_goes_on_the_way_it_was_going(stuck_branch):
    """continue_from the rows of the stuck branch: from its last orbit found again (the
    same state) onwards; and from two rows read backwards (a branch heading down when it
    was cut, though traced towards 22 Hz) downwards, until it folds back past its start."""
    branch, out = stuck_branch
    rows = pd.read_parquet(out / "branch.parquet")
    shooter = Shooter(Parameters(), drives.sine(0.5, 18.0), parameter="freq_hz")
    onwards = continue_from(shooter, rows.iloc[:3], 18.0, rows.freq_hz.iloc[4])
    values = [v for v, _ in onwards.orbits]
    assert values[0] == rows.freq_hz.iloc[2] and np.all(np.diff(values) > 0)
    assert onwards.status == "done"
    assert np.allclose(onwards.orbits[0][1].state, rows.state.iloc[2], rtol=1e-6, atol=1e-12)
    back = continue_from(shooter, rows.iloc[[2, 1]], 18.0, 22.0)
    values = [v for v, _ in back.orbits]
    assert values[0] == rows.freq_hz.iloc[1] and np.all(np.diff(values) < 0)
    assert back.status == "folded back" and values[-1] < 18.0


def test_a_branch_that_ends_at_the_step_floor_is_written_with_its_report(stuck_branch, tmp_path,
                                                                        monkeypatch):
    """A corrector that never converges (stood in) halves the step to its floor: the branch
    ends there with its status, and its table, figure and report are written."""
    from workbench.model import continuation
    branch, _ = stuck_branch
    p = Parameters()
    monkeypatch.setattr(continuation, "_correct", lambda *a, **k: None)
    monkeypatch.setattr(continuation, "_across_phase_zero", lambda *a, **k: None)
    shooter = Shooter(p, drives.sine(0.5, 18.0), parameter="freq_hz")
    ended = continue_branch(shooter, 18.0, 22.0, start=branch.orbits[0][1],
                            on_orbit=lambda b: write_branch(b, tmp_path, p))
    assert ended.status == "step floor" and len(ended.orbits) == 1
    assert "Status: step floor" in (tmp_path / "report.md").read_text()
    assert (tmp_path / "branch.png").exists()


def test_the_continue_command_refuses_what_it_cannot_trace(tmp_path, capsys):
    assert cli.main(["continue", "--freq-hz", "25:25", "--out", str(tmp_path)]) == 2
    assert "a range is FROM:TO, two different finite numbers" in capsys.readouterr().err
    assert cli.main(["continue", "--freq-hz", "20", "--force-n", "20000:10", "--out",
                     str(tmp_path)]) == 2
    assert "--force-n 20000:10: allowed (0, 10000] N" in capsys.readouterr().err
    assert cli.main(["continue", "--freq-hz", "20", "--force-n", "10", "--out",
                     str(tmp_path)]) == 2
    assert "give one of --freq-hz and --force-n as a range" in capsys.readouterr().err
    assert cli.main(["continue", "--freq-hz", "15:25", "--force-n", "1:100", "--out",
                     str(tmp_path)]) == 2
    capsys.readouterr()
    assert cli.main(["continue", "--freq-hz", "20:20.5", "--force-n", "0.5", "--out",
                     str(tmp_path / "b"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "done" and out["orbits"] >= 2 and out["parameter"] == "freq_hz"


class _Plane:
    """A stand-in manifold: reduced coordinates z move the state by B z (B: N x dim)."""

    def __init__(self, B):
        self.B, self.dim = B, B.shape[1]

    def move(self, x, z):
        return x + self.B @ z


def test_the_tangent_keeps_its_direction_where_the_reduced_coordinates_change():
    """The branch's tangent is oriented along the step from the orbit before (in the full
    state), whatever the reduced coordinates: a branch whose regime at phase 0 changes (and
    with it the coordinates' number and basis) goes on the way it came, not back towards the
    range's direction.  Here the null vector of [J - I, dR] is (z, lambda) = (1, -1) (the
    branch runs to lower lambda, past a fold): with a secant along it the tangent keeps
    lambda decreasing, with the secant reversed it turns, and without one it points up the
    range."""
    x, scale, d = np.zeros(3), np.ones(3), np.ones(2)
    J, dR = np.array([[2.0]]), np.array([1.0])        # (J - I) z + dR lambda = 0: z = -lambda
    for B in (np.array([[1.0], [0.0], [0.0]]), np.array([[0.0], [0.0], [-1.0]])):
        manifold = _Plane(B)
        ahead = np.concatenate([B[:, 0], [-1.0]])      # the full-state step, lambda down
        t = _tangent(J, dR, d, manifold, x, scale, ahead)
        assert t[1] < 0 and t[0] > 0
        t = _tangent(J, dR, d, manifold, x, scale, -ahead)
        assert t[1] > 0
        assert _tangent(J, dR, d, manifold, x, scale, None, direction=1.0)[1] > 0


def test_at_a_period_doubling_the_orbit_of_twice_the_period_is_found():
    """83.7 N at 20 Hz (1.016 mm, tip mass, cubic cork): the period-1 orbit has a multiplier
    near -1.20 (its stability lost by a period doubling above, `studies/period_doubling.toml`).  Shooting the two-period
    map from it moved along that multiplier's Floquet vector finds an orbit of two periods
    that one period does not bring back (not the period-1 orbit again): it has a line at
    10 Hz."""
    from workbench.model.continuation import SAME_ORBIT, _moved_by_period, doubled_start
    p = Parameters()
    shooter = Shooter(p, drives.sine(83.7, 20.0), parameter="force_n")
    one = periodic_orbit(p, drives.sine(83.7, 20.0))
    assert one.status == "ok" and one.stable is False, one.message
    crossed = one.deciding()[np.argmax(np.abs(one.deciding()))]
    assert crossed.real < -1.0 and abs(crossed.imag) < 1e-9
    shooter.phase = one.phase
    branch = Branch("force_n", orbits=[(83.7, one), (83.7, one)])
    found = doubled_start(shooter, branch, 1)
    assert found is not None
    value, two, side = found
    assert value == 83.7 and side == 1 and two.periods == 2 and two.residual <= 1e-7
    assert _moved_by_period(shooter, two, shooter.drive_at(83.7)) > 100 * SAME_ORBIT
    # its 10 Hz line: 7e-4 of the 20 Hz line this near the doubling (where it grows as the
    # square root of the distance); the period-1 orbit shot as two periods (at 200 N) has
    # 7e-6, the sums' noise
    assert two.responses["strain1_h0.5"] > 1e-4 * two.responses["strain1_h1"]
