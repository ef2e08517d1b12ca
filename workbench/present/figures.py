"""Figures of a study, in the style of the paper's §6, as PNG and PDF.

From the points table (one row per grid point, :mod:`workbench.study.sweep`):

- :func:`frf_maps`            tip RMS over gap x frequency, a panel per other axis value
- :func:`response_curves`     tip RMS against frequency, a line per gap
- :func:`regime_shares`       contact-code time shares by frequency (stacked bars)
- :func:`bifurcation`         tip once per forcing period against frequency,
                              up and down sweeps overlaid

From the saved time series of single points:

- :func:`time_history`        force, strains, accelerations, tip (Fig. 6)
- :func:`strain_spectra`      power spectra of both strains (Fig. 7-8)
- :func:`switching_diagram`   the contact code against time (Fig. 9)
- :func:`spectrogram`         short-time spectrum of a strain (Fig. 11-12)

From FRF tables (:mod:`workbench.lab.frf`, :mod:`workbench.lab.modal`):

- :func:`frf_figure`          |H|, phase and coherence of each response
- :func:`stabilisation_chart` the poles of a modal fit by model order

Points that are not steady (``steady`` False) are marked, failed points are
shown as gaps: nothing is silently mixed in.  Every function returns the
figure; :func:`save` writes it.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.patches  # noqa: E402
import matplotlib.ticker  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from scipy import signal as sps  # noqa: E402

from ..study.metrics import CONTACT_CODES, psd  # noqa: E402
from ..model.regimes import code_words  # noqa: E402
from . import units  # noqa: E402
from ..study.grid import label, panels  # noqa: E402
from ..lab.frf import field_unit  # noqa: E402

CODE_COLORS = dict(zip(CONTACT_CODES, plt.get_cmap("tab10").colors))
#: The channels of a time history (paper Fig. 6), shown in SI (:mod:`workbench.present.units`).
SERIES_CHANNELS = ("force1", "strain1", "strain2", "accel1", "accel3", "tip")


#: Resolution of the PNG files (dots per inch).
DPI = 120


def save(fig, path: Path) -> list[Path]:
    """Write ``fig`` as ``path``.png and ``path``.pdf; return both paths.  The suffixes are
    appended: a name may hold dots ("spectrogram_gap-1.016mm").

    Both files are cropped to the figure's drawn extent plus savefig.pad_inches
    (matplotlib's ``bbox_inches="tight"``).  The layout and the extent are
    computed once, at the PNG's resolution, and kept for both files: saving
    each with "tight" lays the figure out and measures it again per file.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    out = [path.with_name(path.name + ".png"), path.with_name(path.name + ".pdf")]
    fig.set_dpi(DPI)
    fig.draw_without_rendering()                  # runs the layout engine, if any
    fig.set_layout_engine("none")                 # ... and keeps its result
    extent = fig.get_tightbbox(fig.canvas.get_renderer()).padded(
        matplotlib.rcParams["savefig.pad_inches"])
    for p in out:
        fig.savefig(p, dpi=DPI, bbox_inches=extent)
    plt.close(fig)
    return out


def _grid(n: int, width=4.2, height=3.2, **kw):
    cols = min(n, 3)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, height * rows), squeeze=False,
                             layout="constrained", **kw)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, list(axes.flat[:n])


def _ok(table):
    return table[table.status == "ok"]


def frf_maps(table: pd.DataFrame, quantity: str = "tip_rms"):
    """Colour map of ``quantity`` over gap x drive frequency; '*' marks points not steady,
    '!' points outside the validated range (``metrics.validity``)."""
    parts = panels(table, ("gap_mm", "freq_hz"))
    fig, axes = _grid(len(parts), sharex=True, sharey=True)
    factor = units.quantity(quantity)[2]
    values = _ok(table)[quantity].to_numpy() * factor
    values = values[values > 0]
    vmax = values.max() if len(values) else 1.0
    norm = matplotlib.colors.LogNorm(vmin=max(values.min(), vmax * 1e-3) if len(values) else 1e-3,
                                     vmax=vmax)
    gaps = np.sort(table.axis_gap_mm.unique())
    freqs = np.sort(table.axis_freq_hz.unique())
    for ax, (title, part) in zip(axes, parts):
        grid = np.full((len(gaps), len(freqs)), np.nan)
        for _, r in _ok(part).iterrows():
            grid[np.searchsorted(gaps, r.axis_gap_mm), np.searchsorted(freqs, r.axis_freq_hz)] = \
                r[quantity] * factor
        im = ax.imshow(grid, origin="lower", aspect="auto", cmap="viridis", norm=norm,
                       extent=(-0.5, len(freqs) - 0.5, -0.5, len(gaps) - 0.5))
        for _, r in _ok(part).iterrows():
            ax.text(np.searchsorted(freqs, r.axis_freq_hz), np.searchsorted(gaps, r.axis_gap_mm),
                    f"{r[quantity] * factor:.2g}" + ("" if r.steady else "*")
                    + ("!" if r.get("out_of_range", "") else ""), ha="center", va="center",
                    fontsize=8 if len(freqs) <= 10 else 7,
                    color="k" if norm(r[quantity] * factor) > 0.6 else "w")   # on viridis' light end
        ax.set_xticks(range(len(freqs)), [f"{f:g}" for f in freqs], fontsize=7)
        ax.set_yticks(range(len(gaps)), [f"{g:g}" for g in gaps])
        ax.set_title(title, fontsize=9)
        ax.set_xlabel(label("freq_hz"))
        ax.set_ylabel(label("gap_mm"))
    fig.colorbar(im, ax=axes, label=units.quantity_label(quantity))
    fig.supxlabel("cell: the value; *: not steady, !: outside the validated range, "
                  "blank: failed", fontsize=8)
    return fig


def response_curves(table: pd.DataFrame, quantity: str = "tip_rms"):
    """``quantity`` against drive frequency, a line per gap; hollow markers: not steady."""
    parts = panels(table, ("gap_mm", "freq_hz"))
    fig, axes = _grid(len(parts), sharey=True)
    factor = units.quantity(quantity)[2]
    for ax, (title, part) in zip(axes, parts):
        ax.set_yscale("log")
        for i, (gap, g) in enumerate(_ok(part).groupby("axis_gap_mm")):
            g = g.sort_values("axis_freq_hz")
            color = f"C{i}"
            y = g[quantity] * factor
            ax.plot(g.axis_freq_hz, y, "-", color=color, label=f"{gap:g} mm")
            steady = g.steady.astype(bool)
            ax.plot(g.axis_freq_hz[steady], y[steady], "o", color=color, ms=4)
            ax.plot(g.axis_freq_hz[~steady], y[~steady], "o", mfc="none", color=color, ms=6)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel(label("freq_hz"))
        ax.set_ylabel(units.quantity_label(quantity))
        ax.grid(alpha=0.3)
    axes[0].legend(title="gap (hollow: not steady)", fontsize=7, title_fontsize=7)
    return fig


def regime_shares(table: pd.DataFrame):
    """Stacked bars of the contact-code time shares per drive frequency, a panel per rest."""
    parts = panels(table, ("freq_hz",))
    fig, axes = _grid(len(parts), sharey=True)
    shown = set()
    for ax, (title, part) in zip(axes, parts):
        part = _ok(part).sort_values("axis_freq_hz")
        x = np.arange(len(part))
        bottom = np.zeros(len(part))
        for code in CONTACT_CODES:
            share = part[f"share_{code}"].to_numpy()
            if not np.any(share > 0):        # no bars of zero height to draw
                continue
            ax.bar(x, share, bottom=bottom, color=CODE_COLORS[code], width=0.8)
            bottom += share
            shown.add(code)
        ax.set_xticks(x, [f"{f:g}{'' if s else '*'}" for f, s in
                          zip(part.axis_freq_hz, part.steady.astype(bool))], fontsize=7)
        ax.set_ylim(0, 1)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel(label("freq_hz") + " (*: not steady)")
        ax.set_ylabel("time share")
    handles = [matplotlib.patches.Patch(color=CODE_COLORS[c], label=code_words(c))
               for c in CONTACT_CODES if c in shown]
    fig.legend(handles=handles, title="contact code (the points touching)", fontsize=7,
               title_fontsize=7, loc="outside right upper")
    return fig


def bifurcation(table: pd.DataFrame):
    """Tip displacement once per forcing period against frequency (up and down overlaid)."""
    parts = panels(table, ("freq_hz",))
    fig, axes = _grid(len(parts))
    styles = {"up": ("C0", "^", "up"), "down": ("C3", "v", "down"), "": ("k", ".", "")}
    for ax, (title, part) in zip(axes, parts):
        for direction, g in _ok(part).groupby("direction"):
            color, marker, name = styles.get(direction, styles[""])
            f = np.concatenate([np.full(len(s), fr) for fr, s in zip(g.axis_freq_hz,
                                                                      g.tip_poincare)])
            y = np.concatenate([np.asarray(s, float) for s in g.tip_poincare]) * \
                units.channel("tip")[1]
            ax.plot(f, y, marker, color=color, ms=3, alpha=0.6, ls="none",
                    label=f"{name} sweep" if name else None)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel(label("freq_hz"))
        ax.set_ylabel(f"tip at phase 0 ({units.channel('tip')[0]})")
        ax.grid(alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    return fig


def _window(signals: pd.DataFrame, seconds: float | None):
    if seconds is None:
        return signals
    t = signals.index.to_numpy()
    return signals[t >= t[-1] - seconds]


def time_history(signals: pd.DataFrame, static_tip_y: float, title: str, seconds: float = 0.5):
    """The last ``seconds`` of the sensor channels and the tip (paper Fig. 6)."""
    s = _window(signals, seconds)
    fig, axes = plt.subplots(len(SERIES_CHANNELS), 1, figsize=(8, 1.6 * len(SERIES_CHANNELS)),
                             sharex=True, layout="constrained")
    t = s.index.to_numpy()
    for ax, ch in zip(axes, SERIES_CHANNELS):
        y = s.tip_y - static_tip_y if ch == "tip" else s[ch]
        ax.plot(t, y * units.channel(ch)[1], lw=0.8)
        ax.set_ylabel(units.channel_label(ch), fontsize=8)
        ax.grid(alpha=0.3)
    axes[0].set_title(title, fontsize=9)
    axes[-1].set_xlabel("time (s)")
    return fig


def strain_spectra(signals: pd.DataFrame, title: str, seconds: float | None = None,
                   fmax: float = 250.0):
    """Power spectral density of strain1 and strain2 (Welch, 1 s segments; Fig. 7-8)."""
    s = _window(signals, seconds)
    t = s.index.to_numpy()
    fig, ax = plt.subplots(figsize=(8, 3.5))
    for ch in ("strain1", "strain2"):
        f, p = psd(t, s[ch].to_numpy() * units.channel(ch)[1])
        keep = f <= fmax
        ax.semilogy(f[keep], p[keep], lw=0.9, label=ch)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel(f"strain PSD ({units.channel('strain1')[0]}²/Hz)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    return fig


def switching_diagram(events: pd.DataFrame, t_end: float, title: str, seconds: float = 0.5):
    """The contact code against time over the last ``seconds`` (paper Fig. 9)."""
    from ..model.regimes import contact_code

    t0 = t_end - seconds
    t = events.t.to_numpy()
    codes = np.asarray(contact_code(events.to_regime.to_numpy(dtype=int)))
    start = max(np.searchsorted(t, t0, side="right") - 1, 0)     # the regime in force at t0
    tt = np.concatenate([[t0], t[start + 1:], [t_end]])
    cc = np.concatenate([codes[start:], codes[-1:]])
    level = {c: i for i, c in enumerate(CONTACT_CODES)}
    fig, ax = plt.subplots(figsize=(8, 3))
    ax.step(tt, [level[int(c)] for c in cc], where="post", lw=0.9)
    ax.set_yticks(range(len(CONTACT_CODES)), [str(c) for c in CONTACT_CODES])
    ax.set_ylabel("points in contact")
    ax.set_xlabel("time (s)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    return fig


def spectrogram(signals: pd.DataFrame, title: str, channel: str = "strain1",
                fmax: float = 200.0, segment_s: float = 2.0):
    """Short-time power spectrum of ``channel`` against time in minutes (Fig. 11-12)."""
    t = signals.index.to_numpy()
    fs = 1.0 / np.median(np.diff(t))
    n = min(int(round(segment_s * fs)), len(t) // 4)
    unit, factor = units.channel(channel)
    f, tt, sxx = sps.spectrogram(signals[channel].to_numpy() * factor, fs=fs, nperseg=n,
                                 noverlap=n // 2, detrend="constant")
    keep = f <= fmax
    fig, ax = plt.subplots(figsize=(8, 4))
    db = 10 * np.log10(sxx[keep] + 1e-300)
    # rasterized: the PDF holds the mesh as one image, not a path per cell
    im = ax.pcolormesh((t[0] + tt) / 60.0, f[keep], db, shading="auto", cmap="jet",
                       vmin=db.max() - 80, vmax=db.max(), rasterized=True)
    fig.colorbar(im, ax=ax, label=f"{channel} PSD (dB re 1 {unit}²/Hz)")
    ax.set_xlabel("time (min)")
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(title, fontsize=9)
    return fig


# --- comparison of a simulation with a record (``workbench compare``, seed §6) ---------
def overlay_time_history(records: dict[str, pd.DataFrame], channels, title: str,
                         seconds: float = 0.5):
    """The last ``seconds`` of each channel, one line per source (paper Fig. 6)."""
    fig, axes = plt.subplots(len(channels), 1, figsize=(8, 1.7 * len(channels)), sharex=True,
                             squeeze=False)
    for ax, ch in zip(axes[:, 0], channels):
        for name, rec in records.items():
            s = _window(rec, seconds)
            ax.plot(s.index.to_numpy(), s[ch].to_numpy() * units.channel(ch)[1], lw=0.8,
                    label=name)
        ax.set_ylabel(units.channel_label(ch), fontsize=8)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=7, loc="upper right")
    axes[0, 0].set_title(title, fontsize=9)
    axes[-1, 0].set_xlabel("time (s)")
    return fig


def overlay_spectra(records: dict[str, pd.DataFrame], channels, title: str, fmax: float = 250.0):
    """Power spectra of each channel, one line per source (paper Fig. 7-8)."""
    fig, axes = _grid(len(channels), width=4.6, height=3.0)
    for ax, ch in zip(axes, channels):
        for name, rec in records.items():
            f, p = psd(rec.index.to_numpy(), rec[ch].to_numpy() * units.channel(ch)[1])
            keep = f <= fmax
            ax.semilogy(f[keep], p[keep], lw=0.8, label=name)
        unit = units.channel(ch)[0]
        ax.set_title(f"{ch}: PSD ({unit}²/Hz)" if unit else f"{ch}: PSD", fontsize=9)
        ax.set_xlabel("frequency (Hz)")
        ax.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=7)
    fig.suptitle(title, fontsize=9)
    return fig


def code_series_diagrams(codes: dict[str, pd.Series], title: str, seconds: float = 0.5):
    """Contact code against time, one panel per source (paper Fig. 9-10)."""
    level = {c: i for i, c in enumerate(CONTACT_CODES)}
    fig, axes = plt.subplots(len(codes), 1, figsize=(8, 2.4 * len(codes)), sharex=True,
                             squeeze=False)
    for ax, (name, series) in zip(axes[:, 0], codes.items()):
        t = series.index.to_numpy()
        keep = t >= t[-1] - seconds
        ax.step(t[keep], [level.get(int(c), 0) for c in series.to_numpy()[keep]], where="post",
                lw=0.9)
        ax.set_yticks(range(len(CONTACT_CODES)), [str(c) for c in CONTACT_CODES])
        ax.set_ylabel(f"{name}\npoints in contact", fontsize=8)
        ax.grid(alpha=0.3)
    axes[0, 0].set_title(title, fontsize=9)
    axes[-1, 0].set_xlabel("time (s)")
    return fig


def frf_axis(ax, f_lo: float, f_hi: float) -> None:
    """A frequency axis (Hz) over [f_lo, f_hi]: logarithmic when the band spans more than a
    decade (modes from 2 Hz to 160 Hz stay apart), labelled in plain numbers at 1, 2 and 5
    per decade (1 alone over more than three decades), the minor ticks unlabelled."""
    if f_hi > 10.0 * max(f_lo, 1e-300):
        ax.set_xscale("log")
        subs = (1.0, 2.0, 5.0) if f_hi <= 1e3 * f_lo else (1.0,)
        ax.xaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=subs))
        ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlim(f_lo, f_hi)


def frf_figure(tables, responses, title: str, f_max: float | None = None,
               modes: pd.DataFrame | None = None, f_min: float = 0.0):
    """|H1| (and H2 for one table), the phase of H1 and, where it is defined, the coherence of
    each response (one column each), in the field's units, on :func:`frf_axis`.

    ``tables``: one FRF table (:func:`workbench.lab.frf.frf`); or {source: table}
    (simulation over experiment), drawn as each source's H1, over (f_min, f_max] (Hz; default
    the tables' band).  ``modes`` (a table with
    ``f_hz``, :mod:`workbench.lab.modal`) are marked by vertical lines.  The coherence row is
    left out when no table has one: one hit (impact window) or one record-long segment (a
    single average is coherent by definition); the title says which."""
    sources = {"": tables} if isinstance(tables, pd.DataFrame) else dict(tables)
    single = len(sources) == 1
    averaged = [t for t in sources.values()
                if t.attrs.get("window") != "impact" and t.attrs.get("averages", 1) > 1]
    rows = 3 if averaged else 2
    fig, axes = plt.subplots(rows, len(responses), figsize=(4.4 * len(responses), 2.6 * rows + 1),
                             sharex=True, squeeze=False, layout="constrained",
                             gridspec_kw={"height_ratios": [2, 1, 1][:rows]})
    f_lo, f_hi = np.inf, 0.0
    for j, r in enumerate(responses):
        unit, scale = field_unit(r)
        for source, table in sources.items():
            f = table.index.to_numpy()
            band = (f > 0) & (f >= f_min) & (f <= (f_max if f_max is not None else f[-1]))
            f_lo, f_hi = min(f_lo, f[band][0]), max(f_hi, f[band][-1])
            h1 = table[f"{r}_H1"].to_numpy()[band]
            name = f"{source} H1".strip()
            axes[0, j].plot(f[band], np.abs(h1) * scale, label=name, lw=0.9)
            if single and table.attrs.get("window") != "impact":
                axes[0, j].plot(f[band], np.abs(table[f"{r}_H2"].to_numpy()[band]) * scale,
                                label="H2", alpha=0.7, lw=0.9)
            axes[1, j].plot(f[band], np.degrees(np.angle(h1)), lw=0.8)
            if rows == 3:
                axes[2, j].plot(f[band], table[f"{r}_coherence"].to_numpy()[band], lw=0.8,
                                label=source or None)
        axes[0, j].set_yscale("log")
        axes[0, j].set_title(f"{r}: |H| ({unit})", fontsize=9)
        axes[0, j].grid(alpha=0.3, which="both")
        axes[1, j].set_ylim(-180, 180)
        axes[1, j].set_yticks([-180, -90, 0, 90, 180])
        if rows == 3:
            axes[2, j].set_ylim(0, 1.05)
        axes[-1, j].set_xlabel("frequency (Hz)")
        if modes is not None:
            for fn in modes.f_hz:
                for ax in axes[:, j]:
                    ax.axvline(fn, color="0.5", lw=0.6, ls=":")
    for ax in axes.flat:
        frf_axis(ax, f_lo, f_hi)
    axes[0, 0].legend(fontsize=8)
    axes[0, 0].set_ylabel("|H|")
    axes[1, 0].set_ylabel("phase H1 (deg)")
    if rows == 3:
        axes[2, 0].set_ylabel("coherence")
    why = "" if rows == 3 else (" (no coherence: one hit)" if any(
        t.attrs.get("window") == "impact" for t in sources.values())
        else " (no coherence: one segment, coherent by definition)")
    fig.suptitle(title + why, fontsize=10)
    return fig


def stabilisation_chart(stabilisation: pd.DataFrame, table: pd.DataFrame, modes: pd.DataFrame,
                        title: str):
    """The stabilisation chart of a modal fit (:mod:`workbench.lab.modal`): each pole's model
    order against its frequency (Hz), stable poles (frequency and damping) as crosses, the
    others as dots, the identified modes as vertical lines labelled with f and zeta, over
    the sum of the responses' normalised |H1| (right axis)."""
    a = stabilisation.attrs
    fig, ax = plt.subplots(figsize=(8.0, 4.6), layout="constrained")
    other = stabilisation[~stabilisation.stable]
    stable = stabilisation[stabilisation.stable]
    ax.plot(other.f_hz, other.order, ".", color="0.7", ms=3, label="pole")
    ax.plot(stable.f_hz, stable.order, "x", color="tab:blue", ms=4, label="stable in f and ζ")
    for m in modes.itertuples():
        ax.axvline(m.f_hz, color="tab:red", lw=0.8)
        zeta = f"ζ {m.zeta:.3g}" if m.zeta_resolved else "ζ: record too short"
        ax.annotate(f"{m.f_hz:.4g} Hz\n{zeta}", (m.f_hz, 1.0), xycoords=("data", "axes fraction"),
                    xytext=(2, -2), textcoords="offset points", va="top", fontsize=7,
                    color="tab:red", rotation=90)
    f = table.index.to_numpy()
    band = (f >= max(a["band_lo_hz"], f[1])) & (f <= a["band_hi_hz"] * (1 + 1e-12))
    level = sum(np.abs(table[f"{r}_H1"].to_numpy()[band])
                / max(np.abs(table[f"{r}_H1"].to_numpy()[band]).max(), 1e-300)
                for r in a["responses"])
    twin = ax.twinx()
    twin.plot(f[band], level, color="k", lw=0.7, alpha=0.6)
    twin.set_yscale("log")
    twin.set_ylabel("Σ |H1| / max |H1| (responses)")
    ax.set_ylabel("model order")
    ax.set_xlabel("frequency (Hz)")
    frf_axis(ax, f[band][0], f[band][-1])
    ax.set_ylim(0, stabilisation.order.max() + 2)
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title(title, fontsize=10)
    return fig
