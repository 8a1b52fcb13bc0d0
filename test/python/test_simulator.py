"""The simulator stage through the Python API and the CLI (issue 2)."""
import io
import math

import numpy as np
import pytest

import bvc3d


def read_csv(text):
    return np.genfromtxt(io.StringIO(text), delimiter=",", names=True)


def test_scan_array_layout_and_values():
    w = bvc3d.World.cross(tilt_deg=45)
    s = w.scan("horizontal", 1.0, 2.0, 0.0)
    assert s.dtype == np.float64 and s.shape == (720, 3)
    # Beam 0 looks along +x from (1, 2): the outer wall x = 5 is 4 m away.
    assert s[0, 0] == pytest.approx(4.0, abs=1e-12)
    assert np.all((s[:, 1] > -math.pi) & (s[:, 1] <= math.pi))
    assert np.all(s[:, 2] == 0.0)
    sph = w.scan("spherical", 1.0, 2.0, 0.3)
    assert sph.shape == (45 * 180, 3)
    assert np.all(sph[:, 2] > 0)
    custom = bvc3d.Sensor(elevations=[0.1, 0.0], azimuth_count=90, height=0.3)
    assert w.scan(custom, 1.0, 2.0, 0.0).shape == (180, 3)
    assert bvc3d.Sensor.spherical(upper_only=False).beam_count == 16200


def test_scan_is_deterministic_and_noise_is_seeded():
    w = bvc3d.World.cross(tilt_deg=30)
    noisy = bvc3d.Sensor(elevations=[0.0], azimuth_count=360, range_noise_sd=0.05, dropout=0.1, height=0.08)
    a = w.scan(noisy, 0.5, -2.0, 1.0, noise_seed=3, scan_index=7)
    b = w.scan(noisy, 0.5, -2.0, 1.0, noise_seed=3, scan_index=7)
    c = w.scan(noisy, 0.5, -2.0, 1.0, noise_seed=4, scan_index=7)
    np.testing.assert_array_equal(a, b)
    assert a.shape != c.shape or not np.array_equal(a, c)


def test_random_walk_dict_and_determinism():
    w = bvc3d.World.cross(tilt_deg=60)
    a = bvc3d.random_walk(w, 0.25, 5)
    b = bvc3d.random_walk(w, 0.25, 5)
    c = bvc3d.random_walk(w, 0.25, 6)
    assert set(a) == {"t", "x", "y", "z", "heading", "bumped"}
    assert not a["z"].any()  # a ground robot stays on the floor
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])
    assert a["bumped"].dtype == np.bool_
    assert np.all(np.diff(a["t"]) > 0)
    assert np.max(np.abs(a["x"])) <= 4.75 + 1e-9
    assert len(a["x"]) != len(c["x"]) or not np.array_equal(a["x"], c["x"])


def test_world_from_yaml_and_errors(tmp_path, source_dir):
    w = bvc3d.World.from_yaml(str(source_dir / "configs/worlds/two-rooms.yaml"))
    assert w.name == "two-rooms"
    assert w.triangles.shape[1:] == (3, 3)
    bad = tmp_path / "bad.yaml"
    bad.write_text("objects:\n  - box: {center: [0, 0, 0], size: [1, 1]}\nwalkable: {rect: [-1, -1, 1, 1]}\n")
    with pytest.raises(ValueError, match=r"objects\[0\]\.box\.size.*expected a list of 3 numbers"):
        bvc3d.World.from_yaml(str(bad))
    with pytest.raises(ValueError, match="tilt_deg"):
        bvc3d.World.cross(tilt_deg=85)
    with pytest.raises(ValueError, match="neither 'horizontal', 'spherical'"):
        bvc3d.World.cross().scan("lidar9000", 0, 0, 0)


def test_cli_scan_matches_python(cli, tmp_path):
    out = tmp_path / "scan.csv"
    cli("scan", "--world", "cross", "--tilt", 45, "--sensor", "spherical", "--pose", "1.5,-2,0.7", "--out", out,
        check=True)
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    expected = bvc3d.World.cross(45).scan("spherical", 1.5, -2.0, 0.7)
    np.testing.assert_array_equal(rows, expected)  # shortest round-trip text: exact
    assert out.read_text().splitlines()[0] == "range,azimuth,elevation"
    deg = cli("scan", "--world", "cross-45", "--sensor", "horizontal", "--pose", "1.5,-2,90deg", check=True)
    first = read_csv(deg.stdout)[0]
    assert first["azimuth"] == pytest.approx(math.pi / 2)


def test_cli_walk_matches_python(cli, tmp_path):
    out = tmp_path / "walk.csv"
    cli("walk", "--world", "cross", "--tilt", 30, "--hours", 0.2, "--seed", 9, "--out", out, check=True)
    d = np.genfromtxt(out, delimiter=",", names=True)
    ref = bvc3d.random_walk(bvc3d.World.cross(30), 0.2, 9)
    for k in ("t", "x", "y", "heading"):
        np.testing.assert_array_equal(d[k], ref[k])
    np.testing.assert_array_equal(d["bumped"].astype(bool), ref["bumped"])


def test_cli_help_is_complete(cli):
    top = cli("--help", check=True).stdout
    for sub in ("scan", "walk"):
        assert sub in top
        text = cli(sub, "--help", check=True).stdout
        assert "--world" in text and "--out" in text
    assert "--pose" in cli("scan", "--help").stdout
    assert "--seed" in cli("walk", "--help").stdout


BAD_WORLDS = {
    "malformed.yaml": ("objects: [ {box: {center: [0,0,0]} \n", "", "malformed YAML"),
    "unknown_key.yaml": ("objects:\n  - box: {center: [0,0,0], size: [1,1,1], colour: red}\n"
                         "walkable: {rect: [-4,-4,4,4]}\n",
                         "objects[0].box.colour", "unknown key"),
    "wrong_type.yaml": ("objects:\n  - cross_arena: {tilt_deg: steep}\n", "objects[0].cross_arena.tilt_deg",
                        "expected a number"),
    "missing_mesh.yaml": ("objects:\n  - mesh: {file: nowhere.obj}\nwalkable: {rect: [-4,-4,4,4]}\n",
                          "objects[0].mesh.file", "does not exist"),
    "broken_mesh.yaml": ("objects:\n  - mesh: {file: broken.obj}\nwalkable: {rect: [-4,-4,4,4]}\n",
                         "objects[0].mesh.file", "broken.obj"),
    "empty.yaml": ("objects: []\nwalkable: {rect: [-4,-4,4,4]}\n", "objects", "no objects"),
    "degenerate.yaml": ("objects:\n  - quad: [[0,0,0],[1,1,1],[2,2,2],[3,3,3]]\nwalkable: {rect: [-4,-4,4,4]}\n",
                        "objects[0].quad", "degenerate"),
    "impossible.yaml": ("objects:\n  - cross_arena: {tilt_deg: 80}\n", "objects[0].cross_arena", "outer walls"),
}


@pytest.mark.parametrize("name", sorted(BAD_WORLDS))
@pytest.mark.parametrize("command", ["scan", "walk"])
def test_cli_bad_worlds(cli, tmp_path, source_dir, name, command):
    text, key, reason = BAD_WORLDS[name]
    (tmp_path / "broken.obj").write_bytes((source_dir / "test/data/broken.obj").read_bytes())
    world = tmp_path / name
    world.write_text(text)
    out = tmp_path / "out.csv"
    args = ["--pose", "0,0,0"] if command == "scan" else ["--hours", "0.01"]
    proc = cli(command, "--world", world, *args, "--out", out)
    assert proc.returncode == 2, proc.stderr
    assert str(world) in proc.stderr
    assert key in proc.stderr and reason in proc.stderr, proc.stderr
    assert not out.exists()
    assert list(tmp_path.glob("out.csv*")) == []  # no temporary left behind either


@pytest.mark.parametrize("args, message", [
    (["scan", "--world", "atlantis", "--pose", "0,0,0"], "neither a preset"),
    (["scan", "--pose", "0,0"], "--pose expects X,Y,HEADING"),
    (["scan", "--pose", "0,nan,0"], "not a finite number"),
    (["scan", "--sensor", "radar", "--pose", "0,0,0"], "neither 'horizontal', 'spherical'"),
    (["walk", "--world", "cross-30", "--tilt", "45"], "a tilt only applies"),
    (["walk", "--world", "cross", "--tilt", "95"], "tilt_deg must be in [0, 90)"),
    (["walk", "--world", "cross", "--lean", "up"], "lean 'up'"),
])
def test_cli_bad_arguments(cli, args, message):
    proc = cli(*args)
    assert proc.returncode == 2, proc.stderr
    assert message in proc.stderr


def test_cli_rejects_unwritable_output(cli, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    proc = cli("walk", "--hours", "0.01", "--out", blocker / "walk.csv")
    assert proc.returncode == 2
    assert "not a folder" in proc.stderr


def test_cli_negative_hours_is_a_usage_error(cli):
    proc = cli("walk", "--hours", "-1")
    assert proc.returncode != 0
    assert "hours" in proc.stderr.lower()


def test_scan_rejects_non_finite_poses():
    w = bvc3d.World.cross()
    for pose in [(float("nan"), 0, 0), (0, 0, float("inf")), (1e30, 0, 0)]:
        with pytest.raises(ValueError, match="finite and within"):
            w.scan("spherical", *pose)
