"""Figures and report.md for a folder of bvc3d trial files.

    /usr/bin/python3 -m bvc3d.report DIR

DIR holds the trial files (*.h5) and the tables `bvc3d paper` writes (trials.csv, summary.csv,
summary.md). Figures are PNG files in DIR/figures; DIR/report.md shows the table and every figure.
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

DPI = 120
# Metrics with a figure of their own: (axis label, title), from the analysis stage's one table.
METRICS = {m["name"]: (m["label"], m["title"]) for m in metric_table if m["title"]}


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def num(s):
    try:
        return float(s)
    except (TypeError, ValueError):
        return math.nan


class Folder:
    """The trials of one experiment folder, grouped by model and world."""

    def __init__(self, path):
        self.path = path
        for name in ("trials.csv", "summary.csv"):
            if not os.path.exists(os.path.join(path, name)):
                raise SystemExit(f"bvc3d.report: {path} has no {name}; run `bvc3d paper` (or `bvc3d summarize {path}`) first")
        self.trials = read_csv(os.path.join(path, "trials.csv"))
        self.summary = read_csv(os.path.join(path, "summary.csv"))
        self.models = list(dict.fromkeys(r["model"] for r in self.summary))
        worlds = list(dict.fromkeys(r["world"] for r in self.summary))
        self.conditions = list(dict.fromkeys(r["condition"] for r in self.summary))
        tilt = {r["world"]: num(r["tilt_deg"]) for r in self.summary}
        self.worlds = sorted(worlds, key=lambda w: (math.isnan(tilt[w]), tilt[w], w))
        self.tilt = tilt
        self.seeds = sorted({int(r["seed"]) for r in self.trials})

    def file(self, model, world, seed=None):
        seed = self.seeds[0] if seed is None else seed
        for r in self.trials:
            if r["model"] == model and r["world"] == world and int(r["seed"]) == seed:
                return os.path.join(self.path, r["name"] + ".h5")
        return None

    def stat(self, model, world, metric):
        for r in self.summary:
            if r["model"] == model and r["world"] == world:
                return num(r[metric + "_mean"]), num(r[metric + "_sd"])
        return math.nan, math.nan

    def world_label(self, w):
        t = self.tilt.get(w, math.nan)
        return f"{t:g}°" if not math.isnan(t) else w


def hexmap(ax, centers, values, extent=None, cmap="viridis", vmin=None, vmax=None):
    """Draw per-bin values at their hexagon centers: each center falls in its own bin."""
    cx, cy = centers[:, 0], centers[:, 1]
    if extent is None:
        extent = (cx.min(), cx.max(), cy.min(), cy.max())
    return ax.hexbin(cx, cy, C=values, gridsize=50, extent=extent, cmap=cmap, vmin=vmin, vmax=vmax,
                     reduce_C_function=np.mean, linewidths=0.0)


def fig_bars(folder, metric, out):
    label, title = METRICS[metric]
    fig, ax = plt.subplots(figsize=(7, 3.6))
    n = len(folder.models)
    width = 0.8 / max(n, 1)
    x = np.arange(len(folder.worlds))
    for i, m in enumerate(folder.models):
        stats = [folder.stat(m, w, metric) for w in folder.worlds]
        means = [s[0] for s in stats]
        sds = [0 if math.isnan(s[1]) else s[1] for s in stats]
        ax.bar(x + (i - (n - 1) / 2) * width, means, width, yerr=sds if len(folder.seeds) > 1 else None,
               label=m, capsize=2)
    ax.set_xticks(x, [folder.world_label(w) for w in folder.worlds])
    ax.set_xlabel("tilt of the central walls")
    ax.set_ylabel(label)
    ax.set_title(title + (f" (mean ± sd, {len(folder.seeds)} seeds)" if len(folder.seeds) > 1 else ""))
    ax.legend(fontsize=8, ncol=min(n, 5))
    fig.tight_layout()
    fig.savefig(out, dpi=DPI)
    plt.close(fig)


def fig_sai_grid(folder, out):
    nr, nc = len(folder.models), len(folder.worlds)
    fig, axes = plt.subplots(nr, nc, figsize=(2.6 * nc + 0.8, 2.5 * nr), squeeze=False)
    vmax = 0
    data = {}
    for m in folder.models:
        for w in folder.worlds:
            path = folder.file(m, w)
            if path and os.path.exists(path):
                with h5py.File(path, "r") as f:
                    data[m, w] = (f["metrics/bin_centers"][:], f["metrics/sai"][:], f["metrics"].attrs["msai"])
                    vmax = max(vmax, float(np.max(data[m, w][1])) if len(data[m, w][1]) else 0)
    im = None
    for i, m in enumerate(folder.models):
        for j, w in enumerate(folder.worlds):
            ax = axes[i][j]
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_aspect("equal")
            if (m, w) in data:
                c, sai, msai = data[m, w]
                im = hexmap(ax, c, sai, cmap="inferno", vmin=0, vmax=vmax)
                ax.set_title(f"MSAI {msai:.3f}", fontsize=8)
            if j == 0:
                ax.set_ylabel(m)
            if i == nr - 1:
                ax.set_xlabel(folder.world_label(w))
    if im is not None:
        fig.colorbar(im, ax=axes, shrink=0.6, label="SAI")
    fig.suptitle("Spatial aliasing index per bin (rows: models, columns: tilt)")
    fig.savefig(out, dpi=DPI)
    plt.close(fig)


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


def fig_place_fields(folder, out):
    """Example fields at the largest tilt: a multimodal cell (MI > 1) of the first model and a
    unimodal cell (MI == 1) of the last model. Each panel is titled by what it shows: a model
    without a cell of the wanted kind gets its largest cell of another kind, said so in the title.
    Returns the panel titles."""
    world = folder.worlds[-1]
    panels = []
    for model, want in ((folder.models[0], "multimodal"), (folder.models[-1], "unimodal")):
        path = folder.file(model, world)
        if not path:
            continue
        with h5py.File(path, "r") as f:
            mi = f["metrics/modality"][:]
            maps = f["metrics/rate_maps"][:]
            centers = f["metrics/bin_centers"][:]
        cell, what = pick_example_cell(mi, maps, want)
        where = f"{folder.world_label(world)} tilt"
        if cell is None:
            panels.append((f"{model}: {what}\n{where}", None, None))
        else:
            sep = "\n" if what.startswith("no ") else " "  # a fallback note gets a line of its own
            panels.append((f"{what}:{sep}{model} cell {cell} (MI = {int(mi[cell])})\n{where}", centers, maps[:, cell]))
    fig, axes = plt.subplots(1, max(len(panels), 1), figsize=(4.2 * max(len(panels), 1), 4))
    axes = np.atleast_1d(axes)
    for ax, (title, centers, values) in zip(axes, panels):
        if values is not None:
            hexmap(ax, centers, values, cmap="viridis", vmin=0, vmax=1)
        else:
            ax.set_xticks([])
            ax.set_yticks([])
        ax.set_aspect("equal")
        ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=DPI)
    plt.close(fig)
    return [p[0] for p in panels]


def fig_trajectory(folder, out):
    path = folder.file(folder.models[0], folder.worlds[0])
    with h5py.File(path, "r") as f:
        x, y, t = f["samples/x"][:], f["samples/y"][:], f["samples/t"][:]
    fig, ax = plt.subplots(figsize=(4.6, 4.6))
    ax.plot(x, y, lw=0.2, color="tab:blue")
    ax.set_aspect("equal")
    hours = (t[-1] - t[0]) / 3600 if len(t) else 0
    ax.set_title(f"Sampling trajectory: {len(x)} model steps in {hours:.1f} h")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    fig.tight_layout()
    fig.savefig(out, dpi=DPI)
    plt.close(fig)


def fig_environments(folder, out):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    import bvc3d

    worlds = [w for w in folder.worlds if not math.isnan(folder.tilt[w])]
    if not worlds:
        return False
    fig = plt.figure(figsize=(3.4 * len(worlds), 3.6))
    for i, w in enumerate(worlds):
        ax = fig.add_subplot(1, len(worlds), i + 1, projection="3d")
        tri = bvc3d.World.cross(tilt_deg=folder.tilt[w]).triangles
        # Leave out the ceiling and the floor, as the paper's figure shows the arena open.
        keep = ~(np.all(np.isclose(tri[:, :, 2], 2.5), axis=1) | np.all(np.isclose(tri[:, :, 2], 0.0), axis=1))
        walls = tri[keep]
        inner = np.array([np.abs(t[:, :2]).max() < 4.9 for t in walls])
        ax.add_collection3d(Poly3DCollection(walls[~inner], facecolor="lightgray", edgecolor="none", alpha=0.25))
        ax.add_collection3d(Poly3DCollection(walls[inner], facecolor="tab:orange", edgecolor="k", linewidth=0.2, alpha=0.9))
        ax.set_xlim(-5, 5)
        ax.set_ylim(-5, 5)
        ax.set_zlim(0, 2.5)
        ax.set_box_aspect((10, 10, 2.5))
        ax.set_title(f"{folder.world_label(w)} tilt", fontsize=9)
        ax.set_axis_off()
    fig.tight_layout()
    fig.savefig(out, dpi=DPI)
    plt.close(fig)
    return True


def swept_keys(summary):
    """The swept-key columns of summary.csv ("swept:<key>")."""
    return [c for c in summary[0] if c.startswith("swept:")] if summary else []


def as_number(values):
    try:
        return [float(v) for v in values], True
    except ValueError:
        return list(values), False


def fig_sweep(folder, keys, metric, out):
    """A metric against the first swept key, one line per combination of the other keys."""
    label, title = METRICS[metric]
    x_key, others = keys[0], keys[1:]
    lines = {}
    for r in folder.summary:
        lines.setdefault(tuple(r[k] for k in others), []).append(r)
    fig, ax = plt.subplots(figsize=(7, 3.8))
    xs_all = list(dict.fromkeys(r[x_key] for r in folder.summary))
    numeric = as_number(xs_all)[1]
    for combo, rows in lines.items():
        xs = [float(r[x_key]) if numeric else xs_all.index(r[x_key]) for r in rows]
        means = [num(r[metric + "_mean"]) for r in rows]
        sds = [0.0 if math.isnan(num(r[metric + "_sd"])) else num(r[metric + "_sd"]) for r in rows]
        name = ", ".join(f"{k[6:]}={v}" for k, v in zip(others, combo)) or None
        ax.errorbar(xs, means, yerr=sds, marker="o", capsize=3, label=name)
    if not numeric:
        ax.set_xticks(range(len(xs_all)), xs_all, rotation=20, fontsize=8)
    ax.set_xlabel(x_key[6:])
    ax.set_ylabel(label)
    seeds = len(folder.seeds)
    ax.set_title(title + (f" (mean ± sd over {seeds} seeds)" if seeds > 1 else ""))
    if others:
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=DPI)
    plt.close(fig)


def make_sweep_report(folder, figdir):
    keys = swept_keys(folder.summary)
    figures = []
    for metric in METRICS:
        name = f"sweep_{metric}.png"
        fig_sweep(folder, keys, metric, os.path.join(figdir, name))
        shown = [k[6:] for k in keys]
        figures.append((name, f"{METRICS[metric][1]} against {shown[0]}" +
                        (f", one line per value of {', '.join(shown[1:])}." if shown[1:] else ".")))
    return figures


def write_report(folder, figures):
    with open(os.path.join(folder.path, "summary.md")) as f:
        table = f.read()
    lines = ["# bvc3d experiment report", "",
             f"{len(folder.trials)} trials: {len(folder.conditions)} conditions (models {', '.join(folder.models)}; "
             f"worlds {', '.join(folder.worlds)}), seeds {', '.join(map(str, folder.seeds))}.", "",
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
    figures = []

    def add(name, sentence, draw):
        if draw(os.path.join(figdir, name)) is not False:
            figures.append((name, sentence))

    add("environments.png", "The arenas in 3-D (ceiling and floor left out): the central cross walls lean toward the "
        "+x,+y corner by the given tilt while their footprint stays put.", lambda p: fig_environments(folder, p))
    add("trajectory.png", "The robot's random walk during the sampling phase of one trial: coverage of the arena.",
        lambda p: fig_trajectory(folder, p))
    add("place_fields.png", "Rate maps of two example place cells at the largest tilt: a multimodal (aliased, "
        "MI > 1) cell of the first model and a unimodal (MI = 1) cell of the last model. A model without a cell of "
        "that kind shows another cell, and the panel's title says so.", lambda p: fig_place_fields(folder, p))
    add("mi_active.png", "Fraction of place cells with at least one field (MI > 0), per model and tilt.",
        lambda p: fig_bars(folder, "frac_active", p))
    add("mi_mean.png", "Mean modality index of the active cells: fields per cell; 1 is a single place field.",
        lambda p: fig_bars(folder, "mean_mi_active", p))
    add("mi_multimodal.png", "Fraction of multimodal place cells (MI > 1): cells that fire in several places.",
        lambda p: fig_bars(folder, "frac_multimodal", p))
    add("sai_grid.png", "Spatial aliasing index of every bin: how similar its population vector is to those of "
        "bins more than 2 m away. Bright regions are aliased.", lambda p: fig_sai_grid(folder, p))
    add("msai.png", "Mean spatial aliasing index per model and tilt: lower is better.",
        lambda p: fig_bars(folder, "msai", p))
    add("decoding.png", "Median position error when each sample of the second half is decoded to the cosine-"
        "nearest rate-map bin of the first half: the direct measure of localization.",
        lambda p: fig_bars(folder, "decode_median_m", p))
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
