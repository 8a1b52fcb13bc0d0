"""Regenerates the results of docs/building-scale.md: place cells that cover a building, on the hall-lidar recording
and on a Gazebo building's floor.

    /usr/bin/python3 docs/building-scale/make.py --recording PATH/hall-lidar [--work DIR] [--steps rates growing ...]
    /usr/bin/python3 docs/building-scale/make.py --house PATH/aws-robomaker-small-house-world --steps floor
    /usr/bin/python3 docs/building-scale/make.py --steps arenas

Reuses the setup of docs/real-data.md's place-cell step (docs/real-data/make.py: the hall's map in the floor's
frame, the 0.5 m template grid, the real scans as queries, the paper's random walk of a person-sized body) and its
read-out (each scan's settled place-cell response, decoded to the most cosine-similar template). Run from the
repository's root after building (build/bvc3d and build/python). Writes the tables (CSV) next to this script; the
large intermediate files (the map, BVC rates along the walk) go to --work (the same default as docs/real-data's, so
the two scripts share them). Steps (default: rates growing; in this order):

  rates    the hall's map and templates (if not there yet), and each model's BVC rates of the templates, the real
           scans and the learning walk (cached in --work)
  growing  a growing place-cell network (bvc3d.GrowingPlaceCells) learned on the walk, every real scan localized
           with it, beside the BVC decoding of the same model and the paper's 250 cells
  multiscale  ms-2d's three scales with their place cells reading BVCs alone (g = 0) learned on the same walk,
           each scale and the scales fused decoded as `growing` decodes (hall-multiscale.csv)
  floor    trials of eight models (FLOOR_MODELS) × FLOOR_SEEDS seeds on the floor of the AWS RoboMaker small house
           (--house: the world's folder as AWS publishes it), run by `bvc3d sweep` in --work/gazebo-floor (a rerun
           skips the trials already there); every analysed population of every trial → floor.csv, floor.png
  arenas   the paper's experiment (`bvc3d paper`, the tilted cross arenas, 4 h + 4 h) of 2d, 3d-3l, ms-2d and ms-3d
           × ARENA_SEEDS seeds in --work/arenas (resumable); every place-cell population → arenas.csv, arenas.png

A hall model is one line of MODELS, a floor model one of FLOOR_MODELS. Sized for a shared 2-core machine: see
docs/building-scale.md for what was run.
"""
import argparse
import csv
import importlib.util
import pathlib
import shutil
import subprocess
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]

# The models, each a name bvc3d knows (a preset) or one of docs/real-data's YAML files. One line each.
MODELS = [
    "2d",
    "3d-3l",
]
WALK_HOURS = 1.0  # the learning walk (docs/real-data.md's place-cell step: one hour, seed 0)
WALK_SEED = 0


def load_real_data():
    """docs/real-data/make.py as a module: its setup and read-out are this page's too."""
    spec = importlib.util.spec_from_file_location("real_data_make", ROOT / "docs" / "real-data" / "make.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


rd = load_real_data()
log = rd.log


def walk_and_rates(setup, name, model=None, seed=WALK_SEED):
    """The learning walk (docs/real-data.md's) and model `name`'s BVC rates along it, float32 (the place cells take
    their inputs as float32, so nothing is lost), cached in floor/NAME-walk-Hh.npz (NAME-walk-Hh-seedS.npz for
    another walk than WALK_SEED's). `model`: a model YAML to read instead of the name (default: rd.model_arg(name))."""
    import bvc3d
    suffix = "" if seed == WALK_SEED else f"-seed{seed}"
    cache = setup["floor"] / f"{name}-walk-{WALK_HOURS:g}h{suffix}.npz"
    if not cache.exists():
        start = time.time()
        walk = bvc3d.random_walk(setup["world"], WALK_HOURS, seed, height=rd.BODY_HEIGHT)
        path = {k: walk[k] for k in ("t", "x", "y", "heading")}
        path["z"] = np.full(len(walk["t"]), setup["height"])
        rates = bvc3d.replay_simulated(str(setup["floor"] / "hall-map.yaml"), path, setup["sensor"],
                                       model or rd.model_arg(name))["bvc_rates"]
        np.savez(cache, bvc=rates.astype(np.float32), x=walk["x"], y=walk["y"])
        log(f"{name}: BVC rates along the {WALK_HOURS:g} h walk (seed {seed}) in {time.time() - start:.0f} s")
    return np.load(cache)


def hall_setup(rec, work):
    if not (work / "grid.csv").exists() or not (work / "hall-map.ply").exists():
        rd.hall_map(rec, work)
    return rd.floor_setup(rec, work)


def write_hall_table(rows, name, group):
    """Each row's median over the BVC decoding's of its `group` (the row whose network is "bvc"), then the rows to
    HERE/name, floats to 4 significant digits."""
    for row in rows:
        row["median_over_bvc"] = row["median_m"] / next(r["median_m"] for r in rows
                                                        if r[group] == row[group] and r["network"] == "bvc")
    with open(HERE / name, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        for row in rows:
            w.writerow({k: f"{v:.4g}" if isinstance(v, float) else v for k, v in row.items()})
    log("wrote", HERE / name)


def prepare(rec, work):
    setup = hall_setup(rec, work)
    for name in MODELS:
        rd.template_query_rates(setup, name)
        walk_and_rates(setup, name)
    return setup


# The networks learned on the walk, beside the BVC decoding: (label, how to make it). GrowingPlaceCells' defaults are
# bvc3d's (docs/model-reference.md#growing-place-cells); "paper" is the paper's 250 cells on the same walk.
# Two variants show how the results move with the recruitment's parameters.
NETWORKS = [
    ("paper", lambda n_bvc: bvc3d_module().PlaceCellNetwork(n_bvc, seed=0)),
    ("growing", lambda n_bvc: bvc3d_module().GrowingPlaceCells(n_bvc, seed=0)),
    ("growing threshold=0.8", lambda n_bvc: bvc3d_module().GrowingPlaceCells(n_bvc, seed=0, threshold=0.8)),
    ("growing threshold=0.9 sample_every=1",
     lambda n_bvc: bvc3d_module().GrowingPlaceCells(n_bvc, seed=0, threshold=0.9, sample_every=1)),
]


def bvc3d_module():
    import bvc3d
    return bvc3d


def learn_on_walk(net, walk_bvc):
    """The online protocol of docs/real-data.md: learning on at every step of the walk, then frozen."""
    for b in walk_bvc:
        net.step(b.astype(np.float64), True)
    return net.weights


def decode(templates, grid, queries, qxyz):
    import bvc3d
    r = bvc3d.localize(templates, grid, queries, qxyz)
    s = r["decoded_summary"]
    return {"median_m": s["median_m"], "mean_m": s["mean_m"], "within_1m": s["within_1m"],
            "within_2m": s["within_2m"], "silent_queries": float(np.mean(queries.max(axis=1) == 0)),
            "silent_templates": float(np.mean(templates.max(axis=1) == 0))}


def growing(rec, work):
    setup = prepare(rec, work)
    grid, qxyz = setup["grid"], setup["qxyz"]
    rows = []
    for name in MODELS:
        bvc = rd.template_query_rates(setup, name)
        walk = walk_and_rates(setup, name)
        base = decode(bvc["templates"], grid, bvc["queries"], qxyz)
        rows.append({"model": name, "network": "bvc", "cells": bvc["templates"].shape[1], "steps": 0,
                     "learn_s": 0.0, **base})
        for label, make in NETWORKS:
            start = time.time()
            net = make(walk["bvc"].shape[1])
            W = learn_on_walk(net, walk["bvc"])
            learned = time.time() - start
            result = decode(rd.settled_place_rates(bvc["templates"], W), grid,
                            rd.settled_place_rates(bvc["queries"], W), qxyz)
            rows.append({"model": name, "network": label, "cells": W.shape[0], "steps": len(walk["bvc"]),
                         "learn_s": learned, **result})
            log(f"{name} {label}: {W.shape[0]} cells, median {result['median_m']:.2f} m "
                f"(BVC {base['median_m']:.2f} m), {100 * result['silent_queries']:.0f} % silent queries")
    write_hall_table(rows, "hall.csv", "model")



# The authors' multiscale model on the hall, its place cells reading the BVCs alone (ms-2d-bvc.yaml: g = 0; a real scan
# brings no grid-cell input, so the grid cells cannot take part in its read-out). Each scale is stepped by hand as
# NETWORKS are: its BVC layer (ms-2d's, docs/model-reference.md#multiscale-models) a 2-D model of its own, its place
# cells a PlaceCellNetwork with the scale's size and inhibition, all learned on the same walk. Decoded per scale and
# fused as the trials fuse them (each scale's rate vector scaled to unit length, side by side).
MS_SCALES = [  # (scale, the BVC layer's keys beyond 8 directions to 25 m, the place cells' keys)
    ("s", "n_per_axis: 100, sigma_r: 0.5, sigma_theta: 0.017453292519943295",
     dict(n_place=2000, gamma_pp=1.0, gamma_pb=0.35)),
    ("m", "n_per_axis: 50, sigma_r: 1, sigma_theta: 0.05235987755982988",
     dict(n_place=1000, gamma_pp=0.7, gamma_pb=0.35)),
    ("l", "n_per_axis: 75, sigma_r: 1.5, sigma_theta: 0.08726646259971647",
     dict(n_place=500, gamma_pp=0.7, gamma_pb=0.25)),
]
MS_WALK_SEEDS = [0, 1, 2]  # the learning walks (seed 0: the growing step's)


def scale_rates(setup, label, model):
    """BVC rates of the templates and the real queries for a model YAML, cached in floor/LABEL-bvc.npz."""
    import bvc3d
    cache = setup["floor"] / f"{label}-bvc.npz"
    if not cache.exists():
        np.savez(cache, templates=bvc3d.replay_simulated(str(setup["floor"] / "hall-map.yaml"), setup["grid_path"],
                                                         setup["sensor"], model, step_per_row=True)["bvc_rates"],
                 queries=setup["queries"].replay(model)["bvc_rates"])
    return np.load(cache)


def settled(bvc, weights, params):
    """rd.settled_place_rates for a network with other parameters than the paper's."""
    import bvc3d
    net = bvc3d.PlaceCellNetwork(bvc.shape[1], **params)
    net.weights = weights
    out = np.empty((len(bvc), weights.shape[0]), np.float32)
    for i, v in enumerate(np.asarray(bvc, np.float64)):
        net.reset()
        steps = [net.step(v, False) for _ in range(rd.SETTLE)]
        out[i] = np.mean(steps[rd.SETTLE - rd.SETTLE // 2:], axis=0)
    return out


def unit_rows(parts):
    """The scales side by side, each row of each scaled to unit length (a silent row stays 0)."""
    out = []
    for part in parts:
        norm = np.linalg.norm(part, axis=1, keepdims=True)
        out.append(np.divide(part, norm, out=np.zeros_like(part, dtype=np.float64), where=norm > 0))
    return np.hstack(out)


def multiscale(rec, work):
    """Every scale learned on each walk of MS_WALK_SEEDS (the place cells' weights drawn with seed 3·walk + scale);
    the BVC decoding does not depend on the walk and is written once (walk_seed empty)."""
    import bvc3d
    setup = hall_setup(rec, work)
    grid, qxyz = setup["grid"], setup["qxyz"]
    rows, bvc_parts = [], ([], [])
    models = []
    for scale, keys, params in MS_SCALES:
        label = f"ms-2d-{scale}"
        model = setup["floor"] / f"{label}.yaml"
        model.write_text(f"name: {label}\nbase: 2d\nbvc: {{n_dir: 8, max_dist: 25, {keys}}}\n")
        bvc = scale_rates(setup, label, str(model))
        models.append((scale, label, model, params, bvc))
        bvc_parts[0].append(bvc["templates"])
        bvc_parts[1].append(bvc["queries"])
        rows.append({"model": "ms-2d-bvc", "walk_seed": "", "scale": scale, "network": "bvc",
                     "cells": bvc["templates"].shape[1], "learn_s": 0.0,
                     **decode(bvc["templates"], grid, bvc["queries"], qxyz)})
    rows.append({"model": "ms-2d-bvc", "walk_seed": "", "scale": "fused", "network": "bvc",
                 "cells": sum(p.shape[1] for p in bvc_parts[0]), "learn_s": 0.0,
                 **decode(unit_rows(bvc_parts[0]), grid, unit_rows(bvc_parts[1]), qxyz)})
    for walk_seed in MS_WALK_SEEDS:
        place_parts = ([], [])
        for i, (scale, label, model, params, bvc) in enumerate(models):
            walk = walk_and_rates(setup, label, str(model), seed=walk_seed)
            start = time.time()
            W = learn_on_walk(bvc3d.PlaceCellNetwork(walk["bvc"].shape[1], seed=3 * walk_seed + i, **params),
                              walk["bvc"])
            learned = time.time() - start
            templates, queries = settled(bvc["templates"], W, params), settled(bvc["queries"], W, params)
            place_parts[0].append(templates)
            place_parts[1].append(queries)
            rows.append({"model": "ms-2d-bvc", "walk_seed": walk_seed, "scale": scale, "network": "place",
                         "cells": W.shape[0], "learn_s": learned, **decode(templates, grid, queries, qxyz)})
            log(f"ms-2d-bvc walk {walk_seed} {scale}: place median {rows[-1]['median_m']:.2f} m")
        rows.append({"model": "ms-2d-bvc", "walk_seed": walk_seed, "scale": "fused", "network": "place",
                     "cells": sum(p.shape[1] for p in place_parts[0]), "learn_s": 0.0,
                     **decode(unit_rows(place_parts[0]), grid, unit_rows(place_parts[1]), qxyz)})
        log(f"ms-2d-bvc walk {walk_seed} fused: place median {rows[-1]['median_m']:.2f} m")
    write_hall_table(rows, "hall-multiscale.csv", "scale")


# ---------------------------------------------------------------------------------------- a Gazebo building's floor

# The AWS RoboMaker small house (one furnished storey, 19 × 11.4 m), loaded as docs/buildings.md loads it: without the
# models Gazebo fetches from its online store. The models: the paper's single-scale presets, the authors' multiscale
# presets (and the same with their place cells reading BVCs alone, g = 0) and growing networks on 2-D and on 3-D BVCs
# (the model YAMLs next to this script). Each trial is the paper's protocol (explore with learning, then sample
# frozen) at FLOOR_HOURS per phase; the models of a seed ride one walk (`bvc3d sweep` shares it).
HOUSE_WORLD = "worlds/small_house.world"
# New models go at the end: a sweep numbers its conditions in this order, and the trials already run keep their names.
FLOOR_MODELS = ["2d", "3d-3l", "ms-2d", "ms-3d", "growing-2d.yaml", "growing-3d.yaml", "ms-2d-bvc.yaml",
                "ms-3d-bvc.yaml"]
FLOOR_ORDER = ["2d", "3d-3l", "ms-2d", "ms-2d-bvc", "ms-3d", "ms-3d-bvc", "growing-2d", "growing-3d"]  # tables, figure
FLOOR_SEEDS = 5
FLOOR_HOURS = 2  # h per phase: the 40 trials in about 45 min on the shared 2-core machine
FLOOR_JOBS = 2
# The modality index's DBSCAN counts rate-map bins (min_samples within eps = 1 m), and bins grow with the floor:
# gridsize 50 across the house's 18.1 × 10.6 m gives hexagons of 0.068 m², 2.1 times the paper's 9.5 m arena's
# (0.032 m²), so the paper's 20 bins of field are 9.4 of the house's. The trials analyse with FLOOR_MIN_SAMPLES; the
# modality is also recomputed from their rate maps (the library's own function) at each count of MODALITY_COUNTS.
FLOOR_MIN_SAMPLES = 6
MODALITY_COUNTS = [9, 20]  # the paper's field area in the house's bins; the paper's count as it stands
FLOOR_FIGURE_METRICS = [("decode_median_all_m", "median error (m),\nundecoded at chance", "log"),
                        ("frac_undecoded", "fraction of samples\nnot decoded", "linear"),
                        (f"mean_mi_active_ms{MODALITY_COUNTS[0]}", "mean MI of active\ncells", "linear"),
                        ("msai", "MSAI", "linear")]


def floor_sweep(house, work):
    """Writes the sweep, the world YAML and the model YAMLs into work/gazebo-floor and runs the sweep there; the
    engine skips every trial whose file is already complete. Returns the trials' folder."""
    world = house / HOUSE_WORLD
    if not world.is_file():
        sys.exit(f"--house {house}: no {HOUSE_WORLD} in it (give the small house's folder as AWS publishes it)")
    folder = work / "gazebo-floor"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "small-house.yaml").write_text(f"sdf: {world}\nmissing_models: skip\n")
    for model in FLOOR_MODELS:
        if model.endswith(".yaml"):
            shutil.copyfile(HERE / model, folder / model)
    (folder / "sweep.yaml").write_text(
        "name: floor\n"
        "base:\n"
        "  world: small-house.yaml\n"
        f"  protocol: {{explore_hours: {FLOOR_HOURS:g}, sample_hours: {FLOOR_HOURS:g}}}\n"
        f"  analysis: {{min_samples: {FLOOR_MIN_SAMPLES}}}\n"
        "grid:\n"
        f"  model: [{', '.join(FLOOR_MODELS)}]\n"
        f"seeds: {FLOOR_SEEDS}\n")
    trials = folder / "trials"
    cmd = [str(ROOT / "build" / "bvc3d"), "sweep", str(folder / "sweep.yaml"), "--out", str(trials),
           "--jobs", str(FLOOR_JOBS), "--no-report", "--verbose"]
    log(" ".join(cmd))
    start = time.time()
    subprocess.run(cmd, check=True)
    log(f"sweep in {time.time() - start:.0f} s")
    return trials


def population_rows(path, metric_names, modality_counts=MODALITY_COUNTS):
    """One row per analysed population of a trial file: the model's own place cells (`place`, the file's main
    metrics) and every /populations/NAME with metrics, with its number of cells (for `place-fused`, the sum of the
    place-cell scales it concatenates), for a growing network how many it recruited, and its modality recomputed
    from its rate maps at each count K of MODALITY_COUNTS (frac_active_msK, mean_mi_active_msK,
    frac_multimodal_msK)."""
    import h5py
    from bvc3d import analysis
    rows = []
    with h5py.File(path, "r") as f:
        model, seed = str(f.attrs["model"]), int(f.attrs["seed"])
        groups = {"place": (f["metrics"], f["samples/rates"].shape[1], None)}
        for name, group in f.get("populations", {}).items():
            if "metrics" not in group:
                continue
            cells = group["rates"].shape[1] if "rates" in group else None
            recruited = int(np.sum(group["recruited_at"][:] >= 0)) if "recruited_at" in group else None
            groups[name] = (group["metrics"], cells, recruited)
        for name, (metrics, cells, recruited) in groups.items():
            if cells is None:  # the fused decoding: the place-cell scales side by side
                cells = sum(c for n, (_, c, _) in groups.items() if c is not None and (n == "place" or
                                                                                     n.startswith("place-")))
            modality = metrics["modality"][:]
            area = metrics["field_area"][:][modality > 0]
            row = {"model": model, "seed": seed, "population": name, "cells": cells,
                   "recruited": "" if recruited is None else recruited,
                   "field_area_median_m2": float(np.median(area)) if len(area) else float("nan")}
            row.update({k: float(metrics.attrs[k]) for k in metric_names if k in metrics.attrs})
            centers, maps = metrics["bin_centers"][:], metrics["rate_maps"][:]
            for count in modality_counts:
                mi = analysis.modality(centers, maps, eps=float(metrics.attrs["eps"]), min_samples=count)
                row.update({f"{k}_ms{count}": float(v) for k, v in analysis.modality_summary(mi).items()})
            rows.append(row)
    return rows


def floor(house, work):
    import bvc3d
    trials = floor_sweep(house, work)
    names = [m["name"] for m in bvc3d.metric_table]
    rows = [row for path in sorted(trials.glob("*.h5")) for row in population_rows(path, names)]
    order = {m: i for i, m in enumerate(FLOOR_ORDER)}
    pops = {p: i for i, p in enumerate(FLOOR_FIGURE_POPULATIONS)}
    rows.sort(key=lambda r: (order.get(r["model"], len(order)), pops.get(r["population"], len(pops)), r["population"],
                             r["seed"]))
    fields = ["model", "seed", "population", "cells", "recruited", "field_area_median_m2"]
    fields += [k for k in names if any(k in r for r in rows)]
    fields += [k for k in rows[0] if k not in fields]
    with open(HERE / "floor.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for row in rows:
            w.writerow({k: f"{v:.6g}" if isinstance(v, float) else v for k, v in row.items()})
    log("wrote", HERE / "floor.csv", f"({len(rows)} rows)")
    print(floor_table(rows))
    floor_figure(rows)


def floor_table(rows):
    """docs/building-scale.md's table: per model and place-cell population, the median over seeds [smallest,
    largest]; the modality at the first of MODALITY_COUNTS. Counts of cells rather than fractions, and the
    multimodal share of the active cells, so that populations of 250 to 3 500 cells (and a growing network's budget
    of which it recruited a part) compare."""
    def spread(values, fmt):
        values = np.asarray(values, float)
        if np.all(np.isnan(values)):
            return "–"
        return f"{fmt.format(np.nanmedian(values))} [{fmt.format(np.nanmin(values))}, {fmt.format(np.nanmax(values))}]"

    # A growing model's own 250 place cells are its base preset's, on the same walk: the table shows them once.
    def same(a, b):
        return [{k: v for k, v in r.items() if k != "model"} for r in a] == \
            [{k: v for k, v in r.items() if k != "model"} for r in b]
    for model, base in (("growing-2d", "2d"), ("growing-3d", "3d-3l")):
        mine, theirs = ([r for r in rows if r["model"] == m and r["population"] == "place"] for m in (model, base))
        log(f"{model}'s place cells {'are' if same(mine, theirs) else 'are NOT'} {base}'s, metric for metric")
    lines = ["| model | population | cells | active cells (MI > 0) | field area | mean MI | multimodal of active | "
             "MSAI | decoding median | not decoded | median, undecoded at chance |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for model, pop, mine in shown_groups(rows):
        cells = spread([r["recruited"] for r in mine], "{:.0f}") if mine[0]["recruited"] != "" else mine[0]["cells"]
        k = f"_ms{MODALITY_COUNTS[0]}"
        active = [r["frac_active" + k] * r["cells"] for r in mine]
        multi = [r["frac_multimodal" + k] / r["frac_active" + k] if r["frac_active" + k] > 0 else np.nan for r in mine]
        lines.append(f"| {model} | {pop} | {cells} | {spread(active, '{:.0f}')} | "
                     f"{spread([r['field_area_median_m2'] for r in mine], '{:.2f}')} m² | "
                     f"{spread([r['mean_mi_active' + k] for r in mine], '{:.2f}')} | {spread(multi, '{:.2f}')} | "
                     f"{spread([r['msai'] for r in mine], '{:.4f}')} | "
                     f"{spread([r['decode_median_m'] for r in mine], '{:.2f}')} m | "
                     f"{spread([r['frac_undecoded'] for r in mine], '{:.3f}')} | "
                     f"{spread([r['decode_median_all_m'] for r in mine], '{:.2f}')} m |")
    return "\n".join(lines)


FLOOR_FIGURE_POPULATIONS = ["place", "place-m", "place-l", "place-fused", "growing"]


def shown_groups(rows):
    """(model, population, its rows) of the table and the figure: the place-cell populations, in order; a growing
    model's own 250 place cells are its base preset's on the same walk (floor_table checks it), shown once."""
    for model in dict.fromkeys(r["model"] for r in rows):
        for pop in FLOOR_FIGURE_POPULATIONS:
            mine = [r for r in rows if r["model"] == model and r["population"] == pop]
            if mine and not (model.startswith("growing") and pop == "place"):
                yield model, pop, mine


def floor_figure(rows):
    """Each place-cell population's metrics, a dot per seed and a bar at the median, one panel per metric."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from bvc3d import figures
    groups = [(f"{model} {pop}", mine) for model, pop, mine in shown_groups(rows)]
    fig, axes = plt.subplots(len(FLOOR_FIGURE_METRICS), 1, figsize=(9, 2.4 * len(FLOOR_FIGURE_METRICS)),
                             sharex=True, constrained_layout=True)
    for ax, (metric, label, scale) in zip(axes, FLOOR_FIGURE_METRICS):
        for i, (_, mine) in enumerate(groups):
            values = np.array([r[metric] for r in mine])
            ax.bar(i, np.nanmedian(values), color="0.8", width=0.7)
            ax.plot(np.full(len(values), i), values, "o", color="C0", ms=3)
        ax.set_ylabel(label)
        ax.set_yscale(scale)
        if scale == "log":
            ax.set_yticks([0.2, 0.5, 1, 2, 5], ["0.2", "0.5", "1", "2", "5"])
            ax.minorticks_off()
        ax.grid(axis="y", alpha=0.3)
    axes[-1].set_xticks(range(len(groups)), [g for g, _ in groups], rotation=60, ha="right", fontsize=8)
    axes[0].set_title(f"AWS small house: {FLOOR_SEEDS} seeds, {FLOOR_HOURS:g} h explore + {FLOOR_HOURS:g} h sample "
                      "(bar: median over seeds)", fontsize=9)
    figures.save(fig, HERE / "floor.png")
    log("wrote", HERE / "floor.png")


ARENA_MODELS = ["2d", "3d-3l", "ms-2d", "ms-3d"]
ARENA_TILTS = [0, 30, 45, 60]
ARENA_SEEDS = 1  # the paper's 4 h + 4 h: 16 trials in about 20 min on the shared 2-core machine
ARENA_SHOWN = [("2d", "place", "2d"), ("3d-3l", "place", "3d-3l"), ("ms-2d", "place-fused", "ms-2d, fused"),
               ("ms-2d", "place-l", "ms-2d, large scale"), ("ms-3d", "place-fused", "ms-3d, fused"),
               ("ms-3d", "place-l", "ms-3d, large scale")]  # the figure's lines
ARENA_TABLE_ROWS = [("2d", "place", "2d"), ("3d-3l", "place", "3d-3l")] + [
    (m, p, f"{m}, {label}") for m in ("ms-2d", "ms-3d") for p, label in
    (("place-fused", "fused"), ("place", "small scale"), ("place-m", "medium scale"), ("place-l", "large scale"))]
ARENA_COLORS = {"2d": "C0", "3d-3l": "C1", "ms-2d": "C2", "ms-3d": "C3"}
ARENA_METRICS = [("decode_median_all_m", "median decoding error (m),\nundecoded at chance"),
                 ("frac_undecoded", "samples undecoded"), ("msai", "MSAI"), ("frac_multimodal", "multimodal fields")]


def arena_table(rows):
    """docs/building-scale.md's table: per model and population, each metric at 0° / 30° / 45° / 60° (seed means)."""
    def at(mine, metric, fmt):
        return " / ".join(fmt.format(np.mean([r[metric] for r in mine if r["tilt_deg"] == t])) for t in ARENA_TILTS)
    lines = []
    for model, population, label in ARENA_TABLE_ROWS:
        mine = [r for r in rows if r["model"] == model and r["population"] == population]
        if mine:
            lines.append(f"| {label} | {mine[0]['cells']} | {at(mine, 'decode_median_all_m', '{:.2f}')} | "
                         f"{at(mine, 'frac_undecoded', '{:.1%}')} | {at(mine, 'msai', '{:.4f}')} | "
                         f"{at(mine, 'frac_multimodal', '{:.2f}')} |")
    return "\n".join(lines)


def arenas(_, work):
    """The paper's experiment (`bvc3d paper`: the tilted cross arenas, 4 h + 4 h) with the multiscale models beside
    the paper's 2d and 3d-3l; every analysed population of every trial into arenas.csv, and arenas.png."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import bvc3d
    out = work / "arenas"
    cmd = [str(ROOT / "build" / "bvc3d"), "paper", "--models", ",".join(ARENA_MODELS), "--tilts",
           ",".join(map(str, ARENA_TILTS)), "--seeds", str(ARENA_SEEDS), "--out", str(out), "--jobs", "1",
           "--no-report"]
    log(" ".join(cmd))
    subprocess.run(cmd, check=True)
    names = [m["name"] for m in bvc3d.metric_table]
    import h5py
    rows = []
    for path in sorted(out.glob("*.h5")):
        with h5py.File(path, "r") as f:
            tilt = float(f.attrs["tilt_deg"])
        rows += [dict(r, tilt_deg=tilt) for r in population_rows(path, names, modality_counts=())
                 if r["population"].startswith("place") and r["seed"] < ARENA_SEEDS]  # a folder may hold more seeds
    rows.sort(key=lambda r: (ARENA_MODELS.index(r["model"]), r["population"], r["tilt_deg"], r["seed"]))
    fields = ["model", "tilt_deg", "seed", "population", "cells", "field_area_median_m2"] + [
        k for k in names if any(k in r for r in rows)]
    with open(HERE / "arenas.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for row in rows:
            w.writerow({k: f"{v:.6g}" if isinstance(v, float) else v for k, v in row.items()})
    log("wrote", HERE / "arenas.csv", f"({len(rows)} rows)")
    print(arena_table(rows))
    fig, axes = plt.subplots(1, len(ARENA_METRICS), figsize=(4.2 * len(ARENA_METRICS), 3.8))
    for model, population, label in ARENA_SHOWN:
        mine = [r for r in rows if r["model"] == model and r["population"] == population]
        for ax, (metric, title) in zip(axes, ARENA_METRICS):
            means = [np.mean([r[metric] for r in mine if r["tilt_deg"] == t]) for t in ARENA_TILTS]
            style = {"place-fused": "-o", "place-l": ":^"}.get(population, "--s")
            ax.plot(ARENA_TILTS, means, style, color=ARENA_COLORS[model], label=label)
            ax.set_title(title, fontsize=10)
            ax.set_xlabel("wall tilt (°)")
            ax.set_xticks(ARENA_TILTS)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"The paper's arenas, 4 h + 4 h, mean of {ARENA_SEEDS} seed(s)")
    fig.tight_layout()
    fig.savefig(HERE / "arenas.png", dpi=90)
    log("wrote", HERE / "arenas.png")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--recording", type=pathlib.Path, help="the hall-lidar folder (steps rates, growing)")
    parser.add_argument("--house", type=pathlib.Path,
                        help="the AWS RoboMaker small house's folder, holding worlds/ and models/ (step floor)")
    parser.add_argument("--work", type=pathlib.Path, default=pathlib.Path("/tmp/bvc3d-real-data"))
    parser.add_argument("--steps", nargs="*", default=["rates", "growing"])
    args = parser.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    sys.path.insert(0, str(ROOT / "build" / "python"))
    steps = {"rates": (prepare, "recording"), "growing": (growing, "recording"),
             "multiscale": (multiscale, "recording"), "floor": (floor, "house"), "arenas": (arenas, None)}
    for step in args.steps:
        if step not in steps:
            sys.exit(f"unknown step '{step}' (known: {', '.join(steps)})")
        run, data = steps[step]
        if data and getattr(args, data) is None:
            sys.exit(f"step {step} needs --{data}")
    for step in args.steps:
        run, data = steps[step]
        log("step", step)
        run(getattr(args, data).resolve() if data else None, args.work.resolve())


if __name__ == "__main__":
    main()
