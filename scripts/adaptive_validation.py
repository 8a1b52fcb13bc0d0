#!/usr/bin/python3
"""Does the elevation chooser's criterion rank configurations as full trials do? (docs/adaptive.md)

Reads the full trials of a finished `bvc3d sweep configs/sweeps/adaptive-validation.yaml` (its
trials.csv: MSAI per elevation set and tilt), computes the criterion of the same elevation sets on
the chooser's own walks (`bvc3d choose-elevations --sets`, walk seeds that no trial uses), and
prints, per tilt and pooled, Spearman's rank correlation between the two, as Markdown. The same for
the BVC population's aliasing on the walks (the chooser prints it beside the criterion): does the
input's aliasing predict the place cells'? --figure draws both as scatter plots over every
configuration.

    scripts/adaptive_validation.py BVC3D SWEEP_DIR [--walk-seeds 101,102] [--explore-minutes 30] [--jobs 2]
                                   [--figure docs/adaptive/aliasing-scatter.png]
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

ROW = re.compile(r"^\s*(\d+)\s+([-\d., ]+?)\s+(\d+)\s+([-\d.naN]+)\s+([-\d.naN]+)\s+([-\d.naN]+)\s*$")


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
    """{elevations: (criterion, BVC MSAI)} from one choose-elevations run on one walk."""
    arg = ";".join(",".join(repr(e) for e in s) for s in sets)
    with tempfile.TemporaryDirectory() as tmp:
        res = subprocess.run([bvc3d, "choose-elevations", "--world", "cross", "--tilt", str(tilt), "--sets", arg,
                              "--seed", str(seed), "--explore-minutes", str(minutes), "--jobs", str(jobs),
                              "--out", str(Path(tmp) / "m.yaml")], capture_output=True, text=True, check=True)
    scores = {}
    for line in res.stdout.splitlines():
        m = ROW.match(line)
        if m:
            scores[tuple(float(v) for v in m.group(2).split(","))] = (float(m.group(4)), float(m.group(6)))
    if len(scores) != len(sets):
        sys.exit(f"could not read the criterion table:\n{res.stdout}")
    return scores


def figure(path, points):
    """Full-trial MSAI against the BVC population's MSAI and against the criterion, one color per tilt."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(9, 4), constrained_layout=True)
    for ax, key, label in ((axes[0], "bvc", "BVC population's MSAI on the walks"),
                           (axes[1], "crit", "criterion: place cells' MSAI on the walks")):
        for tilt in sorted({p["tilt"] for p in points}):
            mine = [p for p in points if p["tilt"] == tilt]
            ax.errorbar([p[key] for p in mine], [p["full"] for p in mine], yerr=[p["full_sd"] for p in mine],
                        fmt="o", ms=4, capsize=2, label=f"{tilt:g}°")
        rho = spearmanr([p[key] for p in points], [p["full"] for p in points]).statistic
        ax.set_xlabel(label)
        ax.set_title(f"Spearman ρ = {rho:.2f} over {len(points)} configurations", fontsize=10)
    axes[0].set_ylabel("place cells' MSAI in full trials (mean ± sd over seeds)")
    axes[1].legend(title="tilt", fontsize=8)
    fig.savefig(path, dpi=120)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bvc3d")
    ap.add_argument("sweep_dir")
    ap.add_argument("--walk-seeds", default="101,102")
    ap.add_argument("--explore-minutes", type=float, default=30)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--figure", help="write the scatter plots here (PNG)")
    a = ap.parse_args()
    trials = full_trials(a.sweep_dir)
    seeds = [int(s) for s in a.walk_seeds.split(",")]
    points = []
    print("| tilt | elevations (rad) | full-trial MSAI (mean ± sd, seeds) | criterion, per walk seed "
          + " / ".join(map(str, seeds)) + " | BVC MSAI, per walk |")
    print("|---|---|---|---|---|")
    summary = []
    for tilt in sorted(trials):
        sets = sorted(trials[tilt], key=lambda s: (len(s), s))
        per_seed = [criterion(a.bvc3d, tilt, sets, s, a.explore_minutes, a.jobs) for s in seeds]
        full = np.array([np.mean(trials[tilt][s]) for s in sets])
        crit = np.array([np.mean([c[s][0] for c in per_seed]) for s in sets])
        bvc = np.array([np.mean([c[s][1] for c in per_seed]) for s in sets])
        for s, f, cr, b in zip(sets, full, crit, bvc):
            sd = np.std(trials[tilt][s], ddof=1) if len(trials[tilt][s]) > 1 else 0.0
            points.append(dict(tilt=tilt, full=f, full_sd=sd, crit=cr, bvc=b))
            print(f"| {tilt:g}° | {', '.join(f'{e:g}' for e in s)} | {f:.4f} ± {sd:.4f} ({len(trials[tilt][s])}) "
                  f"| {' / '.join(f'{c[s][0]:.4f}' for c in per_seed)} "
                  f"| {' / '.join(f'{c[s][1]:.4f}' for c in per_seed)} |")
        rho = spearmanr(crit, full).statistic
        rho_each = [spearmanr([c[s][0] for s in sets], full).statistic for c in per_seed]
        rho_bvc = spearmanr(bvc, full).statistic
        best_full, best_crit = sets[int(np.argmin(full))], sets[int(np.argmin(crit))]
        summary.append((tilt, len(sets), rho, rho_each, rho_bvc, best_full, best_crit, full[int(np.argmin(crit))],
                        full.min()))
    print()
    print("| tilt | configurations | Spearman ρ (mean criterion) | ρ per walk | ρ of the BVC MSAI "
          "| best by full trials "
          "| chosen by criterion | its full-trial MSAI vs the best |")
    print("|---|---|---|---|---|---|---|---|")
    for tilt, n, rho, each, rb, bf, bc, fc, fb in summary:
        print(f"| {tilt:g}° | {n} | {rho:.2f} | {' / '.join(f'{r:.2f}' for r in each)} | {rb:.2f} "
              f"| {', '.join(f'{e:g}' for e in bf)} | {', '.join(f'{e:g}' for e in bc)} | {fc:.4f} vs {fb:.4f} |")
    full_all = [p["full"] for p in points]
    print(f"\npooled over {len(points)} (configuration, tilt) pairs: Spearman ρ = "
          f"{spearmanr([p['crit'] for p in points], full_all).statistic:.2f} (criterion), "
          f"{spearmanr([p['bvc'] for p in points], full_all).statistic:.2f} (BVC MSAI)")
    if a.figure:
        figure(a.figure, points)


if __name__ == "__main__":
    main()
