#!/usr/bin/env python3
"""Writes the corpus cases of ROS bags (bags/): broken MCAP files, ROS 2 bag folders and ROS 1 bags,
each read by `bvc3d replay --bag` (or `bag-info`). The outputs are committed; rerun this after changing
it (the ROS 1 cases need Debian's python3-rosbag and python3-sensor-msgs):

    /usr/bin/python3 test/bad_inputs/make_bag_cases.py
"""
import pathlib
import shutil
import struct
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "python"))
import bag_writers as bw  # noqa: E402

BAGS = HERE / "bags"
F32 = 7
REPLAY = "replay --bag {} --cloud-topic /points --pose-topic /odom --model 2d --out {tmp}"
TF_REPLAY = "replay --bag {} --cloud-topic /points --tf-frames map,lidar --model 2d --out {tmp}"
XYZ = [("x", 0, F32, 1), ("y", 4, F32, 1), ("z", 8, F32, 1)]
CHANNELS = [(0, "/points", "sensor_msgs/msg/PointCloud2"), (1, "/odom", "nav_msgs/msg/Odometry")]


def cloud(stamp, fields=XYZ, step=12, n=40):
    data = b"".join(struct.pack("<fff", 3.0 + i * 0.1, 1.0, 0.0) + bytes(max(step - 12, 0)) for i in range(n))
    return bw.cdr_cloud(stamp, "lidar", 1, n, fields, step, data)


def odom(stamp, q=(0, 0, 0, 1)):
    return bw.cdr_odometry(stamp, "map", "lidar", (0.1 * stamp, 0, 0), q)


def messages(stamps=(1.0, 1.1, 1.2), cloud_of=cloud, odom_of=odom):
    """Logged at 1.0, 1.1, 1.2 s, stamped `stamps`."""
    out = []
    for k, t in enumerate(stamps):
        ns = int(round((1.0 + 0.1 * k) * 1e9))
        out += [(1, ns, odom_of(t)), (0, ns, cloud_of(t))]
    return out


def mcap_bytes(**kw):
    with tempfile.TemporaryDirectory() as folder:
        path = pathlib.Path(folder) / "case.mcap"
        bw.mcap(path, kw.pop("channels", CHANNELS), kw.pop("msgs", None) or messages(), **kw)
        return path.read_bytes()


def tf_gap():
    static = bw.cdr_tf([(0.0, "map", "odom", (0, 0, 0), (0, 0, 0, 1))])
    dyn = [bw.cdr_tf([(t, "odom", "lidar", (t, 0, 0), (0, 0, 0, 1))]) for t in (1.0, 1.1, 2.0)]
    ns = lambda t: int(round(t * 1e9))  # noqa: E731
    msgs = [(0, ns(0.5), static)] + [(1, ns(t), d) for t, d in zip((1.0, 1.1, 2.0), dyn)]
    msgs += [(2, ns(t), cloud(t)) for t in (1.05, 1.5)]
    return mcap_bytes(channels=[(0, "/tf_static", "tf2_msgs/msg/TFMessage"), (1, "/tf", "tf2_msgs/msg/TFMessage"),
                                (2, "/points", "sensor_msgs/msg/PointCloud2")], msgs=msgs)


def good():
    return mcap_bytes()


def empty_rows(t):
    return bw.cdr_cloud(t, "lidar", 3_000_000_000, 0, XYZ, 12, b"")


def truncated_cloud(t):
    return cloud(t)[:60]


# name: (bytes, command, expectations)
MCAP_CASES = {
    "mcap-bad-magic.mcap": (b"\x89MCAQ0\r\n" + good()[8:], REPLAY, "bad magic"),
    "mcap-truncated.mcap": (good()[: len(good()) // 2], REPLAY, "truncated"),
    "mcap-chunk-crc.mcap": (mcap_bytes(chunk_crc=0x1234567), REPLAY, "chunk 0; CRC"),
    "mcap-compressed-size-lies.mcap": (mcap_bytes(lie_size=1000), REPLAY, "chunk 0; declared"),
    "mcap-unknown-compression.mcap": (mcap_bytes(compression="none", compression_name="brotli"), REPLAY, "brotli"),
    "mcap-json-encoding.mcap": (mcap_bytes(encoding="json"), REPLAY, "/points; message 0; unknown message encoding"),
    "mcap-missing-topic.mcap": (good(), REPLAY.replace("/points", "/lidar"), "/lidar"),
    "mcap-no-z.mcap": (mcap_bytes(msgs=messages(cloud_of=lambda t: cloud(t, XYZ[:2]))), REPLAY,
                       "/points; message 0; 'z'"),
    "mcap-point-step-small.mcap": (mcap_bytes(msgs=messages(cloud_of=lambda t: cloud(t, step=8, n=3))), REPLAY,
                                   "/points; message 0; point step"),
    "mcap-stamps-out-of-order.mcap": (mcap_bytes(msgs=messages(stamps=(1.0, 1.15, 1.12))), REPLAY,
                                      "/points; message 2; out of order"),
    "mcap-truncated-message.mcap": (mcap_bytes(msgs=messages(cloud_of=truncated_cloud)), REPLAY,
                                    "/points; message 0; truncated"),
    # Billions of rows without points (fuzz_cdr's finding: once walked row by row).
    "mcap-empty-rows.mcap": (mcap_bytes(msgs=messages(cloud_of=empty_rows)), REPLAY,
                             "/points; message 0; empty cloud"),
    "mcap-bad-quaternion.mcap": (mcap_bytes(msgs=messages(odom_of=lambda t: odom(t, (0, 0, 0, 0.5)))), REPLAY,
                                 "/odom; message 0; quaternion"),
    "mcap-tf-gap.mcap": (tf_gap(), TF_REPLAY, "/points; message 1; gap"),
    "mcap-bag-info-truncated.mcap": (good()[:100], "bag-info {}", "truncated"),
}


def ros2_folder(name, storage_format="cdr", corrupt=False):
    folder = BAGS / name
    shutil.rmtree(folder, ignore_errors=True)
    bw.ros2_sqlite(folder, [(1, "/points", "sensor_msgs/msg/PointCloud2"), (2, "/odom", "nav_msgs/msg/Odometry")],
                   [(1 if c == 0 else 2, t, d) for c, t, d in messages()], storage_format)
    if corrupt:
        (folder / "bag_0.db3").write_bytes(b"SQLite format 3\0" + bytes(range(256)) * 8)


def ros1_records(data, start=13):
    """(start, header fields, data start, data length) of each record from `start`: the ROS 1 bag format
    2.0 (after its 13-byte "#ROSBAG V2.0" line, records of a uint32 header length, the header's
    length-prefixed name=value fields, a uint32 data length and the data)."""
    records, pos = [], start
    while pos < len(data):
        header_length = struct.unpack_from("<I", data, pos)[0]
        header, fields, f = data[pos + 4:pos + 4 + header_length], {}, 0
        while f < header_length:
            n = struct.unpack_from("<I", header, f)[0]
            name, _, value = bytes(header[f + 4:f + 4 + n]).partition(b"=")
            fields[name] = value
            f += 4 + n
        data_length = struct.unpack_from("<I", data, pos + 4 + header_length)[0]
        records.append((pos, fields, pos + 8 + header_length, data_length))
        pos += 8 + header_length + data_length
    return records


def ros1_bags():
    try:
        import rosbag
        import rospy
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import PointCloud2, PointField
    except ImportError:
        print("make_bag_cases: no python3-rosbag/python3-sensor-msgs: the ROS 1 cases are left as they are")
        return {}

    def written(compression):
        path = pathlib.Path(tempfile.mkdtemp()) / "case.bag"
        with rosbag.Bag(str(path), "w", compression=compression) as bag:
            for i in range(3):
                t = rospy.Time.from_sec(1.0 + 0.1 * i)
                c = PointCloud2()
                c.header.stamp, c.header.frame_id = t, "lidar"
                c.height, c.width, c.point_step, c.row_step = 1, 40, 12, 480
                c.fields = [PointField(name=n, offset=o, datatype=d, count=k) for n, o, d, k in XYZ]
                c.data = b"".join(struct.pack("<fff", 3.0 + k * 0.1, 1.0, 0.0) for k in range(40))
                o = Odometry()
                o.header.stamp, o.header.frame_id, o.child_frame_id = t, "map", "lidar"
                o.pose.pose.orientation.w = 1.0
                bag.write("/odom", o, t)
                bag.write("/points", c, t)
        data = path.read_bytes()
        shutil.rmtree(path.parent)
        return data

    data = written("none")
    # A cloud whose data array claims 2 GB (the message itself is whole): refused before any allocation.
    first = struct.pack("<I", 480) + struct.pack("<fff", 3.0, 1.0, 0.0)
    at = data.index(first)
    lying = data[:at] + struct.pack("<I", 0x7FFFFFFF) + data[at + 4:]
    # Inside the first chunk: a message record whose data runs 100 kB past the chunk's end (rosbag storage
    # would copy that far); an index entry pointing at the chunk's first record, a connection.
    chunk = next(r for r in ros1_records(data) if r[1][b"op"] == b"\x05")
    inner = next(r for r in ros1_records(data[chunk[2]:chunk[2] + chunk[3]], 0) if r[1][b"op"] == b"\x02")
    length_at = chunk[2] + inner[2] - 4
    message_lies = bytearray(data)
    struct.pack_into("<I", message_lies, length_at, inner[3] + 100000)
    index = next(r for r in ros1_records(data) if r[1][b"op"] == b"\x04")
    index_lies = bytearray(data)
    struct.pack_into("<I", index_lies, index[2] + 8, 0)
    # An lz4 chunk whose frame does not start with lz4's magic number.
    lz4 = bytearray(written("lz4"))
    lz4_chunk = next(r for r in ros1_records(lz4) if r[1][b"op"] == b"\x05")
    lz4[lz4_chunk[2]:lz4_chunk[2] + 4] = b"\0\0\0\0"
    return {
        "ros1-message-length-lies.bag": (bytes(message_lies), REPLAY,
                                         f"chunk at byte {chunk[0]}, byte {inner[2] - 4} of its uncompressed "
                                         "data; a record's data claims"),
        "ros1-index-offset-lies.bag": (bytes(index_lies), REPLAY,
                                       "the index points at byte 0 of the chunk before it; no message record starts"),
        "ros1-lz4-not-lz4.bag": (bytes(lz4), REPLAY, "chunk's lz4 data cannot be decompressed"),
        "ros1-cloud-length-lies.bag": (lying, REPLAY, "/points; message 0; truncated or corrupt"),
        "ros1-truncated.bag": (data[: len(data) * 2 // 3], REPLAY, "ros1-truncated.bag"),
        "ros1-not-a-bag.bag": (b"#ROSBAG V2.0\n" + bytes(range(256)) * 4, REPLAY, "not a readable ROS 1 bag"),
        "ros1-wrong-pose-type.bag": (data, REPLAY.replace("/odom", "/points"), "/points; PointCloud2; not nav_msgs"),
    }


def main():
    BAGS.mkdir(exist_ok=True)
    old = {line.split("|")[0].strip(): line for line in (BAGS / "cases.txt").read_text().splitlines()
           if line.startswith("ros1-")} if (BAGS / "cases.txt").exists() else {}
    lines = ["# Made by ../make_bag_cases.py: ROS bags read as recordings (FILE | COMMAND | EXPECT)."]
    cases = dict(MCAP_CASES)
    ros1 = ros1_bags()
    cases.update(ros1)
    for name, (data, cmd, expect) in cases.items():
        (BAGS / name).write_bytes(data)
        lines.append(f"{name} | {cmd} | {expect}")
    if not ros1:
        lines += list(old.values())
    ros2_folder("ros2-json-encoding", storage_format="json")
    lines.append(f"ros2-json-encoding | {REPLAY} | ros2-json-encoding; /points; message 0; "
                 "unknown message encoding 'json'")
    ros2_folder("ros2-corrupt-db", corrupt=True)
    lines.append(f"ros2-corrupt-db | {REPLAY} | bag_0.db3; SQLite")
    ros2_folder("ros2-lz4-compressed")
    with open(BAGS / "ros2-lz4-compressed" / "metadata.yaml", "a") as f:
        f.write("  compression_format: lz4\n  compression_mode: FILE\n")
    lines.append(f"ros2-lz4-compressed | bag-info {{}} | metadata.yaml; compression_format; 'lz4'")
    (BAGS / "ros1-format-1.2.bag").write_bytes(b"#ROSRECORD V1.2\n" + bytes(64))
    lines.append(f"ros1-format-1.2.bag | {REPLAY} | ros1-format-1.2.bag; ROS 1 bag format 1.2 is not supported")
    (BAGS / "cases.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
