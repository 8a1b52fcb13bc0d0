"""Regenerates the results of docs/building-scale.md: place cells that cover a building, on the hall-lidar recording.

    /usr/bin/python3 docs/building-scale/make.py --recording PATH/hall-lidar [--work DIR] [--steps ...]

Reuses the setup of docs/real-data.md's place-cell step (docs/real-data/make.py: the hall's map in the floor's
frame, the 0.5 m template grid, the real scans as queries, the paper's random walk of a person-sized body) and its
read-out (each scan's settled place-cell response, decoded to the most cosine-similar template). Run from the
repository's root after building (build/bvc3d and build/python). Writes the tables (CSV) next to this script; the
large intermediate files (the map, BVC rates along the walk) go to --work (the same default as docs/real-data's, so
the two scripts share them). Steps (default: all, in this order):

  rates    the hall's map and templates (if not there yet), and each model's BVC rates of the templates, the real
           scans and the learning walk (cached in --work)
  growing  a growing place-cell network (bvc3d.GrowingPlaceCells) learned on the walk, every real scan localized
           with it, beside the BVC decoding of the same model and the paper's 250 cells

A model is one line of MODELS. Sized for a shared 2-core machine: see docs/building-scale.md for what was run.
"""
import argparse
import csv
import importlib.util
import pathlib
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


def walk_and_rates(setup, name):
    """The learning walk (docs/real-data.md's) and model `name`'s BVC rates along it, float32 (the place cells take
    their inputs as float32, so nothing is lost), cached in floor/NAME-walk-Hh.npz."""
    import bvc3d
    cache = setup["floor"] / f"{name}-walk-{WALK_HOURS:g}h.npz"
    if not cache.exists():
        start = time.time()
        walk = bvc3d.random_walk(setup["world"], WALK_HOURS, WALK_SEED, height=rd.BODY_HEIGHT)
        path = {k: walk[k] for k in ("t", "x", "y", "heading")}
        path["z"] = np.full(len(walk["t"]), setup["height"])
        rates = bvc3d.replay_simulated(str(setup["floor"] / "hall-map.yaml"), path, setup["sensor"],
                                       rd.model_arg(name))["bvc_rates"]
        np.savez(cache, bvc=rates.astype(np.float32), x=walk["x"], y=walk["y"])
        log(f"{name}: BVC rates along the {WALK_HOURS:g} h walk in {time.time() - start:.0f} s")
    return np.load(cache)


def prepare(rec, work):
    if not (work / "grid.csv").exists() or not (work / "hall-map.ply").exists():
        rd.hall_map(rec, work)
    setup = rd.floor_setup(rec, work)
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
    for row in rows:
        row["median_over_bvc"] = row["median_m"] / next(r["median_m"] for r in rows
                                                        if r["model"] == row["model"] and r["network"] == "bvc")
    with open(HERE / "hall.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        for row in rows:
            w.writerow({k: f"{v:.4g}" if isinstance(v, float) else v for k, v in row.items()})
    log("wrote", HERE / "hall.csv")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--recording", required=True, type=pathlib.Path, help="the hall-lidar folder")
    parser.add_argument("--work", type=pathlib.Path, default=pathlib.Path("/tmp/bvc3d-real-data"))
    parser.add_argument("--steps", nargs="*", default=["rates", "growing"])
    args = parser.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    sys.path.insert(0, str(ROOT / "build" / "python"))
    steps = {"rates": prepare, "growing": growing}
    for step in args.steps:
        if step not in steps:
            sys.exit(f"unknown step '{step}' (known: {', '.join(steps)})")
        log("step", step)
        steps[step](args.recording.resolve(), args.work.resolve())


if __name__ == "__main__":
    main()
