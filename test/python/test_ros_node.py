"""The bvc3d_ros node on a live ROS 1 graph (docs/ros.md#the-node): roscore on 127.0.0.1 (a free port),
`rosbag play` of a bag the test writes, the node's published rates against `bvc3d replay` of the same bag,
its revisits against the same rule computed here in numpy, and a clean shutdown on SIGINT."""
import os
import pathlib
import shutil
import signal
import socket
import subprocess
import time

import numpy as np
import pytest

from conftest import CLI

h5py = pytest.importorskip("h5py")
NODE = pathlib.Path(CLI).parent / "bvc3d_ros"
TOOLS = ["roscore", "rosbag", "roslaunch"]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def ros_env(tmp_path):
    missing = [t for t in TOOLS if not shutil.which(t)]
    if missing or not NODE.exists():
        pytest.skip(f"ROS 1 tools or the node are missing ({', '.join(missing) or NODE}): scripts/setup installs them")
    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{port}", ROS_IP="127.0.0.1", ROS_HOME=str(tmp_path),
               ROS_LOG_DIR=str(tmp_path / "log"), ROS_PACKAGE_PATH=str(NODE.parent / "ros"),
               PYTHONUNBUFFERED="1")
    env.pop("ROS_HOSTNAME", None)
    core = subprocess.Popen(["roscore", "-p", str(port)], env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        for _ in range(100):
            if subprocess.run(["rosparam", "list"], env=env, capture_output=True).returncode == 0:
                break
            time.sleep(0.2)
        else:
            pytest.fail("roscore did not come up")
        yield env
    finally:
        core.send_signal(signal.SIGINT)
        try:
            core.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(core.pid, signal.SIGKILL)
            core.wait()


def wait_for(predicate, seconds, what):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if predicate():
            return
        time.sleep(0.1)
    pytest.fail(f"timed out waiting for {what}")


RECORDER = r"""
import sys, rospy
from std_msgs.msg import Float32MultiArray, Int64, Float32
from geometry_msgs.msg import PoseStamped
rospy.init_node("bvc3d_test_recorder", anonymous=True, disable_signals=True)
out = open(sys.argv[1], "w", buffering=1)
def writer(tag):
    def cb(m):
        data = m.data if isinstance(m.data, (list, tuple)) else [m.data]
        out.write(tag + " " + " ".join(repr(float(v)) for v in data) + "\n")
    return cb
subs = [rospy.Subscriber("/bvc3d_ros/bvc_rates", Float32MultiArray, writer("bvc"), queue_size=1000),
        rospy.Subscriber("/bvc3d_ros/place_rates", Float32MultiArray, writer("place"), queue_size=1000),
        rospy.Subscriber("/bvc3d_ros/revisit", Int64, writer("revisit"), queue_size=1000),
        rospy.Subscriber("/bvc3d_ros/revisit_distance", Float32, writer("distance"), queue_size=1000),
        rospy.Subscriber("/bvc3d_ros/decoded_pose", PoseStamped, lambda m: out.write(
            "decoded %r %r %r\n" % (m.pose.position.x, m.pose.position.y, m.pose.position.z)), queue_size=1000)]
out.write("ready\n")
rospy.spin()
"""


def read_recorded(path):
    rows = {"bvc": [], "place": [], "revisit": [], "distance": [], "decoded": []}
    for line in pathlib.Path(path).read_text().splitlines():
        tag, *values = line.split()
        if tag in rows:
            rows[tag].append([float(v) for v in values])
    return rows


def cosine_revisits(bvc, t, window_scans, window_s, threshold):
    """SPEC 15's sequential rule, by hand: scan i's best match among scans j with i - j > window_scans and
    t_i - t_j > window_s, by cosine of the BVC rates; a revisit when 1 - cosine <= threshold."""
    norm = np.linalg.norm(bvc, axis=1, keepdims=True)
    unit = bvc / np.where(norm > 0, norm, 1)
    out = []
    for i in range(len(bvc)):
        js = [j for j in range(i) if i - j > window_scans and t[i] - t[j] > window_s]
        if not js:
            continue
        c = unit[js] @ unit[i]
        best = js[int(np.argmax(c))]
        if 1 - c.max() <= threshold:
            out.append((i, best, 1 - c.max()))
    return out


POSE_SOURCES = {"odometry": (["--pose-topic", "/odom"], ["pose_topic:=/odom", "templates_pose_topic:=/odom"], "/odom"),
                "tf": (["--tf-frames", "map,sensor"], ["tf_frames:=map,sensor", "templates_tf_frames:=map,sensor"],
                       "/tf")}


@pytest.mark.parametrize("source", POSE_SOURCES)
def test_node_publishes_what_replay_computes(ros_env, tmp_path, cli, source):
    replay_poses, launch_poses, pose_topic = POSE_SOURCES[source]
    bag = tmp_path / "walk.bag"
    cli("export-scans", "--world", "cross", "--hours", "0.006", "--seed", "5", "--format", "ros1", "--out", bag,
        check=True)
    cli("replay", "--bag", bag, "--cloud-topic", "/points", *replay_poses, "--model", "3d-3l", "--out",
        tmp_path / "replay.h5", check=True)
    with h5py.File(tmp_path / "replay.h5") as f:
        want_bvc = np.asarray(f["samples/bvc_rates"])
        want_place = np.asarray(f["samples/rates"])
        t = np.asarray(f["samples/t"])
        xyz = np.c_[f["samples/x"], f["samples/y"], f["samples/z"]]
    recorded = tmp_path / "recorded.txt"
    recorder = subprocess.Popen(["/usr/bin/python3", "-c", RECORDER, str(recorded)], env=ros_env,
                                start_new_session=True)
    node_log = open(tmp_path / "node.log", "w")
    # The launch file, as a user starts the node; a short revisit window so that the walk has revisits.
    node = subprocess.Popen(["roslaunch", "--wait", "bvc3d", "bvc3d.launch", "cloud_topic:=/points",
                             *launch_poses, f"templates_bag:={bag}", "model:=3d-3l", "revisit_window_scans:=10",
                             "revisit_window_s:=2.0", "revisit_threshold:=0.05"],
                            env=ros_env, stdout=node_log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        wait_for(lambda: recorded.exists() and "ready" in recorded.read_text(), 60, "the recorder")
        wait_for(lambda: "bvc3d_ros: model" in (tmp_path / "node.log").read_text(), 60, "the node")
        play = subprocess.run(["rosbag", "play", "--wait-for-subscribers", "-r", "2", "--topics", "/points",
                               pose_topic, "--", str(bag)], env=ros_env, capture_output=True, text=True, timeout=300)
        assert play.returncode == 0, play.stderr
        wait_for(lambda: len(read_recorded(recorded)["place"]) >= len(want_bvc), 30, "every scan's rates")
        time.sleep(0.5)
    finally:
        node.send_signal(signal.SIGINT)  # roslaunch passes SIGINT on to the node
        try:
            code = node.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(node.pid, signal.SIGKILL)
            code = node.wait()
        recorder.send_signal(signal.SIGINT)
        try:
            recorder.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(recorder.pid, signal.SIGKILL)
        node_log.close()
    log = (tmp_path / "node.log").read_text()
    assert code == 0, log
    assert f"bvc3d_ros: stopped after {len(want_bvc)} scans (0 dropped while busy, 0 skipped)" in log, log
    got = read_recorded(recorded)
    np.testing.assert_array_equal(np.array(got["bvc"], dtype=np.float32), want_bvc)
    np.testing.assert_array_equal(np.array(got["place"], dtype=np.float32), want_place)
    # The bag's own scans are the templates: each scan decodes to itself, at its own position.
    np.testing.assert_allclose(np.array(got["decoded"]), xyz, atol=1e-9)
    revisits = cosine_revisits(want_bvc.astype(float), t, 10, 2.0, 0.05)
    assert revisits, "the walk should revisit places"
    assert [int(r[0]) for r in got["revisit"]] == [best for _, best, _ in revisits]
    np.testing.assert_allclose([r[0] for r in got["distance"]], [d for _, _, d in revisits], atol=1e-5)


def test_node_refuses_bad_parameters(ros_env, tmp_path):
    proc = subprocess.run([str(NODE), "_cloud_topic:=/points", "_model:=no-such-model", "_pose_topic:=/odom"],
                          env=ros_env, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2 and "no-such-model" in proc.stderr
    proc = subprocess.run([str(NODE), "__name:=bvc3d_other", "_cloud_topic:=/points"], env=ros_env,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2 and "pose_topic" in proc.stderr
