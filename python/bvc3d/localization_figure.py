"""The figure of `bvc3d localize`: per model, the templates, each query's true position, its decoded
position and the error between them, seen from above.

    /usr/bin/python3 -m bvc3d.localization_figure DIR

DIR holds localization.csv, queries.csv and templates.csv (as `bvc3d localize` writes them); the
figure is DIR/localization.png.
"""
import argparse
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from .report import num, read_csv  # noqa: E402

DPI = 120


def figure(directory, out=None):
    summary = read_csv(os.path.join(directory, "localization.csv"))
    queries = read_csv(os.path.join(directory, "queries.csv"))
    templates = read_csv(os.path.join(directory, "templates.csv"))
    models = [row["model"] for row in summary]
    cols = min(len(models), 3)
    rows = math.ceil(len(models) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 4.2 * rows), squeeze=False)
    for ax in axes.flat[len(models):]:
        ax.set_visible(False)
    for ax, row in zip(axes.flat, summary):
        model = row["model"]
        tx = [num(t["x"]) for t in templates if t["model"] == model]
        ty = [num(t["y"]) for t in templates if t["model"] == model]
        q = [r for r in queries if r["model"] == model]
        ax.scatter(tx, ty, s=4, c="0.75", label="templates", zorder=1)
        ax.plot([num(r["x"]) for r in q], [num(r["y"]) for r in q], "-", c="0.3", lw=0.8, zorder=2)
        for r in q:
            if r["decoded"] == "":
                continue
            x, y, dx, dy = num(r["x"]), num(r["y"]), num(r["decoded_x"]), num(r["decoded_y"])
            ax.plot([x, dx], [y, dy], "-", c="tab:red", lw=0.7, alpha=0.8, zorder=3)
        ax.scatter([num(r["x"]) for r in q], [num(r["y"]) for r in q], s=10, c="k", label="queries (true)", zorder=4)
        ax.scatter([num(r["decoded_x"]) for r in q], [num(r["decoded_y"]) for r in q], s=14, marker="x",
                   c="tab:red", label="decoded", zorder=5)
        ax.set_title(f"{model} ({row['rates']} rates): median {num(row['median_m']):.2f} m, "
                     f"≤2 m {100 * num(row['within_2m']):.0f}%\nchance median {num(row['chance_median_m']):.1f} m, "
                     f"nearest {num(row['nearest_median_m']):.2f} m", fontsize=9)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    axes.flat[0].legend(fontsize=7, loc="best")
    fig.tight_layout()
    path = out or os.path.join(directory, "localization.png")
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("directory")
    args = parser.parse_args(argv)
    try:
        print("figure:", figure(args.directory))
    except (OSError, KeyError) as e:
        print(f"bvc3d.localization_figure: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
