"""Place recognition (issue 28, SPEC §15): Scan Context against a numpy transcription of SPEC §15 on
hand-made clouds; the protocol's precision, recall, AUC and F1max against scikit-learn; recall@1 and the
exclusion window on toy sequences whose answer is known (and against the protocol written out in numpy);
the heading variants; the KITTI-BEV conversion against its README's rule; the command and the Python
function giving the same tables."""
import csv
import importlib.util
import math

import numpy as np
import pytest
from sklearn.metrics import auc, precision_recall_curve

import bvc3d
from conftest import SOURCE_DIR, run_cli

KITTI = SOURCE_DIR.parent / "shared" / "data" / "kitti-bev"
needs_kitti = pytest.mark.skipif(not (KITTI / "00" / "pose.txt").exists(),
                                 reason=f"the KITTI-BEV data set is not at {KITTI}")


# ------------------------------------------------------------------- Scan Context: numpy transcription

def sc_numpy(points, rings=20, sectors=60, max_radius=80.0, lidar_height=2.0):
    """SPEC §15's Scan Context written out: ring ⌈ρ/Δρ⌉ and sector ⌈α/Δα⌉ (from 1, clamped), the largest
    z + lidar_height of a bin's points, 0 when empty."""
    p = np.asarray(points, dtype=float)
    rho = np.hypot(p[:, 0], p[:, 1])
    alpha = np.degrees(np.arctan2(p[:, 1], p[:, 0]))
    alpha = np.where(alpha < 0, alpha + 360, alpha)
    keep = rho <= max_radius
    ring = np.clip(np.ceil(rho / (max_radius / rings)), 1, rings).astype(int) - 1
    sector = np.clip(np.ceil(alpha / (360 / sectors)), 1, sectors).astype(int) - 1
    bins = np.full((rings, sectors), -np.inf)
    np.maximum.at(bins, (ring[keep], sector[keep]), p[keep, 2] + lidar_height)
    bins[np.isinf(bins)] = 0
    return bins


def sc_distance_numpy(a, b):
    """The mean over sectors non-empty in both of 1 - cos(a[:, c + s], b[:, c]), minimised over s."""
    best = (math.inf, 0)
    for s in range(a.shape[1]):
        turned = np.roll(a, -s, axis=1)  # turned[:, c] = a[:, (c + s) % S]
        na, nb = np.linalg.norm(turned, axis=0), np.linalg.norm(b, axis=0)
        both = (na > 0) & (nb > 0)
        cos = (turned * b).sum(axis=0)[both] / (na[both] * nb[both])
        d = float(np.mean(1 - cos)) if both.any() else 1.0
        if d < best[0]:
            best = (d, s)
    return best


def cloud(rng, n, sectors_used, rings=20, sectors=60, max_radius=80.0):
    """Points well inside their bins (no point near a bin's edge, where rounding could move it), in the
    given sectors, each bin holding several points at different heights."""
    sector = rng.choice(sectors_used, n)
    ring = rng.integers(0, rings, n)
    alpha = np.radians((sector + rng.uniform(0.2, 0.8, n)) * 360 / sectors)
    rho = (ring + rng.uniform(0.2, 0.8, n)) * max_radius / rings
    z = rng.uniform(-1.5, 8.0, n)
    return np.column_stack([rho * np.cos(alpha), rho * np.sin(alpha), z])


def turn(points, degrees):
    a = math.radians(degrees)
    r = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])
    return points @ r.T


@pytest.mark.parametrize("seed", range(4))
def test_scan_context_bins_are_the_numpy_transcription(seed):
    rng = np.random.default_rng(seed)
    p = np.vstack([cloud(rng, 3000, np.arange(60)), rng.uniform(-120, 120, (500, 3))])  # some beyond 80 m
    sc = bvc3d.scan_context(p)
    np.testing.assert_array_equal(sc["bins"], sc_numpy(p))
    np.testing.assert_allclose(sc["ring_key"], sc_numpy(p).mean(axis=1), rtol=1e-12)
    # Other sizes read the same rule.
    np.testing.assert_array_equal(bvc3d.scan_context(p, rings=7, sectors=13, max_radius=30, lidar_height=0)["bins"],
                                  sc_numpy(p, 7, 13, 30, 0))


@pytest.mark.parametrize("k", [0, 1, 7, 30, 59])
def test_a_turned_copy_matches_with_the_right_shift(k):
    rng = np.random.default_rng(k)
    a = cloud(rng, 2000, rng.choice(60, 40, replace=False))
    b = turn(a, 6.0 * k)  # k whole sectors counter-clockwise
    sa, sb = bvc3d.scan_context(a)["bins"], bvc3d.scan_context(b)["bins"]
    np.testing.assert_array_equal(sb, np.roll(sa, k, axis=1))
    d, shift = bvc3d.scan_context_distance(sb, sa)  # sb[:, c + shift] = sa[:, c]
    assert shift == k and d < 1e-12
    assert bvc3d.scan_context_distance(sa, sb) == pytest.approx((0.0, (60 - k) % 60), abs=1e-12)


@pytest.mark.parametrize("seed", range(6))
def test_distances_of_unrelated_clouds_are_the_numpy_transcription(seed):
    rng = np.random.default_rng(100 + seed)
    a = sc_numpy(cloud(rng, 400, rng.choice(60, 30, replace=False)))
    b = sc_numpy(cloud(rng, 400, rng.choice(60, 30, replace=False)))
    d, shift = bvc3d.scan_context_distance(a, b)
    dn, sn = sc_distance_numpy(a, b)
    assert shift == sn and d == pytest.approx(dn, abs=1e-12)


def test_a_sector_empty_in_either_is_skipped():
    rng = np.random.default_rng(5)
    a = sc_numpy(cloud(rng, 500, np.arange(0, 30)))
    b = a.copy()
    b[:, 40] = rng.uniform(1, 5, 20)  # filled in b, empty in a: not compared
    b[:, 3] = 0                       # empty in b, filled in a: not compared
    d, shift = bvc3d.scan_context_distance(a, b)
    assert shift == 0 and d < 1e-12
    # One shared sector made to differ: its 1 - cos over the sectors filled in both (a's 30), no other.
    c = a.copy()
    c[:, 5] = rng.uniform(1, 5, 20) * (a[:, 5] > 0)
    d, shift = bvc3d.scan_context_distance(a, c)
    expect = (1 - a[:, 5] @ c[:, 5] / (np.linalg.norm(a[:, 5]) * np.linalg.norm(c[:, 5]))) / 30
    assert np.count_nonzero(np.linalg.norm(a, axis=0)) == 30
    assert shift == 0 and d == pytest.approx(expect, abs=1e-12) and d == pytest.approx(sc_distance_numpy(a, c)[0])
    # Nothing shared at any shift: 1, as for an all-zero rate vector.
    assert bvc3d.scan_context_distance(a, np.zeros_like(a)) == (1.0, 0)


# ------------------------------------------------------------------- metrics against scikit-learn

def score_lists():
    rng = np.random.default_rng(7)
    lists = []
    for n, ties in [(12, False), (200, False), (300, True), (50, True)]:
        d = rng.uniform(0, 1, n)
        if ties:
            d = np.round(d * 10) / 10  # many equal distances
        has_revisit = rng.uniform(size=n) < 0.6
        correct = has_revisit & (rng.uniform(size=n) < 0.7 - 0.5 * d)  # right matches tend to be near
        lists.append((d, correct, has_revisit))
    d = np.array([0.1, 0.2, 0.3, 0.4, 0.5])  # by hand: thresholds 0.1 ... 0.5
    lists.append((d, np.array([1, 0, 1, 0, 0], bool), np.array([1, 1, 1, 0, 1], bool)))
    return lists


@pytest.mark.parametrize("case", range(5))
def test_precision_recall_auc_f1_are_scikit_learns(case):
    d, correct, has_revisit = score_lists()[case]
    r = bvc3d.analysis.precision_recall(d, correct, has_revisit)
    precision, recall, thresholds = precision_recall_curve(correct, -d)
    # scikit-learn's recall divides by the right matches; the protocol's by the revisits.
    scale = correct.sum() / has_revisit.sum()
    np.testing.assert_allclose(r["precision"], precision, rtol=0, atol=1e-15)
    np.testing.assert_allclose(r["recall"], recall * scale, rtol=1e-15, atol=1e-15)
    np.testing.assert_array_equal(r["threshold"][:-1], -thresholds)
    assert r["auc"] == pytest.approx(auc(recall * scale, precision), abs=1e-12)
    p, q = precision, recall * scale
    f1 = np.where(p + q > 0, 2 * p * q / np.where(p + q > 0, p + q, 1), 0)
    assert r["f1_max"] == pytest.approx(f1.max(), abs=1e-12)
    assert r["recall_at_1"] == correct.sum() / has_revisit.sum()
    assert (r["queries"], r["revisits"], r["n_correct"]) == (len(d), has_revisit.sum(), correct.sum())
    if case == 4:  # by hand: at 0.1 P 1 R 1/4, at 0.3 P 2/3 R 1/2, at 0.5 P 2/5 R 1/2
        np.testing.assert_allclose(r["precision"], [2 / 5, 2 / 4, 2 / 3, 1 / 2, 1, 1])
        np.testing.assert_allclose(r["recall"], [1 / 2, 1 / 2, 1 / 2, 1 / 4, 1 / 4, 0])
        assert r["f1_max"] == pytest.approx(max(2 * (2 / 3) * 0.5 / (2 / 3 + 0.5), 2 * 0.25 / 1.25))


def test_metrics_without_revisits_are_undefined():
    r = bvc3d.analysis.precision_recall([0.2, 0.4], [False, False], [False, False])
    assert math.isnan(r["recall_at_1"]) and math.isnan(r["f1_max"]) and math.isnan(r["auc"])
    with pytest.raises(ValueError, match="correct without a revisit"):
        bvc3d.analysis.precision_recall([0.2], [True], [False])


# ------------------------------------------------------------------- the protocol on toy sequences

def protocol_numpy(rates, xy, times, exclude_scans, exclude_seconds, revisit_m):
    """SPEC §15's sequential protocol written out: candidates older than both windows, the most
    cosine-similar (first maximum), a revisit when a candidate lies within revisit_m."""
    unit = rates / np.maximum(np.linalg.norm(rates, axis=1, keepdims=True), 1e-300)
    rows = []
    for i in range(len(rates)):
        j = np.arange(i)
        ok = (i - j > exclude_scans) & ((times[i] - times[j] > exclude_seconds) if times is not None else True)
        j = j[ok]
        if len(j) == 0:
            continue
        cos = unit[j] @ unit[i]
        m = j[np.argmax(cos)]
        dist = np.hypot(*(xy[j] - xy[i]).T)
        match_m = math.hypot(*(xy[m] - xy[i]))
        rows.append((i, m, 1 - cos.max(), match_m, bool((dist <= revisit_m).any()), match_m <= revisit_m))
    return rows


def out_and_back(n=100, sigma=1.5):
    """Scans 0..n-1 drive x = 0..n-1 m, scans n..2n-1 drive back (x = 2n-1-i); a scan's descriptor is a
    bump over cells placed every 2 m of x, so the best match is the nearest older scan."""
    i = np.arange(2 * n)
    x = np.where(i < n, i, 2 * n - 1 - i).astype(float)
    centres = np.arange(0, n, 2.0)
    rates = np.exp(-0.5 * ((x[:, None] - centres[None]) / sigma) ** 2).astype(np.float32)
    return rates, np.column_stack([x, np.zeros_like(x)]), i.astype(float)


def test_recall_at_1_and_the_exclusion_window_on_a_known_sequence():
    rates, xy, t = out_and_back()
    r = bvc3d.analysis.loop_closure(rates, xy, t)  # 50 scans and 30 s (1 scan a second): 50 scans
    # By hand: scan i queries scans j <= i - 51; on the way out nothing within 5 m is that old; on the
    # way back scan i (x = 199 - i) has scan 194 - i ... i - 51 within 5 m from i = 123 on.
    assert r["protocol"] == "sequential"
    np.testing.assert_array_equal(r["query"], np.arange(51, 200))
    np.testing.assert_array_equal(np.nonzero(r["has_revisit"])[0] + 51, np.arange(123, 200))
    assert (r["queries"], r["revisits"], r["n_correct"], r["recall_at_1"]) == (149, 77, 77, 1.0)
    # Where the query's own place is old enough (i >= 125), the match is exactly it.
    back = r["query"] >= 125
    np.testing.assert_array_equal(r["match"][back], 199 - r["query"][back])
    assert np.all(r["match_m"][back] == 0) and r["median_match_m"] == 0
    # A longer time window (80 s) leaves the revisits from i = 138 on; the scan window alone (no times) 51.
    r = bvc3d.analysis.loop_closure(rates, xy, t, exclude_seconds=80)
    np.testing.assert_array_equal(r["query"], np.arange(81, 200))
    assert r["revisits"] == 62 and r["recall_at_1"] == 1
    r = bvc3d.analysis.loop_closure(rates, xy, None, exclude_scans=10, exclude_seconds=1e6)
    np.testing.assert_array_equal(r["query"], np.arange(11, 200))
    # The split: every query (the way back) has a database scan (the way out) at its own x.
    r = bvc3d.analysis.loop_closure(rates, xy, database=(0, 99), queries=(100, 199))
    assert r["protocol"] == "split" and (r["queries"], r["revisits"], r["recall_at_1"]) == (100, 100, 1.0)
    np.testing.assert_array_equal(r["match"], 199 - np.arange(100, 200))


def test_a_match_at_exactly_the_revisit_radius_is_right():
    xy = np.array([[0, 0]] + [[1000 + 10 * k, 0] for k in range(60)] + [[3, 4], [3, 4.000001]], float)
    rates = np.zeros((len(xy), 4), np.float32)
    rates[:, 0] = 1  # every scan alike: the oldest candidate wins the tie
    r = bvc3d.analysis.loop_closure(rates, xy, exclude_scans=5)
    assert list(r["query"][-2:]) == [61, 62] and list(r["match"][-2:]) == [0, 0]
    assert list(r["match_m"][-2:]) == [5.0, pytest.approx(5.0000008)]
    assert list(r["has_revisit"][-2:]) == [True, False] and list(r["correct"][-2:]) == [True, False]


@pytest.mark.parametrize("seed", range(3))
def test_the_protocol_is_the_numpy_transcription(seed):
    rng = np.random.default_rng(seed)
    n = 400
    xy = np.cumsum(rng.normal(0, 1.5, (n, 2)), axis=0)
    xy[250:] = xy[50:200][::-1][: n - 250] + rng.normal(0, 1, (n - 250, 2))  # a stretch driven again
    rates = rng.uniform(0, 1, (n, 64)).astype(np.float32) * (rng.uniform(size=(n, 64)) < 0.3)
    rates[250:] += 0.8 * rates[50:200][::-1][: n - 250]
    t = np.cumsum(rng.uniform(0.2, 1.5, n))
    r = bvc3d.analysis.loop_closure(rates, xy, t, exclude_scans=30, exclude_seconds=20, revisit_m=4)
    rows = protocol_numpy(rates.astype(np.float64), xy, t, 30, 20, 4)
    np.testing.assert_array_equal(r["query"], [q[0] for q in rows])
    np.testing.assert_array_equal(r["match"], [q[1] for q in rows])
    np.testing.assert_allclose(r["distance"], [q[2] for q in rows], atol=2e-6)
    np.testing.assert_allclose(r["match_m"], [q[3] for q in rows], rtol=1e-12)
    np.testing.assert_array_equal(r["has_revisit"], [q[4] for q in rows])
    np.testing.assert_array_equal(r["correct"], [q[5] for q in rows])
    assert 20 < r["revisits"] < len(rows)


def test_windows_and_splits_that_leave_nothing_are_refused():
    rates, xy, t = out_and_back(20)
    with pytest.raises(ValueError, match="as long as the sequence"):
        bvc3d.analysis.loop_closure(rates, xy, t)  # 40 scans, 50-scan window
    with pytest.raises(ValueError, match="overlaps itself"):
        bvc3d.analysis.loop_closure(rates, xy, database=(0, 20), queries=(20, 39))
    with pytest.raises(ValueError, match="reaches past the last scan"):
        bvc3d.analysis.loop_closure(rates, xy, database=(0, 19), queries=(20, 40))
    with pytest.raises(ValueError, match="empty"):
        bvc3d.analysis.loop_closure(rates, xy, database=(5, 2), queries=(20, 39))


def test_a_turned_query_matches_over_the_bvc_directions():
    """The heading-free match turns a query by s steps: the value of cell (l, k, m) moves to
    (l, (k + s) mod n_dir, m), which is what the BVC layer gives for the scene turned by s·2π/n_dir."""
    layer = bvc3d.BoundaryVectorLayer(elevations=[0.0, 0.2], n_dir=8, n_per_axis=10)
    rng = np.random.default_rng(3)
    returns = np.column_stack([rng.uniform(1, 10, 300), rng.uniform(-np.pi, np.pi, 300), rng.uniform(0, 0.3, 300)])
    base = layer.rates(returns)
    turned = returns.copy()
    turned[:, 1] = np.angle(np.exp(1j * (returns[:, 1] + 3 * 2 * np.pi / 8)))  # the scene turned by 3 steps
    moved = layer.rates(turned)
    np.testing.assert_allclose(moved.reshape(2, 8, 10), np.roll(base.reshape(2, 8, 10), 3, axis=1), atol=1e-6)
    # A sequence whose last scan is the first one turned: the plain match misses it, the turned one finds it.
    others = rng.uniform(0, 0.5, (60, 160))
    rates = np.vstack([base, others, moved]).astype(np.float32)
    xy = np.column_stack([np.r_[0, np.arange(60) * 10 + 100, 0], np.zeros(62)])
    plain = bvc3d.analysis.loop_closure(rates, xy, exclude_scans=5)
    free = bvc3d.analysis.loop_closure(rates, xy, exclude_scans=5, turns=8, turn_size=10)
    assert free["match"][-1] == 0 and free["distance"][-1] < 1e-6
    assert plain["distance"][-1] > 0.05


# ------------------------------------------------------------------- KITTI-BEV conversion

def kitti_bev_module():
    spec = importlib.util.spec_from_file_location("kitti_bev", SOURCE_DIR / "docs" / "place-recognition" /
                                                  "kitti_bev.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@needs_kitti
def test_the_kitti_bev_conversion_is_the_readme_rule(tmp_path):
    """Scans 100 and 110 of sequence 00: the recording's points are the README's pixel centres, and
    placed with their poses they land on each other (README: 85 % within 0.5 m; a transposed rule 14 %)."""
    import matplotlib.image
    kb = kitti_bev_module()
    kb.convert(KITTI / "00", tmp_path / "rec", heights=False, scans=[100, 110])
    rec = bvc3d.Recording.open(tmp_path / "rec" / "scans.txt", tmp_path / "rec" / "poses.txt")
    assert len(rec.poses) == 2 and list(rec.times) == pytest.approx([10.0, 11.0])
    poses = np.loadtxt(KITTI / "00" / "pose.txt")[[100, 110]].reshape(2, 3, 4)
    world = []
    for k, i in enumerate([100, 110]):
        image = np.round(matplotlib.image.imread(str(KITTI / "00" / "imgs" / f"{i:06d}.png")) * 255)
        expect = [((75 - row) * 0.4 + 0.2, (75 - col) * 0.4 + 0.2, 0.0)
                  for row in range(151) for col in range(151) if image[row, col] > 0]
        points = rec.points(k)
        np.testing.assert_allclose(points, expect, atol=1e-6)  # float32 files
        np.testing.assert_allclose(rec.poses[k][:3], poses[k], atol=1e-12)
        world.append(points @ poses[k][:, :3].T + poses[k][:, 3])

    def aligned(a, b):
        d = np.sqrt(((a[:, None, :2] - b[None, :, :2]) ** 2).sum(axis=2)).min(axis=1)
        return np.mean(d <= 0.5)
    assert aligned(world[0], world[1]) > 0.8
    transposed = [rec.points(k)[:, [1, 0, 2]] @ poses[k][:, :3].T + poses[k][:, 3] for k in range(2)]
    assert aligned(transposed[0], transposed[1]) < 0.3
    # The heights variant stands each point on the road at the top of its column.
    kb.convert(KITTI / "00", tmp_path / "high", heights=True, scans=[100])
    high = bvc3d.Recording.open(tmp_path / "high" / "scans.txt", tmp_path / "high" / "poses.txt").points(0)
    np.testing.assert_allclose(high[:, :2], rec.points(0)[:, :2])
    levels = (high[:, 2] + 1.73) / 0.4
    np.testing.assert_allclose(levels, np.round(levels), atol=1e-5)
    assert levels.min() >= 1 - 1e-5 and levels.max() <= 10 + 1e-5


# ------------------------------------------------------------------- the command and the function

def two_laps(tmp_path, turn_second=0.0):
    """Two laps around the cross arena's central walls, the second driven with the heading turned by
    `turn_second` (the robot drives sideways: the same places seen turned)."""
    n = 166  # one lap of 24 m in 0.144 m steps (the last 0.1 m short)
    i = np.arange(n)
    s = i * 0.144
    side = (s // 6.0).astype(int)
    u = s - 6.0 * side - 3.0
    x = np.choose(side, [u, np.full(n, 4.0), -u, np.full(n, -4.0)])
    y = np.choose(side, [np.full(n, -4.0), u, np.full(n, 4.0), -u])
    h = np.choose(side, [0.0, math.pi / 2, math.pi, -math.pi / 2])
    rows = np.column_stack([np.arange(2 * n) * 0.288, np.r_[x, x], np.r_[y, y], np.r_[h, h + turn_second]])
    path = tmp_path / "laps.csv"
    np.savetxt(path, rows, delimiter=",", header="t,x,y,heading", comments="", fmt="%.12g")
    return path, n


def read_table(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_the_command_and_the_function_give_the_same_tables(tmp_path):
    route, n = two_laps(tmp_path)
    descriptors = "bvc:2d,bvc-drift:2d,bvc-free:2d,place-cells:2d,scan-context"
    out = tmp_path / "out"
    run_cli("place-recognition", "--world", "cross", "--route", route, "--sensor", "horizontal", "--descriptors",
            descriptors, "--exclude-seconds", 10, "--out", out, check=True)
    with open(out / "queries.csv") as f:
        assert f.readline().strip() == "descriptor,query,match,distance,match_m,has_revisit,correct"
    with open(out / "summary.csv") as f:
        assert f.readline().strip() == "descriptor,protocol,recall_at_1,f1_max,auc,queries,revisits,timed"
    assert (out / "place-recognition.png").stat().st_size > 10000
    r = bvc3d.place_recognition(world="cross", route=route, sensor="horizontal", descriptors=descriptors,
                                exclude_seconds=10)
    queries, summary = read_table(out / "queries.csv"), read_table(out / "summary.csv")
    assert [q["descriptor"] for q in queries] == r["queries"]["descriptor"]
    np.testing.assert_array_equal([int(q["match"]) for q in queries], r["queries"]["match"])
    np.testing.assert_array_equal([float(q["distance"]) for q in queries], r["queries"]["distance"])
    np.testing.assert_array_equal([q["correct"] == "1" for q in queries], r["queries"]["correct"])
    assert [s["descriptor"] for s in summary] == descriptors.split(",")
    np.testing.assert_array_equal([float(s["recall_at_1"]) for s in summary], r["summary"]["recall_at_1"])
    assert r["summary"]["uses_heading"] == [True, True, False, True, False]
    # Each summary agrees with its queries: revisits from the positions (the second lap's queries, at
    # least 10 s = 35 scans after the place they revisit), recall@1 = right matches / revisits.
    xy = np.column_stack([r["scans"]["x"], r["scans"]["y"]])
    t = np.arange(2 * n) * 0.288
    for k, name in enumerate(descriptors.split(",")):
        mine = np.array(r["queries"]["descriptor"]) == name
        q = r["queries"]["query"][mine]
        revisit = [np.any((np.hypot(*(xy[:i - 50] - xy[i]).T) <= 5) & (t[i] - t[:i - 50] > 10)) for i in q]
        np.testing.assert_array_equal(r["queries"]["has_revisit"][mine], revisit)
        assert r["summary"]["revisits"][k] == sum(revisit) > n - 60
        assert r["summary"]["recall_at_1"][k] == r["queries"]["correct"][mine].sum() / sum(revisit)
    # The BVC rates find most revisits (the rest are matched to look-alike places of the symmetric arena).
    assert r["summary"]["recall_at_1"][0] > 0.75


def test_a_turned_revisit_is_found_without_the_heading(tmp_path):
    """The second lap seen turned by 90° (the robot drives sideways): allocentric BVC rates are the same
    (they read the heading), the heading-free match finds the first lap's scan at its own place by
    turning two of the 8 directions, Scan Context by shifting 15 sectors."""
    route, n = two_laps(tmp_path, turn_second=math.pi / 2)
    r = bvc3d.place_recognition(world="cross", route=route, sensor="horizontal",
                                descriptors="bvc:2d,bvc-free:2d,scan-context", exclude_seconds=10)
    xy = np.column_stack([r["scans"]["x"], r["scans"]["y"]])
    for name in ["bvc:2d", "bvc-free:2d", "scan-context"]:
        mine = np.array(r["queries"]["descriptor"]) == name
        second = r["queries"]["query"][mine] >= n
        match, dist = r["queries"]["match"][mine][second], r["queries"]["distance"][mine][second]
        q = r["queries"]["query"][mine][second]
        assert np.median(dist) < 1e-5, name
        if name == "bvc:2d":  # allocentric: its own place on the first lap
            assert np.mean(match == q - n) > 0.95
        else:
            # Without the heading, a place and its images under the arena's quarter turns look the same:
            # the match is one of them (and often the place itself).
            images = [xy[q] @ np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]])
                      for a in np.arange(4) * math.pi / 2]
            gap = np.min([np.hypot(*(xy[match] - im).T) for im in images], axis=0)
            assert np.mean(gap < 0.2) > 0.95, name
            assert np.mean(match == q - n) > 0.2, name


def test_the_heading_drift_is_a_seeded_random_walk(tmp_path):
    n = 1500
    rows = np.column_stack([np.arange(n) * 2.0, np.full(n, -4.0), np.full(n, -4.0), np.zeros(n)])
    route = tmp_path / "still.csv"
    np.savetxt(route, rows, delimiter=",", header="t,x,y,heading", comments="")
    run = [bvc3d.place_recognition(world="cross", route=route, sensor="horizontal", descriptors="scan-context",
                                   drift_deg_per_sqrt_min=d, seed=s)["scans"]["drift"]
           for d, s in [(3.0, 1), (3.0, 1), (3.0, 2)]]
    np.testing.assert_array_equal(run[0], run[1])
    assert not np.array_equal(run[0], run[2]) and run[0][0] == 0
    # Increments over 2 s are N(0, (3°)²·2/60): standardised, mean 0 and SD 1 within sampling error.
    z = np.diff(run[0]) / (math.radians(3.0) * math.sqrt(2 / 60))
    assert abs(z.mean()) < 4 / math.sqrt(n) and abs(z.std() - 1) < 4 / math.sqrt(2 * n)


def test_bad_requests_are_refused_with_the_reason(tmp_path):
    route, n = two_laps(tmp_path)
    with pytest.raises(ValueError, match="unknown descriptor 'bvc2d'"):
        bvc3d.place_recognition(world="cross", route=route, sensor="horizontal", descriptors="bvc2d")
    with pytest.raises(ValueError, match="needs a model"):
        bvc3d.place_recognition(world="cross", route=route, sensor="horizontal", descriptors="bvc")
    with pytest.raises(ValueError, match="as long as the sequence"):
        bvc3d.place_recognition(world="cross", route=route, sensor="horizontal", exclude_scans=1000)
    with pytest.raises(ValueError, match="overlaps itself"):
        bvc3d.place_recognition(world="cross", route=route, sensor="horizontal", database="0:100",
                                queries="100:200")
    proc = run_cli("place-recognition", "--world", "cross", "--route", route, "--sensor", "horizontal",
                   "--descriptors", "scan-context", "--database", "0:10", "--queries", "5:20", "--out", tmp_path / "x")
    assert proc.returncode == 2 and "overlaps itself" in proc.stderr and not (tmp_path / "x").exists()


def test_a_recording_of_the_route_gives_what_the_route_gives(tmp_path):
    """The route's scans written as a recording (export-scans, float64) and read back: the same queries,
    matches and revisits, distances within float rounding."""
    route, n = two_laps(tmp_path, turn_second=math.pi / 2)
    run_cli("export-scans", "--world", "cross", "--trajectory", route, "--sensor", "horizontal", "--format", "pcd-f8",
            "--out", tmp_path / "rec", check=True)
    descriptors = "bvc:2d,bvc-free:2d,place-cells:2d,scan-context"
    sim = bvc3d.place_recognition(world="cross", route=route, sensor="horizontal", descriptors=descriptors,
                                  exclude_seconds=10)
    rec = bvc3d.place_recognition(tmp_path / "rec" / "scans.txt", tmp_path / "rec" / "poses.txt",
                                  descriptors=descriptors, exclude_seconds=10)
    for key in ["query", "match", "has_revisit", "correct"]:
        np.testing.assert_array_equal(rec["queries"][key], sim["queries"][key], err_msg=key)
    np.testing.assert_allclose(rec["queries"]["distance"], sim["queries"]["distance"], atol=1e-5)
    np.testing.assert_allclose(rec["scans"]["t"], sim["scans"]["t"], atol=1e-9)
    np.testing.assert_allclose(rec["scans"]["heading"], sim["scans"]["heading"], atol=1e-9)
    # A Recording opened beforehand (as any reader of recordings gives one) is the same input.
    opened = bvc3d.Recording.open(tmp_path / "rec" / "scans.txt", tmp_path / "rec" / "poses.txt")
    again = bvc3d.place_recognition(opened, descriptors=descriptors, exclude_seconds=10)
    for key in rec["queries"]:
        np.testing.assert_array_equal(again["queries"][key], rec["queries"][key], err_msg=key)
    with pytest.raises(ValueError, match="carries its poses"):
        bvc3d.place_recognition(opened, tmp_path / "rec" / "poses.txt")


HALL = SOURCE_DIR.parent / "shared" / "data" / "hall-lidar"


@pytest.mark.skipif(not (HALL / "poses.csv").exists(), reason=f"the hall-lidar recording is not at {HALL}")
def test_the_hall_has_no_revisit_in_the_sequential_sense():
    r = bvc3d.place_recognition(HALL, HALL / "poses.csv", descriptors="bvc:2d,scan-context")
    assert list(r["summary"]["queries"]) == [9, 9] and list(r["summary"]["revisits"]) == [0, 0]
    assert all(math.isnan(v) for v in r["summary"]["recall_at_1"])
    np.testing.assert_array_equal(r["queries"]["query"][:9], np.arange(51, 60))
    assert np.all(r["queries"]["match_m"] > 5)


# ------------------------------------------------------------------- the figure's floor plan

ROOM_YAML = """name: room
objects:
  - box: {center: [0, -6.1, 1.5], size: [12.4, 0.2, 3]}
  - box: {center: [0, 6.1, 1.5], size: [12.4, 0.2, 3]}
  - box: {center: [-6.1, 0, 1.5], size: [0.2, 12.4, 3]}
  - box: {center: [6.1, 0, 1.5], size: [0.2, 12.4, 3]}
  - box: {center: [0, 0, 1.5], size: [4, 4, 3]}
walkable: {rect: [-6, -6, 6, 6]}
"""


def plan_segments(ax):
    """The segments of every line collection on `ax` (the route and the queries are lines and points)."""
    from matplotlib.collections import LineCollection
    parts = [np.asarray(c.get_segments()).reshape(-1, 2, 2) for c in ax.collections if isinstance(c, LineCollection)]
    return np.concatenate(parts) if parts else np.empty((0, 2, 2))


def rectangle_edges(x0, y0, x1, y1):
    return np.array([[[x0, y0], [x1, y0]], [[x1, y0], [x1, y1]], [[x1, y1], [x0, y1]], [[x0, y1], [x0, y0]]], float)


def on_an_edge(points, edges, tol=1e-6):
    """Whether each point lies on one of the axis-parallel edges (S, 2, 2)."""
    lo, hi = np.minimum(edges[:, 0], edges[:, 1]), np.maximum(edges[:, 0], edges[:, 1])
    inside = np.all((points[:, None] >= lo[None] - tol) & (points[:, None] <= hi[None] + tol), axis=2)
    return inside.any(axis=1)


def test_the_figure_draws_a_simulated_route_over_its_floor_plan(tmp_path):
    """Issue 43, finding 10: a route through a world is drawn over the world's floor plan at the body's height
    (as route --figure draws it): here a 12 m room with a 4 m block, every box taller than the body. The plan's
    segments are the boxes' outlines (walls from the YAML, computed here), and the block's four edges are whole
    in it. A recording of the same route has no world: its figure is the route alone, and nothing says so."""
    import matplotlib
    matplotlib.use("Agg")
    from bvc3d import place_recognition_figure
    world = tmp_path / "room.yaml"
    world.write_text(ROOM_YAML)
    route, _ = two_laps(tmp_path)
    out = tmp_path / "sim"
    run_cli("place-recognition", "--world", world, "--route", route, "--sensor", "horizontal", "--descriptors",
            "scan-context", "--exclude-seconds", 10, "--out", out, check=True)
    # The boxes' outlines at the body's height, from the YAML: the walls' and the block's rectangles.
    boxes = [(-6.2, -6.2, 6.2, -6.0), (-6.2, 6.0, 6.2, 6.2), (-6.2, -6.2, -6.0, 6.2), (6.0, -6.2, 6.2, 6.2),
             (-2, -2, 2, 2), (-6, -6, 6, 6)]
    edges = np.concatenate([rectangle_edges(*b) for b in boxes])
    fig = place_recognition_figure.draw(out, world=world)
    drawn = plan_segments(fig.axes[1])
    assert len(drawn) >= 4
    assert on_an_edge(drawn.reshape(-1, 2), edges).all(), drawn
    for edge in rectangle_edges(-2, -2, 2, 2):
        assert any(np.allclose(s, edge) or np.allclose(s, edge[::-1]) for s in drawn), edge
    # Drawn as route --figure draws it: the world's own floor plan at the body's height, whole.
    np.testing.assert_array_equal(drawn, bvc3d.World.from_yaml(world).floor_plan(height=0.1)["segments"])
    assert "room" in fig.axes[1].get_title() and "floor plan" in fig.axes[1].get_title()
    # The command drew the same figure: it passes its world to the figure.
    again, bare = tmp_path / "again.png", tmp_path / "bare.png"
    place_recognition_figure.figure(out, again, world=bvc3d.World.from_yaml(world))
    place_recognition_figure.figure(out, bare)
    png = (out / "place-recognition.png").read_bytes()
    assert png == again.read_bytes() and png != bare.read_bytes()
    # The same route as a recording: no world, the route alone, and no word of a missing plan.
    run_cli("export-scans", "--world", world, "--trajectory", route, "--sensor", "horizontal", "--format",
            "pcd-f8", "--out", tmp_path / "rec", check=True)
    rec = tmp_path / "rec-out"
    proc = run_cli("place-recognition", "--scans", tmp_path / "rec" / "scans.txt", "--poses",
                   tmp_path / "rec" / "poses.txt", "--descriptors", "scan-context", "--exclude-seconds", 10,
                   "--out", rec, check=True)
    assert "plan" not in proc.stdout + proc.stderr and "world" not in proc.stdout + proc.stderr, proc
    fig = place_recognition_figure.draw(rec)
    assert len(plan_segments(fig.axes[1])) == 0 and fig.axes[1].get_title() == ""
    place_recognition_figure.figure(rec, bare)
    assert (rec / "place-recognition.png").read_bytes() == bare.read_bytes()
