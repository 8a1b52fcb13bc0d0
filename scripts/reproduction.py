#!/usr/bin/python3
"""The tables of docs/reproduction.md from the experiment folders its commands write.

    PYTHONPATH=build/python /usr/bin/python3 scripts/reproduction.py results/repro docs/reproduction [--jobs 2]

Reads the folders spec, s1-protocol, s2-reading, s3-geometry, s4-robot, s5-labels and authors
under RESULTS (each written by `bvc3d paper`, see the doc), and writes to OUT:

- <folder>-trials.csv: every trial's metrics and sample count (from the trial files);
- s6-lag-trials.csv: the authors' trials analyzed with the paper's conventions instead of the
  authors' (the ablation's step before `analysis`: same samples, only the analysis differs);
- comparison.csv: per model, tilt and metric the authors' published value (published.csv), bvc3d's
  authors configuration (mean, sd, min, max over seeds; whether the published value lies within
  mean ± 2 sd) and the paper's configuration as specified;
- ablation.csv: per step, model, tilt and metric the mean and sd over the seeds every step has, and
  the change from the step above with that change in standard errors (change_z);
- samples.csv: recorded samples per trial, per configuration;
- thinned.csv: the authors' configuration's trials thinned evenly to the paper's 30 000 samples and
  analyzed with the authors' conventions (MSAI and mean MI as run and thinned).

Then prints the doc's tables as Markdown.
"""
import argparse
import csv
import math
import os
import sys
from multiprocessing import Pool

import h5py
import numpy as np

import bvc3d.analysis as an

STEPS = ["spec", "s1-protocol", "s2-reading", "s3-geometry", "s4-robot", "s5-labels", "s6-lag", "authors"]
STEP_TEXT = {"spec": "SPEC", "s1-protocol": "+ protocol", "s2-reading": "+ 2-D reading", "s3-geometry": "+ geometry",
             "s4-robot": "+ robot", "s5-labels": "+ labels, roll", "s6-lag": "+ position lag",
             "authors": "+ analysis = authors"}
METRICS = ["frac_active", "mean_mi_active", "frac_multimodal", "msai", "decode_median_m", "decode_mean_m",
           "frac_undecoded", "decode_median_all_m", "decode_mean_all_m", "n_bins"]
PUBLISHED = ["frac_active", "mean_mi_active", "frac_multimodal", "msai", "n_bins"]
FAMILIES = ["2-D", "3d-0.1", "3d-0.2", "3d-3l"]
TILTS = [0, 30, 45, 60]


def family(model):
    """The paper's model a bvc3d model stands for: 2d and 2d-8beam are the 2-D model."""
    return "2-D" if model.startswith("2d") else model.replace("-authors", "")


def trial_row(path, reanalyze=False):
    """A trial's identity, sample count and metrics: as stored, or recomputed with the paper's
    analysis (default parameters: no fixed N, one quantile, no sample dropped)."""
    with h5py.File(path, "r") as f:
        row = {"name": f.attrs["name"], "model": f.attrs["model"], "world": f.attrs["world"],
               "tilt_deg": int(round(float(f.attrs["tilt_deg"]))), "seed": int(f.attrs["seed"]),
               "samples": int(f["walk"].attrs["sample_steps"])}
        if not reanalyze:
            row.update({m: float(f["metrics"].attrs[m]) for m in METRICS})
            return row
        x, y, rates = f["samples/x"][:], f["samples/y"][:], f["samples/rates"][:]
    out = an.analyze(x, y, rates)
    s, d = out["modality_summary"], out["decoding"]
    row.update({"frac_active": s["frac_active"], "mean_mi_active": s["mean_mi_active"],
                "frac_multimodal": s["frac_multimodal"], "msai": out["msai"], "decode_median_m": d["median_m"],
                "decode_mean_m": d["mean_m"], "frac_undecoded": d["frac_undecoded"],
                "decode_median_all_m": d["median_all_m"], "decode_mean_all_m": d["mean_all_m"],
                "n_bins": float(len(out["centers"]))})
    return row


def reanalyzed(path):
    return trial_row(path, reanalyze=True)


THINNED_SAMPLES = 30000  # what the paper reports per 4-hour trial


def thinned(path):
    """A trial's samples thinned evenly (by index) to THINNED_SAMPLES, analyzed with the authors'
    conventions as stored in the trial file: does the sample count move MSAI?"""
    with h5py.File(path, "r") as f:
        row = {"name": f.attrs["name"], "model": f.attrs["model"], "tilt_deg": int(round(float(f.attrs["tilt_deg"]))),
               "seed": int(f.attrs["seed"]), "samples": int(f["walk"].attrs["sample_steps"]),
               "msai": float(f["metrics"].attrs["msai"]), "mean_mi_active": float(f["metrics"].attrs["mean_mi_active"])}
        x, y, rates = f["samples/x"][:], f["samples/y"][:], f["samples/rates"][:]
    keep = np.unique(np.round(np.linspace(0, len(x) - 1, min(THINNED_SAMPLES, len(x)))).astype(int))
    out = an.analyze(x[keep], y[keep], rates[keep], mi_quantile=0.2, skip_samples=1, msai_bins=2662)
    row.update({"thinned_samples": len(keep), "thinned_msai": out["msai"],
                "thinned_mean_mi_active": out["modality_summary"]["mean_mi_active"]})
    return row


def write_csv(path, rows, fields):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore", lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.10g}" if isinstance(v, float) else v) for k, v in r.items()})


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def stats(values):
    v = np.array([x for x in values if not math.isnan(x)], dtype=float)
    if len(v) == 0:
        return math.nan, math.nan, math.nan, math.nan, 0
    sd = v.std(ddof=1) if len(v) > 1 else math.nan
    return v.mean(), sd, v.min(), v.max(), len(v)


def group(rows, seeds=None):
    """{(family, tilt): [rows]} (only the given seeds, if any)."""
    out = {}
    for r in rows:
        if seeds is None or int(r["seed"]) in seeds:
            out.setdefault((family(r["model"]), int(r["tilt_deg"])), []).append(r)
    return out


def fmt(x, digits):
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{digits}f}"


DIGITS = {"frac_active": 3, "mean_mi_active": 2, "frac_multimodal": 3, "msai": 4, "decode_median_m": 2,
          "decode_mean_m": 2, "frac_undecoded": 3, "decode_median_all_m": 2, "decode_mean_all_m": 2, "n_bins": 0}


def main():
    p = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    p.add_argument("results")
    p.add_argument("out")
    p.add_argument("--jobs", type=int, default=2)
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    fields = ["name", "model", "world", "tilt_deg", "seed", "samples"] + METRICS
    trials = {}
    with Pool(args.jobs) as pool:
        for step in STEPS:
            folder = os.path.join(args.results, "authors" if step == "s6-lag" else step)
            files = sorted(os.path.join(folder, n) for n in os.listdir(folder) if n.endswith(".h5")) \
                if os.path.isdir(folder) else []
            if not files:
                print(f"(no trial files in {folder}: {step} left out)", file=sys.stderr)
                continue
            rows = pool.map(reanalyzed if step == "s6-lag" else trial_row, files)
            trials[step] = sorted(rows, key=lambda r: (r["seed"], r["tilt_deg"], r["model"]))
            write_csv(os.path.join(args.out, f"{step}-trials.csv"), trials[step], fields)
    # Steps that do not rerun a model keep the previous step's trials of it (same configuration).
    carried = {"s2-reading": ("s1-protocol", "3d"), "s5-labels": ("s4-robot", "2-D")}
    for step, (source, prefix) in carried.items():
        if step in trials and source in trials:
            trials[step] = trials[step] + [r for r in trials[source] if family(r["model"]).startswith(prefix)]

    published = read_csv(os.path.join(args.out, "published.csv"))
    if "authors" in trials:
        comparison(args.out, published, trials)
    ablation(args.out, trials)
    samples(args.out, trials)
    folder = os.path.join(args.results, "authors")
    if os.path.isdir(folder):
        with Pool(args.jobs) as pool:
            thin_rows = pool.map(thinned, sorted(os.path.join(folder, n) for n in os.listdir(folder)
                                                 if n.endswith(".h5")))
        thin(args.out, thin_rows)


def thin(out, rows):
    rows = sorted(rows, key=lambda r: (r["seed"], r["tilt_deg"], r["model"]))
    write_csv(os.path.join(out, "thinned.csv"), rows, list(rows[0]))
    print(f"\n## the authors' configuration thinned to {THINNED_SAMPLES} samples: MSAI as run → thinned\n")
    print("| model | " + " | ".join(f"{t}°" for t in TILTS) + " |")
    print("|---|" + "---|" * len(TILTS))
    for fam in FAMILIES:
        cells = []
        for t in TILTS:
            g = [r for r in rows if family(r["model"]) == fam and r["tilt_deg"] == t]
            full, few = np.mean([r["msai"] for r in g]), np.mean([r["thinned_msai"] for r in g])
            cells.append(f"{full:.4f} → {few:.4f} ({100 * (few / full - 1):+.1f} %)")
        print(f"| {fam} | " + " | ".join(cells) + " |")


def comparison(out, published, trials):
    authors, spec = group(trials["authors"]), group(trials.get("spec", []))
    rows = []
    for pub in published:
        key = (family(pub["model"]), int(pub["tilt_deg"]))
        for m in PUBLISHED:
            if not pub[m]:
                continue
            value = float(pub[m])
            mean, sd, lo, hi, n = stats([float(r[m]) for r in authors.get(key, [])])
            s_mean, s_sd, _, _, s_n = stats([float(r[m]) for r in spec.get(key, [])])
            rows.append({"model": key[0], "tilt_deg": key[1], "metric": m, "published": value, "authors_mean": mean,
                         "authors_sd": sd, "authors_min": lo, "authors_max": hi, "authors_seeds": n,
                         "within_2sd": bool(abs(value - mean) <= 2 * sd),
                         "z": (value - mean) / sd if sd > 0 else math.nan,
                         "spec_mean": s_mean, "spec_sd": s_sd, "spec_seeds": s_n})
    write_csv(os.path.join(out, "comparison.csv"), rows, list(rows[0]))
    print("\n## published vs bvc3d authors (mean ± sd) vs SPEC (mean ± sd)\n")
    print("| model | metric | " + " | ".join(f"{t}°" for t in TILTS) + " |")
    print("|---|---|" + "---|" * len(TILTS))
    for fam in FAMILIES:
        for m in PUBLISHED:
            cells = []
            for t in TILTS:
                r = next((r for r in rows if r["model"] == fam and r["tilt_deg"] == t and r["metric"] == m), None)
                if r is None:
                    cells.append("–")
                    continue
                d = DIGITS[m]
                mark = "" if r["within_2sd"] else " **✗**"
                cells.append(f"{fmt(r['published'], d)} / {fmt(r['authors_mean'], d)} ± {fmt(r['authors_sd'], d)}{mark}"
                             f" / {fmt(r['spec_mean'], d)} ± {fmt(r['spec_sd'], d)}")
            if any(c != "–" for c in cells):
                print(f"| {fam} | {m} | " + " | ".join(cells) + " |")


def ablation(out, trials):
    seeds = set.intersection(*[{int(r["seed"]) for r in rows} for rows in trials.values()])
    rows = []
    for step in STEPS:
        if step not in trials:
            continue
        g = group(trials[step], seeds)
        for fam in FAMILIES:
            for t in TILTS:
                for m in METRICS:
                    mean, sd, _, _, n = stats([float(r[m]) for r in g.get((fam, t), [])])
                    rows.append({"step": step, "model": fam, "tilt_deg": t, "metric": m, "mean": mean, "sd": sd,
                                 "seeds": n})
    add_changes(rows)
    write_csv(os.path.join(out, "ablation.csv"), rows, list(rows[0]))
    print_effects(rows)
    print(f"\n## ablation (seeds {sorted(seeds)}): mean over seeds, 0° / 30° / 45° / 60°\n")
    for m in ["mean_mi_active", "frac_multimodal", "msai", "frac_active", "frac_undecoded", "decode_median_m",
              "decode_mean_all_m"]:
        print(f"\n### {m}\n")
        print("| step | " + " | ".join(FAMILIES) + " |")
        print("|---|" + "---|" * len(FAMILIES))
        for step in STEPS:
            if step not in trials:
                continue
            cells = []
            for fam in FAMILIES:
                vals = [next((r["mean"] for r in rows if r["step"] == step and r["model"] == fam and r["tilt_deg"] == t
                              and r["metric"] == m), math.nan) for t in TILTS]
                cells.append(" / ".join(fmt(v, DIGITS[m]) for v in vals))
            print(f"| {STEP_TEXT[step]} | " + " | ".join(cells) + " |")


def add_changes(rows):
    """Each row's change from the step above it (same model, tilt and metric) and that change in
    standard errors of the difference of two means over independent seeds, sqrt(sd1²/n1 + sd2²/n2)."""
    previous = {}
    for r in rows:
        key = (r["model"], r["tilt_deg"], r["metric"])
        before = previous.get(key)
        r["change"], r["change_z"] = math.nan, math.nan
        if before is not None and r["seeds"] > 1 and before["seeds"] > 1 and not math.isnan(r["mean"] - before["mean"]):
            r["change"] = r["mean"] - before["mean"]
            se = math.sqrt(r["sd"] ** 2 / r["seeds"] + before["sd"] ** 2 / before["seeds"])
            r["change_z"] = r["change"] / se if se > 0 else (0.0 if r["change"] == 0 else math.inf)
        if r["seeds"]:
            previous[key] = r


def print_effects(rows):
    """Per step and metric: in how many (model, tilt) cells the step moved the metric by more than
    3 standard errors, and the median change there."""
    metrics = ["mean_mi_active", "frac_multimodal", "msai", "frac_undecoded", "decode_median_m"]
    print("\n## which step moves what: cells (of model × tilt) changed by > 3 standard errors, median change\n")
    print("| step | " + " | ".join(metrics) + " |")
    print("|---|" + "---|" * len(metrics))
    for step in STEPS[1:]:
        cells = []
        for m in metrics:
            moved = [r for r in rows if r["step"] == step and r["metric"] == m and abs(r["change_z"]) > 3]
            tested = [r for r in rows if r["step"] == step and r["metric"] == m and not math.isnan(r["change_z"])
                      and r["change"] != 0]
            med = fmt(float(np.median([r["change"] for r in moved])), DIGITS[m] + 1) if moved else "–"
            cells.append(f"{len(moved)}/{len(tested)} ({med})" if tested else "–")
        print(f"| {STEP_TEXT[step]} | " + " | ".join(cells) + " |")


def samples(out, trials):
    rows = []
    for step in STEPS:
        if step in trials and step != "s6-lag":
            mean, sd, lo, hi, n = stats([float(r["samples"]) for r in trials[step]])
            rows.append({"step": step, "samples_mean": mean, "samples_sd": sd, "samples_min": lo, "samples_max": hi,
                         "trials": n})
    write_csv(os.path.join(out, "samples.csv"), rows, list(rows[0]))
    print("\n## recorded samples per trial\n")
    for r in rows:
        print(f"- {STEP_TEXT[r['step']]}: {r['samples_mean']:.0f} ± {r['samples_sd']:.0f} "
              f"({r['samples_min']:.0f}–{r['samples_max']:.0f})")


if __name__ == "__main__":
    main()
