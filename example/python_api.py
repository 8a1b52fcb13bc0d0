#!/usr/bin/python3
"""The whole pipeline from Python, stage by stage: world -> scan -> BVCs -> place cells -> analysis.

    PYTHONPATH=build/python /usr/bin/python3 example/python_api.py [HOURS]
"""
import sys

import numpy as np

import bvc3d
import bvc3d.analysis

hours = float(sys.argv[1]) if len(sys.argv) > 1 else 0.5
world = bvc3d.World.cross(tilt_deg=45)               # or bvc3d.World.from_yaml("configs/worlds/two-rooms.yaml")
walk = bvc3d.random_walk(world, hours=hours, seed=0)   # dict of arrays: t, x, y, heading, bumped
layer = bvc3d.BoundaryVectorLayer.preset("3d-0.2")     # or BoundaryVectorLayer(elevations=[0.0, 0.2], ...)
sensor = bvc3d.model_sensor("3d-0.2")                  # the spherical scanner
net = bvc3d.PlaceCellNetwork(layer.n_cells, n_place=250, seed=0)

# Learn along the first half of the walk, then record with learning frozen (the paper's protocol).
half = len(walk["x"]) // 2
rates = []
for i, (x, y, h) in enumerate(zip(walk["x"], walk["y"], walk["heading"])):
    returns = world.scan(sensor, x, y, h)              # (N, 3): range, allocentric azimuth, elevation
    v = net.step(layer.rates(returns), learn=i < half)
    if i >= half:
        rates.append(v)
rates = np.array(rates)
x, y = walk["x"][half:], walk["y"][half:]

centers, maps = bvc3d.analysis.rate_maps(x, y, rates)
mi = bvc3d.analysis.modality(centers, maps)
sai, msai = bvc3d.analysis.aliasing(centers, maps)
print(f"{len(x)} samples, {len(centers)} bins")
print("modality:", bvc3d.analysis.modality_summary(mi))
print(f"MSAI: {msai:.4f}")
print("decoding:", bvc3d.analysis.decoding_error(x, y, rates))
