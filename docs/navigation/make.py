"""Navigation results for docs/navigation.md: runs `bvc3d navigate` per world and model, gathers every start into
docs/navigation/starts.csv and the per-goal summaries into docs/navigation/summary.csv, and draws
docs/navigation/results.png (success rate and path ratio per world and model).

Run from the repository root after building: /usr/bin/python3 docs/navigation/make.py [--seeds N] [--starts N]
[--learn-hours H] [--models 2d,3d-3l,ms-2d,ms-3d] [--worlds nav-open,...] [--prune P]
[--rollout-weights float32|float16] [--prefix P] [--house DIR] [--gather]. The world `floor` is the AWS RoboMaker
small house's floor (Gazebo), read from the folder given by --house (holding worlds/ and models/ as AWS publishes
it); the other worlds are in configs/worlds/.
--gather runs nothing and gathers the worlds and models already run. Each run's own
folder (paths, reward maps, figures, and runs/ with each finished learning run: a run again with the same options
skips those) is kept in build/navigation/PREFIXWORLD-MODEL/; the learning runs' times go to PREFIXlearning.csv.
"""
import argparse
import csv
import pathlib
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
HERE = ROOT / "docs" / "navigation"
GOALS = {"nav-open": "7,7;-7,7;-7,-7;7,-7", "nav-cross": "7,7;-7,7;-7,-7;7,-7", "nav-maze": "7,7;-7,7;-7,-7;7,-7",
         "nav-wall": "-2,2", "cross-0": "3.5,3.5;-3.5,-3.5", "cross-60": "3.5,3.5;-3.5,-3.5",
         "floor": "5,2;-5,-2"}
HOUSE_WORLD = "worlds/small_house.world"  # in the folder given by --house


def world_arg(name, house, folder):
    """The world's file: configs/worlds/NAME.yaml, or for `floor` a world YAML written into folder pointing at the
    small house (its furniture models are in the house's models/ folder; skip those it does not ship)."""
    if name == "floor":
        if house is None or not (house / HOUSE_WORLD).is_file():
            sys.exit(f"world floor needs --house: the small house's folder holding {HOUSE_WORLD}")
        file = folder / "floor.yaml"
        file.write_text(f"sdf: {(house / HOUSE_WORLD).resolve()}\nmodel_path: [{(house / 'models').resolve()}]\n"
                        "missing_models: skip\n")
        return str(file)
    file = ROOT / "configs" / "worlds" / f"{name}.yaml"
    return str(file) if file.exists() else name


def gather(out, world, rows, summary, learning):
    """Adds a run's starts, per-goal summary and learning times (these with the world) to the tables."""
    for name, table in (("starts.csv", rows), ("summary.csv", summary), ("learning.csv", learning)):
        with open(out / name, newline="") as f:
            table += [dict(r, world=world) if name == "learning.csv" else r for r in csv.DictReader(f)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--starts", type=int, default=20)
    ap.add_argument("--learn-hours", type=float, default=15)
    ap.add_argument("--models", default="2d,3d-3l")
    ap.add_argument("--worlds", default="nav-open,nav-cross,nav-maze,nav-wall,cross-0,cross-60")
    ap.add_argument("--prefix", default="", help="prefix of the files written (a partial run beside the main one)")
    ap.add_argument("--prune", type=float, default=0.0, help="adjacency.prune (0.01 for the multiscale sizes)")
    ap.add_argument("--rollout-weights", choices=["float32", "float16"], default="float32",
                    help="adjacency.rollout_weights (float16: the rollouts read 16-bit weights)")
    ap.add_argument("--bvc3d", default=str(ROOT / "build" / "bvc3d"), help="the program to run")
    ap.add_argument("--house", type=pathlib.Path, help="the small house's folder (world floor)")
    ap.add_argument("--gather", action="store_true",
                    help="run nothing: gather the worlds and models whose runs are finished (their starts.csv)")
    a = ap.parse_args()
    rows, summary, learning = [], [], []
    for world in a.worlds.split(","):
        for model in a.models.split(","):
            out = ROOT / "build" / "navigation" / f"{a.prefix}{world}-{model}"
            if a.gather:
                if (out / "starts.csv").exists():
                    gather(out, world, rows, summary, learning)
                else:
                    print(f"{world} {model}: not run, left out", file=sys.stderr)
                continue
            out.mkdir(parents=True, exist_ok=True)
            # A YAML file: the options of the command line and the adjacency's copy (pruning, weights), which have no
            # option.
            config = out.parent / f"{a.prefix}{world}-{model}.yaml"
            goals = [[float(c) for c in g.split(",")] for g in GOALS[world].split(";")]
            config.write_text(f"world: {world_arg(world, a.house, out.parent)}\ngoals: {goals}\nmodels: [{model}]\n"
                              f"seeds: {a.seeds}\n"
                              f"navigation: {{starts: {a.starts}, max_learn_hours: {a.learn_hours}}}\n"
                              f"adjacency: {{prune: {a.prune}, rollout_weights: {a.rollout_weights}}}\n")
            cmd = [a.bvc3d, "navigate", "--config", str(config), "--out", str(out)]
            print(" ".join(cmd), file=sys.stderr, flush=True)
            subprocess.run(cmd, check=True)
            gather(out, world, rows, summary, learning)
    for name, table in (("starts.csv", rows), ("summary.csv", summary), ("learning.csv", learning)):
        with open(HERE / (a.prefix + name), "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(table[0].keys()))
            w.writeheader()
            w.writerows(table)
    worlds = list(dict.fromkeys(r["world"] for r in rows))
    models = list(dict.fromkeys(r["model"] for r in rows))
    draw_results(rows, worlds, models, HERE / (a.prefix + "results.png"))


def draw_results(rows, worlds, models, path, title=None, log=False):
    """Per world and model over all goals and learning runs: success rate, and the path ratio of the reached starts
    (median, quartiles); a world without starts of a model has no bar."""
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4))
    width = 0.8 / len(models)
    for m, model in enumerate(models):
        rate, med, lo, hi = [], [], [], []
        for world in worlds:
            mine = [r for r in rows if r["world"] == world and r["model"] == model]
            ok = [float(r["path_ratio"]) for r in mine if r["success"] == "1"]
            rate.append(100 * len(ok) / len(mine) if mine else np.nan)
            q = np.percentile(ok, [25, 50, 75]) if ok else [np.nan] * 3
            lo.append(q[1] - q[0]), med.append(q[1]), hi.append(q[2] - q[1])
        x = np.arange(len(worlds)) + m * width
        ax1.bar(x, rate, width, label=model)
        ax2.bar(x, med, width, yerr=[lo, hi], label=model, capsize=3)
    for ax, label in ((ax1, "starts reached (%)"), (ax2, "path ratio of reached starts\n(median, quartiles)")):
        ax.set_xticks(np.arange(len(worlds)) + 0.4 - width / 2, worlds, rotation=20)
        ax.set_ylabel(label)
        ax.legend(fontsize=8)
    if log:
        ax2.set_yscale("log")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)

if __name__ == "__main__":
    main()
