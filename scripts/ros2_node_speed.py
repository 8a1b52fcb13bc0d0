#!/usr/bin/env python3
"""How bvc3d_ros2 keeps up with an os1-128 at 10 Hz (docs/ros.md#the-ros-2-node): exports an os1-128 walk
as an MCAP bag, starts the node pinned to one core (taskset) with a model, plays the bag at 10 Hz into it
through DDS on the loopback (test/ros2/ros2_peer), and reports the scans processed and dropped, the
latency the node publishes (median, 95th percentile, max) and the node's CPU time per scan (user + system,
every thread, from /proc: less moved by other load than wall time).

    /usr/bin/python3 scripts/ros2_node_speed.py build [--hours 0.02] [--model 3d-3l] [--rate 10] [--core 0]
        [--socket-buffer 4MB]
"""
import argparse
import os
import pathlib
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "test" / "python"))
from test_ros2_node import LOOPBACK  # noqa: E402


def cpu_seconds(pid):
    fields = pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("build")
    ap.add_argument("--hours", type=float, default=0.02)
    ap.add_argument("--world", default="configs/worlds/two-rooms.yaml")
    ap.add_argument("--model", default="3d-3l")
    ap.add_argument("--rate", type=float, default=10)
    ap.add_argument("--core", default="0")
    ap.add_argument("--socket-buffer", default="default", help="Cyclone's SocketReceiveBufferSize min (e.g. 4MB)")
    a = ap.parse_args()
    build = pathlib.Path(a.build).resolve()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        bag = tmp / "os128.mcap"
        subprocess.run([build / "bvc3d", "export-scans", "--world", a.world, "--sensor", "os1-128", "--hours",
                        str(a.hours), "--seed", "1", "--format", "mcap", "--out", bag], check=True,
                       capture_output=True)
        # A receive buffer that holds a few clouds (3 MB each): the kernel's default (~200 KB) loses fragments.
        buffer = f'<Internal><SocketReceiveBufferSize min="{a.socket_buffer}"/></Internal>'
        (tmp / "cyclonedds.xml").write_text(LOOPBACK.replace("</Discovery>", "</Discovery>\n    " + buffer))
        env = dict(os.environ, CYCLONEDDS_URI=f"file://{tmp / 'cyclonedds.xml'}", ROS_DOMAIN_ID="77")
        rec = subprocess.Popen([build / "test" / "ros2_peer", "record", "bvc3d_ros2", tmp / "rec.txt"], env=env)
        log = open(tmp / "node.log", "w")
        node = subprocess.Popen(["taskset", "-c", a.core, build / "bvc3d_ros2", "--ros-args", "-p",
                                 "cloud_topic:=/points", "-p", "pose_topic:=/odom", "-p", f"model:={a.model}"],
                                env=env, stdout=log, stderr=subprocess.STDOUT)
        while "bvc3d_ros2: model" not in (tmp / "node.log").read_text():
            time.sleep(0.2)
        cpu0 = cpu_seconds(node.pid)
        play = subprocess.run([build / "test" / "ros2_peer", "play", bag, "/points", "/odom", str(a.rate)],
                              env=env, capture_output=True, text=True, check=True)
        time.sleep(2)
        cpu = cpu_seconds(node.pid) - cpu0
        node.send_signal(signal.SIGINT)
        node.wait(timeout=60)
        rec.send_signal(signal.SIGINT)
        rec.wait(timeout=30)
        log.close()
        lines = (tmp / "rec.txt").read_text().splitlines()
        latency = np.array([float(x.split()[1]) for x in lines if x.startswith("latency")])
        points = [len(x.split()) for x in lines if x.startswith("bvc")]
        played = int(play.stdout.split()[1])
        stopped = [x for x in (tmp / "node.log").read_text().splitlines() if "stopped after" in x]
        print(f"model {a.model}, {played} os1-128 scans played at {a.rate:g} Hz, node on core {a.core}")
        print(stopped[0] if stopped else "(no stop line)")
        print(f"latency on the worker: median {1e3 * np.median(latency):.1f} ms, 95th percentile "
              f"{1e3 * np.percentile(latency, 95):.1f} ms, max {1e3 * latency.max():.1f} ms ({len(latency)} scans)")
        print(f"node CPU time (all threads, user + system): {1e3 * cpu / max(1, len(latency)):.1f} ms per scan "
              f"processed; the period is {1e3 / a.rate:.0f} ms")
        print(f"load average during the run: {os.getloadavg()}; {len(points)} rate vectors recorded")


if __name__ == "__main__":
    main()
