"""Regenerates the grid-cell section of docs/building-scale.md: how decoding degrades when grid cells are fed by path
integration with noise instead of the true position.

    /usr/bin/python3 docs/building-scale/path_integration.py [--work DIR] [--seeds 3] [--hours 0.25,1,2]
                                                             [--noise 0,0.001,0.003,0.01,0.03]

Each trial is `bvc3d run` in the paper's upright cross arena, the paper's protocol (explore, then sample) with both
phases shortened to H simulated hours, and a model of the paper's 2-D BVCs plus two populations: one grid module
(λ = 4 m, 800 cells) fed by path integration with noise sd σ m per axis per model step (σ = 0: the true position),
and 250 place cells reading the BVCs and the grid cells (grid_influence 0.3, grid_p_connect 0.3: the small scale
of the multiscale presets). The paper's place cells (BVCs only) run beside them in the same trial. Every population
is decoded as docs/analysis.md says (rate maps of the first half of the sample phase, the second half decoded).
The path-integration error at step k is a random walk of sd σ·√k per axis, so a longer trial means a larger drift.

Writes path-integration.csv (one row per trial and population) and path-integration.png next to this script; the
trial files go to --work (default /tmp/bvc3d-path-integration) and a trial already there is not run again. Run from
the repository's root after building (build/bvc3d).
"""
import argparse
import csv
import pathlib
import subprocess
import sys

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
BVC3D = ROOT / "build" / "bvc3d"
STEP_S = 0.288  # the model step (docs/model-reference.md)
# The populations read from each trial file: (label, HDF5 group of its metrics).
POPULATIONS = [("grid", "populations/grid/metrics"), ("place, BVC + grid", "populations/place-g/metrics"),
               ("place, BVC only (paper)", "metrics")]
METRICS = ["decode_median_m", "decode_median_all_m", "frac_undecoded", "frac_multimodal"]


def model_yaml(noise):
    grid = "input: pose" if noise == 0 else f"input: path, path_noise: {noise:g}"
    return (f"name: grid-path-{noise:g}\nbase: 2d\npopulations:\n"
            f"  - {{name: grid, kind: grid, spacing: 4, n: 800, {grid}}}\n"
            "  - {name: place-g, kind: place, inputs: [bvc, grid], n_place: 250, grid_influence: 0.3, "
            "grid_p_connect: 0.3}\n")


def run_trial(work, noise, hours, seed):
    model = work / f"model-{noise:g}.yaml"
    model.write_text(model_yaml(noise))
    out = work / f"trial-{noise:g}-{hours:g}h-{seed}.h5"
    cmd = [str(BVC3D), "run", "--world", "cross", "--tilt", "0", "--model", str(model), "--hours", f"{hours:g}",
           "--seed", str(seed), "--out", str(out)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return out


def read_rows(path, noise, hours, seed):
    import h5py
    rows = []
    with h5py.File(path, "r") as f:
        steps = int(round(2 * hours * 3600 / STEP_S))  # both phases
        for label, group in POPULATIONS:
            a = f[group].attrs
            row = {"noise_m_per_step": noise, "hours_per_phase": hours, "seed": seed, "population": label,
                   "path_error_sd_m_at_end": noise * np.sqrt(steps)}
            for m in METRICS:
                row[m] = float(a[m]) if m in a else float("nan")
            rows.append(row)
    return rows


def figure(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    hours = sorted({r["hours_per_phase"] for r in rows})
    noises = sorted({r["noise_m_per_step"] for r in rows})
    fig, axes = plt.subplots(1, len(POPULATIONS), figsize=(4.2 * len(POPULATIONS), 3.6), sharey=True)
    for ax, (label, _) in zip(axes, POPULATIONS):
        for h in hours:
            med = [np.median([r["decode_median_m"] for r in rows
                              if r["population"] == label and r["hours_per_phase"] == h and r["noise_m_per_step"] == s])
                   for s in noises]
            ax.plot(range(len(noises)), med, marker="o", label=f"{h:g} h + {h:g} h")
        ax.set_xticks(range(len(noises)), [f"{s:g}" for s in noises])
        ax.set_title(label, fontsize=10)
        ax.set_xlabel("path-integration noise σ (m per axis per step)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("median decoding error (m)")
    axes[0].legend(title="explore + sample", fontsize=8)
    fig.suptitle("Upright cross arena, 2-D BVCs; grid module λ = 4 m fed by noisy path integration "
                 "(median over seeds)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--work", type=pathlib.Path, default=pathlib.Path("/tmp/bvc3d-path-integration"))
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--hours", default="0.25,1,2", help="simulated hours of each phase, comma-separated")
    parser.add_argument("--noise", default="0,0.001,0.003,0.01,0.03", help="σ, m per axis per model step")
    args = parser.parse_args()
    if not BVC3D.exists():
        sys.exit(f"path_integration.py: {BVC3D} not found: build bvc3d first (README)")
    args.work.mkdir(parents=True, exist_ok=True)
    rows = []
    for hours in [float(h) for h in args.hours.split(",")]:
        for noise in [float(s) for s in args.noise.split(",")]:
            for seed in range(args.seeds):
                trial = run_trial(args.work, noise, hours, seed)
                rows += read_rows(trial, noise, hours, seed)
                print(f"σ {noise:g}, {hours:g} h, seed {seed}: " + ", ".join(
                    f"{r['population']} {r['decode_median_m']:.2f} m" for r in rows[-len(POPULATIONS):]),
                      flush=True)
    with open(HERE / "path-integration.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    figure(rows, HERE / "path-integration.png")


if __name__ == "__main__":
    main()
