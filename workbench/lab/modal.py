"""Modal parameters from FRFs by the field's own tool: sdypy-EMA's LSCF and a stabilisation chart.

The poles of an FRF table (:mod:`workbench.lab.frf`) come from the
least-squares complex-frequency estimator (LSCF; Guillaume, Verboven et al.,
"A poly-reference implementation of the least-squares complex frequency-domain
estimator", IMAC XXI, 2003) as sdypy-EMA implements it
(``sdypy.EMA.Model.get_poles("lscf")``), fitted to every response's H1 at
once (a common denominator), each scaled to unit RMS over the band so that
strain and acceleration weigh alike.  The estimator is run at every model
order up to ``2 * order`` (step 2), and the modes are read from its
stabilisation chart, as a modal engineer reads it:

- a pole at one order is *stable* when the order below has a pole within
  :data:`STABLE_F` in frequency and :data:`STABLE_ZETA` in damping ratio
  (relative; the usual 1 % and 5 %, Peeters et al., "The PolyMAX frequency-domain
  method", Shock Vib. 11, 2004);
- stable poles closer than :data:`STABLE_F` in frequency form a column of the
  chart; a column that holds a stable pole at :data:`MIN_ORDERS_SHARE` of the
  orders (at least :data:`MIN_ORDERS`) is a candidate, its frequency and
  damping ratio the medians over its column;
- an over-modelled fit of clean data also stabilises computational poles, so
  a candidate is a physical mode only where it carries the response: the
  modal constants of all candidates are fitted to each H1 by least squares
  (LSFD, Ewins, Modal Testing, 2nd ed., §4.4: a residue per pole, its
  conjugate's the conjugate, and real residual terms 1 and 1/(i omega)^2 for
  the modes outside the band), and a mode's term must reach :data:`MIN_CONTRIBUTION`
  of the response's largest |H1| in the band on at least one response (on
  the locked joint's hammer test the modes reach 1.4-100 %, the rest at
  most 0.2 %).

An impact record's exponential window exp(-t/tau) shifts every pole by
-1/tau (Fladung & Rost, Mech. Syst. Signal Process. 11(1), 1997): the poles
are shifted back by +1/tau before anything is read from them.

A mode's damping is measured only when the record (or the Welch segment)
spans at least :data:`MIN_DECAY_TIMES` of its decay times 1/(zeta omega_n):
below that, the mode's half-power bandwidth 2 zeta f_n is under 0.64 of the
frequency resolution 1/T, and after the exponential window its own decay is
under 30 % of the decay the window adds (ln(1/EXP_END) / T = 4.6 / T), so a
small error in the fitted pole is a large one in zeta.  Such a mode gets its
frequency and a damping ratio of NaN with ``zeta_resolved`` False.
"""
from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from ..model.params import ParameterError
from .frf import responses_of

#: Stability of a pole against the order below: relative change of frequency and damping ratio.
STABLE_F = 0.01
STABLE_ZETA = 0.05
#: A chart column is a mode when it is stable at this share of the orders, and at least this many.
MIN_ORDERS_SHARE = 0.3
MIN_ORDERS = 4
#: A mode's largest term, relative to the response's largest |H1| in the band (module docstring).
MIN_CONTRIBUTION = 0.01
#: Poles with a damping ratio outside (0, ZETA_MAX) are not structural modes (noise, the fit's
#: computational poles).
ZETA_MAX = 0.3
#: The default highest order (sdypy-EMA's pol_order_high: models of order 2, 4, ... 2 * ORDER),
#: enough for the dozen modes of a band with room for the computational poles.
ORDER = 40
#: Decay times 1/(zeta omega_n) the record must span for a mode's damping (module docstring).
MIN_DECAY_TIMES = 2.0
#: The columns of a mode table.
MODE_COLUMNS = ["mode", "f_hz", "zeta", "zeta_resolved", "decay_times", "orders_stable",
                "contribution", "band_lo_hz", "band_hi_hz"]


def chart(table: pd.DataFrame, responses=None, f_min: float = 0.0, f_max: float | None = None,
          order: int | None = None) -> pd.DataFrame:
    """The stabilisation chart of an FRF table's H1 over [f_min, f_max] (Hz; default the
    table's band): one row per pole with positive frequency of each model order, columns
    ``order``, ``f_hz``, ``zeta`` and ``stable`` (module docstring).  ``order``: the highest
    model order is 2 * order (default :data:`ORDER`, or a quarter of the band's frequency
    lines where they are fewer).  Poles are corrected for an impact record's exponential
    window.  Raises ParameterError on a band it cannot fit."""
    f = table.index.to_numpy(dtype=float)
    f_max = float(f[-1]) if f_max is None else min(float(f_max), float(f[-1]))
    if not 0.0 <= f_min < f_max:
        raise ParameterError(f"f_min = {f_min:g} Hz: must be below f_max = {f_max:g} Hz")
    keep = f <= f_max * (1 + 1e-12)
    lines = int(np.count_nonzero(keep & (f >= f_min)))
    if order is None:
        order = max(2, min(ORDER, lines // 4))
    if not isinstance(order, (int, np.integer)) or not 2 <= order <= 200:
        raise ParameterError(f"order = {order!r}: allowed a whole number in [2, 200]")
    responses = list(responses) if responses is not None else responses_of(table)
    if lines < 4 * order:
        raise ParameterError(f"the band {f_min:g}-{f_max:g} Hz has {lines} frequency lines; "
                             f"the order {order} needs at least {4 * order}")
    h = np.nan_to_num(np.array([table[f"{r}_H1"].to_numpy()[keep] for r in responses]))
    level = np.sqrt(np.mean(np.abs(h[:, f[keep] >= f_min]) ** 2, axis=1, keepdims=True))
    h = h / np.where(level > 0, level, 1.0)
    from sdypy import EMA
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # its note that upper was clamped to the last bin
        model = EMA.Model(frf=h, freq=f[keep], lower=max(f_min, f[1]), upper=f_max,
                          pol_order_high=int(order))     # lower: the static line is not fitted
        model.get_poles("lscf", show_progress=False)
    shift = 1.0 / table.attrs["exp_tau_s"] if table.attrs.get("exp_tau_s") else 0.0
    rows, previous = [], None
    for k, poles in enumerate(model.all_poles):
        p = np.asarray(poles)
        p = p[np.isfinite(p) & (p.imag > 0)] + shift
        wn = np.abs(p)
        zeta = -p.real / np.where(wn > 0, wn, 1.0)
        fn = wn / (2 * np.pi)
        keep_p = (zeta > 0) & (zeta < ZETA_MAX) & (fn >= f_min) & (fn <= f_max)
        fn, zeta = fn[keep_p], zeta[keep_p]
        stable = np.zeros(len(fn), dtype=bool)
        if previous is not None and len(previous[0]):
            df = np.abs(fn[:, None] - previous[0][None, :]) / fn[:, None]
            dz = np.abs(zeta[:, None] - previous[1][None, :]) / zeta[:, None]
            stable = np.any((df < STABLE_F) & (dz < STABLE_ZETA), axis=1)
        rows.append(pd.DataFrame({"order": 2 * (k + 1), "f_hz": fn, "zeta": zeta,
                                  "stable": stable}))
        previous = (fn, zeta)
    out = pd.concat(rows, ignore_index=True)
    out.attrs.update(band_lo_hz=float(f_min), band_hi_hz=float(f_max), orders=len(rows),
                     window_shift=shift,
                     record_s=float(table.attrs.get("segment_s", 1.0 / max(f[1] - f[0], 1e-300))),
                     responses=responses)
    return out


def modes(table: pd.DataFrame, stabilisation: pd.DataFrame) -> pd.DataFrame:
    """The physical modes of an FRF table read from its stabilisation chart (:func:`chart`;
    module docstring): one row per mode with its frequency (Hz), damping ratio (NaN where the
    record is too short to measure it, ``zeta_resolved`` False), the record's length in the
    mode's decay times, the number of orders at which it is stable, its largest share of a
    response, and the band it was fitted in (Hz)."""
    a = stabilisation.attrs
    stable = stabilisation[stabilisation.stable].sort_values("f_hz")
    need = max(MIN_ORDERS, int(np.ceil(MIN_ORDERS_SHARE * a["orders"])))
    rows = []
    if len(stable):
        f = stable.f_hz.to_numpy()
        breaks = np.flatnonzero(np.diff(f) / f[1:] > STABLE_F) + 1
        for column in np.split(np.arange(len(f)), breaks):
            group = stable.iloc[column]
            if group.order.nunique() >= need:
                rows.append({"f_hz": float(group.f_hz.median()),
                             "zeta_fit": float(group.zeta.median()),
                             "orders_stable": int(group.order.nunique())})
    found = pd.DataFrame(rows, columns=["f_hz", "zeta_fit", "orders_stable"])
    found["contribution"] = contributions(table, found, a)
    found = found[found.contribution >= MIN_CONTRIBUTION].reset_index(drop=True)
    decay_times = a["record_s"] * found.zeta_fit * 2 * np.pi * found.f_hz
    resolved = decay_times >= MIN_DECAY_TIMES
    out = found.assign(zeta=found.zeta_fit.where(resolved), zeta_resolved=resolved,
                       decay_times=decay_times, band_lo_hz=a["band_lo_hz"],
                       band_hi_hz=a["band_hi_hz"], mode=np.arange(1, len(found) + 1))
    return out[MODE_COLUMNS]


def contributions(table: pd.DataFrame, candidates: pd.DataFrame, attrs: dict) -> np.ndarray:
    """Each candidate mode's largest term over the responses, relative to the response's
    largest |H1| in the band: modal constants fitted by least squares (module docstring)."""
    if not len(candidates):
        return np.zeros(0)
    f = table.index.to_numpy(dtype=float)
    band = (f >= max(attrs["band_lo_hz"], f[1])) & (f <= attrs["band_hi_hz"] * (1 + 1e-12))
    s = 2j * np.pi * f[band]
    wn = 2 * np.pi * candidates.f_hz.to_numpy()
    zeta = candidates.zeta_fit.to_numpy()
    poles = -zeta * wn + 1j * wn * np.sqrt(1 - zeta ** 2) - attrs["window_shift"]
    even = 1.0 / (s[:, None] - poles) + 1.0 / (s[:, None] - np.conj(poles))
    odd = 1j / (s[:, None] - poles) - 1j / (s[:, None] - np.conj(poles))
    basis = np.hstack([even, odd, np.ones((len(s), 1)), 1.0 / s[:, None] ** 2])
    basis = np.vstack([basis.real, basis.imag])        # real unknowns: H(-w) = conj H(w)
    n = len(poles)
    share = np.zeros(n)
    for r in attrs["responses"]:
        h = np.nan_to_num(table[f"{r}_H1"].to_numpy()[band])
        top = np.max(np.abs(h))
        if top == 0:
            continue
        coef = np.linalg.lstsq(basis, np.concatenate([h.real, h.imag]) / top, rcond=None)[0]
        modal = even * coef[:n] + odd * coef[n:2 * n]
        share = np.maximum(share, np.max(np.abs(modal), axis=0))
    return share


def unresolved_words(table: pd.DataFrame) -> list[str]:
    """One sentence per mode whose damping the record is too short to measure."""
    return [f"{m.f_hz:.4g} Hz: the record spans {m.decay_times:.2g} of its decay times, fewer "
            f"than {MIN_DECAY_TIMES:g}; too short to measure its damping ratio"
            for m in table.itertuples() if not m.zeta_resolved]


def mode_table(tables: dict[str, pd.DataFrame], responses=None, f_min: float = 0.0,
               f_max: float | None = None, order: int | None = None) -> pd.DataFrame:
    """The modes of each FRF table ({source: table}), one row per mode with a ``source``
    column first (the columns of :func:`modes`)."""
    found = [modes(table, chart(table, responses, f_min, f_max, order)).assign(source=source)
             for source, table in tables.items()]
    columns = ["source", *MODE_COLUMNS]
    found = [m for m in found if len(m)]
    return pd.concat(found, ignore_index=True)[columns] if found else pd.DataFrame(columns=columns)
