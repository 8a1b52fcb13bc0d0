"""Figure helpers shared by the reports (bvc3d.report for the paper's and sweeps' folders,
bvc3d.flight_report for the flying agents'): the metric table's labels, short number and seed texts,
legends outside the axes, bar charts of a metric per model and world (marked when too low to see,
error bars of non-negative quantities stopping at 0), and writing a figure.

A figure of a folder takes its ``folder``: an object with ``models``, ``worlds``, ``tilt`` (world ->
degrees or NaN), ``stat(model, world, metric)`` -> (mean, sd), ``replicated()``, ``non_negative(metric)``,
``spread_text()`` and ``tilt_axis()`` (bvc3d.report.Folder).
"""
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ._core import metric_table  # noqa: E402

DPI = 120
# Metrics with a figure of their own: (axis label, title), from the analysis stage's one table.
METRICS = {m["name"]: (m["label"], m["title"]) for m in metric_table if m["title"]}
DIGITS = {m["name"]: m["digits"] for m in metric_table}
# A bar lower than this fraction of the axis height is hard to see: it gets a mark and its value.
TINY = 0.015


def fmt(v):
    """A number as short text (45, 0.1, 1e-06), anything else as it is."""
    if isinstance(v, bytes):
        v = v.decode()
    if isinstance(v, (int, np.integer)) and not isinstance(v, bool):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return f"{float(v):g}"
    return str(v)


def seed_list(seeds):
    """Seeds as short text: "0", "0, 1, 4", "0–9"."""
    seeds = sorted(seeds)
    if len(seeds) > 2 and seeds == list(range(seeds[0], seeds[-1] + 1)):
        return f"{seeds[0]}–{seeds[-1]}"
    return ", ".join(map(str, seeds))


def legend_outside(ax, title):
    """The legend to the right of the axes, where it cannot cover data."""
    return ax.legend(title=title, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=8,
                     title_fontsize=8, frameon=False)


def error_bars(means, sds, clip):
    """Asymmetric (2, n) error bars: +sd up, -sd down, but not below 0 when the quantity cannot be negative."""
    means, sds = np.asarray(means, float), np.nan_to_num(np.asarray(sds, float))
    sds = np.where(np.isnan(means), 0.0, sds)
    lower = np.minimum(sds, np.maximum(np.nan_to_num(means), 0.0)) if clip else sds
    return np.vstack([lower, sds])


def mark_small_bars(ax, bars, means, tops, digits):
    """Bars too low to see (0, or below TINY of the axis height) get a thick line at their base and their
    value written above them (n/a for a missing value)."""
    lo, hi = ax.get_ylim()
    marks = []
    for bar, mean, top in zip(bars, means, tops):
        if not (math.isnan(mean) or abs(mean) < TINY * (hi - lo)):
            continue
        x0, width = bar.get_x(), bar.get_width()
        ax.plot([x0, x0 + width], [0, 0], color=bar.get_facecolor(), lw=3, solid_capstyle="butt", zorder=3)
        text = "n/a" if math.isnan(mean) else (f"{mean:.{digits}f}" if digits >= 0 else f"{mean:g}")
        marks.append(ax.annotate(text, xy=(x0 + width / 2, 0 if math.isnan(top) else top), xytext=(0, 2),
                                 textcoords="offset points", rotation=90, ha="center", va="bottom", fontsize=6.5))
    return marks


def bars_figure(folder, metric):
    """One bar per model and world (mean ± sd over seeds, or one trial), as a matplotlib Figure."""
    label, title = METRICS[metric]
    fig, ax = plt.subplots(figsize=(7, 3.6))
    n = len(folder.models)
    width = 0.8 / max(n, 1)
    x = np.arange(len(folder.worlds))
    clip = folder.non_negative(metric)
    drawn = []
    for i, m in enumerate(folder.models):
        stats = [folder.stat(m, w, metric) for w in folder.worlds]
        means = np.array([s[0] for s in stats])
        yerr = error_bars(means, [s[1] for s in stats], clip) if folder.replicated() else None
        bars = ax.bar(x + (i - (n - 1) / 2) * width, np.nan_to_num(means), width, yerr=yerr, label=m, capsize=2)
        tops = np.nan_to_num(means) + (yerr[1] if yerr is not None else 0)
        drawn.append((bars, means, np.where(np.isnan(means), np.nan, tops)))
    lo, hi = ax.get_ylim()
    if hi - lo <= 0 or (clip and hi <= 0):
        ax.set_ylim(0, 1)
    elif clip:
        ax.set_ylim(bottom=min(lo, 0.0))
    marks = [m for bars, means, tops in drawn for m in mark_small_bars(ax, bars, means, tops, DIGITS.get(metric, 3))]
    lo, hi = ax.get_ylim()
    if any(m.xy[1] > lo + 0.8 * (hi - lo) for m in marks):  # a value label high up: room for its text
        ax.set_ylim(top=hi + 0.15 * (hi - lo))
    if folder.tilt_axis():
        ax.set_xticks(x, [f"{folder.tilt[w]:g}" for w in folder.worlds])
        ax.set_xlabel("tilt of the central walls (°), cross arena")
    else:
        ax.set_xticks(x, folder.worlds)
        ax.set_xlabel("world")
    ax.set_ylabel(label)
    ax.set_title(f"{title}\n{folder.spread_text()}", fontsize=10)
    legend_outside(ax, "model")
    fig.tight_layout()
    return fig


def save(fig, out):
    """Writes a figure; a failed write names its file (Pillow removes what it wrote and raises an
    OSError without a file name)."""
    try:
        fig.savefig(out, dpi=DPI)
    except OSError as e:
        if e.errno is None or e.filename:
            raise
        raise OSError(e.errno, e.strerror, str(out)) from e
    finally:
        plt.close(fig)
