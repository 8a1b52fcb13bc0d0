"""Bags that other tools read as their own, and bags as other tools write them (docs/ros.md#formats).

Our MCAP files read by the official TypeScript MCAP library (@mcap/core, from npm: test/js/read_mcap.mjs)
record by record and through the summary and indexes, against an independent reader written here from the
specification; `export-scans --format ros2` as a ROS 2 bag folder; and MCAP files and ROS 2 / ROS 1 bags
crafted here as other writers leave them: no footer (a crashed recording), attachments and metadata
records, channels without schema or without messages, a summary with message indexes, 4 MB of zeros in a
~150-byte zstd chunk, rosbag2's zstd FILE and MESSAGE compression, a bare .db3, a ROS 1 bag of format 1.2."""
import json
import pathlib
import shutil
import sqlite3
import struct
import subprocess
import zlib

import numpy as np
import pytest

import bag_writers as bw
from conftest import SOURCE_DIR

bvc3d = pytest.importorskip("bvc3d")

READ_MCAP = SOURCE_DIR / "test" / "js" / "read_mcap.mjs"
HAVE_MCAP_CORE = shutil.which("node") and (SOURCE_DIR / "node_modules" / "@mcap" / "core").is_dir()


def spec_messages(path):
    """The messages of an MCAP file by an independent reader of the specification (the data section, chunks
    decompressed by Debian's zstd, CRCs checked): [topic, log time, sha256] in file order, and the summary's
    record opcodes."""
    import hashlib
    b = path.read_bytes()
    assert b[:8] == bw.MAGIC and b[-8:] == bw.MAGIC
    topics, out = {}, []

    def walk(data, pos, end):
        while pos < end:
            op, n = struct.unpack_from("<BQ", data, pos)
            c = data[pos + 9:pos + 9 + n]
            if op == 0x04:
                cid = struct.unpack_from("<H", c)[0]
                tl = struct.unpack_from("<I", c, 4)[0]
                topics[cid] = c[8:8 + tl].decode()
            elif op == 0x05:
                cid, _, log_time = struct.unpack_from("<HIQ", c)
                out.append([topics[cid], str(log_time), hashlib.sha256(c[22:]).hexdigest()])
            elif op == 0x06:
                size, crc = struct.unpack_from("<QI", c, 16)
                cl = struct.unpack_from("<I", c, 28)[0]
                rl = struct.unpack_from("<Q", c, 32 + cl)[0]
                packed = c[40 + cl:40 + cl + rl]
                inner = subprocess.run(["zstd", "-d", "-q", "-c"], input=packed, capture_output=True,
                                       check=True).stdout
                assert len(inner) == size and zlib.crc32(inner) == crc
                walk(inner, 0, len(inner))
            elif op == 0x0F:
                assert struct.unpack_from("<I", c)[0] == zlib.crc32(data[:pos])
                return pos + 9 + n
            pos += 9 + n

    summary_at = walk(b, 8, len(b))
    summary_start, offsets_start, crc = struct.unpack_from("<QQI", b, len(b) - 8 - 20)
    assert summary_start == summary_at
    assert crc == zlib.crc32(b[summary_start:len(b) - 8 - 4])
    ops = []
    pos = summary_start
    while pos < offsets_start:
        op, n = struct.unpack_from("<BQ", b, pos)
        ops.append(op)
        pos += 9 + n
    return out, ops


def read_with_mcap_core(path):
    proc = subprocess.run(["node", str(READ_MCAP), str(path)], capture_output=True, text=True, timeout=300,
                          cwd=SOURCE_DIR)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


@pytest.mark.skipif(not HAVE_MCAP_CORE, reason="needs node and @mcap/core (`npm ci` installs it)")
def test_mcap_export_is_read_by_the_official_library(tmp_path, cli):
    # About 10 MB of clouds: several chunks of ~4 MB, each with its message indexes.
    cli("export-scans", "--world", "cross", "--hours", "0.01", "--seed", "3", "--format", "mcap", "--out",
        tmp_path / "walk.mcap", check=True)
    mine, summary_ops = spec_messages(tmp_path / "walk.mcap")
    assert summary_ops.count(0x08) >= 2 and 0x0B in summary_ops and 0x03 in summary_ops and 0x04 in summary_ops
    got = read_with_mcap_core(tmp_path / "walk.mcap")
    assert got["profile"] == "ros2"
    assert got["stream"] == mine  # record by record: the same messages, bytes and times
    assert sorted(got["indexed"]) == sorted(mine)  # through the index: all of them...
    times = [int(m[1]) for m in got["indexed"]]
    assert times == sorted(times)  # ...in log-time order
    n = len(mine) // 3
    assert got["chunks"] == summary_ops.count(0x08) and got["chunks"] >= 2
    s = got["statistics"]
    assert s["messageCount"] == 3 * n and s["chunkCount"] == got["chunks"] and s["channelCount"] == 3
    assert sorted(s["channelMessageCounts"].values()) == [n, n, n]
    assert s["messageStartTime"] == str(min(times)) and s["messageEndTime"] == str(max(times))
    kinds = {c["topic"]: (c["schema"], c["schemaEncoding"], c["encoding"]) for c in got["channels"]}
    assert kinds == {"/points": ("sensor_msgs/msg/PointCloud2", "ros2msg", "cdr"),
                     "/odom": ("nav_msgs/msg/Odometry", "ros2msg", "cdr"),
                     "/tf": ("tf2_msgs/msg/TFMessage", "ros2msg", "cdr")}
    assert all("reliability: 1" in c["metadata"]["offered_qos_profiles"] for c in got["channels"])


def test_ros2_export_is_a_bag_folder(tmp_path, cli):
    yaml = pytest.importorskip("yaml")
    args = ["export-scans", "--world", "cross", "--hours", "0.004", "--seed", "3"]
    cli(*args, "--format", "mcap", "--out", tmp_path / "walk.mcap", check=True)
    cli(*args, "--format", "ros2", "--out", tmp_path / "walk", check=True)
    assert sorted(p.name for p in (tmp_path / "walk").iterdir()) == ["metadata.yaml", "walk_0.mcap"]
    # The same bytes as the .mcap export: one writer.
    assert (tmp_path / "walk" / "walk_0.mcap").read_bytes() == (tmp_path / "walk.mcap").read_bytes()
    mine, _ = spec_messages(tmp_path / "walk" / "walk_0.mcap")
    info = yaml.safe_load((tmp_path / "walk" / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    times = [int(m[1]) for m in mine]
    assert info["version"] == 5 and info["storage_identifier"] == "mcap"
    assert info["relative_file_paths"] == ["walk_0.mcap"] and info["message_count"] == len(mine)
    assert info["starting_time"]["nanoseconds_since_epoch"] == min(times)
    assert info["duration"]["nanoseconds"] == max(times) - min(times)
    counts = {t["topic_metadata"]["name"]: t["message_count"] for t in info["topics_with_message_count"]}
    assert counts == {t: sum(m[0] == t for m in mine) for t in ("/points", "/odom", "/tf")}
    assert all(t["topic_metadata"]["serialization_format"] == "cdr" for t in info["topics_with_message_count"])
    assert info["files"][0]["path"] == "walk_0.mcap" and info["files"][0]["message_count"] == len(mine)
    a = bvc3d.Recording.open_bag(tmp_path / "walk", "/points", pose_topic="/odom").replay("3d-3l")
    b = bvc3d.Recording.open_bag(tmp_path / "walk.mcap", "/points", pose_topic="/odom").replay("3d-3l")
    np.testing.assert_array_equal(a["bvc_rates"], b["bvc_rates"])
    assert "ROS 2 bag (mcap)" in cli("bag-info", tmp_path / "walk", check=True).stdout
    # An existing bag folder is refused unless --force (experiments.md#outputs-that-exist), as a bag file is;
    # with --force it is written again over itself, but never over a folder that holds anything else.
    again = cli(*args, "--format", "ros2", "--out", tmp_path / "walk")
    assert again.returncode == 2 and "--force" in again.stderr, again.stderr
    cli(*args, "--format", "ros2", "--out", tmp_path / "walk", "--force", check=True)
    assert sorted(p.name for p in (tmp_path / "walk").iterdir()) == ["metadata.yaml", "walk_0.mcap"]
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "notes.txt").write_text("mine")
    for force in ([], ["--force"]):
        bad = cli(*args, "--format", "ros2", "--out", tmp_path / "other", *force)
        assert bad.returncode == 2 and "notes.txt" in bad.stderr
        assert sorted(p.name for p in (tmp_path / "other").iterdir()) == ["notes.txt"]
    # A ROS 2 bag is a folder: a name that ends as a bag file's is refused.
    bad = cli(*args, "--format", "ros2", "--out", tmp_path / "walk2.mcap")
    assert bad.returncode == 2 and "--format mcap for a .mcap file" in bad.stderr, bad.stderr
    assert not (tmp_path / "walk2.mcap").exists()


# ---- MCAP and ROS 2 bags as other writers leave them (crafted here) ----

from test_bags import check_recording, cloud_bag_messages  # noqa: E402

CHANNELS = [(0, "/points", "sensor_msgs/msg/PointCloud2"), (1, "/odom", "nav_msgs/msg/Odometry")]


def messages(seed=1):
    clouds, odoms, expected, poses = cloud_bag_messages(np.random.default_rng(seed), False)
    return [(0, t, d) for t, d in clouds] + [(1, t, d) for t, d in odoms], expected, poses


def crafted(path, data_records, summary_records=(), footer=True):
    """An MCAP file: magic, header, the records given, DataEnd and (with `footer`) the summary given and a
    Footer that points at it."""
    out = bytearray(bw.MAGIC) + bw.record(0x01, bw._s("ros2") + bw._s("crafted"))
    for r in data_records:
        out += r
    out += bw.record(0x0F, struct.pack("<I", 0))
    if footer:
        start = len(out) if summary_records else 0
        for r in summary_records:
            out += r
        out += bw.record(0x02, struct.pack("<QQI", start, 0, 0)) + bw.MAGIC
    pathlib.Path(path).write_bytes(bytes(out))


def definitions(channels=CHANNELS):
    return [r for cid, topic, typ in channels for r in (
        bw.record(0x03, struct.pack("<H", cid + 1) + bw._s(typ) + bw._s("ros2msg") + bw._s("")),
        bw.record(0x04, struct.pack("<HH", cid, cid + 1) + bw._s(topic) + bw._s("cdr") + struct.pack("<I", 0)))]


def message_records(msgs):
    return [bw.record(0x05, struct.pack("<HIQQ", c, i, t, t) + d) for i, (c, t, d) in enumerate(msgs)]


def test_mcap_without_footer_is_read_to_its_last_complete_record(tmp_path, cli):
    msgs, expected, poses = messages()
    records = definitions() + message_records(msgs)
    crafted(tmp_path / "whole.mcap", records)
    whole = (tmp_path / "whole.mcap").read_bytes()
    # A recording that stopped inside the last odometry message (the last record): no DataEnd, no footer.
    cut = whole[:whole.index(records[-1]) + len(records[-1]) - 10]
    (tmp_path / "crashed.mcap").write_bytes(cut)
    info = cli("bag-info", tmp_path / "crashed.mcap")
    assert info.returncode == 0, info.stderr
    assert "warning" in info.stderr and "no footer" in info.stderr and "truncated" in info.stderr
    assert "5 messages" in info.stdout  # 3 clouds and 2 of the 3 poses
    rec = bvc3d.Recording.open_bag(tmp_path / "crashed.mcap", "/points", pose_topic="/odom", time_tolerance=0.15)
    assert len(rec) == 3
    # Cut between records: every message there, still a warning.
    (tmp_path / "stopped.mcap").write_bytes(whole[:whole.index(records[-1]) + len(records[-1])])
    info = cli("bag-info", tmp_path / "stopped.mcap")
    assert info.returncode == 0 and "no footer" in info.stderr and "6 messages" in info.stdout
    check_recording(bvc3d.Recording.open_bag(tmp_path / "stopped.mcap", "/points", pose_topic="/odom"), expected,
                    poses)
    # Nothing complete: refused, naming the file.
    (tmp_path / "header.mcap").write_bytes(whole[:60])
    bad = cli("bag-info", tmp_path / "header.mcap")
    assert bad.returncode == 2 and "header.mcap" in bad.stderr and "no complete message" in bad.stderr


def test_mcap_attachments_metadata_and_schemaless_channels(tmp_path, cli):
    msgs, expected, poses = messages()
    attachment = bw.record(0x09, struct.pack("<QQ", 5, 5) + bw._s("calib.yaml") + bw._s("text/yaml") +
                           struct.pack("<Q", 3) + b"a: 1" [:3] + struct.pack("<I", 0))
    metadata = bw.record(0x0C, bw._s("robot") + struct.pack("<I", len(bw._s("k") + bw._s("v"))) + bw._s("k") +
                         bw._s("v"))
    no_schema = bw.record(0x04, struct.pack("<HH", 7, 0) + bw._s("/raw") + bw._s("cdr") + struct.pack("<I", 0))
    crafted(tmp_path / "x.mcap", [attachment, metadata] + definitions() + [no_schema] + message_records(msgs) +
            [bw.record(0x05, struct.pack("<HIQQ", 7, 0, 5, 5) + b"\0\1\0\0")])
    check_recording(bvc3d.Recording.open_bag(tmp_path / "x.mcap", "/points", pose_topic="/odom"), expected, poses)
    info = cli("bag-info", tmp_path / "x.mcap", check=True).stdout
    assert "/raw" in info and "3 topics, 7 messages" in info
    bad = cli("replay", "--bag", tmp_path / "x.mcap", "--cloud-topic", "/raw", "--pose-topic", "/odom", "--model",
              "2d", "--out", tmp_path / "r.h5")
    assert bad.returncode == 2 and "/raw" in bad.stderr and "no schema" in bad.stderr
    # Schema id 0 is reserved: a schema record may not take it.
    crafted(tmp_path / "zero.mcap", [bw.record(0x03, struct.pack("<H", 0) + bw._s("x/msg/Y") + bw._s("ros2msg") +
                                               bw._s(""))])
    bad = cli("bag-info", tmp_path / "zero.mcap")
    assert bad.returncode == 2 and "id 0" in bad.stderr


def test_mcap_channels_only_in_the_summary_are_listed(tmp_path, cli):
    msgs, _, _ = messages()
    quiet = [(5, "/diagnostics", "diagnostic_msgs/msg/DiagnosticArray"), (6, "/events", "std_msgs/msg/String")]
    crafted(tmp_path / "x.mcap", definitions() + message_records(msgs), definitions(CHANNELS + quiet))
    info = cli("bag-info", tmp_path / "x.mcap", check=True).stdout
    assert "4 topics, 6 messages" in info
    assert [line.split()[:4] for line in info.splitlines() if line.startswith("/events")] == \
        [["/events", "std_msgs/msg/String", "cdr", "0"]]


def test_zstd_chunk_of_zeros_is_read(tmp_path, cli):
    """4 MB of zeros compress to ~150 bytes (a ratio near 28 000): bounded by the declared size, not a ratio."""
    zeros = bw.record(0x05, struct.pack("<HIQQ", 0, 0, 10, 10) + bytes(4 << 20))
    inner = b"".join(definitions([(0, "/blob", "std_msgs/msg/ByteMultiArray")])) + zeros
    packed = bw.compress(inner, "zstd")
    assert len(packed) < 1000
    chunk = bw.record(0x06, struct.pack("<QQQI", 10, 10, len(inner), zlib.crc32(inner)) + bw._s("zstd") +
                      struct.pack("<Q", len(packed)) + packed)
    crafted(tmp_path / "zeros.mcap", [chunk])
    info = cli("bag-info", tmp_path / "zeros.mcap", check=True).stdout
    assert "1 topics, 1 messages" in info and "/blob" in info
    # A chunk that claims more than it holds is still refused.
    lying = bw.record(0x06, struct.pack("<QQQI", 10, 10, len(inner) + 1, zlib.crc32(inner)) + bw._s("zstd") +
                      struct.pack("<Q", len(packed)) + packed)
    crafted(tmp_path / "lying.mcap", [lying])
    bad = cli("bag-info", tmp_path / "lying.mcap")
    assert bad.returncode == 2 and "chunk 0" in bad.stderr and "declared" in bad.stderr
    # A frame that does not say its size, in a chunk that claims 8 GB: refused as the data runs out, with no
    # 8 GB buffer allocated first (the buffer grows with what the data holds).
    bare = subprocess.run(["zstd", "-q", "-c", "--no-content-size"], input=inner, capture_output=True,
                          check=True).stdout
    huge = bw.record(0x06, struct.pack("<QQQI", 10, 10, 8 << 30, zlib.crc32(inner)) + bw._s("zstd") +
                     struct.pack("<Q", len(bare)) + bare)
    crafted(tmp_path / "huge.mcap", [huge])
    bad = cli("bag-info", tmp_path / "huge.mcap", timeout=60)
    assert bad.returncode == 2 and "chunk 0" in bad.stderr and "declared" in bad.stderr


def test_bag_info_reads_the_index_not_the_chunks(tmp_path, cli):
    # ~200 scans in ~9 chunks: the first 100 /tf messages (which bag-info reads for the links) are in the first.
    cli("export-scans", "--world", "cross", "--hours", "0.02", "--seed", "3", "--format", "mcap", "--out",
        tmp_path / "walk.mcap", check=True)
    good = cli("bag-info", tmp_path / "walk.mcap", check=True).stdout
    data = bytearray((tmp_path / "walk.mcap").read_bytes())
    # Spoil the last chunk's compressed records (its CRC no longer holds): the summary, the message indexes
    # and the first chunk (the first cloud) are all bag-info reads, so it does not notice; a replay does.
    chunk_starts = []
    pos = 8
    while pos < len(data):
        op, n = struct.unpack_from("<BQ", data, pos)
        if op == 0x06:
            chunk_starts.append((pos, n))
        if op == 0x0F:
            break
        pos += 9 + n
    assert len(chunk_starts) >= 6
    at, n = chunk_starts[-1]
    middle = at + 9 + n // 2
    data[middle:middle + 64] = bytes(64)
    (tmp_path / "spoiled.mcap").write_bytes(bytes(data))
    info = cli("bag-info", tmp_path / "spoiled.mcap")
    assert info.returncode == 0, info.stderr
    assert info.stdout.splitlines()[1:] == good.splitlines()[1:]
    bad = cli("replay", "--bag", tmp_path / "spoiled.mcap", "--cloud-topic", "/points", "--pose-topic", "/odom",
              "--model", "2d", "--out", tmp_path / "r.h5")
    assert bad.returncode == 2 and f"chunk {len(chunk_starts) - 1}" in bad.stderr


def sqlite_folder(tmp_path, name="bag", storage_format="cdr"):
    msgs, expected, poses = messages()
    topics = [(1, "/points", "sensor_msgs/msg/PointCloud2"), (2, "/odom", "nav_msgs/msg/Odometry")]
    bw.ros2_sqlite(tmp_path / name, topics, [(c + 1, t, d) for c, t, d in msgs], storage_format)
    return tmp_path / name, expected, poses


def test_rosbag2_zstd_file_and_message_compression(tmp_path, cli):
    folder, expected, poses = sqlite_folder(tmp_path, "file")
    db = folder / "bag_0.db3"
    subprocess.run(["zstd", "-q", "--rm", "-o", f"{db}.zstd", str(db)], check=True)  # rosbag2's name
    meta = (folder / "metadata.yaml").read_text().replace("- bag_0.db3", "- bag_0.db3.zstd")
    (folder / "metadata.yaml").write_text(meta + "  compression_format: zstd\n  compression_mode: FILE\n")
    check_recording(bvc3d.Recording.open_bag(folder, "/points", pose_topic="/odom"), expected, poses)
    assert "files compressed with zstd" in cli("bag-info", folder, check=True).stdout

    folder, expected, poses = sqlite_folder(tmp_path, "message")
    con = sqlite3.connect(folder / "bag_0.db3")
    for row, data in con.execute("SELECT id, data FROM messages").fetchall():
        packed = subprocess.run(["zstd", "-q", "-c"], input=bytes(data), capture_output=True, check=True).stdout
        con.execute("UPDATE messages SET data = ? WHERE id = ?", (packed, row))
    con.commit()
    con.close()
    meta = (folder / "metadata.yaml").read_text()
    (folder / "metadata.yaml").write_text(meta + "  compression_format: zstd\n  compression_mode: MESSAGE\n")
    check_recording(bvc3d.Recording.open_bag(folder, "/points", pose_topic="/odom"), expected, poses)

    (folder / "metadata.yaml").write_text(meta + "  compression_format: lz4\n  compression_mode: MESSAGE\n")
    bad = cli("bag-info", folder)
    assert bad.returncode == 2 and "lz4" in bad.stderr and "metadata.yaml" in bad.stderr


def test_unknown_serialization_is_one_rule_for_sqlite_and_mcap(tmp_path, cli):
    """rosbag2's wrong_rmw_test: metadata.yaml and the storage name another serialization than cdr. The
    bag is listed (with that format), and a topic of it is refused when read, whatever the storage."""
    sq, _, _ = sqlite_folder(tmp_path, "sqlite", storage_format="wrong_format")
    mc = tmp_path / "mcap"
    mc.mkdir()
    msgs, _, _ = messages()
    bw.mcap(mc / "bag_0.mcap", CHANNELS, msgs)
    (mc / "metadata.yaml").write_text((sq / "metadata.yaml").read_text().replace("sqlite3", "mcap")
                                      .replace("bag_0.db3", "bag_0.mcap"))
    for folder in (sq, mc):
        info = cli("bag-info", folder)
        assert info.returncode == 0, info.stderr
        assert "wrong_format" in info.stdout
        bad = cli("replay", "--bag", folder, "--cloud-topic", "/points", "--pose-topic", "/odom", "--model", "2d",
                  "--out", tmp_path / "r.h5")
        assert bad.returncode == 2 and "unknown message encoding 'wrong_format'" in bad.stderr, bad.stderr


def test_storage_without_metadata(tmp_path, cli):
    folder, expected, poses = sqlite_folder(tmp_path)
    # A bare .db3: read from itself.
    check_recording(bvc3d.Recording.open_bag(folder / "bag_0.db3", "/points", pose_topic="/odom"), expected, poses)
    # A folder that lost its metadata.yaml: read from its storage files, as `ros2 bag reindex` would.
    (folder / "metadata.yaml").unlink()
    check_recording(bvc3d.Recording.open_bag(folder, "/points", pose_topic="/odom"), expected, poses)
    # A folder with neither: what is missing, said.
    (tmp_path / "empty").mkdir()
    bad = cli("bag-info", tmp_path / "empty")
    assert bad.returncode == 2 and "without metadata.yaml and without .db3 or .mcap files" in bad.stderr
    subprocess.run(["zstd", "-q", "--rm", "-o", str(folder / "bag_0.db3.zstd"), str(folder / "bag_0.db3")],
                   check=True)
    bad = cli("bag-info", folder)
    assert bad.returncode == 2 and "bag_0.db3.zstd" in bad.stderr and "compressed" in bad.stderr


def test_ros1_bag_format_1_2_is_named(tmp_path, cli):
    (tmp_path / "old.bag").write_bytes(b"#ROSRECORD V1.2\n" + bytes(100))
    bad = cli("bag-info", tmp_path / "old.bag")
    assert bad.returncode == 2 and "ROS 1 bag format 1.2 is not supported" in bad.stderr
