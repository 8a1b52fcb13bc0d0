"""Success and path ratio against learning time in the 60° cross arena, for docs/navigation.md: gathers the runs
make.py wrote there with the same goals, seeds and prune (learning cut at a fixed time: `ms-cap-` and `lt-H-`; to
SPEC's criteria: `ms-` and `ms2-`) into docs/navigation/learning-curve.csv and draws learning-curve.png.

Run from the repository root after the make.py runs it names (docs/navigation.md says which):
/usr/bin/python3 docs/navigation/learning_curve.py
"""
import csv
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = pathlib.Path(__file__).resolve().parent
PREFIXES = ["lt-0.1-", "ms-cap-", "lt-0.2-", "lt-0.3-", "ms-", "ms2-"]
MODELS = ["2d", "3d-3l", "ms-2d", "ms-3d"]


def read(name):
    with open(HERE / name, newline="") as f:
        return list(csv.DictReader(f))


def main():
    rows = []
    for prefix in PREFIXES:
        if not (HERE / f"{prefix}starts.csv").exists():
            print(f"skipped {prefix}: no {prefix}starts.csv (run make.py with --prefix {prefix})")
            continue
        starts, learning = read(f"{prefix}starts.csv"), read(f"{prefix}learning.csv")
        for model in MODELS:
            mine = [r for r in starts if r["model"] == model and r["world"] == "cross-60"]
            if not mine:
                continue
            learn = {r["seed"]: float(r["learn_s"]) for r in learning if r["model"] == model}
            ok = [float(r["path_ratio"]) for r in mine if r["success"] == "1"]
            q25, q50, q75 = np.percentile(ok, [25, 50, 75]) if ok else (np.nan,) * 3
            rows.append({"model": model, "runs": prefix, "learn_h": np.mean(list(learn.values())) / 3600,
                         "starts": len(mine), "success_rate": len(ok) / len(mine), "path_ratio_median": q50,
                         "path_ratio_q25": q25, "path_ratio_q75": q75})
    with open(HERE / "learning-curve.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows({k: (round(v, 4) if isinstance(v, float) else v) for k, v in r.items()} for r in rows)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    for model in MODELS:
        mine = sorted((r for r in rows if r["model"] == model), key=lambda r: r["learn_h"])
        if not mine:
            continue
        h = [r["learn_h"] for r in mine]
        style = "-o" if model.startswith("ms") else "--s"
        ax1.plot(h, [100 * r["success_rate"] for r in mine], style, label=model)
        med = np.array([r["path_ratio_median"] for r in mine])
        err = [med - [r["path_ratio_q25"] for r in mine], [r["path_ratio_q75"] for r in mine] - med]
        ax2.errorbar(h, med, yerr=err, fmt=style, capsize=3, label=model)
    ax1.set_xlabel("learning time (simulated h, mean of 5 runs)")
    ax1.set_ylabel("starts reached (%)")
    ax2.set_xlabel("learning time (simulated h, mean of 5 runs)")
    ax2.set_ylabel("path ratio of reached starts\n(median, quartiles)")
    for ax in (ax1, ax2):
        ax.legend()
        ax.grid(alpha=0.3)
    fig.suptitle("60° cross arena, goals (±3.5, ±3.5): learning cut at a time, or to SPEC's criteria (last point)")
    fig.tight_layout()
    fig.savefig(HERE / "learning-curve.png", dpi=100)
    print(f"wrote {HERE / 'learning-curve.csv'} ({len(rows)} rows) and learning-curve.png")


if __name__ == "__main__":
    main()
