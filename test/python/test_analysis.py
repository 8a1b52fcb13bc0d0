"""bvc3d.analysis against its peers: matplotlib's hexbin, numpy's percentile, scikit-learn's DBSCAN,
a brute-force numpy SAI and a dense numpy decoder (docs/model-reference.md#analysis, issue 4)."""
import math

import matplotlib
import numpy as np
from numpy_oracles import numpy_rate_maps
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from sklearn.cluster import DBSCAN  # noqa: E402
from sklearn.neighbors import NearestNeighbors  # noqa: E402

import bvc3d  # noqa: E402
from bvc3d import analysis as A  # noqa: E402
from bvc3d._core import analysis as _core  # noqa: E402


# ---------------------------------------------------------------------------------------------
# helpers


def mpl_hexbin(x, y, c, gridsize=50, extent=None):
    """Offsets and values of an actual matplotlib hexbin."""
    fig, ax = plt.subplots()
    try:
        pc = ax.hexbin(x, y, C=c, gridsize=gridsize, extent=extent, reduce_C_function=np.mean)
        return np.array(pc.get_offsets()), np.array(pc.get_array())
    finally:
        plt.close(fig)


def assert_same_as_matplotlib(x, y, values, gridsize=50, extent=None):
    centers, means, counts = A.hexbin(x, y, values, gridsize=gridsize, extent=extent)
    cols = values.reshape(len(x), -1)
    means = means.reshape(len(centers), -1)
    for k in range(cols.shape[1]):
        off, arr = mpl_hexbin(x, y, cols[:, k].astype(np.float64), gridsize, extent)
        assert off.shape == centers.shape, f"column {k}: {len(off)} bins in matplotlib, {len(centers)} here"
        assert np.array_equal(off, centers), "bin centers differ"
        np.testing.assert_allclose(means[:, k], arr, rtol=0, atol=1e-12)
    assert counts.sum() <= len(x) and np.all(counts > 0)
    return centers, means, counts


def walk(tilt=45, hours=1.0, seed=1):
    w = bvc3d.random_walk(bvc3d.World.cross(tilt), hours, seed)
    return w["x"], w["y"]


def place_population(x, y, n_cells, rng, sigma=0.6, silent_frac=0.1, floor=0.05):
    """Sparse place-field-like rates: each cell has 1-3 Gaussian fields; small values are 0."""
    rates = np.zeros((len(x), n_cells))
    for c in range(n_cells):
        if rng.random() < silent_frac:
            continue
        for _ in range(rng.choice([1, 1, 2, 3])):
            cx, cy = rng.uniform(-4.5, 4.5, 2)
            rates[:, c] += rng.uniform(0.3, 1.0) * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * sigma**2))
    rates[rates < floor] = 0
    return rates.astype(np.float32)


def sklearn_count(points, eps, min_samples):
    if len(points) == 0:
        return 0
    return int(DBSCAN(eps=eps, min_samples=min_samples).fit(points).labels_.max() + 1)


def sklearn_neighborhoods(points, eps):
    nb = NearestNeighbors(radius=eps).fit(points).radius_neighbors(points, return_distance=False)
    return [set(v.tolist()) for v in nb]


def our_neighborhoods(points, eps):
    off, ind = _core.radius_neighbors(np.ascontiguousarray(points, dtype=float), eps)
    return [set(ind[off[i]:off[i + 1]].tolist()) for i in range(len(points))]


def plain_neighborhoods(points, eps):
    d2 = (points[:, None, 0] - points[None, :, 0]) ** 2 + (points[:, None, 1] - points[None, :, 1]) ** 2
    return [set(np.nonzero(row <= eps * eps)[0].tolist()) for row in d2]


# ---------------------------------------------------------------------------------------------
# hexbin


@pytest.mark.parametrize("n,gridsize,extent", [
    (1000, 50, None), (5000, 50, None), (3000, 20, None), (3000, 7, None), (2000, 2, None),
    (4000, 50, (-5.0, 5.0, -5.0, 5.0)), (4000, 30, (-3.0, 2.0, -1.0, 4.0)),  # points outside are dropped
])
def test_hexbin_random_points_match_matplotlib(n, gridsize, extent):
    rng = np.random.default_rng(n + gridsize)
    x = rng.uniform(-5, 5, n)
    y = rng.normal(0, 2, n)
    values = np.column_stack([rng.random(n), rng.normal(size=n), (rng.random(n) < 0.1) * rng.random(n)])
    assert_same_as_matplotlib(x, y, values, gridsize, extent)


def test_hexbin_one_point_and_two_coincident_points():
    assert_same_as_matplotlib(np.array([0.3]), np.array([-2.0]), np.array([0.7]))
    assert_same_as_matplotlib(np.array([0.0]), np.array([0.0]), np.array([1.5]))  # nonsingular around 0
    assert_same_as_matplotlib(np.array([1e-300, 1e-300]), np.array([3.0, 3.0]), np.array([1.0, 2.0]))


def test_hexbin_vertical_and_horizontal_lines():
    rng = np.random.default_rng(5)
    y = rng.uniform(-4, 4, 500)
    assert_same_as_matplotlib(np.full(500, 2.5), y, rng.random(500))   # x range singular
    assert_same_as_matplotlib(y, np.full(500, -1.0), rng.random(500))  # y range singular
    assert_same_as_matplotlib(np.full(50, 7.0), np.full(50, 7.0), rng.random(50))


def exact_index_point(lo, step, target):
    """A float v with (v - lo) / step == target exactly (as numpy evaluates it), or None."""
    v = lo + target * step
    for k in range(-32, 33):
        w = v + k * np.spacing(v)
        if (w - lo) / step == target:
            return w
    return None


def test_hexbin_points_exactly_on_bin_boundaries():
    # The grid matplotlib builds for this extent, to place points at exact index coordinates: on
    # the x.5 rounding boundary (round half to even), on the d1 == d2 ties between the lattices
    # (matplotlib gives them to lattice 2) and on the grid's outer edges.
    xmin, xmax, ymin, ymax, gs = -5.0, 5.0, -5.0, 5.0, 50
    ny = int(gs / math.sqrt(3))
    pad = 1e-9 * (xmax - xmin)
    x0, x1 = xmin - pad, xmax + pad
    sx, sy = (x1 - x0) / gs, (ymax - ymin) / ny
    targets = []
    for i in range(0, gs + 1, 3):
        for j in range(0, ny + 1, 2):
            targets += [(i + 0.5, j), (i + 0.25, j + 0.25), (i + 0.75, j + 0.25), (i + 0.25, j + 0.75),
                        (i, j + 0.5), (i + 0.5, j + 0.5), (i, j), (i - 0.5, j), (i + 0.5, j - 0.5)]
    pts = []
    for tx, ty in targets:
        px, py = exact_index_point(x0, sx, tx), exact_index_point(ymin, sy, ty)
        if px is not None and py is not None:
            pts.append((px, py))
    pts = np.array(pts)
    assert len(pts) > 0.5 * len(targets)
    ix, iy = (pts[:, 0] - x0) / sx, (pts[:, 1] - ymin) / sy
    d1 = (ix - np.round(ix)) ** 2 + 3.0 * (iy - np.round(iy)) ** 2
    d2 = (ix - np.floor(ix) - 0.5) ** 2 + 3.0 * (iy - np.floor(iy) - 0.5) ** 2
    assert np.sum(d1 == d2) > 50, "the set must contain exact ties between the two lattices"
    rng = np.random.default_rng(0)
    values = rng.random(len(pts))
    assert_same_as_matplotlib(pts[:, 0], pts[:, 1], values, gs, (xmin, xmax, ymin, ymax))
    # Add the corners of the extent so that the data's own extent is the same rectangle.
    corners = np.array([[xmin, ymin], [xmax, ymax]])
    allp = np.vstack([pts, corners])
    assert_same_as_matplotlib(allp[:, 0], allp[:, 1], rng.random(len(allp)), gs, None)


@pytest.mark.parametrize("tilt,seed", [(45, 1), (0, 2), (60, 3)])
def test_hexbin_random_walk_trajectory(tilt, seed):
    x, y = walk(tilt, 1.0, seed)
    rng = np.random.default_rng(seed)
    rates = place_population(x, y, 3, rng, silent_frac=0.0)
    values = np.column_stack([rates.astype(np.float64), rng.random(len(x))])
    assert_same_as_matplotlib(x, y, values)


def test_hexbin_float32_values_are_read_exactly():
    x, y = walk(30, 0.5, 4)
    v32 = np.random.default_rng(2).random((len(x), 4)).astype(np.float32)
    c32, m32, n32 = A.hexbin(x, y, v32)
    c64, m64, n64 = A.hexbin(x, y, v32.astype(np.float64))
    assert np.array_equal(c32, c64) and np.array_equal(n32, n64)
    np.testing.assert_allclose(m32, m64, rtol=0, atol=1e-15)
    assert_same_as_matplotlib(x, y, v32)


def test_hexbin_one_column_shapes_and_counts():
    x, y = walk(0, 0.2, 7)
    centers, means, counts = A.hexbin(x, y, np.ones(len(x)))
    assert means.shape == (len(centers),) and np.all(means == 1.0)
    fig, ax = plt.subplots()
    off = ax.hexbin(x, y, gridsize=50)  # count mode: same bins when every bin has >= 1 point
    counts_mpl = np.asarray(off.get_array())
    plt.close(fig)
    assert np.array_equal(np.sort(counts_mpl[counts_mpl > 0]), np.sort(counts.astype(float)))
    assert counts.sum() == len(x)


# ---------------------------------------------------------------------------------------------
# rate maps


def test_percentile_is_numpys_bit_for_bit():
    rng = np.random.default_rng(4)
    for trial in range(300):
        n = int(rng.choice([1, 2, 3, 10, int(rng.integers(1, 3000))]))
        v = rng.random(n) * (rng.random(n) < rng.random())
        for p in (0.0, 10.0, 100.0, 100 * float(rng.random()), 100 * 0.1, float(rng.integers(0, 101))):
            assert _core.percentile(v, p) == np.percentile(v, p), (n, p)


@pytest.mark.parametrize("quantile", [0.0, 0.1, 0.37, 0.5, 0.9, 1.0])
def test_rate_maps_threshold_matches_numpy_percentile(quantile):
    x, y = walk(45, 1.0, 11)
    rng = np.random.default_rng(11)
    rates = place_population(x, y, 40, rng, silent_frac=0.0, floor=0.0)  # dense: the quantile bites
    rates[:, :5] *= (rng.random((len(x), 5)) < 0.3)     # ties at zero
    rates[:, 5] = 0                                      # a silent cell stays zero
    rates[:, 6] = 0.25                                   # a constant cell
    centers, maps = A.rate_maps(x, y, rates, quantile=quantile)
    c2, means, _ = A.hexbin(x, y, rates)
    assert np.array_equal(centers, c2)
    np.testing.assert_array_equal(maps, numpy_rate_maps(means, quantile))
    assert np.all(maps[:, 5] == 0) and np.all(np.isfinite(maps))
    assert np.all(maps.max(axis=0)[np.arange(40) != 5] == 1.0)


def test_rate_maps_one_cell_and_extent():
    x, y = walk(0, 0.5, 3)
    r = np.exp(-(x**2 + y**2))
    centers, m = A.rate_maps(x, y, r, extent=(-5, 5, -5, 5), gridsize=40)
    off, arr = mpl_hexbin(x, y, r, 40, (-5, 5, -5, 5))
    assert m.shape == (len(centers),) and np.array_equal(centers, off)
    np.testing.assert_allclose(m, numpy_rate_maps(arr[:, None], 0.1)[:, 0], rtol=0, atol=1e-12)


# ---------------------------------------------------------------------------------------------
# DBSCAN / modality


@pytest.mark.parametrize("density", [0.5, 3.0, 10.0, 40.0])
def test_dbscan_random_points_match_sklearn(density):
    rng = np.random.default_rng(int(density * 10))
    for trial in range(12):
        side = rng.uniform(2, 12)
        n = max(1, int(density * side * side * rng.uniform(0.5, 1.5)))
        pts = rng.uniform(-side / 2, side / 2, (n, 2))
        if trial % 3 == 0:  # clumps
            pts = np.vstack([rng.normal(rng.uniform(-5, 5, 2), rng.uniform(0.2, 1.0), (n // 3 + 1, 2))
                             for _ in range(3)])
        eps = float(rng.choice([1.0, rng.uniform(0.2, 2.0)]))
        ms = int(rng.choice([20, 5, int(rng.integers(1, 40))]))
        assert A.dbscan_cluster_count(pts, eps, ms) == sklearn_count(pts, eps, ms), (density, trial, n, eps, ms)


def hex_lattice(a, rows, cols, origin=(0.0, 0.0), angle=0.0):
    i, j = np.meshgrid(np.arange(cols), np.arange(rows))
    px = a * (i + 0.5 * (j % 2))
    py = a * j * math.sqrt(3) / 2
    ca, sa = math.cos(angle), math.sin(angle)
    return np.column_stack([origin[0] + ca * px.ravel() - sa * py.ravel(),
                            origin[1] + sa * px.ravel() + ca * py.ravel()])


def test_dbscan_hex_lattice_at_exactly_eps():
    # Six neighbors at nominally eps: whether each counts decides core points for min_samples = 7.
    rng = np.random.default_rng(2)
    n_cases = 0
    for trial in range(40):
        a = float(rng.choice([1.0, 0.5, 0.3, 1 / 3]))
        lat = hex_lattice(a, int(rng.integers(3, 25)), int(rng.integers(3, 25)),
                          origin=tuple(rng.uniform(-5, 5, 2) * (trial % 2)),
                          angle=float(rng.choice([0.0, math.pi / 6, rng.uniform(0, math.pi)])))
        keep = rng.random(len(lat)) < rng.uniform(0.6, 1.0)
        pts = lat[keep]
        for ms in (3, 5, 6, 7, 8, 20):
            assert A.dbscan_cluster_count(pts, a, ms) == sklearn_count(pts, a, ms), (trial, a, ms)
            n_cases += 1
        assert our_neighborhoods(pts, a) == sklearn_neighborhoods(pts, a)
    assert n_cases == 240


def test_dbscan_hexbin_centers_at_exactly_eps():
    # The bins' own lattice with eps = a center-to-center distance as computed in floating point.
    x, y = walk(45, 1.0, 5)
    centers, _, _ = A.hexbin(x, y, np.ones(len(x)), gridsize=50)
    d = np.sqrt(((centers[:, None, :] - centers[None, :, :]) ** 2).sum(-1))
    rng = np.random.default_rng(5)
    near = np.unique(d[(d > 0) & (d < 1.2)])
    for eps in list(rng.choice(near, 8, replace=False)) + [float(near.min())]:
        sub = centers[rng.random(len(centers)) < 0.8]
        for ms in (2, 4, 7, 13, 20):
            assert A.dbscan_cluster_count(sub, eps, ms) == sklearn_count(sub, eps, ms), (eps, ms)
        assert our_neighborhoods(sub, eps) == sklearn_neighborhoods(sub, eps)


def test_dbscan_kd_tree_node_tests_are_reproduced():
    # Points a distance with dx² + dy² = 1 + 2^-52 apart: the point test rejects them at eps = 1,
    # but sklearn's KD-tree accepts a whole node when pow(max box distance², 0.5) == 1 <= eps.
    rng = np.random.default_rng(3)
    differs_from_plain = 0
    for trial in range(150):
        n = int(rng.integers(2, 250))
        w = int(rng.integers(1, 4))
        p = np.zeros((n, 2))
        p[:, 0] = rng.integers(-w, w + 1, n) + rng.integers(-1, 2, n) * 2.0**-26 * (trial % 2)
        p[:, 1] = rng.integers(-1, 2, n) * 2.0**-26 + 3.0 * rng.integers(0, 3, n) * (trial % 3 == 0)
        if trial % 4 == 1:
            p = p[:, ::-1].copy()
        sk = sklearn_neighborhoods(p, 1.0)
        assert our_neighborhoods(p, 1.0) == sk, trial
        differs_from_plain += sk != plain_neighborhoods(p, 1.0)
        for ms in (2, 3, int(rng.integers(1, 30))):
            assert A.dbscan_cluster_count(p, 1.0, ms) == sklearn_count(p, 1.0, ms), (trial, ms)
    assert differs_from_plain > 10, "the set must exercise sklearn's node-level acceptance"


def test_dbscan_small_sets_use_sklearns_brute_force_rule():
    # n <= 11: NearestNeighbors picks brute force (|x|² - 2x.y + |y|²), which rounds differently.
    rng = np.random.default_rng(8)
    differs_from_plain = 0
    for trial in range(400):
        n = int(rng.integers(1, 12))
        a = float(rng.choice([1.0, 0.3, 0.7]))
        base = rng.uniform(-6, 6, 2)
        ij = rng.integers(-2, 3, (n, 2))
        pts = np.column_stack([base[0] + a * (ij[:, 0] + 0.5 * (ij[:, 1] % 2)),
                               base[1] + a * ij[:, 1] * math.sqrt(3) / 2])
        sk = sklearn_neighborhoods(pts, a)
        assert our_neighborhoods(pts, a) == sk
        differs_from_plain += sk != plain_neighborhoods(pts, a)
        for ms in range(1, n + 2):
            assert A.dbscan_cluster_count(pts, a, ms) == sklearn_count(pts, a, ms)
    assert differs_from_plain > 10


def test_modality_on_real_rate_maps_matches_sklearn():
    for tilt, seed in [(0, 1), (45, 2), (60, 3)]:
        x, y = walk(tilt, 2.0, seed)
        rng = np.random.default_rng(seed)
        rates = place_population(x, y, 60, rng, sigma=float(rng.uniform(0.4, 0.8)))
        centers, maps = A.rate_maps(x, y, rates)
        for eps, ms in [(1.0, 20), (0.5, 5), (float(centers[1, 1] - centers[0, 1]), 7)]:
            mi = A.modality(centers, maps, eps, ms)
            ref = [sklearn_count(centers[maps[:, c] > 0], eps, ms) for c in range(maps.shape[1])]
            assert mi.tolist() == ref, (tilt, eps, ms)
        assert A.modality(centers, maps).max() >= 2  # multi-field cells exist in this population


def test_modality_summary():
    s = A.modality_summary([0, 1, 2, 3, 0, 1])
    assert s == pytest.approx({"frac_active": 4 / 6, "mean_mi_active": 7 / 4, "frac_multimodal": 2 / 6})
    s = A.modality_summary([0, 0])
    assert s["frac_active"] == 0 and math.isnan(s["mean_mi_active"]) and s["frac_multimodal"] == 0
    assert all(math.isnan(v) for v in A.modality_summary(np.array([], dtype=int)).values())


# ---------------------------------------------------------------------------------------------
# spatial aliasing


def sai_brute(centers, maps, d_th):
    n = len(centers)
    norms = np.linalg.norm(maps, axis=1)
    sai = np.zeros(n)
    for i in range(n):  # the double loop, the inner one vectorised
        dx, dy = centers[i, 0] - centers[:, 0], centers[i, 1] - centers[:, 1]
        far = (np.sqrt(dx * dx + dy * dy) > d_th) & (np.arange(n) != i) & (norms > 0)
        if norms[i] > 0:
            sai[i] = np.sum(maps[far] @ maps[i] / (norms[far] * norms[i]))
    return sai / n


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_sai_matches_brute_force_double_loop(seed):
    x, y = walk(45, 0.3, seed)
    rng = np.random.default_rng(seed)
    rates = place_population(x, y, 12, rng, sigma=1.0)
    centers, maps = A.rate_maps(x, y, rates, gridsize=16)
    # A d_th equal to a center distance: pairs at exactly d_th are near (not > d_th).
    d = np.sqrt(((centers[:, None, :] - centers[None, :, :]) ** 2).sum(-1))
    for d_th in (2.0, 0.0, float(d[0, len(d) // 2]), 100.0):
        sai, msai = A.aliasing(centers, maps, d_th)
        ref = sai_brute(centers, maps, d_th)
        np.testing.assert_allclose(sai, ref, rtol=0, atol=1e-12)
        assert msai == pytest.approx(ref.mean(), abs=1e-12)


def test_sai_random_maps_with_zero_rows_and_negative_entries():
    rng = np.random.default_rng(9)
    centers = rng.uniform(-5, 5, (150, 2))
    maps = rng.normal(size=(150, 7)) * (rng.random((150, 7)) < 0.4)
    maps[::10] = 0
    sai, msai = A.aliasing(centers, maps, 2.0)
    np.testing.assert_allclose(sai, sai_brute(centers, maps, 2.0), rtol=0, atol=1e-12)
    assert np.all(sai[::10] == 0)


# ---------------------------------------------------------------------------------------------
# decoding


def dense_decoder(x, y, rates, templates="rate_maps", quantile=0.1, gridsize=50):
    """the reference decoder in plain numpy: templates from the first half on the whole trial's grid,
    cosine similarity of every second-half sample with every template, argmax."""
    n = len(x)
    half = n // 2
    ext = (x.min(), x.max(), y.min(), y.max())
    centers, means, counts = A.hexbin(x[:half], y[:half], rates[:half].astype(np.float64), gridsize, ext)
    tmpl = numpy_rate_maps(means, quantile) if templates == "rate_maps" else means
    norms = np.linalg.norm(tmpl, axis=1, keepdims=True)
    unit = np.divide(tmpl, norms, out=np.zeros_like(tmpl), where=norms > 0)
    scores = rates[half:].astype(np.float64) @ unit.T
    best = scores.argmax(axis=1)
    ok = scores.max(axis=1) > 0
    dx, dy = x[half:] - centers[best, 0], y[half:] - centers[best, 1]
    err = np.sqrt(dx * dx + dy * dy)
    # Chance for an undecoded sample: its mean distance to the template bins, weighted by occupancy.
    dist = np.hypot(x[half:, None] - centers[None, :, 0], y[half:, None] - centers[None, :, 1])
    chance = dist @ counts / counts.sum()
    every = np.where(ok, err, chance)
    return np.median(err[ok]), err[ok].mean(), ok.sum(), (~ok).sum(), np.median(every), every.mean()


# sparse rates, and dense ones (the blocked-product path); a quantile that removes nothing (0.1,
# sparse maps) and ones that cut real values of dense maps
@pytest.mark.parametrize("floor,quantile", [(0.05, 0.1), (0.0, 0.1), (0.0, 0.6), (0.05, 0.95)])
@pytest.mark.parametrize("templates", ["rate_maps", "means"])
def test_decoding_matches_a_dense_numpy_decoder(floor, quantile, templates):
    x, y = walk(30, 1.0, 6)
    rates = place_population(x, y, 80, np.random.default_rng(6), sigma=0.7, floor=floor)
    if floor == 0:
        rates += np.float32(1e-3) * np.random.default_rng(7).random(rates.shape, dtype=np.float32)
    rates[len(x) // 2 + 5] = 0  # a silent sample is not decoded
    d = A.decoding_error(x, y, rates, quantile=quantile, templates=templates)
    med, mean, n_ok, n_bad, med_all, mean_all = dense_decoder(x, y, rates, templates, quantile)
    assert d["n_decoded"] == n_ok and d["n_undecoded"] == n_bad and n_bad >= 1
    assert d["median_m"] == pytest.approx(med, abs=1e-9)
    assert d["mean_m"] == pytest.approx(mean, abs=1e-9)
    assert d["frac_undecoded"] == n_bad / (n_ok + n_bad)
    assert d["median_all_m"] == pytest.approx(med_all, abs=1e-9)
    assert d["mean_all_m"] == pytest.approx(mean_all, abs=1e-9)


def test_undecoded_samples_count_at_chance():
    """Silencing a third of the second half: those samples count at their occupancy-weighted chance
    error, which is far worse than decoding, so the error over all samples rises."""
    x, y = walk(0, 1.0, 12)
    rates = place_population(x, y, 100, np.random.default_rng(12), sigma=0.6)
    rates += np.float32(1e-3)  # every cell a little active: every sample decodes
    half = len(x) // 2
    full = A.decoding_error(x, y, rates)
    assert full["n_undecoded"] == 0 and full["frac_undecoded"] == 0
    assert full["median_all_m"] == full["median_m"] and full["mean_all_m"] == full["mean_m"]
    rates[half::3] = 0
    d = A.decoding_error(x, y, rates)
    _, _, n_ok, n_bad, med_all, mean_all = dense_decoder(x, y, rates)
    assert d["n_undecoded"] == n_bad == len(range(half, len(x), 3))
    assert d["frac_undecoded"] == pytest.approx(1 / 3, abs=0.01)
    assert (d["mean_all_m"] == pytest.approx(mean_all, abs=1e-9)
            and d["median_all_m"] == pytest.approx(med_all, abs=1e-9))
    assert d["mean_all_m"] > d["mean_m"] + 1.0  # chance in a 10 m arena is metres, decoding is decimetres


def test_decoding_default_templates_are_the_spec_rate_maps():
    """docs/model-reference.md#analysis: the templates are the thresholded, max-normalized rate maps of the first
    half."""
    x, y = walk(45, 1.0, 8)
    rates = place_population(x, y, 120, np.random.default_rng(8), sigma=0.7)  # peak rates 0.3-1: scaling matters
    d = A.decoding_error(x, y, rates)
    med, mean, n_ok, n_bad, _, _ = dense_decoder(x, y, rates, "rate_maps", 0.1)
    assert (d["n_decoded"], d["n_undecoded"]) == (n_ok, n_bad)
    assert abs(d["median_m"] - med) < 1e-9 and abs(d["mean_m"] - mean) < 1e-9
    assert d == A.decoding_error(x, y, rates, templates="rate_maps", quantile=0.1)
    # ... and not the raw means: the per-cell normalization changes which bins win.
    med_m, mean_m, _, _, _, _ = dense_decoder(x, y, rates, "means")
    assert abs(mean - mean_m) > 1e-6
    means = A.decoding_error(x, y, rates, templates="means")
    assert abs(means["mean_m"] - mean_m) < 1e-9
    # The quantile is the rate maps' quantile.
    q = A.decoding_error(x, y, rates, quantile=0.97)
    med_q, mean_q, _, _, _, _ = dense_decoder(x, y, rates, "rate_maps", 0.97)
    assert abs(q["median_m"] - med_q) < 1e-9 and abs(q["mean_m"] - mean_q) < 1e-9 and abs(mean_q - mean) > 1e-6


@pytest.mark.parametrize("templates", ["rate_maps", "means"])
def test_decoding_gaussian_fields_is_accurate_and_shuffled_is_chance(templates):
    x, y = walk(0, 4.0, 12)
    rng = np.random.default_rng(12)
    n_cells = 250
    cx, cy = rng.uniform(-5, 5, n_cells), rng.uniform(-5, 5, n_cells)
    rates = np.exp(-((x[:, None] - cx) ** 2 + (y[:, None] - cy) ** 2) / (2 * 0.75**2)).astype(np.float32)
    rates[rates < 0.05] = 0
    good = A.decoding_error(x, y, rates, templates=templates)
    assert good["median_m"] < 0.35 and good["mean_m"] < 0.5 and good["n_undecoded"] == 0
    shuffled = rates[rng.permutation(len(x))]
    bad = A.decoding_error(x, y, shuffled, templates=templates)
    # Chance: the distance from the true positions to the centers of random samples' positions.
    half = len(x) // 2
    pick = rng.integers(0, half, len(x) - half)
    chance = np.median(np.hypot(x[half:] - x[pick], y[half:] - y[pick]))
    assert 0.75 * chance < bad["median_m"] < 1.25 * chance, (bad, chance)
    assert bad["median_m"] > 5 * good["median_m"]


# ---------------------------------------------------------------------------------------------
# per-cell statistics and the one-call analysis


def test_cell_stats_match_numpy():
    x, y = walk(45, 1.0, 21)
    rates = place_population(x, y, 30, np.random.default_rng(21))
    rates[:, 0] = 0
    st = A.cell_stats(x, y, rates)
    centers, means, counts = A.hexbin(x, y, rates)
    _, maps = A.rate_maps(x, y, rates)
    p = counts / counts.sum()
    lam = p @ means
    np.testing.assert_allclose(st["peak_rate"], means.max(axis=0), rtol=1e-15)
    np.testing.assert_allclose(st["mean_rate"], lam, rtol=1e-12)
    np.testing.assert_allclose(st["mean_rate"], rates.astype(float).mean(axis=0), rtol=1e-9)
    # Hexagon area: matplotlib's polygon [sx, sy/3] * unit hexagon.
    sx = np.diff(np.unique(centers[:, 0])).min() * 2
    sy = np.diff(np.unique(centers[:, 1])).min() * 2
    area = 0.5 * sx * sy
    np.testing.assert_allclose(st["field_area_m2"], (maps > 0.5).sum(axis=0) * area, rtol=1e-9)
    with np.errstate(divide="ignore", invalid="ignore"):
        terms = np.where(means > 0, p[:, None] * means * np.log2(means / lam), 0.0)
    info = terms.sum(axis=0)
    active = lam > 0
    assert not active[0] and active.sum() > 20
    np.testing.assert_allclose(st["spatial_info"], info, rtol=1e-10, atol=1e-300)
    np.testing.assert_allclose(st["spatial_info_per_rate"][active], info[active] / lam[active], rtol=1e-10)
    assert np.all(st["spatial_info"][~active] == 0) and np.all(np.isnan(st["spatial_info_per_rate"][~active]))


@pytest.mark.parametrize("quantile,templates", [(0.1, "rate_maps"), (0.1, "means"), (0.9, "rate_maps")])
def test_analyze_equals_the_single_metrics(quantile, templates):
    x, y = walk(60, 1.0, 31)
    rates = place_population(x, y, 50, np.random.default_rng(31), floor=0.0 if quantile > 0.5 else 0.05)
    out = A.analyze(x, y, rates, quantile=quantile, decoding_templates=templates)
    centers, maps = A.rate_maps(x, y, rates, quantile=quantile)
    assert np.array_equal(out["centers"], centers) and np.array_equal(out["maps"], maps)
    mi = A.modality(centers, maps)
    assert np.array_equal(out["modality"], mi)
    assert out["modality_summary"] == A.modality_summary(mi)
    sai, msai = A.aliasing(centers, maps)
    assert np.array_equal(out["sai"], sai) and out["msai"] == msai
    assert out["decoding"] == A.decoding_error(x, y, rates, quantile=quantile, templates=templates)
    st = A.cell_stats(x, y, rates, quantile=quantile)
    for k in st:
        np.testing.assert_array_equal(out["cells"][k], st[k])


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_analyze_zero_and_one_sample(dtype):
    """A trial may record fewer than 2 samples: analyze reports it instead of raising."""
    for n in (0, 1):
        x, y = np.full(n, 1.5), np.full(n, -2.0)
        rates = np.zeros((n, 4), dtype=dtype)
        if n:
            rates[0, 1] = 0.7
        out = A.analyze(x, y, rates)
        d = out["decoding"]
        assert math.isnan(d["median_m"]) and math.isnan(d["mean_m"])
        assert d["n_decoded"] == 0 and d["n_undecoded"] == n - n // 2
        assert out["modality"].tolist() == [0, 0, 0, 0]
        assert out["maps"].shape == (n, 4) and out["mean_maps"].shape == (n, 4) and out["centers"].shape == (n, 2)
        assert out["counts"].tolist() == [1] * n and len(out["sai"]) == n
        s = out["modality_summary"]
        assert s["frac_active"] == 0 and s["frac_multimodal"] == 0 and math.isnan(s["mean_mi_active"])
        if n == 0:
            assert math.isnan(out["msai"])
            assert all(np.all(np.isnan(out["cells"][k])) for k in ("peak_rate", "mean_rate", "spatial_info"))
        else:
            # One point is what matplotlib makes of it: one bin at the point's own (expanded) grid.
            off, arr = mpl_hexbin(x, y, rates[:, 1].astype(np.float64))
            assert np.array_equal(out["centers"], off) and out["mean_maps"][:, 1].tolist() == arr.tolist()
            assert out["maps"].tolist() == [[0.0, 1.0, 0.0, 0.0]]
            assert out["msai"] == 0.0 and out["sai"].tolist() == [0.0]
            assert out["cells"]["peak_rate"][1] == pytest.approx(0.7)
        # The single metrics agree where they are defined (decoding needs 2 samples).
        centers, maps = A.rate_maps(x, y, rates)
        assert np.array_equal(out["centers"], centers) and np.array_equal(out["maps"], maps)
        with pytest.raises(ValueError, match="at least 2 samples"):
            A.decoding_error(x, y, rates)
    # Two samples are decoded: the second from the first one's template.
    x, y = np.array([0.0, 0.0]), np.array([0.0, 1.0])
    d = A.analyze(x, y, np.ones((2, 3), dtype=dtype))["decoding"]
    assert d["n_decoded"] == 1 and d["n_undecoded"] == 0 and d["median_m"] == pytest.approx(1.0, abs=0.05)


# ---------------------------------------------------------------------------------------------
# bad input


def test_bad_input_raises_value_error():
    x, y = walk(0, 0.1, 1)
    r = np.ones((len(x), 3))
    with pytest.raises(ValueError, match="same length"):
        A.hexbin(x, y[:-1], r[:, 0])
    with pytest.raises(ValueError, match="one row per sample"):
        A.rate_maps(x, y, r[:-1])
    xn = x.copy()
    xn[3] = np.nan
    with pytest.raises(ValueError, match="finite"):
        A.hexbin(xn, y, r)
    with pytest.raises(ValueError, match="finite"):
        A.decoding_error(x, np.where(np.arange(len(y)) == 2, np.inf, y), r)
    rn = r.copy()
    rn[1, 1] = np.nan
    with pytest.raises(ValueError, match="finite"):
        A.rate_maps(x, y, rn)
    for g in (0, 1, -3, 2.5):
        with pytest.raises(ValueError, match="gridsize"):
            A.hexbin(x, y, r, gridsize=g)
    for q in (-0.1, 1.5, float("nan")):
        with pytest.raises(ValueError, match="quantile"):
            A.rate_maps(x, y, r, quantile=q)
    centers, maps = A.rate_maps(x, y, r)
    for eps in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="eps"):
            A.modality(centers, maps, eps=eps)
        with pytest.raises(ValueError, match="eps"):
            A.dbscan_cluster_count(centers, eps=eps)
    with pytest.raises(ValueError, match="min_samples"):
        A.modality(centers, maps, min_samples=0)
    with pytest.raises(ValueError, match="maps"):
        A.modality(centers[:-1], maps)
    with pytest.raises(ValueError, match="d_th"):
        A.aliasing(centers, maps, d_th=-1.0)
    with pytest.raises(ValueError, match="extent"):
        A.hexbin(x, y, r, extent=(1.0, 0.0, -1.0, 1.0))
    with pytest.raises(ValueError, match="extent"):
        A.hexbin(x, y, r, extent=(0.0, 1.0, 2.0))
    with pytest.raises(ValueError, match="at least 2 samples"):
        A.decoding_error(x[:1], y[:1], r[:1])
    with pytest.raises(ValueError, match="templates"):
        A.decoding_error(x, y, r, templates="maps")
    with pytest.raises(ValueError, match="decoding_templates"):
        A.analyze(x, y, r, decoding_templates="mean")
    with pytest.raises(ValueError, match="quantile"):
        A.decoding_error(x, y, r, quantile=2.0)
    with pytest.raises(ValueError, match="templates"):
        _core.decoding_error(x, y, r, 50, None, 0.1, "nope")
    # The compiled layer checks too (InputError is a ValueError).
    with pytest.raises(ValueError, match="gridsize"):
        _core.hexbin(x, y, r, 1, None)
    with pytest.raises(ValueError, match="eps"):
        _core.dbscan_cluster_count(centers, 0.0, 5)
