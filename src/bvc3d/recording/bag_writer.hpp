#pragma once
// Writing simulated scans as a bag that ROS tools play (docs/ros.md#export). Takes: clouds in the
// sensor's frame and each scan's world-from-sensor pose with its time. Gives: a ROS 1 bag (Debian's
// rosbag storage library), an MCAP file (ROS 2: CDR, ros2msg schemas, zstd chunks, indexed) or a ROS 2
// bag folder (metadata.yaml and that MCAP file, as `ros2 bag record -s mcap` writes them) with
//   /points  sensor_msgs/PointCloud2  x, y, z as FLOAT64 (point_step 24), frame `sensor`
//   /odom    nav_msgs/Odometry        map ← sensor (the sensor's pose; zero covariance and twist)
//   /tf      tf2_msgs/TFMessage       the same transform, map → sensor
// every message stamped and logged at `start` + the scan's time (ROS takes a zero stamp for "no
// time"). All or nothing: the file appears only when complete.
#include <filesystem>
#include <string>
#include <vector>

#include "bvc3d/recording/point_cloud.hpp"
#include "bvc3d/recording/pose_file.hpp"

namespace bvc3d::recording {

enum class BagFormat { ros1, mcap, ros2 };

struct BagWriteOptions {
    BagFormat format = BagFormat::ros1;
    double start = 1.0;  // s, added to every scan's time
    std::string cloud_topic = "/points", odom_topic = "/odom", fixed_frame = "map", sensor_frame = "sensor";
};

// Every pose needs a time, increasing.
void write_bag(const std::filesystem::path& file, const std::vector<PointCloud>& clouds,
               const std::vector<PoseRecord>& poses, const BagWriteOptions& options);

}  // namespace bvc3d::recording
