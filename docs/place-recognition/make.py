"""Regenerates the results of docs/place-recognition.md: every table (CSV, next to this script) and figure
(docs/figures/pr-*.png) the page shows.

    /usr/bin/python3 docs/place-recognition/make.py --data PATH [--work DIR] [--steps ...]

PATH holds the data sets `kitti-bev/` (sequences 00, 02, 05), `hall-lidar/` and `gazebo/` (as its READMEs
describe them). Run from the repository's root after building (build/bvc3d, build/python). The KITTI-BEV
images become recordings in --work (kitti_bev.py; nothing is copied into the repository), and every run's
own tables stay there. Steps (default: all but buildings, in this order):

  speed      KITTI 00 through one 2-D BVC descriptor and Scan Context, timed (speed.csv)
  kitti      KITTI 00, 02, 05: every descriptor, both protocols (kitti.csv, kitti-published.csv,
             kitti-direction.csv, figures pr-kitti.png and pr-kitti-false.png)
  drift      the allocentric BVC descriptor with the heading drifting 0-60 degrees per sqrt(min) (kitti-drift.csv)
  hall       the hall recording: every descriptor, the protocols that apply (hall.csv, pr-hall.png)
  buildings  tours of the Gazebo hospital and small house (needs the buildings worlds, sensors and tours)
"""
import argparse
import csv
import math
import os
import pathlib
import resource
import subprocess
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
FIGURES = ROOT / "docs" / "figures"
sys.path.insert(0, str(HERE))
import kitti_bev  # noqa: E402

STREET = str(HERE / "street-2d.yaml")
STREET32 = str(HERE / "street-2d-32.yaml")
HALL_UP4 = str(ROOT / "docs" / "real-data" / "hall-up4.yaml")
SEQUENCES = ["00", "02", "05"]
# BEVPlace's split (the data set's README): database and query scans, both included.
SPLITS = {"00": ("0:3000", "3200:4540"), "02": ("0:3400", "3600:4660"), "05": ("0:1000", "1200:2760")}
# Recall@1 (%) published on these images with that split (BEVPlace's README table, as the data set's README
# quotes it): learned, rotation-invariant, and none reads the pose.
PUBLISHED = {"PointNetVLAD": (91.6, 62.3, 76.9), "MinkLoc3D-V2": (95.9, 72.3, 86.4),
             "OverlapTransformer": (96.7, 80.1, 91.9), "BEVPlace": (99.7, 98.1, 99.3)}
KITTI_DESCRIPTORS = [f"bvc:2d", f"bvc:{STREET}", f"bvc:{STREET32}", f"bvc-drift:{STREET32}", f"bvc-free:{STREET32}",
                     f"place-cells:{STREET32}", "scan-context"]
# KITTI-BEV's points reach 35 m (the image's corners): nothing is dropped for range.
KITTI_RANGE = ["--max-range", "40"]
DRIFTS = [0, 1, 5, 20, 60]  # degrees per sqrt(minute)
HALL_DESCRIPTORS = ["bvc:2d", "bvc:3d-0.1", "bvc:3d-0.2", "bvc:3d-3l", f"bvc:{HALL_UP4}", "bvc-drift:3d-3l",
                    "bvc-free:3d-3l", f"bvc-free:{HALL_UP4}", "place-cells:3d-3l", "scan-context"]
# The hall: the default windows; its split in halves; and a window of 3 scans and no time, under which
# a query's neighbours 4-5 scans back (3.6-4.5 m away) are its revisits.
HALL_PROTOCOLS = {"sequential": [], "split": ["--database", "0:29", "--queries", "30:59"],
                  "neighbours": ["--exclude-scans", "3", "--exclude-seconds", "0"]}


def log(*args):
    print("[make]", *args, flush=True)


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def write_csv(name, rows, columns):
    path = HERE / name
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns, lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({c: r.get(c, "") for c in columns})
    log("wrote", path)


def place_recognition(out, *args):
    """Runs `bvc3d place-recognition ARGS --out OUT`; returns its details rows, wall time and the child's
    user and system time."""
    cmd = [str(ROOT / "build" / "bvc3d"), "place-recognition", *map(str, args), "--out", str(out)]
    log(" ".join(cmd))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(cmd, check=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    log(f"  {wall:.1f} s")
    return read_csv(out / "details.csv"), wall, after.ru_utime - before.ru_utime, after.ru_stime - before.ru_stime


def kitti_recording(data, work, sequence, heights):
    """The sequence as a recording in work (written once): its scan list and pose file."""
    folder = work / f"kitti-{sequence}-{'heights' if heights else 'flat'}"
    if not (folder / "scans.txt").exists():
        log("converting", sequence, "heights" if heights else "flat", "->", folder)
        kitti_bev.convert(data / "kitti-bev" / sequence, folder, heights=heights)
    return ["--scans", folder / "scans.txt", "--poses", folder / "poses.txt"]


def machine():
    model = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name")),
                 "?")
    return model, os.cpu_count()


# ------------------------------------------------------------------------------------------- speed

def speed(data, work):
    """KITTI 00 through the 2-D BVC descriptor and Scan Context in one run, then each alone, on 2 threads."""
    rec = kitti_recording(data, work, "00", heights=False)
    model, cores = machine()
    load = os.getloadavg()[0]
    rows = []
    for name, descriptors in [("both", f"bvc:{STREET32},scan-context"), ("bvc", f"bvc:{STREET32}"),
                              ("scan-context", "scan-context")]:
        details, wall, user, system = place_recognition(work / f"speed-{name}", *rec, *KITTI_RANGE, "--descriptors",
                                                        descriptors, "--threads", 2, "--no-figure")
        for d in details:
            rows.append(dict(run=name, descriptor=d["descriptor"], scans=4541, wall_s=f"{wall:.2f}",
                             user_s=f"{user:.2f}", sys_s=f"{system:.2f}", describe_s=f"{float(d['describe_s']):.2f}",
                             search_s=f"{float(d['search_s']):.2f}", recall_at_1=d["recall_at_1"],
                             cpu=model, cores=cores, load_before=f"{load:.2f}"))
    write_csv("speed.csv", rows, ["run", "descriptor", "scans", "wall_s", "user_s", "sys_s", "describe_s", "search_s",
                                  "recall_at_1", "cpu", "cores", "load_before"])
    search_benchmarks(model, cores)


def search_benchmarks(model, cores):
    """The search's micro-benchmarks (test/ubench/bench_place_recognition.cpp), medians of 3."""
    load = os.getloadavg()[0]
    cmd = [str(ROOT / "build" / "test" / "ubench" / "ubench"), "--benchmark_filter=Search|ScanContext",
           "--benchmark_repetitions=3", "--benchmark_report_aggregates_only=true", "--benchmark_format=csv"]
    log(" ".join(cmd))
    text = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    rows = []
    for r in csv.DictReader(text[text.index("name,"):].splitlines()):
        if not r["name"].endswith("_median"):
            continue
        scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[r["time_unit"]]
        per_query = 1000.0 / float(r["items_per_second"]) if r.get("items_per_second") else ""
        rows.append(dict(benchmark=r["name"].removesuffix("_median"), real_ms=f"{float(r['real_time']) * scale:.3f}",
                         cpu_ms=f"{float(r['cpu_time']) * scale:.3f}",
                         ms_per_item=f"{per_query:.3f}" if per_query != "" else "",
                         cpu=model, cores=cores, load_before=f"{load:.2f}"))
    write_csv("search.csv", rows, ["benchmark", "real_ms", "cpu_ms", "ms_per_item", "cpu", "cores", "load_before"])


# ------------------------------------------------------------------------------------------- KITTI

def label(details_row, recording):
    name = details_row["descriptor"]
    return name + " (heights)" if recording == "heights" else name


def direction_rows(out, sequence, protocol):
    """Recall@1 of the revisits made in the same direction and in the opposite one (the nearest older
    scan within 5 m heading more than 90 degrees away), from a run's queries.csv and scans.csv."""
    opposite = {i: turn > math.pi / 2 for i, _, turn, _ in nearest_revisits(out)}
    groups = {}
    for q in read_csv(out / "queries.csv"):
        if q["has_revisit"] != "1":
            continue
        key = (q["descriptor"], "opposite" if opposite[int(q["query"])] else "same")
        n, right = groups.get(key, (0, 0))
        groups[key] = (n + 1, right + (q["correct"] == "1"))
    return [dict(sequence=sequence, protocol=protocol, descriptor=d, direction=k, revisits=n,
                 recall_at_1=f"{right / n:.4f}") for (d, k), (n, right) in sorted(groups.items())]


def nearest_revisits(out, window_s=30.0, window_scans=50):
    """For each query with a revisit (the default windows): the query, its nearest scan outside the window,
    their heading difference (rad) and the time between them (s)."""
    scans = read_csv(out / "scans.csv")
    xy = np.array([[float(s["x"]), float(s["y"])] for s in scans])
    h = np.array([float(s["heading"]) for s in scans])
    t = np.array([float(s["t"]) for s in scans])
    first = read_csv(out / "details.csv")[0]["descriptor"]
    out_rows = []
    for q in read_csv(out / "queries.csv"):
        if q["descriptor"] != first or q["has_revisit"] != "1":
            continue
        i = int(q["query"])
        old = np.nonzero((i - np.arange(len(xy)) > window_scans) & (t[i] - t > window_s))[0]
        j = old[np.argmin(np.hypot(*(xy[old] - xy[i]).T))]
        out_rows.append((i, j, abs(math.remainder(h[i] - h[j], 2 * math.pi)), t[i] - t[j]))
    return out_rows


def revisit_row(out, sequence):
    """How a sequence's revisits come: in which direction, and how long after the place was last seen."""
    r = nearest_revisits(out)
    gap = np.array([g for *_, g in r]) / 60
    opposite = sum(1 for _, _, turn, _ in r if turn > math.pi / 2)
    return dict(sequence=sequence, revisits=len(r), same_direction=len(r) - opposite, opposite_direction=opposite,
                gap_min_minutes=f"{gap.min():.2f}", gap_median_minutes=f"{np.median(gap):.2f}",
                gap_max_minutes=f"{gap.max():.2f}")


def kitti(data, work):
    rows, directions = [], []
    for s in SEQUENCES:
        for protocol, extra in [("sequential", []), ("split", ["--database", SPLITS[s][0], "--queries", SPLITS[s][1]])]:
            for recording, descriptors in [("flat", KITTI_DESCRIPTORS), ("heights", ["scan-context"])]:
                out = work / f"kitti-{s}-{protocol}-{recording}"
                details, wall, _, _ = place_recognition(out, *kitti_recording(data, work, s, recording == "heights"),
                                                        *KITTI_RANGE, "--descriptors", ",".join(descriptors), *extra,
                                                        "--no-figure")
                queries = read_csv(out / "queries.csv")
                for d in details:
                    # Queries that share nothing with any candidate (a silent place-cell vector, say).
                    one = sum(1 for q in queries
                              if q["descriptor"] == d["descriptor"] and float(q["distance"]) >= 1 - 1e-9)
                    rows.append(dict(d, sequence=s, recording=recording, descriptor=label(d, recording),
                                     distance_one=one))
                if protocol == "sequential":
                    for r in direction_rows(out, s, protocol):
                        directions.append(dict(r, descriptor=r["descriptor"] + (" (heights)" if recording == "heights"
                                                                                 else "")))
    write_csv("kitti.csv", rows, ["sequence", "protocol", "recording", "descriptor", "uses_heading", "recall_at_1",
                                  "f1_max", "auc", "queries", "revisits", "correct", "median_match_m", "distance_one",
                                  "describe_s", "search_s"])
    write_csv("kitti-revisits.csv", [revisit_row(work / f"kitti-{s}-sequential-flat", s) for s in SEQUENCES],
              ["sequence", "revisits", "same_direction", "opposite_direction", "gap_min_minutes",
               "gap_median_minutes", "gap_max_minutes"])
    write_csv("kitti-direction.csv", directions, ["sequence", "protocol", "descriptor", "direction", "revisits",
                                                   "recall_at_1"])
    write_csv("kitti-published.csv",
              [dict(method=m, sequence=s, protocol="split", recall_at_1=v[k], uses_heading=0,
                    source="BEVPlace README (zjuluolun/BEVPlace), as quoted by the KITTI-BEV data set's README")
               for m, v in PUBLISHED.items() for k, s in enumerate(SEQUENCES)],
              ["method", "sequence", "protocol", "recall_at_1", "uses_heading", "source"])
    figure_kitti(work)
    figure_false_positives(work, "00")


def figure_kitti(work):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(16, 5.4), sharey=True)
    for ax, s in zip(axes, SEQUENCES):
        for recording in ["flat", "heights"]:
            out = work / f"kitti-{s}-sequential-{recording}"
            pr = read_csv(out / "pr.csv")
            for d in read_csv(out / "details.csv"):
                name = label(d, recording)
                points = [p for p in pr if p["descriptor"] == d["descriptor"]]
                heading = " *" if d["uses_heading"] == "1" else ""
                ax.plot([float(p["recall"]) for p in points], [float(p["precision"]) for p in points], lw=1.2,
                        ls="--" if recording == "heights" else "-",
                        label=f"{name}{heading}: R@1 {100 * float(d['recall_at_1']):.1f}%, "
                              f"F1 {float(d['f1_max']):.2f}")
        ax.set_title(f"KITTI {s}, sequential loop closure", fontsize=10)
        ax.set_xlabel("recall")
        ax.set_xlim(0, 1.02)
        ax.set_ylim(0, 1.02)
        ax.legend(fontsize=6.5, loc="lower left")
    axes[0].set_ylabel("precision")
    fig.suptitle("* reads the pose's heading", fontsize=9, x=0.99, ha="right")
    fig.tight_layout()
    fig.savefig(FIGURES / "pr-kitti.png", dpi=110)
    plt.close(fig)
    log("wrote", FIGURES / "pr-kitti.png")


def f1_threshold(pr_rows):
    best = (-1.0, 0.0)
    for p in pr_rows:
        prec, rec = float(p["precision"]), float(p["recall"])
        if prec + rec > 0 and 2 * prec * rec / (prec + rec) > best[0]:
            best = (2 * prec * rec / (prec + rec), float(p["threshold"]))
    return best[1]


def figure_false_positives(work, sequence):
    """The route of one sequence and, per descriptor, its loop closures at its F1max threshold: right
    ones (green) and false ones (red lines from the query to where it was matched); and how far the
    false ones reach (kitti-false.csv)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    out = work / f"kitti-{sequence}-sequential-flat"
    scans = read_csv(out / "scans.csv")
    xy = np.array([[float(s["x"]), float(s["y"])] for s in scans])
    names = ["bvc:street-2d-32", "bvc-free:street-2d-32", "scan-context"]
    pr, queries = read_csv(out / "pr.csv"), read_csv(out / "queries.csv")
    fig, axes = plt.subplots(1, len(names), figsize=(5.4 * len(names), 5.4))
    rows = []
    for ax, name in zip(axes, names):
        tau = f1_threshold([p for p in pr if p["descriptor"] == name])
        ax.plot(xy[:, 0], xy[:, 1], c="0.75", lw=0.8)
        right, false = 0, []
        for q in queries:
            if q["descriptor"] != name or float(q["distance"]) > tau:
                continue
            i, m = int(q["query"]), int(q["match"])
            if q["correct"] == "1":
                right += 1
                ax.plot(*xy[i], ".", c="tab:green", ms=2)
            else:
                false.append(float(q["match_m"]))
                ax.plot([xy[i, 0], xy[m, 0]], [xy[i, 1], xy[m, 1]], "-", c="tab:red", lw=0.6)
                ax.plot(*xy[i], ".", c="tab:red", ms=3)
        ax.set_title(f"KITTI {sequence}, {name}\nat its F1max threshold: {right} right, {len(false)} false",
                     fontsize=9)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x (m)")
        f = np.array(false)
        rows.append(dict(sequence=sequence, descriptor=name, threshold=f"{tau:.6f}", right=right, false=len(f),
                         false_median_m=f"{np.median(f):.1f}", false_within_20m=int(np.sum(f <= 20)),
                         false_min_m=f"{f.min():.1f}", false_max_m=f"{f.max():.1f}"))
    fig.tight_layout()
    fig.savefig(FIGURES / "pr-kitti-false.png", dpi=110)
    plt.close(fig)
    log("wrote", FIGURES / "pr-kitti-false.png")
    write_csv("kitti-false.csv", rows, ["sequence", "descriptor", "threshold", "right", "false", "false_median_m",
                                        "false_within_20m", "false_min_m", "false_max_m"])


# ------------------------------------------------------------------------------------------- drift

def drift(data, work):
    rows = []
    for s in SEQUENCES:
        for d in DRIFTS:
            details, _, _, _ = place_recognition(work / f"drift-{s}-{d}", *kitti_recording(data, work, s, False),
                                                 *KITTI_RANGE, "--descriptors", f"bvc-drift:{STREET32}",
                                                 "--drift-deg-per-sqrt-min", d, "--no-figure")
            drifted = np.abs([float(r["drift"]) for r in read_csv(work / f"drift-{s}-{d}" / "scans.csv")])
            for r in details:
                rows.append(dict(r, sequence=s, drift_deg_per_sqrt_min=d,
                                 final_drift_deg=f"{math.degrees(drifted[-1]):.2f}",
                                 max_drift_deg=f"{math.degrees(drifted.max()):.2f}"))
    write_csv("kitti-drift.csv", rows, ["sequence", "drift_deg_per_sqrt_min", "final_drift_deg", "max_drift_deg",
                                        "descriptor", "recall_at_1", "f1_max", "auc", "queries", "revisits"])


# ------------------------------------------------------------------------------------------- hall

def hall(data, work):
    rec = ["--scans", data / "hall-lidar", "--poses", data / "hall-lidar" / "poses.csv"]
    rows = []
    for protocol, extra in HALL_PROTOCOLS.items():
        out = work / f"hall-{protocol}"
        details, _, _, _ = place_recognition(out, *rec, "--descriptors", ",".join(HALL_DESCRIPTORS), *extra,
                                             "--no-figure")
        queries = read_csv(out / "queries.csv")
        for d in details:
            mine = [q for q in queries if q["descriptor"] == d["descriptor"]]
            wrong = [q for q in mine if q["correct"] != "1"]
            right = [float(q["distance"]) for q in mine if q["correct"] == "1"]
            wrong_d = [float(q["distance"]) for q in wrong]
            wrong_m = [float(q["match_m"]) for q in wrong]
            rows.append(dict(d, protocol=protocol,
                             min_wrong_distance=f"{min(wrong_d):.4f}" if wrong else "",
                             median_right_distance=f"{np.median(right):.4f}" if right else "",
                             median_wrong_match_m=f"{np.median(wrong_m):.2f}" if wrong else "",
                             min_wrong_match_m=f"{min(wrong_m):.2f}" if wrong else "",
                             max_wrong_match_m=f"{max(wrong_m):.2f}" if wrong else ""))
    write_csv("hall.csv", rows, ["protocol", "descriptor", "uses_heading", "recall_at_1", "f1_max", "auc", "queries",
                                 "revisits", "correct", "median_match_m", "min_wrong_distance",
                                 "median_right_distance", "median_wrong_match_m", "min_wrong_match_m",
                                 "max_wrong_match_m"])


# ------------------------------------------------------------------------------------------- buildings

BUILDINGS = {"hospital": "gazebo/aws-robomaker-hospital-world/worlds/hospital.world",
             "small-house": "gazebo/aws-robomaker-small-house-world/worlds/small_house.world"}
BUILDING_SENSOR = "os1-64"  # a real 64-beam sensor model with its range noise (issue 27's presets)
BUILDING3D = str(HERE / "building-3d.yaml")
BUILDING_DESCRIPTORS = ["bvc:2d", "bvc:3d-0.1", "bvc:3d-0.2", "bvc:3d-3l", f"bvc:{BUILDING3D}", "bvc-free:3d-3l",
                        f"bvc-free:{BUILDING3D}", "place-cells:3d-3l", f"place-cells:{BUILDING3D}", "scan-context"]
BUILDING_FIGURE = ["bvc:2d", "bvc:3d-3l", "bvc:building-3d", "scan-context"]
RAISED = 0.5  # m: the sensor's height above the map's, for the height step (queries 0.5 m higher)


def bvc3d(*args, **kw):
    cmd = [str(ROOT / "build" / "bvc3d"), *map(str, args)]
    log(" ".join(cmd))
    return subprocess.run(cmd, check=True, **kw)


def floor_plan(world, route, work, name):
    """The building seen from above: the points a scan of every 20th route pose hits between 0.3 and 1.8 m
    above the floor (export-scans' scans in the world frame)."""
    rows = np.loadtxt(route, delimiter=",", skiprows=1)
    header = route.read_text().splitlines()[0]
    sparse = work / f"{name}-plan-route.csv"
    np.savetxt(sparse, rows[::20], delimiter=",", header=header, comments="", fmt="%.9g")
    folder = work / f"{name}-plan"
    bvc3d("export-scans", "--world", world, "--trajectory", sparse, "--sensor", BUILDING_SENSOR, "--format", "pcd",
          "--out", folder)
    poses = np.loadtxt(folder / "poses.txt", delimiter=",", usecols=(0, 1, 2, 3)).reshape(-1, 4, 4)  # 4x4 rows, time
    points = []
    for k, pose in enumerate(poses):
        data = (folder / f"{k:06d}.pcd").read_bytes()
        p = np.frombuffer(data[data.index(b"DATA binary\n") + 12:], dtype="<f4").reshape(-1, 3).astype(float)
        w = p @ pose[:3, :3].T + pose[:3, 3]
        points.append(w[(w[:, 2] > 0.3) & (w[:, 2] < 1.8), :2])
    return np.vstack(points)


def building_figure(work, name, plan):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    out = work / f"{name}-tour"
    scans = read_csv(out / "scans.csv")
    xy = np.array([[float(s["x"]), float(s["y"])] for s in scans])
    pr, queries = read_csv(out / "pr.csv"), read_csv(out / "queries.csv")
    fig, axes = plt.subplots(1, len(BUILDING_FIGURE), figsize=(4.8 * len(BUILDING_FIGURE), 5))
    rows = []
    for ax, descriptor in zip(axes, BUILDING_FIGURE):
        tau = f1_threshold([p for p in pr if p["descriptor"] == descriptor])
        ax.plot(plan[:, 0], plan[:, 1], ",", c="0.6")
        ax.plot(xy[:, 0], xy[:, 1], c="0.3", lw=0.5)
        right, false = 0, []
        for q in queries:
            if q["descriptor"] != descriptor or float(q["distance"]) > tau:
                continue
            i, m = int(q["query"]), int(q["match"])
            if q["correct"] == "1":
                right += 1
            else:
                false.append(float(q["match_m"]))
                ax.plot([xy[i, 0], xy[m, 0]], [xy[i, 1], xy[m, 1]], "-", c="tab:red", lw=0.7)
                ax.plot(*xy[i], ".", c="tab:red", ms=3)
        ax.set_title(f"{name}, {descriptor}\nat its F1max threshold: {right} right, {len(false)} false", fontsize=9)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x (m)")
        rows.append(dict(building=name, descriptor=descriptor, threshold=f"{tau:.6f}", right=right, false=len(false),
                         false_median_m=f"{np.median(false):.1f}" if false else ""))
    fig.tight_layout()
    fig.savefig(FIGURES / f"pr-{name}.png", dpi=110)
    plt.close(fig)
    log("wrote", FIGURES / f"pr-{name}.png")
    return rows


def raised(route, work, name):
    """The tour driven twice, the second time with the sensor RAISED higher (times continue): with the
    first drive as the database and the second as the queries, a map made at one height queried at another."""
    rows = np.loadtxt(route, delimiter=",", skiprows=1)
    names = route.read_text().splitlines()[0].split(",")
    if "z" not in names:
        rows = np.insert(rows, 3, 0.0, axis=1)
        names.insert(3, "z")
    second = rows.copy()
    second[:, 0] += rows[-1, 0] + 1.0
    second[:, names.index("z")] += RAISED
    path = work / f"{name}-raised.csv"
    np.savetxt(path, np.vstack([rows, second]), delimiter=",", header=",".join(names), comments="", fmt="%.9g")
    return path, len(rows)


def buildings(data, work):
    """Tours of the Gazebo hospital and small house scanned by a real sensor model (issue 27's worlds,
    sensors and tours): every descriptor, the sequential protocol, where the false positives lie, and the
    same tour queried with the sensor 0.5 m higher than the map's."""
    if subprocess.run([str(ROOT / "build" / "bvc3d"), "route", "--help"], capture_output=True).returncode != 0:
        sys.exit("the buildings step needs `bvc3d route --tour`, Gazebo worlds and real sensor presets (issue 27): "
                 "not in this build")
    rows, directions, false_rows = [], [], []
    for name, relative in BUILDINGS.items():
        world = data / relative
        route = work / f"{name}-tour-route.csv"
        if not route.exists():
            bvc3d("route", "--world", world, "--tour", "--out", route)
        for protocol, path, extra in [("sequential", route, []), ("raised", *raised_args(route, work, name))]:
            out = work / f"{name}-{'tour' if protocol == 'sequential' else 'raised'}"
            details, _, _, _ = place_recognition(out, "--world", world, "--route", path, "--sensor", BUILDING_SENSOR,
                                                 "--descriptors", ",".join(BUILDING_DESCRIPTORS), *extra,
                                                 "--no-figure")
            for d in details:
                rows.append(dict(d, building=name, protocol=protocol))
            if protocol == "sequential":
                directions += [dict(r, sequence=name) for r in direction_rows(out, name, protocol)]
        false_rows += building_figure(work, name, floor_plan(world, route, work, name))
    write_csv("buildings.csv", rows, ["building", "protocol", "descriptor", "uses_heading", "recall_at_1", "f1_max",
                                      "auc", "queries", "revisits", "correct", "median_match_m"])
    write_csv("buildings-direction.csv", directions, ["sequence", "protocol", "descriptor", "direction", "revisits",
                                                      "recall_at_1"])
    write_csv("buildings-false.csv", false_rows, ["building", "descriptor", "threshold", "right", "false",
                                                  "false_median_m"])


def raised_args(route, work, name):
    path, n = raised(route, work, name)
    return path, ["--database", f"0:{n - 1}", "--queries", f"{n}:{2 * n - 1}"]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--data", required=True, type=pathlib.Path,
                        help="the folder holding kitti-bev/, hall-lidar/ and gazebo/")
    parser.add_argument("--work", type=pathlib.Path, default=pathlib.Path("/tmp/bvc3d-place-recognition"))
    parser.add_argument("--steps", nargs="*", default=["speed", "kitti", "drift", "hall"])
    args = parser.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    FIGURES.mkdir(parents=True, exist_ok=True)
    os.environ.setdefault("PYTHONPATH", str(ROOT / "build" / "python"))
    steps = {"speed": speed, "kitti": kitti, "drift": drift, "hall": hall, "buildings": buildings}
    for step in args.steps:
        if step not in steps:
            sys.exit(f"unknown step '{step}' (known: {', '.join(steps)})")
        log("step", step)
        steps[step](args.data.resolve(), args.work.resolve())


if __name__ == "__main__":
    main()
