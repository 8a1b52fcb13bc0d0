#!/usr/bin/env python3
"""Writes the seed corpora of the fuzzers (test/fuzz/corpus/<target>/): a few small valid inputs
each, for libFuzzer to mutate. The outputs are committed; rerun after changing this:

    /usr/bin/python3 test/fuzz/make_corpus.py
"""
import base64
import pathlib
import shutil
import struct

HERE = pathlib.Path(__file__).resolve().parent
SOURCE = HERE.parents[1]
CORPUS = HERE / "corpus"


def lzf_literal(data):
    """LZF as literal runs only (control byte n - 1 < 32, then n bytes): valid input for lzf_decompress."""
    out = b""
    for i in range(0, len(data), 32):
        chunk = data[i:i + 32]
        out += bytes([len(chunk) - 1]) + chunk
    return out


def pcd(data_kind, points):
    head = (f"# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
            f"WIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
            f"POINTS {len(points)}\nDATA {data_kind}\n").encode()
    if data_kind == "ascii":
        return head + "".join(f"{x} {y} {z} {i}\n" for x, y, z, i in points).encode()
    if data_kind == "binary":
        return head + b"".join(struct.pack("<4f", *p) for p in points)
    field_major = b"".join(struct.pack(f"<{len(points)}f", *[p[k] for p in points]) for k in range(4))
    packed = lzf_literal(field_major)
    return head + struct.pack("<II", len(packed), len(field_major)) + packed


POINTS = [(1.0, 2.0, 0.5, 7.0), (-3.0, 0.25, 1.0, 1.0), (float("nan"), 0.0, 0.0, 0.0)]
PLY_CLOUD_ASCII = b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n" \
                  b"property uchar intensity\nend_header\n1 2 3 9\n4 5 6 1\n"
PLY_CLOUD_BINARY = b"ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty double x\nproperty double y\n" \
                   b"property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n" + \
                   struct.pack("<6d", 1, 2, 3, 4, 5, 6) + struct.pack("<B3i", 3, 0, 1, 1)
CUBE_OBJ = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3/1 4/1\nvt 0 0\nvn 0 0 1\n" \
           b"f 1//1 2//1 5//1\nf -1 -2 -3\n"
STL_BINARY = b"solid-looking binary header".ljust(80, b" ") + struct.pack("<I", 1) + \
             struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0)
STL_ASCII = b"solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n" \
            b"  endloop\n endfacet\nendsolid t\n"
PLY_MESH = b"ply\nformat ascii 1.0\ncomment a triangle\nelement vertex 3\nproperty float x\nproperty float y\n" \
           b"property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n" \
           b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"

SEEDS = {
    "fuzz_world_yaml": {
        "cross.yaml": (SOURCE / "configs/worlds/cross-30.yaml").read_bytes(),
        "objects.yaml": b"name: w\nobjects:\n  - box: {center: [0, 0, 1], size: [1, 1, 2], yaw_deg: 30}\n"
                        b"  - quad: [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\n"
                        b"  - tilted_wall: {center: [2, 0], length: 3, thickness: 0.2, height: 2, yaw_deg: 0, "
                        b"tilt_deg: 20}\n"
                        b"walkable: {polygon: [[-5, -5], [5, -5], [5, 5], [-5, 5]]}\n"
                        b"start: {points: [[-4, -4], [4, 4]]}\n",
        "arena-start.yaml": b"objects:\n  - cross_arena: {tilt_deg: 45, lean: -x+y, half_width: 6}\n"
                            b"  - box: {center: [3, 3, 0.5], size: [1, 1, 1], rotation_deg: [0, 10, 0]}\n"
                            b"start: {rect: [-5, -5, -3, -3]}\n",
    },
    "fuzz_model_yaml": {
        "noisy.yaml": (SOURCE / "configs/models/3d-0.2-noisy.yaml").read_bytes(),
        "wide.yaml": (SOURCE / "configs/models/3d-0.15-wide.yaml").read_bytes(),
        "velodyne.yaml": (SOURCE / "configs/models/velodyne-64.yaml").read_bytes(),
        "inline.yaml": b"base: 2d\nsensor: {preset: spherical, keep_rows: all, max_range: 20}\n"
                       b"bvc: {elevations_deg: [0, 10], n_dir: 16, normalization: fixed, norm_constant: 2}\n"
                       b"place: {n_place: 50, gain: 2}\n",
    },
    "fuzz_trial_yaml": {
        "trial.yaml": b"world: {source: cross, tilt_deg: 45, lean: +x+y}\nmodel: 3d-0.2\nseed: 7\n"
                      b"protocol: {kind: explore_then_sample, explore_hours: 4, sample_hours: 4, record_bvc: false}\n"
                      b"robot: {radius: 0.25, height: 0.1, speed: 0.5, turn_rate: 2.1, model_dt: 0.288, n_walk: 10}\n"
                      b"analysis: {gridsize: 50, quantile: 0.1, eps: 1.0, min_samples: 20, d_th: 2.0, extent: arena}\n",
        "inline-model.yaml": b"world: cross-30\nmodel: {base: 2d, place: {n_place: 20}}\nseed: 18446744073709551615\n"
                             b"protocol: {kind: online, sample_hours: 0.5}\nanalysis: {extent: [-5, 5, -5, 5]}\n",
    },
    "fuzz_scan": {
        "ascii.pcd": b"\x00" + pcd("ascii", POINTS),
        "binary.pcd": b"\x00" + pcd("binary", POINTS),
        "compressed.pcd": b"\x00" + pcd("binary_compressed", POINTS),
        "ascii.ply": b"\x01" + PLY_CLOUD_ASCII,
        "binary.ply": b"\x01" + PLY_CLOUD_BINARY,
        "kitti.bin": b"\x02" + struct.pack("<8f", 1, 2, 3, 0.5, -1, -2, -3, 0.25),
    },
    "fuzz_poses": {
        "kitti.txt": b"\x00" + b"1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1.5 0 1 0 0 0 0 1 0\n",
        "tum.txt": b"\x01" + b"# t x y z qx qy qz qw\n1.0 0 0 0 0 0 0 1\n1.1 0.5 0 0 0 0 0.0998 0.995\n",
        "matrix.txt": b"\x02" + b"1,0,0,0,\n0,1,0,0,\n0,0,1,0,\n0,0,0,2.5,\n",
        "auto.txt": b"\x03" + b"1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n",
    },
    "fuzz_scan_list": {
        "extrinsics.txt": b"\x00" + b"# base from sensor\n1 0 0 0.1\n0 1 0 0\n0 0 1 0.3\n0 0 0 1\n",
        "list.txt": b"\x01" + b"# scans\nscan1.pcd 0.0\nscan2.pcd, 0.1\n",
    },
    "fuzz_mesh_check": {
        "mesh.ply": b"\x00" + PLY_MESH,
        "binary.ply": b"\x00" + PLY_CLOUD_BINARY,
        "mesh.obj": b"\x01" + CUBE_OBJ,
        "binary.stl": b"\x02" + STL_BINARY,
        "ascii.stl": b"\x02" + STL_ASCII,
        # A regression seed found by the fuzzer: an element with a huge count and no properties
        # (once walked instance by instance: a timeout).
        "timeout-element-without-properties.ply": base64.b64decode(
            "AHBseQpmb3JtYXQgYXNjaWkgMS4wCmNvbW1lbnQgYSB0cmlhbmdsZQplbGVtZW50IHZlcnRleAAAAAAAAAAAAAAAAXVpbnQ4AAD//wLo"
            "AAAAACAzNzc3Nzc3Nzc3NzdlbmRfaGVhZGVyCjAgMCAwCjEgMCAwCjAgMSAw9szfz9/O38sK"),
    },
}


def bag_seeds():
    """MCAP files and CDR messages from the tests' independent writers; ROS 1 bags and messages from
    Debian's python3-rosbag (left out when it is not installed)."""
    import sys
    import tempfile
    sys.path.insert(0, str(SOURCE / "test" / "python"))
    import bag_writers as bw
    xyz = [("x", 0, 7, 1), ("y", 4, 7, 1), ("z", 8, 7, 1)]
    data = b"".join(struct.pack("<fff", *p[:3]) for p in POINTS)
    cloud = bw.cdr_cloud(1.5, "lidar", 1, 3, xyz, 12, data)
    cloud_be = bw.cdr_cloud(1.5, "lidar", 1, 3, xyz, 12, b"".join(struct.pack(">fff", *p[:3]) for p in POINTS),
                            big=True)
    odom = bw.cdr_odometry(1.5, "map", "lidar", (1, 2, 3), (0, 0, 0.6, 0.8))
    tf = bw.cdr_tf([(1.5, "map", "lidar", (1, 2, 3), (0, 0, 0.6, 0.8))])
    channels = [(0, "/points", "sensor_msgs/msg/PointCloud2"), (1, "/odom", "nav_msgs/msg/Odometry"),
                (2, "/tf", "tf2_msgs/msg/TFMessage")]
    msgs = [(0, 1500000000, cloud), (1, 1500000000, odom), (2, 1500000000, tf)]
    mcaps = {}
    with tempfile.TemporaryDirectory() as folder:
        for name, kw in {"zstd.mcap": {}, "lz4.mcap": {"compression": "lz4"}, "plain.mcap": {"chunked": False}}.items():
            path = pathlib.Path(folder) / name
            bw.mcap(path, channels, msgs, **kw)
            mcaps[name] = path.read_bytes()
    seeds = {"fuzz_mcap": mcaps,
             "fuzz_cdr": {"cloud": b"\x00" + cloud, "cloud-be": b"\x00" + cloud_be, "odom": b"\x01" + odom,
                          "pose": b"\x02" + odom[:4 + 4 + 4 + 8 + 56], "tf": b"\x03" + tf}}
    try:
        import io
        import rosbag
        import rospy
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import PointCloud2, PointField
    except ImportError:
        print("make_corpus: no python3-rosbag: the ROS 1 seeds are left out")
        return seeds
    c = PointCloud2(height=1, width=3, point_step=12, row_step=36, data=data,
                    fields=[PointField(name=n, offset=o, datatype=d, count=k) for n, o, d, k in xyz])
    c.header.stamp, c.header.frame_id = rospy.Time(1, 5), "lidar"
    o = Odometry()
    o.header.stamp, o.header.frame_id, o.child_frame_id = rospy.Time(1, 5), "map", "lidar"
    o.pose.pose.orientation.w = 1.0
    def serialized(m):
        b = io.BytesIO()
        m.serialize(b)
        return b.getvalue()
    with tempfile.TemporaryDirectory() as folder:
        path = pathlib.Path(folder) / "x.bag"
        with rosbag.Bag(str(path), "w") as bag:
            bag.write("/points", c, rospy.Time(1, 5))
            bag.write("/odom", o, rospy.Time(1, 5))
        plain = path.read_bytes()
        with rosbag.Bag(str(path), "w", compression="lz4") as bag:
            bag.write("/points", c, rospy.Time(1, 5))
        packed = path.read_bytes()
    seeds["fuzz_bag"] = {"plain.bag": b"\x00" + plain, "lz4.bag": b"\x00" + packed,
                         "cloud": b"\x01" + serialized(c), "odom": b"\x02" + serialized(o)}
    return seeds


def main():
    if CORPUS.exists():
        shutil.rmtree(CORPUS)
    SEEDS.update(bag_seeds())
    for target, files in SEEDS.items():
        (CORPUS / target).mkdir(parents=True)
        for name, data in files.items():
            (CORPUS / target / name).write_bytes(data)
    print(f"{sum(len(f) for f in SEEDS.values())} seeds for {len(SEEDS)} fuzzers")


if __name__ == "__main__":
    main()
