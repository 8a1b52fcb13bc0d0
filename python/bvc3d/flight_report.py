"""Figures for the flying agents' experiment (`bvc3d flight`, docs/flying.md).

bvc3d.report calls ``make_flight_report`` for a folder whose trial files hold flying agents' trials
(format version 2: positions x, y, z). The figures follow the conventions of bvc3d.figures: each says which
worlds, models and seeds it shows, axes are in meters, legends sit outside the axes, and bars are one
trial's values or means ± sd over seeds (error bars of non-negative quantities stop at 0).
"""
import math
import os
import warnings

import matplotlib.pyplot as plt
import numpy as np

from . import figures

try:
    import h5py
except ImportError:  # pragma: no cover - Debian's python3-h5py is a dependency
    h5py = None

# The version of trial files with 3-D positions, and the newest this module reads.
FLIGHT_FORMAT_VERSION = 2
KNOWN_VERSIONS = (1, 2)
BATS = "bats, Yartsev & Ulanovsky 2013"


def file_version(path):
    """A trial file's format_version (1 when it predates the attribute); ValueError for one this
    module does not know."""
    with h5py.File(path, "r") as f:
        v = int(f.attrs.get("format_version", 1))
    if v not in KNOWN_VERSIONS:
        raise ValueError(f"{path}: trial file format_version {v}; this bvc3d reads versions "
                         f"{KNOWN_VERSIONS[0]} to {KNOWN_VERSIONS[-1]} (written by a newer bvc3d?)")
    return v


def is_flight_folder(folder):
    """The folder's trials are flying agents' (3-D positions): their files have format version 2."""
    versions = set()
    for r in folder.trials:
        path = os.path.join(folder.path, r["name"] + ".h5")
        if os.path.exists(path):
            versions.add(file_version(path))
    return FLIGHT_FORMAT_VERSION in versions


def voxel_array(centers, values):
    """Per-voxel values as a dense (nx, ny, nz) array (NaN where no voxel was visited) and the voxel
    centers along each axis. The voxel side is the smallest spacing of the centers."""
    centers = np.asarray(centers, float)
    axes, index = [], []
    for d in range(3):
        u = np.unique(centers[:, d])
        step = np.min(np.diff(u)) if len(u) > 1 else 1.0
        i = np.rint((centers[:, d] - u[0]) / step).astype(int)
        axes.append(u[0] + step * np.arange(i.max() + 1))
        index.append(i)
    grid = np.full([len(a) for a in axes], np.nan)
    grid[tuple(index)] = values
    return grid, axes


def extent_of(a, b):
    """imshow extent for voxel centers a (horizontal) and b (vertical): the voxels' edges."""
    sa = a[1] - a[0] if len(a) > 1 else 0.5
    sb = b[1] - b[0] if len(b) > 1 else 0.5
    return (a[0] - sa / 2, a[-1] + sa / 2, b[0] - sb / 2, b[-1] + sb / 2)


def nanmax(a, axis):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN lines stay NaN
        return np.nanmax(a, axis=axis)


def pick_unimodal(mi, maps, isotropy):
    """The example field of a model: among its cells with MI = 1 (and a finite isotropy), the one with
    the most active voxels; None if it has none."""
    mi = np.asarray(mi)
    cand = [c for c in np.flatnonzero(mi == 1) if np.isfinite(isotropy[c])]
    if not cand:
        return None
    return int(cand[int(np.argmax([(maps[:, c] > 0).sum() for c in cand]))])


def fields_figure(folder):
    """Per model (rows), one cell with a single 3-D field in the first world and seed: maximum
    projections onto the three planes and the three slices through the field's peak voxel."""
    world, seed = folder.worlds[0], folder.seeds[0]
    rows = []
    for model in folder.models:
        path = folder.file(model, world, seed)
        if not path or not os.path.exists(path):
            continue
        with h5py.File(path, "r") as f:
            mi, maps = f["metrics/modality"][:], f["metrics/rate_maps"][:]
            centers, iso = f["metrics/bin_centers"][:], f["metrics/isotropy"][:]
        cell = pick_unimodal(mi, maps, iso)
        rows.append((model, cell, centers, maps, iso))
    fig, axes = plt.subplots(max(len(rows), 1), 6, figsize=(17, 2.9 * max(len(rows), 1)), squeeze=False)
    im = None
    for r, (model, cell, centers, maps, iso) in enumerate(rows):
        if cell is None:
            axes[r][0].set_title(f"{model}: no cell with a single field (MI = 1)", fontsize=8, loc="left")
            for ax in axes[r]:
                ax.set_axis_off()
            continue
        grid, (xs, ys, zs) = voxel_array(centers, maps[:, cell])
        peak = np.unravel_index(np.nanargmax(grid), grid.shape)
        panels = [
            ("max over z", nanmax(grid, 2).T, xs, ys, "x (m)", "y (m)"),
            ("max over y", nanmax(grid, 1).T, xs, zs, "x (m)", "z (m)"),
            ("max over x", nanmax(grid, 0).T, ys, zs, "y (m)", "z (m)"),
            (f"slice z = {zs[peak[2]]:.2f} m", grid[:, :, peak[2]].T, xs, ys, "x (m)", "y (m)"),
            (f"slice y = {ys[peak[1]]:.2f} m", grid[:, peak[1], :].T, xs, zs, "x (m)", "z (m)"),
            (f"slice x = {xs[peak[0]]:.2f} m", grid[peak[0], :, :].T, ys, zs, "y (m)", "z (m)"),
        ]
        for ax, (what, img, a, b, la, lb) in zip(axes[r], panels):
            im = ax.imshow(img, origin="lower", extent=extent_of(a, b), cmap="viridis", vmin=0, vmax=1,
                           interpolation="nearest")
            ax.set_facecolor("0.85")  # unvisited voxels
            ax.set_title(what, fontsize=8)
            ax.set_xlabel(la, fontsize=8)
            ax.set_ylabel(lb, fontsize=8)
            ax.tick_params(labelsize=7)
        axes[r][0].set_title(f"{model} cell {cell} (MI = 1, isotropy {iso[cell]:.2f})\nmax over z", fontsize=8)
    fig.suptitle(f"Example single 3-D place fields: {world}, seed {seed}; per model the MI = 1 cell with the most "
                 "active voxels (0.5 m voxels; gray: never visited)", fontsize=10)
    fig.tight_layout(rect=(0, 0, 0.93, 0.95))
    if im is not None:
        cax = fig.add_axes((0.94, 0.15, 0.012, 0.7))
        fig.colorbar(im, cax=cax, label="rate map (thresholded, 1 = the cell's peak)")
    return fig


def trajectory_figure(folder, minutes=20):
    """The first minutes of the first trial's sampling flight in 3-D, and its time at each height."""
    model, world, seed = folder.models[0], folder.worlds[0], folder.seeds[0]
    path = folder.file(model, world, seed)
    with h5py.File(path, "r") as f:
        x, y, z, t = f["samples/x"][:], f["samples/y"][:], f["samples/z"][:], f["samples/t"][:]
    first = t <= t[0] + 60 * minutes if len(t) else np.zeros(0, bool)
    fig = plt.figure(figsize=(10, 4.6))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    ax.plot(x[first], y[first], z[first], lw=0.5, color="tab:blue")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    span = [np.ptp(v) if len(v) else 1.0 for v in (x, y, z)]
    ax.set_box_aspect([max(s, 0.1) for s in span])
    hours = (t[-1] - t[0]) / 3600 if len(t) else 0
    ax.set_title(f"The first {minutes} min of sampling ({first.sum()} model steps)", fontsize=9)
    ax2 = fig.add_subplot(1, 2, 2)
    ax2.hist(z, bins=40, orientation="horizontal", color="tab:blue")
    ax2.set_ylabel("z, the body's center (m)")
    ax2.set_xlabel("model steps")
    ax2.set_title(f"Heights of all {len(z)} steps of the {hours:.2g} h sampling phase", fontsize=9)
    fig.suptitle(f"The flying agent's random walk: {world}, seed {seed} (trial {os.path.basename(path)[:-3]})",
                 fontsize=10)
    fig.tight_layout()
    return fig


def isotropy_figure(folder):
    """Per world, the distribution of every single field's isotropy (all seeds pooled), one line per model."""
    fig, axes = plt.subplots(1, len(folder.worlds), figsize=(3.8 * len(folder.worlds) + 1.6, 3.4), squeeze=False)
    bins = np.logspace(-1.5, 1.5, 41)
    for ax, w in zip(axes[0], folder.worlds):
        for m in folder.models:
            values = []
            for s in folder.seeds:
                path = folder.file(m, w, s)
                if path and os.path.exists(path):
                    with h5py.File(path, "r") as f:
                        iso = f["metrics/isotropy"][:]
                    values.extend(iso[np.isfinite(iso) & (iso > 0)])
            ax.hist(np.clip(values, bins[0], bins[-1]), bins=bins, histtype="step", lw=1.3,
                    label=f"{m} ({len(values)})")
        ax.axvline(1.0, color="k", ls="--", lw=1, label=f"1: round ({BATS})")
        ax.set_xscale("log")
        ax.set_xlabel("isotropy: sd z / mean sd x, y")
        ax.set_ylabel("cells with MI = 1")
        ax.set_title(w, fontsize=9)
    figures.legend_outside(axes[0][-1], "model (fields)")
    seeds = figures.seed_list(folder.seeds)
    fig.suptitle(f"Isotropy of single 3-D fields, every MI = 1 cell of seed{'s' if len(folder.seeds) > 1 else ''} "
                 f"{seeds} pooled (values beyond the axis are drawn at its ends)", fontsize=10)
    fig.tight_layout()
    return fig


def bar_positions(folder):
    n = len(folder.models)
    width = 0.8 / max(n, 1)
    x = np.arange(len(folder.worlds))
    return {(m, w): x[j] + (i - (n - 1) / 2) * width for i, m in enumerate(folder.models)
            for j, w in enumerate(folder.worlds)}


def isotropy_bars(folder):
    fig = figures.bars_figure(folder, "isotropy_median")
    ax = fig.axes[0]
    ax.axhline(1.0, color="k", ls="--", lw=1, label="1: round (bats)")
    figures.legend_outside(ax, "model")
    fig.tight_layout()
    return fig


def vertical_bars(folder):
    fig = figures.bars_figure(folder, "decode_vertical_median_m")
    ax = fig.axes[0]
    pos = bar_positions(folder)
    xs = [pos[m, w] for m in folder.models for w in folder.worlds]
    ys = [folder.stat(m, w, "decode_vertical_chance_m")[0] for m in folder.models for w in folder.worlds]
    ax.plot(xs, ys, "k_", ms=12, mew=2, ls="none", label="random guess (chance)")
    lo, hi = ax.get_ylim()
    top = max([hi] + [y for y in ys if not math.isnan(y)])
    ax.set_ylim(lo, top * 1.05)
    figures.legend_outside(ax, "model")
    fig.tight_layout()
    return fig


def worlds_figure(folder):
    """The worlds in 3-D with their flight volumes (the body's center stays 0.2 m further inside)."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    import bvc3d

    worlds = []
    for w in folder.worlds:
        source = None
        path = folder.file(folder.models[0], w)
        if path and os.path.exists(path):
            with h5py.File(path, "r") as f:
                source = figures.fmt(f.attrs.get("world_source", w))
        try:
            worlds.append((w, bvc3d.World.preset(source or w)))
        except ValueError:
            continue
    if not worlds:
        return None
    fig = plt.figure(figsize=(3.8 * len(worlds), 3.8))
    for i, (name, world) in enumerate(worlds):
        ax = fig.add_subplot(1, len(worlds), i + 1, projection="3d")
        tri = world.triangles
        lo, hi = tri.reshape(-1, 3).min(axis=0), tri.reshape(-1, 3).max(axis=0)
        # Leave out floor and ceiling, as the paper's figure shows its arena open.
        keep = ~(np.all(np.isclose(tri[:, :, 2], hi[2]), axis=1) | np.all(np.isclose(tri[:, :, 2], lo[2]), axis=1))
        ax.add_collection3d(Poly3DCollection(tri[keep], facecolor="tab:orange", edgecolor="k", linewidth=0.1,
                                             alpha=0.35))
        fv = world.flight_volume
        if fv is not None:
            r, z0, z1 = fv["region"], fv["z_min"], fv["z_max"]
            edges = []
            for k in range(len(r)):
                a, b = r[k], r[(k + 1) % len(r)]
                edges += [[(a[0], a[1], z0), (b[0], b[1], z0)], [(a[0], a[1], z1), (b[0], b[1], z1)],
                          [(a[0], a[1], z0), (a[0], a[1], z1)]]
            ax.add_collection3d(Line3DCollection(edges, colors="tab:blue", linewidths=0.8))
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_zlim(lo[2], hi[2])
        ax.set_box_aspect(hi - lo)
        size = " × ".join(f"{d:g}" for d in hi - lo)
        ax.set_title(f"{name}: {size} m (x × y × z)\nblue: flight volume" +
                     (f" z {fv['z_min']:g}–{fv['z_max']:g} m" if fv is not None else ""), fontsize=9)
        ax.set_xlabel("x (m)", fontsize=7)
        ax.set_ylabel("y (m)", fontsize=7)
        ax.set_zlabel("z (m)", fontsize=7)
        ax.tick_params(labelsize=6)
    fig.subplots_adjust(left=0.0, right=0.97, bottom=0.02, top=0.86, wspace=0.1)
    return fig


def make_flight_report(folder, figdir):
    """Draws the figures; returns (file name, sentence) pairs for report.md."""
    drawn = []

    def add(name, sentence, make):
        fig = make()
        if fig is None:
            return
        figures.save(fig, os.path.join(figdir, name))
        drawn.append((name, sentence))

    seed = folder.seeds[0]
    first = f" (the first of seeds {figures.seed_list(folder.seeds)})" if len(folder.seeds) > 1 else ""
    one = f"seed {seed}{first}"
    bars = f"Bars: {folder.spread_text()}."
    add("worlds.png", "The worlds in 3-D (floor and ceiling left out) with their flight volumes (blue): the flying "
        "agent's body, a 0.2 m sphere, stays inside.", lambda: worlds_figure(folder))
    add("trajectory3d.png", f"The flying agent's random walk in {folder.worlds[0]} ({one}): the first minutes in "
        "3-D, and the time spent at each height over the whole sampling phase.", lambda: trajectory_figure(folder))
    add("fields3d.png", f"One single 3-D field (MI = 1) per model in {folder.worlds[0]} ({one}): maximum projections "
        "onto the three planes and slices through the peak voxel, axes in meters.", lambda: fields_figure(folder))
    add("frac_unimodal.png", f"Fraction of place cells with exactly one 3-D field (MI = 1). {bars}",
        lambda: figures.bars_figure(folder, "frac_unimodal"))
    add("frac_multimodal.png",
        f"Fraction of multimodal place cells (MI > 1): cells that fire in several places. {bars}",
        lambda: figures.bars_figure(folder, "frac_multimodal"))
    add("mi_mean.png", f"Mean modality index of the active cells (1: a single field). {bars}",
        lambda: figures.bars_figure(folder, "mean_mi_active"))
    add("isotropy.png", f"Median isotropy of the single fields (sd along z over the mean sd along x and y); the dashed "
        f"line is a round field, as the bats' fields were. {bars}", lambda: isotropy_bars(folder))
    add("isotropy_hist.png",
        "The isotropy of every single field, all seeds pooled: the distribution behind the medians.",
        lambda: isotropy_figure(folder))
    add("msai.png", f"Mean spatial aliasing index over voxels (d_th 2 m in 3-D): lower is better. {bars}",
        lambda: figures.bars_figure(folder, "msai"))
    add("decoding_horizontal.png", f"Median horizontal (x, y) part of the decoding error. {bars}",
        lambda: figures.bars_figure(folder, "decode_horizontal_median_m"))
    add("decoding_vertical.png", "Median vertical (z) part of the decoding error, with the error of a decoder that "
        f"guesses a voxel at random (black marks): a code that does not know the height decodes z at chance. {bars}",
        lambda: vertical_bars(folder))
    return drawn
