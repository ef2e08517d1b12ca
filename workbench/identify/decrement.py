"""Damping ratio, natural frequency and modulus from a free decay (seed §4.4, Eq. 2, Appendix B).

A cantilevered beam is deflected, released, and the peaks of its decaying
response are read: the first peak x1 at t1, the last peak xn at tn, and the
count n.  :func:`log_decrement` turns them into the damped period Td, the
damping ratio zeta, the natural frequency omega_n and, when the beam's mass
per length, length and area moment are given, EI and E by Eq. 2,

    E I = 11 mu omega_n^2 L^4 / 140       (Appendix A: a tip-loaded cantilever's
                                           static stiffness 3EI/L^3 with the
                                           kinetic energy of its static shape).

**Conventions of Appendix B** (found by reproducing all six rows to the
printed digits; see ``workbench identify tables``):

* Td = (tn - t1) / n: the time from the first to the last peak over n;
* delta = ln(x1 / xn) / (n - 1): the decrement over the n - 1 cycles between
  the first and the n-th peak, zeta = delta / sqrt(4 pi^2 + delta^2);
* omega_n = 2 pi / (Td sqrt(1 - zeta^2)), computed from Td as tabulated, i.e.
  rounded to 1e-6 s (``td_round_s=1e-6``; None keeps it exact).  With the
  exact Td the last digit of omega_n differs in four rows of six.

The two counts are inconsistent with each other (n peaks span n - 1
periods); the paper's numbers need both, so both are kept and documented.
``appendix_b_conventions=False`` uses n - 1 for both, the textbook form.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..study.metrics import parabolic_vertex
from ..model.params import ParameterError, check_positive

#: Eq. 2's factor: E I = EI_FACTOR mu omega_n^2 L^4.
EI_FACTOR = 11.0 / 140.0


class Decrement(NamedTuple):
    """What a logarithmic decrement gives (units in the field names' docs)."""

    Td: float        #: damped period (s)
    delta: float     #: logarithmic decrement per cycle (-)
    zeta: float      #: damping ratio (-)
    omega_d: float   #: damped natural frequency (rad/s)
    omega_n: float   #: undamped natural frequency (rad/s)
    EI: float        #: bending stiffness (g cm^3/s^2), NaN unless mu, length given
    E: float         #: Young's modulus (g/(cm s^2)), NaN unless the area moment is given

    @property
    def E_gpa(self) -> float:
        """Young's modulus in GPa (1 GPa = 1e10 g/(cm s^2))."""
        return self.E / 1.0e10


def log_decrement(x1: float, xn: float, t1: float, tn: float, n: int, *,
                  mu: float | None = None, length: float | None = None,
                  area_moment: float | None = None, appendix_b_conventions: bool = True,
                  td_round_s: float | None = 1e-6) -> Decrement:
    """Td, zeta and omega_n from two peaks of a free decay; EI and E by Eq. 2.

    ``x1``, ``xn``: amplitudes of the first and n-th peak (any unit, same for
    both); ``t1``, ``tn``: their times (s); ``n``: the number of peaks, >= 2.
    ``mu`` (g/cm), ``length`` (cm) and ``area_moment`` (cm^4) of the beam
    give EI (needs mu and length) and E = EI / I.  The conventions are
    Appendix B's (module docstring).
    """
    x1 = check_positive("x1", x1, "(signal unit)")
    xn = check_positive("xn", xn, "(signal unit)")
    if not xn < x1:
        raise ParameterError(f"xn = {xn} must be below x1 = {x1}: the peaks of a decay shrink")
    if not (isinstance(n, (int, np.integer)) and n >= 2):
        raise ParameterError(f"n = {n!r} must be a whole number of peaks >= 2")
    if not (math.isfinite(t1) and math.isfinite(tn) and tn > t1):
        raise ParameterError(f"tn = {tn} s must come after t1 = {t1} s")
    cycles_td = n if appendix_b_conventions else n - 1
    td = (tn - t1) / cycles_td
    if td_round_s is not None:
        td = round(td / td_round_s) * td_round_s
    if not td > 0.0:
        raise ParameterError(f"tn - t1 = {tn - t1:g} s over {cycles_td} cycles is a period below "
                             f"the tabulation step {td_round_s:g} s: the peaks are too close")
    delta = math.log(x1 / xn) / (n - 1)
    zeta = delta / math.sqrt(4.0 * math.pi ** 2 + delta ** 2)
    omega_d = 2.0 * math.pi / td
    omega_n = omega_d / math.sqrt(1.0 - zeta ** 2)
    ei = e = float("nan")
    if mu is not None and length is not None:
        ei = bending_stiffness(omega_n, check_positive("mu", mu, "g/cm"),
                               check_positive("length", length, "cm"))
        if area_moment is not None:
            e = ei / check_positive("area_moment", area_moment, "cm^4")
    return Decrement(td, delta, zeta, omega_d, omega_n, ei, e)


def bending_stiffness(omega_n: float, mu: float, length: float) -> float:
    """EI (g cm^3/s^2) of a cantilever from its first natural frequency, Eq. 2."""
    return EI_FACTOR * mu * omega_n ** 2 * length ** 4


def decay_peaks(t: np.ndarray, x: np.ndarray, min_height: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Times and heights of the positive peaks of a decaying record, refined by
    a parabola through each peak and its neighbours (s, signal unit).

    ``min_height`` drops peaks at or below it (noise at the end of a decay).
    """
    from scipy.signal import find_peaks

    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float) - float(np.mean(x))
    idx, _ = find_peaks(x, height=min_height if min_height > 0 else None)
    idx = idx[(idx > 0) & (idx < len(x) - 1)]
    shift, height = parabolic_vertex(x[idx - 1], x[idx], x[idx + 1])
    return t[idx] + shift * np.gradient(t)[idx], height


def decrement_from_record(t: np.ndarray, x: np.ndarray, min_height: float = 0.0,
                          **beam) -> Decrement:
    """:func:`log_decrement` of a measured decay: from its first to its last
    positive peak above ``min_height`` (``beam``: mu, length, area_moment).
    The textbook convention (n - 1 periods) is used, since the peaks are
    counted here rather than read from a table."""
    tp, xp = decay_peaks(t, x, min_height)
    if len(tp) < 2:
        raise ParameterError(f"the record has {len(tp)} peak(s) above {min_height}: need two or more")
    return log_decrement(float(xp[0]), float(xp[-1]), float(tp[0]), float(tp[-1]), len(tp),
                         appendix_b_conventions=False, td_round_s=None, **beam)
