#pragma once
// What the ROS nodes share, whatever carries their messages (bvc3d_ros over ROS 1's TCPROS,
// bvc3d_ros2 over DDS): the node's parameters by name, the poses by time (PoseSource) and the one-slot
// queue with its worker (NodeCore). Takes: clouds (as closures that decode them on the worker), poses
// and tf transforms as they arrive. Gives: for each scan the worker processes, its model step
// (node_model.hpp), its latency and the count of scans dropped so far, to a publishing callback.
// A scan that arrives while another waits replaces it (the replaced one is counted as dropped): the
// node always works on the newest scan and never falls behind.
//
// Read by the ROS 1 node's C++17 side: nothing newer than C++17 here.
#include <Eigen/Geometry>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recording/ros_messages.hpp"
#include "bvc3d/recording/tf_tree.hpp"
#include "node_model.hpp"

namespace bvc3d::ros_node {

// The node's parameters, read by name through `get(name, default)` (a ROS 1 parameter server, or a
// YAML file with `-p name:=value` overrides): each name and default written once, here.
struct PoseParams {
    std::string pose_topic, pose_type = "odometry";
    std::string fixed_frame_tf, sensor_frame_tf;  // from tf_frames "FIXED,SENSOR"
    double time_tolerance = 0.05, tf_tolerance = 0.2, pose_wait = 0.1;
};
struct NodeSettings {
    NodeParams model;
    PoseParams poses;
    std::string cloud_topic = "points", fixed_frame = "map";
};

// Splits "FIXED,SENSOR" (InputError naming `name` otherwise).
void split_tf_frames(const std::string& text, const std::string& name, PoseParams& p);

template <class Get>
NodeSettings read_settings(Get&& get, const std::string& prefix) {
    NodeSettings s;
    NodeParams& p = s.model;
    p.model = get("model", p.model);
    p.learn = get("learn", p.learn);
    p.weights = get("weights", p.weights);
    p.seed = static_cast<std::uint64_t>(get("seed", 0));
    p.min_range = get("min_range", p.min_range);
    p.max_range = get("max_range", p.max_range);
    p.slice_half_width_deg = get("slice_half_width_deg", p.slice_half_width_deg);
    p.templates_bag = get("templates_bag", p.templates_bag);
    p.templates_cloud_topic = get("templates_cloud_topic", p.templates_cloud_topic);
    p.templates_pose_topic = get("templates_pose_topic", p.templates_pose_topic);
    p.templates_tf_frames = get("templates_tf_frames", p.templates_tf_frames);
    p.templates_scans = get("templates_scans", p.templates_scans);
    p.templates_poses = get("templates_poses", p.templates_poses);
    p.decode_place = get("decode_rates", std::string("bvc")) == "place";
    p.revisit_place = get("revisit_rates", std::string("bvc")) == "place";
    p.revisit_window_scans = get("revisit_window_scans", p.revisit_window_scans);
    p.revisit_window_s = get("revisit_window_s", p.revisit_window_s);
    p.revisit_threshold = get("revisit_threshold", p.revisit_threshold);
    PoseParams& q = s.poses;
    q.pose_topic = get("pose_topic", q.pose_topic);
    q.pose_type = get("pose_type", q.pose_type);
    split_tf_frames(get("tf_frames", std::string()), prefix + "tf_frames", q);
    q.time_tolerance = get("time_tolerance", q.time_tolerance);
    q.tf_tolerance = get("tf_tolerance", q.tf_tolerance);
    q.pose_wait = get("pose_wait", q.pose_wait);
    s.cloud_topic = get("cloud_topic", s.cloud_topic);
    s.fixed_frame = get("fixed_frame", s.fixed_frame);
    if (q.fixed_frame_tf.empty() == q.pose_topic.empty())
        throw InputError("give " + prefix + "pose_topic (with " + prefix + "pose_type odometry or pose_stamped) or " +
                         prefix + "tf_frames");
    if (q.pose_type != "odometry" && q.pose_type != "pose_stamped")
        throw InputError(prefix + "pose_type '" + q.pose_type + "' is not odometry or pose_stamped");
    return s;
}

// Poses by time: from a pose topic (each the nearest within a tolerance, as a replay pairs them) or
// from tf (the chain interpolated at the stamp).
class PoseSource {
public:
    explicit PoseSource(const PoseParams& p) : p_(p) {}
    bool uses_tf() const { return !p_.fixed_frame_tf.empty(); }
    // Each throws InputError for a pose or transform it refuses (the rest of a tf message is kept).
    void add_pose(double stamp, const Eigen::Vector3d& position, const Eigen::Quaterniond& orientation);
    void add_tf(const std::vector<recording::StampedTransform>& transforms, bool is_static);
    // The pose at `stamp`, waiting up to `wait` for data that has not arrived yet: until then only a
    // pose that later data cannot change is taken (a tf sample at or after the stamp on every link; a
    // pose stamped at or after it), then the best there is within the tolerances. nullopt (and why)
    // if there is none.
    std::optional<Eigen::Isometry3d> at(double stamp, const std::string& frame, std::chrono::duration<double> wait,
                                        std::string& why);
    void wake() { changed_.notify_all(); }

private:
    std::optional<Eigen::Isometry3d> lookup(double stamp, const std::string& frame, bool final, std::string& why) const;
    PoseParams p_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<std::pair<double, Eigen::Isometry3d>> poses_;
    recording::TfTree tree_;
};

class NodeCore {
public:
    struct Output {
        double stamp = 0;  // the cloud's
        ScanResult result;
        double latency_s = 0;  // on the worker: pose lookup, points, model, decoding, revisit search
        std::size_t dropped = 0;
    };
    // A cloud to process, decoded on the worker (the transport's callback only moves it into the slot).
    using Cloud = std::function<recording::CloudMessage()>;
    using Publish = std::function<void(const Output&)>;
    using Warn = std::function<void(const std::string&)>;

    NodeCore(const NodeSettings& settings, Publish publish, Warn warn);
    ~NodeCore();
    NodeCore(const NodeCore&) = delete;
    NodeCore& operator=(const NodeCore&) = delete;

    const NodeModel& model() const { return model_; }
    PoseSource& poses() { return poses_; }
    // Into the one slot; never blocks longer than a move.
    void put(Cloud cloud);
    // Finishes the scan in hand, then the worker ends.
    void stop();
    std::size_t processed() const { return processed_; }
    std::size_t dropped() const { return dropped_; }
    std::size_t skipped() const { return skipped_; }

private:
    void work();
    void process(const Cloud& cloud);
    NodeModel model_;
    PoseSource poses_;
    double pose_wait_;
    Publish publish_;
    Warn warn_;
    std::mutex mutex_;
    std::condition_variable ready_;
    Cloud pending_;
    bool stopping_ = false;
    std::atomic<std::size_t> processed_{0}, dropped_{0}, skipped_{0};
    std::thread worker_;
};

}  // namespace bvc3d::ros_node
