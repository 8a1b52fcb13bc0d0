"""The figure of `bvc3d place-recognition`: every descriptor's precision-recall curve, and the route seen
from above with the queries that have a revisit, over its world's floor plan when it has a world.

    /usr/bin/python3 -m bvc3d.place_recognition_figure DIR [--world WORLD --tilt DEG --lean CORNER \
        --missing-models skip]

DIR holds details.csv, pr.csv, queries.csv and scans.csv (as `bvc3d place-recognition` writes them);
the figure is DIR/place-recognition.png. A simulated route's world (the command passes its --world and
the options given with it) is drawn as `route --figure` draws it: the floor plan at the robot's body
height (bvc3d.route_figure.draw_plan). A recording has no world: its route is drawn alone.
"""
import argparse
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from .report import num, read_csv  # noqa: E402
from .route_figure import BODY_HEIGHT, add_world_arguments, draw_plan, open_world  # noqa: E402

DPI = 120


def _pct(v):
    return "n/a" if math.isnan(v) else f"{100 * v:.1f}%"


def draw(directory, world=None, body_height=BODY_HEIGHT):
    """The figure of a folder as a matplotlib Figure (figure() writes it). `world` (a World, or a preset or
    world file's name; None for a recording) is the route's: its floor plan is drawn under the route."""
    details = read_csv(os.path.join(directory, "details.csv"))
    pr = read_csv(os.path.join(directory, "pr.csv"))
    scans = read_csv(os.path.join(directory, "scans.csv"))
    queries = read_csv(os.path.join(directory, "queries.csv"))
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5.2))
    for row in details:
        name = row["descriptor"]
        points = [p for p in pr if p["descriptor"] == name]
        recall = [num(p["recall"]) for p in points]
        precision = [num(p["precision"]) for p in points]
        heading = " (uses the heading)" if row["uses_heading"] == "1" else ""
        label = (f"{name}{heading}: recall@1 {_pct(num(row['recall_at_1']))}, F1max {num(row['f1_max']):.2f}, "
                 f"AUC {num(row['auc']):.2f}")
        left.plot(recall, precision, "-", lw=1.2, label=label, drawstyle="steps-post")
    protocol = details[0]["protocol"] if details else ""
    if details and all(int(row["revisits"]) == 0 for row in details):
        left.text(0.5, 0.5, "no query has a revisit\n(no older scan outside the exclusion window within the\n"
                  "revisit radius): recall, F1max and AUC are undefined", ha="center", va="center", fontsize=9,
                  transform=left.transAxes)
    untimed = details and details[0].get("timed") == "0"
    left.set_xlim(0, 1.02)
    left.set_ylim(0, 1.02)
    left.set_xlabel("recall (right matches / queries with a revisit)")
    left.set_ylabel("precision")
    left.set_title(f"precision-recall, {protocol} protocol" + (" (scans without times)" if untimed else ""),
                   fontsize=10)
    left.legend(fontsize=7, loc="lower left")
    x = [num(s["x"]) for s in scans]
    y = [num(s["y"]) for s in scans]
    if world is not None:
        world = open_world(world)
        draw_plan(right, world, body_height)
        right.set_title(f"{world.name}: the route over the floor plan at the body's height\n"
                        f"(0–{body_height:g} m; red: where the floor ends)", fontsize=9)
    right.plot(x, y, "-", c="0.6", lw=0.8, label="route")
    first = details[0]["descriptor"] if details else None
    revisit = {int(q["query"]) for q in queries if q["descriptor"] == first and q["has_revisit"] == "1"}
    right.scatter([x[i] for i in sorted(revisit)], [y[i] for i in sorted(revisit)], s=4, c="tab:blue",
                  label=f"queries with a revisit ({len(revisit)})", zorder=3)
    if x:
        right.scatter([x[0]], [y[0]], marker="^", c="k", s=30, label="start", zorder=4)
    right.set_aspect("equal", adjustable="datalim")
    right.set_xlabel("x (m)")
    right.set_ylabel("y (m)")
    right.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return fig


def figure(directory, out=None, world=None, body_height=BODY_HEIGHT):
    fig = draw(directory, world, body_height)
    path = out or os.path.join(directory, "place-recognition.png")
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("directory")
    add_world_arguments(parser, required=False)
    args = parser.parse_args(argv)
    try:
        world = None if args.world is None else open_world(args.world, args.tilt, args.lean, args.missing_models)
        print("figure:", figure(args.directory, world=world))
    except (OSError, KeyError, ValueError, IndexError) as e:
        print(f"bvc3d.place_recognition_figure: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
