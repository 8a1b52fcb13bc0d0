"""Analysis of recorded samples (docs/analysis.md): rate maps, modality index, spatial aliasing,
localization error and per-cell statistics. numpy in, numpy out; the work is done in C++.
3-D positions (flying agents, docs/flying.md#analysis): ``voxel_rate_maps``, ``dbscan_labels``,
``isotropy`` and ``analyze3d``, on the same code paths.

Conventions (docs/analysis.md has the details):

* Bins are exactly matplotlib 3.6.3's ``Axes.hexbin(x, y, C, gridsize, extent,
  reduce_C_function=numpy.mean)`` bins: same extent rule (data min/max made nonsingular, x padded
  by 1e-9 of its range), same two lattices and tie-breaking, same bin order, only visited bins.
* Values may be float32 (read as is) or float64 (anything else is converted); means are summed in
  float64 either way.
* The modality index is scikit-learn 1.2.1's ``DBSCAN(eps, min_samples).fit(points)`` cluster
  count, reproduced down to points at exactly ``eps``.
* Every function raises ValueError on bad input (mismatched lengths, non-finite coordinates or
  values, gridsize < 2, quantile outside [0, 1], eps <= 0, complex, boolean or object arrays, ...).
* Ctrl-C interrupts a long call within a fraction of a second (KeyboardInterrupt).
"""
import numbers

import numpy as np

from ._core import analysis as _an

# The defaults are the C++ analysis parameters' (AnalysisParams::table(), the ones trial files record
# and `bvc3d config` prints): for 2-D positions, and for 3-D ones (DBSCAN's min_samples 10).
_D2 = _an.defaults(2)
_D3 = _an.defaults(3)

__all__ = [
    "hexbin",
    "rate_maps",
    "modality",
    "modality_summary",
    "dbscan_cluster_count",
    "aliasing",
    "decoding_error",
    "cell_stats",
    "analyze",
    "voxel_rate_maps",
    "dbscan_labels",
    "isotropy",
    "analyze3d",
]


def _real(values, name):
    """values as a numpy array of real numbers: integer or floating dtypes only. Complex, boolean,
    object and text arrays are refused, not cast (a cast would drop imaginary parts or invent
    numbers)."""
    a = np.asarray(values)
    if a.dtype.kind not in "iuf":
        raise ValueError(f"{name} must hold real numbers (integer or floating point), got dtype {a.dtype}")
    return a


def _positions(x, y):
    x = np.ascontiguousarray(_real(x, "x"), dtype=np.float64)
    y = np.ascontiguousarray(_real(y, "y"), dtype=np.float64)
    if x.ndim != 1 or y.ndim != 1:
        raise ValueError(f"x and y must be 1-D arrays, got shapes {x.shape} and {y.shape}")
    if x.shape != y.shape:
        raise ValueError(f"x and y must have the same length, got {len(x)} and {len(y)}")
    return x, y


def _samples(values, n, name):
    """(n,) or (n, C) float32/float64 C-contiguous; returns (array 2-D, was_1d)."""
    v = _real(values, name)
    v = np.ascontiguousarray(v, dtype=np.float32 if v.dtype == np.float32 else np.float64)
    if v.ndim not in (1, 2):
        raise ValueError(f"{name} must be (n,) or (n, n_cells), got shape {v.shape}")
    if v.shape[0] != n:
        raise ValueError(f"{name} must have one row per sample: {v.shape[0]} rows for {n} samples")
    return (v.reshape(n, 1), True) if v.ndim == 1 else (v, False)


def _gridsize(gridsize):
    if isinstance(gridsize, bool) or not isinstance(gridsize, numbers.Integral):
        raise ValueError(f"gridsize must be an integer, got {gridsize!r}")
    if gridsize < 2:
        raise ValueError(f"gridsize must be >= 2 (matplotlib's grid has int(gridsize / sqrt(3)) rows), got {gridsize}")
    return int(gridsize)


def _extent(extent):
    if extent is None:
        return None
    e = np.asarray(_real(extent, "extent"), dtype=np.float64).ravel()
    if e.shape != (4,):
        raise ValueError(f"extent must be (xmin, xmax, ymin, ymax), got {extent!r}")
    return tuple(float(v) for v in e)


def _number(v, name):
    """A real scalar (int or float, numpy's too); complex, bool and text are refused."""
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (numbers.Real, np.integer, np.floating)):
        raise ValueError(f"{name} must be a real number, got {v!r}")
    return float(v)


def _quantile(q):
    q = _number(q, "quantile")
    if not 0.0 <= q <= 1.0:
        raise ValueError(f"quantile must lie in [0, 1], got {q}")
    return q


def _dbscan_params(eps, min_samples):
    eps = _number(eps, "eps")
    if not eps > 0 or not np.isfinite(eps):
        raise ValueError(f"eps must be a positive number, got {eps}")
    if isinstance(min_samples, bool) or not isinstance(min_samples, numbers.Integral) or min_samples < 1:
        raise ValueError(f"min_samples must be an integer >= 1, got {min_samples!r}")
    return eps, int(min_samples)


def _d_th(d_th):
    d_th = _number(d_th, "d_th")
    if not d_th >= 0 or not np.isfinite(d_th):
        raise ValueError(f"d_th must be a finite distance >= 0, got {d_th}")
    return d_th


_TEMPLATES = tuple(_an.decoding_templates)


def _count(n, name):
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
        raise ValueError(f"{name} must be an integer >= 0, got {n!r}")
    return int(n)


def _templates(templates, name="templates"):
    if templates not in _TEMPLATES:
        raise ValueError(f"{name} must be {' or '.join(map(repr, _TEMPLATES))}, got {templates!r}")
    return templates


def _centers_maps(centers, maps):
    c = np.ascontiguousarray(_real(centers, "centers"), dtype=np.float64)
    if c.ndim != 2 or c.shape[1] not in (2, 3):
        raise ValueError(f"centers must be an (N, 2) or (N, 3) array, got shape {c.shape}")
    m = np.ascontiguousarray(_real(maps, "maps"), dtype=np.float64)
    was_1d = m.ndim == 1
    if was_1d:
        m = m.reshape(-1, 1)
    if m.ndim != 2 or m.shape[0] != c.shape[0]:
        raise ValueError(f"maps must be (N,) or (N, n_cells) with N = {c.shape[0]} bins, got shape {np.shape(maps)}")
    if m.shape[1] == 0:
        raise ValueError(f"maps have no cells (shape {np.shape(maps)}): give (N,) or (N, n_cells) with n_cells >= 1")
    return c, m, was_1d


def hexbin(x, y, values, gridsize=_D2["gridsize"], extent=None):
    """Mean of ``values`` per hexagonal bin, exactly as matplotlib's hexbin computes it.

    Parameters: x, y (n,) positions; values (n,) or (n, C) (float32 or float64), all columns
    binned in one pass; gridsize hexagons across x; extent (xmin, xmax, ymin, ymax) or None for the
    data's own min/max.

    Returns ``(centers (B, 2), means (B,) or (B, C), counts (B,))`` over the B visited bins in
    matplotlib's order: ``centers`` equals ``PolyCollection.get_offsets()`` and each column of
    ``means`` equals ``get_array()`` of ``ax.hexbin(x, y, C=column, gridsize=gridsize,
    extent=extent, reduce_C_function=numpy.mean)``. Points whose bin falls outside an explicit
    extent are dropped, as matplotlib drops them.
    """
    x, y = _positions(x, y)
    v, was_1d = _samples(values, len(x), "values")
    centers, means, counts = _an.hexbin(x, y, v, _gridsize(gridsize), _extent(extent))
    return centers, (means[:, 0] if was_1d else means), counts


def rate_maps(x, y, rates, gridsize=_D2["gridsize"], quantile=_D2["quantile"], extent=None):
    """Thresholded, normalized rate maps (docs/analysis.md).

    Per cell (column of ``rates``): the mean rate per visited bin (``hexbin``), then values below
    ``numpy.percentile(cell_map, 100 * quantile)`` (linear) set to 0, then the map divided by its
    maximum. A cell whose maximum is <= 0 (silent) gets an all-zero map (never NaN).

    Returns ``(centers (B, 2), maps (B, n_cells))`` (``maps`` is (B,) for 1-D ``rates``).
    """
    x, y = _positions(x, y)
    r, was_1d = _samples(rates, len(x), "rates")
    centers, maps, _, _ = _an.rate_maps(x, y, r, _gridsize(gridsize), _quantile(quantile), _extent(extent))
    return centers, (maps[:, 0] if was_1d else maps)


def dbscan_cluster_count(points, eps=_D2["eps"], min_samples=_D2["min_samples"]):
    """Number of clusters ``sklearn.cluster.DBSCAN(eps, min_samples).fit(points)`` finds
    (labels >= 0), for (N, 2) or (N, 3) points; identical to scikit-learn 1.2.1 for any input,
    including points at exactly ``eps`` from each other. 0 for no points."""
    p = np.ascontiguousarray(_real(points, "points"), dtype=np.float64)
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise ValueError(f"points must be an (N, 2) or (N, 3) array, got shape {p.shape}")
    eps, min_samples = _dbscan_params(eps, min_samples)
    return int(_an.dbscan_cluster_count(p, eps, min_samples))


def modality(centers, maps, eps=_D2["eps"], min_samples=_D2["min_samples"]):
    """Modality index per cell: the DBSCAN cluster count (``dbscan_cluster_count``) over the
    centers of the bins where the cell's map is > 0, in bin order.

    Returns an int array (n_cells,) (an int for 1-D ``maps``).
    """
    c, m, was_1d = _centers_maps(centers, maps)
    eps, min_samples = _dbscan_params(eps, min_samples)
    mi = np.asarray(_an.modality(c, m, eps, min_samples), dtype=np.int64)
    return int(mi[0]) if was_1d else mi


def modality_summary(counts):
    """The paper's three figures from per-cell modality indices: ``frac_active`` (fraction of all
    cells with MI > 0), ``mean_mi_active`` (mean MI over cells with MI > 0, NaN if none),
    ``frac_multimodal`` (fraction of all cells with MI > 1). NaN everywhere for no cells."""
    counts = np.asarray(counts)
    if counts.ndim != 1:
        raise ValueError(f"counts must be 1-D, got shape {counts.shape}")
    if counts.size and not np.issubdtype(counts.dtype, np.integer):
        raise ValueError(f"counts must be integers, got dtype {counts.dtype}")
    return dict(_an.modality_summary(counts.astype(np.int64, copy=False)))


def aliasing(centers, maps, d_th=_D2["d_th"]):
    """Spatial aliasing (docs/analysis.md).

    ``SAI_i = (1/N) * sum over j != i with |c_i - c_j| > d_th of cos(a_i, a_j)`` where a_i is row i
    of ``maps`` (the population vector of bin i), cos = 0 when either vector is zero and N is the
    number of bins; distances are Euclidean over the centers' 2 or 3 coordinates. Returns ``(sai (B,), msai)``,
    msai = mean SAI (NaN for no bins).
    """
    c, m, _ = _centers_maps(centers, maps)
    sai, msai = _an.aliasing(c, m, _d_th(d_th))
    return sai, float(msai)


def decoding_error(x, y, rates, gridsize=_D2["gridsize"], extent=None, quantile=_D2["quantile"],
                   templates=_D2["decoding_templates"]):
    """Localization error of a population-vector decoder (docs/analysis.md).

    Templates (``templates="rate_maps"``, the reference decoder): the rate maps of the first ``n // 2``
    samples, i.e. the mean rate of every cell in every bin they visit, thresholded at the cell's
    ``quantile`` and divided by the cell's maximum, exactly as ``rate_maps`` does it, but on the
    trial's grid (extent from all samples unless given). ``templates="means"`` uses the raw mean
    rates per bin instead (no threshold, no per-cell scaling; ``quantile`` is then unused).
    Each sample of the second half is decoded to the bin whose template is most cosine-similar to
    the sample's rates (ties: first bin in matplotlib's order); its error is the distance from its
    true position to that bin's center. Samples with no positive similarity to any template (e.g.
    all cells silent) are not decoded: they are counted in ``n_undecoded`` and left out of
    ``median_m`` and ``mean_m``. ``median_all_m`` and ``mean_all_m`` count them at chance: the mean
    distance from the sample's true position to the first half's template bins, each weighted by the
    number of first-half samples in it. Needs at least 2 samples (ValueError otherwise; ``analyze``
    copes with fewer).

    Returns a dict: ``median_m``, ``mean_m`` (NaN if nothing was decoded), ``n_decoded``,
    ``n_undecoded``, ``frac_undecoded``, ``median_all_m``, ``mean_all_m``.
    """
    x, y = _positions(x, y)
    r, _ = _samples(rates, len(x), "rates")
    return dict(_an.decoding_error(x, y, r, _gridsize(gridsize), _extent(extent), _quantile(quantile),
                                   _templates(templates)))


def cell_stats(x, y, rates, gridsize=_D2["gridsize"], quantile=_D2["quantile"], extent=None):
    """Per-cell statistics from the rate maps, as a dict of (n_cells,) arrays:

    * ``peak_rate``: maximum of the cell's mean-rate map;
    * ``mean_rate``: occupancy-weighted mean rate, sum_b p_b * rate_b with p_b = count_b / n;
    * ``field_area_m2``: number of bins whose normalized map (``rate_maps``) is > 0.5 times the
      area of one hexagon (sx * sy / 2);
    * ``spatial_info``: Skaggs information sum_b p_b rate_b log2(rate_b / mean_rate) in bits per
      sample (bins with rate <= 0 add nothing; 0 for a silent cell);
    * ``spatial_info_per_rate``: the same divided by mean_rate (Skaggs' bits per spike; NaN for a
      silent cell).
    """
    x, y = _positions(x, y)
    r, _ = _samples(rates, len(x), "rates")
    return {k: np.asarray(v) for k, v in
            _an.cell_stats(x, y, r, _gridsize(gridsize), _quantile(quantile), _extent(extent)).items()}


def analyze(x, y, rates, gridsize=_D2["gridsize"], quantile=_D2["quantile"], eps=_D2["eps"],
            min_samples=_D2["min_samples"], d_th=_D2["d_th"], extent=None, decoding_templates=_D2["decoding_templates"],
            mi_quantile=None, skip_samples=_D2["skip_samples"], msai_bins=_D2["msai_bins"]):
    """Every metric of one trial in one call (the C++ entry point the experiment uses).

    Returns a dict: ``centers``, ``counts``, ``mean_maps``, ``maps``, ``bin_area_m2``,
    ``modality``, ``modality_summary`` (dict), ``sai``, ``msai``, ``decoding`` (dict as
    ``decoding_error(..., quantile=quantile, templates=decoding_templates)``; same grid as the
    maps), ``cells`` (dict as ``cell_stats``).

    The authors' conventions (docs/reproduction.md), off by default: ``mi_quantile`` thresholds the
    maps the modality index is counted on at its own quantile (None: ``quantile``);
    ``skip_samples`` drops that many samples at the start before anything else; ``msai_bins`` > 0
    divides SAI and MSAI by that fixed number of bins instead of the number of bins (their 2662).

    Any number of samples is accepted: with none there are no bins (every MI 0, MSAI NaN, cell
    statistics NaN); with fewer than 2 nothing is decoded (NaN errors, ``n_decoded`` 0,
    ``n_undecoded`` = ``n - n // 2``).
    """
    x, y = _positions(x, y)
    r, _ = _samples(rates, len(x), "rates")
    eps, min_samples = _dbscan_params(eps, min_samples)
    out = dict(_an.analyze(x, y, r, _gridsize(gridsize), _quantile(quantile), eps, min_samples, _d_th(d_th),
                           _extent(extent), _templates(decoding_templates, "decoding_templates"),
                           _D2["mi_quantile"] if mi_quantile is None else _quantile(mi_quantile),
                           _count(skip_samples, "skip_samples"),
                           _count(msai_bins, "msai_bins")))
    out["decoding"] = dict(out["decoding"])
    out["modality_summary"] = dict(out["modality_summary"])
    out["cells"] = dict(out["cells"])
    return out


def _positions3(positions):
    p = np.ascontiguousarray(_real(positions, "positions"), dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"positions must be an (n, 3) array of x, y, z, got shape {p.shape}")
    return p


def _voxel(voxel):
    voxel = float(voxel)
    if not voxel > 0 or not np.isfinite(voxel):
        raise ValueError(f"voxel must be a positive length, got {voxel}")
    return voxel


def _volume(volume):
    if volume is None:
        return None
    v = np.asarray(_real(volume, "volume"), dtype=np.float64).ravel()
    if v.shape != (6,):
        raise ValueError(f"volume must be (xmin, xmax, ymin, ymax, zmin, zmax), got {volume!r}")
    return tuple(float(x) for x in v)


def voxel_rate_maps(positions, rates, voxel=_D3["voxel"], volume=None, quantile=_D3["quantile"]):
    """3-D rate maps on cubic voxels (docs/flying.md#analysis), as ``rate_maps`` on hexagons.

    Voxels of side ``voxel`` from the lower corner of ``volume`` (xmin, xmax, ymin, ymax, zmin, zmax;
    positions outside it fall in no voxel), or without a volume from the positions' own minimum.
    Voxel (i, j, k) spans [x0 + i*voxel, x0 + (i+1)*voxel) (and likewise in y, z); only visited voxels
    exist, in the order of their flat index (i*ny + j)*nz + k. Per cell: the mean rate per voxel,
    values below the cell's ``quantile`` set to 0, divided by its maximum.

    Returns ``(centers (B, 3), maps (B, n_cells), counts (B,))`` (``maps`` is (B,) for 1-D rates).
    """
    p = _positions3(positions)
    r, was_1d = _samples(rates, len(p), "rates")
    centers, maps, _, counts = _an.voxel_rate_maps(p, r, _voxel(voxel), _volume(volume), _quantile(quantile))
    return centers, (maps[:, 0] if was_1d else maps), counts


def dbscan_labels(points, eps=_D3["eps"], min_samples=_D3["min_samples"]):
    """``sklearn.cluster.DBSCAN(eps, min_samples).fit(points).labels_``, identical for (N, 2) or (N, 3)
    points: per point its cluster (numbered as scikit-learn numbers them) or -1 for noise."""
    p = np.ascontiguousarray(_real(points, "points"), dtype=np.float64)
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise ValueError(f"points must be an (N, 2) or (N, 3) array, got shape {p.shape}")
    eps, min_samples = _dbscan_params(eps, min_samples)
    return np.asarray(_an.dbscan_labels(p, eps, min_samples), dtype=np.int64)


def isotropy(centers, maps, modality, eps=_D3["eps"], min_samples=_D3["min_samples"]):
    """Field isotropy per cell (docs/flying.md#analysis): for a cell with ``modality`` 1, its field is
    the one DBSCAN cluster among the voxels where its map is > 0 (noise left out), each voxel weighted
    by its map value; isotropy = the weighted sd of the field's z over the mean of its weighted sds
    of x and y (population sds). 1 is round, > 1 a vertical column, < 1 a flat disc. NaN for cells
    with another modality; +inf for a field with vertical spread only. Returns (n_cells,) floats."""
    c = np.ascontiguousarray(_real(centers, "centers"), dtype=np.float64)
    if c.ndim != 2 or c.shape[1] != 3:
        raise ValueError(f"centers must be an (N, 3) array, got shape {c.shape}")
    c, m, _ = _centers_maps(c, maps)
    mi = np.asarray(modality).ravel()
    if mi.shape != (m.shape[1],):
        raise ValueError(f"modality must have one entry per cell ({m.shape[1]}), got shape {np.shape(modality)}")
    eps, min_samples = _dbscan_params(eps, min_samples)
    return np.asarray(_an.isotropy(c, m, [int(v) for v in mi], eps, min_samples))


def analyze3d(positions, rates, voxel=_D3["voxel"], volume=None, quantile=_D3["quantile"], eps=_D3["eps"],
              min_samples=_D3["min_samples"], d_th=_D3["d_th"], decoding_templates=_D3["decoding_templates"]):
    """Every metric of one trial of 3-D positions (a flying agent), on the code paths of ``analyze``:
    voxel rate maps, modality (DBSCAN in 3-D, default min_samples 10), SAI/MSAI over voxel centers,
    decoding with its horizontal and vertical parts, cell statistics, isotropy.

    Returns a dict: ``centers``, ``counts``, ``mean_maps``, ``maps``, ``voxel_volume_m3``,
    ``modality``, ``modality_summary``, ``sai``, ``msai``, ``decoding`` (as ``analyze``'s, plus
    ``median_horizontal_m``, ``mean_horizontal_m``, ``median_vertical_m``, ``mean_vertical_m`` and
    ``median_vertical_chance_m``, the vertical error of a decoder that guesses a first-half voxel at
    random weighted by its samples), ``cells``, ``isotropy`` (n_cells,) and ``metrics`` (the scalar
    metrics as trial files record them).
    """
    p = _positions3(positions)
    r, _ = _samples(rates, len(p), "rates")
    eps, min_samples = _dbscan_params(eps, min_samples)
    out = dict(_an.analyze3d(p, r, _voxel(voxel), _volume(volume), _quantile(quantile), eps, min_samples, _d_th(d_th),
                             _templates(decoding_templates, "decoding_templates")))
    for key in ("decoding", "modality_summary", "cells", "metrics"):
        out[key] = dict(out[key])
    return out


# Place recognition's protocol on arrays (docs/place-recognition.md): the compiled functions as they are.
precision_recall = _an.precision_recall
loop_closure = _an.loop_closure
__all__ += ["precision_recall", "loop_closure"]
