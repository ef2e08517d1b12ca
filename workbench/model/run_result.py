"""The result of a run (:class:`Run`): samples, events, statistics and the integrator's
account, and how a run's chunks are assembled into one."""
from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..core import layout as ly
from . import antialias
from .params import Parameters
from .regimes import contact_code, contact_shares_of, in_contact
from .validity import validity

if TYPE_CHECKING:
    import pandas as pd

#: The smallest energy scale (erg) of :meth:`Run.energy_balance_rel`.
ENERGY_SCALE_FLOOR_ERG = 1.0

#: Run statistics of the contact logic reported by :meth:`Run.summary` (docs/model.md §7).
CONTACT_STAT_KEYS = ("accumulations", "accumulation_energy_lost_erg", "inconsistent_resolved",
                     "inconsistent_energy_lost_erg", "least_violated", "stepped_steps",
                     "stepped_energy_lost_erg", "s_min_cm", "s_max_cm")

#: Intervals accepted at the finest level listed in :meth:`Run.summary` (all are in ``control``).
SUMMARY_FLOOR_ROWS = 20

Q_COLUMNS = list(ly.COORD_NAMES)
QD_COLUMNS = [f"{n}_dot" for n in ly.COORD_NAMES]
ENERGY_COLUMNS = ["e_kin", "e_elastic", "e_gravity", "e_cork", "w_excitation", "d_structural",
                  "d_cork", "d_friction", "d_impact", "w_constraint"]


def energy_account(columns) -> tuple:
    """The total mechanical energy E and the balance residual (erg) of the energy columns.

    ``columns`` maps the names of ENERGY_COLUMNS to NumPy arrays:
    residual = E - E(0) - W_excitation + D_structural + D_cork + D_friction + D_impact.
    """
    c = columns
    total = c["e_kin"] + c["e_elastic"] + c["e_gravity"] + c["e_cork"]
    residual = (total - total[0] - c["w_excitation"] + c["d_structural"] + c["d_cork"]
                + c["d_friction"] + c["d_impact"])
    return total, residual


@dataclass
class Run:
    """The result of :func:`simulate`.

    The samples and the event log are kept as the kernel wrote them
    (``t``, ``states``, ``sensors``, ``log``); :attr:`signals` and
    :attr:`events` are DataFrames of them, built on first use (pandas is
    not imported until then, so a run whose summary is all that is wanted
    does not pay for it).
    """

    params: Parameters
    excitation: np.ndarray
    dt: float
    duration: float
    status: int
    message: str
    wall_s: float
    t: np.ndarray               # sample times (s), (n,)
    states: np.ndarray          # (q, q') at the samples, (n, 18), CGS
    sensors: np.ndarray         # the kernel's signals (layout SIGNALS), (n, N_SIG)
    log: np.ndarray             # the event log (layout LOG_*), (n_events, N_LOG)
    stats: dict
    static_tip_y: float
    initial: str
    units: dict = field(default_factory=dict)
    t0: float = 0.0
    compile_s: float = 0.0      # compiling or loading the kernel (not in wall_s)
    method: str = "rk4"
    tol: float | None = None    # the controlled method's relative tolerance
    control: dict = field(default_factory=dict)   # steps, rejections, error estimate (summary())
    anti_alias: dict = field(default_factory=dict)  # the analog channels' filter (antialias.summary)

    @property
    def ok(self) -> bool:
        return self.status == ly.OK

    @property
    def stopped(self) -> bool:
        """Ended early by the ``stop`` condition given to :func:`simulate`."""
        return self.status == ly.STOPPED

    @property
    def t_end(self) -> float:
        """The time reached (s): t0 + duration unless the run stopped early."""
        return float(self.stats["t_reached"])

    @property
    def simulated_s(self) -> float:
        """Simulated seconds: the time reached minus the start time t0."""
        return self.t_end - self.t0

    @functools.cached_property
    def signals(self) -> pd.DataFrame:
        """DataFrame indexed by time t (s): q, q', the signals of SIGNALS, contact flags."""
        import pandas as pd
        df = pd.DataFrame(self.states, columns=Q_COLUMNS + QD_COLUMNS)
        for j, name in enumerate(ly.SIGNALS):
            df[name] = self.sensors[:, j]
        df["regime"] = df["regime"].astype(np.int16)
        regimes = df["regime"].to_numpy()
        for k in range(ly.N_POINTS):
            df[f"contact{k + 1}"] = in_contact(k, regimes)
        df["contact_code"] = contact_code(regimes).astype(np.int16)
        df.index = pd.Index(self.t, name="t")
        return df

    @functools.cached_property
    def events(self) -> pd.DataFrame:
        """DataFrame of the event log: time, kind, from/to regime, point, impulses, kinetic
        energy lost (erg) and each point's part of it."""
        import pandas as pd
        logs = self.log
        return pd.DataFrame({
            "t": logs[:, ly.LOG_T],
            "kind": pd.Categorical([ly.EVENT_KINDS[int(k)] for k in logs[:, ly.LOG_KIND]],
                                   categories=ly.EVENT_KINDS),
            "from_regime": logs[:, ly.LOG_FROM].astype(np.int16),
            "to_regime": logs[:, ly.LOG_TO].astype(np.int16),
            "point": logs[:, ly.LOG_POINT].astype(np.int8),
            **{f"impulse_n{k + 1}": logs[:, ly.LOG_P + k] for k in range(ly.N_POINTS)},
            "impulse_t": logs[:, ly.LOG_PT],
            "ke_lost": logs[:, ly.LOG_DKE],
            **{f"ke_lost{k + 1}": logs[:, ly.LOG_DKE_P + k] for k in range(ly.N_POINTS)},
        })

    @property
    def transitions(self) -> pd.DataFrame:
        """Counts of (from_regime, to_regime) over the events, starting event excluded."""
        ev = self.events[self.events.kind != "start"]
        return (ev.groupby(["from_regime", "to_regime"]).size().rename("count").reset_index())

    @property
    def energy(self) -> pd.DataFrame:
        """The energy account (erg) with the total E and the balance residual (:func:`energy_account`)."""
        e = self.signals[ENERGY_COLUMNS].copy()
        e["total"], e["residual"] = energy_account(
            {name: e[name].to_numpy() for name in ENERGY_COLUMNS})
        return e

    def signal(self, name: str) -> np.ndarray:
        """The samples of one signal of SIGNALS (its unit there), without building ``signals``."""
        return self.sensors[:, ly.SIGNALS.index(name)]

    def energy_balance_rel(self) -> float:
        """Largest |residual| over the run's energy scale (docs/model.md §9).

        The scale is the throughput |W_excitation| + dissipations at the end,
        plus the largest kinetic energy and the largest change of the
        mechanical energy E from E(0) (so that a free decay, whose throughput
        starts at zero, reads sensibly from its first sample), floored at
        ENERGY_SCALE_FLOOR_ERG: a run that stays at rest divides its
        round-off residual by 1 erg, not by a near-zero throughput.
        """
        c = {name: self.signal(name) for name in ENERGY_COLUMNS}
        total, residual = energy_account(c)
        last = {name: float(x[-1]) for name, x in c.items()}
        scale = (abs(last["w_excitation"]) + last["d_structural"] + last["d_cork"]
                 + last["d_friction"] + last["d_impact"] + float(c["e_kin"].max())
                 + float(np.abs(total - total[0]).max()))
        return float(np.abs(residual).max() / max(scale, ENERGY_SCALE_FLOOR_ERG))

    def contact_time_share(self) -> dict[str, float]:
        """Fraction of the simulated time spent in each contact code (from the event log)."""
        return contact_shares_of(self.log[:, ly.LOG_T], self.log[:, ly.LOG_TO],
                                 float(self.log[0, ly.LOG_T]), self.t_end)

    def summary(self) -> dict:
        """Scalar results of the run (the ``workbench run --json`` object)."""
        kinds = self.log[:, ly.LOG_KIND]
        visited = (set(int(r) for r in self.log[:, ly.LOG_TO])
                   | set(int(r) for r in self.signal("regime")))
        tip = self.signal("tip_y") - self.static_tip_y
        return {
            "status": "ok" if self.ok else "failed",
            "status_code": self.status,
            "message": self.message,
            "simulated_s": self.simulated_s,
            "wall_s": self.wall_s,
            "compile_s": self.compile_s,
            "dt": self.dt,
            "method": self.method,
            "tol": self.tol,
            **{key: value for key, value in self.control.items() if key != "floor_intervals"},
            "floor_intervals": self.control.get("floor_intervals", [])[:SUMMARY_FLOOR_ROWS],
            "anti_alias": self.anti_alias,
            "initial": self.initial,
            "n_events": int((kinds != ly.KIND_START).sum()),
            "n_impacts": int((kinds == ly.KIND_IMPACT).sum()),
            "regimes_visited": sorted(visited),
            "contact_time_share": self.contact_time_share(),
            "max_penetration_cm": float(self.stats["max_penetration_cm"]),
            "max_drift_cm": float(self.stats["max_drift_cm"]),
            "max_correction_cm": float(self.stats["max_correction_cm"]),
            "t_max_penetration": float(self.stats["t_max_penetration"]),
            "energy_balance_rel": self.energy_balance_rel(),
            "impact_energy_lost_erg": float(self.stats["impact_energy_lost_erg"]),
            **{key: self.stats[key] for key in CONTACT_STAT_KEYS},
            "strain1_rms": float(np.std(self.signal("strain1"))),
            "strain2_rms": float(np.std(self.signal("strain2"))),
            "tip_disp_peak_cm": float(np.abs(tip).max()),
            **validity(self),
        }

    def to_parquet(self, path) -> None:
        """Signals to ``path``; events to the same name with ``.events.parquet``."""
        path = str(path)
        self.signals.to_parquet(path)
        stem = path[:-len(".parquet")] if path.endswith(".parquet") else path
        self.events.to_parquet(stem + ".events.parquet")


def control_summary(ctl: np.ndarray, floor_log: np.ndarray, tol: float, dt: float,
                    duration: float) -> dict:
    """The controlled run's steps, rejections and error estimates (Run.summary keys).

    ``intervals_by_step`` counts the steps accepted in each band
    (dt / 2^(j+1), dt / 2^j] (s; base step dt, steps above dt in the
    first).  Besides the largest local
    estimate, the run's global error is estimated as the root sum of
    squares of the accepted steps' local estimates (local errors of
    random sign): ``q_error_rss`` for the positions (relative to their
    scales, as the tip's error relative to its range) and
    ``share_error_rss`` for the contact codes' time shares (the events'
    time errors over the run's ``duration`` (s)); ``global_error_est`` is
    the larger (docs/model.md, "How far to trust it").
    """
    n_floor = int(ctl[ly.CTL_N_FLOOR])
    floors = [{"t0": float(r[ly.FL_T0]), "t1": float(r[ly.FL_T1]),
               "from_regime": int(r[ly.FL_FROM]), "to_regime": int(r[ly.FL_TO]),
               "events": int(r[ly.FL_EVENTS]),
               "error_over_tol": None if r[ly.FL_ERR] < 0 else float(r[ly.FL_ERR]),
               "moreau_jean_steps": int(r[ly.FL_STEPPED])}
              for r in floor_log[:min(n_floor, len(floor_log))]]
    done = ctl[ly.CTL_INTERVALS] > 0
    names = [*Q_COLUMNS, *QD_COLUMNS, *ly.EV_NAMES, "event_time"]
    arg = int(ctl[ly.CTL_ARG_ERR_MAX])
    q_rss = float(np.sqrt(ctl[ly.CTL_Q_SSQ]))
    share_rss = float(np.sqrt(ctl[ly.CTL_T_SSQ])) / duration if duration > 0 else 0.0
    per_level = ctl[ly.CTL_LEVELS:ly.CTL_LEVELS + ly.N_CTL_LEVELS]
    levels = {f"{dt / 2 ** j:.4g}": int(n) for j, n in enumerate(per_level) if n > 0}
    return {"steps": int(ctl[ly.CTL_STEPS]), "steps_all": int(ctl[ly.CTL_WORK]),
            "intervals": int(ctl[ly.CTL_INTERVALS]), "rejected": int(ctl[ly.CTL_REJECTED]),
            "h_min": float(ctl[ly.CTL_H_MIN]) if done else None,
            "h_max": float(ctl[ly.CTL_H_MAX]) if done else None,
            "error_est_max": float(ctl[ly.CTL_ERR_MAX] * tol),
            "error_over_tol_max": float(ctl[ly.CTL_ERR_MAX]),
            "t_error_max": float(ctl[ly.CTL_T_ERR_MAX]),
            "error_max_in": names[arg] if done else None,
            "rejected_by_events": int(ctl[ly.CTL_REJECTED_EVENTS]),
            "intervals_by_step": levels,
            "global_error_est": max(q_rss, share_rss), "q_error_rss": q_rss,
            "share_error_rss": share_rss,
            "floor_count": n_floor, "floor_intervals": floors}


def fixed_step_summary(dt: float, steps: int) -> dict:
    """The summary keys of a fixed-step run: its steps, and no error estimate."""
    return {"steps": steps, "steps_all": steps, "intervals": steps, "rejected": 0,
            "h_min": dt, "h_max": dt, "error_est_max": None, "error_over_tol_max": None,
            "t_error_max": None, "error_max_in": None, "rejected_by_events": 0,
            "global_error_est": None, "q_error_rss": None, "share_error_rss": None,
            "intervals_by_step": {f"{dt:.4g}": steps}, "floor_count": 0, "floor_intervals": []}


def record_so_far(params, ex, dt, duration, parts_t, parts_y, parts_s, parts_analog, parts_log,
                   st, static_tip, label, t0) -> Run:
    """The samples so far whose filtered channels are final, as a Run (status OK)."""
    analog = np.concatenate(parts_analog)
    n = len(analog)
    sig = np.concatenate(parts_s)[:n]
    sig[:, antialias.ANALOG_COLUMNS] = analog
    return assemble(params, ex, dt, duration, ly.OK, 0.0, [np.concatenate(parts_t)[:n]],
                     [np.concatenate(parts_y)[:n]], [sig], parts_log, st, static_tip, label, t0)


def assemble(params, ex, dt, duration, status, wall, parts_t, parts_y, parts_s, parts_log, st,
              static_tip, label, t0) -> Run:
    t = np.concatenate(parts_t)
    ys = np.concatenate(parts_y)
    sig = np.concatenate(parts_s)
    logs = np.concatenate(parts_log) if parts_log else np.empty((0, ly.N_LOG))
    units = {n: u for n, u in zip(ly.COORD_NAMES, ly.COORD_UNITS)}
    units.update({f"{n}_dot": f"{u}/s" for n, u in zip(ly.COORD_NAMES, ly.COORD_UNITS)})
    units.update(dict(zip(ly.SIGNALS, ly.SIGNAL_UNITS)))
    units.update({"t": "s", "impulse_t": "dyn s", "ke_lost": "erg"})
    stats = {"max_penetration_cm": max(0.0, st[ly.ST_MAX_PEN]), "max_drift_cm": st[ly.ST_MAX_DRIFT],
             "max_correction_cm": st[ly.ST_MAX_CORRECTION],
             "t_max_penetration": st[ly.ST_T_MAX_PEN],
             "max_penetration_where": int(st[ly.ST_PEN_WHERE]),
             "impact_energy_lost_erg": st[ly.ST_E_IMPACT], "t_reached": st[ly.ST_T],
             "steps": int(st[ly.ST_STEP]),
             "accumulations": int(st[ly.ST_N_ACCUM]),
             "accumulation_energy_lost_erg": st[ly.ST_E_ACCUM],
             "inconsistent_resolved": int(st[ly.ST_N_INCONSISTENT]),
             "inconsistent_energy_lost_erg": st[ly.ST_E_INCONSISTENT],
             "least_violated": int(st[ly.ST_N_UNRESOLVED]),
             "stepped_steps": int(st[ly.ST_N_STEPPED]),
             "stepped_energy_lost_erg": st[ly.ST_E_STEPPED],
             "s_min_cm": st[ly.ST_S_MIN], "s_max_cm": st[ly.ST_S_MAX], "past_end": int(st[ly.ST_N_PAST_END]), "past_end_uncrossed": int(st[ly.ST_N_PAST_END_UNCROSSED]), "past_info": st[ly.ST_PAST_INFO:ly.ST_PAST_INFO + 7].tolist()}
    return Run(params=params, excitation=ex, dt=dt, duration=duration, status=int(status),
               message=ly.MESSAGES[int(status)], wall_s=wall, t=t, states=ys, sensors=sig, log=logs,
               stats=stats, static_tip_y=static_tip, initial=label, units=units, t0=t0)
