"""Time every docs/model-reference.md#analysis metric of one trial-sized input with bvc3d and with the straightforward
numpy / scikit-learn computation of the same metric, and check that they agree.

    PYTHONPATH=build/python /usr/bin/python3 test/ubench/analysis_bench.py [--samples 50000]
        [--cells 250] [--repeats 3] [--seed 1] [--dense]

Input: a random walk in the 45° cross arena (docs/model-reference.md#robot-and-random-walk) cut to --samples steps,
and --cells sparse place-field-like rates (1-3 Gaussian fields per cell, sigma 0.6 m, values below 0.05 set to 0,
10 % silent cells), float32 as a trial records them. Times are the median of --repeats runs
(references slower than 5 s run once). --dense replaces the rates by uniform random ones, all
non-zero: the worst case for the sparse code paths (every cell active in every bin).
"""
import argparse
import math
import statistics
import time

import numpy as np
from sklearn.cluster import DBSCAN

import bvc3d
from bvc3d import analysis as A


def timed(fn, repeats):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
        if times[-1] > 5:
            break
    return statistics.median(times), out


def trial_input(n_samples, n_cells, seed, dense=False):
    w = bvc3d.random_walk(bvc3d.World.cross(45), n_samples * 0.3 / 3600 * 1.3 + 0.1, seed)
    x, y = w["x"][:n_samples], w["y"][:n_samples]
    assert len(x) == n_samples, "walk too short"
    rng = np.random.default_rng(seed)
    if dense:
        return x, y, rng.random((n_samples, n_cells), dtype=np.float32)
    rates = np.zeros((n_samples, n_cells), dtype=np.float32)
    for c in range(n_cells):
        if rng.random() < 0.1:
            continue
        r = np.zeros(n_samples)
        for _ in range(rng.choice([1, 1, 2, 3])):
            cx, cy = rng.uniform(-4.5, 4.5, 2)
            r += rng.uniform(0.3, 1.0) * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * 0.6**2))
        r[r < 0.05] = 0
        rates[:, c] = r
    return x, y, rates


# --- the straightforward numpy / scikit-learn versions ---------------------------------------


def np_bins(x, y, gridsize=50, extent=None):
    """matplotlib 3.6.3's hexbin rule, vectorised: flat bin index per point (-1 outside)."""
    nx = gridsize
    ny = int(nx / math.sqrt(3))
    if extent is None:
        from matplotlib.transforms import nonsingular
        xmin, xmax = nonsingular(x.min(), x.max(), expander=0.1)
        ymin, ymax = nonsingular(y.min(), y.max(), expander=0.1)
    else:
        xmin, xmax, ymin, ymax = extent
    padding = 1.e-9 * (xmax - xmin)
    xmin -= padding
    xmax += padding
    sx, sy = (xmax - xmin) / nx, (ymax - ymin) / ny
    ix, iy = (x - xmin) / sx, (y - ymin) / sy
    ix1, iy1 = np.round(ix).astype(int), np.round(iy).astype(int)
    ix2, iy2 = np.floor(ix).astype(int), np.floor(iy).astype(int)
    d1 = (ix - ix1) ** 2 + 3.0 * (iy - iy1) ** 2
    d2 = (ix - ix2 - 0.5) ** 2 + 3.0 * (iy - iy2 - 0.5) ** 2
    n1 = (nx + 1) * (ny + 1)
    ok1 = (0 <= ix1) & (ix1 < nx + 1) & (0 <= iy1) & (iy1 < ny + 1)
    ok2 = (0 <= ix2) & (ix2 < nx) & (0 <= iy2) & (iy2 < ny)
    flat = np.where(d1 < d2, np.where(ok1, ix1 * (ny + 1) + iy1, -1), np.where(ok2, n1 + ix2 * ny + iy2, -1))
    cx = np.concatenate([np.repeat(np.arange(nx + 1), ny + 1), np.repeat(np.arange(nx) + 0.5, ny)]) * sx + xmin
    cy = np.concatenate([np.tile(np.arange(ny + 1), nx + 1), np.tile(np.arange(ny), nx) + 0.5]) * sy + ymin
    return flat, np.column_stack([cx, cy]), n1 + nx * ny, 0.5 * sx * sy


def np_means(flat, centers, n_bins, values):
    ok = flat >= 0
    counts = np.bincount(flat[ok], minlength=n_bins)
    visited = np.nonzero(counts)[0]
    sums = np.stack([np.bincount(flat[ok], weights=values[ok, c], minlength=n_bins) for c in range(values.shape[1])], 1)
    return centers[visited], sums[visited] / counts[visited, None], counts[visited]


def np_threshold_normalize(means, quantile=0.1):
    maps = means.copy()
    for k in range(maps.shape[1]):
        col = maps[:, k]
        col[col < np.percentile(col, 100 * quantile)] = 0
        top = col.max()
        maps[:, k] = col / top if top > 0 else 0.0
    return maps


def np_rate_maps(x, y, rates, quantile=0.1):
    flat, centers, n_bins, area = np_bins(x, y)
    c, means, counts = np_means(flat, centers, n_bins, rates)
    return c, np_threshold_normalize(means, quantile), means, counts, area


def mpl_hexbin_cells(x, y, rates, cells):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots()
    for k in cells:
        ax.hexbin(x, y, C=rates[:, k], gridsize=50, reduce_C_function=np.mean)
    plt.close(fig)


def sk_modality(centers, maps):
    out = []
    for k in range(maps.shape[1]):
        pts = centers[maps[:, k] > 0]
        out.append(0 if len(pts) == 0 else int(DBSCAN(eps=1.0, min_samples=20).fit(pts).labels_.max() + 1))
    return np.array(out)


def np_sai(centers, maps, d_th=2.0):
    norms = np.linalg.norm(maps, axis=1, keepdims=True)
    unit = np.divide(maps, norms, out=np.zeros_like(maps), where=norms > 0)
    cos = unit @ unit.T
    d = np.sqrt((centers[:, None, 0] - centers[None, :, 0]) ** 2 + (centers[:, None, 1] - centers[None, :, 1]) ** 2)
    sai = np.where(d > d_th, cos, 0.0).sum(axis=1) / len(centers)
    return sai, sai.mean()


def np_decoding(x, y, rates, templates="rate_maps"):
    """the reference decoder: templates = the first half's rate maps on the trial's grid (or raw means)."""
    half = len(x) // 2
    flat, centers, n_bins, _ = np_bins(x, y)
    c, means, _ = np_means(flat[:half], centers, n_bins, rates[:half])
    tmpl = np_threshold_normalize(means) if templates == "rate_maps" else means
    norms = np.linalg.norm(tmpl, axis=1, keepdims=True)
    unit = np.divide(tmpl, norms, out=np.zeros_like(tmpl), where=norms > 0)
    errors = []
    for s in range(half, len(x), 2000):  # chunks: the full score matrix would need ~0.5 GB
        scores = rates[s:s + 2000].astype(np.float64) @ unit.T
        best = scores.argmax(axis=1)
        ok = scores.max(axis=1) > 0
        e = np.sqrt((x[s:s + 2000] - c[best, 0]) ** 2 + (y[s:s + 2000] - c[best, 1]) ** 2)
        errors.append(e[ok])
    errors = np.concatenate(errors)
    return {"median_m": float(np.median(errors)), "mean_m": float(errors.mean()), "n_decoded": len(errors)}


def np_cell_stats(x, y, rates):
    c, maps, means, counts, area = np_rate_maps(x, y, rates)
    p = counts / counts.sum()
    lam = p @ means
    with np.errstate(divide="ignore", invalid="ignore"):
        info = np.where(means > 0, p[:, None] * means * np.log2(means / lam), 0.0).sum(axis=0)
    return {"peak_rate": means.max(axis=0), "mean_rate": lam, "field_area_m2": (maps > 0.5).sum(axis=0) * area,
            "spatial_info": info}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--samples", type=int, default=50000)
    ap.add_argument("--cells", type=int, default=250)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--dense", action="store_true", help="dense random rates (worst case)")
    args = ap.parse_args()

    x, y, rates = trial_input(args.samples, args.cells, args.seed, args.dense)
    rates64 = rates.astype(np.float64)
    active = (rates > 0).mean()
    print(f"input: {len(x)} samples x {rates.shape[1]} cells (float32), {100 * active:.1f} % non-zero rates")

    rows = []
    R = args.repeats
    t_b, (centers, maps) = timed(lambda: A.rate_maps(x, y, rates), R)
    t_r, (c_ref, maps_ref, _, _, _) = timed(lambda: np_rate_maps(x, y, rates64), R)
    assert np.array_equal(centers, c_ref) and np.allclose(maps, maps_ref, rtol=0, atol=1e-12)
    rows.append(("rate maps (hexbin + threshold)", t_b, t_r, "numpy bincount per cell"))
    few = list(range(5))
    t_mpl, _ = timed(lambda: mpl_hexbin_cells(x, y, rates64, few), 1)
    rows.append(("  (matplotlib hexbin per cell)", None, t_mpl * rates.shape[1] / len(few),
                 f"{len(few)} cells timed, x{rates.shape[1] // len(few)}"))

    t_b, mi = timed(lambda: A.modality(centers, maps), R)
    t_r, mi_ref = timed(lambda: sk_modality(centers, maps), R)
    assert np.array_equal(mi, mi_ref)
    rows.append(("modality (DBSCAN per cell)", t_b, t_r, "sklearn DBSCAN per cell"))

    t_b, (sai, msai) = timed(lambda: A.aliasing(centers, maps), R)
    t_r, (sai_ref, msai_ref) = timed(lambda: np_sai(centers, maps), R)
    assert np.allclose(sai, sai_ref, rtol=0, atol=1e-12)
    rows.append(("spatial aliasing (SAI, MSAI)", t_b, t_r, "numpy Gram + distance matrices"))

    t_b, dec = timed(lambda: A.decoding_error(x, y, rates), R)
    t_r, dec_ref = timed(lambda: np_decoding(x, y, rates), R)
    assert dec["n_decoded"] == dec_ref["n_decoded"] and abs(dec["mean_m"] - dec_ref["mean_m"]) < 1e-9
    rows.append(("decoding error (rate-map templates)", t_b, t_r, "numpy dense scores (reference BLAS)"))
    t_b, dec = timed(lambda: A.decoding_error(x, y, rates, templates="means"), R)
    t_r, dec_ref = timed(lambda: np_decoding(x, y, rates, "means"), R)
    assert dec["n_decoded"] == dec_ref["n_decoded"] and abs(dec["mean_m"] - dec_ref["mean_m"]) < 1e-9
    rows.append(("  (option: raw-mean templates)", t_b, t_r, "numpy dense scores (reference BLAS)"))

    t_b, st = timed(lambda: A.cell_stats(x, y, rates), R)
    t_r, st_ref = timed(lambda: np_cell_stats(x, y, rates64), R)
    assert np.allclose(st["spatial_info"], st_ref["spatial_info"], rtol=1e-9, atol=1e-300)
    rows.append(("cell stats (peak, area, Skaggs)", t_b, t_r, "numpy"))

    t_all, out = timed(lambda: A.analyze(x, y, rates), R)
    ref_total = sum(r[2] for r in rows if r[1] is not None and not r[0].startswith(("cell stats", "  (")))
    rows.append(("all metrics, one call (analyze)", t_all, ref_total, "sum of the reference rows above"))

    print(f"{'metric':36s} {'bvc3d [s]':>10s} {'reference [s]':>14s} {'ratio':>8s}  reference")
    for name, tb, tr, ref in rows:
        tb_s = f"{tb:10.4f}" if tb is not None else f"{'':10s}"
        ratio = f"{tr / tb:7.0f}x" if tb else f"{'':8s}"
        print(f"{name:36s} {tb_s} {tr:14.3f} {ratio}  {ref}")
    s = out["modality_summary"]
    print(f"results: MI>0 {s['frac_active']:.3f}, mean MI {s['mean_mi_active']:.3f}, MI>1 {s['frac_multimodal']:.3f}, "
          f"MSAI {out['msai']:.4f}, decoding median {out['decoding']['median_m']:.3f} m "
          f"(mean {out['decoding']['mean_m']:.3f} m), {len(out['centers'])} bins; bvc3d == reference: yes")
    print(f"target: all metrics of one trial <= 1 s: {'met' if t_all <= 1.0 else 'NOT met'} ({t_all:.3f} s)")


if __name__ == "__main__":
    main()
