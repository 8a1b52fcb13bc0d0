"""Recordings (issue 11): localization against a brute-force numpy reference, the export -> replay
round trip through the program's files, the preprocessing against numpy, maps and point-cloud
worlds, errors (file, line, scan index; exit 2; no output), and the real hall-lidar recording."""
import os
import pathlib

import h5py
import numpy as np
import pytest

import bvc3d
from conftest import SOURCE_DIR, run_cli

HALL = SOURCE_DIR.parent / "shared" / "data" / "hall-lidar"
needs_hall = pytest.mark.skipif(not (HALL / "poses.csv").exists(),
                                reason=f"the hall-lidar recording is not at {HALL}")


# ---------------------------------------------------------------- localization: numpy reference

def brute_force_localize(t, tp, q, qp):
    """SPEC §11 localization written out with numpy: cosine similarity, first maximum."""
    def unit(m):
        m = m.astype(np.float64)
        n = np.linalg.norm(m, axis=1, keepdims=True)
        return np.divide(m, n, out=np.zeros_like(m), where=n > 0)
    sim = unit(q) @ unit(t).T
    best = sim.argmax(axis=1)
    ok = sim[np.arange(len(q)), best] > 0
    horiz = np.hypot(qp[:, None, 0] - tp[None, :, 0], qp[:, None, 1] - tp[None, :, 1])
    err = horiz[np.arange(len(q)), best]
    vert = np.abs(qp[:, 2] - tp[best, 2])

    def summary(e):
        return dict(median_m=np.median(e), mean_m=e.mean(), within_1m=np.mean(e <= 1), within_2m=np.mean(e <= 2))
    return dict(decoded=np.where(ok, best, -1), error=err, ok=ok, vertical=vert,
                decoded_summary=summary(err[ok]), chance=summary(horiz[ok].ravel()),
                nearest=summary(horiz.min(axis=1)[ok]), nearest_error=horiz.min(axis=1))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_localize_matches_numpy_brute_force(seed):
    rng = np.random.default_rng(seed)
    T, Q, C = 37, 23, 31
    tp = rng.uniform(-6, 6, (T, 3))
    qp = rng.uniform(-6, 6, (Q, 3))
    t = rng.random((T, C)).astype(np.float32) ** 4
    q = rng.random((Q, C)).astype(np.float32) ** 4
    q[3] = 0  # all zero: undecoded
    t[5] = 0  # a silent template is never chosen
    out = bvc3d.localize(t, tp, q, qp)
    ref = brute_force_localize(t, tp, q, qp)
    np.testing.assert_array_equal(out["decoded"], ref["decoded"])
    assert out["n_undecoded"] == 1
    np.testing.assert_allclose(out["error"][ref["ok"]], ref["error"][ref["ok"]], rtol=0, atol=1e-12)
    np.testing.assert_allclose(out["vertical_error"][ref["ok"]], ref["vertical"][ref["ok"]], rtol=0, atol=1e-12)
    assert np.isnan(out["error"][3])
    np.testing.assert_allclose(out["nearest_error"], ref["nearest_error"], rtol=0, atol=1e-12)
    for key in ("decoded_summary", "chance", "nearest"):
        for k, v in ref[key].items():
            assert out[key][k] == pytest.approx(v, abs=1e-12), (key, k)


def test_localize_rejects_mismatched_inputs():
    with pytest.raises(bvc3d.InputError, match="same model"):
        bvc3d.localize(np.ones((3, 4), np.float32), np.zeros((3, 3)), np.ones((2, 5), np.float32), np.zeros((2, 3)))
    with pytest.raises(bvc3d.InputError, match="at least one template"):
        bvc3d.localize(np.ones((0, 4), np.float32), np.zeros((0, 3)), np.ones((2, 4), np.float32), np.zeros((2, 3)))


# ---------------------------------------------------------------- export -> replay through files

@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """Three simulated minutes of the random walk in cross-45, exported as float64 PCD scans."""
    d = tmp_path_factory.mktemp("export") / "walk"
    run_cli("export-scans", "--world", "cross", "--tilt", 45, "--hours", 0.03, "--seed", 4, "--sensor", "spherical",
            "--format", "pcd-f8", "--out", d, check=True)
    return d


def test_export_writes_a_recording(exported):
    names = sorted(os.listdir(exported))
    assert "poses.txt" in names and "scans.txt" in names
    scans = [n for n in names if n.endswith(".pcd")]
    rec = bvc3d.Recording.open(exported, exported / "poses.txt")
    assert len(rec) == len(scans) > 100
    walk = bvc3d.random_walk(bvc3d.World.cross(45), 0.03, 4)
    np.testing.assert_allclose(rec.times, walk["t"][:len(rec)], atol=1e-9)
    np.testing.assert_allclose(rec.poses[:, 0, 3], walk["x"][:len(rec)], atol=1e-12)
    np.testing.assert_allclose(rec.poses[:, 2, 3], 0.18, atol=1e-12)  # the spherical scanner's height


def test_export_then_replay_gives_the_simulations_rates(exported, tmp_path):
    out = tmp_path / "replay.h5"
    run_cli("replay", "--scans", exported / "scans.txt", "--poses", exported / "poses.txt", "--model", "3d-0.2",
            "--min-range", 0, "--out", out, check=True)
    walk = bvc3d.random_walk(bvc3d.World.cross(45), 0.03, 4)
    sim = bvc3d.run_trial("3d-0.2", "cross", 45, 0, trajectory={k: walk[k] for k in ("t", "x", "y", "heading")},
                          explore_hours=0, sample_hours=1, record_bvc=True)
    with h5py.File(out) as f:
        replayed = f["samples/bvc_rates"][:]
        assert f.attrs["recording"] == "walk"
        assert f.attrs["sensor"] == "recorded"
        assert f["samples/z"].shape == (len(replayed),)
    assert replayed.shape == sim["bvc_rates"].shape
    peak = np.abs(sim["bvc_rates"]).max()
    assert np.abs(replayed - sim["bvc_rates"]).max() <= 1e-6 * peak


def test_replay_is_deterministic(exported, tmp_path):
    for name in ("a.h5", "b.h5"):
        run_cli("replay", "--scans", exported, "--poses", exported / "poses.txt", "--model", "2d", "--learn",
                "--out", tmp_path / name, check=True)
    with h5py.File(tmp_path / "a.h5") as a, h5py.File(tmp_path / "b.h5") as b:
        for k in ("samples/rates", "samples/bvc_rates", "weights"):
            np.testing.assert_array_equal(a[k][:], b[k][:])


def numpy_returns(points, pose, model, min_range=0.3, max_range=20.0, slice_deg=1.0):
    v = points @ pose[:3, :3].T
    r = np.linalg.norm(v, axis=1)
    phi = np.arcsin(v[:, 2] / r)
    keep = (r >= min_range) & (r <= max_range)
    keep &= (np.abs(phi) <= np.radians(slice_deg)) if model.startswith("2d") else (phi >= 0)
    return np.c_[r, np.arctan2(v[:, 1], v[:, 0]), phi][keep]


def test_recording_returns_match_numpy(exported):
    rec = bvc3d.Recording.open(exported, exported / "poses.txt")
    for i in (0, 7):
        pose, points = rec[i]
        for model in ("2d", "3d-3l"):
            got = rec.returns(i, model)
            want = numpy_returns(points, pose, model)
            assert got.shape == want.shape
            np.testing.assert_allclose(got, want, atol=1e-9)
        got = rec.returns(i, "3d-3l", min_range=1.5)
        assert got[:, 0].min() >= 1.5
    assert len(list(iter(rec[j] for j in range(3)))) == 3
    with pytest.raises(bvc3d.InputError, match="min_range"):
        rec.returns(0, "2d", min_range=-1)


def test_localize_cli_table_and_figure(exported, tmp_path):
    out = tmp_path / "loc"
    proc = run_cli("localize", "--scans", exported, "--poses", exported / "poses.txt", "--split", 2,
                   "--model", "2d,3d-0.2", "--out", out, check=True)
    assert "3d-0.2" in proc.stdout
    rows = np.genfromtxt(out / "localization.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert list(rows["model"]) == ["2d", "3d-0.2"]
    # Neighbouring steps are 0.144 m apart: the nearest template is about one step away.
    assert np.all(rows["nearest_median_m"] < 0.2)
    assert np.all(rows["median_m"] <= rows["chance_median_m"])
    q = np.genfromtxt(out / "queries.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    assert np.all(q["query"] % 2 == 1)
    png = (out / "localization.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------- maps and point-cloud worlds

def test_map_of_an_exported_recording_lies_on_the_walls(tmp_path):
    rec = tmp_path / "rec"
    run_cli("export-scans", "--world", "cross-0", "--hours", 0.01, "--sensor", "spherical", "--format", "kitti",
            "--out", rec, check=True)
    out = tmp_path / "map.ply"
    proc = run_cli("map", "--scans", rec, "--poses", rec / "poses.txt", "--voxel", 0.1, "--min-range", 0,
                   "--out", out, check=True)
    assert "voxels" in proc.stdout
    with open(out, "rb") as f:
        header = b""
        while not header.endswith(b"end_header\n"):
            header += f.readline()
        n = int(header.split(b"element vertex ")[1].split(b"\n")[0])
        pts = np.frombuffer(f.read(), dtype="<f4").reshape(n, 3).astype(np.float64)
    # Distance of each point to the nearest surface of the upright cross arena (outer box, ceiling,
    # the two central walls); a voxel's mean lies on the surface unless the voxel spans a corner.
    ax, ay = np.abs(pts[:, 0]), np.abs(pts[:, 1])
    d = np.minimum.reduce([np.abs(5 - ax), np.abs(5 - ay), np.abs(2.5 - pts[:, 2]),
                           np.where(ax <= 3.5, np.abs(ay - 0.15), 9), np.where(ay <= 3.5, np.abs(ax - 0.15), 9),
                           np.where(ay <= 0.15, np.abs(ax - 3.5), 9), np.where(ax <= 0.15, np.abs(ay - 3.5), 9)])
    assert np.mean(d < 1e-4) > 0.9  # float32 coordinates
    assert np.all(d < 0.1)

    # The map as a world: a scan in it sees the arena's walls where the arena has them.
    world = tmp_path / "map.yaml"
    world.write_text(f"objects:\n  - point_cloud: {{file: {out.name}, radius: 0.06}}\n"
                     f"walkable: {{rect: [-4, -4, 4, 4]}}\n")
    w = bvc3d.World.from_yaml(world)
    pose = dict(x=-4.2, y=-4.1, heading=0.4)
    got = w.scan("spherical", **pose)
    truth = bvc3d.World.cross(0).scan("spherical", **pose)
    hit = np.isin(np.round(got[:, 1:], 9), np.round(truth[:, 1:], 9)).all(axis=1)
    assert hit.mean() > 0.95
    # Beams that saw the arena's surfaces see the map's spheres within a radius and a voxel of them.
    both = {tuple(np.round(a, 9)): r for r, *a in truth}
    diffs = [abs(r - both[tuple(np.round(a, 9))]) for r, *a in got if tuple(np.round(a, 9)) in both]
    assert np.median(diffs) < 0.1


# ---------------------------------------------------------------- errors: file, line, scan; exit 2; no output

def test_cli_errors_name_the_problem_and_write_nothing(exported, tmp_path):
    out = tmp_path / "r.h5"
    proc = run_cli("replay", "--scans", tmp_path / "missing", "--poses", exported / "poses.txt", "--model", "2d",
                   "--out", out)
    assert proc.returncode == 2 and "missing" in proc.stderr and not out.exists()

    # A broken scan in the middle: the scan's index and file, no trial file.
    broken = tmp_path / "broken"
    broken.mkdir()
    for name in os.listdir(exported):
        (broken / name).write_bytes((exported / name).read_bytes())
    victim = sorted(p for p in os.listdir(broken) if p.endswith(".pcd"))[3]
    data = (broken / victim).read_bytes()
    (broken / victim).write_bytes(data[: len(data) // 2])
    proc = run_cli("replay", "--scans", broken, "--poses", broken / "poses.txt", "--model", "3d-0.2", "--out", out)
    assert proc.returncode == 2, proc.stderr
    assert "scan 3" in proc.stderr and victim in proc.stderr, proc.stderr
    assert not out.exists() and not any(p.name.startswith("r.h5") for p in tmp_path.iterdir())

    # Pose file with a bad line: the file and the line.
    bad_poses = tmp_path / "poses.txt"
    lines = (exported / "poses.txt").read_text().splitlines()
    lines[5] = "1,2,oops,4,"
    bad_poses.write_text("\n".join(lines) + "\n")
    proc = run_cli("replay", "--scans", exported, "--poses", bad_poses, "--model", "2d", "--out", out)
    assert proc.returncode == 2 and "line 6" in proc.stderr and "oops" in proc.stderr, proc.stderr

    # Counts that differ and no times to pair by.
    few = tmp_path / "few.txt"
    few.write_text("\n".join(lines[:8]) .replace(",0,0,0,", ",0,0,0,") + "\n")
    kitti = tmp_path / "kitti.txt"
    kitti.write_text("1 0 0 0 0 1 0 0 0 0 1 0\n" * 3)
    proc = run_cli("replay", "--scans", exported, "--poses", kitti, "--model", "2d", "--out", out)
    assert proc.returncode == 2 and "times" in proc.stderr, proc.stderr

    proc = run_cli("localize", "--scans", exported, "--poses", exported / "poses.txt", "--model", "2d",
                   "--out", tmp_path / "loc")
    assert proc.returncode == 2 and "--split" in proc.stderr
    assert not (tmp_path / "loc").exists()
    proc = run_cli("map", "--scans", exported, "--poses", exported / "poses.txt", "--out", tmp_path / "m.xyz")
    assert proc.returncode == 2 and ".ply or .pcd" in proc.stderr
    proc = run_cli("replay", "--scans", exported, "--poses", exported / "poses.txt", "--model", "2d",
                   "--weights", exported / "000000.pcd", "--out", out)
    assert proc.returncode == 2 and not out.exists()

    # Export into a folder holding other files: refused, the folder untouched.
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep me")
    proc = run_cli("export-scans", "--world", "cross", "--hours", 0.002, "--out", mine)
    assert proc.returncode == 2 and "notes.txt" in proc.stderr
    assert sorted(os.listdir(mine)) == ["notes.txt"]

    # A trajectory with a bad row: the file and the line.
    traj = tmp_path / "t.csv"
    traj.write_text("t,x,y,heading,roll_deg\n0,0,0,0,0\n1,0,1,0,x\n")
    proc = run_cli("export-scans", "--world", "cross", "--trajectory", traj, "--out", tmp_path / "e")
    assert proc.returncode == 2 and "line 3" in proc.stderr and not (tmp_path / "e").exists()


@pytest.mark.parametrize("command", ["replay", "localize", "map", "export-scans"])
def test_every_command_explains_itself(command):
    proc = run_cli(command, "--help")
    assert proc.returncode == 0
    assert "docs/" in proc.stdout and "--out" in proc.stdout


# ---------------------------------------------------------------- the real recording

@needs_hall
def test_hall_lidar_replays_and_localizes_scan_to_scan(tmp_path):
    out = tmp_path / "hall.h5"
    proc = run_cli("replay", "--scans", HALL, "--poses", HALL / "poses.csv", "--model", "3d-3l", "--out", out,
                   check=True)
    assert "60 scans" in proc.stdout
    rec = bvc3d.Recording.open(HALL, HALL / "poses.csv")
    with h5py.File(out) as f:
        assert f["samples/bvc_rates"].shape == (60, 960)
        np.testing.assert_allclose(f["samples/x"][:], rec.poses[:, 0, 3])
        np.testing.assert_allclose(f["samples/t"][:], rec.times - rec.times[0], atol=1e-6)
        assert float(f.attrs["recording_t0"]) == pytest.approx(rec.times[0])
        assert np.all(np.abs(f["samples/bvc_rates"][:].max(axis=1) - 0.5) < 1e-7)
    loc = tmp_path / "loc"
    run_cli("localize", "--scans", HALL, "--poses", HALL / "poses.csv", "--split", 2, "--model", "2d,3d-3l",
            "--out", loc, "--no-figure", check=True)
    rows = np.genfromtxt(loc / "localization.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    # Neighbouring scans ~0.9 m apart look alike: every model decodes near the nearest-template bound.
    assert np.all(rows["median_m"] < 1.5)
    assert np.all(rows["within_2m"] > 0.8)
    assert np.all(rows["chance_median_m"] > 5)
