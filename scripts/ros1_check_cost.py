#!/usr/bin/python3
"""What checking a ROS 1 bag's framing costs (docs/ros.md): writes a bag of 300 clouds of 30 000 points
and 300 odometry messages (108 MB uncompressed) with Debian's python3-rosbag, once per chunk compression,
and times `bvc3d bag-info` on each (best of 3 wall times). bag-info reads only the index and the first
message of each topic, so its time is almost all the check, which decompresses every chunk.

    /usr/bin/python3 scripts/ros1_check_cost.py build/bvc3d
"""
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np
import rosbag
import rospy
from nav_msgs.msg import Odometry
from sensor_msgs.msg import PointCloud2, PointField


def write_bag(path, compression):
    rng = np.random.default_rng(0)
    with rosbag.Bag(str(path), "w", compression=compression) as bag:
        for i in range(300):
            t = rospy.Time.from_sec(1 + 0.1 * i)
            c = PointCloud2()
            c.header.stamp, c.header.frame_id = t, "lidar"
            c.height, c.width, c.point_step, c.row_step = 1, 30000, 12, 12 * 30000
            c.fields = [PointField(name=k, offset=4 * j, datatype=7, count=1) for j, k in enumerate("xyz")]
            c.data = (np.round(rng.normal(size=(30000, 3)) * 500) / 100).astype("<f4").tobytes()
            o = Odometry()
            o.header.stamp, o.header.frame_id, o.child_frame_id = t, "map", "lidar"
            o.pose.pose.orientation.w = 1.0
            bag.write("/odom", o, t)
            bag.write("/points", c, t)


def main():
    cli = sys.argv[1] if len(sys.argv) > 1 else "build/bvc3d"
    with tempfile.TemporaryDirectory() as tmp:
        for compression in ("none", "lz4", "bz2"):
            path = pathlib.Path(tmp) / f"{compression}.bag"
            write_bag(path, compression)
            best = float("inf")
            for _ in range(3):
                start = time.perf_counter()
                subprocess.run([cli, "bag-info", str(path)], check=True, stdout=subprocess.DEVNULL)
                best = min(best, time.perf_counter() - start)
            print(f"{compression}: {path.stat().st_size / 1e6:.1f} MB, bag-info {best:.2f} s")


if __name__ == "__main__":
    main()
