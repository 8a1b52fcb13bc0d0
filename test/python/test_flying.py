"""Flying agents (docs/flying.md): the 3-D analysis against brute-force numpy and scikit-learn on
synthetic 3-D fields, isotropy on hand-made ellipsoidal fields, and the flying walk and trials from
Python (issue 12)."""
import numpy as np
from numpy_oracles import numpy_rate_maps
import pytest
from sklearn.cluster import DBSCAN

import bvc3d
from bvc3d import analysis as A
from conftest import SOURCE_DIR

VOLUME = (-2.9, 2.9, -2.3, 2.3, 0.2, 2.5)  # the flight room's flight volume


@pytest.fixture(scope="module")
def flight():
    w = bvc3d.flying_walk(bvc3d.World.preset("flight-room"), 1.0, 4)
    return np.column_stack([w["x"], w["y"], w["z"]])


def gaussian_population(p, n_cells, rng, sigma=(0.5, 0.5, 0.5), floor=0.05):
    """Rates of cells with one or two 3-D Gaussian fields each; small values are 0."""
    lo, hi = np.array(VOLUME[0::2]), np.array(VOLUME[1::2])
    rates = np.zeros((len(p), n_cells))
    for c in range(n_cells):
        for _ in range(rng.choice([1, 1, 2])):
            center = rng.uniform(lo, hi)
            rates[:, c] += rng.uniform(0.3, 1.0) * np.exp(-0.5 * (((p - center) / np.asarray(sigma)) ** 2).sum(1))
    rates[rates < floor] = 0
    return rates.astype(np.float32)


def numpy_voxels(p, side, volume):
    """Voxel (i, j, k) of each position, written out in numpy (-1 outside), and the grid's shape."""
    lo, hi = np.array(volume[0::2]), np.array(volume[1::2])
    n = np.maximum(1, np.ceil((hi - lo) / side)).astype(int)
    u = (p - lo) / side
    ijk = np.floor(u).astype(int)
    ijk = np.where((ijk == n) & (u <= n), n - 1, ijk)  # the far face belongs to the last voxel
    inside = np.all((u >= 0) & (ijk < n), axis=1)
    flat = (ijk[:, 0] * n[1] + ijk[:, 1]) * n[2] + ijk[:, 2]
    return np.where(inside, flat, -1), n, lo


def numpy_voxel_means(p, rates, side, volume):
    flat, n, lo = numpy_voxels(p, side, volume)
    bins = np.unique(flat[flat >= 0])
    means = np.array([rates[flat == b].astype(np.float64).mean(axis=0) for b in bins])
    counts = np.array([(flat == b).sum() for b in bins])
    i, j, k = bins // (n[1] * n[2]), (bins // n[2]) % n[1], bins % n[2]
    centers = lo + side * (np.column_stack([i, j, k]) + 0.5)
    return centers, means, counts


# ---------------------------------------------------------------------------------------------
# voxel rate maps


@pytest.mark.parametrize("side,quantile", [(0.5, 0.1), (0.3, 0.0), (1.0, 0.5)])
def test_voxel_rate_maps_match_numpy(flight, side, quantile):
    rates = gaussian_population(flight, 30, np.random.default_rng(1))
    centers, maps, counts = A.voxel_rate_maps(flight, rates, voxel=side, volume=VOLUME, quantile=quantile)
    c2, means, n2 = numpy_voxel_means(flight, rates, side, VOLUME)
    np.testing.assert_allclose(centers, c2, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(counts, n2)
    np.testing.assert_allclose(maps, numpy_rate_maps(means, quantile), rtol=0, atol=1e-12)


def test_voxels_on_faces_and_outside_the_volume():
    vol = (0.0, 1.0, 0.0, 1.0, 0.0, 1.0)
    # A lower face starts a voxel; the box's far faces belong to its last voxels; outside: no voxel.
    p = np.array([[0.0, 0.0, 0.0], [0.5, 0.5, 0.5], [1.0, 1.0, 1.0], [0.25, 0.75, 0.5], [1.2, 0.5, 0.5],
                  [-0.01, 0.5, 0.5]])
    centers, maps, counts = A.voxel_rate_maps(p, np.arange(6.0), voxel=0.5, volume=vol, quantile=0.0)
    c2, means, n2 = numpy_voxel_means(p, np.arange(6.0)[:, None], 0.5, vol)
    np.testing.assert_allclose(centers, c2, rtol=0, atol=0)
    np.testing.assert_array_equal(counts, n2)
    assert counts.sum() == 4
    np.testing.assert_allclose(centers, [[0.25, 0.25, 0.25], [0.25, 0.75, 0.75], [0.75, 0.75, 0.75]])


def test_voxels_without_a_volume_start_at_the_positions_minimum(flight):
    rates = gaussian_population(flight, 5, np.random.default_rng(2))
    centers, _, counts = A.voxel_rate_maps(flight, rates, voxel=0.5)
    box = (flight[:, 0].min(), flight[:, 0].max() + 1, flight[:, 1].min(), flight[:, 1].max() + 1,
           flight[:, 2].min(), flight[:, 2].max() + 1)  # a box from the minimum, wide enough
    c2, _, n2 = numpy_voxel_means(flight, rates, 0.5, box)
    np.testing.assert_allclose(centers, c2, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(counts, n2)


# ---------------------------------------------------------------------------------------------
# modality: DBSCAN in 3-D


@pytest.mark.parametrize("min_samples", [1, 5, 10, 20])
def test_dbscan_labels_are_sklearns_on_3d_points(min_samples):
    rng = np.random.default_rng(min_samples)
    blobs = [rng.normal(c, 0.6, (80, 3)) for c in ([0, 0, 0], [4, 1, 1], [1, 5, 2])]
    pts = np.vstack(blobs + [rng.uniform(-3, 8, (60, 3))])
    ours = A.dbscan_labels(pts, eps=1.0, min_samples=min_samples)
    np.testing.assert_array_equal(ours, DBSCAN(eps=1.0, min_samples=min_samples).fit(pts).labels_)


def test_dbscan_on_a_voxel_lattice_at_exactly_eps():
    # 0.5 m voxel centers: neighbours at exactly 1.0 m are within eps (scikit-learn's <=).
    g = np.stack(np.meshgrid(*[np.arange(6) * 0.5] * 3, indexing="ij"), -1).reshape(-1, 3) + 0.25
    keep = np.random.default_rng(3).random(len(g)) < 0.6
    for ms in (5, 10, 20, 33, 34):
        ours = A.dbscan_labels(g[keep], eps=1.0, min_samples=ms)
        np.testing.assert_array_equal(ours, DBSCAN(eps=1.0, min_samples=ms).fit(g[keep]).labels_)


def test_modality_of_3d_fields_counts_sklearns_clusters(flight):
    rates = gaussian_population(flight, 40, np.random.default_rng(5))
    r = A.analyze3d(flight, rates, volume=VOLUME)
    for c in range(40):
        active = r["maps"][:, c] > 0
        labels = DBSCAN(eps=1.0, min_samples=10).fit(r["centers"][active]).labels_ if active.any() else []
        assert r["modality"][c] == len(set(labels) - {-1}), c


# ---------------------------------------------------------------------------------------------
# isotropy


def weighted_isotropy(points, w):
    mean = (w[:, None] * points).sum(0) / w.sum()
    sd = np.sqrt((w[:, None] * (points - mean) ** 2).sum(0) / w.sum())
    return sd[2] / (0.5 * (sd[0] + sd[1]))


def ellipsoid_map(sx, sy, sz, side=0.25, extent=4.0):
    """A Gaussian field with these sds on a dense lattice of voxel centers, cut at 5 % of its peak."""
    axis = np.arange(-extent, extent + 1e-9, side)
    g = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), -1).reshape(-1, 3)
    v = np.exp(-0.5 * ((g[:, 0] / sx) ** 2 + (g[:, 1] / sy) ** 2 + (g[:, 2] / sz) ** 2))
    v[v < 0.05] = 0
    return g, v


@pytest.mark.parametrize("sds,expected", [((0.6, 0.6, 0.6), 1.0), ((0.5, 0.5, 1.0), 2.0), ((0.8, 0.8, 0.4), 0.5),
                                          ((0.4, 0.8, 0.6), 1.0)])
def test_isotropy_of_ellipsoidal_fields(sds, expected):
    centers, v = ellipsoid_map(*sds)
    iso = A.isotropy(centers, v[:, None], [1], eps=1.0, min_samples=10)
    active = v > 0
    # Exactly the weighted sds of the field's voxels (numpy) ...
    assert iso[0] == pytest.approx(weighted_isotropy(centers[active], v[active]), rel=1e-12)
    # ... and, for these smooth fields cut at the same level on every axis, the ratio of their sds.
    assert iso[0] == pytest.approx(expected, rel=0.02)


def test_isotropy_leaves_out_noise_voxels_and_other_cells():
    centers, v = ellipsoid_map(0.5, 0.5, 1.0)
    # A lone far voxel with a high rate is DBSCAN noise: not part of the field.
    centers = np.vstack([centers, [[3.9, 3.9, 3.9]]])
    v = np.append(v, 1.0)
    v[(np.abs(centers - [3.9, 3.9, 3.9]).max(1) > 0) & (np.linalg.norm(centers - [3.9, 3.9, 3.9], axis=1) < 1.1)] = 0
    maps = np.column_stack([v, v, np.zeros_like(v)])
    iso = A.isotropy(centers, maps, [1, 2, 0], eps=1.0, min_samples=10)
    field = (v > 0) & (np.linalg.norm(centers - [3.9, 3.9, 3.9], axis=1) > 0)
    assert iso[0] == pytest.approx(weighted_isotropy(centers[field], v[field]), rel=1e-12)
    assert np.isnan(iso[1]) and np.isnan(iso[2])


# ---------------------------------------------------------------------------------------------
# decoding, aliasing and the whole 3-D analysis


def dense_decoder3(p, rates, volume, quantile=0.1, side=0.5):
    """The reference decoder in plain numpy: first-half voxel templates (rate maps), cosine argmax
    for each second-half sample; the errors and their horizontal and vertical parts."""
    half = len(p) // 2
    centers, means, counts = numpy_voxel_means(p[:half], rates[:half], side, volume)
    tmpl = numpy_rate_maps(means, quantile)
    norms = np.linalg.norm(tmpl, axis=1, keepdims=True)
    unit = np.divide(tmpl, norms, out=np.zeros_like(tmpl), where=norms > 0)
    scores = rates[half:].astype(np.float64) @ unit.T
    best, ok = scores.argmax(axis=1), scores.max(axis=1) > 0
    d = (p[half:] - centers[best])[ok]
    horizontal, vertical = np.hypot(d[:, 0], d[:, 1]), np.abs(d[:, 2])
    # chance: every (second-half sample, first-half voxel) pair weighted by the voxel's samples
    err = np.abs(p[half:, 2][:, None] - centers[None, :, 2]).ravel()
    w = np.broadcast_to(counts[None, :], (len(p) - half, len(counts))).ravel().astype(float)
    order = np.argsort(err, kind="stable")
    cum = np.cumsum(w[order])
    chance = err[order][np.searchsorted(cum, 0.5 * w.sum())]
    return np.hypot(horizontal, vertical), horizontal, vertical, chance


def sai_brute3(centers, maps, d_th):
    n = len(centers)
    norms = np.linalg.norm(maps, axis=1)
    sai = np.zeros(n)
    for i in range(n):
        far = (np.linalg.norm(centers - centers[i], axis=1) > d_th) & (np.arange(n) != i) & (norms > 0)
        if norms[i] > 0:
            sai[i] = np.sum(maps[far] @ maps[i] / (norms[far] * norms[i]))
    return sai / n


def test_analyze3d_decoding_and_aliasing_match_numpy(flight):
    rng = np.random.default_rng(8)
    rates = gaussian_population(flight, 60, rng, sigma=(0.6, 0.6, 0.6))
    rates += np.float32(1e-3) * rng.random(rates.shape, dtype=np.float32)  # no ties in the argmax
    r = A.analyze3d(flight, rates, volume=VOLUME)
    total, horizontal, vertical, chance = dense_decoder3(flight, rates, VOLUME)
    d = r["decoding"]
    assert d["median_m"] == pytest.approx(np.median(total), abs=1e-9)
    assert d["median_horizontal_m"] == pytest.approx(np.median(horizontal), abs=1e-9)
    assert d["mean_horizontal_m"] == pytest.approx(horizontal.mean(), abs=1e-9)
    assert d["median_vertical_m"] == pytest.approx(np.median(vertical), abs=1e-9)
    assert d["mean_vertical_m"] == pytest.approx(vertical.mean(), abs=1e-9)
    assert d["median_vertical_chance_m"] == pytest.approx(chance, abs=1e-12)
    # Gaussian fields localize: far better than chance along z.
    assert d["median_vertical_m"] < 0.5 * d["median_vertical_chance_m"]
    np.testing.assert_allclose(r["sai"], sai_brute3(r["centers"], r["maps"], 2.0), rtol=0, atol=1e-12)
    assert r["metrics"]["decode_vertical_median_m"] == d["median_vertical_m"]
    assert r["metrics"]["frac_unimodal"] == pytest.approx(np.mean(r["modality"] == 1))
    iso = r["isotropy"][r["modality"] == 1]
    assert r["metrics"]["isotropy_median"] == pytest.approx(np.median(iso[~np.isnan(iso)]))
    # Round fields (the same sd on every axis) read a little below 1 in a room 2.3 m high: floor and
    # ceiling cut the fields near them along z only.
    assert 0.55 < r["metrics"]["isotropy_median"] < 1.0


def test_columns_that_ignore_height_have_high_isotropy_and_no_vertical_decoding(flight):
    # Cells tuned to x, y only (what upward-only layers could give at worst): columns, and a
    # vertical error no better than chance.
    rng = np.random.default_rng(9)
    rates = gaussian_population(flight, 60, rng, sigma=(0.5, 0.5, 1e9))
    rates += np.float32(1e-3) * rng.random(rates.shape, dtype=np.float32)
    r = A.analyze3d(flight, rates, volume=VOLUME)
    assert r["metrics"]["isotropy_median"] > 1.2  # the round fields of the test above: < 1
    assert r["decoding"]["median_vertical_m"] > 0.6 * r["decoding"]["median_vertical_chance_m"]


# ---------------------------------------------------------------------------------------------
# the flying walk and flying trials from Python


def test_flying_walk_is_seeded_and_stays_in_the_volume():
    world = bvc3d.World.preset("flight-room")
    a, b = bvc3d.flying_walk(world, 0.2, 7), bvc3d.flying_walk(world, 0.2, 7)
    for k in ("t", "x", "y", "z", "heading"):
        np.testing.assert_array_equal(a[k], b[k])
    assert not np.array_equal(a["x"], bvc3d.flying_walk(world, 0.2, 8)["x"])
    v = world.flight_volume
    assert v["z_min"] == pytest.approx(0.2) and v["z_max"] == pytest.approx(2.5)
    r = 0.2
    assert a["z"].min() >= v["z_min"] + r - 1e-9 and a["z"].max() <= v["z_max"] - r + 1e-9
    assert np.abs(a["x"]).max() <= 2.9 - r + 1e-9 and np.abs(a["y"]).max() <= 2.3 - r + 1e-9
    # It flies: the height changes by the pitch of flight (up to ±60°, 0.288 m per step).
    dz = np.diff(a["z"])
    assert np.abs(dz).max() <= 0.288 * np.sin(np.pi / 3) + 1e-9 and np.ptp(a["z"]) > 1.5
    # A bigger body keeps further from the walls.
    big = bvc3d.flying_walk(world, 0.2, 7, radius=0.5)
    assert big["z"].min() >= 0.7 - 1e-9


def test_flying_trial_reports_3d_metrics_and_errors_for_mismatches():
    r = bvc3d.run_trial(model="fly-5l", world="flight-room", agent="flight", explore_hours=0.05, sample_hours=0.05,
                        seed=2)
    assert {"frac_unimodal", "isotropy_median", "decode_vertical_median_m"} <= set(r["metrics"])
    assert len(r["z"]) == len(r["x"]) and np.ptp(r["z"]) > 0.5
    with pytest.raises(bvc3d.InputError, match="no flight volume"):
        bvc3d.run_trial(model="fly-5l", world=str(SOURCE_DIR / "configs" / "worlds" / "two-rooms.yaml"), agent="flight",
                        explore_hours=0.01, sample_hours=0.01)
    with pytest.raises(bvc3d.InputError, match="preset for the ground robot"):
        bvc3d.run_trial(model="3d-0.2", world="flight-room", agent="flight", explore_hours=0.01, sample_hours=0.01)
    with pytest.raises(bvc3d.InputError, match="flight-only world"):
        bvc3d.run_trial(model="2d", world="flight-room", explore_hours=0.01, sample_hours=0.01)


# ---------------------------------------------------------------------------------------------
# bvc3d flight: trial files with z and a format version, summary, figures


def check_flight_tables_script(folder, out):
    """scripts/flight_tables.py (the tables of docs/flying.md) against the trial files read directly:
    stored metrics, the share of column fields, and the field pairs of multimodal cells by sklearn."""
    import csv
    import os
    import subprocess
    import sys

    import h5py

    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.dirname(os.path.dirname(bvc3d.__file__))] + sys.path))
    subprocess.run([sys.executable, str(SOURCE_DIR / "scripts" / "flight_tables.py"), str(folder), str(out)],
                   check=True, env=env, capture_output=True, text=True)
    rows = {(r["model"], int(r["seed"])): r for r in csv.DictReader(open(out / "trials.csv"))}
    stacked = {(r["model"], int(r["seed"])): r for r in csv.DictReader(open(out / "stacked.csv"))}
    assert set(rows) == {("fly-up", 0), ("fly-5l", 0)}
    for (model, seed), row in rows.items():
        with h5py.File(folder / f"flight-room_{model}_seed{seed}.h5", "r") as f:
            m = f["metrics"].attrs
            for key in ("frac_unimodal", "frac_multimodal", "isotropy_median", "frac_undecoded"):
                assert float(row[key]) == pytest.approx(float(m[key]), rel=1e-12, nan_ok=True)
            iso = f["metrics/isotropy"][:]
            iso = iso[np.isfinite(iso)]
            assert int(row["single_fields"]) == len(iso)
            if len(iso):
                assert float(row["frac_columns"]) == pytest.approx(np.count_nonzero(iso > 1.5) / len(iso))
            c, maps, mi = f["metrics/bin_centers"][:], f["metrics/rate_maps"][:], f["metrics/modality"][:]
        pairs = 0
        for k in np.flatnonzero(mi > 1):
            n = len(set(DBSCAN(eps=1.0, min_samples=10).fit(c[maps[:, k] > 0]).labels_) - {-1})
            pairs += n * (n - 1) // 2
        assert int(stacked[(model, seed)]["pairs"]) == pairs


def test_flight_command_writes_3d_trials_summary_and_figures(tmp_path):
    import h5py

    from conftest import run_cli
    out = tmp_path / "flight"
    run_cli("flight", "--out", out, "--models", "fly-up,fly-5l", "--worlds", "flight-room", "--seeds", "1",
            "--hours", "0.03", "--jobs", "1", check=True)
    with h5py.File(out / "flight-room_fly-5l_seed0.h5", "r") as f:
        assert f.attrs["format_version"] == 2
        z, centers = f["samples/z"][:], f["metrics/bin_centers"][:]
        assert centers.shape[1] == 3 and np.ptp(z) > 0.5
        np.testing.assert_allclose(f["metrics/volume"][:], VOLUME)
        iso = f["metrics/isotropy"][:]
        assert np.array_equal(np.isnan(iso), f["metrics/modality"][:] != 1)
    summary = (out / "summary.md").read_text()
    assert "isotropy (median)" in summary and "decoding vertical (m)" in summary
    figures = {p.name for p in (out / "figures").iterdir()}
    assert {"worlds.png", "trajectory3d.png", "isotropy.png", "decoding_vertical.png", "frac_unimodal.png"} <= figures
    assert "decoding_vertical.png" in (out / "report.md").read_text()
    check_flight_tables_script(out, tmp_path / "tables")
    # A file of a format version this bvc3d does not know is refused by name, not misread.
    newer = out / "flight-room_fly-up_seed0.h5"
    with h5py.File(newer, "r+") as f:
        f.attrs["format_version"] = 3
    r = run_cli("analyze", newer)
    assert r.returncode == 2 and "format_version 3" in r.stderr and str(newer) in r.stderr
    r = run_cli("flight", "--out", out, "--models", "fly-up", "--worlds", "flight-room", "--seeds", "1",
                "--hours", "0.03", "--jobs", "1")
    assert r.returncode == 2 and "format_version 3" in r.stderr


def test_flight_command_refuses_ground_models_and_worlds(tmp_path):
    from conftest import run_cli
    r = run_cli("flight", "--out", tmp_path / "a", "--models", "3d-0.2", "--worlds", "flight-room", "--hours", "0.01")
    assert r.returncode == 2 and "preset for the ground robot" in r.stderr
    world = SOURCE_DIR / "configs" / "worlds" / "two-rooms.yaml"
    r = run_cli("flight", "--out", tmp_path / "b", "--models", "fly-up", "--worlds", world, "--hours", "0.01")
    assert r.returncode == 2 and "no flight volume" in r.stderr
    assert not (tmp_path / "a").exists() or not any((tmp_path / "a").glob("*.h5"))


def test_two_flights_into_one_folder_the_second_refuses(tmp_path):
    """`bvc3d flight` takes the output folder's lock as `paper` does: a second run into the folder of a
    running one stops at once (status 2) naming the lock and its holder, and writes nothing."""
    import subprocess
    import time

    from conftest import CLI, run_cli
    out = tmp_path / "flight"
    args = ["flight", "--out", out, "--models", "fly-up", "--worlds", "flight-room", "--hours", "1", "--no-report"]
    first = subprocess.Popen([CLI, *map(str, args)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        lock = out / ".bvc3d.lock"
        for _ in range(400):
            if lock.exists() and lock.read_text():
                break
            time.sleep(0.05)
        assert lock.exists(), "the first flight took no lock"
        second = run_cli(*args)
        assert second.returncode == 2, second.stderr
        assert (f"bvc3d: error: output folder '{out}' is in use by bvc3d process {first.pid}" in second.stderr
                and f"lock file '{lock}'" in second.stderr), second.stderr
        assert first.poll() is None and not list(out.glob("*.h5"))  # the first one runs on, alone
    finally:
        first.kill()
        first.wait()


def test_flight_memory_check_and_no_memory_check(tmp_path):
    """A flight too long for the machine's memory is refused before it starts, and says how to go on
    anyway; `--no-memory-check` is accepted as by the other experiments."""
    from conftest import run_cli
    base = ["flight", "--models", "fly-up", "--worlds", "flight-room", "--no-report"]
    big = run_cli(*base, "--out", tmp_path / "big", "--explore-hours", "0", "--sample-hours", "9000")
    assert big.returncode == 2 and "needs about" in big.stderr and "--no-memory-check" in big.stderr, big.stderr
    assert not (tmp_path / "big").exists()  # refused before anything was written
    small = run_cli(*base, "--out", tmp_path / "small", "--hours", "0.01", "--jobs", "1", "--no-memory-check")
    assert small.returncode == 0, small.stderr
    assert (tmp_path / "small" / "flight-room_fly-up_seed0.h5").exists()


def test_the_flying_protocol_is_one_for_the_command_and_python():
    """`bvc3d flight` and run_trial(agent="flight") state the same default protocol, from one table."""
    import re

    from conftest import run_cli
    help_text = run_cli("flight", "--help", check=True).stdout
    command = re.search(r"--hours FLOAT +Both phases this many simulated hours \(default (\d+) \+ (\d+)\)", help_text)
    python = re.search(r"a world with a flight volume, (\d+) \+ (\d+) h unless given", bvc3d.run_trial.__doc__)
    assert command and python and command.groups() == python.groups() == ("8", "8")


def test_flight_tables_field_pairs_of_a_stacked_cell():
    """A cell with two round fields, one above the other (4 m apart in z, 0.5 m in x): the script's
    field pairs give the distances between the fields' weighted centroids."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("flight_tables", SOURCE_DIR / "scripts" / "flight_tables.py")
    ft = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ft)
    g = np.arange(-2.25, 2.26, 0.5)
    zs = np.arange(0.25, 5.8, 0.5)
    centers = np.array([(x, y, z) for x in g for y in g for z in zs])
    lower, upper = np.array([0.25, -0.25, 0.75]), np.array([-0.25, -0.25, 4.75])
    rate = sum(np.exp(-np.sum((centers - c) ** 2, axis=1) / (2 * 0.6 ** 2)) for c in (lower, upper))
    maps = np.where(rate > 0.05, rate, 0.0)[:, None]
    pairs = ft.field_pairs(centers, maps, np.array([2]), eps=1.0, min_samples=10)
    assert pairs.shape == (1, 4)
    on = maps[:, 0] > 0
    lab = DBSCAN(eps=1.0, min_samples=10).fit(centers[on]).labels_
    cents = sorted((np.average(centers[on][lab == k], axis=0, weights=maps[on, 0][lab == k]) for k in (0, 1)),
                   key=lambda q: q[2])
    np.testing.assert_allclose(pairs[0], [np.hypot(*(cents[1][:2] - cents[0][:2])), cents[1][2] - cents[0][2],
                                          cents[0][2], cents[1][2]], rtol=1e-12)
    assert pairs[0, 0] == pytest.approx(0.5, abs=0.1) and pairs[0, 1] == pytest.approx(4.0, abs=0.15)
