#!/usr/bin/python3
"""How the paper's findings depend on the analysis parameters (docs/reproduction.md).

Re-analyzes the trial files of an experiment folder with other DBSCAN min_samples and rate-map
quantiles (one parameter at a time around the default values) and prints, per setting, model and
world, the mean over seeds of MI>0, mean MI, MI>1 and MSAI.

    PYTHONPATH=build/python /usr/bin/python3 scripts/sensitivity.py results/paper [--jobs 2] [--csv out.csv]
"""
import argparse
import csv
import glob
import os
import sys
from multiprocessing import Pool

import h5py
import numpy as np

import bvc3d.analysis as an

SETTINGS = [("min_samples", v) for v in (5, 10, 20, 40)] + [("quantile", v) for v in (0.5, 0.9, 0.95)]


def analyze(path):
    with h5py.File(path, "r") as f:
        x, y, rates = f["samples/x"][:], f["samples/y"][:], f["samples/rates"][:]
        model, world = f.attrs["model"], f.attrs["world"]
    out = []
    for name, value in SETTINGS:
        q = value if name == "quantile" else 0.1
        ms = value if name == "min_samples" else 20
        centers, maps = an.rate_maps(x, y, rates, quantile=q)
        mi = an.modality(centers, maps, min_samples=ms)
        s = an.modality_summary(mi)
        _, msai = an.aliasing(centers, maps)
        out.append((name, value, model, world, s["frac_active"], s["mean_mi_active"], s["frac_multimodal"], msai))
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    p.add_argument("folder")
    p.add_argument("--jobs", type=int, default=os.cpu_count())
    p.add_argument("--csv", help="also write every row to this CSV")
    args = p.parse_args()
    files = sorted(glob.glob(os.path.join(args.folder, "*.h5")))
    if not files:
        sys.exit(f"no trial files in {args.folder}")
    with Pool(args.jobs) as pool:
        rows = [r for per_file in pool.map(analyze, files) for r in per_file]
    groups = {}
    for r in rows:
        groups.setdefault(r[:4], []).append(r[4:])
    header = ["parameter", "value", "model", "world", "frac_active", "mean_mi_active", "frac_multimodal", "msai"]
    table = [list(k) + list(np.nanmean(np.array(v, dtype=float), axis=0)) for k, v in groups.items()]
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            csv.writer(f).writerows([header] + table)
    for name, value in SETTINGS:
        print(f"\n{name} = {value}")
        print(f"{'model':10} {'world':9} {'MI>0':>6} {'meanMI':>7} {'MI>1':>6} {'MSAI':>8}")
        for row in table:
            if row[0] == name and row[1] == value:
                print(f"{row[2]:10} {row[3]:9} {row[4]:6.3f} {row[5]:7.2f} {row[6]:6.3f} {row[7]:8.4f}")


if __name__ == "__main__":
    main()
