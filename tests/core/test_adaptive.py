"""The controlled methods (workbench.core.adaptive, workbench.core.pair): Dormand-Prince 8(5,3)
(the default) and 5(4) steps chosen by their embedded estimates, events on their dense output,
against fixed RK4 and closed forms."""
import math

import numpy as np
import pytest

from workbench.core import layout as ly
from workbench.core.constrained import rhs_regime
from workbench.core.pair import dense, pair_step
from workbench.model import drives
from workbench.model import packing as mdl
from workbench.model.limits import DEFAULT_TOL
from workbench.model.params import ParameterError, Parameters
from workbench.model.step_policy import default_dt
from workbench.model.simulate import simulate
from workbench.model.tableaus import DOP853, DOPRI5, write_tableau

ALL = set(ly.COORD_NAMES)
JOINT_HELD = ("s", "v", "psi")


def held_except(*names):
    return tuple(sorted(ALL - set(names)))


@pytest.fixture(scope="module")
def rocking():
    """The default case's first 0.1 s, driven hard from the paper's start: impacts, stick-slip."""
    return Parameters().replace(gap_mm=1.016), drives.sine(200.0, 20.0, ramp_s=0.02)


def test_the_same_input_gives_bit_identical_output(rocking):
    p, ex = rocking
    a, b = (simulate(p, ex, 0.1, initial="paper") for _ in range(2))
    assert a.method == "dop853" and a.tol == DEFAULT_TOL
    assert len(a.events) > 20
    assert np.array_equal(a.states, b.states) and np.array_equal(a.log, b.log)
    assert a.control == b.control


def _tip(method, dt, **kw):
    run = simulate(Parameters(), drives.sine(100.0, 20.0), 0.02, dt=dt, method=method,
                   fixed=JOINT_HELD, initial="paper", output_hz=1.0 / (4 * dt), **kw)
    assert run.ok, run.message
    return run.states[-1, :ly.N_DOF]


def test_the_pair_converges_at_its_order():
    """Steps held at dt (level_max 0), the joint held, a 20 Hz sine over 20 ms: the slope of
    log error against log step is the pair's order, 5 (the reference: the pair at a quarter
    of the smallest step; below 5e-5 s round-off, ~5e-13 cm, takes over)."""
    fine = _tip("dopri5", 1.25e-5, tol=1e-1, level_max=0)
    steps = np.array([1e-4, 5e-5])
    errors = [np.max(np.abs(_tip("dopri5", dt, tol=1e-1, level_max=0) - fine)) for dt in steps]
    slope = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert abs(slope - 5.0) < 0.5, (slope, errors)


def test_the_dense_output_has_the_interpolants_order():
    """One step of h from a state of the driven beam (joint held): the dense output at the
    step's middle against the state there from 256 steps of h / 512.  Shampine's interpolant
    is of order 4, so its local error is O(h^5): halving h divides it by about 32."""
    p = Parameters()
    ex = drives.sine(100.0, 20.0)
    model = mdl.build(p, fixed=JOINT_HELD)
    write_tableau(model.P, DOPRI5)
    work = mdl.make_work()
    y0 = np.zeros(ly.N_AUG)
    y0[:ly.N_STATE] = simulate(p, ex, 0.01, fixed=JOINT_HELD, initial="paper").states[-1]
    st = np.zeros(ly.N_ST)

    def step(t, y, h, out):
        assert rhs_regime(t, y, model, ex, work, work.stages[ly.STAGE_K1]) == ly.OK
        work.ev[:] = 1.0
        assert pair_step(t, y, h, model, ex, work, st, out) == ly.OK

    errors = []
    hs = np.array([4e-4, 2e-4, 1e-4])
    for h in hs:
        exact = y0.copy()
        nxt = np.empty(ly.N_AUG)
        for k in range(256):
            step(0.01 + k * h / 512, exact, h / 512, nxt)
            exact = nxt.copy()
        end = np.empty(ly.N_AUG)
        step(0.01, y0, h, end)
        mid = np.empty(ly.N_AUG)
        dense(0.5, h, y0, model.P, work.stages, mid)
        errors.append(np.max(np.abs(mid[:ly.N_DOF] - exact[:ly.N_DOF])))
    slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert abs(slope - 5.0) < 0.4, (slope, errors)
    half = np.empty(ly.N_AUG)
    dense(1.0, hs[-1], y0, model.P, work.stages, half)    # theta = 1 is the step's end
    np.testing.assert_allclose(half[:ly.N_DOF], end[:ly.N_DOF], rtol=0, atol=1e-12)


def test_frictionless_slide_on_a_stiff_cork_stays_within_the_tolerance_closed_form():
    """The body on the lower plate, frictionless, on the static cork's spring alone (only s
    and v move): s'' = -omega^2 s, omega = sqrt(k / m), 300 1/s.  From every sample the
    exact motion over the next output interval (1 ms) gives the local error of the run; the
    controller keeps it below tol times the motion's scale, with steps of at most 1 ms."""
    p = Parameters().replace(cork="static", cork_c=0.0, mu_s=0.0, mu_k=0.0,
                             s_travel=float("inf"))
    k = p.cork_law[1]
    m = p.m4 + p.mu_b * p.l_b + (p.m6 if p.tip_mass else 0.0)
    omega = math.sqrt(k / m)
    s0 = 0.5
    q0 = np.zeros(18)
    q0[ly.S], q0[ly.V] = s0, -p.gap / 2
    local, steps = {}, {}
    for tol in (1e-4, 1e-8):
        run = simulate(p, None, 0.1, dt=1e-3, tol=tol, output_hz=1000, initial=q0,
                       fixed=held_except("s", "v"), regime=9)
        assert run.ok and run.method == "dop853", run.message
        assert set(run.events.kind) <= {"start", "slip-stick"}   # reversals; it never leaves
        sig = run.signals
        s, sd = sig.s.to_numpy(), sig.s_dot.to_numpy()
        h = np.diff(sig.index.to_numpy())
        exact = s[:-1] * np.cos(omega * h) + sd[:-1] / omega * np.sin(omega * h)
        local[tol] = np.abs(s[1:] - exact).max() / s0
        steps[tol] = run.control["steps"]
        assert local[tol] < tol, (tol, local[tol])
        assert np.abs(s - s0 * np.cos(omega * sig.index.to_numpy())).max() < 100 * tol * s0
        assert run.control["error_over_tol_max"] <= 1.0 and run.control["floor_count"] == 0
    assert local[1e-8] < local[1e-4] / 5 and steps[1e-8] > steps[1e-4], (local, steps)


def test_tightening_the_tolerance_converges_to_the_fixed_step_limit(rocking):
    """Errors against RK4 at a 1/64 step (no rule of the model depends on the step) fall with
    the tolerance, and the companion run (check_accuracy) measures them within a factor 10."""
    p, ex = rocking
    dt = default_dt(p, ex)
    ref = simulate(p, ex, 0.1, dt=dt / 64, initial="paper")
    scale = np.ptp(ref.signals.tip_y)
    ref_shares = ref.contact_time_share()
    err = {}
    for tol in (1e-3, 1e-5, 1e-7):
        run = simulate(p, ex, 0.1, tol=tol, initial="paper", check_accuracy=tol > 1e-7)
        assert run.ok, run.message
        tip = np.abs(run.signals.tip_y.to_numpy() - ref.signals.tip_y.to_numpy()).max() / scale
        shares = run.contact_time_share()
        share = max(abs(shares.get(c, 0.0) - ref_shares.get(c, 0.0))
                    for c in set(shares) | set(ref_shares))
        err[tol] = max(tip, share)
        c = run.control
        if tol > 1e-7:
            assert 0.1 < c["error_measured"] / err[tol] < 10.0, (tol, c, err[tol])
        assert c["global_error_est"] == max(c["q_error_rss"], c["share_error_rss"])
        assert 0 < c["h_min"] <= c["h_max"] <= 2 * dt      # DOP853: up to 2 base steps
    assert err[1e-7] < err[1e-5] < err[1e-3] and err[1e-7] < err[1e-5] / 10, err
    assert err[1e-7] < 1e-6, err


def test_a_gap_dipping_below_zero_inside_one_step_is_an_impact():
    """The body (only v moves) thrown up to graze the upper plate: its gap dips below zero
    for 9e-5 s inside one step of 2e-4 s (steps held there, level_max 0), positive at both
    ends, 1e-6 cm deep (a dip counts when deeper than the gap's error, tol times the
    clearance: 5e-8 cm here).  The impact is found, at the closed-form time (gravity
    alone), to 1e-9 s."""
    p = Parameters()
    q0 = np.zeros(18)
    geometry = simulate(p, None, 1e-4, dt=1e-4, initial=q0, fixed=held_except("v"))
    gap0 = geometry.signals.gap2.iloc[0]            # the upper gap at v = 0 (cm)
    depth = 1e-6                                    # the apex passes the plate by this (cm)
    delta = 1e-6                                    # the gap at the start (cm)
    u = math.sqrt(2.0 * p.g * (delta + depth))      # upward speed that reaches the apex
    q0[ly.V] = gap0 - delta
    q0[ly.N_DOF + ly.V] = u
    run = simulate(p, None, 4e-4, dt=2e-4, tol=1e-6, level_max=0, output_hz=5000,
                   initial=q0, fixed=held_except("v"))
    assert run.ok, run.message
    impacts = run.events[run.events.kind == "impact"]
    assert len(impacts) >= 1 and impacts.point.iloc[0] in (2, 4)
    t_hit = (u - math.sqrt(u * u - 2.0 * p.g * delta)) / p.g
    assert abs(impacts.t.iloc[0] - t_hit) < 1e-9, (impacts.t.iloc[0], t_hit)


def test_falling_across_the_gap_closed_form():
    p = Parameters()
    run = simulate(p, None, 0.05, initial=np.zeros(18), fixed=held_except("v"))
    assert run.ok and run.method == "dop853", run.message
    impacts = run.events[run.events.kind == "impact"]
    assert len(impacts) == 1
    assert abs(impacts.t.iloc[0] - math.sqrt(p.gap / p.g)) < 1e-9   # gap/2 = g t^2 / 2
    end = run.signals.iloc[-1]
    assert end.v == pytest.approx(-p.gap / 2, abs=1e-12) and abs(end.v_dot) < 1e-9


def test_a_tolerance_out_of_range_names_the_option():
    p = Parameters()
    with pytest.raises(ParameterError, match=r"tol = 0\.5 is outside the allowed range"):
        simulate(p, None, 0.01, tol=0.5)
    with pytest.raises(ParameterError, match="tol = 0.001 is for the controlled method"):
        simulate(p, None, 0.01, method="rk4", tol=1e-3)
    with pytest.raises(ParameterError, match="method = 'euler' is not a method"):
        simulate(p, None, 0.01, method="euler")


def test_cli_run_reports_the_integrators_account(capsys):
    import json

    from workbench.cli import main
    rc = main(["run", "--gap-mm", "1.016", "--freq-hz", "20", "--force-n", "20", "--duration",
               "0.05", "--tol", "1e-5", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["method"] == "dop853" and out["tol"] == 1e-5
    for key in ("steps", "rejected", "h_min", "h_max", "error_est_max", "floor_count",
                "floor_intervals"):
        assert key in out
    assert out["error_est_max"] <= 1e-5 or out["floor_count"] > 0
    assert main(["run", "--duration", "0.05", "--tol", "2", "--json"]) == 2
    assert "--tol = 2 is outside the allowed range" in capsys.readouterr().err
    assert main(["run", "--duration", "0.05", "--dt", "5e-5", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["method"] == "rk4"


def test_steps_at_the_floor_are_reported(rocking):
    """A tolerance the smallest step cannot meet (Dormand-Prince 5(4) at 1e-9 with steps of
    at least a quarter of the base step): the run goes on, and each step accepted at the
    floor is listed with its time and regimes."""
    p, ex = rocking
    run = simulate(p, ex, 0.05, tol=1e-9, level_max=2, initial="paper", method="dopri5")
    assert run.ok, run.message
    c = run.control
    assert c["floor_count"] > 0 and len(c["floor_intervals"]) == c["floor_count"]
    floor = default_dt(p, ex) / 4
    assert c["h_min"] <= floor * (1 + 1e-9)
    for row in c["floor_intervals"]:
        assert 0.0 <= row["t0"] < row["t1"] <= 0.05 + 1e-12
        assert row["t1"] - row["t0"] <= floor * (1 + 1e-9)
        assert 0 <= row["from_regime"] <= 16 and 0 <= row["to_regime"] <= 16
        assert row["error_over_tol"] > 1.0
    assert run.summary()["floor_count"] == c["floor_count"]


def test_an_accumulating_case_converges_with_the_tolerance_as_with_the_step():
    """0.635 mm, tip mass, quadratic cork, 50 N at 45 Hz: impacts that accumulate (closed by
    full-set impacts, ACCUM_TIME_S in seconds).  Tightening the tolerance and refining the
    fixed step approach the same event counts (measured: 767 and 786 events at 3e-5 and
    2e-7, 786 and 779 at RK4 1/32 and 1/64 of the default step; 15, 20, 20, 19 accumulations)."""
    p = Parameters().replace(cork="quadratic", gap_mm=0.635, tip_mass=True)
    ex = drives.sine(50.0, 45.0, ramp_s=0.5)
    runs = {"tol": simulate(p, ex, 1.0), "tight": simulate(p, ex, 1.0, tol=2e-7),
            "fixed": simulate(p, ex, 1.0, dt=default_dt(p, ex) / 32)}
    n = {k: r.summary()["n_events"] for k, r in runs.items()}
    for r in runs.values():
        assert r.ok and r.summary()["accumulations"] > 0 and r.summary()["stepped_steps"] == 0
    assert abs(n["tight"] - n["fixed"]) <= abs(n["tol"] - n["fixed"]) + 2
    assert abs(n["tight"] - n["fixed"]) / n["fixed"] < 0.01, n


@pytest.mark.parametrize("d", [6e-8, -6e-8])
def test_a_short_step_to_an_event_agrees_with_a_step_of_the_pair_there(rocking, d):
    """A step of the pair moved on by a Heun step of d (the kernel's correction of at most
    SHORT_STEP_S towards an event) against a step of the pair from the same start to that
    time, in the regime the rocking run ends in (contact forces acting), on the kernel's error
    scales: they agree within a thousandth of the tolerance, though the state moved by a
    thousand times that."""
    from workbench.core.adaptive import _short_step
    from workbench.core.config import SHORT_STEP_S
    from workbench.core.contact import eval_geometry
    from workbench.core.error_scales import PARTNER
    assert abs(d) <= SHORT_STEP_S
    p, ex = rocking
    run = simulate(p, ex, 0.05, initial="paper")
    regime = int(run.log[-1, ly.LOG_TO])
    assert regime > 0, "the test needs a contact regime"
    model = mdl.build(p)
    write_tableau(model.P, DOP853)
    work = mdl.make_work()
    work.rg[ly.RG_SET] = (regime + 1) // 2
    work.rg[ly.RG_STICK] = 1.0 if regime % 2 == 1 else 0.0
    st = np.zeros(ly.N_ST)
    y0 = np.zeros(ly.N_AUG)
    y0[:ly.N_STATE] = run.states[-1]
    eval_geometry(y0[:ly.N_DOF], model.P, work.cg)      # slipping: along the slip rate
    row = work.cg[ly.CG_T + ly.SET_FIRST[(regime + 1) // 2]]
    qd = y0[ly.N_DOF:ly.N_STATE]
    rate = row[ly.CG_DS] * qd[ly.S] + row[ly.CG_DV] * qd[ly.V] + row[ly.CG_DPSI] * qd[ly.PSI]
    work.rg[ly.RG_SIGN] = 1.0 if rate >= 0.0 else -1.0
    t, h = run.t[-1], 1e-4
    last = int(model.P[ly.P_RK_STAGES]) - 1
    stages = work.stages

    def pair_to(step, out):
        assert rhs_regime(t, y0, model, ex, work, stages[ly.STAGE_K1]) == ly.OK
        work.ev[:] = 1.0
        assert pair_step(t, y0, step, model, ex, work, st, out) == ly.OK

    pair_to(h, stages[ly.STAGE_BASE])
    stages[ly.STAGE_KBASE] = stages[last]
    assert _short_step(t + h, d, model, ex, work, st) == ly.OK
    short = stages[ly.STAGE_HI, :ly.N_STATE].copy()
    direct = np.empty(ly.N_AUG)
    pair_to(h + d, direct)
    peak = np.abs(run.states).max(axis=0)       # the kernel's error scales (error_scales)
    scale = np.array([max(peak[i], peak[PARTNER[i % ly.N_DOF] + i // ly.N_DOF * ly.N_DOF])
                      for i in range(ly.N_STATE)])
    gap = np.max(np.abs(short - direct[:ly.N_STATE]) / scale)
    moved = np.max(np.abs(short - stages[ly.STAGE_BASE, :ly.N_STATE]) / scale)
    assert gap < 1e-3 * DEFAULT_TOL and moved > 1e3 * gap, (gap, moved)   # 7.5e-9, 4.6e-5


def _free_flight_step(p, ex, run, i, h):
    """A step of the pair of h (s) from the rocking run's sample i (in free flight), as the
    kernel leaves it before locating an event: its start's first stage and events, its end
    and events, its dense output's stages.  Returns (model, work, st, the start's state)."""
    from workbench.core.event_functions import event_values
    from workbench.core.pair import prepare_dense
    model = mdl.build(p)
    write_tableau(model.P, DOP853)
    work = mdl.make_work()
    work.rg[:] = 0.0                                    # free flight
    stages, ev = work.stages, work.ev
    st = np.zeros(ly.N_ST)
    t = run.t[i]
    stages[ly.STAGE_CUR] = 0.0
    stages[ly.STAGE_CUR, :ly.N_STATE] = run.states[i]
    assert rhs_regime(t, stages[ly.STAGE_CUR], model, ex, work, stages[ly.STAGE_K1]) == ly.OK
    event_values(stages[ly.STAGE_CUR], model.P, model.free, work.cg, work.rg, ev,
                 ly.EV_START, ly.EV_RATE_START)
    assert pair_step(t, stages[ly.STAGE_CUR], h, model, ex, work, st,
                     stages[ly.STAGE_NEXT]) == ly.OK
    event_values(stages[ly.STAGE_NEXT], model.P, model.free, work.cg, work.rg, ev,
                 ly.EV_END, ly.EV_RATE_END)
    assert prepare_dense(t, stages[ly.STAGE_CUR], h, model, ex, work) == ly.OK
    return model, work, st, stages[ly.STAGE_CUR].copy()


def test_an_event_the_pairs_steps_do_not_reach_is_not_applied(rocking):
    """A step whose dense output located an event (here a gap, given as located at mid-step)
    that the pair's own states do not cross by the step's end: the search for the event's
    state returns theta = -1, and the step is not cut there (``_to_event`` returns NOT_REACHED
    with the state, the time and the log unchanged; the main loop tries the step shorter, and
    at the smallest step takes it whole). Taking the step's end as the event's state would
    apply an impact at an open gap."""
    from workbench.core.adaptive import NOT_REACHED, _step_past, _take_whole, _to_event
    from workbench.core.hybrid import _trial
    p, ex = rocking
    run = simulate(p, ex, 0.05, initial="paper")
    regime = run.sensors[:, ly.SIGNALS.index("regime")]
    free = np.flatnonzero(regime == 0)
    assert free.size, "the test needs a sample in free flight"
    i = free[free.size // 2]
    t, h = run.t[i], 1e-4
    model, work, st, y = _free_flight_step(p, ex, run, i, h)
    stages, ev = work.stages, work.ev
    gaps = ev[ly.EV_END, ly.EV_GAP:ly.EV_GAP + ly.N_POINTS]
    e = ly.EV_GAP + int(np.argmax(gaps))
    assert ev[ly.EV_START, e] > 0.0 and ev[ly.EV_END, e] > 0.0
    assert _trial(0.5, t, h, np.bool_(True), model, ex, work) == ly.OK
    ev[ly.EV_HI, e] = ev[ly.EV_TRY, e]                  # "located" at theta = 0.5
    status, theta = _step_past(e, 0.5, t, h, model, ex, work, st)
    assert status == ly.OK and theta == -1.0, (status, theta)
    log = np.zeros((8, ly.N_LOG))
    assert _trial(0.5, t, h, np.bool_(True), model, ex, work) == ly.OK
    ev[ly.EV_HI, e] = ev[ly.EV_TRY, e]
    status, t_after, n_log = _to_event(e, 0.5, t, h, t + 1.0, y, model, ex, work, log, 0, st)
    assert (status, t_after, n_log) == (NOT_REACHED, t, 0)
    np.testing.assert_array_equal(stages[ly.STAGE_CUR], y)
    assert not log.any() and st[ly.ST_N_EVENTS] == 0.0
    # at the smallest step the step is taken whole, with no event: its end is the new start
    end, end_events = stages[ly.STAGE_NEXT].copy(), ev[ly.EV_END].copy()
    assert _take_whole(t + h, model, ex, work) == ly.OK
    np.testing.assert_array_equal(stages[ly.STAGE_CUR], end)
    np.testing.assert_array_equal(ev[ly.EV_START], end_events)
    k_end = np.empty(ly.N_AUG)
    assert rhs_regime(t + h, end, model, ex, work, k_end) == ly.OK
    np.testing.assert_array_equal(stages[ly.STAGE_K1], k_end)


@pytest.mark.parametrize("past, bracket", [(0.1, True), (-0.2, False)])
def test_a_search_out_of_iterations_keeps_the_state_past_the_event_or_none(rocking, past,
                                                                            bracket, monkeypatch):
    """The search for an event's state (``_step_past``) misled by the slope it is given: the
    gap of the rocking run's first impact from free flight, in a step of the pair whose dense
    output crosses it at mid-step.  Started 0.1 of the step past the crossing with 1/1.99 of
    the dense output's slope, its Newton steps overshoot by 0.99 of the distance, alternating
    sides; started 0.2 before it with 50 times the slope, they creep towards it.  Both run out
    of PAST_ITERS tries, the last before the event.  With a bracket the search returns its far
    end, past the event, and the state there (a step of the pair to that fraction); without
    one it returns -1, not reached.  The compiled kernel does what its Python source does, in
    which the tries are counted.  (Returning the last try's state, before the event, with
    another fraction fails both.)"""
    import workbench.core.adaptive as adaptive
    from workbench.core.hybrid import _trial
    p, ex = rocking
    run = simulate(p, ex, 0.05, initial="paper")
    regime = run.sensors[:, ly.SIGNALS.index("regime")]
    impacts = run.events[(run.events.kind == "impact") & (run.events.from_regime == 0)]
    t_impact, point = float(impacts.t.iloc[0]), int(impacts.point.iloc[0])
    i = int(np.searchsorted(run.t, t_impact)) - 1
    assert regime[i] == 0, "the test needs the sample before the impact in free flight"
    h = 2.0 * (t_impact - run.t[i])
    e = ly.EV_GAP + point - 1
    tries = []

    def search(kernel):
        model, work, st, _ = _free_flight_step(p, ex, run, i, h)
        t, ev, stages = run.t[i], work.ev, work.stages
        assert ev[ly.EV_START, e] > 0.0 > ev[ly.EV_END, e]

        def dense_value(x):
            assert _trial(x, t, h, np.bool_(True), model, ex, work) == ly.OK
            return ev[ly.EV_TRY, e]
        lo, hi = 0.0, 1.0                               # the dense output's crossing
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if dense_value(mid) >= 0.0 else (lo, mid)
        theta, ratio = hi + past, 1.99 if bracket else 0.02
        f_slope = dense_value(theta - adaptive.SLOPE_FRACTION)
        f_theta = dense_value(theta)                    # its state in STAGE_TRY
        stages[ly.STAGE_HI] = stages[ly.STAGE_TRY]
        ev[ly.EV_HI] = ev[ly.EV_TRY]
        ev[ly.EV_HI, e] = f_slope - (f_slope - f_theta) / ratio    # the slope misread
        status, found = kernel(e, theta, t, h, model, ex, work, st)
        assert status == ly.OK
        return found, stages[ly.STAGE_HI].copy(), ev[ly.EV_HI, e], (model, work, st, t)

    found, state, value, _ = search(adaptive._step_past)
    pair_state_at = adaptive._pair_state_at

    def counted(x, *args):
        tries.append(x)
        return pair_state_at(x, *args)
    monkeypatch.setattr(adaptive, "_pair_state_at", counted)
    found_py, state_py, value_py, (model, work, st, t) = search(adaptive._step_past.py_func)
    assert found_py == found and value_py == value
    np.testing.assert_array_equal(state_py, state)
    if not bracket:
        assert found == -1.0 and len(tries) == adaptive.PAST_ITERS, (found, len(tries))
        return
    assert len(tries) == adaptive.PAST_ITERS + 1 and tries[-1] == found   # the far end, again
    assert 0.0 < found < 1.0 and value < 0.0
    direct = np.empty(ly.N_AUG)
    assert rhs_regime(t, work.stages[ly.STAGE_CUR], model, ex, work,
                      work.stages[ly.STAGE_K1]) == ly.OK
    assert pair_step(t, work.stages[ly.STAGE_CUR], found * h, model, ex, work, st,
                     direct) == ly.OK
    np.testing.assert_array_equal(direct, state)
