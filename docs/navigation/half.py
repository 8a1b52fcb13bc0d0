"""The float16 rollouts against the float32 ones (docs/navigation.md#speed): ms-2d at full size (--seeds 5 --starts 20
--learn-hours 15 --prune 0.01), the same learning walks, the rollouts reading the float32 sparse copy (full-starts.csv,
ms2-starts.csv: the runs of "Every world at full size") or the float16 packed copy (make.py ... --rollout-weights
float16 --prefix h16- and h16w-: h16-starts.csv, h16w-starts.csv). Prints per world the starts reached (per learning
run), the path ratio of the reached, the starts whose walk differs (another path length or time: the rounding changed
a choice) and the starts not in both and, over all worlds, the two proportions' z.
Run from the repository root: /usr/bin/python3 docs/navigation/half.py
"""
import csv
import math
import pathlib

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
FLOAT32 = ["full-starts.csv", "ms2-starts.csv"]
FLOAT16 = ["h16-starts.csv", "h16w-starts.csv"]


def read(names):
    out = []
    for name in names:
        if (HERE / name).exists():
            with open(HERE / name, newline="") as f:
                out += [r for r in csv.DictReader(f) if r["model"] == "ms-2d"]
    return out


def summary(rows, world):
    mine = [r for r in rows if r["world"] == world]
    ok = [float(r["path_ratio"]) for r in mine if r["success"] == "1"]
    seeds = sorted({int(r["seed"]) for r in mine})
    per_run = [sum(r["success"] == "1" for r in mine if int(r["seed"]) == s) for s in seeds]
    return len(mine), len(ok), per_run, (np.median(ok) if ok else float("nan"))


def differing(f32, f16, world):
    """Starts (the same world, learning run, goal and start position) whose walks differ, and which of them succeeded
    with each; and the starts not in both runs (a walk of another length draws the next starts from the learning
    run's generator at another point, so they differ from there on)."""
    key = ("seed", "goal_x", "goal_y", "start_x", "start_y")
    walk = {tuple(r[k] for k in key): r for r in f32 if r["world"] == world}
    mine = [r for r in f16 if r["world"] == world]
    diff, unpaired = [], 0
    for r in mine:
        a = walk.get(tuple(r[k] for k in key))
        if a is None:
            unpaired += 1
        elif (a["path_m"], a["time_s"]) != (r["path_m"], r["time_s"]):
            diff.append((a, r))
    success = sum(a["success"] == "1" for a, _ in diff), sum(b["success"] == "1" for _, b in diff)
    text = f"{len(diff)} (reached: {success[0]} / {success[1]})"
    return text + (f"; {unpaired} other starts" if unpaired else "")


def main():
    f32, f16 = read(FLOAT32), read(FLOAT16)
    worlds = list(dict.fromkeys(r["world"] for r in f16))
    print("| world | float32: reached, per run | float16: reached, per run | path ratio, reached (32 / 16) "
          "| walks that differ |")
    print("|---|---|---|---|---|")
    totals = [[0, 0], [0, 0]]
    for world in worlds:
        a, b = summary(f32, world), summary(f16, world)
        if a[0] == 0:
            continue
        for t, s in zip(totals, (a, b)):
            t[0] += s[0]
            t[1] += s[1]
        print(f"| {world} | {100 * a[1] / a[0]:.1f} % ({a[1]} of {a[0]}): {', '.join(map(str, a[2]))} | "
              f"{100 * b[1] / b[0]:.1f} % ({b[1]} of {b[0]}): {', '.join(map(str, b[2]))} | {a[3]:.2f} / {b[3]:.2f} "
              f"| {differing(f32, f16, world)} |")
    (n1, k1), (n2, k2) = totals
    p1, p2, p = k1 / n1, k2 / n2, (k1 + k2) / (n1 + n2)
    z = (p2 - p1) / math.sqrt(p * (1 - p) * (1 / n1 + 1 / n2))
    print(f"all: float32 {100 * p1:.1f} % of {n1}, float16 {100 * p2:.1f} % of {n2}, z = {z:.2f}")


if __name__ == "__main__":
    main()
