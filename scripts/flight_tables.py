#!/usr/bin/python3
"""The tables of docs/flying.md from the trial files of a `bvc3d flight` folder.

    PYTHONPATH=build/python /usr/bin/python3 scripts/flight_tables.py results/flight docs/flying

Writes to OUT:
- trials.csv: per trial (world, model, seed) the stored metrics, the number of single fields and the
  share of them that are columns (isotropy > 1.5) or near round (0.5-1.5);
- summary.csv: per world and model the mean and sd over seeds of each of those;
- stacked.csv: per trial the pairs of fields of its multimodal cells (rate-weighted centroids of the
  cell's DBSCAN clusters, the stored analysis's eps and min_samples): how far apart horizontally and
  vertically, the share of pairs within 1 m horizontally and more than 1.5 m apart vertically
  ("stacked"), and the median heights of the lower and the upper field.
Then prints the doc's tables as Markdown.
"""
import argparse
import collections
import csv
import glob
import os

import h5py
import numpy as np

import bvc3d.analysis as an

METRICS = ["frac_unimodal", "frac_multimodal", "isotropy_median", "msai", "decode_horizontal_median_m",
           "decode_vertical_median_m", "decode_vertical_chance_m", "frac_undecoded", "decode_mean_all_m"]
WORLDS = ["flight-room", "atrium", "cross-60"]
MODELS = ["fly-up", "fly-5l", "fly-9l"]


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def analysis_params(f):
    """eps and min_samples of the analysis the trial file was written with (its config)."""
    lines = text(f.attrs["config"]).split("analysis:")[1].splitlines()
    kv = dict(line.strip().split(": ", 1) for line in lines if ": " in line)
    return float(kv["eps"]), int(kv["min_samples"])


def field_pairs(centers, maps, modality, eps, min_samples):
    """(horizontal, vertical, z lower, z upper) per pair of fields of each multimodal cell."""
    pairs = []
    for k in np.flatnonzero(modality > 1):
        on = maps[:, k] > 0
        pts, w = centers[on], maps[on, k]
        labels = an.dbscan_labels(pts, eps=eps, min_samples=min_samples)
        cents = [np.average(pts[labels == c], axis=0, weights=w[labels == c]) for c in sorted(set(labels) - {-1})]
        for i in range(len(cents)):
            for j in range(i + 1, len(cents)):
                lo, hi = sorted((cents[i], cents[j]), key=lambda q: q[2])
                pairs.append((np.hypot(*(hi[:2] - lo[:2])), hi[2] - lo[2], lo[2], hi[2]))
    return np.array(pairs).reshape(-1, 4)


def trial(path):
    with h5py.File(path, "r") as f:
        row = {"world": text(f.attrs["world"]), "model": text(f.attrs["model"]), "seed": int(f.attrs["seed"]),
               "samples": int(f["walk"].attrs["sample_steps"])}
        row.update({m: float(f["metrics"].attrs[m]) for m in METRICS})
        iso = f["metrics/isotropy"][:]
        iso = iso[np.isfinite(iso)]
        row["single_fields"] = len(iso)
        row["frac_columns"] = float(np.mean(iso > 1.5)) if len(iso) else float("nan")
        row["frac_round"] = float(np.mean((iso >= 0.5) & (iso <= 1.5))) if len(iso) else float("nan")
        eps, min_samples = analysis_params(f)
        pairs = field_pairs(f["metrics/bin_centers"][:], f["metrics/rate_maps"][:], f["metrics/modality"][:],
                            eps, min_samples)
    stacked = {"world": row["world"], "model": row["model"], "seed": row["seed"], "pairs": len(pairs)}
    if len(pairs):
        stacked.update({"median_horizontal_m": np.median(pairs[:, 0]), "median_vertical_m": np.median(pairs[:, 1]),
                        "frac_stacked": np.mean((pairs[:, 0] < 1.0) & (pairs[:, 1] > 1.5)),
                        "median_z_lower_m": np.median(pairs[:, 2]), "median_z_upper_m": np.median(pairs[:, 3])})
    return row, stacked


def write_csv(path, rows):
    fields = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, restval="")
        w.writeheader()
        w.writerows(rows)


def cell(values, digits):
    v = np.array([x for x in values if np.isfinite(x)])
    if not len(v):
        return "–"
    sd = f" ± {np.std(v, ddof=1):.{digits}f}" if len(v) > 1 else ""
    return f"{np.mean(v):.{digits}f}{sd}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder")
    ap.add_argument("out")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    results = [trial(p) for p in sorted(glob.glob(os.path.join(a.folder, "*.h5")))]
    rows = [r for r, _ in results]
    stacked = [s for _, s in results]
    write_csv(os.path.join(a.out, "trials.csv"), rows)
    write_csv(os.path.join(a.out, "stacked.csv"), stacked)
    groups = collections.defaultdict(list)
    for r in rows:
        groups[(r["world"], r["model"])].append(r)
    order = sorted(groups, key=lambda k: (WORLDS.index(k[0]) if k[0] in WORLDS else 99,
                                          MODELS.index(k[1]) if k[1] in MODELS else 99, k))
    columns = METRICS + ["frac_columns", "frac_round", "samples"]
    summary = []
    for key in order:
        g = groups[key]
        s = {"world": key[0], "model": key[1], "seeds": len(g)}
        for m in columns:
            v = np.array([r[m] for r in g], dtype=float)
            s[m + "_mean"] = np.nanmean(v) if np.isfinite(v).any() else float("nan")
            s[m + "_sd"] = np.nanstd(v, ddof=1) if np.isfinite(v).sum() > 1 else float("nan")
        summary.append(s)
    write_csv(os.path.join(a.out, "summary.csv"), summary)

    print("| world | model | MI = 1 | MI > 1 | isotropy (median) | columns | horizontal error (m) "
          "| vertical error (m) | vertical chance (m) | undecoded | mean error, all (m) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    digits = {"frac_unimodal": 2, "frac_multimodal": 3, "isotropy_median": 2, "frac_columns": 2,
              "decode_horizontal_median_m": 2, "decode_vertical_median_m": 2, "decode_vertical_chance_m": 2,
              "frac_undecoded": 2, "decode_mean_all_m": 2}
    for key in order:
        g = groups[key]
        print(f"| {key[0]} | {key[1]} | " + " | ".join(cell([r[m] for r in g], d) for m, d in digits.items()) + " |")
    print("\nStacked fields of multimodal cells (per trial with pairs):\n")
    print("| world | model | seed | pairs | median horizontal (m) | median vertical (m) | stacked "
          "| z lower / upper (m) |")
    print("|---|---|---|---|---|---|---|---|")
    for s in stacked:
        if s["pairs"]:
            print(f"| {s['world']} | {s['model']} | {s['seed']} | {s['pairs']} | {s['median_horizontal_m']:.2f} | "
                  f"{s['median_vertical_m']:.2f} | {s['frac_stacked']:.2f} | "
                  f"{s['median_z_lower_m']:.2f} / {s['median_z_upper_m']:.2f} |")


if __name__ == "__main__":
    main()
