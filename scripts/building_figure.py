#!/usr/bin/env python3
"""The figure of docs/buildings.md: the AWS RoboMaker hospital's floor plan, a tour of it and one
os1-64 scan, from the Gazebo world beside the repository (../shared/data/gazebo; not part of it).

    PYTHONPATH=build/python /usr/bin/python3 scripts/building_figure.py [--out docs/figures/hospital_tour.png]
"""
import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

import bvc3d  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
HOSPITAL = ROOT.parent / "shared" / "data" / "gazebo" / "aws-robomaker-hospital-world" / "worlds" / "hospital.world"


def plan_segments(triangles, z_lo, z_hi):
    """The outline, seen from above, of every triangle's part between z_lo and z_hi."""
    z = triangles[:, :, 2]
    keep = (z.max(axis=1) >= z_lo) & (z.min(axis=1) <= z_hi)
    segs = []
    for tri in triangles[keep]:
        poly = list(tri)
        for z0, sign in ((z_lo, 1.0), (z_hi, -1.0)):
            out = []
            for i in range(len(poly)):
                a, b = poly[i], poly[(i + 1) % len(poly)]
                da, db = sign * (a[2] - z0), sign * (b[2] - z0)
                if da >= 0:
                    out.append(a)
                if (da >= 0) != (db >= 0):
                    out.append(a + (da / (da - db)) * (b - a))
            poly = out
            if not poly:
                break
        segs += [(poly[i][:2], poly[(i + 1) % len(poly)][:2]) for i in range(len(poly))]
    return np.array(segs).reshape(-1, 2, 2)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "figures" / "hospital_tour.png"))
    args = parser.parse_args()
    if not HOSPITAL.exists():
        raise SystemExit(f"building_figure: the hospital world is not at {HOSPITAL}")
    world = bvc3d.World.from_sdf(HOSPITAL, missing_models="skip")
    tour = bvc3d.tour(world)
    stats = tour["stats"]
    # One scan, from a step of the tour in the ward corridor.
    i = int(np.argmin(np.hypot(tour["x"] - 6.0, tour["y"] + 12.0)))
    x, y, h = tour["x"][i], tour["y"][i], tour["heading"][i]
    scan = world.scan("os1-64", x, y, h, noise_seed=1)
    r, az, el = scan[:, 0], scan[:, 1], scan[:, 2]
    height = [m for m in bvc3d.lidar_models() if m["name"] == "os1-64"][0]["height"]
    hits = np.c_[x + r * np.cos(el) * np.cos(az), y + r * np.cos(el) * np.sin(az), height + r * np.sin(el)]
    mid = (hits[:, 2] > 0.05) & (hits[:, 2] < 2.5)  # neither floor nor ceiling

    fig, ax = plt.subplots(figsize=(7.5, 13))
    ax.add_collection(LineCollection(plan_segments(world.triangles, 0.3, 1.5), colors="0.55", linewidths=0.3))
    ax.add_collection(LineCollection(world.drop_edges, colors="tab:red", linewidths=0.6))
    t = tour["t"] / 60
    points = np.c_[tour["x"], tour["y"]].reshape(-1, 1, 2)
    path = LineCollection(np.concatenate([points[:-1], points[1:]], axis=1), cmap="viridis", linewidths=0.9)
    path.set_array(t[:-1])
    ax.add_collection(path)
    ax.scatter(hits[mid, 0], hits[mid, 1], s=2.5, c="tab:orange", lw=0, rasterized=True, zorder=3)
    ax.plot([x], [y], marker=(3, 0, np.degrees(h) - 90), color="k", ms=9)
    ax.plot([tour["x"][0]], [tour["y"][0]], "ks", ms=5)
    fig.colorbar(path, ax=ax, fraction=0.04, pad=0.02, label="time on the tour (min)")
    ax.set_aspect("equal")
    ax.set_xlim(-13.5, 13.5)
    ax.set_ylim(-36, 22)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"AWS RoboMaker hospital: a tour ({stats['length']:.0f} m, within 1 m of "
                 f"{100 * stats['coverage']:.1f} % of the floor,\n{stats['reverse_length']:.0f} m driven again in the "
                 f"opposite direction) and one os1-64 scan (orange: {mid.sum()} returns off floor and ceiling)",
                 fontsize=8.5)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"building_figure: wrote {args.out}")


if __name__ == "__main__":
    main()
