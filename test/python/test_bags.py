"""ROS bags as recordings (docs/ros.md), read back against independent writers (test/python/bag_writers.py:
CDR by hand, MCAP from the specification, ROS 2 SQLite folders, ROS 1 bags by Debian's python3-rosbag) and
hand computations (the points of odd cloud layouts, the tf chain interpolated by lerp and slerp)."""
import shutil
import struct
import subprocess
import zlib

import numpy as np
import pytest

import bag_writers as bw

bvc3d = pytest.importorskip("bvc3d")

FLOAT32, FLOAT64 = 7, 8


def odd_cloud(points, big=False, height=2):
    """An organised cloud with x float64 at offset 5, y float32 at 13, z float64 at 17, an intensity at 0,
    point_step 29: the odd layout a driver may use. NaN rows stay in the data."""
    e = ">" if big else "<"
    data = b""
    for x, y, z in points:
        rec = bytearray(29)
        rec[0:4] = struct.pack(e + "f", 7.5)
        rec[5:13] = struct.pack(e + "d", x)
        rec[13:17] = struct.pack(e + "f", y)
        rec[17:25] = struct.pack(e + "d", z)
        data += bytes(rec)
    fields = [("intensity", 0, FLOAT32, 1), ("x", 5, FLOAT64, 1), ("y", 13, FLOAT32, 1), ("z", 17, FLOAT64, 1)]
    return fields, data, height, len(points) // height


def expected_points(points):
    p = np.array(points, dtype=float)
    p[:, 1] = p[:, 1].astype(np.float32)  # y is stored as float32
    return p[np.isfinite(p).all(axis=1)]


def scan_points(rng, n=6):
    p = rng.uniform(-5, 5, size=(n, 3))
    p[2] = np.nan  # an organised cloud's "no return"
    return [tuple(v) for v in p]


def pose_matrix(p, q):
    m = np.eye(4)
    m[:3, :3] = bw.quaternion_matrix(q)
    m[:3, 3] = p
    return m


def cloud_bag_messages(rng, big):
    clouds, odoms, expected, poses = [], [], [], []
    for i in range(3):
        stamp = 100.0 + 0.1 * i
        pts = scan_points(rng)
        fields, data, h, w = odd_cloud(pts, big)
        clouds.append((int(round(stamp * 1e9)), bw.cdr_cloud(stamp, "lidar", h, w, fields, 29, data, big)))
        p, q = (i, 2.0 * i, 0.5), bw.rotation_quaternion(0.3 * i, 0.1, -0.05)
        odoms.append((int(round(stamp * 1e9)), bw.cdr_odometry(stamp, "map", "lidar", p, q, big)))
        expected.append(expected_points(pts))
        poses.append(pose_matrix(p, q))
    return clouds, odoms, expected, poses


def check_recording(rec, expected, poses):
    assert len(rec) == len(expected)
    for i, e in enumerate(expected):
        np.testing.assert_array_equal(rec.points(i), e)  # exact: the same numbers as stored
        np.testing.assert_allclose(rec.poses[i], poses[i], atol=1e-12)
    np.testing.assert_allclose(rec.times, 100.0 + 0.1 * np.arange(len(expected)), atol=1e-9)


@pytest.mark.parametrize("compression", ["zstd", "lz4", "none", "unchunked"])
@pytest.mark.parametrize("big", [False, True])
def test_mcap_clouds_of_any_layout(tmp_path, compression, big):
    rng = np.random.default_rng(1)
    clouds, odoms, expected, poses = cloud_bag_messages(rng, big)
    msgs = [(0, t, d) for t, d in clouds] + [(1, t, d) for t, d in odoms]
    path = tmp_path / "x.mcap"
    bw.mcap(path, [(0, "/points", "sensor_msgs/msg/PointCloud2"), (1, "/odom", "nav_msgs/msg/Odometry")], msgs,
            chunked=compression != "unchunked", compression="none" if compression == "unchunked" else compression)
    check_recording(bvc3d.Recording.open_bag(path, "/points", pose_topic="/odom"), expected, poses)


def test_ros2_sqlite_bag(tmp_path):
    rng = np.random.default_rng(2)
    clouds, odoms, expected, poses = cloud_bag_messages(rng, big=True)
    topics = [(1, "/points", "sensor_msgs/msg/PointCloud2"), (2, "/odom", "nav_msgs/msg/Odometry")]
    bw.ros2_sqlite(tmp_path / "bag", topics, [(2, t, d) for t, d in odoms] + [(1, t, d) for t, d in clouds])
    check_recording(bvc3d.Recording.open_bag(tmp_path / "bag", "/points", pose_topic="/odom"), expected, poses)


def slerp(q0, q1, s):
    q0, q1 = np.asarray(q0), np.asarray(q1)
    d = np.dot(q0, q1)
    if d < 0:
        q1, d = -q1, -d
    omega = np.arccos(min(d, 1.0))
    return (np.sin((1 - s) * omega) * q0 + np.sin(s * omega) * q1) / np.sin(omega)


def tf_bag(path, second_at=10.1):
    """map -> odom static; odom -> base dynamic at 10.0 and `second_at`; base -> lidar static; a cloud at 10.025."""
    q0, q1 = bw.rotation_quaternion(0.0, 0.2, 0.0), bw.rotation_quaternion(0.5, -0.1, 0.05)
    p0, p1 = (0.0, 0.0, 0.0), (1.0, 2.0, 0.4)
    qb = bw.rotation_quaternion(0.0, 0.0, 0.3)
    static = bw.cdr_tf([(0.0, "map", "odom", (1.0, 0.0, 0.0), (0, 0, 0, 1)),
                        (0.0, "base", "lidar", (0.1, 0.0, 0.5), qb)])
    dyn = [bw.cdr_tf([(10.0, "odom", "base", p0, q0)]), bw.cdr_tf([(second_at, "/odom", "base", p1, q1)])]
    pts = [(1.0, 2.0, 3.0), (4.0, 5.0, 6.0)]
    data = b"".join(struct.pack("<fff", *p) for p in pts)
    cloud = bw.cdr_cloud(10.025, "lidar", 1, 2, [("x", 0, FLOAT32, 1), ("y", 4, FLOAT32, 1), ("z", 8, FLOAT32, 1)],
                         12, data)
    ns = lambda t: int(round(t * 1e9))  # noqa: E731
    bw.mcap(path, [(0, "/tf_static", "tf2_msgs/msg/TFMessage"), (1, "/tf", "tf2_msgs/msg/TFMessage"),
                   (2, "/points", "sensor_msgs/msg/PointCloud2")],
            [(0, ns(0.5), static), (1, ns(10.0), dyn[0]), (1, ns(second_at), dyn[1]), (2, ns(10.025), cloud)])
    s = 0.025 / (second_at - 10.0)
    odom_base = pose_matrix(np.array(p0) + s * (np.array(p1) - np.array(p0)), slerp(q0, q1, s))
    return pose_matrix((1.0, 0, 0), (0, 0, 0, 1)) @ odom_base @ pose_matrix((0.1, 0.0, 0.5), qb)


def test_tf_chain_interpolated_by_hand(tmp_path):
    expected = tf_bag(tmp_path / "tf.mcap")
    rec = bvc3d.Recording.open_bag(tmp_path / "tf.mcap", "/points", tf_frames="map,lidar")
    np.testing.assert_allclose(rec.poses[0], expected, atol=1e-12)


def test_tf_gap_is_an_error(tmp_path):
    tf_bag(tmp_path / "gap.mcap", second_at=10.5)
    with pytest.raises(ValueError, match=r"gap\.mcap.*/points.*message 0.*gap of 0\.5 s"):
        bvc3d.Recording.open_bag(tmp_path / "gap.mcap", "/points", tf_frames="map,lidar", tf_tolerance=0.2)
    rec = bvc3d.Recording.open_bag(tmp_path / "gap.mcap", "/points", tf_frames="map,lidar", tf_tolerance=0.6)
    assert len(rec) == 1


rosbag = pytest.importorskip("rosbag") if shutil.which("rosbag") else None


@pytest.mark.parametrize("compression", ["none", "bz2", "lz4"])
def test_ros1_bag_written_by_python_rosbag(tmp_path, compression):
    if rosbag is None:
        pytest.skip("Debian's python3-rosbag is not installed")
    msg = pytest.importorskip("sensor_msgs.msg")
    geo = pytest.importorskip("geometry_msgs.msg")
    import rospy
    rng = np.random.default_rng(3)
    path = tmp_path / "x.bag"
    expected, poses = [], []
    with rosbag.Bag(str(path), "w", compression=compression) as bag:
        for i in range(3):
            stamp = rospy.Time.from_sec(100.0 + 0.1 * i)
            pts = scan_points(rng, 8)
            fields, data, h, w = odd_cloud(pts, big=False, height=2)
            c = msg.PointCloud2()
            c.header.stamp, c.header.frame_id = stamp, "lidar"
            c.height, c.width, c.point_step, c.row_step = h, w, 29, 29 * w
            c.fields = [msg.PointField(name=n, offset=o, datatype=d, count=k) for n, o, d, k in fields]
            c.data = data
            p = geo.PoseStamped()
            p.header.stamp, p.header.frame_id = stamp, "map"
            q = bw.rotation_quaternion(0.2 * i, -0.1, 0.0)
            p.pose.position.x, p.pose.position.y, p.pose.position.z = 3.0 * i, -1.0, 0.25
            p.pose.orientation.x, p.pose.orientation.y, p.pose.orientation.z, p.pose.orientation.w = q
            bag.write("/pose", p, stamp)
            bag.write("/points", c, stamp)
            expected.append(expected_points(pts))
            poses.append(pose_matrix((3.0 * i, -1.0, 0.25), q))
    check_recording(bvc3d.Recording.open_bag(path, "/points", pose_topic="/pose"), expected, poses)


def read_mcap(path):
    """An independent MCAP reader (the specification): message counts per topic, chunk CRCs checked."""
    b = path.read_bytes()
    assert b[:8] == bw.MAGIC and b[-8:] == bw.MAGIC
    topics, counts = {}, {}

    def walk(data, pos, end):
        while pos < end:
            op, n = struct.unpack_from("<BQ", data, pos)
            c = data[pos + 9:pos + 9 + n]
            if op == 0x04:
                cid, _ = struct.unpack_from("<HH", c)
                tl = struct.unpack_from("<I", c, 4)[0]
                topics[cid] = c[8:8 + tl].decode()
            elif op == 0x05:
                cid = struct.unpack_from("<H", c)[0]
                counts[topics[cid]] = counts.get(topics[cid], 0) + 1
            elif op == 0x06:
                size, crc = struct.unpack_from("<QI", c, 16)
                cl = struct.unpack_from("<I", c, 28)[0]
                comp = c[32:32 + cl].decode()
                rl = struct.unpack_from("<Q", c, 32 + cl)[0]
                packed = c[40 + cl:40 + cl + rl]
                inner = packed if comp == "" else subprocess.run(["zstd", "-d", "-q", "-c"], input=packed,
                                                                 capture_output=True, check=True).stdout
                assert len(inner) == size and zlib.crc32(inner) == crc
                walk(inner, 0, len(inner))
            elif op == 0x02:
                return
            pos += 9 + n

    walk(b, 8, len(b) - 8)
    return counts


def test_export_bags_and_replay_them(tmp_path, cli):
    args = ["export-scans", "--world", "cross", "--hours", "0.004", "--seed", "3"]
    cli(*args, "--format", "pcd-f8", "--out", tmp_path / "walk", check=True)
    cli(*args, "--format", "ros1", "--out", tmp_path / "walk.bag", check=True)
    cli(*args, "--format", "mcap", "--out", tmp_path / "walk.mcap", check=True)
    n = len((tmp_path / "walk" / "scans.txt").read_text().splitlines())
    assert read_mcap(tmp_path / "walk.mcap") == {"/points": n, "/odom": n, "/tf": n}
    if shutil.which("rosbag"):  # Debian's rosbag reads what bvc3d wrote
        info = subprocess.run(["rosbag", "info", "--yaml", str(tmp_path / "walk.bag")], capture_output=True,
                              text=True, check=True).stdout
        assert f"messages: {3 * n}" in info and "sensor_msgs/PointCloud2" in info
    files = bvc3d.Recording.open(tmp_path / "walk" / "scans.txt", tmp_path / "walk" / "poses.txt")
    base = files.replay("3d-3l")
    for bag, how in [("walk.bag", {"pose_topic": "/odom"}), ("walk.mcap", {"tf_frames": "map,sensor"})]:
        rec = bvc3d.Recording.open_bag(tmp_path / bag, "/points", **how)
        np.testing.assert_allclose(rec.poses, files.poses, atol=1e-12)
        run = rec.replay("3d-3l")
        # A bag carries each pose as a quaternion (rounded at 1e-16): a return at elevation 0 (the
        # spherical scanner's lowest row) may fall on either side of the upper half it keeps.
        np.testing.assert_allclose(run["bvc_rates"], base["bvc_rates"], atol=1e-5)
        np.testing.assert_allclose(run["rates"], base["rates"], atol=1e-5)
        # The same bag read twice (and a bag against itself through another pose source) is the same.
        again = bvc3d.Recording.open_bag(tmp_path / bag, "/points", pose_topic="/odom").replay("3d-3l")
        if "pose_topic" in how:
            np.testing.assert_array_equal(again["bvc_rates"], run["bvc_rates"])
    info = cli("bag-info", tmp_path / "walk.mcap", check=True).stdout
    assert "MCAP" in info and f"/points" in info and "sensor_msgs/msg/PointCloud2" in info
    assert f"{n}" in info and "map -> sensor" in info


def test_bag_options_reach_the_commands(tmp_path, cli):
    cli("export-scans", "--world", "cross", "--hours", "0.003", "--seed", "4", "--format", "mcap", "--out",
        tmp_path / "w.mcap", check=True)
    bag = ["--bag", tmp_path / "w.mcap", "--cloud-topic", "/points", "--pose-topic", "/odom"]
    cli("replay", *bag, "--model", "2d", "--out", tmp_path / "r.h5", check=True)
    cli("map", *bag, "--voxel", "0.2", "--out", tmp_path / "m.ply", check=True)
    cli("localize", *bag, "--split", "2", "--model", "2d", "--no-figure", "--out", tmp_path / "loc", check=True)
    assert (tmp_path / "loc" / "localization.csv").exists()
    bad = cli("replay", "--bag", tmp_path / "w.mcap", "--cloud-topic", "/nope", "--pose-topic", "/odom",
              "--model", "2d", "--out", tmp_path / "no.h5")
    assert bad.returncode == 2 and "/nope" in bad.stderr and "w.mcap" in bad.stderr
    assert not (tmp_path / "no.h5").exists()
