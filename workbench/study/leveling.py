"""A response-limited drive: each point's force set as the lab set it.

The paper's operator set the shaker's amplitude trial by trial "so as to not saturate the
sensors" (seed §5.2).  A study with a ``[limits]`` table does the same by a stated rule, for
drives with a force (``force_n``: sine, chirp, hammers).  The point's force is the largest, up
to the study's ``force_n``, at which every limit of :class:`Limits` holds over the whole run:

- ``accel_g``: the accelerometers' largest |acceleration| (g) within their range;
- ``force_transducer_n``: the force transducer's largest |force1| (N) within its range;
- ``tip_cm``: the tip's largest deflection from its static equilibrium (cm) within the
  deflection the beams' shapes were compared with the rig at;
- ``slot``: the loose body's largest |slide| within the slot's travel (``s_travel``).

The most restrictive limit decides.  The search (:func:`level`) brackets the largest force:

1. run at the first estimate (the previous frequency's force in a study's chain, else the
   study's ``force_n``);
2. while no run has met every limit, run again lower: for each limit exceeded, at
   ``LEVEL_MARGIN * F / ratio`` where the response follows the force (tip, accelerometers,
   force transducer), at ``F / step`` for the slide (a friction ratchet: it jumps to the
   end stop once the body slips, so its ratio says nothing of the force), the lowest of
   these; ``step`` starts at ``resolution`` and squares after each such run;
3. while every run has met the limits, run again at ``F * step`` (at most ``force_n``), the
   step squaring likewise;
4. once a force that meets every limit (F_ok) and one that does not (F_over) are known, halve
   the bracket in log force until F_over <= resolution * F_ok.

A run stops as soon as its record exceeds a limit (``simulate(stop=...)``: the record so far
is the whole run's first part, so the verdict is the whole run's), which makes the runs above
the limits cheap.  (Short trial runs to bracket the force, the candidates then run whole, cost
more: the slide's ratchet reaches the end stop late in the run at forces a 3 s trial passes,
docs/performance.md.)

The kept run is the one at F_ok: the force used is within ``resolution`` of the largest force
meeting the limits, if the responses grow with the force (nearly always: a response that falls
as the force grows, past a jump of the nonlinear response, can hide a larger force within
the limits).  A point whose every run up to ``max_runs``, or down to ``MIN_FORCE_FRACTION``
of ``force_n``, exceeds a limit keeps its lowest force's run, run whole, with ``level_met``
false: the report lists it with its largest responses.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Callable

from ..model.limits import ACCEL_RANGE_G, FORCE_RANGE_N, VALID_TIP_CM
from ..model.validity import RESPONSES, validity

#: The margin below a limit aimed at when a proportional response sets the next force.
LEVEL_MARGIN = 0.97
#: The lowest force tried, as a fraction of the study's force_n.
MIN_FORCE_FRACTION = 1e-3
#: The limits whose responses follow the force (the next force is scaled by them).
PROPORTIONAL = ("tip", "accel", "force")


@dataclass(frozen=True)
class Limits:
    """The limits of a response-limited drive (module docstring); None switches one off."""

    accel_g: float | None = ACCEL_RANGE_G            # g: PCB 352A24 datasheet, +-50 g
    force_transducer_n: float | None = FORCE_RANGE_N  # N: PCB 208C03 datasheet, 2224 N
    tip_cm: float | None = VALID_TIP_CM              # cm: seed §5.3's 8.4 cm deflection test
    slot: bool = True                                # the slide within params.s_travel
    resolution: float = 1.25                         # F_over <= resolution * F_ok
    max_runs: int = 10                               # runs a point may take

    def ratios(self, run) -> dict[str, float]:
        """Each limit's largest response over the run divided by the limit (> 1: exceeded)."""
        v = validity(run)
        out = {}
        for name, limit in (("accel", self.accel_g), ("force", self.force_transducer_n),
                            ("tip", self.tip_cm)):
            if limit is not None:
                out[name] = v[RESPONSES[name][0]] / limit
        if self.slot:
            out["slot"] = v[RESPONSES["slot"][0]] / run.params.s_travel
        return out

    def exceeded(self, run) -> str | None:
        """The limits the run exceeds, in words, or None: ``simulate``'s ``stop`` condition."""
        over = {k: v for k, v in self.ratios(run).items() if v > 1.0}
        return ", ".join(f"{k} at {v:.3g} of its limit" for k, v in over.items()) or None

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass
class Leveled:
    """The outcome of :func:`level`: the kept run and how it was found."""

    run: object
    force_n: float              # the kept run's force (N)
    runs: int                   # runs taken
    met: bool                   # the kept run meets every limit
    limit: str                  # the limit that decided ("force_n": none, the study's force)
    force_over_n: float         # the lowest force tried that exceeded a limit (N; nan: none)
    estimate_n: float           # the first force tried (N)

    def row(self) -> dict:
        """The point's columns: force_n_used, level_runs, level_met, level_limit, ..."""
        return {"force_n_used": self.force_n, "level_runs": self.runs, "level_met": self.met,
                "level_limit": self.limit, "level_force_over_n": self.force_over_n,
                "level_estimate_n": self.estimate_n}


def level(simulate_at: Callable[..., object], force_max: float, limits: Limits,
          estimate: float | None = None) -> Leveled:
    """The run (``simulate_at(force, stop=...)``, a :class:`~workbench.model.simulate.Run`) at
    the largest force up to ``force_max`` (N) meeting every limit, by the search of the
    module docstring, from ``estimate`` (N) if given."""
    force = force_max if estimate is None or not estimate > 0 else min(force_max, estimate)
    first = force
    floor = force_max * MIN_FORCE_FRACTION
    ok = over = None               # (force, run, ratios) of the largest passing, lowest failing
    down = up = limits.resolution
    runs = 0
    while True:
        run = simulate_at(force, stop=limits.exceeded)
        runs += 1
        if not (run.ok or run.stopped):
            return Leveled(run, force, runs, False, "the run failed", _force(over), first)
        ratios = limits.ratios(run)
        if run.ok and max(ratios.values(), default=0.0) <= 1.0:
            if ok is None or force > ok[0]:
                ok = (force, run, ratios)
        elif over is None or force < over[0]:
            over = (force, run, ratios)
        if ok is not None and ok[0] >= force_max:
            return Leveled(ok[1], ok[0], runs, True, "force_n", _force(over), first)
        if ok is not None and over is not None and over[0] <= limits.resolution * ok[0]:
            return Leveled(ok[1], ok[0], runs, True, _decider(over[2]), over[0], first)
        if runs >= limits.max_runs or (ok is None and force <= floor):
            break
        if ok is not None and over is not None:
            force = math.sqrt(ok[0] * over[0])
        elif ok is None:
            f, _, r = over
            force = max(floor, min(LEVEL_MARGIN * f / value if name in PROPORTIONAL else f / down
                                   for name, value in r.items() if value > 1.0))
            down *= down
        else:
            force = min(force_max, ok[0] * up)
            up *= up
    if ok is not None:             # the runs ran out before the bracket closed
        return Leveled(ok[1], ok[0], runs, True, _decider(over[2]) if over else "max_runs",
                       _force(over), first)
    run = simulate_at(over[0])     # the lowest force tried, run whole for the point's measures
    return Leveled(run, over[0], runs + 1, False, _decider(over[2]), over[0], first)


def _force(found) -> float:
    return float("nan") if found is None else found[0]


def _decider(ratios: dict) -> str:
    """The limit exceeded most at a failing force."""
    return max(ratios, key=ratios.get)
