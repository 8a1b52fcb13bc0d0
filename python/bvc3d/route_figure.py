"""A route or a tour over the floor plan of its world: what `bvc3d route --figure FILE` draws.

    /usr/bin/python3 -m bvc3d.route_figure --world WORLD [--tilt DEG --lean CORNER --missing-models skip] \
        --trajectory FILE --out FILE.png

The floor plan is the world cut at the ground robot's body, as its collision sees it: the outline of
every surface between the floor (or the world's step height) and the body's top (0.1 m, the paper's
robot; --body-height), with the walkable region's edge and the drop edges (where the floor ends, red).
The path is coloured by time; a triangle marks the start and its heading.
"""
import argparse
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402

from . import _core  # noqa: E402

DPI = 120
BODY_HEIGHT = 0.10  # m, the paper's robot (RobotParams::height)


def draw_plan(ax, world, body_height=BODY_HEIGHT):
    """The world's floor plan at body height on `ax`: grey outlines (discs for a point cloud's spheres),
    the drop edges in red. Returns the plan's segments (S, 2, 2)."""
    plan = world.floor_plan(height=body_height)
    segments, radii = plan["segments"], plan["radii"]
    lines = radii == 0
    ax.add_collection(LineCollection(segments[lines], colors="0.45", linewidths=0.5))
    for (a, b), r in zip(segments[~lines], radii[~lines]):
        ax.add_patch(Circle(a, r, color="0.45", lw=0))
    if len(world.drop_edges):
        ax.add_collection(LineCollection(world.drop_edges, colors="tab:red", linewidths=0.8))
    return segments


def open_world(world, tilt_deg=None, lean="+x+y", missing_models="error"):
    """`world` itself when it is a World, else the world its source names (a preset, a world YAML or a Gazebo
    world) with the options given."""
    if isinstance(world, _core.World):
        return world
    return _core.World.preset(str(world), tilt_deg, lean, missing_models)


def add_world_arguments(parser, required):
    """--world, --tilt, --lean and --missing-models, as the command that calls the figure passes them."""
    parser.add_argument("--world", required=required, help="a world preset, world YAML or Gazebo world")
    parser.add_argument("--tilt", type=float, default=None, help="degrees the cross arena's central walls lean")
    parser.add_argument("--lean", default="+x+y", help="the corner they lean toward (default +x+y)")
    parser.add_argument("--missing-models", default="error",
                        help="a Gazebo world's models that are not found: 'skip' or 'error' (default)")


def draw_path(ax, fig, t, x, y, heading):
    """The path coloured by time (minutes when it is long), its start as a black triangle."""
    minutes = t[-1] > 300
    scale, unit = (60.0, "min") if minutes else (1.0, "s")
    points = np.c_[x, y].reshape(-1, 1, 2)
    path = LineCollection(np.concatenate([points[:-1], points[1:]], axis=1), cmap="viridis", linewidths=1.0)
    path.set_array((t[:-1] - t[0]) / scale)
    ax.add_collection(path)
    fig.colorbar(path, ax=ax, fraction=0.04, pad=0.02, label=f"time along the path ({unit})")
    ax.plot([x[0]], [y[0]], marker=(3, 0, math.degrees(heading[0]) - 90), color="k", ms=9, ls="none",
            label="start")


def figure(world_source, trajectory, out, body_height=BODY_HEIGHT, tilt_deg=None, lean="+x+y",
           missing_models="error"):
    world = open_world(world_source, tilt_deg, lean, missing_models)
    path = _core.read_trajectory(str(trajectory))
    t, x, y, heading = path["t"], path["x"], path["y"], path["heading"]
    if len(t) < 2:
        raise ValueError(f"trajectory '{trajectory}' has fewer than 2 rows: nothing to draw")
    fig, ax = plt.subplots()
    segments = draw_plan(ax, world, body_height)
    draw_path(ax, fig, t, x, y, heading)
    corners = np.r_[segments.reshape(-1, 2), np.c_[x, y]]
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    pad = 0.03 * max(hi - lo) + 0.5
    width, height = hi - lo + 2 * pad
    fig.set_size_inches(min(14.0, max(5.0, 8.0 * width / max(width, height)) + 1.5),
                        min(14.0, max(4.0, 8.0 * height / max(width, height))))
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    length = float(np.sum(np.hypot(np.diff(x), np.diff(y))))
    ax.set_title(f"{world.name}: {trajectory} ({length:.0f} m in {t[-1] - t[0]:.0f} s) over the floor plan at\n"
                 f"the body's height (0–{body_height:g} m; red: where the floor ends)", fontsize=9)
    ax.legend(fontsize=8, loc="best")
    fig.tight_layout()
    fig.savefig(out, dpi=DPI)
    plt.close(fig)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_world_arguments(parser, required=True)
    parser.add_argument("--trajectory", required=True, help="the route: a trajectory file (t, x, y, [z], heading)")
    parser.add_argument("--out", required=True, help="the figure to write (.png)")
    parser.add_argument("--body-height", type=float, default=BODY_HEIGHT, help="m: the plan's cut (default 0.1)")
    args = parser.parse_args(argv)
    try:
        print("figure:", figure(args.world, args.trajectory, args.out, args.body_height, args.tilt, args.lean,
                                       args.missing_models))
    except (OSError, ValueError) as e:
        print(f"bvc3d.route_figure: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
