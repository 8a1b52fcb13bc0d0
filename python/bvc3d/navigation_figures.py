"""Figures of a `bvc3d navigate` folder (docs/navigation.md): paths over the world with the goal, the reward map,
and path ratio against learning time. Run: python3 -m bvc3d.navigation_figures FOLDER [WORLD]"""
import csv
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .figures import save  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([r[k] for r in rows]) for k in (rows[0].keys() if rows else [])}


def floats(table, key):
    return table[key].astype(float)


def only(table, model):
    """The rows of one model (tables of several models carry a model column)."""
    if not table or "model" not in table:
        return table
    pick = table["model"] == model
    return {k: v[pick] for k, v in table.items()}


def reward_background(ax, maps, seed, goal):
    pick = (floats(maps, "seed") == seed) & (floats(maps, "goal") == goal)
    sc = ax.scatter(floats(maps, "x")[pick], floats(maps, "y")[pick], c=floats(maps, "reward")[pick], s=12,
                    marker="s", cmap="viridis", linewidths=0)
    return sc


def main(folder, world=""):
    """Draws the figures; prints (and returns) the names of those it wrote."""
    folder = pathlib.Path(folder)
    drawn = []
    starts, paths, maps, learning = (read(folder / n) for n in ("starts.csv", "paths.csv", "reward_map.csv",
                                                                 "learning.csv"))
    model = starts["model"][0]  # the figures show the first model of the folder
    starts, paths, maps, learning = (only(t, model) for t in (starts, paths, maps, learning))
    seeds = np.unique(floats(starts, "seed"))
    seed = seeds[0]
    goals = sorted({(float(x), float(y)) for x, y in zip(starts["goal_x"], starts["goal_y"])})
    # Paths over the world (its free floor as the reward map's points) with each goal, the first seed.
    fig, axes = plt.subplots(1, len(goals), figsize=(5 * len(goals), 5), squeeze=False)
    index = np.arange(len(starts["seed"]))
    for g, (gx, gy) in enumerate(goals):
        ax = axes[0, g]
        if maps:
            reward_background(ax, maps, seed, g).set_alpha(0.35)
        mine = index[(floats(starts, "seed") == seed) & (floats(starts, "goal_x") == gx) &
                     (floats(starts, "goal_y") == gy)]
        first = index[floats(starts, "seed") == seed][0]
        for i in mine:
            pick = (floats(paths, "seed") == seed) & (floats(paths, "start") == i - first)
            ok = starts["success"][i] == "1"
            ax.plot(floats(paths, "x")[pick], floats(paths, "y")[pick], lw=0.8, color="C0" if ok else "C3")
            ax.plot(float(starts["start_x"][i]), float(starts["start_y"][i]), "o", ms=3, color="k")
        ax.plot(gx, gy, "*", ms=16, color="gold", mec="k")
        ax.add_patch(plt.Circle((gx, gy), 1.0, fill=False, ls="--", color="k"))
        ax.set_aspect("equal")
        ax.set_title(f"goal ({gx:g}, {gy:g}): paths (blue reached, red failed)")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    fig.suptitle(f"{world}, model {model}, seed {seed:g}")
    save(fig, folder / "paths.png")
    drawn.append("paths.png")
    # The reward maps of the first seed.
    if maps:
        fig, axes = plt.subplots(1, len(goals), figsize=(5 * len(goals), 4.4), squeeze=False)
        for g, (gx, gy) in enumerate(goals):
            ax = axes[0, g]
            fig.colorbar(reward_background(ax, maps, seed, g), ax=ax, label="reward read-out r")
            ax.plot(gx, gy, "*", ms=16, color="gold", mec="k")
            ax.set_aspect("equal")
            ax.set_title(f"reward cell of goal ({gx:g}, {gy:g}) after replay")
        save(fig, folder / "reward_map.png")
        drawn.append("reward_map.png")
    # Path ratio against learning time: each learning run's median over its reached starts.
    fig, ax = plt.subplots(figsize=(5.5, 4))
    learn = {float(s): float(t) / 3600 for s, t in zip(learning["seed"], learning["learn_s"])}
    for s in seeds:
        pick = (floats(starts, "seed") == s) & (starts["success"] == "1")
        if pick.any():
            ax.plot(learn[s], np.median(floats(starts, "path_ratio")[pick]), "o", color="C0")
    ax.set_xlabel("learning time (simulated h)")
    ax.set_ylabel("path ratio (median of reached starts)")
    ax.set_title(f"path ratio against learning time ({model})")
    save(fig, folder / "path_ratio_learning.png")
    drawn.append("path_ratio_learning.png")
    print(f"drew {', '.join(drawn)} in {folder}")
    return drawn


if __name__ == "__main__":
    main(*sys.argv[1:])
