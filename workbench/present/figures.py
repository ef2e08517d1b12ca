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

Points that are not steady (``steady`` False) are marked, failed points are
shown as gaps: nothing is silently mixed in.  Every function returns the
figure; :func:`save` writes it.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.patches  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from scipy import signal as sps  # noqa: E402

from ..study.metrics import CONTACT_CODES, QUANTITIES, psd  # noqa: E402
from ..study.grid import label, panels  # noqa: E402
from ..lab.frf import field_unit  # noqa: E402

CODE_COLORS = dict(zip(CONTACT_CODES, plt.get_cmap("tab10").colors))
SERIES_CHANNELS = (("force1", "force1 (dyn)"), ("strain1", "strain1 (-)"),
                   ("strain2", "strain2 (-)"), ("accel1", "accel1 (cm/s²)"),
                   ("accel3", "accel3 (cm/s²)"), ("tip", "tip displacement (cm)"))


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
    values = _ok(table)[quantity].to_numpy()
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
                r[quantity]
        im = ax.imshow(grid, origin="lower", aspect="auto", cmap="viridis", norm=norm,
                       extent=(-0.5, len(freqs) - 0.5, -0.5, len(gaps) - 0.5))
        for _, r in _ok(part).iterrows():
            ax.text(np.searchsorted(freqs, r.axis_freq_hz), np.searchsorted(gaps, r.axis_gap_mm),
                    f"{r[quantity]:.2g}" + ("" if r.steady else "*")
                    + ("!" if r.get("out_of_range", "") else ""), ha="center", va="center",
                    fontsize=6, color="w")
        ax.set_xticks(range(len(freqs)), [f"{f:g}" for f in freqs], fontsize=7)
        ax.set_yticks(range(len(gaps)), [f"{g:g}" for g in gaps])
        ax.set_title(title, fontsize=9)
        ax.set_xlabel(label("freq_hz"))
        ax.set_ylabel(label("gap_mm"))
    fig.colorbar(im, ax=axes, label=f"{QUANTITIES[quantity]}; *: not steady, "
                 "!: outside the validated range, blank: failed")
    return fig


def response_curves(table: pd.DataFrame, quantity: str = "tip_rms"):
    """``quantity`` against drive frequency, a line per gap; hollow markers: not steady."""
    parts = panels(table, ("gap_mm", "freq_hz"))
    fig, axes = _grid(len(parts), sharey=True)
    for ax, (title, part) in zip(axes, parts):
        ax.set_yscale("log")
        for i, (gap, g) in enumerate(_ok(part).groupby("axis_gap_mm")):
            g = g.sort_values("axis_freq_hz")
            color = f"C{i}"
            ax.plot(g.axis_freq_hz, g[quantity], "-", color=color, label=f"{gap:g} mm")
            steady = g.steady.astype(bool)
            ax.plot(g.axis_freq_hz[steady], g[quantity][steady], "o", color=color, ms=4)
            ax.plot(g.axis_freq_hz[~steady], g[quantity][~steady], "o", mfc="none",
                    color=color, ms=6)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel(label("freq_hz"))
        ax.set_ylabel(QUANTITIES[quantity])
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
    handles = [matplotlib.patches.Patch(color=CODE_COLORS[c], label=str(c))
               for c in CONTACT_CODES if c in shown]
    axes[-1].legend(handles=handles, title="contact", fontsize=7, title_fontsize=7,
                    bbox_to_anchor=(1.02, 1), loc="upper left")
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
            y = np.concatenate([np.asarray(s, float) for s in g.tip_poincare])
            ax.plot(f, y, marker, color=color, ms=3, alpha=0.6, ls="none",
                    label=f"{name} sweep" if name else None)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel(label("freq_hz"))
        ax.set_ylabel("tip at phase 0 (cm)")
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
                             sharex=True)
    t = s.index.to_numpy()
    for ax, (ch, name) in zip(axes, SERIES_CHANNELS):
        y = s.tip_y - static_tip_y if ch == "tip" else s[ch]
        ax.plot(t, y, lw=0.8)
        ax.set_ylabel(name, fontsize=8)
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
        f, p = psd(t, s[ch].to_numpy())
        keep = f <= fmax
        ax.semilogy(f[keep], p[keep], lw=0.9, label=ch)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("strain PSD (1/Hz)")
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
    f, tt, sxx = sps.spectrogram(signals[channel].to_numpy(), fs=fs, nperseg=n,
                                 noverlap=n // 2, detrend="constant")
    keep = f <= fmax
    fig, ax = plt.subplots(figsize=(8, 4))
    db = 10 * np.log10(sxx[keep] + 1e-300)
    # rasterized: the PDF holds the mesh as one image, not a path per cell
    im = ax.pcolormesh((t[0] + tt) / 60.0, f[keep], db, shading="auto", cmap="jet",
                       vmin=db.max() - 80, vmax=db.max(), rasterized=True)
    fig.colorbar(im, ax=ax, label=f"{channel} PSD (dB re 1/Hz)")
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
            ax.plot(s.index.to_numpy(), s[ch].to_numpy(), lw=0.8, label=name)
        ax.set_ylabel(ch, fontsize=8)
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
            f, p = psd(rec.index.to_numpy(), rec[ch].to_numpy())
            keep = f <= fmax
            ax.semilogy(f[keep], p[keep], lw=0.8, label=name)
        ax.set_title(ch, fontsize=9)
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


def frf_figure(tables, responses, title: str, f_max: float | None = None):
    """|H|, the phase of H1 and the coherence of each response (one column each).

    ``tables``: one FRF table (:func:`workbench.lab.frf.frf`), drawn as H1 and
    H2; or {source: table} (simulation over experiment), drawn as each source's H1."""
    sources = {"": tables} if isinstance(tables, pd.DataFrame) else dict(tables)
    single = len(sources) == 1
    fig, axes = plt.subplots(3, len(responses), figsize=(4.2 * len(responses), 7.5), sharex=True,
                             squeeze=False, gridspec_kw={"height_ratios": [2, 1, 1]})
    for j, r in enumerate(responses):
        for source, table in sources.items():
            f = table.index.to_numpy()
            band = (f > 0) & (f <= (f_max if f_max is not None else f[-1]))
            unit, scale = field_unit(r)
            h1 = table[f"{r}_H1"].to_numpy()[band]
            name = f"{source} H1".strip()
            axes[0, j].semilogy(f[band], np.abs(h1) * scale, label=name, lw=0.9)
            if single:
                axes[0, j].semilogy(f[band], np.abs(table[f"{r}_H2"].to_numpy()[band]) * scale,
                                    label="H2", alpha=0.7, lw=0.9)
            axes[1, j].plot(f[band], np.degrees(np.angle(h1)), lw=0.8, label=name)
            axes[2, j].plot(f[band], table[f"{r}_coherence"].to_numpy()[band], lw=0.8,
                            label=source or None)
        axes[0, j].set_title(r, fontsize=9)
        axes[0, j].set_ylabel(f"|H| ({field_unit(r)[0]})")
        axes[0, j].legend(fontsize=8)
        axes[0, j].grid(alpha=0.3, which="both")
        axes[2, j].set_ylim(0, 1.05)
        axes[2, j].set_xlabel("frequency (Hz)")
    axes[1, 0].set_ylabel("phase H1 (deg)")
    axes[2, 0].set_ylabel("coherence")
    fig.suptitle(title, fontsize=10)
    return fig
