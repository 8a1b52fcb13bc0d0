#!/usr/bin/python3
"""Does the elevation chooser's criterion rank configurations as full trials do? (docs/adaptive.md)

Reads the full trials of a finished `bvc3d sweep configs/sweeps/adaptive-validation.yaml` (its
trials.csv: MSAI per elevation set and tilt), computes the criterion of the same elevation sets on
the chooser's own walks (`bvc3d choose-elevations --sets`, walk seeds that no trial uses), and
prints, per tilt and pooled, Spearman's rank correlation between the two, as Markdown.

    scripts/adaptive_validation.py BVC3D SWEEP_DIR [--walk-seeds 101,102] [--explore-minutes 30] [--jobs 2]
"""
import argparse
import csv
import re
import subprocess
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

import numpy as np
from scipy.stats import spearmanr

ROW = re.compile(r"^\s*(\d+)\s+([-\d., ]+?)\s+(\d+)\s+([-\d.naN]+)\s+([-\d.naN]+)\s*$")


def elevations_of(row):
    """The trial's elevations as a tuple of floats, from the trials.csv row."""
    text = row.get("swept:model.bvc.elevations") or ""
    if row.get("model") == "3d-3l":
        return (0.0, 0.1, 0.2)
    return tuple(float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", text))


def full_trials(sweep_dir):
    """{tilt: {elevations: [msai, ...]}} from trials.csv."""
    out = defaultdict(lambda: defaultdict(list))
    with open(Path(sweep_dir) / "trials.csv") as f:
        for row in csv.DictReader(f):
            out[float(row["tilt_deg"])][elevations_of(row)].append(float(row["msai"]))
    return out


def criterion(bvc3d, tilt, sets, seed, minutes, jobs):
    """{elevations: criterion} from one choose-elevations run on one walk."""
    arg = ";".join(",".join(repr(e) for e in s) for s in sets)
    with tempfile.TemporaryDirectory() as tmp:
        res = subprocess.run([bvc3d, "choose-elevations", "--world", "cross", "--tilt", str(tilt), "--sets", arg,
                              "--seed", str(seed), "--explore-minutes", str(minutes), "--jobs", str(jobs),
                              "--out", str(Path(tmp) / "m.yaml")], capture_output=True, text=True, check=True)
    scores = {}
    for line in res.stdout.splitlines():
        m = ROW.match(line)
        if m:
            scores[tuple(float(v) for v in m.group(2).split(","))] = float(m.group(4))
    if len(scores) != len(sets):
        sys.exit(f"could not read the criterion table:\n{res.stdout}")
    return scores


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bvc3d")
    ap.add_argument("sweep_dir")
    ap.add_argument("--walk-seeds", default="101,102")
    ap.add_argument("--explore-minutes", type=float, default=30)
    ap.add_argument("--jobs", type=int, default=2)
    a = ap.parse_args()
    trials = full_trials(a.sweep_dir)
    seeds = [int(s) for s in a.walk_seeds.split(",")]
    pooled_c, pooled_t = [], []
    print("| tilt | elevations (rad) | full-trial MSAI | criterion, per walk seed " + " / ".join(map(str, seeds)) + " |")
    print("|---|---|---|---|")
    summary = []
    for tilt in sorted(trials):
        sets = sorted(trials[tilt], key=lambda s: (len(s), s))
        per_seed = [criterion(a.bvc3d, tilt, sets, s, a.explore_minutes, a.jobs) for s in seeds]
        full = np.array([np.mean(trials[tilt][s]) for s in sets])
        crit = np.array([np.mean([c[s] for c in per_seed]) for s in sets])
        for s, f in zip(sets, full):
            cs = [c[s] for c in per_seed]
            print(f"| {tilt:g}° | {', '.join(f'{e:g}' for e in s)} | {f:.4f} | {' / '.join(f'{v:.4f}' for v in cs)} |")
        rho = spearmanr(crit, full).statistic
        rho_each = [spearmanr([c[s] for s in sets], full).statistic for c in per_seed]
        best_full, best_crit = sets[int(np.argmin(full))], sets[int(np.argmin(crit))]
        summary.append((tilt, len(sets), rho, rho_each, best_full, best_crit, full[int(np.argmin(crit))], full.min()))
        pooled_c += list(crit)
        pooled_t += list(full)
    print()
    print("| tilt | configurations | Spearman ρ (mean criterion) | ρ per walk | best by full trials | chosen by criterion "
          "| its full-trial MSAI vs the best |")
    print("|---|---|---|---|---|---|---|")
    for tilt, n, rho, each, bf, bc, fc, fb in summary:
        print(f"| {tilt:g}° | {n} | {rho:.2f} | {' / '.join(f'{r:.2f}' for r in each)} | {', '.join(f'{e:g}' for e in bf)} "
              f"| {', '.join(f'{e:g}' for e in bc)} | {fc:.4f} vs {fb:.4f} |")
    print(f"\npooled over {len(pooled_t)} (configuration, tilt) pairs: Spearman ρ = {spearmanr(pooled_c, pooled_t).statistic:.2f}")


if __name__ == "__main__":
    main()
