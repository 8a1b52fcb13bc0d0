"""The table of docs/navigation.md's "Every world at full size": success, path ratio of the reached starts (median and
quartiles), SPL and starts reached per learning run, per world and model, from the starts make.py wrote at full size
(--seeds 5 --starts 20 --learn-hours 15 --prune 0.01): full-starts.csv, and for the 60° cross arena ms-starts.csv
and ms2-starts.csv (the same protocol, run first). Draws all-worlds.png (success and path ratio per world and
model). Run from the repository root: /usr/bin/python3 docs/navigation/table.py
"""
import csv
import pathlib
import sys

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import make  # noqa: E402  (make.py beside this file: its figure of success and path ratio)
SOURCES = ["full-starts.csv", "ms2-starts.csv", "ms-starts.csv"]
WORLDS = ["nav-open", "nav-cross", "nav-maze", "nav-wall", "cross-0", "cross-60", "floor"]
MODELS = ["2d", "3d-3l", "ms-2d", "ms-3d"]


def rows():
    out = []
    for name in SOURCES:
        if (HERE / name).exists():
            with open(HERE / name, newline="") as f:
                out += list(csv.DictReader(f))
    return out


def stats(mine):
    """Success rate, quartiles of the reached starts' path ratios, SPL (mean of success / max(1, path ratio)), and
    the starts reached per learning run (seed)."""
    ok = [float(r["path_ratio"]) for r in mine if r["success"] == "1"]
    spl = np.mean([1 / max(1.0, float(r["path_ratio"])) if r["success"] == "1" else 0.0 for r in mine])
    seeds = sorted({int(r["seed"]) for r in mine})
    per_run = [sum(1 for r in mine if int(r["seed"]) == s and r["success"] == "1") for s in seeds]
    q = np.percentile(ok, [25, 50, 75]) if ok else [np.nan] * 3
    return len(ok) / len(mine), q, spl, per_run


def main():
    table = rows()
    print("| world | model | starts | success | path ratio, reached: median [q25, q75] | SPL | reached per run |")
    print("|---|---|---|---|---|---|---|")
    found = []
    for world in WORLDS:
        for model in MODELS:
            mine = [r for r in table if r["world"] == world and r["model"] == model]
            if not mine:
                continue
            rate, q, spl, per_run = stats(mine)
            found.append(world)
            print(f"| {world} | {model} | {len(mine)} | {100 * rate:.1f} % ({round(rate * len(mine))}) | "
                  f"{q[1]:.2f} [{q[0]:.2f}, {q[2]:.2f}] | {spl:.2f} | {', '.join(map(str, per_run))} |")
    worlds = [w for w in WORLDS if w in found]
    make.draw_results(table, worlds, MODELS, HERE / "all-worlds.png", log=True,
                      title="5 learning runs × 20 starts per goal, prune 10⁻², learning to SPEC's criteria")

if __name__ == "__main__":
    main()
