"""Every figure a report, `workbench frf` and `workbench compare` draw is fit for a paper: no text
overlaps another (matplotlib's tight bounding boxes, as drawn), no axes is empty without a text
saying why, and a log axis has at least two labelled ticks.  Each figure is checked as it is
saved (``figures.save`` wrapped), so the check sees exactly what lands on disk."""
from __future__ import annotations

import itertools

import matplotlib
import matplotlib.ticker
import pytest

from workbench import cli
from workbench.present import figures as F
from workbench.study import definition as S
from workbench.study import sweep as W
from workbench.present.report import make_report

from small_studies import CHIRP, DAMAGE, SMALL

#: Two texts overlap when their boxes share more than this many square pixels (at the saved DPI).
OVERLAP_PX2 = 4.0


def _ticks(axis):
    """(tick label, in view) of an x or y axis: each visible, non-empty label of its major and
    minor ticks, and whether its tick lies within the view (matplotlib keeps some beyond it
    that it does not draw)."""
    lo, hi = sorted(axis.get_view_interval())
    span = (hi - lo) * 1e-9
    for tick in [*axis.get_major_ticks(), *axis.get_minor_ticks()]:
        for label in (tick.label1, tick.label2):
            if label.get_visible() and label.get_text().strip():
                yield label, lo - span <= tick.get_loc() <= hi + span


def _texts(fig):
    """Every visible, non-empty text the figure draws: titles, labels, legends, annotations
    and the tick labels within view."""
    tick_labels, drawn = set(), []
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            for tick in [*axis.get_major_ticks(), *axis.get_minor_ticks()]:
                tick_labels |= {id(tick.label1), id(tick.label2)}
            if ax.get_visible():
                drawn += [label for label, in_view in _ticks(axis) if in_view]
    for artist in fig.findobj(matplotlib.text.Text):
        if id(artist) in tick_labels or not artist.get_visible() or not artist.get_text().strip():
            continue
        if artist.axes is not None and not artist.axes.get_visible():
            continue
        drawn.append(artist)
    return drawn


def problems(fig) -> list[str]:
    """What is wrong with a drawn figure (module docstring); empty when nothing is."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    found = []
    boxes = [(t, t.get_window_extent(renderer)) for t in _texts(fig)]
    for (a, ba), (b, bb) in itertools.combinations(boxes, 2):
        w = min(ba.x1, bb.x1) - max(ba.x0, bb.x0)
        h = min(ba.y1, bb.y1) - max(ba.y0, bb.y0)
        if w > 0 and h > 0 and w * h > OVERLAP_PX2:
            found.append(f"{a.get_text()[:30]!r} overlaps {b.get_text()[:30]!r}")
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        drawn = [*ax.lines, *ax.collections, *ax.images, *ax.patches]
        said = [t for t in ax.texts if t.get_text().strip()]
        if not drawn and not said and ax.get_label() != "<colorbar>":
            found.append(f"an empty axes without a word: {ax.get_title()!r}")
        for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            if axis.get_scale() != "log":
                continue
            ticks = list(_ticks(axis))
            shown = [label for label, in_view in ticks if in_view]
            if ticks and len(shown) < 2:           # no labels at all: a shared axis' inner side
                found.append(f"a log {name} axis with {len(shown)} labelled tick(s): "
                             f"{ax.get_title()!r}")
    return found


@pytest.fixture
def checked(monkeypatch):
    """Wrap figures.save: check each figure before it is written; collect (name, problems)."""
    seen = []
    save = F.save

    def checking_save(fig, path):
        seen.append((path.name, problems(fig)))
        return save(fig, path)

    monkeypatch.setattr(F, "save", checking_save)
    return seen


#: The sweep tests' small grid with a third gap, five frequencies and the tip mass on and off.
GRID = SMALL.replace('name = "small"', 'name = "grid"').replace(
    "gap_mm = [0.508, 1.016]\nfreq_hz = [20.0, 30.0]",
    "gap_mm = [0.508, 0.762, 1.016]\nfreq_hz = [10.0, 20.0, 30.0, 40.0, 50.0]\n"
    "tip_mass = [false, true]")





def _report(tmp_path, text, name):
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    study = S.load(path)
    W.run_study(study, tmp_path / "res", jobs=2, progress=False)
    make_report(study, tmp_path / "res", jobs=1)


def test_the_figures_of_a_grid_a_chirp_and_a_damage_report_are_clean(tmp_path, checked):
    _report(tmp_path, GRID, "grid")
    _report(tmp_path, CHIRP, "chirp")
    _report(tmp_path, DAMAGE.replace("[axes]", "[axes]\ntip_mass = [false, true]"), "damage")
    names = [n for n, _ in checked]
    for expected in ("frf_map_tip", "response_curves", "regime_shares", "bifurcation",
                     "time_history_", "strain_spectra_", "switching_", "spectrogram_", "frf_",
                     "wear_map", "impact_map", "friction_map"):
        assert any(n.startswith(expected) for n in names), (expected, names)
    bad = [(n, p) for n, p in checked if p]
    assert not bad, "\n".join(f"{n}: {p}" for n, p in bad)


def test_the_figures_of_frf_and_compare_are_clean(tmp_path, checked, capsys):
    hit, chirp = tmp_path / "hit.uff", tmp_path / "chirp.tdms"
    assert cli.main(["run", "--impulse", "joint", "--joint", "locked", "--duration", "4",
                     "--out", str(hit), "--json"]) == 0
    assert cli.main(["run", "--gap-mm", "1.016", "--chirp", "5:60:3", "--duration", "3",
                     "--out", str(chirp), "--json"]) == 0
    assert cli.main(["frf", str(hit), "--f-max", "300", "--out", str(tmp_path / "f1")]) == 0
    assert cli.main(["frf", str(chirp), "--f-min", "5", "--f-max", "60",
                     "--out", str(tmp_path / "f2")]) == 0
    assert cli.main(["compare", str(chirp), "--out", str(tmp_path / "cmp")]) == 0
    capsys.readouterr()
    names = [n for n, _ in checked]
    assert names.count("frf") == 3 and names.count("stabilisation") == 2
    assert {"time_history", "spectra", "switching"} <= set(names)
    bad = [(n, p) for n, p in checked if p]
    assert not bad, "\n".join(f"{n}: {p}" for n, p in bad)


def test_the_checker_finds_what_it_is_for():
    """Two texts on top of each other, an empty axes, a log axis with one labelled tick."""
    import matplotlib.pyplot as plt
    fig, (a, b, c) = plt.subplots(1, 3)
    a.plot([0, 1], [0, 1])
    a.text(0.5, 0.5, "one label")
    a.text(0.5, 0.5, "another label")
    c.semilogy([1, 2], [2.0, 9.0])                    # no decade in view, the minors unlabelled
    c.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    found = problems(fig)
    plt.close(fig)
    assert any("overlaps" in p and "label" in p for p in found)
    assert any("empty axes" in p for p in found)
    assert any("log y axis with 0 labelled" in p for p in found)
    clean, ax = plt.subplots()
    ax.semilogy([1.0, 10.0, 100.0])
    ax.set_title("a clean figure")
    assert problems(clean) == []
    plt.close(clean)
