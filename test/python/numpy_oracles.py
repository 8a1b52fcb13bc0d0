"""Oracles written out in numpy, shared by the tests (they share no code with bvc3d)."""
import numpy as np


def numpy_rate_maps(means, quantile):
    """docs/model-reference.md#analysis maps from per-bin means, written out in numpy: per cell, values below
    numpy.percentile(cell, 100 q) set to 0, then divided by the cell's maximum (silent: zeros)."""
    maps = means.copy()
    for k in range(maps.shape[1]):
        col = maps[:, k]
        col[col < np.percentile(col, 100 * quantile)] = 0
        top = col.max()
        maps[:, k] = col / top if top > 0 else 0.0
    return maps
