"""Figures and report.md for a folder of bvc3d trial files.

    PYTHONPATH=build/python /usr/bin/python3 -m bvc3d.report DIR

DIR holds the trial files (*.h5) and the tables `bvc3d paper` writes (trials.csv, summary.csv,
summary.md). Figures are PNG files in DIR/figures; DIR/report.md states how the trials were run and
analyzed (read from the trial files) and shows the table and every figure.

Every figure says what it shows: the worlds, the models, the seeds (one trial, or the mean ± sd over
seeds), with axis labels and units. Legends sit outside the axes, bars too small to see are marked
and labeled with their value, and error bars of quantities that cannot be negative stop at 0.
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

try:
    import h5py
except ImportError:  # pragma: no cover - Debian's python3-h5py is a dependency
    h5py = None

from ._core import metric_table
from .figures import (DIGITS, DPI, METRICS, TINY, bars_figure, error_bars, fmt,  # noqa: F401 (the report's names)
                      legend_outside, mark_small_bars, save, seed_list)

METRIC_NAMES = {m["name"] for m in metric_table}
# Units of the analysis parameters a trial file's /metrics attributes record (the others have none).
UNITS = {"eps": "m", "d_th": "m"}


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def num(s):
    try:
        return float(s)
    except (TypeError, ValueError):
        return math.nan


def protocol_text(attrs):
    """What a trial's protocol did, from its file's attributes."""
    kind = fmt(attrs.get("protocol", "unknown protocol"))
    explore, sample = fmt(attrs.get("explore_hours", "?")), fmt(attrs.get("sample_hours", "?"))
    if kind == "online":
        return f"online: one {sample} h phase, recorded while learning"
    if kind == "explore_then_sample":
        return (f"explore_then_sample: {explore} h of exploration with learning on (not recorded), then {sample} h "
                f"of sampling with learning frozen (recorded)")
    return f"{kind}: explore_hours {explore}, sample_hours {sample}"


def analysis_text(metrics_group):
    """How a trial's metrics were computed: the /metrics attributes that are not metrics, and the grid."""
    parts = [f"{k} {fmt(v)}" + (f" {UNITS[k]}" if k in UNITS else "")
             for k, v in metrics_group.attrs.items() if k not in METRIC_NAMES]
    if "extent" in metrics_group:
        x0, x1, y0, y1 = metrics_group["extent"][:]
        parts.append(f"grid over x {x0:g} to {x1:g} m, y {y0:g} to {y1:g} m")
    else:
        parts.append("grid over each trial's trajectory")
    return ", ".join(parts)


class Folder:
    """The trials of one experiment folder, grouped by model and world."""

    def __init__(self, path):
        self.path = path
        for name in ("trials.csv", "summary.csv"):
            if not os.path.exists(os.path.join(path, name)):
                raise SystemExit(f"bvc3d.report: {path} has no {name}; run `bvc3d paper` "
                                 f"(or `bvc3d summarize {path}`) first")
        self.trials = read_csv(os.path.join(path, "trials.csv"))
        self.summary = read_csv(os.path.join(path, "summary.csv"))
        self.models = list(dict.fromkeys(r["model"] for r in self.summary))
        worlds = list(dict.fromkeys(r["world"] for r in self.summary))
        self.conditions = list(dict.fromkeys(r["condition"] for r in self.summary))
        tilt = {r["world"]: num(r["tilt_deg"]) for r in self.summary}
        self.worlds = sorted(worlds, key=lambda w: (math.isnan(tilt[w]), tilt[w], w))
        self.tilt = tilt
        self.seeds = sorted({int(r["seed"]) for r in self.trials})
        counts = [int(num(r.get("n_seeds"))) if not math.isnan(num(r.get("n_seeds"))) else 1 for r in self.summary]
        self.seeds_per_condition = sorted(set(counts)) or [1]

    def file(self, model, world, seed=None):
        seed = self.seeds[0] if seed is None else seed
        for r in self.trials:
            if r["model"] == model and r["world"] == world and int(r["seed"]) == seed:
                return os.path.join(self.path, r["name"] + ".h5")
        return None

    def stat(self, model, world, metric):
        for r in self.summary:
            if r["model"] == model and r["world"] == world:
                return num(r.get(metric + "_mean")), num(r.get(metric + "_sd"))
        return math.nan, math.nan

    def replicated(self):
        """Some condition has more than one seed: values are means, with a spread."""
        return max(self.seeds_per_condition) > 1

    def non_negative(self, metric):
        """Every trial's value of the metric is >= 0 (then so is any mean, and error bars stop at 0)."""
        values = [num(r.get(metric)) for r in self.trials]
        return all(v >= 0 for v in values if not math.isnan(v))

    def spread_text(self):
        """What one bar or point is: a trial, or a mean ± sd over seeds."""
        seeds = seed_list(self.seeds)
        if not self.replicated():
            return f"one trial each (seed {seeds})" if len(self.seeds) == 1 else f"one trial each (seeds {seeds})"
        n = self.seeds_per_condition
        count = f"{n[0]}" if len(n) == 1 else f"{n[0]}–{n[-1]}"
        return f"mean ± sd over {count} seeds ({seeds}); error bars stop at 0"

    def tilt_axis(self):
        """All worlds are cross arenas told apart by their tilt (the x axis is then the tilt)."""
        tilts = [self.tilt[w] for w in self.worlds]
        return all(not math.isnan(t) for t in tilts) and len(set(tilts)) == len(tilts)

    def world_label(self, w):
        t = self.tilt.get(w, math.nan)
        return f"{t:g}°" if not math.isnan(t) else w

    def settings(self):
        """Per trial (in trials.csv order): (protocol text, analysis text, seed), read from the files."""
        out = []
        for r in self.trials:
            path = os.path.join(self.path, r["name"] + ".h5")
            try:
                with h5py.File(path, "r") as f:
                    out.append((protocol_text(f.attrs), analysis_text(f["metrics"]),
                                int(f.attrs.get("seed", r["seed"]))))
            except (OSError, KeyError) as e:
                out.append((f"unreadable ({os.path.basename(path)}: {e})", "unreadable", int(r["seed"])))
        return out


def hexmap(ax, centers, values, extent=None, cmap="viridis", vmin=None, vmax=None):
    """Draw per-bin values at their hexagon centers: each center falls in its own bin."""
    cx, cy = centers[:, 0], centers[:, 1]
    if extent is None:
        extent = (cx.min(), cx.max(), cy.min(), cy.max())
    return ax.hexbin(cx, cy, C=values, gridsize=50, extent=extent, cmap=cmap, vmin=vmin, vmax=vmax,
                     reduce_C_function=np.mean, linewidths=0.0)


# The paper report's bar figures come from the metric table (bar_metrics). Their files keep the
# names they had before; a metric added to the table gets <name>.png. A note adds to a figure's
# sentence what its title does not say.
BAR_FILES = {"frac_active": "mi_active.png", "mean_mi_active": "mi_mean.png", "frac_multimodal": "mi_multimodal.png",
             "decode_median_m": "decoding.png", "frac_undecoded": "decoding_coverage.png"}
BAR_NOTES = {
    "mean_mi_active": "fields per cell; 1 is a single place field",
    "frac_multimodal": "cells that fire in several places",
    "msai": "lower is better",
    "decode_median_m": "each sample of the second half decoded to the cosine-nearest rate-map bin of the first "
                       "half, the direct measure of localization",
    "frac_undecoded": "samples with no positive similarity to any template, which the decoding errors leave out",
    "decode_median_all_m": "the undecoded samples counted at chance",
}


def bar_metrics(dims=2):
    """The metrics drawn as bars: those of the metric table with a figure of their own (a title) that
    trials of ``dims``-coordinate positions report, in the table's order."""
    return [m["name"] for m in metric_table if m["title"] and m["dims"] in (0, dims)]


def bar_file(metric):
    return BAR_FILES.get(metric, f"{metric}.png")


def bar_sentence(folder, metric):
    """What a bar figure shows, for report.md: its title, the axes, the note, what a bar is."""
    per = "per model and tilt" if folder.tilt_axis() else "per model and world"
    note = f": {BAR_NOTES[metric]}" if metric in BAR_NOTES else ""
    return f"{METRICS[metric][1]}, {per}{note}. Bars: {folder.spread_text()}."


def fig_bars(folder, metric, out):
    save(bars_figure(folder, metric), out)


def sai_grid_figure(folder):
    """The SAI of every bin, one trial per panel (the first seed): rows models, columns worlds."""
    seed = folder.seeds[0]
    nr, nc = len(folder.models), len(folder.worlds)
    fig, axes = plt.subplots(nr, nc, figsize=(2.6 * nc + 0.8, 2.5 * nr), squeeze=False, sharex=True, sharey=True)
    vmax = 0
    data = {}
    for m in folder.models:
        for w in folder.worlds:
            path = folder.file(m, w, seed)
            if path and os.path.exists(path):
                with h5py.File(path, "r") as f:
                    data[m, w] = (f["metrics/bin_centers"][:], f["metrics/sai"][:], f["metrics"].attrs["msai"])
                    vmax = max(vmax, float(np.max(data[m, w][1])) if len(data[m, w][1]) else 0)
    im = None
    for i, m in enumerate(folder.models):
        for j, w in enumerate(folder.worlds):
            ax = axes[i][j]
            ax.set_aspect("equal")
            ax.tick_params(labelsize=7)
            where = f"{folder.world_label(w)} tilt" if folder.tilt_axis() else w
            if (m, w) in data:
                c, sai, msai = data[m, w]
                im = hexmap(ax, c, sai, cmap="inferno", vmin=0, vmax=vmax)
                ax.set_title(f"{m}, {where}: MSAI {msai:.4f}", fontsize=8)
            else:
                ax.set_title(f"{m}, {where}: no trial file", fontsize=8)
            if j == 0:
                ax.set_ylabel("y (m)", fontsize=8)
            if i == nr - 1:
                ax.set_xlabel("x (m)", fontsize=8)
    if im is not None:
        fig.colorbar(im, ax=axes, shrink=0.6, label="SAI (similarity to bins > d_th away)")
    others = f" of seeds {seed_list(folder.seeds)}" if len(folder.seeds) > 1 else ""
    fig.suptitle(f"Spatial aliasing index per bin: one trial per panel, seed {seed}{others}\n"
                 f"(rows: models; columns: worlds)")
    return fig


def fig_sai_grid(folder, out):
    save(sai_grid_figure(folder), out)


def modality_kind(mi):
    """What a cell with modality index ``mi`` is: "multimodal" (MI > 1), "unimodal" (MI == 1),
    "silent" (no field)."""
    return "multimodal" if mi > 1 else "unimodal" if mi == 1 else "silent"


def pick_example_cell(mi, maps, want):
    """The example cell for a panel that should show a ``want`` ("multimodal" or "unimodal") cell.

    Returns ``(cell, title)``, ``cell`` None if no cell has a field. Among the cells of the wanted
    kind, the one with the largest field (most active bins) shows the pattern best; if the model has
    none, the largest cell with any field is shown and the title says so."""
    mi = np.asarray(mi)
    cand = np.flatnonzero(mi > 1) if want == "multimodal" else np.flatnonzero(mi == 1)
    prefix = ""
    if len(cand) == 0:
        cand = np.flatnonzero(mi > 0)
        if len(cand) == 0:
            return None, f"no {want} cell; no cell has a field (every MI = 0)"
        prefix = f"no {want} cell; showing "
    cell = int(cand[np.argmax((maps[:, cand] > 0).sum(axis=0))])
    kind = modality_kind(int(mi[cell]))
    return cell, f"{prefix}a {kind} one" if prefix else kind


def place_fields_figure(folder):
    """Example fields at the largest tilt: a multimodal cell (MI > 1) of the first model and a
    unimodal cell (MI == 1) of the last model. Each panel is titled by what it shows: a model
    without a cell of the wanted kind gets its largest cell of another kind, said so in the title.
    Returns the figure and the panel titles."""
    world, seed = folder.worlds[-1], folder.seeds[0]
    panels = []
    for model, want in ((folder.models[0], "multimodal"), (folder.models[-1], "unimodal")):
        path = folder.file(model, world, seed)
        if not path:
            continue
        with h5py.File(path, "r") as f:
            mi = f["metrics/modality"][:]
            maps = f["metrics/rate_maps"][:]
            centers = f["metrics/bin_centers"][:]
        cell, what = pick_example_cell(mi, maps, want)
        where = (f"{folder.world_label(world)} tilt" if folder.tilt_axis() else world) + f", seed {seed}"
        if cell is None:
            panels.append((f"{model}: {what}\n{where}", None, None))
        else:
            sep = "\n" if what.startswith("no ") else " "  # a fallback note gets a line of its own
            panels.append((f"{what}:{sep}{model} cell {cell} (MI = {int(mi[cell])})\n{where}", centers, maps[:, cell]))
    fig, axes = plt.subplots(1, max(len(panels), 1), figsize=(4.2 * max(len(panels), 1), 4))
    axes = np.atleast_1d(axes)
    im = None
    for ax, (title, centers, values) in zip(axes, panels):
        if values is not None:
            im = hexmap(ax, centers, values, cmap="viridis", vmin=0, vmax=1)
        ax.set_aspect("equal")
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    fig.tight_layout()
    if im is not None:
        fig.colorbar(im, ax=list(axes), shrink=0.8, label="rate map (thresholded, 1 = the cell's peak)")
    return fig, [p[0] for p in panels]


def fig_place_fields(folder, out):
    fig, titles = place_fields_figure(folder)
    save(fig, out)
    return titles


def trajectory_figure(folder):
    model, world, seed = folder.models[0], folder.worlds[0], folder.seeds[0]
    path = folder.file(model, world, seed)
    with h5py.File(path, "r") as f:
        x, y, t = f["samples/x"][:], f["samples/y"][:], f["samples/t"][:]
    fig, ax = plt.subplots(figsize=(4.6, 4.6))
    ax.plot(x, y, lw=0.2, color="tab:blue")
    ax.set_aspect("equal")
    hours = (t[-1] - t[0]) / 3600 if len(t) else 0
    ax.set_title(f"Sampling trajectory: {len(x)} model steps in {hours:.2g} h\n"
                 f"{world}, seed {seed} (trial {os.path.basename(path)[:-3]})", fontsize=9)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    fig.tight_layout()
    return fig


def fig_trajectory(folder, out):
    save(trajectory_figure(folder), out)


def environments_figure(folder):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    import bvc3d

    worlds = [w for w in folder.worlds if not math.isnan(folder.tilt[w])]
    if not worlds:
        return None
    fig = plt.figure(figsize=(3.4 * len(worlds), 3.6))
    for i, w in enumerate(worlds):
        ax = fig.add_subplot(1, len(worlds), i + 1, projection="3d")
        tri = bvc3d.World.cross(tilt_deg=folder.tilt[w]).triangles
        # Leave out the ceiling and the floor, as the paper's figure shows the arena open.
        keep = ~(np.all(np.isclose(tri[:, :, 2], 2.5), axis=1) | np.all(np.isclose(tri[:, :, 2], 0.0), axis=1))
        walls = tri[keep]
        inner = np.array([np.abs(t[:, :2]).max() < 4.9 for t in walls])
        ax.add_collection3d(Poly3DCollection(walls[~inner], facecolor="lightgray", edgecolor="none", alpha=0.25))
        ax.add_collection3d(Poly3DCollection(walls[inner], facecolor="tab:orange", edgecolor="k", linewidth=0.2,
                                             alpha=0.9))
        ax.set_xlim(-5, 5)
        ax.set_ylim(-5, 5)
        ax.set_zlim(0, 2.5)
        ax.set_box_aspect((10, 10, 2.5))
        lo, hi = tri.reshape(-1, 3).min(axis=0), tri.reshape(-1, 3).max(axis=0)
        size = " × ".join(f"{d:g}" for d in hi - lo)
        ax.set_title(f"{w}: central walls tilted {folder.tilt[w]:g}°\narena {size} m (x × y × z)", fontsize=9)
        ax.set_axis_off()
    fig.subplots_adjust(left=0.0, right=1.0, bottom=0.0, top=0.86, wspace=0.0)  # room for two-line titles
    return fig


def fig_environments(folder, out):
    fig = environments_figure(folder)
    if fig is None:
        return False
    save(fig, out)
    return True


def swept_keys(summary):
    """The swept-key columns of summary.csv ("swept:<key>")."""
    return [c for c in summary[0] if c.startswith("swept:")] if summary else []


def as_number(values):
    try:
        return [float(v) for v in values], True
    except ValueError:
        return list(values), False


def sweep_figure(folder, keys, metric):
    """A metric against the first swept key, one line per combination of the other keys."""
    label, title = METRICS[metric]
    x_key, others = keys[0], keys[1:]
    lines = {}
    for r in folder.summary:
        lines.setdefault(tuple(r[k] for k in others), []).append(r)
    fig, ax = plt.subplots(figsize=(7, 3.8))
    xs_all = list(dict.fromkeys(r[x_key] for r in folder.summary))
    numeric = as_number(xs_all)[1]
    clip = folder.non_negative(metric)
    for combo, rows in lines.items():
        xs = [float(r[x_key]) if numeric else xs_all.index(r[x_key]) for r in rows]
        means = [num(r.get(metric + "_mean")) for r in rows]
        yerr = error_bars(means, [num(r.get(metric + "_sd")) for r in rows], clip) if folder.replicated() else None
        name = (combo[0] if len(others) == 1 else ", ".join(f"{k[6:]}={v}" for k, v in zip(others, combo))) or None
        ax.errorbar(xs, means, yerr=yerr, marker="o", capsize=3, label=name)
    if not numeric:
        ax.set_xticks(range(len(xs_all)), xs_all, rotation=20, fontsize=8)
    ax.set_xlabel(x_key[6:])
    ax.set_ylabel(label)
    if clip:
        ax.set_ylim(bottom=min(ax.get_ylim()[0], 0.0))
    ax.set_title(f"{title}\n{folder.spread_text()}", fontsize=10)
    if others:
        legend_outside(ax, ", ".join(k[6:] for k in others))
    fig.tight_layout()
    return fig


def fig_sweep(folder, keys, metric, out):
    save(sweep_figure(folder, keys, metric), out)


def make_sweep_report(folder, figdir):
    keys = swept_keys(folder.summary)
    figures = []
    for metric in METRICS:
        if not any(math.isfinite(num(r.get(metric + "_mean"))) for r in folder.summary):
            continue  # a metric of other trials (e.g. 3-D only): nothing to draw
        name = f"sweep_{metric}.png"
        fig_sweep(folder, keys, metric, os.path.join(figdir, name))
        shown = [k[6:] for k in keys]
        figures.append((name, f"{METRICS[metric][1]} against {shown[0]}" +
                        (f", one line per value of {', '.join(shown[1:])}" if shown[1:] else "") +
                        f": {folder.spread_text()}."))
    return figures


def grouped(values):
    """Distinct values with their counts, most common first: [(value, count)]."""
    counts = {}
    for v in values:
        counts[v] = counts.get(v, 0) + 1
    return sorted(counts.items(), key=lambda kv: -kv[1])


def setting_lines(folder):
    """The report's account of how the trials were run and analyzed, from the trial files."""
    settings = folder.settings()
    n = len(settings)
    lines = []
    for what, index in (("Protocol", 0), ("Analysis", 1)):
        groups = grouped(s[index] for s in settings)
        if len(groups) == 1:
            lines.append(f"- **{what}** ({'the same for all' if n > 1 else 'the'} {n} trial{'s' if n > 1 else ''}): "
                         f"{groups[0][0]}.")
        else:
            lines.append(f"- **{what} differs between trials** — compare with care:")
            lines += [f"  - {value} ({count} trial{'s' if count > 1 else ''})" for value, count in groups]
    seeds = sorted({s[2] for s in settings})
    if folder.replicated():
        per = folder.seeds_per_condition
        count = f"{per[0]}" if len(per) == 1 else f"{per[0]} to {per[-1]}"
        lines.append(f"- **Seeds**: {seed_list(seeds)} ({count} per condition). Tables and bars show the mean over "
                     f"seeds ± the sample standard deviation; error bars of quantities that cannot be negative "
                     f"stop at 0.")
    else:
        lines.append(f"- **Seeds**: {seed_list(seeds)}, one trial per condition: every value in the table "
                     f"and the figures "
                     f"is a single trial's (no means, no spreads; run more seeds with `--seeds N` for those).")
    return lines


def write_report(folder, figures):
    with open(os.path.join(folder.path, "summary.md")) as f:
        table = f.read()
    lines = ["# bvc3d experiment report", "",
             f"{len(folder.trials)} trials: {len(folder.conditions)} conditions (models {', '.join(folder.models)}; "
             f"worlds {', '.join(folder.worlds)}).", "", *setting_lines(folder), "",
             "## Summary", "", table, "", "## Figures", ""]
    for name, sentence in figures:
        lines += [f"### {name.split('.')[0].replace('_', ' ')}", "", sentence, "", f"![{name}](figures/{name})", ""]
    tmp = os.path.join(folder.path, "report.md.tmp")
    with open(tmp, "w") as f:
        f.write("\n".join(lines))
    os.replace(tmp, os.path.join(folder.path, "report.md"))


def make_report(path):
    if h5py is None:
        raise SystemExit("bvc3d.report needs h5py (Debian: apt-get install python3-h5py)")
    folder = Folder(path)
    figdir = os.path.join(path, "figures")
    os.makedirs(figdir, exist_ok=True)
    if os.path.exists(os.path.join(path, "sweep.yaml")) and swept_keys(folder.summary):
        figures = make_sweep_report(folder, figdir)
        write_report(folder, figures)
        return figures
    from . import flight_report
    try:
        flying = flight_report.is_flight_folder(folder)
    except ValueError as e:
        raise SystemExit(f"bvc3d.report: {e}")
    if flying:  # flying agents' trials (`bvc3d flight`): 3-D figures
        figures = flight_report.make_flight_report(folder, figdir)
        write_report(folder, figures)
        return figures
    figures = []

    def add(name, sentence, draw):
        if draw(os.path.join(figdir, name)) is not False:
            figures.append((name, sentence))

    seed = folder.seeds[0]
    one = f"seed {seed}" + (f" (the first of seeds {seed_list(folder.seeds)})" if len(folder.seeds) > 1 else "")
    add("environments.png", "The arenas in 3-D (ceiling and floor left out): the central cross walls lean toward the "
        "+x,+y corner by the given tilt while their footprint stays put.", lambda p: fig_environments(folder, p))
    add("trajectory.png", f"The robot's random walk during the sampling phase of one trial "
        f"({folder.worlds[0]}, {one}): "
        "coverage of the arena.", lambda p: fig_trajectory(folder, p))
    add("place_fields.png", f"Rate maps of two example place cells at the largest tilt ({one}): a multimodal (aliased, "
        "MI > 1) cell of the first model and a unimodal (MI = 1) cell of the last model. A model without a cell of "
        "that kind shows another cell, and the panel's title says so.", lambda p: fig_place_fields(folder, p))
    add("sai_grid.png", "Spatial aliasing index of every bin: how similar its population vector is to those of "
        f"bins more than d_th away. Bright regions are aliased. One trial per panel: {one}.",
        lambda p: fig_sai_grid(folder, p))
    for metric in bar_metrics(dims=2):
        add(bar_file(metric), bar_sentence(folder, metric), lambda p, metric=metric: fig_bars(folder, metric, p))
    write_report(folder, figures)
    return figures


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m bvc3d.report", description=__doc__.strip().splitlines()[0])
    parser.add_argument("folder", help="experiment folder (trial files, trials.csv, summary.csv)")
    args = parser.parse_args(argv)
    if not os.path.isdir(args.folder):
        raise SystemExit(f"bvc3d.report: {args.folder} is not a folder")
    figures = make_report(args.folder)
    print(f"report: {os.path.join(args.folder, 'report.md')} ({len(figures)} figures)")


if __name__ == "__main__":
    main(sys.argv[1:])
