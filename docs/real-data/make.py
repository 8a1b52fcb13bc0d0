"""Regenerates the real-data results of docs/real-data.md from the hall-lidar recording.

    /usr/bin/python3 docs/real-data/make.py --recording PATH/hall-lidar [--work DIR] [--steps ...]

PATH/hall-lidar holds 0000.pcd ... 0059.pcd and poses.csv. Run from the repository's root after
building (build/bvc3d and build/python). Writes the small summary tables (CSV) next to this script
and the figures to docs/figures/real-*.png; the large intermediate files (the point map, template
trial files, the learning walk) go to --work. Steps (default: all, in this order):

  scan-to-scan  every other scan as a query against the others as templates
  scan-to-map   the hall's map from the recording, simulated template scans on a 0.5 m grid of its
                floor with the real sensor's beam pattern, every real scan localized against them
  place-cells   place cells learned on a random walk through the map, real scans localized with them

Sized for a shared 2-core machine: under a heavy load from other jobs, scan-to-map took 8 minutes and
place-cells 16; both keep their intermediate files in --work and reuse them when rerun.
"""
import argparse
import csv
import os
import pathlib
import shutil
import subprocess
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
FIGURES = ROOT / "docs" / "figures"
PAPER_MODELS = ["2d", "3d-0.1", "3d-0.2", "3d-3l"]
OWN_MODELS = [str(HERE / "3d-3l-wide.yaml"), str(HERE / "hall-up4.yaml")]
MODELS = PAPER_MODELS + OWN_MODELS
MODEL_NAMES = PAPER_MODELS + ["3d-3l-wide", "hall-up4"]

GRID = 0.5          # m, template spacing
MAP_VOXEL = 0.05    # m
MAP_MAX_RANGE = 40  # m: the few far outliers (up to 481 m) stay out of the map
SPHERE = 0.05       # m, radius of the map's points as spheres
CLEARANCE = 0.3     # m: a template is inside geometry when map points lie this close to its column


def log(*args):
    print("[make]", *args, flush=True)


def bvc3d(*args, **kw):
    cmd = [str(ROOT / "build" / "bvc3d"), *map(str, args)]
    log(" ".join(cmd))
    start = time.time()
    subprocess.run(cmd, check=True, **kw)
    log(f"  {time.time() - start:.1f} s")


def read_ply(path):
    """The vertices of a binary little-endian float PLY (as `bvc3d map` writes it)."""
    with open(path, "rb") as f:
        header = b""
        while not header.endswith(b"end_header\n"):
            header += f.readline()
        n = int(header.split(b"element vertex ")[1].split(b"\n")[0])
        return np.frombuffer(f.read(), dtype="<f4").reshape(n, 3).astype(np.float64)


def read_pcd_xyz(path):
    """x, y, z of a binary float32 PCD with exactly those fields (the recording's layout)."""
    data = pathlib.Path(path).read_bytes()
    start = data.index(b"DATA binary\n") + len(b"DATA binary\n")
    return np.frombuffer(data[start:], dtype="<f4").reshape(-1, 3).astype(np.float64)


def read_poses(path):
    """4x4 rows, comma-separated with a trailing comma (the recording's poses.csv): the rigid
    transforms (bottom row 0 0 0 1) and the times (the file's bottom row 0 0 0 T)."""
    m = np.loadtxt(path, delimiter=",", usecols=(0, 1, 2, 3)).reshape(-1, 4, 4)
    times = m[:, 3, 3].copy()
    m[:, 3] = [0, 0, 0, 1]
    return m, times


def copy_table(src, name):
    shutil.copyfile(src, HERE / name)
    log("wrote", HERE / name)


# ------------------------------------------------------------------------------------ scan to scan

def scan_to_scan(rec, work):
    out = work / "scan-to-scan"
    bvc3d("localize", "--scans", rec, "--poses", rec / "poses.csv", "--split", 2, "--model", ",".join(MODELS),
          "--out", out)
    copy_table(out / "localization.csv", "scan-to-scan.csv")
    shutil.copyfile(out / "localization.png", FIGURES / "real-scan-to-scan.png")


# ------------------------------------------------------------------------------------ scan to map

def sensor_rings(rec):
    """The 64 rings' elevations, read from the data: a comb e0 + k·δ (k = 0..63) fitted to the
    histogram of sensor-frame elevations of points farther than 8 m (where the beams' offsets from
    the sensor's center no longer matter). Also the residual of each detected histogram peak."""
    elevations = []
    for scan in sorted(rec.glob("*.pcd")):
        p = read_pcd_xyz(scan)
        far = p[np.linalg.norm(p, axis=1) > 8]
        elevations.append(np.degrees(np.arctan2(far[:, 2], np.hypot(far[:, 0], far[:, 1]))))
    el = np.concatenate(elevations)
    bins = np.arange(-48, 48, 0.02)
    hist, _ = np.histogram(el, bins=bins)
    kernel = np.exp(-0.5 * (np.arange(-10, 11) / 3) ** 2)
    smooth = np.convolve(hist, kernel / kernel.sum(), "same")
    centers = 0.5 * (bins[:-1] + bins[1:])
    best = (-1, 0, 0)
    for delta in np.arange(1.38, 1.46, 0.0005):
        for e0 in np.arange(-46.5, -43.0, 0.01):
            score = np.interp(e0 + np.arange(64) * delta, centers, smooth).sum()
            if score > best[0]:
                best = (score, delta, e0)
    _, delta, e0 = best
    return e0 + np.arange(64) * delta, delta, len(el)


def floor_grid(points, poses):
    """The floor under the map on a GRID-spaced lattice: per cell the lowest z with at least 5 map
    points within 0.1 m above it; a plane fitted to the cells within 8 m of the path; the cells
    within 0.15 m of that plane are the mapped floor."""
    ij = np.floor(points[:, :2] / GRID).astype(np.int64)
    lo = ij.min(axis=0)
    ij -= lo
    nx, ny = ij.max(axis=0) + 1
    key = ij[:, 0] * ny + ij[:, 1]
    order = np.argsort(key, kind="stable")
    keys, zs = key[order], points[order, 2]
    starts = np.r_[0, np.nonzero(np.diff(keys))[0] + 1]
    ends = np.r_[starts[1:], len(keys)]
    floor = np.full(nx * ny, np.nan)
    for s, e in zip(starts, ends):
        z = np.sort(zs[s:e])
        dense = np.searchsorted(z, z + 0.1) - np.arange(len(z)) >= 5
        if dense.any():
            floor[keys[s]] = z[np.argmax(dense)]
    cx = (np.arange(nx) + lo[0] + 0.5) * GRID
    cy = (np.arange(ny) + lo[1] + 0.5) * GRID
    X, Y = np.meshgrid(cx, cy, indexing="ij")
    X, Y, floor = X.ravel(), Y.ravel(), floor
    from scipy.spatial import cKDTree  # scikit-learn's dependency
    path = cKDTree(poses[:, :2, 3])
    near, _ = path.query(np.c_[X, Y])
    fit = ~np.isnan(floor) & (near < 8)
    A = np.c_[X[fit], Y[fit], np.ones(fit.sum())]
    plane, *_ = np.linalg.lstsq(A, floor[fit], rcond=None)
    residual = floor[fit] - A @ plane
    on_floor = ~np.isnan(floor) & (np.abs(floor - (plane[0] * X + plane[1] * Y + plane[2])) < 0.15)
    return np.c_[X[on_floor], Y[on_floor]], plane, residual


def template_grid(points, cells, plane, height):
    """The template poses: each floor cell's center at `height` above the floor plane, unless map
    points (other than the floor, 0.3 m up, to the sensor's height + 0.3 m) lie within CLEARANCE of
    its vertical: then the place is inside geometry (a wall, a pillar, furniture) and left out."""
    from scipy.spatial import cKDTree
    tree = cKDTree(points[:, :2])
    floor_z = plane[0] * cells[:, 0] + plane[1] * cells[:, 1] + plane[2]
    keep = np.ones(len(cells), bool)
    for k, near in enumerate(tree.query_ball_point(cells, CLEARANCE)):
        if near:
            z = points[near, 2] - floor_z[k]
            keep[k] = not np.any((z > 0.3) & (z < height + 0.3))
    return np.c_[cells[keep], floor_z[keep] + height], int((~keep).sum())


def write_trajectory(path, xyz):
    rows = np.c_[np.arange(len(xyz), dtype=float), xyz, np.zeros(len(xyz))]
    np.savetxt(path, rows, delimiter=",", header="t,x,y,z,heading", comments="", fmt="%.9g")


def write_sensor(path, rings, columns):
    text = ("# The hall-lidar sensor's beam pattern read from its scans (docs/real-data.md): 64 rings,\n"
            f"# {columns} columns; mounted at the pose itself (height 0: template poses give the sensor's z).\n"
            "name: hall-os64\n"
            "elevations_deg: [" + ", ".join(f"{e:.3f}" for e in rings[::-1]) + "]\n"
            f"azimuth_count: {columns}\nheight: 0\nmax_range: 20\n")
    pathlib.Path(path).write_text(text)


def hall_map(rec, work):
    """The hall's point map (work/hall-map.ply), the sensor's beam pattern (hall-os64.yaml), the floor
    and the template grid (work/grid.csv, work/hall-map.yaml, scan-to-map-setup.csv)."""
    poses, _ = read_poses(rec / "poses.csv")
    map_file = work / "hall-map.ply"
    if not map_file.exists():
        bvc3d("map", "--scans", rec, "--poses", rec / "poses.csv", "--voxel", MAP_VOXEL, "--max-range", MAP_MAX_RANGE,
              "--out", map_file)
    points = read_ply(map_file)
    rings, delta, n_far = sensor_rings(rec)
    columns = 2048
    write_sensor(HERE / "hall-os64.yaml", rings, columns)
    cells, plane, residual = floor_grid(points, poses)
    heights = poses[:, 2, 3] - (plane[0] * poses[:, 0, 3] + plane[1] * poses[:, 1, 3] + plane[2])
    height = float(np.median(heights))
    grid, blocked = template_grid(points, cells, plane, height)
    write_trajectory(work / "grid.csv", grid)
    (work / "hall-map.yaml").write_text(
        "name: hall-map\nobjects:\n"
        f"  - point_cloud: {{file: {map_file.name}, radius: {SPHERE}}}\n"
        "walkable: {rect: [%g, %g, %g, %g]}\n" % (grid[:, 0].min(), grid[:, 1].min(), grid[:, 0].max(),
                                                  grid[:, 1].max()))
    facts = {
        "map_points": len(points), "ring_spacing_deg": delta, "ring_lowest_deg": rings[0],
        "ring_highest_deg": rings[-1],
        "far_points_for_rings": n_far, "floor_cells": len(cells), "templates": len(grid), "inside_geometry": blocked,
        "floor_slope_x": plane[0], "floor_slope_y": plane[1], "floor_z0": plane[2],
        "floor_residual_p5": np.percentile(residual, 5), "floor_residual_p95": np.percentile(residual, 95),
        "sensor_height_median": height, "sensor_height_min": heights.min(), "sensor_height_max": heights.max(),
    }
    with open(HERE / "scan-to-map-setup.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["quantity", "value"])
        for k, v in facts.items():
            w.writerow([k, f"{v:.6g}" if isinstance(v, float) else v])
    log("setup:", facts)


def scan_to_map(rec, work):
    hall_map(rec, work)
    for model, name in zip(MODELS, MODEL_NAMES):
        out = work / f"templates_{name}.h5"
        if not out.exists():
            # The grid's rows are places, not a track in time: one scan per row.
            bvc3d("replay", "--world", work / "hall-map.yaml", "--trajectory", work / "grid.csv", "--step-per-row",
                  "--sensor", HERE / "hall-os64.yaml", "--model", model, "--out", out)
    out = work / "scan-to-map"
    bvc3d("localize", "--templates", work / "templates_{model}.h5", "--queries", rec, "--query-poses",
          rec / "poses.csv", "--model", ",".join(MODELS), "--out", out)
    copy_table(out / "localization.csv", "scan-to-map.csv")
    copy_table(out / "queries.csv", "scan-to-map-queries.csv")  # each query's decoded place: the failures
    shutil.copyfile(out / "localization.png", FIGURES / "real-scan-to-map.png")
    aliasing_figure(rec, work, out)


def unit_rows(m):
    m = np.asarray(m, dtype=np.float64)
    n = np.linalg.norm(m, axis=1, keepdims=True)
    return np.divide(m, n, out=np.zeros_like(m), where=n > 0)


def top_view(ax, returns, title):
    """Returns within 14 m seen from above, colored by elevation (what the upper layers read)."""
    import matplotlib.pyplot as plt
    r, theta, phi = returns.T
    d = r * np.cos(phi)
    near = d < 14
    sc = ax.scatter(d[near] * np.cos(theta[near]), d[near] * np.sin(theta[near]), c=np.degrees(phi[near]), s=0.2,
                    cmap="viridis", vmin=0, vmax=40, rasterized=True)
    for radius in (4, 8, 12):
        ax.add_patch(plt.Circle((0, 0), radius, fill=False, ls=":", color="0.5"))
    ax.set_aspect("equal")
    ax.set_xlim(-14, 14)
    ax.set_ylim(-14, 14)
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("east (m)")
    return sc


def aliasing_figure(rec, work, out):
    """Why distant places are confused: the worst query of the paper's 3d-3l model, its real scan
    and the simulated scan where it was decoded, and each model's similarity over the templates."""
    import h5py
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import bvc3d
    queries = list(csv.DictReader(open(out / "queries.csv")))
    worst = max((q for q in queries if q["model"] == "3d-3l"), key=lambda q: float(q["error_m"]))
    qi = int(worst["query"])
    recording = bvc3d.Recording.open(rec, rec / "poses.csv")
    pose, _ = recording[qi]
    world = bvc3d.World.from_yaml(work / "hall-map.yaml")
    sensor = bvc3d.Sensor.from_yaml(str(HERE / "hall-os64.yaml"))
    dx, dy, dz = (float(worst[k]) for k in ("decoded_x", "decoded_y", "decoded_z"))
    simulated = world.scan(sensor, x=dx, y=dy, heading=0.0, z=dz)
    simulated = simulated[(simulated[:, 2] >= 0) & (simulated[:, 0] >= 0.3) & (simulated[:, 0] <= 20)]
    fig, axes = plt.subplots(1, 5, figsize=(22, 4.6))
    top_view(axes[0], recording.returns(qi, "3d-3l"), f"real scan {qi} at ({pose[0, 3]:.1f}, {pose[1, 3]:.1f})")
    sc = top_view(axes[1], simulated, f"simulated template at ({dx:.2f}, {dy:.2f})\nwhere 3d-3l decodes it")
    fig.colorbar(sc, ax=axes[1], label="elevation (°)", fraction=0.046)
    for ax, model in zip(axes[2:], ["2d", "3d-3l", "hall-up4"]):
        with h5py.File(work / f"templates_{model}.h5") as f:
            t = f["samples/bvc_rates"][:]
            tx, ty = f["samples/x"][:], f["samples/y"][:]
        q = recording.replay(str(HERE / f"{model}.yaml") if model == "hall-up4" else model)["bvc_rates"][qi]
        sim = unit_rows(t) @ unit_rows(q[None, :])[0]
        sc = ax.scatter(tx, ty, c=sim, s=6, cmap="magma", vmin=np.percentile(sim, 5), vmax=sim.max())
        best = np.argmax(sim)
        ax.plot(pose[0, 3], pose[1, 3], "o", mfc="none", mec="tab:cyan", ms=10, mew=2, label="true")
        ax.plot(tx[best], ty[best], "x", c="tab:cyan", ms=10, mew=2, label="decoded")
        ax.set_aspect("equal")
        ax.set_title(f"{model}: cosine similarity of scan {qi}\nto every template", fontsize=9)
        ax.set_xlabel("x (m)")
        fig.colorbar(sc, ax=ax, fraction=0.046)
    axes[2].legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(FIGURES / "real-aliasing.png", dpi=90)
    plt.close(fig)
    log("wrote", FIGURES / "real-aliasing.png")


# ------------------------------------------------------------------------------------ place cells

# (model, hours of the learning walk): the 2-D model and 3d-3l on one hour; the 2-D model also on
# four (cheap), to see what longer learning changes. ("hall-up4", 1.0) can be added: its simulated
# scans take about three times as long as 3d-3l's (more and wider elevation rows to cast).
PLACE_RUNS = [("2d", 1.0), ("2d", 4.0), ("3d-3l", 1.0)]
BODY_HEIGHT = 1.6   # m: the robot is a person carrying the sensor (radius 0.25 m)
SETTLE = 20         # network steps per scan; its response is the mean of the last SETTLE // 2


def model_arg(name):
    return str(HERE / f"{name}.yaml") if name in ("hall-up4", "3d-3l-wide") else name


def floor_frame(plane):
    """The rigid transform (4x4) that takes the recording's frame to one whose z is the height
    above the fitted floor plane z = a·x + b·y + c."""
    a, b, c = plane
    n = np.array([-a, -b, 1.0])
    n /= np.linalg.norm(n)
    v = np.cross(n, [0.0, 0.0, 1.0])
    s, cos = np.linalg.norm(v), n[2]
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    R = np.eye(3) + K + K @ K * ((1 - cos) / s**2)
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = -R @ np.array([0.0, 0.0, c])
    return T


def write_ply(path, points):
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
              "property float z\nend_header\n" % len(points))
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(points.astype("<f4").tobytes())


def write_matrix_poses(path, poses, times):
    with open(path, "w") as f:
        for P, t in zip(poses, times):
            for r in range(3):
                f.write(",".join(repr(float(v)) for v in P[r]) + ",\n")
            f.write(f"0,0,0,{t!r},\n")


def settled_place_rates(bvc, weights):
    """Each row's place-cell response on its own: the trained network, reset, driven by that BVC
    vector for SETTLE steps (frozen); the response is the mean rate over the last SETTLE // 2 steps,
    which smooths the period-2 swing that recurrent inhibition gives some inputs."""
    import bvc3d
    net = bvc3d.PlaceCellNetwork(bvc.shape[1], n_place=weights.shape[0])
    net.weights = weights
    out = np.empty((len(bvc), weights.shape[0]), np.float32)
    for i, v in enumerate(np.asarray(bvc, np.float64)):
        net.reset()
        steps = [net.step(v, False) for _ in range(SETTLE)]
        out[i] = np.mean(steps[SETTLE - SETTLE // 2:], axis=0)
    return out


def summary_row(label, model, rates, result):
    s, ch, ne = result["decoded_summary"], result["chance"], result["nearest"]
    return [label, model, rates, s["median_m"], s["mean_m"], s["within_1m"], s["within_2m"], result["n_undecoded"],
            ch["median_m"], ch["within_2m"], ne["median_m"], ne["within_1m"]]


def floor_setup(rec, work):
    """The map, the template grid and the recording's poses in the floor frame (under work/floor), as a dict:
    floor (the folder), world, grid (templates, n x 3), queries (the Recording), qxyz, sensor, height (the
    sensor's), grid_path and query_path (places, not tracks in time: replay_simulated steps them with
    step_per_row=True). Needs hall_map's outputs."""
    import bvc3d
    from scipy.spatial import ConvexHull
    points = read_ply(work / "hall-map.ply")
    poses, times = read_poses(rec / "poses.csv")
    setup = {row["quantity"]: float(row["value"]) for row in csv.DictReader(open(HERE / "scan-to-map-setup.csv"))}
    plane = (setup["floor_slope_x"], setup["floor_slope_y"], setup["floor_z0"])
    height = setup["sensor_height_median"]
    T = floor_frame(plane)
    floor = work / "floor"
    floor.mkdir(exist_ok=True)
    # The map, the template grid and the recording's poses in the floor frame.
    write_ply(floor / "hall-map.ply", points @ T[:3, :3].T + T[:3, 3])
    grid = np.loadtxt(work / "grid.csv", delimiter=",", skiprows=1)[:, 1:4]
    grid = grid @ T[:3, :3].T + T[:3, 3]
    write_matrix_poses(floor / "poses.csv", [T @ P for P in poses], times)
    hull = grid[ConvexHull(grid[:, :2]).vertices, :2]
    (floor / "hall-map.yaml").write_text(
        "name: hall-map-floor\nobjects:\n"
        "  - point_cloud: {file: hall-map.ply, radius: %g, crop_z: [0.2, 40]}\n" % SPHERE +
        "walkable: {polygon: [" + ", ".join(f"[{x:.3f}, {y:.3f}]" for x, y in hull) + "]}\n")
    world = bvc3d.World.from_yaml(floor / "hall-map.yaml")
    queries = bvc3d.Recording.open(rec, floor / "poses.csv")
    qxyz = queries.poses[:, :3, 3]
    sensor = str(HERE / "hall-os64.yaml")
    grid_path = {"t": np.arange(len(grid), dtype=float), "x": grid[:, 0], "y": grid[:, 1], "z": grid[:, 2],
                 "heading": np.zeros(len(grid))}
    # The real scans' poses, level, for simulated stand-ins of the real scans in the map.
    heading = np.arctan2(queries.poses[:, 1, 0], queries.poses[:, 0, 0])
    query_path = {"t": np.arange(len(qxyz), dtype=float), "x": qxyz[:, 0], "y": qxyz[:, 1], "z": qxyz[:, 2],
                  "heading": heading}
    return dict(floor=floor, world=world, grid=grid, queries=queries, qxyz=qxyz, sensor=sensor, height=height,
                grid_path=grid_path, query_path=query_path)


def template_query_rates(setup, name):
    """Model `name`'s BVC rates of the templates and of the real queries, cached in floor/NAME-bvc.npz (they do
    not depend on the walk)."""
    import bvc3d
    floor = setup["floor"]
    bvc_file = floor / f"{name}-bvc.npz"
    if not bvc_file.exists():
        np.savez(bvc_file,
                 templates=bvc3d.replay_simulated(str(floor / "hall-map.yaml"), setup["grid_path"], setup["sensor"],
                                                  model_arg(name), step_per_row=True)["bvc_rates"],
                 queries=setup["queries"].replay(model_arg(name))["bvc_rates"])
    return np.load(bvc_file)


def place_cells(rec, work):
    import bvc3d
    setup = floor_setup(rec, work)
    floor, world, grid, queries, qxyz = (setup[k] for k in ("floor", "world", "grid", "queries", "qxyz"))
    sensor, height, query_path = setup["sensor"], setup["height"], setup["query_path"]
    rows, per_query, walks = [], [], []
    for name, hours in PLACE_RUNS:
        walk = bvc3d.random_walk(world, hours, 0, height=BODY_HEIGHT)
        path = {k: walk[k] for k in ("t", "x", "y", "heading")}
        path["z"] = np.full(len(walk["t"]), height)
        step = max(1, len(walk["x"]) // 20000)
        covered = np.mean(np.min(np.hypot(grid[:, None, 0] - walk["x"][None, ::step],
                                          grid[:, None, 1] - walk["y"][None, ::step]), axis=1) <= GRID)
        walks.append([name, hours, len(walk["t"]), int(np.sum(walk["bumped"])), f"{covered:.3f}"])
        cache = floor / f"{name}-{hours:g}h.npz"
        if not cache.exists():
            start = time.time()
            learned = bvc3d.replay_simulated(str(floor / "hall-map.yaml"), path, sensor, model_arg(name), learn=True)
            np.savez(cache, weights=learned["weights"])
            log(f"{name}, {hours:g} h: learned in {time.time() - start:.0f} s")
        sim_file = floor / f"{name}-simulated-queries.npz"
        if not sim_file.exists():
            np.savez(sim_file, queries=bvc3d.replay_simulated(str(floor / "hall-map.yaml"), query_path, sensor,
                                                              model_arg(name), step_per_row=True)["bvc_rates"])
        bvc = template_query_rates(setup, name)
        W = np.load(cache)["weights"]
        simulated = np.load(sim_file)["queries"]
        place_t = settled_place_rates(bvc["templates"], W)
        cases = [("real", "place", place_t, settled_place_rates(bvc["queries"], W)),
                 ("simulated", "place", place_t, settled_place_rates(simulated, W))]
        if hours == 1.0:
            cases = [("real", "bvc", bvc["templates"], bvc["queries"]),
                     ("simulated", "bvc", bvc["templates"], simulated)] + cases
        for queries_kind, rates, t, q in cases:
            r = bvc3d.localize(t, grid, q, qxyz)
            rows.append(summary_row(f"{hours:g}", name, rates, r) +
                        [queries_kind, f"{np.mean(q.max(axis=1) == 0):.3f}"])
            per_query += [[name, hours, rates, queries_kind, i, *qxyz[i, :2], r["decoded"][i], r["error"][i]]
                          for i in range(len(q))]
        walks[-1] += [f"{np.mean(place_t.max(axis=0) > 0):.3f}", f"{np.mean(place_t.max(axis=1) == 0):.3f}"]
        log(f"{name}, {hours:g} h: {100 * np.mean(place_t.max(axis=0) > 0):.0f}% of place cells active on some "
            f"template, {100 * np.mean(place_t.max(axis=1) == 0):.0f}% of templates with no active cell")
    with open(HERE / "place-cells.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["walk_hours", "model", "rates", "median_m", "mean_m", "within_1m", "within_2m", "undecoded",
                    "chance_median_m", "chance_within_2m", "nearest_median_m", "nearest_within_1m", "queries",
                    "silent_queries"])
        for row in rows:
            w.writerow([f"{v:.4g}" if isinstance(v, float) else v for v in row])
    with open(work / "place-cells-queries.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["model", "walk_hours", "rates", "queries", "query", "x", "y", "decoded", "error_m"])
        w.writerows(per_query)
    with open(HERE / "place-cells-walks.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["model", "walk_hours", "steps", "bumps", "templates_within_0.5m_of_walk",
                    "place_cells_active_on_templates",
                    "silent_templates"])
        w.writerows(walks)
    log("wrote", HERE / "place-cells.csv")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--recording", required=True, type=pathlib.Path, help="the hall-lidar folder")
    parser.add_argument("--work", type=pathlib.Path, default=pathlib.Path("/tmp/bvc3d-real-data"))
    parser.add_argument("--steps", nargs="*", default=["scan-to-scan", "scan-to-map", "place-cells"])
    args = parser.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    FIGURES.mkdir(parents=True, exist_ok=True)
    os.environ.setdefault("PYTHONPATH", str(ROOT / "build" / "python"))  # for the figure modules bvc3d runs
    sys.path.insert(0, str(ROOT / "build" / "python"))
    steps = {"scan-to-scan": scan_to_scan, "scan-to-map": scan_to_map, "place-cells": place_cells}
    for step in args.steps:
        if step not in steps:
            sys.exit(f"unknown step '{step}' (known: {', '.join(steps)})")
        log("step", step)
        steps[step](args.recording.resolve(), args.work.resolve())


if __name__ == "__main__":
    main()
