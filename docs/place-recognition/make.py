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
  hall       the hall recording: every descriptor, the protocols that apply (hall.csv)
  buildings  tours of the Gazebo hospital and small house scanned by an os1-64: every descriptor, recall by
             revisit radius and direction, the false loop closures; the tour driven again at the same height
             and with the sensor 0.5 m higher (buildings.csv, buildings-radius.csv, buildings-false.csv,
             figures pr-buildings.png, pr-hospital.png, pr-small-house.png)
"""
import argparse
import csv
import json
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
KITTI_DESCRIPTORS = ["bvc:2d", f"bvc:{STREET}", f"bvc:{STREET32}", f"bvc-drift:{STREET32}", f"bvc-free:{STREET32}",
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


def place_recognition_once(out, *args):
    """place_recognition(), unless OUT already holds the tables of an earlier run of this script (their
    timing.json beside them: the command writes its tables whole or not at all), so that a long step
    interrupted part-way resumes. Returns the details rows, wall and user time, and the load before."""
    timing = out / "timing.json"
    if timing.exists() and (out / "details.csv").exists():
        log("reusing", out)
        t = json.loads(timing.read_text())
        return read_csv(out / "details.csv"), t["wall_s"], t["user_s"], t["load_before"]
    load = os.getloadavg()[0]
    details, wall, user, _ = place_recognition(out, *args)
    timing.write_text(json.dumps({"wall_s": wall, "user_s": user, "load_before": load}))
    return details, wall, user, load


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
                plot_curve(ax, d, pr, label(d, recording), 1.2, recording == "heights")
        finish_pr_panel(ax, f"KITTI {s}, sequential loop closure")
    save_pr_figure(fig, axes, "pr-kitti.png")


def plot_curve(ax, d, pr, name, lw, dashed):
    """One descriptor's precision-recall curve (its details row d, the run's pr rows), labelled with its
    recall@1 and F1max; * marks a descriptor that reads the pose's heading."""
    points = [p for p in pr if p["descriptor"] == d["descriptor"]]
    heading = " *" if d["uses_heading"] == "1" else ""
    ax.plot([float(p["recall"]) for p in points], [float(p["precision"]) for p in points], lw=lw,
            ls="--" if dashed else "-",
            label=f"{name}{heading}: R@1 {100 * float(d['recall_at_1']):.1f}%, F1 {float(d['f1_max']):.2f}")


def finish_pr_panel(ax, title):
    ax.set_title(title, fontsize=10)
    ax.set_xlabel("recall")
    ax.set_xlim(0, 1.02)
    ax.set_ylim(0, 1.02)
    ax.legend(fontsize=6.5, loc="lower left")


def save_pr_figure(fig, axes, file):
    import matplotlib.pyplot as plt
    axes[0].set_ylabel("precision")
    fig.suptitle("* reads the pose's heading", fontsize=9, x=0.99, ha="right")
    fig.tight_layout()
    fig.savefig(FIGURES / file, dpi=110)
    plt.close(fig)
    log("wrote", FIGURES / file)


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

# The AWS worlds include models that Gazebo fetches from its online store; they are not in the data set,
# so the buildings are loaded without them (docs/buildings.md).
BUILDINGS = {"hospital": "gazebo/aws-robomaker-hospital-world/worlds/hospital.world",
             "small-house": "gazebo/aws-robomaker-small-house-world/worlds/small_house.world"}
BUILDING_SENSOR = "os1-64"  # a real 64-beam sensor model with its range noise (0.03 m), 0.18 m above the base
BUILDING3D = str(HERE / "building-3d.yaml")
BUILDING1L = str(HERE / "building-1l.yaml")  # building-3d's horizontal layer alone: what its upward layers add
BUILDING_DESCRIPTORS = ["bvc:2d", "bvc:3d-0.1", "bvc:3d-0.2", "bvc:3d-3l", f"bvc:{BUILDING1L}", f"bvc:{BUILDING3D}",
                        f"bvc-drift:{BUILDING3D}", "bvc-free:3d-3l", f"bvc-free:{BUILDING3D}", "place-cells:3d-3l",
                        f"place-cells:{BUILDING3D}", "scan-context"]
# The drives at two heights: the descriptors whose answer the height could change, one of each kind.
HEIGHT_DESCRIPTORS = ["bvc:2d", "bvc:3d-3l", f"bvc:{BUILDING1L}", f"bvc:{BUILDING3D}", f"bvc-free:{BUILDING3D}",
                      f"place-cells:{BUILDING3D}", "scan-context"]
BUILDING_FIGURE = ["bvc:2d", "bvc:3d-3l", "bvc:building-3d", "scan-context"]
RADII = [1.0, 2.0, 5.0]  # m: recall@1 with these revisit radii, from the runs at the protocol's 5 m
FAR_M = 10.0  # m: a false loop closure this far from the query joins two different places
# The step further: the tour driven twice, the second drive as queries against the first. "level": the
# same height (only the sensor's noise differs: the control); "raised": the sensor 0.5 m higher, as a
# robot of another height, or a map made by another platform, would see the building.
HEIGHT_STEPS = {"level": 0.0, "raised": 0.5}


def bvc3d(*args, **kw):
    cmd = [str(ROOT / "build" / "bvc3d"), *map(str, args)]
    log(" ".join(cmd))
    return subprocess.run(cmd, check=True, **kw)


def world_yaml(data, work, name):
    """A world YAML in work that loads the building without the models it cannot find."""
    path = work / f"{name}.yaml"
    path.write_text(f"sdf: {data / BUILDINGS[name]}\nmissing_models: skip\n")
    return path


def floor_plan(world, route, every=20):
    """The building seen from above: the points that os1-64 scans from every 20th pose of the route hit
    between 0.3 and 1.8 m above the floor (x, y)."""
    sys.path.insert(0, os.environ["PYTHONPATH"])  # main() points it at this build's package
    import bvc3d as py
    w = py.World.from_yaml(world)
    rows = np.loadtxt(route, delimiter=",", skiprows=1)
    points = []
    for t, x, y, z, heading in rows[::every, :5]:
        s = w.scan(BUILDING_SENSOR, x, y, heading, z=z)
        r, az, el = s[:, 0], s[:, 1], s[:, 2]
        p = np.column_stack([x + r * np.cos(el) * np.cos(az), y + r * np.cos(el) * np.sin(az),
                             z + 0.18 + r * np.sin(el)])
        points.append(p[(p[:, 2] > 0.3) & (p[:, 2] < 1.8), :2])
    return np.vstack(points)


def nearest_older(out, window_s=30.0, window_scans=50):
    """Per scan of a sequential run: the distance (m) to the nearest scan outside its exclusion window and
    that scan's heading difference (rad); NaN where none is old enough."""
    scans = read_csv(out / "scans.csv")
    xy = np.array([[float(s["x"]), float(s["y"])] for s in scans])
    h = np.array([float(s["heading"]) for s in scans])
    t = np.array([float(s["t"]) for s in scans])
    near, turn = np.full(len(xy), np.nan), np.full(len(xy), np.nan)
    for i in range(len(xy)):
        old = np.nonzero((i - np.arange(len(xy)) > window_scans) & (t[i] - t > window_s))[0]
        if len(old):
            d = np.hypot(*(xy[old] - xy[i]).T)
            near[i] = d.min()
            turn[i] = abs(math.remainder(h[i] - h[old[np.argmin(d)]], 2 * math.pi))
    return near, turn


def radius_rows(out, name):
    """Recall@1 with revisit radii of 1, 2 and 5 m (the best match does not depend on the radius): the
    queries whose nearest older scan lies within R, and how many of their matches lie within R; split by
    the direction of that nearest scan (same: within 90 degrees)."""
    near, turn = nearest_older(out)
    rows = []
    for q_desc in [d["descriptor"] for d in read_csv(out / "details.csv")]:
        queries = [q for q in read_csv(out / "queries.csv") if q["descriptor"] == q_desc]
        i = np.array([int(q["query"]) for q in queries])
        m = np.array([float(q["match_m"]) for q in queries])
        for radius in RADII:
            for direction, keep in [("both", np.ones(len(i), bool)), ("same", turn[i] <= math.pi / 2),
                                    ("opposite", turn[i] > math.pi / 2)]:
                has = (near[i] <= radius) & keep
                rows.append(dict(building=name, descriptor=q_desc, radius_m=radius, direction=direction,
                                 revisits=int(has.sum()),
                                 recall_at_1=f"{np.mean(m[has] <= radius):.4f}" if has.any() else "nan"))
    return rows


def false_rows(out, name):
    """False loop closures per descriptor: at its F1max threshold (how many, how far, how many join places
    more than 10 m apart), and at equal recall (25 and 50 % of the revisits: the false ones then accepted,
    from the curve's interpolated precision)."""
    pr, queries = read_csv(out / "pr.csv"), read_csv(out / "queries.csv")
    rows = []
    for d in read_csv(out / "details.csv"):
        name_d = d["descriptor"]
        curve = [p for p in pr if p["descriptor"] == name_d]
        tau = f1_threshold(curve)
        accepted = [q for q in queries if q["descriptor"] == name_d and float(q["distance"]) <= tau]
        false = np.array([float(q["match_m"]) for q in accepted if q["correct"] != "1"])
        row = dict(building=name, descriptor=name_d, threshold=f"{tau:.6f}",
                   right=sum(1 for q in accepted if q["correct"] == "1"), false=len(false),
                   false_far=int(np.sum(false > FAR_M)),
                   false_median_m=f"{np.median(false):.1f}" if len(false) else "")
        revisits = int(d["revisits"])
        for r in (0.25, 0.5):
            ps = [float(p["precision"]) for p in curve if float(p["recall"]) >= r]
            p = max(ps) if ps else 0.0
            row[f"false_at_recall_{int(r * 100)}"] = f"{r * revisits * (1 - p) / p:.0f}" if p > 0 else ""
        rows.append(row)
    return rows


def threshold_at_recall(curve, recall):
    """The smallest threshold at which a curve reaches `recall` (its largest if it never does)."""
    reached = [float(p["threshold"]) for p in curve if float(p["recall"]) >= recall]
    return min(reached) if reached else max(float(p["threshold"]) for p in curve)


def building_figure(out, name, plan):
    """The building from above with the tour, and per descriptor its false loop closures where it finds a
    quarter of the revisits (red: from the query to where it was matched): the same recall for each."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scans = read_csv(out / "scans.csv")
    xy = np.array([[float(s["x"]), float(s["y"])] for s in scans])
    pr, queries = read_csv(out / "pr.csv"), read_csv(out / "queries.csv")
    wide = np.ptp(plan[:, 0]) > np.ptp(plan[:, 1])
    n = len(BUILDING_FIGURE)
    fig, axes = plt.subplots(2 if wide else 1, n // 2 if wide else n, figsize=(13, 8.4) if wide else (4.4 * n, 9.4))
    for ax, descriptor in zip(axes.flat, BUILDING_FIGURE):
        tau = threshold_at_recall([p for p in pr if p["descriptor"] == descriptor], 0.25)
        ax.plot(plan[:, 0], plan[:, 1], ",", c="0.55")
        ax.plot(xy[:, 0], xy[:, 1], c="tab:blue", lw=0.4, alpha=0.6)
        right, false = 0, 0
        for q in queries:
            if q["descriptor"] != descriptor or float(q["distance"]) > tau:
                continue
            i, m = int(q["query"]), int(q["match"])
            if q["correct"] == "1":
                right += 1
                continue
            false += 1
            # Thousands of lines: faint, so that where they gather shows; the queries as dots on top.
            ax.plot([xy[i, 0], xy[m, 0]], [xy[i, 1], xy[m, 1]], "-", c="tab:red", lw=0.3, alpha=0.06)
            ax.plot(*xy[i], "o", c="tab:red", ms=1.5, alpha=0.6)
        ax.set_title(f"{name}, {descriptor}\nat a quarter of the revisits: {right} right, {false} false", fontsize=9)
        ax.set_xlim(plan[:, 0].min() - 0.5, plan[:, 0].max() + 0.5)
        ax.set_ylim(plan[:, 1].min() - 0.5, plan[:, 1].max() + 0.5)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=7)
    fig.tight_layout()
    fig.savefig(FIGURES / f"pr-{name}.png", dpi=100)
    plt.close(fig)
    log("wrote", FIGURES / f"pr-{name}.png")


def figure_buildings_pr(work):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(BUILDINGS), figsize=(12, 5.2), sharey=True)
    for ax, name in zip(axes, BUILDINGS):
        out = work / f"{name}-tour"
        pr = read_csv(out / "pr.csv")
        for d in read_csv(out / "details.csv"):
            plot_curve(ax, d, pr, d["descriptor"], 1.1, d["descriptor"].startswith(("bvc-", "place-")))
        finish_pr_panel(ax, f"{name} tour ({BUILDING_SENSOR}), sequential loop closure")
    save_pr_figure(fig, axes, "pr-buildings.png")


def driven_twice(route, work, name, lift):
    """The tour driven twice (times continue), the second time with the base `lift` m higher; returns the
    route file and the number of rows of one drive."""
    rows = np.loadtxt(route, delimiter=",", skiprows=1)
    names = route.read_text().splitlines()[0].split(",")
    second = rows.copy()
    second[:, 0] += rows[-1, 0] + 1.0
    second[:, names.index("z")] += lift
    path = work / f"{name}-twice-{lift:g}.csv"
    np.savetxt(path, np.vstack([rows, second]), delimiter=",", header=",".join(names), comments="", fmt="%.17g")
    return path, len(rows)


def buildings(data, work):
    """Tours of the Gazebo hospital and small house scanned by a real sensor model (issue 27's worlds,
    sensors and tours): every descriptor, the sequential protocol, recall by revisit radius and direction,
    where the false loop closures lie; then the tour driven again as queries, at the same height and with
    the sensor 0.5 m higher."""
    if subprocess.run([str(ROOT / "build" / "bvc3d"), "route", "--help"], capture_output=True).returncode != 0:
        sys.exit("the buildings step needs `bvc3d route --tour`, Gazebo worlds and real sensor presets: not in "
                 "this build")
    model, cores = machine()
    rows, radius, false = [], [], []
    for name in BUILDINGS:
        world = world_yaml(data, work, name)
        route = work / f"{name}-tour-route.csv"
        if not route.exists():
            bvc3d("route", "--world", world, "--tour", "--out", route)
        runs = [("sequential", f"{name}-tour", route, BUILDING_DESCRIPTORS, [])]
        for step, lift in HEIGHT_STEPS.items():
            path, n = driven_twice(route, work, name, lift)
            runs.append((step, f"{name}-{step}", path, HEIGHT_DESCRIPTORS,
                         ["--database", f"0:{n - 1}", "--queries", f"{n}:{2 * n - 1}"]))
        for protocol, folder, path, descriptors, extra in runs:
            out = work / folder
            details, wall, user, load = place_recognition_once(out, "--world", world, "--route", path, "--sensor",
                                                               BUILDING_SENSOR, "--descriptors", ",".join(descriptors),
                                                               "--threads", 2, *extra, "--no-figure")
            for d in details:
                rows.append(dict(d, building=name, protocol=protocol, scans=len(read_csv(out / "scans.csv")),
                                 wall_s=f"{wall:.1f}", user_s="" if user is None else f"{user:.1f}",
                                 load_before="" if load is None else f"{load:.2f}", cpu=model,
                                 cores=cores))
        radius += radius_rows(work / f"{name}-tour", name)
        false += false_rows(work / f"{name}-tour", name)
        building_figure(work / f"{name}-tour", name, floor_plan(world, route))
    write_csv("buildings.csv", rows, ["building", "protocol", "descriptor", "uses_heading", "recall_at_1", "f1_max",
                                      "auc", "queries", "revisits", "correct", "median_match_m", "describe_s",
                                      "scans", "wall_s", "user_s", "load_before", "cpu", "cores"])
    write_csv("buildings-radius.csv", radius, ["building", "descriptor", "radius_m", "direction", "revisits",
                                               "recall_at_1"])
    write_csv("buildings-false.csv", false, ["building", "descriptor", "threshold", "right", "false", "false_far",
                                             "false_median_m", "false_at_recall_25", "false_at_recall_50"])
    figure_buildings_pr(work)


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
