"""The regime vocabulary outside the kernels: regime, contact set, points, contact code, name.

A regime is a number 0..16 (docs/model.md §7): 0 free flight; for the
contact set k = 1..8, 2k - 1 sticks and 2k slips.  A contact set is a
tuple of contact points (0-based; the paper numbers them 1..4), and the
paper's contact code writes its points 1-based (0, 1, 2, 3, 4, 13, 14, 23,
24).  The kernels hold the same tables in :mod:`workbench.core.layout`
(``SET_FIRST``, ``SET_SECOND``, ``CONTACT_CODE``); this module is the one
place that turns them into words, for everything else (the reference included).
Every function takes a number or a NumPy array of them.
"""
from __future__ import annotations

import numpy as np

from ..core import layout as ly

N_REGIMES = ly.N_REGIMES
N_SETS = ly.N_SETS
N_POINTS = ly.N_POINTS
#: The points of each contact set (0-based), by set number.
SETS = tuple(tuple(p for p in (ly.SET_FIRST[k], ly.SET_SECOND[k]) if p >= 0) for k in range(N_SETS))
#: The paper's contact code of each contact set, by set number.
CONTACT_CODES = tuple(int(c) for c in ly.CONTACT_CODE)


def set_of(regime):
    """The contact set (0..8) of a regime."""
    return (regime + 1) // 2


def is_stick(regime):
    """Does the regime stick (odd numbers)?  Free flight does not."""
    return regime % 2 == 1


def regime_of(set_index: int, stick: bool) -> int:
    """The regime of a contact set (0..8) and a stick flag."""
    if set_index == 0:
        return 0
    return 2 * set_index - 1 if stick else 2 * set_index


def set_of_points(points) -> int:
    """The contact set of the given points (0-based, any order); ValueError if none."""
    return SETS.index(tuple(sorted(points)))


def contact_code(regime):
    """The paper's contact code (0, 1, 2, 3, 4, 13, 14, 23, 24) of a regime."""
    codes = np.array(CONTACT_CODES)[set_of(np.asarray(regime))]
    return int(codes) if codes.ndim == 0 else codes


#: Where each contact point is (docs/model.md §7, Fig. 4), in words.
POINT_WORDS = {1: "inner end on the lower plate", 2: "inner end on the upper plate",
               3: "lower lip on the body", 4: "upper lip on the body"}


def code_words(code: int) -> str:
    """The paper's contact code in words: '0 free flight', '13 points 1+3 (inner end on the
    lower plate, lower lip on the body)'."""
    if code == 0:
        return "0 free flight"
    points = [int(c) for c in str(code)]
    if len(points) == 1:
        return f"{code} point {code} ({POINT_WORDS[code]})"
    return (f"{code} points {'+'.join(map(str, points))} "
            f"({', '.join(POINT_WORDS[p] for p in points)})")


def regime_name(regime: int) -> str:
    """'free', or e.g. 'stick {2,3}' / 'slip {1}' (points 1-based)."""
    if regime == 0:
        return "free"
    code = str(contact_code(regime))
    return f"{'stick' if is_stick(regime) else 'slip'} {{{','.join(code)}}}"


def in_contact(point: int, regime):
    """Is the point (0-based) closed in the regime?  (1 or 0, as the regime's shape.)"""
    members = np.array([point in s for s in SETS], dtype=np.int8)
    out = members[set_of(np.asarray(regime))]
    return int(out) if out.ndim == 0 else out


def regime_time_of(times, to_regime, t0: float, t1: float) -> dict[int, float]:
    """Time (s) spent in each regime within [t0, t1], from the event times (s) and the
    regimes they enter (a run's event log; the regime before the first event is not counted)."""
    out: dict[int, float] = {}
    for k in range(len(times)):
        start = max(times[k], t0)
        end = min(times[k + 1] if k + 1 < len(times) else t1, t1)
        if end > start:
            out[int(to_regime[k])] = out.get(int(to_regime[k]), 0.0) + end - start
    return out


def contact_shares_of(times, to_regime, t0: float, t1: float) -> dict[str, float]:
    """Fraction of [t0, t1] spent in each contact code ("0", "1", ..., "23"), from the event
    times (s) and the regimes they enter."""
    share: dict[str, float] = {}
    for reg, dur in regime_time_of(times, to_regime, t0, t1).items():
        code = str(contact_code(reg))
        share[code] = share.get(code, 0.0) + dur
    total = t1 - t0
    return {c: v / total for c, v in sorted(share.items())} if total > 0 else {}
