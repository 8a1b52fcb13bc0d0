"""Worlds built in Python (docs/worlds.md#python): from a dict with the keys of a world YAML, or from
triangles. Both go through the world YAML's reader, so the checks and messages are the files' own."""
import json

import numpy as np

from ._core import World


def _plain(value):
    if hasattr(value, "tolist"):
        return value.tolist()
    raise ValueError(f"a world description holds numbers, lists and dicts, not {type(value).__name__}")


def world_from_dict(description, name="<python>"):
    """A world from a dict with the keys of a world YAML: objects (box, quad, triangle, tilted_wall, mesh,
    point_cloud, cross_arena), walkable, start, flight_volume, name. Errors name the key, e.g.
    "<python>: key 'objects[0].box.size': all three sizes must be > 0"."""
    if not isinstance(description, dict):
        raise ValueError("a world description is a dict with the keys of a world YAML (objects, walkable, ...)")
    try:
        text = json.dumps(description, default=_plain, allow_nan=False)  # JSON is YAML
    except ValueError as e:
        raise ValueError(f"{name}: {e} (a NaN or infinite number?)") from None
    return World.from_yaml_text(text, name)


def _region(region, key):
    r = np.asarray(region, dtype=float)
    if r.shape == (4,):
        return {"rect": r.tolist()}
    if r.ndim == 2 and r.shape[1] == 2:
        return {"polygon": r.tolist()}
    raise ValueError(f"{key} is (xmin, ymin, xmax, ymax) or a (K, 2) polygon, got shape {r.shape}")


def world_from_triangles(triangles, walkable, start=None, name="triangles"):
    """A world from a (T, 3, 3) array of triangle corners (metres) and the floor region the robot's body
    stays inside (walkable: (xmin, ymin, xmax, ymax) or a (K, 2) polygon); start: where trials start (default:
    the walkable region). Degenerate triangles and corners beyond ±1e6 m are refused, naming the triangle."""
    t = np.asarray(triangles, dtype=float)
    if t.ndim != 3 or t.shape[1:] != (3, 3) or len(t) == 0:
        raise ValueError(f"triangles must be a (T, 3, 3) array of corners with T >= 1, got shape {t.shape}")
    bad = np.flatnonzero(~np.isfinite(t).all(axis=(1, 2)))
    if bad.size:
        raise ValueError(f"triangles[{bad[0]}] has a NaN or infinite corner")
    d = {"name": name, "objects": [{"triangle": tri} for tri in t.tolist()], "walkable": _region(walkable, "walkable")}
    if start is not None:
        d["start"] = _region(start, "start")
    return world_from_dict(d, name)


World.from_dict = staticmethod(world_from_dict)
World.from_triangles = staticmethod(world_from_triangles)
