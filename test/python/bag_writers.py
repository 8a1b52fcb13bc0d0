"""Independent writers of the bag formats bvc3d reads, for the tests (they share no code with bvc3d):
CDR encoded by hand (XCDR1: a 4-byte encapsulation header, primitives aligned to their size from its
end), MCAP written from the format specification (records, chunks compressed with lz4 through
python3-lz4 or zstd through Debian's `zstd` program, CRC-32 from zlib), ROS 2 bag folders (SQLite,
rosbag2's tables and metadata.yaml), and ROS 1 bags through Debian's python3-rosbag."""
import pathlib
import sqlite3
import struct
import subprocess
import zlib

import numpy as np

MAGIC = b"\x89MCAP0\r\n"


class Cdr:
    """CDR by hand: each primitive aligned to its size, counted from the end of the 4-byte header."""

    def __init__(self, big=False):
        self.big = big
        self.e = ">" if big else "<"
        self.body = bytearray()

    def align(self, n):
        while len(self.body) % n:
            self.body.append(0)

    def put(self, fmt, *v):
        size = struct.calcsize("<" + fmt[0])
        self.align(size)
        self.body += struct.pack(self.e + fmt, *v)

    def string(self, s):
        b = s.encode() + b"\0"
        self.put("I", len(b))
        self.body += b

    def bytes(self):
        return bytes([0, 0 if self.big else 1, 0, 0]) + bytes(self.body)


def cdr_header(w, stamp, frame):
    sec = int(np.floor(stamp))
    w.put("i", sec)
    w.put("I", int(round((stamp - sec) * 1e9)))
    w.string(frame)


def cdr_cloud(stamp, frame, height, width, fields, point_step, data, big=False):
    """fields: (name, offset, datatype, count)"""
    w = Cdr(big)
    cdr_header(w, stamp, frame)
    w.put("I", height)
    w.put("I", width)
    w.put("I", len(fields))
    for name, offset, datatype, count in fields:
        w.string(name)
        w.put("I", offset)
        w.put("B", datatype)
        w.put("I", count)
    w.put("B", 1 if big else 0)
    w.put("I", point_step)
    w.put("I", point_step * width)
    w.put("I", len(data))
    w.body += data
    w.put("B", 0)
    return w.bytes()


def cdr_odometry(stamp, parent, child, p, q, big=False):
    w = Cdr(big)
    cdr_header(w, stamp, parent)
    w.string(child)
    for v in (*p, *q):  # position x y z, orientation x y z w
        w.put("d", v)
    for _ in range(36 + 6 + 36):
        w.put("d", 0.0)
    return w.bytes()


def cdr_tf(transforms, big=False):
    """transforms: (stamp, parent, child, p, q)"""
    w = Cdr(big)
    w.put("I", len(transforms))
    for stamp, parent, child, p, q in transforms:
        cdr_header(w, stamp, parent)
        w.string(child)
        for v in (*p, *q):
            w.put("d", v)
    return w.bytes()


# ---- MCAP (the format specification) ----

def _s(text):
    b = text.encode()
    return struct.pack("<I", len(b)) + b


def record(op, content):
    return struct.pack("<BQ", op, len(content)) + content


def compress(data, how):
    if how == "lz4":
        import lz4.frame
        return lz4.frame.compress(data)
    if how == "zstd":
        return subprocess.run(["zstd", "-q", "-c"], input=data, capture_output=True, check=True).stdout
    return data


def mcap(path, channels, messages, chunked=True, compression="zstd", chunk_crc=True, lie_size=0,
         compression_name=None, encoding="cdr"):
    """channels: [(id, topic, type)]; messages: [(channel id, log time ns, bytes)]. Schemas ros2msg."""
    out = bytearray(MAGIC)
    out += record(0x01, _s("ros2") + _s("test-writer"))
    defs = b""
    for cid, topic, typ in channels:
        defs += record(0x03, struct.pack("<H", cid + 1) + _s(typ) + _s("ros2msg") + _s(""))
        defs += record(0x04, struct.pack("<HH", cid, cid + 1) + _s(topic) + _s(encoding) + struct.pack("<I", 0))
    msgs = b"".join(record(0x05, struct.pack("<HIQQ", c, i, t, t) + d) for i, (c, t, d) in enumerate(messages))
    if chunked:
        inner = defs + msgs
        packed = compress(inner, compression)
        times = [t for _, t, _ in messages] or [0]
        crc = zlib.crc32(inner) if chunk_crc is True else (chunk_crc or 0)
        body = struct.pack("<QQQI", min(times), max(times), len(inner) + lie_size, crc)
        body += _s(compression_name if compression_name is not None else
                   ("" if compression == "none" else compression))
        body += struct.pack("<Q", len(packed)) + packed
        out += record(0x06, body)
    else:
        out += defs + msgs
    out += record(0x0F, struct.pack("<I", zlib.crc32(bytes(out))))
    out += record(0x02, struct.pack("<QQI", 0, 0, 0))
    out += MAGIC
    pathlib.Path(path).write_bytes(bytes(out))


def ros2_sqlite(folder, topics, messages, storage_format="cdr"):
    """topics: [(id, name, type)]; messages: [(topic id, time ns, bytes)]: a ROS 2 bag folder."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True)
    db = sqlite3.connect(folder / "bag_0.db3")
    db.execute("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
               "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)")
    db.execute("CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
               "data BLOB NOT NULL)")
    for tid, name, typ in topics:
        db.execute("INSERT INTO topics VALUES (?, ?, ?, ?, '')", (tid, name, typ, storage_format))
    for tid, t, data in messages:
        db.execute("INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", (tid, t, data))
    db.commit()
    db.close()
    counts = {tid: sum(1 for m in messages if m[0] == tid) for tid, _, _ in topics}
    lines = ["rosbag2_bagfile_information:", "  version: 5", "  storage_identifier: sqlite3",
             "  relative_file_paths:", "    - bag_0.db3", f"  message_count: {len(messages)}",
             "  topics_with_message_count:"]
    for tid, name, typ in topics:
        lines += ["    - topic_metadata:", f"        name: {name}", f"        type: {typ}",
                  f"        serialization_format: {storage_format}", "        offered_qos_profiles: ''",
                  f"      message_count: {counts[tid]}"]
    (folder / "metadata.yaml").write_text("\n".join(lines) + "\n")


def rotation_quaternion(yaw, pitch=0.0, roll=0.0):
    """(x, y, z, w) of Rz(yaw)·Ry(pitch)·Rx(roll)."""
    cy, sy = np.cos(yaw / 2), np.sin(yaw / 2)
    cp, sp = np.cos(pitch / 2), np.sin(pitch / 2)
    cr, sr = np.cos(roll / 2), np.sin(roll / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


def quaternion_matrix(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
