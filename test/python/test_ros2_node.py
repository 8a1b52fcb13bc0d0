"""The bvc3d_ros2 node on a live DDS graph (docs/ros.md#the-ros-2-node), loopback only: Cyclone DDS bound
to 127.0.0.1 with multicast off (its own configuration file), a domain of its own. A test peer on Cyclone's
C API (test/ros2/ros2_peer.cpp) plays an exported bag as ROS 2 messages (PointCloud2 best effort, as a
LiDAR driver publishes, and Odometry) and records what the node publishes; the node's rates against
`bvc3d replay` of the same bag, its revisits against SPEC 15's rule computed here in numpy, and a clean
exit on SIGINT."""
import os
import pathlib
import random
import signal
import subprocess
import time

import numpy as np
import pytest

from conftest import CLI
from test_ros_node import cosine_revisits, read_recorded, wait_for

h5py = pytest.importorskip("h5py")
NODE = pathlib.Path(CLI).parent / "bvc3d_ros2"
PEER = pathlib.Path(CLI).parent / "test" / "ros2_peer"

LOOPBACK = """<?xml version="1.0" encoding="UTF-8"?>
<CycloneDDS xmlns="https://cdds.io/config">
  <Domain Id="any">
    <General>
      <Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces>
      <AllowMulticast>false</AllowMulticast>
    </General>
    <Discovery>
      <ParticipantIndex>auto</ParticipantIndex>
      <MaxAutoParticipantIndex>20</MaxAutoParticipantIndex>
      <Peers><Peer address="127.0.0.1"/></Peers>
    </Discovery>
  </Domain>
</CycloneDDS>
"""


@pytest.fixture
def dds_env(tmp_path):
    if not NODE.exists() or not PEER.exists():
        pytest.skip("bvc3d_ros2 not built (needs Cyclone DDS: cyclonedds-dev, cyclonedds-tools)")
    (tmp_path / "cyclonedds.xml").write_text(LOOPBACK)
    env = dict(os.environ)
    env["CYCLONEDDS_URI"] = f"file://{tmp_path / 'cyclonedds.xml'}"
    env["ROS_DOMAIN_ID"] = str(random.Random(os.getpid()).randrange(100, 230))  # apart from other runs
    return env


def start(args, env, log):
    return subprocess.Popen([str(a) for a in args], env=env, stdout=log, stderr=subprocess.STDOUT,
                            start_new_session=True)


def stop(proc, timeout=30):
    proc.send_signal(signal.SIGINT)
    try:
        return proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        return None


def test_ros2_node_publishes_what_replay_computes(dds_env, tmp_path, cli):
    bag = tmp_path / "walk.mcap"
    cli("export-scans", "--world", "cross", "--hours", "0.006", "--seed", "5", "--format", "mcap", "--out", bag,
        check=True)
    cli("replay", "--bag", bag, "--cloud-topic", "/points", "--pose-topic", "/odom", "--model", "3d-3l", "--out",
        tmp_path / "replay.h5", check=True)
    with h5py.File(tmp_path / "replay.h5") as f:
        want_bvc = np.asarray(f["samples/bvc_rates"])
        want_place = np.asarray(f["samples/rates"])
        t = np.asarray(f["samples/t"])
        xyz = np.c_[f["samples/x"], f["samples/y"], f["samples/z"]]
    # Parameters as ROS 2 gives them: a parameter file, and -p overrides on the command line.
    (tmp_path / "params.yaml").write_text(
        "bvc3d_ros2:\n  ros__parameters:\n    cloud_topic: /points\n    pose_topic: /odom\n    model: 3d-3l\n"
        f"    templates_bag: {bag}\n    templates_cloud_topic: /points\n    templates_pose_topic: /odom\n"
        "    revisit_window_scans: 50\n")
    recorded = tmp_path / "recorded.txt"
    logs = {name: open(tmp_path / f"{name}.log", "w") for name in ("recorder", "node", "player")}
    recorder = start([PEER, "record", "bvc3d_ros2", recorded], dds_env, logs["recorder"])
    node = start([NODE, "--ros-args", "--params-file", tmp_path / "params.yaml", "-p", "revisit_window_scans:=10",
                  "-p", "revisit_window_s:=2.0", "-p", "revisit_threshold:=0.05"], dds_env, logs["node"])
    try:
        wait_for(lambda: recorded.exists() and "ready" in recorded.read_text(), 60, "the recorder")
        wait_for(lambda: "bvc3d_ros2: model" in (tmp_path / "node.log").read_text(), 120, "the node")
        play = subprocess.run([str(PEER), "play", str(bag), "/points", "/odom", "5"], env=dds_env,
                              capture_output=True, text=True, timeout=300)
        assert play.returncode == 0, play.stderr
        wait_for(lambda: len(read_recorded(recorded)["place"]) >= len(want_bvc), 60, "every scan's rates")
        time.sleep(0.5)
    finally:
        code = stop(node)
        stop(recorder)
        for f in logs.values():
            f.close()
    log = (tmp_path / "node.log").read_text()
    assert code == 0, log
    assert f"bvc3d_ros2: stopped after {len(want_bvc)} scans (0 dropped while busy, 0 skipped)" in log, log
    got = read_recorded(recorded)
    np.testing.assert_array_equal(np.array(got["bvc"], dtype=np.float32), want_bvc)
    np.testing.assert_array_equal(np.array(got["place"], dtype=np.float32), want_place)
    np.testing.assert_allclose(np.array(got["decoded"]), xyz, atol=1e-9)
    revisits = cosine_revisits(want_bvc.astype(float), t, 10, 2.0, 0.05)
    assert revisits, "the walk should revisit places"
    assert [int(r[0]) for r in got["revisit"]] == [best for _, best, _ in revisits]
    np.testing.assert_allclose([r[0] for r in got["distance"]], [d for _, _, d in revisits], atol=1e-5)


def test_ros2_node_refuses_bad_parameters(dds_env, tmp_path):
    def run(*args):
        return subprocess.run([str(NODE), *map(str, args)], env=dds_env, capture_output=True, text=True, timeout=60)

    proc = run("--ros-args", "-p", "cloud_topic:=/points", "-p", "model:=no-such-model", "-p", "pose_topic:=/odom")
    assert proc.returncode == 2 and "no-such-model" in proc.stderr
    proc = run("--ros-args", "-p", "cloud_topic:=/points")
    assert proc.returncode == 2 and "pose_topic" in proc.stderr
    proc = run("--ros-args", "-p", "pose_topic:=/odom", "-p", "revisit_treshold:=0.2")
    assert proc.returncode == 2 and "unknown parameter 'revisit_treshold'" in proc.stderr
    proc = run("--ros-args", "-p", "pose_topic:=/odom", "-p", "learn:=maybe")
    assert proc.returncode == 2 and "parameter 'learn'" in proc.stderr
    (tmp_path / "p.yaml").write_text("bvc3d_ros2:\n  model: 3d-3l\n")
    proc = run("--ros-args", "--params-file", tmp_path / "p.yaml")
    assert proc.returncode == 2 and "ros__parameters" in proc.stderr
    proc = subprocess.run([str(NODE), "--ros-args", "-p", "pose_topic:=/odom"], capture_output=True, text=True,
                          timeout=60, env={**dds_env, "ROS_DOMAIN_ID": "999"})
    assert proc.returncode == 2 and "ROS_DOMAIN_ID" in proc.stderr
