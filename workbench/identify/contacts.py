"""Contact detection from the PVDF patch voltages (seed §3.5).

Four PVDF patches in the joint (contact1-4; Table 2) give a voltage when the
loose body presses on them.  As the paper's MATLAB script did, each
patch's peaks above a threshold are found and the four lists are merged
into one contact-code series of at most two points (codes 1-4 for one
point, 13, 14, 23, 24 for two, as in :data:`workbench.core.layout.CONTACT_CODE`).

Two points at the same end of the loose body (1 and 2, or 3 and 4) cannot
touch at once across the clearance; when both read above the threshold the
stronger one is kept.  With more than two patches above it, the strongest
and the strongest compatible one are kept.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..model.params import ParameterError

#: The contact channels, in point order (Table 2).
PATCHES = ("contact1", "contact2", "contact3", "contact4")
#: The end of the loose body each point is at: 1, 2 inner; 3, 4 at the lips.
_END = np.array([0, 0, 1, 1])


def _voltages(voltages) -> np.ndarray:
    """(n, 4) float array from a DataFrame with contact1-4 columns or an array."""
    if isinstance(voltages, pd.DataFrame):
        missing = [c for c in PATCHES if c not in voltages.columns]
        if missing:
            raise ParameterError(f"voltages lack the contact channels {missing}")
        voltages = voltages[list(PATCHES)].to_numpy(dtype=float)
    v = np.asarray(voltages, dtype=float)
    if v.ndim != 2 or v.shape[1] != 4:
        raise ParameterError(f"voltages must have 4 columns (contact1-4), got shape {v.shape}")
    return v


def _thresholds(threshold, n_patches=4) -> np.ndarray:
    thr = np.broadcast_to(np.asarray(threshold, dtype=float), (n_patches,))
    if not np.all(np.isfinite(thr)):
        raise ParameterError(f"threshold = {threshold!r} V must be finite (one value or one per patch)")
    return thr


def _code(points: list[int]) -> int:
    """The contact code of at most two points (0-based indices), e.g. [3, 0] -> 14."""
    return int("".join(str(p + 1) for p in sorted(points))) if points else 0


def _strongest_pair(levels: np.ndarray, above: np.ndarray) -> list[int]:
    """The strongest point above the threshold and the strongest one at the other end."""
    if not above.any():
        return []
    order = [int(i) for i in np.argsort(-levels) if above[i]]
    first = order[0]
    second = next((i for i in order[1:] if _END[i] != _END[first]), None)
    return [first] if second is None else [first, second]


def contact_code_series(voltages, threshold) -> np.ndarray:
    """The contact code at every sample: the points whose voltage exceeds
    ``threshold`` (V; one value or one per patch), at most two (module docstring)."""
    v = _voltages(voltages)
    above = v > _thresholds(threshold)
    codes = np.zeros(len(v), dtype=np.int64)
    for i in np.flatnonzero(above.any(axis=1)):
        codes[i] = _code(_strongest_pair(v[i], above[i]))
    return codes


def detect_contacts(t, voltages, threshold, coincidence_s: float = 2e-3) -> pd.DataFrame:
    """The paper's detection: each patch's peaks above ``threshold``, merged.

    A peak is the largest sample of each run above the threshold.  Peaks
    of different patches within ``coincidence_s`` (s) of the first of a
    group form one contact of at most two points.  Returns a DataFrame
    with ``t`` (s, of the group's first peak), ``code`` and ``points``.
    """
    t = np.asarray(t, dtype=float)
    v = _voltages(voltages)
    if t.shape != (len(v),):
        raise ParameterError(f"t has {t.shape} samples, the voltages {len(v)}")
    thr = _thresholds(threshold)
    peaks = []                                  # (time, patch, height)
    for j in range(4):
        above = v[:, j] > thr[j]
        edges = np.flatnonzero(np.diff(np.concatenate(([0], above.astype(np.int8), [0]))))
        for start, stop in zip(edges[::2], edges[1::2]):
            i = start + int(np.argmax(v[start:stop, j]))
            peaks.append((t[i], j, v[i, j]))
    peaks.sort()
    rows = []
    i = 0
    while i < len(peaks):
        group = [p for p in peaks[i:] if p[0] - peaks[i][0] <= coincidence_s]
        levels = np.full(4, -np.inf)
        for _, j, h in group:
            levels[j] = max(levels[j], h)
        points = _strongest_pair(levels, np.isfinite(levels))
        rows.append((peaks[i][0], _code(points), len(group)))
        i += len(group)
    return pd.DataFrame(rows, columns=["t", "code", "peaks"])
