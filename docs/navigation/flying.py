"""The flying agent's navigation result for docs/navigation.md#flying-to-goals-in-3-d: runs `bvc3d navigate` in the
atrium with goals at two heights (one above the mezzanine slab, one near the floor) per model, gathers every start
into docs/navigation/flying-starts.csv and the per-goal summaries into docs/navigation/flying-summary.csv, and draws
docs/navigation/flying-paths.png (the first learning run's first two paths to each goal,
seen from the side, x–z, and from above, x–y).

Run from the repository root after building: /usr/bin/python3 docs/navigation/flying.py [--seeds N] [--starts N]
[--learn-hours H] [--models fly-up,fly-5l,fly-9l] [--beta B --prefix P]. `--beta 0 --prefix flying-blind` is the
blind baseline (directions drawn uniformly from those offered), written to flying-blind-*.csv. Each model's own
folder (with runs/: a run again with the same options skips the finished learning runs) is kept in
build/navigation/PREFIX-atrium-MODEL/.
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
# Above the mezzanine slab (x -5 to -3.5, top at z = 3.0), and near the floor in the open hall.
GOALS = [[-4.2, 0.0, 3.8], [2.5, 2.5, 0.8]]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--starts", type=int, default=10)
    ap.add_argument("--learn-hours", type=float, default=15)
    ap.add_argument("--models", default="fly-up,fly-5l,fly-9l")
    ap.add_argument("--beta", type=float, help="reward.beta (0: a blind agent); default SPEC's 500")
    ap.add_argument("--prefix", default="flying", help="prefix of the files and folders written")
    ap.add_argument("--bvc3d", default=str(ROOT / "build" / "bvc3d"), help="the program to run")
    a = ap.parse_args()
    rows, summary, folders = [], [], {}
    for model in a.models.split(","):
        out = ROOT / "build" / "navigation" / f"{a.prefix}-atrium-{model}"
        out.mkdir(parents=True, exist_ok=True)
        config = out.parent / f"{a.prefix}-atrium-{model}.yaml"
        config.write_text(f"world: atrium\ngoals: {GOALS}\nmodels: [{model}]\nseeds: {a.seeds}\n"
                          f"navigation: {{starts: {a.starts}, max_learn_hours: {a.learn_hours}}}\n" +
                          (f"reward: {{beta: {a.beta}}}\n" if a.beta is not None else ""))
        cmd = [a.bvc3d, "navigate", "--config", str(config), "--out", str(out), "--no-report"]
        print(" ".join(cmd), file=sys.stderr, flush=True)
        subprocess.run(cmd, check=True)
        folders[model] = out
        for name, table in (("starts.csv", rows), ("summary.csv", summary)):
            with open(out / name, newline="") as f:
                table += list(csv.DictReader(f))
    for name, table in ((f"{a.prefix}-starts.csv", rows), (f"{a.prefix}-summary.csv", summary)):
        with open(HERE / name, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(table[0].keys()), lineterminator="\n")
            w.writeheader()
            w.writerows(table)
    figure(folders, rows, HERE / f"{a.prefix}-paths.png")
    print_table(rows)


def print_table(rows):
    """The table of docs/navigation.md: per model and goal, starts, success and path ratio of the reached starts."""
    print("| model | goal (x, y, z) | starts | success | path ratio of reached starts, median [q25, q75] |")
    print("|---|---|---|---|---|")
    keys = sorted({(r["model"], r["goal_x"], r["goal_y"], r["goal_z"]) for r in rows},
                  key=lambda k: (k[0], -float(k[3])))
    for model, gx, gy, gz in keys:
        mine = [r for r in rows if (r["model"], r["goal_x"], r["goal_y"], r["goal_z"]) == (model, gx, gy, gz)]
        ok = [float(r["path_ratio"]) for r in mine if r["success"] == "1"]
        q = np.percentile(ok, [50, 25, 75]) if ok else [np.nan] * 3
        print(f"| {model} | ({gx}, {gy}, {gz}) | {len(mine)} | {100 * len(ok) / len(mine):.0f} % ({len(ok)}) | "
              f"{q[0]:.2f} [{q[1]:.2f}, {q[2]:.2f}] |")


def figure(folders, rows, file, shown=2):
    """Per model (rows) the first learning run's first `shown` paths to each goal, side (x–z) and top (x–y) views."""
    models = list(folders)
    fig, axes = plt.subplots(len(models), 2, figsize=(11, 4.6 * len(models)), squeeze=False)
    for m, model in enumerate(models):
        with open(folders[model] / "paths.csv", newline="") as f:
            paths = list(csv.DictReader(f))
        mine = [r for r in rows if r["model"] == model]
        seed = mine[0]["seed"]
        runs = [r for r in mine if r["seed"] == seed]
        index = {id(r): s for s, r in enumerate(runs)}  # a start's number in its run (paths.csv's start)
        goals = sorted({(r["goal_x"], r["goal_y"], r["goal_z"]) for r in runs})
        picked = [r for g in goals for r in [r for r in runs if (r["goal_x"], r["goal_y"], r["goal_z"]) == g][:shown]]
        for view, (i, j, label) in enumerate(((0, 2, "z"), (0, 1, "y"))):
            ax = axes[m, view]
            # The mezzanine slab (x −5 to −3.5 and 3.5 to 5 seen from the side) and the pillars seen from above.
            if label == "z":
                for x0 in (-5.0, 3.5):
                    ax.add_patch(plt.Rectangle((x0, 2.8), 1.5, 0.2, color="0.6"))
                ax.set_ylim(0, 6)
            else:
                ax.add_patch(plt.Rectangle((-5, -5), 10, 10, fill=False, color="0.6", hatch="//", lw=0))
                ax.add_patch(plt.Rectangle((-3.5, -3.5), 7, 7, color="white"))
                for cx, cy in ((-1.5, 1.0), (2.0, -1.5)):
                    ax.add_patch(plt.Rectangle((cx - 0.3, cy - 0.3), 0.6, 0.6, color="0.4"))
                ax.set_ylim(-5, 5)
            for r in picked:
                s = index[id(r)]
                pts = np.array([[float(p["x"]), float(p["y"]), float(p["z"])] for p in paths
                                 if p["seed"] == seed and p["start"] == str(s)])
                ok = r["success"] == "1"
                ax.plot(pts[:, i], pts[:, j], lw=0.7, color="C0" if ok else "C3", alpha=0.8)
                ax.plot(pts[0, i], pts[0, j], "o", ms=3, color="k")
            for g in GOALS:
                ax.plot(g[i], g[j], "*", ms=15, color="gold", mec="k")
            ax.set_xlim(-5, 5)
            ax.set_aspect("equal")
            ax.set_xlabel("x (m)")
            ax.set_ylabel(f"{label} (m)")
            ax.set_title(f"{model}, seed {seed}: {'side (x–z)' if label == 'z' else 'top (x–y)'}; "
                         "blue reached, red failed")
    fig.tight_layout()
    fig.savefig(file, dpi=60)


if __name__ == "__main__":
    main()
