"""How fast the joint wears: per contact point and per drive cycle, the friction work, the impact
energy lost, the impacts, the largest normal force and its line load, and a wear volume by
Archard's law.

Over a window [t0, t1] of a run with ``cycles`` drive cycles in it (seconds when the drive has
no frequency), for each contact point k = 1..4 (docs/model.md §7, Fig. 4):

- ``friction_work{k}_erg``: the energy dissipated by Coulomb slip at k, the kernels' integral
  of mu_k lambda_n,k |tau_k'| (signal ``d_friction{k}``; the four add up to the energy audit's
  ``d_friction``);
- ``impact_energy{k}_erg``: the kinetic energy the impulses at k removed (``d_impact{k}``:
  each impact's loss split by the rows of its points, -P_r (u-_r + u+_r) / 2, normal and
  tangential; they add up to ``d_impact``);
- ``impacts{k}``: impacts with a normal impulse at k;
- ``normal_force_max{k}_dyn``: the largest contact force lambda_n,k at the output rate (an
  impact's impulse is not a force and is not in it);
- ``line_load_max{k}_dyn_cm``: that force over the bar's width (2 in, §4.1), the pressure
  proxy of a line contact across the bar;
- ``wear_volume{k}_cm3``: Archard's law, V = k_A F_n s / H (Archard, J. Appl. Phys. 24, 1953),
  with the normal load times the slip distance from the friction work, F_n s = W_f / mu_k
  (Coulomb slip dissipates mu_k F_n per unit distance), k_A and H the :class:`WearConstants`.

All per cycle (per second without a drive frequency), in CGS like the points table
(``workbench.present.units`` shows them in SI: mJ, N, N/mm, mm³); the columns without the
point's number are the sums over the points (the largest, for the force and line load).
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..core import layout as ly
from ..model.params import BAR_WIDTH_CM, ParameterError

N_POINTS = 4
#: The measures summed over the points, and their columns' unit suffixes.
SUMMED = {"friction_work": "_erg", "impact_energy": "_erg", "impacts": "", "wear_volume": "_cm3"}


@dataclass(frozen=True)
class WearConstants:
    """The constants of Archard's law (module docstring); their units, ranges and sources are
    WEAR_UNITS, WEAR_RANGES and WEAR_SOURCES.  A study sets them in its ``[wear]`` table."""

    k_archard: float = 1.0e-4
    hardness_pa: float = 1.0e9
    threshold_mm3: float = 6.45e-7

    def check(self) -> "WearConstants":
        """Self, or ParameterError naming the constant outside its range."""
        for f in fields(self):
            lo, hi = WEAR_RANGES[f.name]
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not lo <= value <= hi:
                raise ParameterError(f"wear.{f.name} = {value!r}: allowed [{lo:g}, {hi:g}] "
                                     f"{WEAR_UNITS[f.name]}")
        return self

    def key(self) -> dict:
        """What a point's row depends on (the threshold only marks the map)."""
        return {"k_archard": self.k_archard, "hardness_pa": self.hardness_pa}

    @property
    def volume_per_work(self) -> float:
        """Wear volume per unit friction work (cm³/erg) at mu_k = 1: k_A / H (H in dyn/cm²)."""
        return self.k_archard / (self.hardness_pa * 10.0)


#: Each constant's unit, range and source (ASSUMPTION: the paper gives no wear data).
WEAR_UNITS = {"k_archard": "-", "hardness_pa": "Pa", "threshold_mm3": "mm³ per cycle"}
WEAR_RANGES = {"k_archard": (1e-8, 1e-2), "hardness_pa": (1e8, 1e11), "threshold_mm3": (1e-15, 1.0)}
WEAR_SOURCES = {
    "k_archard": "ASSUMPTION: 1e-4, unlubricated like metals (Rabinowicz, Friction and Wear of "
                 "Materials, 2nd ed., 1995, Table 7.2: 1e-5 to 1e-3); the paper gives none",
    "hardness_pa": "ASSUMPTION: 1 GPa, aluminium 6061-T6 (about 107 HV; the joint's members "
                   "are aluminium, §4.4); the paper gives none",
    "threshold_mm3": "one of the paper's damage steps (0.127 mm of gap, §5.1) worn in 1e7 cycles "
                     "(a structure's high-cycle life) over a band 1 mm wide (ASSUMPTION) across "
                     "the bar's 50.8 mm: 0.127 x 50.8 x 1 / 1e7 = 6.45e-7 mm³",
}


def wear_constants(table: dict | None) -> WearConstants:
    """The constants of a study's ``[wear]`` table (defaults for those it leaves out)."""
    table = dict(table or {})
    unknown = sorted(set(table) - set(WEAR_UNITS))
    if unknown:
        raise ParameterError(f"[wear] {', '.join(unknown)}: unknown; allowed: "
                             f"{', '.join(WEAR_UNITS)}")
    return WearConstants(**table).check()


def wear_measures(run, t0: float, t1: float, cycles: float,
                  constants: WearConstants = WearConstants()) -> dict:
    """The measures of the module docstring over [t0, t1] (s) of ``run``, per cycle (from the
    run's arrays: pandas is not needed)."""
    if cycles <= 0:
        raise ParameterError(f"cycles = {cycles!r}: must be positive")
    t = np.asarray(run.t)
    win = np.flatnonzero((t >= t0 - 1e-12) & (t <= t1 + 1e-12))
    if not len(win):
        raise ParameterError(f"the window [{t0:g}, {t1:g}] s holds no sample of the run")
    first, last = win[0], win[-1]
    sig = run.sensors
    log = run.log
    impacts = log[(log[:, ly.LOG_KIND] == ly.KIND_IMPACT) & (log[:, ly.LOG_T] >= t0 - 1e-12)
                  & (log[:, ly.LOG_T] <= t1 + 1e-12)]
    mu = run.params.mu_k
    out: dict = {}
    for k in range(1, N_POINTS + 1):
        friction = float(sig[last, ly.SIG_D_FRIC_P + k - 1] - sig[first, ly.SIG_D_FRIC_P + k - 1])
        out[f"friction_work{k}_erg"] = friction / cycles
        out[f"impact_energy{k}_erg"] = float(sig[last, ly.SIG_D_IMPACT_P + k - 1]
                                             - sig[first, ly.SIG_D_IMPACT_P + k - 1]) / cycles
        out[f"impacts{k}"] = float(np.count_nonzero(impacts[:, ly.LOG_P + k - 1])) / cycles
        force = float(sig[win, ly.SIG_LN + k - 1].max(initial=0.0))
        out[f"normal_force_max{k}_dyn"] = force
        out[f"line_load_max{k}_dyn_cm"] = force / BAR_WIDTH_CM
        out[f"wear_volume{k}_cm3"] = (constants.volume_per_work * friction / mu / cycles
                                      if mu > 0 else 0.0)
    for name, suffix in SUMMED.items():
        out[f"{name}{suffix}"] = sum(out[f"{name}{k}{suffix}"] for k in range(1, N_POINTS + 1))
    out["normal_force_max_dyn"] = max(out[f"normal_force_max{k}_dyn"] for k in range(1, 5))
    out["line_load_max_dyn_cm"] = out["normal_force_max_dyn"] / BAR_WIDTH_CM
    return out


def run_wear(run, ramp_s: float, drive_hz: float | None,
             constants: WearConstants = WearConstants()) -> dict:
    """A single run's wear measures: over the run after the drive's ramp, per cycle of the
    drive (per second without a frequency), with the window and its cycles."""
    t = np.asarray(run.t)
    t0, t1 = min(float(ramp_s), float(t[-1])), float(t[-1])
    cycles = (t1 - t0) * drive_hz if drive_hz else (t1 - t0)
    if cycles <= 0:
        return {}
    return {"window_s": [t0, t1], "per": "cycle" if drive_hz else "s", "cycles": cycles,
            **wear_measures(run, t0, t1, cycles, constants)}
