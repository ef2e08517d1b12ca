"""A run's error measured against a companion run of finer settings.

The controlled method's ``global_error_est`` sums local estimates; it cannot
see errors that the motion amplifies after they are made (docs/performance.md,
"The estimate against the measured error").  A companion run measures them:
the same input at a tenth of the tolerance and half the coarsest step
(controlled; where the motion is smooth the controller keeps the coarsest
step at any tolerance, and a tighter tolerance alone would repeat the run)
or a quarter of the step (RK4, fourth order: about 1/256 of the error),
compared sample by sample with the run.  Since the companion's own error
is small beside the run's, the difference is the run's error to within
that fraction.

Measures (the bounds docs/performance.md holds every default run to):

- ``tip_error``: the largest difference of the tip height over the record,
  relative to the companion's range of it;
- ``share_error``: the largest difference of a contact code's time share
  over the record (codes of ``regimes.contact_code``);
- ``event_error``: the difference of the event counts (the starting event
  excluded), relative to the companion's count.

``error_measured`` is the larger of the first two.
"""
from __future__ import annotations

import numpy as np

from workbench.core import layout as ly

from .limits import TOL_RANGE
from .params import ParameterError
from .regimes import contact_shares_of

#: The companion's tolerance is the run's divided by this (controlled method).
TOL_DIVISOR = 10
#: The companion's step is the run's divided by this (fixed-step methods) ...
DT_DIVISOR = 4
#: ... and its coarsest step (controlled method).
COARSEST_DIVISOR = 2
#: The accuracy every default run is held to: the tip within this fraction of its
#: range, every contact share within this (docs/performance.md, "Accuracy").
ERROR_BOUND = 1e-3
#: The keys ``measured`` adds to ``Run.control``.
KEYS = ("error_measured", "tip_error_measured", "share_error_measured",
        "event_error_measured", "companion")


def companion_settings(method_controlled: bool, tol: float | None, dt: float,
                       name: str = "tol") -> dict:
    """The finer settings of the companion run of a run of step ``dt`` (s; the coarsest of
    a controlled run): ``{"tol": tol / 10, "dt": dt / 2}`` or ``{"dt": dt / 4}``.

    A tolerance already at the lower end of TOL_RANGE cannot be divided;
    ParameterError says so, naming the tolerance as ``name``.
    """
    if not method_controlled:
        return {"dt": dt / DT_DIVISOR}
    finer = tol / TOL_DIVISOR
    if finer < TOL_RANGE[0]:
        raise ParameterError(f"{name} = {tol:g} leaves no room for a companion at tol / {TOL_DIVISOR} "
                         f"(the smallest tolerance is {TOL_RANGE[0]:g})")
    return {"tol": finer, "dt": dt / COARSEST_DIVISOR}


def difference(run, ref, t0: float | None = None, t1: float | None = None) -> dict:
    """The differences of ``run`` from ``ref`` over [t0, t1] (s; default the whole record).

    Both runs must share their output times.  Returns ``tip_error``,
    ``share_error``, ``event_error``, ``events`` and ``events_ref``
    (events in (t0, t1]).
    """
    t = run.t
    if len(t) != len(ref.t) or not np.array_equal(t, ref.t):
        raise ValueError("the runs have different output times; compare runs of one output_hz")
    t0 = float(t[0]) if t0 is None else t0
    t1 = float(t[-1]) if t1 is None else t1
    window = (t >= t0 - 1e-12) & (t <= t1 + 1e-12)
    tip = run.signal("tip_y")[window]
    tip_ref = ref.signal("tip_y")[window]
    scale = float(np.ptp(tip_ref))
    shares = contact_shares_of(run.log[:, ly.LOG_T], run.log[:, ly.LOG_TO], t0, t1)
    shares_ref = contact_shares_of(ref.log[:, ly.LOG_T], ref.log[:, ly.LOG_TO], t0, t1)
    codes = set(shares) | set(shares_ref)
    n, n_ref = _events_in(run, t0, t1), _events_in(ref, t0, t1)
    return {"tip_error": float(np.abs(tip - tip_ref).max() / scale) if scale > 0 else 0.0,
            "share_error": float(max((abs(shares.get(c, 0.0) - shares_ref.get(c, 0.0))
                                      for c in codes), default=0.0)),
            "event_error": abs(n - n_ref) / max(n_ref, 1), "events": n, "events_ref": n_ref}


def _events_in(run, t0: float, t1: float) -> int:
    log = run.log
    inside = (log[:, ly.LOG_T] > t0) & (log[:, ly.LOG_T] <= t1)
    return int((inside & (log[:, ly.LOG_KIND] != ly.KIND_START)).sum())


def measured(run, companion, settings: dict) -> dict:
    """``Run.control`` keys: the run's error measured against its ``companion`` run
    (made with ``settings``, from :func:`companion_settings`)."""
    if not companion.ok:
        return {"error_measured": None, "tip_error_measured": None, "share_error_measured": None,
                "event_error_measured": None,
                "companion": {**settings, "status": "failed", "message": companion.message}}
    d = difference(run, companion)
    return {"error_measured": max(d["tip_error"], d["share_error"]),
            "tip_error_measured": d["tip_error"], "share_error_measured": d["share_error"],
            "event_error_measured": d["event_error"],
            "companion": {**settings, "status": "ok", "wall_s": companion.wall_s,
                          "n_events": d["events_ref"]}}
