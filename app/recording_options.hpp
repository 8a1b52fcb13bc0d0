#pragma once
// Command-line options for reading a recording (--scans, --poses and how to pair and preprocess
// them, or a bag: --bag, --cloud-topic, --pose-topic or --tf-frames), shared by the commands that
// take one (replay, localize, map, choose-elevations, view).
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/bag_recording.hpp"
#include "bvc3d/recording/extrinsics.hpp"
#include "bvc3d/recording/recording.hpp"
#include "bvc3d/sensor/recorded_returns.hpp"
#include "table_options.hpp"

namespace bvc3d::cli {

// Where scans and poses are (files, or a bag), and how to read them.
struct RecordingOptions {
    std::string pose_format = "auto", extrinsics;
    double time_tolerance = 0.05;
    std::string bag, cloud_topic, pose_topic, tf_frames;
    double tf_tolerance = recording::BagSource{}.tf_tolerance;

    void add_to(CLI::App& cmd) {
        cmd.add_option("--bag", bag,
                       "Instead of --scans/--poses: a ROS bag (.bag, .mcap, or a ROS 2 bag folder; docs/ros.md)");
        cmd.add_option("--cloud-topic", cloud_topic, "With --bag: the sensor_msgs/PointCloud2 topic");
        cmd.add_option("--pose-topic", pose_topic,
                       "With --bag: the poses, a nav_msgs/Odometry or geometry_msgs/PoseStamped topic");
        cmd.add_option("--tf-frames", tf_frames,
                       "With --bag, instead of --pose-topic: FIXED,SENSOR, the poses from tf (/tf, /tf_static), "
                       "the chain from the fixed frame to the clouds' frame at each cloud's stamp");
        cmd.add_option("--tf-tolerance", tf_tolerance,
                       "Seconds: the largest gap between a tf link's samples around a cloud's stamp")
            ->capture_default_str();
        cmd.add_option("--pose-format", pose_format, "Pose file format: auto, kitti, tum or matrix (4x4 rows)")
            ->capture_default_str();
        cmd.add_option(
            "--extrinsics", extrinsics,
            "Sensor mounting (base-from-sensor): a file, or 12 or 16 numbers; the poses are then the base's");
        cmd.add_option("--time-tolerance", time_tolerance, "Seconds within which a scan pairs with a pose by time")
            ->capture_default_str();
    }
    bool has_bag() const { return !bag.empty(); }
    recording::RecordingOptions options() const {
        recording::RecordingOptions o;
        o.pose_format = recording::parse_pose_format(pose_format);
        o.time_tolerance = time_tolerance;
        if (!extrinsics.empty()) {
            std::error_code ec;
            o.base_from_sensor = std::filesystem::is_regular_file(extrinsics, ec)
                                     ? recording::read_extrinsics(extrinsics)
                                     : recording::parse_extrinsics(extrinsics, "--extrinsics");
        }
        return o;
    }
    std::shared_ptr<const recording::Recording> open(const std::string& scans, const std::string& poses) const {
        if (poses.empty()) throw InputError("the scans '" + scans + "' need a pose file");
        return std::make_shared<const recording::Recording>(recording::open_recording(scans, poses, options()));
    }
    // The bag at `path` read with --cloud-topic and --pose-topic or --tf-frames.
    std::shared_ptr<const recording::Recording> open_bag(const std::string& path) const {
        recording::BagSource s;
        s.bag = path;
        s.cloud_topic = cloud_topic;
        s.pose_topic = pose_topic;
        if (!tf_frames.empty()) recording::parse_tf_frames(tf_frames, s);
        s.tf_tolerance = tf_tolerance;
        return std::make_shared<const recording::Recording>(recording::open_bag_recording(s, options()));
    }
    // --bag, or the scans and poses given.
    std::shared_ptr<const recording::Recording> open_any(const std::string& scans, const std::string& poses) const {
        if (has_bag()) {
            if (!scans.empty() || !poses.empty()) throw InputError("give --bag or --scans and --poses, not both");
            return open_bag(bag);
        }
        if (!cloud_topic.empty() || !pose_topic.empty() || !tf_frames.empty())
            throw InputError("--cloud-topic, --pose-topic and --tf-frames go with --bag");
        return open(scans, poses);
    }
    // Whether `path` names a bag rather than scans: a .bag or .mcap file, or a folder with metadata.yaml.
    static bool is_bag(const std::string& path) {
        const std::filesystem::path p(path);
        std::error_code ec;
        return p.extension() == ".bag" || p.extension() == ".mcap" ||
               std::filesystem::is_regular_file(p / "metadata.yaml", ec);
    }
};

// The preprocessing of recorded scans: the options of the table RecordedReturnParams.
struct PreprocessOptions {
    TableOptions<RecordedReturnParams> table{RecordedReturnParams::table()};

    void add_to(CLI::App& cmd) {
        static const RecordedReturnParams defaults;
        table.add_to(cmd, {}, &defaults);
    }
    RecordedReturnParams get() const {
        RecordedReturnParams p;
        table.apply(p);
        p.validate();
        return p;
    }
};

}  // namespace bvc3d::cli
